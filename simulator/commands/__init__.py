"""One module per ``landnav`` command: ``add_parser(subparsers)`` and ``run(args) -> int``.

``SUMMARIES`` gives each command's one-line help, so ``landnav --help`` lists every command
without importing any (a command's module, and what it needs, is imported only when it runs).
``MODULES`` names the module of a command whose name is not a module name (``import``).
"""

MODULES = {"import": "import_recording"}

SUMMARIES = {
    "validate": "check scenario files; print every problem as file:line: key: message",
    "generate": "write the dataset of a scenario (truth, sensor streams, events)",
    "estimators": "list the registered estimators (name, streams it needs, paper)",
    "estimate": "run one estimator causally over a dataset, write its solution",
    "score": "score solutions against a dataset's truth (table, JSON, report)",
    "run": "generate, run the scenario's estimators, score, write the report",
    "campaign": "Monte Carlo over seeds and sweeps, locally or on Dask; resumable",
    "reproduce": "run the seed papers' experiments over seeds, judge each claim, report",
    "export": "write a dataset as RINEX 3.04, NMEA 0183 or a ROS 2 bag (MCAP)",
    "import": "turn a real recording into a dataset, its reference in place of the truth",
    "twin": "write a scenario that drives the simulator along a dataset's reference",
    "compare": "put two datasets' statistics side by side (a recording and its twin)",
    "schema": "print the JSON Schema of the scenario file (editor completion)",
    "presets": "list the sensor presets with their parameters",
}
