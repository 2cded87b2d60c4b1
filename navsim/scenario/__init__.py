"""Scenario files: strict TOML with the unit in every key name.

This package holds what every kind of scenario shares: the :class:`Scenario` type, reading a file
(:func:`read_scenario_file`), ``--set key=value`` overrides (:func:`apply_overrides`), the schema
machinery (:mod:`navsim.scenario.schema`) and the key sets both run kinds use (the inertial sensors'
datasheet keys, the star sensor's and the faults'). Which schema a scenario is checked against is its
kind's (:mod:`navsim.kinds`: ``navsim.kinds.load_scenario``); every problem ends in one
:class:`InputError` naming the file, the key and what is wrong.
"""

import copy
import tomllib
from dataclasses import dataclass
from pathlib import Path

from startrack import InputError


@dataclass(frozen=True)
class Scenario:
    """A validated scenario: ``data`` is the checked dictionary (units in key names), ``source`` the
    name of its file, ``kind`` the name of its kind (:mod:`navsim.kinds`)."""

    data: dict
    source: str = "<scenario>"
    kind: str = ""

    @property
    def name(self):
        return self.data["name"]

    def __getitem__(self, key):
        return self.data[key]


def parse_override(text):
    """``'gyro.rate_hz=200'`` -> (['gyro', 'rate_hz'], 200.0); the value is read as TOML,
    a bare word as a string."""
    if "=" not in text:
        raise InputError(f"--set {text!r}: expected KEY=VALUE, e.g. --set gyro.rate_hz=200")
    key, raw = text.split("=", 1)
    path = [part.strip() for part in key.strip().split(".")]
    if not all(path):
        raise InputError(f"--set {text!r}: empty key")
    try:
        value = tomllib.loads(f"v = {raw.strip()}")["v"]
    except tomllib.TOMLDecodeError:
        value = raw.strip()
    except RecursionError:
        raise InputError(f"--set {key.strip()}: the value is nested too deeply") from None
    return path, value


def apply_overrides(data, overrides, source):
    """Return a copy of ``data`` with overrides applied; ``overrides`` is a dict {dotted: value}
    (a value of None removes the key) or a list of 'key=value' strings; a number in the key indexes an array of
    tables (``star_sensor.1.fov_deg``)."""
    data = copy.deepcopy(data)
    items = overrides.items() if isinstance(overrides, dict) else (parse_override(o) for o in overrides)
    for key, value in items:
        path = key.split(".") if isinstance(key, str) else list(key)
        node = data
        for part in path[:-1]:
            node = _element(node, part, path, source) if isinstance(node, list) else node.setdefault(part, {})
            if not isinstance(node, (dict, list)):
                raise InputError(f"{source}: {'.'.join(map(str, path))}: {part} is not a table")
        if isinstance(node, list):  # an element of an array of tables replaced whole
            node[_index(node, path[-1], path, source)] = value
        elif value is None:  # the Python API's way to remove an optional key or table
            node.pop(path[-1], None)
        else:
            node[path[-1]] = value
    return data


def _index(array, part, path, source):
    """The index ``part`` (a number: 0 the first) into an array of tables, or an InputError naming the key."""
    try:
        index = int(part)
    except (TypeError, ValueError):
        raise InputError(f"{source}: {'.'.join(map(str, path))}: {part!r} is not an index of the array (0, 1, ...)") from None
    if not 0 <= index < len(array):
        raise InputError(f"{source}: {'.'.join(map(str, path))}: index {index} outside the array of {len(array)}")
    return index


def _element(array, part, path, source):
    """The table at index ``part`` of an array of tables (``star_sensor.1.fov_deg`` names the second head's field)."""
    return array[_index(array, part, path, source)]


def read_scenario_file(path, overrides=()):
    """The raw dictionary of a scenario TOML file with ``overrides`` applied (not yet validated): a
    camera file named in it is taken relative to the scenario file."""
    path = Path(path)
    if not path.exists():
        raise InputError(f"{path}: scenario file not found")
    if path.is_dir():
        raise InputError(f"{path}: is a directory, expected a scenario .toml file")
    try:
        data = tomllib.loads(path.read_text(encoding="utf-8-sig"))  # a byte-order mark is not an error
    except UnicodeDecodeError:
        raise InputError(f"{path}: not a text file (not UTF-8)") from None
    except tomllib.TOMLDecodeError as error:
        raise InputError(f"{path}: invalid TOML: {error}") from None
    except RecursionError:
        raise InputError(f"{path}: invalid TOML: arrays or tables nested too deeply") from None
    data = apply_overrides(data, overrides, str(path))
    sensors = data.get("star_sensor")
    for sensor in sensors if isinstance(sensors, list) else [sensors]:  # a spacecraft's heads, or the one sensor
        image = sensor.get("image") if isinstance(sensor, dict) else None
        if isinstance(image, dict) and isinstance(image.get("camera_file"), str):  # relative to the scenario file
            image["camera_file"] = str(path.parent / image["camera_file"])
    return data


def checked_table(schema, data, source):
    """``data`` checked against ``schema`` (a :class:`~navsim.scenario.schema.Table`), defaults filled;
    an InputError names ``source`` and the key."""
    try:
        return schema.check("", data)
    except InputError as error:
        raise InputError(f"{source}: {error}") from None


def only_chosen(table, where, selector, options, source):
    """No table of an option other than the one ``table[selector]`` chose."""
    for other in options:
        if other != table[selector] and other in table:
            raise InputError(f"{source}: {where}.{other}: given, but {where}.{selector} is {table[selector]!r}")
