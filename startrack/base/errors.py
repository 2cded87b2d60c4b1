"""The one exception type for bad user input, shared by both packages, and the command-line runner.

Raising :class:`InputError` anywhere below a command-line entry point ends the program with its
message on one line and exit status 2, never a traceback. The runner also turns an interruption
(Ctrl-C: exit 130), a failing file system (disk full, permission: exit 1) and an unexpected internal
error (exit 70, with the traceback only when ``STARTRACK_DEBUG`` is set) into one line each.
"""

import argparse
import math
import os
import sys
import traceback


class InputError(ValueError):
    """Bad input named in one clear sentence (file, key, value and what is wrong)."""


def check_range(option: str, value, low: float, high: float):
    """``value`` of ``option`` if it is a finite number in [low, high], else InputError naming both."""
    if value is None or not math.isfinite(value) or not low <= value <= high:
        raise InputError(f"option {option} = {value} is not a finite number in [{low:g}, {high:g}].")
    return value


class ArgumentParser(argparse.ArgumentParser):
    """argparse with its usage errors on one line (the option and the problem, then where to look)."""

    def error(self, message):
        print(f"{self.prog}: error: {message} (see {self.prog} --help)", file=sys.stderr)
        raise SystemExit(2)


def run_command(prog, build_parser, argv=None, call=None) -> int:
    """Build the parser, parse ``argv`` and call ``args.func(args)`` (or ``call(args)``); every failure is one
    line on stderr."""
    try:
        args = build_parser().parse_args(argv)
        return int((call or args.func)(args) or 0)
    except InputError as error:
        return _fail(prog, error, 2)
    except KeyboardInterrupt:
        return _fail(prog, "interrupted", 130, label="")
    except BrokenPipeError:  # output piped into a reader that stopped early (| head)
        os.dup2(os.open(os.devnull, os.O_WRONLY), sys.stdout.fileno())
        return 141
    except OSError as error:  # the file system refused: no space, no permission, read-only, ...
        where = f"{error.filename}: " if error.filename else ""
        return _fail(prog, f"{where}{error.strerror or error}", 1)
    except MemoryError:
        return _fail(prog, "out of memory: make the run shorter or the rates lower", 1)
    except Exception as error:  # a defect of ours: say so in one line, keep the traceback for debugging
        if interrupted(error):
            return _fail(prog, "interrupted", 130, label="")
        if os.environ.get("STARTRACK_DEBUG"):
            traceback.print_exc()
        return _fail(prog, f"{type(error).__name__}: {error} (an internal error; set STARTRACK_DEBUG=1 "
                           "for the traceback and please report it)", 70, label="internal error: ")


def interrupted(error):
    """True when a KeyboardInterrupt is in ``error``'s chain of causes: Ctrl-C inside a compiled kernel reaches
    Python as a SystemError (numba's dispatcher "returned a result with an exception set") caused by it, and is
    an interruption, not a defect or a failure of the input."""
    seen = set()
    while error is not None and id(error) not in seen:
        if isinstance(error, KeyboardInterrupt):
            return True
        seen.add(id(error))
        error = error.__cause__ or error.__context__
    return False


def _fail(prog, message, status, label="error: "):
    print(f"{prog}: {label}{message}", file=sys.stderr)
    return status
