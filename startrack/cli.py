"""``startrack`` command line (contract in DESIGN.md).

Bad input of any kind ends with one line ``startrack: error: ...`` and exit
status 2; no traceback reaches the user.
"""

import argparse
import importlib
import sys

from startrack.errors import InputError

#: Sub-command modules under ``startrack.commands``, in the order ``--help`` lists them.
COMMANDS = ("catalog", "address", "render", "detect")


def build_parser() -> argparse.ArgumentParser:
    parser = argparse.ArgumentParser(
        prog="startrack",
        description="Star sensor: navigation catalog, rendering, centroiding, identification, attitude.",
    )
    subparsers = parser.add_subparsers(dest="command", metavar="COMMAND", required=True)
    for name in COMMANDS:
        importlib.import_module(f"startrack.commands.{name}").register(subparsers)
    return parser


def main(argv=None) -> int:
    parser = build_parser()
    args = parser.parse_args(argv)
    try:
        return int(args.func(args) or 0)
    except InputError as error:
        print(f"startrack: error: {error}", file=sys.stderr)
        return 2
    except KeyboardInterrupt:
        print("startrack: interrupted", file=sys.stderr)
        return 130


if __name__ == "__main__":
    sys.exit(main())
