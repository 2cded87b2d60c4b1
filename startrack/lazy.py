"""Lazy public names of a package (PEP 562): ``import startrack`` or ``import navsim`` costs nothing
until a name is used, so the command lines start fast and load only what a command needs."""

import importlib
import sys


def lazy_exports(package, exports):
    """``(__getattr__, __dir__, __all__)`` for ``package`` whose public names live in the modules of
    ``exports`` ({module: (name, ...)}); a name is imported from its module on first use."""
    where = {name: module for module, names in exports.items() for name in names}

    def __getattr__(name):
        if name not in where:
            raise AttributeError(f"module {package!r} has no attribute {name!r}")
        value = getattr(importlib.import_module(where[name]), name)
        setattr(sys.modules[package], name, value)
        return value

    def __dir__():
        return sorted(set(vars(sys.modules[package])) | set(where))

    return __getattr__, __dir__, sorted(where)
