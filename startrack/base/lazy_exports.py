"""Lazy public names of a package (PEP 562): ``import startrack`` or ``import navsim`` costs nothing
until a name is used, so the command lines start fast and load only what a command needs."""

import importlib
import sys


def lazy_exports(package, exports, modules=None):
    """``(__getattr__, __dir__, __all__)`` for ``package`` whose public names live in the modules of
    ``exports`` ({module: (name, ...)}) or are whole modules (``modules``: {name: module}, a namespace such as
    ``startrack.rotation``); a name is imported on first use."""
    where = {name: module for module, names in exports.items() for name in names}
    modules = dict(modules or {})

    def __getattr__(name):
        if name in modules:
            value = importlib.import_module(modules[name])
        elif name in where:
            value = getattr(importlib.import_module(where[name]), name)
        else:
            raise AttributeError(f"module {package!r} has no attribute {name!r}")
        setattr(sys.modules[package], name, value)
        return value

    def __dir__():
        return sorted(set(vars(sys.modules[package])) | set(where) | set(modules))

    return __getattr__, __dir__, sorted(set(where) | set(modules))
