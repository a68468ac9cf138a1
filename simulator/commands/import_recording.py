"""``landnav import KIND SOURCE... -o DIR``: a real recording as a dataset (SPEC section 9,
``simulator.recordings``)."""

from __future__ import annotations

import argparse
import textwrap

from simulator.commands import SUMMARIES


def add_parser(sub: argparse._SubParsersAction) -> None:
    from simulator.recordings import KINDS

    kinds = "\n".join(f"  {name:10s} {text}" for name, (_, text) in KINDS.items())
    p = sub.add_parser(
        "import", help=SUMMARIES["import"], formatter_class=argparse.RawDescriptionHelpFormatter,
        description=textwrap.fill(
                    "Turn a real recording into a landnav dataset: its streams in landnav's "
                    "files, columns and units (frames converted, every stream's own timestamps "
                    "kept), its reference trajectory as truth.parquet (the manifest says "
                    "\"reference\": true and where it came from), so that `landnav estimate` "
                    "and `landnav score` run on it unchanged; scores are then against that "
                    "reference. What a recording lacks (a broadcast ephemeris, a DOP) is NaN "
                    "and listed in the manifest, and an estimator that needs it is refused by "
                    "name.", 92) + f"\n\nKINDS:\n{kinds}\n\nExample:\n  landnav import comma2k19 "
                    "path/to/segment -o out/c2k19 && landnav score out/c2k19 -e ins_odo_ekf")
    p.add_argument("kind", metavar="KIND", choices=sorted(KINDS), help="the recording's kind")
    p.add_argument("sources", metavar="SOURCE", nargs="+", help="the recording's files/folder")
    p.add_argument("-o", "--output", metavar="DIR", required=True, help="dataset directory")
    p.add_argument("--force", action="store_true", help="replace an existing DIR")
    p.set_defaults(run=run)


def run(args: argparse.Namespace) -> int:
    from simulator.recordings import import_recording

    out = import_recording(args.kind, args.sources, args.output, args.force)
    print(f"wrote {out} ({args.kind}: the reference trajectory is its truth)")
    return 0
