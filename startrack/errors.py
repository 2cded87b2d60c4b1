"""The one exception type for bad user input, shared by both packages.

Raising :class:`InputError` anywhere below a command-line entry point ends the
program with its message on one line and exit status 2, never a traceback.
"""


class InputError(ValueError):
    """Bad input named in one clear sentence (file, key, value and what is wrong)."""
