"""The command line the estimator and replay benchmarks share: drive length and repetitions."""

from __future__ import annotations

import argparse


def hours_and_repeat(doc: str) -> argparse.Namespace:
    """Parse ``--hours`` (drive length, default one hour) and ``--repeat`` (timed runs, the
    best one reported, default 3), with the first paragraph of the benchmark's ``doc``."""
    parser = argparse.ArgumentParser(description=doc.split("\n\n")[0])
    parser.add_argument("--hours", type=float, default=1.0, help="drive length, h")
    parser.add_argument("--repeat", type=int, default=3,
                        help="timed runs (the best is reported)")
    return parser.parse_args()
