"""One module per ``landnav`` command: ``add_parser(subparsers)`` and ``run(args) -> int``."""
