"""Sub-commands of the ``startrack`` command line, one module each.

Each module defines ``register(subparsers)``, which adds its parser and sets
``func`` to a callable taking the parsed arguments and returning an exit code.
"""

import argparse
import importlib

from startrack.base.errors import ArgumentParser

#: Sub-command modules under ``startrack.commands``, in the order ``--help`` lists them.
COMMANDS = ("catalog", "address", "render", "detect", "solve", "serve")


def build_parser() -> argparse.ArgumentParser:
    """The ``startrack`` parser with every sub-command (each module imported when the parser is built)."""
    parser = ArgumentParser(
        prog="startrack",
        description="Star sensor: navigation catalog, rendering, centroiding, identification, attitude.",
    )
    subparsers = parser.add_subparsers(dest="command", metavar="COMMAND", required=True)
    for name in COMMANDS:
        importlib.import_module(f"startrack.commands.{name}").register(subparsers)
    return parser
