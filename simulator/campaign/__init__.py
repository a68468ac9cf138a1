"""Monte Carlo campaigns (``landnav campaign``, SPEC section 3): N seeds x the scenario's
estimators x the sweep points, run in local processes or on a Dask cluster, resumable.

Modules: ``plan`` (sweeps, validation, runs, fingerprint), ``worker`` (one run: generate,
estimate, score, flatten), ``execute`` (local processes or Dask), ``store`` (the folder, one
part file per finished run), ``summary`` (statistics), ``report`` (report.md and plots),
``campaign`` (the whole campaign, start to end).
"""
