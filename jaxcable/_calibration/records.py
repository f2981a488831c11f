"""Towing records: measured time series from towing tests, in SI units, for calibrating
drag; and the units they may be written in.

[`jaxcable.io.TowingRecord`][] holds one test's series and conditions, checked at
construction; [`jaxcable.io.UNITS`][] and [`jaxcable.io.COLUMNS`][] name the units and
the columns a record may have. Reading and writing record files is `jaxcable.io`'s
(`io/_records.py`, which describes the file format).
"""

import dataclasses
import math
import numbers
from collections.abc import Mapping

import numpy as np

from .._typing import RealLike

_G0 = 9.80665  # standard gravity (m/s²), exact by definition
_POUND = 0.45359237  # the international pound (kg), exact by definition
_FOOT = 0.3048  # the international foot (m), exact by definition
_INCH = _FOOT / 12

UNITS: dict[str, dict[str, float]] = {
    "time": {"s": 1.0, "ms": 1e-3, "min": 60.0, "h": 3600.0},
    "velocity": {
        "m/s": 1.0,
        "cm/s": 1e-2,
        "mm/s": 1e-3,
        "km/h": 1000 / 3600,
        "kn": 1852 / 3600,  # the knot: one international nautical mile (1852 m) per hour
        "ft/s": _FOOT,
    },
    "force": {
        "N": 1.0,
        "kN": 1e3,
        "MN": 1e6,
        "kgf": _G0,
        "tf": 1e3 * _G0,  # tonne-force
        "lbf": _POUND * _G0,
    },
    "length": {
        "m": 1.0,
        "cm": 1e-2,
        "mm": 1e-3,
        "km": 1e3,
        "ft": _FOOT,
        "in": _INCH,
        "fathom": 6 * _FOOT,
        "nmi": 1852.0,
    },
    "mass": {"kg": 1.0, "g": 1e-3, "t": 1e3, "lb": _POUND},
    "area": {
        "m²": 1.0,
        "m^2": 1.0,
        "m2": 1.0,
        "cm²": 1e-4,
        "cm^2": 1e-4,
        "cm2": 1e-4,
        "mm²": 1e-6,
        "mm^2": 1e-6,
        "mm2": 1e-6,
        "ft²": _FOOT**2,
        "ft^2": _FOOT**2,
        "ft2": _FOOT**2,
        "in²": _INCH**2,
        "in^2": _INCH**2,
        "in2": _INCH**2,
    },
    "volume": {
        "m³": 1.0,
        "m^3": 1.0,
        "m3": 1.0,
        "l": 1e-3,
        "L": 1e-3,
        "cm³": 1e-6,
        "cm^3": 1e-6,
        "cm3": 1e-6,
        "ft³": _FOOT**3,
        "ft^3": _FOOT**3,
        "ft3": _FOOT**3,
    },
    "mass per length": {"kg/m": 1.0, "g/m": 1e-3, "kg/km": 1e-3, "lb/ft": _POUND / _FOOT},
    "density": {
        "kg/m³": 1.0,
        "kg/m^3": 1.0,
        "kg/m3": 1.0,
        "t/m³": 1e3,
        "t/m^3": 1e3,
        "t/m3": 1e3,
        "g/cm³": 1e3,
        "g/cm^3": 1e3,
        "g/cm3": 1e3,
        "lb/ft³": _POUND / _FOOT**3,
        "lb/ft^3": _POUND / _FOOT**3,
        "lb/ft3": _POUND / _FOOT**3,
    },
    "acceleration": {
        "m/s²": 1.0,
        "m/s^2": 1.0,
        "m/s2": 1.0,
        "ft/s²": _FOOT,
        "ft/s^2": _FOOT,
        "ft/s2": _FOOT,
    },
    # An axial damping C_v, in T = EA ε + C_v ε̇: a force times a time.
    "force × time": {
        "N·s": 1.0,
        "N*s": 1.0,
        "kN·s": 1e3,
        "kN*s": 1e3,
        "lbf·s": _POUND * _G0,
        "lbf*s": _POUND * _G0,
    },
    # A linear damping coefficient: force per velocity.
    "force / velocity": {
        "N·s/m": 1.0,
        "N*s/m": 1.0,
        "kN·s/m": 1e3,
        "kN*s/m": 1e3,
        "lbf·s/ft": _POUND * _G0 / _FOOT,
        "lbf*s/ft": _POUND * _G0 / _FOOT,
    },
    # Zhukov's k₀, in the drag law R = k₀ u² m g of a towed body of mass m.
    "specific drag coefficient": {"s²/m²": 1.0, "s^2/m^2": 1.0, "s2/m2": 1.0},
    "dimensionless": {"-": 1.0, "1": 1.0},
}
"""The known units, by dimension: each unit's factor to SI (multiply a value in the unit
by it to get SI). The first unit of each dimension is its SI unit, which
[`jaxcable.io.write_record`][] uses by default. Every unit belongs to one dimension only.
"""

COLUMNS: dict[str, str] = {
    "time": "time",
    "speed": "velocity",
    "tow_load": "force",
    "tension": "force",
    "depth": "length",
    "layback": "length",
}
"""The columns a towing record may have, each with its dimension (a key of
[`jaxcable.io.UNITS`][]). `time` is required, and comes first in a file; a
[`jaxcable.io.TowingRecord`][] holds it apart from the other columns, as `times`.

Where each is measured (the rigs' docstrings say how they model it):

- `speed`: the tow speed, an input of a horizontal tow; the rise speed of the towed
  element in a vertical tow.
- `tow_load`: the load at the tow point, what a load cell between the towing vessel
  and the cable reads.
- `tension`: a cable tension inside the rig: for a horizontal tow the first segment's,
  half a segment below the tow point, so a load cell's record is `tow_load`, not
  `tension`; for a vertical tow the tether's at its lowest segment.
- `depth`: the end body's depth below the still-water level.
- `layback`: the end body's horizontal distance aft of the tow point.
"""

CONDITIONS: dict[str, str] = {
    # The rigs' arguments (`jaxcable.calibration.HorizontalTow`, `VerticalTow`).
    "cable_length": "length",
    "cable_diameter": "length",
    "cable_mass_per_length": "mass per length",
    "cable_axial_stiffness": "force",
    "cable_axial_damping": "force × time",
    "normal_drag": "dimensionless",
    "tangential_drag": "dimensionless",
    "cable_added_mass": "dimensionless",
    "end_mass": "mass",
    "end_volume": "volume",
    "end_drag_area": "area",
    "end_added_mass": "dimensionless",
    "tow_depth": "length",
    "leader_lift": "force",
    "leader_mass": "mass",
    "leader_drag_area": "area",
    "leader_added_mass": "dimensionless",
    "element_mass": "mass",
    "element_volume": "volume",
    "organism_mass": "mass",
    "specific_drag": "specific drag coefficient",
    "element_drag_area": "area",
    "element_added_mass": "dimensionless",
    "tether_length": "length",
    "tether_diameter": "length",
    "tether_mass_per_length": "mass per length",
    "tether_axial_stiffness": "force",
    "tether_axial_damping": "force × time",
    "tether_normal_drag": "dimensionless",
    "tether_tangential_drag": "dimensionless",
    "start_depth": "length",
    "water_density": "density",
    "gravity": "acceleration",
    "segments": "dimensionless",
    # Common test conditions that no rig takes.
    "tow_speed": "velocity",
    "water_depth": "length",
    "duration": "time",
}
"""The dimension of each known condition key (a key of [`jaxcable.io.UNITS`][]): a
condition given in a file with a unit must be given in a unit of its key's dimension.
It names every argument of the towing rigs. Keys not named here may be given in any
known unit; the rigs reject them when they build from a header.
"""

# Every unit is in one dimension only (the tests check it), so a unit alone says which.
_BY_UNIT = {unit: (dimension, factor) for dimension, units in UNITS.items() for unit, factor in units.items()}


class RecordError(ValueError):
    """A malformed towing record, in a file or built in Python."""


def _error(where: str, message: str) -> RecordError:
    return RecordError(f"{where}: {message}" if where else message)


def _factor(unit: str, dimension: str | None, subject: str, where: str = "") -> float:
    """The SI factor of `unit`, which must be of `dimension` unless that is `None`."""
    entry = _BY_UNIT.get(unit)
    if dimension is None:
        if entry is None:
            known = "; ".join(f"{dim}: {', '.join(units)}" for dim, units in UNITS.items())
            raise _error(where, f"unknown unit {unit!r} for {subject}; known units are {known}")
        return entry[1]
    known = ", ".join(UNITS[dimension])
    if entry is None:
        raise _error(where, f"unknown unit {unit!r} for {subject}; known units of {dimension}: {known}")
    if entry[0] != dimension:
        raise _error(
            where,
            f"unit {unit!r} of {subject} is a unit of {entry[0]}, not {dimension}; known units of {dimension}: {known}",
        )
    return entry[1]


def to_si(value: float, unit: str, dimension: str | None = None) -> float:
    """Convert `value`, given in `unit`, to SI.

    **Arguments:**

    - `value`: the number, in `unit`.
    - `unit`: a unit of [`jaxcable.io.UNITS`][], exactly as written there, e.g. `"kn"`.
    - `dimension`: if given, a key of [`jaxcable.io.UNITS`][] such as `"velocity"`, which
        `unit` must belong to.

    **Returns:**

    `value` in the SI unit of its dimension, as a float.

    **Raises:**

    [`jaxcable.io.RecordError`][] for an unknown unit or dimension, or a unit of another
    dimension.
    """
    if dimension is not None and dimension not in UNITS:
        raise RecordError(f"unknown dimension {dimension!r}; known dimensions: {', '.join(UNITS)}")
    return float(value) * _factor(unit, dimension, f"value {value!r}")


def _float_or_none(text: str) -> float | None:
    try:
        return float(text)
    except ValueError:
        return None


def _check_finite(value: float, text: str, subject: str, where: str) -> None:
    if math.isnan(value):
        raise _error(where, f"{subject} is NaN")
    if math.isinf(value):
        raise _error(where, f"{subject} is not finite: {text!r}")


def _float_array(values, subject: str, where: str) -> np.ndarray:
    try:
        array = np.array(values, dtype=np.float64)
    except (TypeError, ValueError):
        raise _error(where, f"{subject} is not an array of numbers") from None
    # The record is frozen: it owns a read-only copy, shared with no caller.
    array.flags.writeable = False
    return array


def _check_array_finite(array: np.ndarray, subject: str, where: str) -> None:
    bad = ~np.isfinite(array)
    if np.any(bad):
        index = int(np.argmax(bad))
        value = float(array[index])
        state = "NaN" if math.isnan(value) else f"not finite ({value})"
        raise _error(where, f"{subject} is {state} at index {index}")


def _condition(key, value, where: str) -> float | str:
    """A condition's value as a record holds it: a finite float, or a string that a file
    can carry and that reads back as the same string."""
    if not isinstance(key, str) or not key.isidentifier():
        raise _error(where, f"condition key {key!r} is not an identifier (letters, digits, underscore)")
    if isinstance(value, str):
        if not value or value != value.strip() or len(value.splitlines()) != 1:
            raise _error(
                where,
                f"string condition {key!r} = {value!r} must be one line of text without surrounding space",
            )
        if _float_or_none(value) is not None:
            raise _error(where, f"string condition {key!r} = {value!r} reads as a number; give it as a float")
        return value
    if isinstance(value, numbers.Real) and not isinstance(value, bool):
        number = float(value)
        _check_finite(number, repr(value), f"condition {key!r}", where)
        return number
    raise _error(where, f"condition {key!r} must be a number or a string, got {type(value).__name__}")


@dataclasses.dataclass(frozen=True, eq=False, init=False)
class TowingRecord:
    """A towing test's measured time series, in SI units, with its test conditions.

    Records compare by identity (`eq=False`): their arrays have no single truth value.

    **Arguments:**

    - `times`: sample times (s), shape `(samples,)`, strictly increasing, at least two:
        an array, or a list or tuple of numbers.
    - `columns`: every measured column except time, by name (a key of
        [`jaxcable.io.COLUMNS`][] such as `"speed"`, `"tension"`, `"depth"`), each in SI
        units, shape `(samples,)`, as an array or a list or tuple of numbers. At least one.
    - `conditions`: the test conditions, by identifier: numbers in SI units, or strings
        such as the rig's name.
    - `name`: a label; the file's name when read from a file.

    Arrays are stored as read-only float64 copies, and numeric conditions as floats.

    **Raises:**

    [`jaxcable.io.RecordError`][] for fewer than two samples, times that are not 1-D or do
    not strictly increase, a column of another shape than `times` or with an unknown
    name, no column besides time, a NaN or infinite value, or a condition that is not a
    finite number or a one-line string.
    """

    times: np.ndarray
    columns: dict[str, np.ndarray]
    conditions: dict[str, float | str]
    name: str

    # The fields hold what the record made of its arguments (float64 arrays, float
    # conditions); the arguments are what a caller may give, so the dataclass's own
    # `__init__`, which would take the fields' types, is replaced by this one.
    def __init__(
        self,
        times: RealLike,
        columns: Mapping[str, RealLike],
        conditions: Mapping[str, float | np.floating | np.integer | str] | None = None,
        name: str = "",
    ):
        where = name or "towing record"
        times_array = _float_array(times, "times", where)
        if times_array.ndim != 1:
            raise _error(where, f"times must be 1-D, got shape {times_array.shape}")
        if times_array.size < 2:
            raise _error(where, f"a towing record needs at least 2 samples, got {times_array.size}")
        _check_array_finite(times_array, "times", where)
        stalled = np.diff(times_array) <= 0
        if np.any(stalled):
            i = int(np.argmax(stalled)) + 1
            raise _error(
                where,
                f"times must strictly increase, but times[{i}] = {float(times_array[i])!r} follows "
                f"times[{i - 1}] = {float(times_array[i - 1])!r}",
            )
        if not isinstance(columns, Mapping):
            raise _error(where, f"columns must map column names to arrays, got {type(columns).__name__}")
        if not columns:
            raise _error(where, "a towing record needs at least one column besides time")
        column_arrays = {}
        for column, values in columns.items():
            if column == "time":
                raise _error(where, "'time' is not one of the columns: give the times as `times`")
            if column not in COLUMNS:
                known = ", ".join(known_column for known_column in COLUMNS if known_column != "time")
                raise _error(where, f"unknown column {column!r}; known columns: {known}")
            array = _float_array(values, f"column {column!r}", where)
            if array.shape != times_array.shape:
                raise _error(
                    where, f"column {column!r} has shape {array.shape}, but times has shape {times_array.shape}"
                )
            _check_array_finite(array, f"column {column!r}", where)
            column_arrays[column] = array
        checked = {key: _condition(key, value, where) for key, value in (conditions or {}).items()}
        object.__setattr__(self, "times", times_array)
        object.__setattr__(self, "columns", column_arrays)
        object.__setattr__(self, "conditions", checked)
        object.__setattr__(self, "name", name)

    @property
    def duration(self) -> float:
        """The time from the first sample to the last (s)."""
        return float(self.times[-1] - self.times[0])
