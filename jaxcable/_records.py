"""Towing records: measured time series from towing tests, for calibrating drag.

A towing record is a CSV file written in a towing tank or at sea:

```
# jaxcable towing record
# rig = horizontal_tow
# cable_length [m] = 200
# end_mass [kg] = 400
# normal_drag [-] = 1.2
time [s], speed [kn], tension [kN], depth [m]
0.0, 1.944, 5.10, 190.2
0.1, 1.944, 5.12, 190.1
```

**Header.** The leading lines that start with `#` are the header. A header line

- `# key [unit] = value` gives a numeric test condition, converted to SI by `unit`,
  which may be any unit of [`jaxcable.UNITS`][];
- `# key = value` gives a dimensionless number if `value` reads as one, and otherwise
  a string (with its surrounding space stripped), such as the rig's name;
- without `=` is free text, and is ignored.

Keys are Python identifiers (letters, digits and underscores, not starting with a
digit), and each may be given once.

**Columns.** The first line that is neither blank nor a comment names the columns:
`name [unit]`, separated by commas, with space allowed around each part. Every column
needs a unit of its name's dimension in [`jaxcable.COLUMNS`][], each name may appear
once, and the first column must be `time`, followed by at least one other.

**Data.** Each later line holds one sample: as many comma-separated numbers as there
are columns. Every value must be finite (no empty fields, `nan` or `inf`), and time
must strictly increase. Blank lines and lines starting with `#` are skipped. A record
needs at least two samples.

The file is UTF-8 text (a leading byte-order mark is allowed). Units are looked up
exactly as written, case included: `kN` is a kilonewton and `kn` a knot.

Every malformed record raises [`jaxcable.RecordError`][], naming the file, the line,
the column or key and the offending value.
"""

import dataclasses
import math
import numbers
import re
from collections.abc import Iterable, Mapping
from pathlib import Path

import numpy as np

_G0 = 9.80665  # standard gravity (m/s²), exact by definition

UNITS: dict[str, dict[str, float]] = {
    "time": {"s": 1.0, "ms": 1e-3, "min": 60.0, "h": 3600.0},
    "velocity": {
        "m/s": 1.0,
        "cm/s": 1e-2,
        "mm/s": 1e-3,
        "km/h": 1000 / 3600,
        "kn": 1852 / 3600,  # the knot: one international nautical mile (1852 m) per hour
        "ft/s": 0.3048,
    },
    "force": {
        "N": 1.0,
        "kN": 1e3,
        "MN": 1e6,
        "kgf": _G0,
        "tf": 1e3 * _G0,  # tonne-force
        "lbf": 0.45359237 * _G0,  # the international pound is 0.45359237 kg exactly
    },
    "length": {"m": 1.0, "cm": 1e-2, "mm": 1e-3, "km": 1e3, "ft": 0.3048},
    "mass": {"kg": 1.0, "g": 1e-3, "t": 1e3},
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
    },
    # Zhukov's k₀, in the drag law R = k₀ u² m g of a towed body of mass m.
    "specific drag coefficient": {"s²/m²": 1.0, "s^2/m^2": 1.0, "s2/m2": 1.0},
    "dimensionless": {"-": 1.0, "1": 1.0},
}
"""The known units, by dimension: each unit's factor to SI (multiply a value in the unit
by it to get SI). The first unit of each dimension is its SI unit, which
[`jaxcable.write_record`][] uses by default. Every unit belongs to one dimension only.
"""

COLUMNS: dict[str, str] = {
    "time": "time",
    "speed": "velocity",
    "tension": "force",
    "depth": "length",
    "layback": "length",
}
"""The columns a towing record may have, each with its dimension (a key of
[`jaxcable.UNITS`][]). `time` is required, and comes first in a file; a
[`jaxcable.TowingRecord`][] holds it apart from the other columns, as `times`.
"""

# Every unit is in one dimension only (the tests check it), so a unit alone says which.
_BY_UNIT = {unit: (dimension, factor) for dimension, units in UNITS.items() for unit, factor in units.items()}

_CONDITION = re.compile(r"(?P<key>[^\[\]]*?)\s*(?:\[(?P<unit>[^\[\]]*)\])?")
_COLUMN = re.compile(r"(?P<name>[^\[\]]*?)\s*(?:\[(?P<unit>[^\[\]]*)\])?")


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
            f"unit {unit!r} of {subject} is a unit of {entry[0]}, not {dimension}; "
            f"known units of {dimension}: {known}",
        )
    return entry[1]


def to_si(value: float, unit: str, dimension: str | None = None) -> float:
    """Convert `value`, given in `unit`, to SI.

    **Arguments:**

    - `value`: the number, in `unit`.
    - `unit`: a unit of [`jaxcable.UNITS`][], exactly as written there, e.g. `"kn"`.
    - `dimension`: if given, a key of [`jaxcable.UNITS`][] such as `"velocity"`, which
        `unit` must belong to.

    **Returns:**

    `value` in the SI unit of its dimension, as a float.

    **Raises:**

    [`jaxcable.RecordError`][] for an unknown unit or dimension, or a unit of another
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


@dataclasses.dataclass(frozen=True, eq=False)
class TowingRecord:
    """A towing test's measured time series, in SI units, with its test conditions.

    Records compare by identity (`eq=False`): their arrays have no single truth value.

    **Arguments:**

    - `times`: sample times (s), shape `(samples,)`, strictly increasing, at least two.
    - `columns`: every measured column except time, by name (a key of
        [`jaxcable.COLUMNS`][] such as `"speed"`, `"tension"`, `"depth"`), each in SI
        units, shape `(samples,)`. At least one.
    - `conditions`: the test conditions, by identifier: floats in SI units, or strings
        such as the rig's name.
    - `name`: a label; the file's name when read from a file.

    Arrays are stored as read-only float64 copies, and numeric conditions as floats.

    **Raises:**

    [`jaxcable.RecordError`][] for fewer than two samples, times that are not 1-D or do
    not strictly increase, a column of another shape than `times` or with an unknown
    name, no column besides time, a NaN or infinite value, or a condition that is not a
    finite number or a one-line string.
    """

    times: np.ndarray
    columns: dict[str, np.ndarray]
    conditions: dict[str, float | str] = dataclasses.field(default_factory=dict)
    name: str = ""

    def __post_init__(self):
        where = self.name or "towing record"
        times = _float_array(self.times, "times", where)
        if times.ndim != 1:
            raise _error(where, f"times must be 1-D, got shape {times.shape}")
        if times.size < 2:
            raise _error(where, f"a towing record needs at least 2 samples, got {times.size}")
        _check_array_finite(times, "times", where)
        stalled = np.diff(times) <= 0
        if np.any(stalled):
            i = int(np.argmax(stalled)) + 1
            raise _error(
                where,
                f"times must strictly increase, but times[{i}] = {float(times[i])!r} follows "
                f"times[{i - 1}] = {float(times[i - 1])!r}",
            )
        if not isinstance(self.columns, Mapping):
            raise _error(where, f"columns must map column names to arrays, got {type(self.columns).__name__}")
        if not self.columns:
            raise _error(where, "a towing record needs at least one column besides time")
        columns = {}
        for name, values in self.columns.items():
            if name == "time":
                raise _error(where, "'time' is not one of the columns: give the times as `times`")
            if name not in COLUMNS:
                known = ", ".join(column for column in COLUMNS if column != "time")
                raise _error(where, f"unknown column {name!r}; known columns: {known}")
            array = _float_array(values, f"column {name!r}", where)
            if array.shape != times.shape:
                raise _error(
                    where, f"column {name!r} has shape {array.shape}, but times has shape {times.shape}"
                )
            _check_array_finite(array, f"column {name!r}", where)
            columns[name] = array
        conditions = {key: _condition(key, value, where) for key, value in self.conditions.items()}
        object.__setattr__(self, "times", times)
        object.__setattr__(self, "columns", columns)
        object.__setattr__(self, "conditions", conditions)

    @property
    def duration(self) -> float:
        """The time from the first sample to the last (s)."""
        return float(self.times[-1] - self.times[0])


def _read_condition(body: str, conditions: dict, first_lines: dict, number: int, where: str) -> None:
    """Add the condition of a header line (its text after `#`), if it gives one."""
    left, equals, text = body.partition("=")
    if not equals:
        return  # free text
    match = _CONDITION.fullmatch(left.strip())
    if match is None:
        raise _error(where, f"header line {'#' + body!r} must read '# key = value' or '# key [unit] = value'")
    key, unit, text = match["key"], match["unit"], text.strip()
    if not key.isidentifier():
        raise _error(
            where,
            f"condition key {key!r} is not an identifier (letters, digits, underscore); "
            "header lines with '=' give conditions, and free text may not contain '='",
        )
    if key in conditions:
        raise _error(where, f"repeated condition {key!r} (first given on line {first_lines[key]})")
    value = _float_or_none(text)
    if value is None:
        if unit is not None:
            raise _error(where, f"condition {key!r} has unit {unit.strip()!r} but non-numeric value {text!r}")
        if not text:
            raise _error(where, f"condition {key!r} has no value")
        conditions[key] = text
    else:
        _check_finite(value, text, f"condition {key!r}", where)
        if unit is not None:
            value *= _factor(unit.strip(), None, f"condition {key!r}", where)
        conditions[key] = value
    first_lines[key] = number


def _read_columns(line: str, where: str) -> tuple[list[str], list[str], list[float]]:
    """The names, units and SI factors of the columns named in the column header `line`."""
    names, units, factors = [], [], []
    for index, field in enumerate(line.split(","), start=1):
        match = _COLUMN.fullmatch(field.strip())
        if match is None:
            raise _error(where, f"column {index} {field.strip()!r} must read 'name [unit]'")
        name, unit = match["name"], match["unit"]
        if not name:
            raise _error(where, f"column {index} has no name")
        if index == 1 and name != "time":
            raise _error(where, f"the first column must be 'time', got {name!r}")
        if name not in COLUMNS:
            raise _error(where, f"unknown column {name!r}; known columns: {', '.join(COLUMNS)}")
        if name in names:
            raise _error(where, f"duplicate column {name!r}")
        dimension = COLUMNS[name]
        if unit is None:
            example = next(iter(UNITS[dimension]))
            raise _error(
                where, f"column {name!r} has no unit; write it as '{name} [unit]', e.g. '{name} [{example}]'"
            )
        factors.append(_factor(unit.strip(), dimension, f"column {name!r}", where))
        names.append(name)
        units.append(unit.strip())
    if len(names) < 2:
        raise _error(where, "no columns besides time")
    return names, units, factors


def _read_value(field: str, name: str, where: str) -> float:
    text = field.strip()
    if not text:
        raise _error(where, f"column {name!r} is empty")
    value = _float_or_none(text)
    if value is None:
        raise _error(where, f"column {name!r} has non-numeric value {text!r}")
    _check_finite(value, text, f"column {name!r}", where)
    return value


def read_record(path: str | Path) -> TowingRecord:
    """Read a towing record file (the format is described in `jaxcable._records`).

    **Arguments:**

    - `path`: the file.

    **Returns:**

    A [`jaxcable.TowingRecord`][] in SI units, named after the file (e.g. `"tow1.csv"`).

    **Raises:**

    [`jaxcable.RecordError`][], naming the file and line, for a file that is not UTF-8
    text or breaks any rule of the format; `FileNotFoundError` for a missing file.
    """
    path = Path(path)
    try:
        # utf-8-sig: spreadsheets often start their CSV files with a byte-order mark.
        text = path.read_text(encoding="utf-8-sig")
    except UnicodeDecodeError as error:
        raise RecordError(f"{path}: not UTF-8 text ({error.reason} at byte {error.start})") from None
    # One iterator for the header, column header and data, so each loop picks up
    # where the last one stopped.
    lines = ((number, line.strip()) for number, line in enumerate(text.splitlines(), start=1) if line.strip())
    conditions, first_lines = {}, {}
    for number, line in lines:
        if not line.startswith("#"):
            break
        _read_condition(line[1:], conditions, first_lines, number, f"{path}, line {number}")
    else:
        raise RecordError(f"{path}: no column header line, such as 'time [s], speed [m/s]'")
    names, units, factors = _read_columns(line, f"{path}, line {number}")
    rows, previous = [], 0
    for number, line in lines:
        if line.startswith("#"):
            continue
        where = f"{path}, line {number}"
        fields = line.split(",")
        if len(fields) != len(names):
            raise _error(where, f"expected {len(names)} fields ({', '.join(names)}), got {len(fields)}")
        row = [_read_value(field, name, where) for field, name in zip(fields, names)]
        if rows and row[0] <= rows[-1][0]:
            raise _error(
                where,
                f"time {row[0]!r} {units[0]} is not after {rows[-1][0]!r} {units[0]} (line {previous}); "
                "times must strictly increase",
            )
        rows.append(row)
        previous = number
    if len(rows) < 2:
        raise RecordError(f"{path}: a towing record needs at least 2 data rows, got {len(rows)}")
    table = np.asarray(rows) * np.asarray(factors)
    columns = {name: table[:, j] for j, name in enumerate(names[1:], start=1)}
    return TowingRecord(table[:, 0], columns, conditions, name=path.name)


def read_records(paths: Iterable[str | Path]) -> list[TowingRecord]:
    """Read several towing record files, such as the runs of one test to fit jointly.

    **Arguments:**

    - `paths`: the files.

    **Returns:**

    A list of [`jaxcable.TowingRecord`][], in the order of `paths`.

    **Raises:**

    As [`jaxcable.read_record`][]; and `TypeError` for a single path, whose characters
    would otherwise be read as paths.
    """
    if isinstance(paths, (str, Path)):
        raise TypeError("read_records takes a list of paths; for one file use read_record")
    return [read_record(path) for path in paths]


def _number(value: float) -> str:
    # The shortest text that reads back as exactly the same float.
    return repr(float(value))


def write_record(
    path: str | Path,
    record: TowingRecord,
    units: Mapping[str, str] | None = None,
    condition_units: Mapping[str, str] | None = None,
) -> None:
    """Write a towing record file, in the format that [`jaxcable.read_record`][] reads.

    Numbers are written with enough digits to read back as the same floats, so a round
    trip through a file is exact up to the rounding of the unit conversions.

    **Arguments:**

    - `path`: the file to write; an existing file is replaced.
    - `record`: the [`jaxcable.TowingRecord`][] to write.
    - `units`: the unit to write each column in, by column name (including `"time"`),
        e.g. `{"speed": "kn", "tension": "kN"}`. Columns not named are written in SI
        units (s, m/s, N, m).
    - `condition_units`: the unit to write each numeric condition in, by key; any unit
        of [`jaxcable.UNITS`][]. Numeric conditions not named are written without a
        unit, as plain SI numbers; string conditions as `# key = text`.

    **Raises:**

    [`jaxcable.RecordError`][], before anything is written, for a unit that is unknown
    or of the wrong dimension, or one given for a column or numeric condition that the
    record does not have.
    """
    where = str(path)
    units = dict(units or {})
    condition_units = dict(condition_units or {})
    names = ["time", *record.columns]
    for name in units:
        if name not in names:
            raise _error(
                where,
                f"a unit is given for column {name!r}, which the record does not have ({', '.join(names)})",
            )
    for key in condition_units:
        if not isinstance(record.conditions.get(key), float):
            raise _error(
                where,
                f"a unit is given for condition {key!r}, which is not a numeric condition of the record",
            )
    chosen = [units.get(name, next(iter(UNITS[COLUMNS[name]]))) for name in names]
    factors = [_factor(unit, COLUMNS[name], f"column {name!r}", where) for name, unit in zip(names, chosen)]
    lines = ["# jaxcable towing record"]
    for key, value in record.conditions.items():
        if isinstance(value, str):
            lines.append(f"# {key} = {value}")
        elif key in condition_units:
            unit = condition_units[key]
            factor = _factor(unit, None, f"condition {key!r}", where)
            lines.append(f"# {key} [{unit}] = {_number(value / factor)}")
        else:
            lines.append(f"# {key} = {_number(value)}")
    lines.append(", ".join(f"{name} [{unit}]" for name, unit in zip(names, chosen)))
    table = np.column_stack([record.times, *record.columns.values()]) / np.asarray(factors)
    lines.extend(", ".join(map(_number, row)) for row in table)
    Path(path).write_text("\n".join(lines) + "\n", encoding="utf-8")
