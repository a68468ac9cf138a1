"""Truth-referenced scoring of navigation solutions (docs/scores.md) and the report.

Modules
-------
align     truth interpolated at the solution times; per-sample errors in local NED
metrics   the scores of one solution (horizontal, vertical, velocity, attitude, outages, NEES)
consistency  NEES per block, normalised errors, NIS and ANEES (whether a filter knows its error)
evaluate  several solutions on one dataset: read truth and events once, score, write JSON
report    the markdown report with its plots (matplotlib, Agg)
"""
