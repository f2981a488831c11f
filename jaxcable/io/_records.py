"""Towing records: measured time series from towing tests, for calibrating drag.

A towing record is a CSV file written in a towing tank or at sea:

```
# jaxcable towing record
# rig = horizontal_tow
# cable_length [m] = 200
# end_mass [kg] = 400
# normal_drag [-] = 1.2
time [s], speed [kn], tow_load [kN], depth [m]
0.0, 1.944, 5.10, 190.2
0.1, 1.944, 5.12, 190.1
```

**Header.** The leading lines that start with `#` are the header. A header line

- `# key [unit] = value` gives a numeric test condition, converted to SI by `unit`,
  which must be a unit of [`jaxcable.io.UNITS`][] of the key's dimension in
  [`jaxcable.io.CONDITIONS`][] (`# cable_length [kN] = 200` is an error naming the key
  and the unit); a key not named there may take any known unit;
- `# key = value` gives a dimensionless number if `value` reads as one, and otherwise
  a string (with its surrounding space stripped), such as the rig's name;
- without `=` is free text, and is ignored.

Keys are Python identifiers (letters, digits and underscores, not starting with a
digit), and each may be given once.

**Columns.** The first line that is neither blank nor a comment names the columns:
`name [unit]`, separated by commas, with space allowed around each part. Every column
needs a unit of its name's dimension in [`jaxcable.io.COLUMNS`][], each name may appear
once, and the first column must be `time`, followed by at least one other.
[`jaxcable.io.COLUMNS`][] also says where each is measured: a load cell at the tow
point is `tow_load`; `tension` is a tension inside the cable, as the rig models it.

**Data.** Each later line holds one sample: as many comma-separated numbers as there
are columns. Every value must be finite (no empty fields, `nan` or `inf`), and time
must strictly increase. Blank lines and lines starting with `#` are skipped. A record
needs at least two samples.

The file is UTF-8 text (a leading byte-order mark is allowed). Units are looked up
exactly as written, case included: `kN` is a kilonewton and `kn` a knot.

Every malformed record raises [`jaxcable.io.RecordError`][], naming the file, the line,
the column or key and the offending value.
"""

import re
from collections.abc import Iterable, Mapping
from pathlib import Path

import numpy as np

from .._calibration.records import (
    COLUMNS,
    CONDITIONS,
    UNITS,
    RecordError,
    TowingRecord,
    _check_finite,
    _error,
    _factor,
    _float_or_none,
)

_CONDITION = re.compile(r"(?P<key>[^\[\]]*?)\s*(?:\[(?P<unit>[^\[\]]*)\])?")
_COLUMN = re.compile(r"(?P<name>[^\[\]]*?)\s*(?:\[(?P<unit>[^\[\]]*)\])?")


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
            value *= _factor(unit.strip(), CONDITIONS.get(key), f"condition {key!r}", where)
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
            raise _error(where, f"column {name!r} has no unit; write it as '{name} [unit]', e.g. '{name} [{example}]'")
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
    """Read a towing record file (the format is described in `jaxcable.io._records`).

    **Arguments:**

    - `path`: the file.

    **Returns:**

    A [`jaxcable.io.TowingRecord`][] in SI units, named after the file (e.g. `"tow1.csv"`).

    **Raises:**

    [`jaxcable.io.RecordError`][], naming the file and line, for a file that is not UTF-8
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

    A list of [`jaxcable.io.TowingRecord`][], in the order of `paths`.

    **Raises:**

    As [`jaxcable.io.read_record`][]; and `TypeError` for a single path, whose characters
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
    """Write a towing record file, in the format that [`jaxcable.io.read_record`][] reads.

    Numbers are written with enough digits to read back as the same floats, so a round
    trip through a file is exact up to the rounding of the unit conversions.

    **Arguments:**

    - `path`: the file to write; an existing file is replaced.
    - `record`: the [`jaxcable.io.TowingRecord`][] to write.
    - `units`: the unit to write each column in, by column name (including `"time"`),
        e.g. `{"speed": "kn", "tension": "kN"}`. Columns not named are written in SI
        units (s, m/s, N, m).
    - `condition_units`: the unit to write each numeric condition in, by key; any unit
        of [`jaxcable.io.UNITS`][]. Numeric conditions not named are written without a
        unit, as plain SI numbers; string conditions as `# key = text`.

    **Raises:**

    [`jaxcable.io.RecordError`][], before anything is written, for a unit that is unknown
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
        _factor(condition_units[key], CONDITIONS.get(key), f"condition {key!r}", where)
    chosen = [units.get(name, next(iter(UNITS[COLUMNS[name]]))) for name in names]
    factors = [_factor(unit, COLUMNS[name], f"column {name!r}", where) for name, unit in zip(names, chosen)]
    lines = ["# jaxcable towing record"]
    for key, value in record.conditions.items():
        if isinstance(value, str):
            lines.append(f"# {key} = {value}")
        elif key in condition_units:
            unit = condition_units[key]
            factor = _factor(unit, CONDITIONS.get(key), f"condition {key!r}", where)
            lines.append(f"# {key} [{unit}] = {_number(value / factor)}")
        else:
            lines.append(f"# {key} = {_number(value)}")
    lines.append(", ".join(f"{name} [{unit}]" for name, unit in zip(names, chosen)))
    table = np.column_stack([record.times, *record.columns.values()]) / np.asarray(factors)
    lines.extend(", ".join(map(_number, row)) for row in table)
    Path(path).write_text("\n".join(lines) + "\n", encoding="utf-8")
