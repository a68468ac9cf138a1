"""``landnav reproduce``: the seed papers' claims run over seeds and judged, with a report.

Modules: ``paper`` (Experiment, Claim, Verdict, Paper), ``papers`` (the registered papers),
``measures`` (figures shared by the paper modules: spreads, paired win rates, errors against the
truth, windows from the events), ``runner`` (every experiment x seed on the campaign executor,
then every claim judged), ``report`` (report.md and a self-contained report.html), and one
module per paper (``cho2006``, ``tan2008``, ``park2019``, ``chan``, ``karamat2015``).
"""

FULL_SEEDS = 10  # seeds of a full run unless --runs says otherwise
QUICK_SEEDS = 3  # seeds of --quick
