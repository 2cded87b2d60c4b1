"""A small strict schema for nested TOML tables: types, ranges, choices, defaults.

Every problem is reported as one :class:`~startrack.base.errors.InputError` naming the file, the
dotted key and what is wrong ("demo.toml: gyro.rate_hz: must be > 0, got -1").
"""

import copy
from dataclasses import dataclass, field
from typing import Any

from startrack import InputError

REQUIRED = object()


@dataclass(frozen=True)
class Value:
    """A scalar or fixed-length list value.

    ``kind``: 'float', 'int', 'bool', 'str', 'list' (floats, any length), 'ints' (integers, any length),
    'strs' (strings from ``choices``, any length), 'vector' (list of floats of length ``size``),
    'matrix' (size x size floats) or 'quaternion' (4 floats, non-zero norm). Lists of ``min_length`` or more.
    """

    kind: str
    default: Any = REQUIRED
    minimum: float | None = None
    exclusive_minimum: float | None = None
    maximum: float | None = None
    choices: tuple = ()
    size: int = 3
    min_length: int = 0
    doc: str = ""

    def check(self, where, value):
        if value is None and self.default is None:  # an optional value left unset (re-validation)
            return None
        if self.kind == "float":
            if isinstance(value, bool) or not isinstance(value, (int, float)):
                raise InputError(f"{where}: must be a number, got {value!r}")
            value = float(value)
            if value != value or value in (float("inf"), float("-inf")):
                raise InputError(f"{where}: must be a finite number, got {value!r}")
            self._check_range(where, value)
        elif self.kind == "int":
            if isinstance(value, bool) or not isinstance(value, int):
                raise InputError(f"{where}: must be an integer, got {value!r}")
            self._check_range(where, value)
        elif self.kind == "bool":
            if not isinstance(value, bool):
                raise InputError(f"{where}: must be true or false, got {value!r}")
        elif self.kind == "str":
            if not isinstance(value, str):
                raise InputError(f"{where}: must be a string, got {value!r}")
            if self.choices and value not in self.choices:
                raise InputError(f"{where}: must be one of {', '.join(self.choices)}; got {value!r}")
        elif self.kind == "list":
            if not isinstance(value, list):
                raise InputError(f"{where}: must be a list of numbers, got {value!r}")
            value = _numbers(where, value, len(value))
            self._check_length(where, value)
            for v in value:
                self._check_range(where, v)
        elif self.kind == "ints":
            if not isinstance(value, list) or not all(isinstance(v, int) and not isinstance(v, bool) for v in value):
                raise InputError(f"{where}: must be a list of integers, got {value!r}")
            self._check_length(where, value)
            for v in value:
                self._check_range(where, v)
        elif self.kind == "strs":
            if not isinstance(value, list) or not all(isinstance(v, str) for v in value):
                raise InputError(f"{where}: must be a list of strings, got {value!r}")
            self._check_length(where, value)
            unknown = [v for v in value if self.choices and v not in self.choices]
            if unknown:
                raise InputError(f"{where}: {unknown[0]!r} is not one of {', '.join(self.choices)}")
        elif self.kind in ("vector", "quaternion"):
            size = 4 if self.kind == "quaternion" else self.size
            value = _numbers(where, value, size)
            if self.kind == "quaternion" and sum(v * v for v in value) < 1e-12:
                raise InputError(f"{where}: quaternion must have a non-zero norm")
            for v in value:
                self._check_range(where, v)
        elif self.kind == "matrix":
            if not isinstance(value, list) or len(value) != self.size:
                raise InputError(f"{where}: must be a {self.size}x{self.size} list of lists of numbers")
            value = [_numbers(where, row, self.size) for row in value]
            for v in (v for row in value for v in row):
                self._check_range(where, v)
        else:  # pragma: no cover - schema authoring error
            raise AssertionError(self.kind)
        return value

    def _check_length(self, where, value):
        if len(value) < self.min_length:
            raise InputError(f"{where}: needs at least {self.min_length} entries, got {len(value)}")

    def _check_range(self, where, value):
        if self.minimum is not None and value < self.minimum:
            raise InputError(f"{where}: must be >= {self.minimum:g}, got {value!r}")
        if self.exclusive_minimum is not None and value <= self.exclusive_minimum:
            raise InputError(f"{where}: must be > {self.exclusive_minimum:g}, got {value!r}")
        if self.maximum is not None and value > self.maximum:
            raise InputError(f"{where}: must be <= {self.maximum:g}, got {value!r}")


def _numbers(where, value, size):
    if not isinstance(value, list) or len(value) != size:
        raise InputError(f"{where}: must be a list of {size} numbers, got {value!r}")
    out = []
    for v in value:
        if isinstance(v, bool) or not isinstance(v, (int, float)) or v != v or abs(v) == float("inf"):
            raise InputError(f"{where}: must be a list of {size} finite numbers, got {value!r}")
        out.append(float(v))
    return out


@dataclass(frozen=True)
class Table:
    """A table of named entries (Values, Tables or ListOfTables); ``optional`` tables may be absent."""

    entries: dict
    optional: bool = False
    doc: str = ""

    def check(self, where, value):
        if not isinstance(value, dict):
            raise InputError(f"{where}: must be a table")
        unknown = sorted(set(value) - set(self.entries))
        if unknown:
            known = ", ".join(sorted(self.entries))
            raise InputError(f"{where}.{unknown[0]}: unknown key (known keys here: {known})".lstrip("."))
        out = {}
        for key, spec in self.entries.items():
            path = f"{where}.{key}".lstrip(".")
            if key in value:
                out[key] = spec.check(path, value[key])
            elif isinstance(spec, Table) and spec.optional:
                continue
            elif isinstance(spec, Table):
                out[key] = spec.check(path, {})
            elif isinstance(spec, ListOfTables):
                if spec.required:
                    raise InputError(f"{path}: missing required key")
                out[key] = []
            elif spec.default is REQUIRED:
                raise InputError(f"{path}: missing required key")
            else:
                out[key] = copy.deepcopy(spec.default)
        return out


@dataclass(frozen=True)
class Tagged:
    """A table whose ``tag`` key picks one of ``variants`` (name -> :class:`Table`), each with its own
    keys, defaults and bounds (a trajectory segment of one kind)."""

    tag: str
    variants: dict
    doc: str = ""

    def check(self, where, value):
        if not isinstance(value, dict):
            raise InputError(f"{where}: must be a table")
        kind = value.get(self.tag)
        if not isinstance(kind, str) or kind not in self.variants:
            raise InputError(f"{where}.{self.tag}: must be one of {', '.join(self.variants)}; got {kind!r}")
        rest = {key: v for key, v in value.items() if key != self.tag}
        return {self.tag: kind, **self.variants[kind].check(where, rest)}


@dataclass(frozen=True)
class ListOfTables:
    """A TOML array of tables, each checked against ``item`` (a :class:`Table` or :class:`Tagged`)."""

    item: Table | Tagged
    required: bool = False
    min_length: int = 0
    doc: str = field(default="")

    def check(self, where, value):
        if not isinstance(value, list) or not all(isinstance(v, dict) for v in value):
            raise InputError(f"{where}: must be an array of tables")
        if len(value) < self.min_length:
            raise InputError(f"{where}: needs at least {self.min_length} entries")
        return [self.item.check(f"{where}[{i}]", v) for i, v in enumerate(value)]


def is_multiple(high, low):
    """True when the rate ``high`` is an integer multiple (>= 1) of the rate ``low`` (to 1e-9)."""
    ratio = high / low
    return ratio >= 1.0 - 1e-9 and abs(ratio - round(ratio)) < 1e-9
