"""``startrack`` command line (contract in docs/design.md).

Bad input of any kind ends with one line ``startrack: error: ...`` and exit
status 2; no traceback reaches the user.
"""

import sys

from startrack.base.errors import run_command
from startrack.commands import build_parser


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
