"""``startrack`` command line (contract in docs/design.md).

Bad input of any kind ends with one line ``startrack: error: ...`` and exit
status 2; no traceback reaches the user.
"""

import argparse
import importlib
import sys

from startrack.errors import ArgumentParser, run_command

#: Sub-command modules under ``startrack.commands``, in the order ``--help`` lists them.
COMMANDS = ("catalog", "address", "render", "detect", "solve", "serve")


def build_parser() -> argparse.ArgumentParser:
    parser = ArgumentParser(
        prog="startrack",
        description="Star sensor: navigation catalog, rendering, centroiding, identification, attitude.",
    )
    subparsers = parser.add_subparsers(dest="command", metavar="COMMAND", required=True)
    for name in COMMANDS:
        importlib.import_module(f"startrack.commands.{name}").register(subparsers)
    return parser


def main(argv=None) -> int:
    """The command; a ``solve`` is handed to a running ``startrack serve`` of the same code when there is one
    (:mod:`startrack.serve_client`, standard library only: nothing else is imported on that path)."""
    from startrack.serve_client import forward

    try:
        status = forward(argv)
    except KeyboardInterrupt:
        print("startrack: interrupted", file=sys.stderr)
        return 130
    return run_command("startrack", build_parser, argv) if status is None else status


if __name__ == "__main__":
    sys.exit(main())
