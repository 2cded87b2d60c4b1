"""The one exception type for bad user input, shared by both packages, and the command-line runner.

Raising :class:`InputError` anywhere below a command-line entry point ends the
program with its message on one line and exit status 2, never a traceback.
"""

import os
import sys


class InputError(ValueError):
    """Bad input named in one clear sentence (file, key, value and what is wrong)."""


def run_command(prog, parser, argv=None) -> int:
    """Parse ``argv`` and call ``args.func(args)``; bad input -> one line on stderr and exit 2."""
    args = parser.parse_args(argv)
    try:
        return int(args.func(args) or 0)
    except InputError as error:
        print(f"{prog}: error: {error}", file=sys.stderr)
        return 2
    except KeyboardInterrupt:
        print(f"{prog}: interrupted", file=sys.stderr)
        return 130
    except BrokenPipeError:  # output piped into a reader that stopped early (| head)
        os.dup2(os.open(os.devnull, os.O_WRONLY), sys.stdout.fileno())
        return 141
