"""Towing records: the unit table, the CSV reader and writer, and the checks on
malformed records, in files and built in Python.

Unit factors are checked against their definitions written out here, and the values a
file should give are worked out by hand from its text. Error messages must name the
line, column or key and value: the expected line numbers are counted from the test's
own text. Nothing here touches JAX, so the file runs in about a second.
"""

import dataclasses
import re

import numpy as np
import pytest

from jaxcable.io import (
    COLUMNS,
    CONDITIONS,
    UNITS,
    RecordError,
    TowingRecord,
    read_record,
    read_records,
    to_si,
    write_record,
)

G0 = 9.80665  # standard gravity, m/s², exact by definition
POUND = 0.45359237  # kg, exact by definition
FOOT = 0.3048  # m, exact by definition
KNOT = 1852 / 3600  # one nautical mile (1852 m) per hour, in m/s


def _write(tmp_path, text, name="tow1.csv"):
    path = tmp_path / name
    path.write_text(text, encoding="utf-8")
    return path


# --------------------------------------------------------------------------------------
# Units


@pytest.mark.parametrize(
    "unit, dimension, si",
    [
        ("ms", "time", 1e-3),
        ("min", "time", 60.0),
        ("h", "time", 3600.0),
        ("kn", "velocity", KNOT),
        ("km/h", "velocity", 1000 / 3600),
        ("cm/s", "velocity", 0.01),
        ("ft/s", "velocity", FOOT),
        ("kN", "force", 1000.0),
        ("MN", "force", 1e6),
        ("kgf", "force", G0),
        ("tf", "force", 1000 * G0),
        ("lbf", "force", POUND * G0),
        ("ft", "length", FOOT),
        ("km", "length", 1000.0),
        ("mm", "length", 0.001),
        ("g", "mass", 0.001),
        ("t", "mass", 1000.0),
        ("cm²", "area", 0.01**2),
        ("mm^2", "area", 0.001**2),
        ("L", "volume", 0.1**3),
        ("cm3", "volume", 0.01**3),
        ("s²/m²", "specific drag coefficient", 1.0),
        ("-", "dimensionless", 1.0),
        ("in", "length", FOOT / 12),
        ("fathom", "length", 6 * FOOT),
        ("lb", "mass", POUND),
        ("ft²", "area", FOOT**2),
        ("ft3", "volume", FOOT**3),
        ("kg/m", "mass per length", 1.0),
        ("lb/ft", "mass per length", POUND / FOOT),  # 1.488164 kg/m
        ("kg/m³", "density", 1.0),
        ("g/cm3", "density", 1000.0),
        ("lb/ft^3", "density", POUND / FOOT**3),  # 16.01846 kg/m³
        ("m/s²", "acceleration", 1.0),
        ("ft/s2", "acceleration", FOOT),
        ("N·s", "force × time", 1.0),
        ("kN*s", "force × time", 1000.0),
        ("lbf·s", "force × time", POUND * G0),
        ("N·s/m", "force / velocity", 1.0),
        ("lbf*s/ft", "force / velocity", POUND * G0 / FOOT),
    ],
)
def test_unit_factor_matches_its_definition(unit, dimension, si):
    assert to_si(2.0, unit, dimension) == pytest.approx(2 * si, rel=1e-15)
    assert to_si(2.0, unit) == pytest.approx(2 * si, rel=1e-15)


def test_units_are_unambiguous_and_columns_have_known_dimensions():
    every_unit = [unit for units in UNITS.values() for unit in units]
    assert len(every_unit) == len(set(every_unit))
    assert set(COLUMNS.values()) <= set(UNITS)
    assert list(COLUMNS)[0] == "time"
    assert set(CONDITIONS.values()) <= set(UNITS)


def test_every_rig_argument_has_a_dimension():
    from jaxcable.calibration import RIGS, rig_from_conditions

    for name in RIGS:
        arguments = set(rig_from_conditions({"rig": name}).conditions()) - {"rig"}
        assert arguments <= set(CONDITIONS), f"{name}: {sorted(arguments - set(CONDITIONS))} have no dimension"


def test_spot_values_of_imperial_units():
    # Published values, independent of how the table writes them.
    assert to_si(1.0, "lb/ft") == pytest.approx(1.48816394, rel=1e-8)
    assert to_si(1.0, "lb/ft3") == pytest.approx(16.0184634, rel=1e-8)
    assert to_si(1.0, "lbf") == pytest.approx(4.44822162, rel=1e-8)
    assert to_si(64.0, "lb/ft³") == pytest.approx(1025.18, rel=1e-5)  # sea water


@pytest.mark.parametrize(
    "line, message",
    [
        ("# cable_length [kN] = 200", "condition 'cable_length' is a unit of force, not length"),
        ("# tow_depth [kn] = 5", "condition 'tow_depth' is a unit of velocity, not length"),
        ("# water_density [kg/m] = 1025", "condition 'water_density' is a unit of mass per length, not density"),
        ("# normal_drag [m] = 1.2", "condition 'normal_drag' is a unit of length, not dimensionless"),
        ("# gravity [g] = 9.81", "condition 'gravity' is a unit of mass, not acceleration"),
    ],
)
def test_condition_in_a_unit_of_the_wrong_dimension_is_an_error(tmp_path, line, message):
    text = f"# rig = horizontal_tow\n{line}\ntime [s], speed [kn]\n0, 1\n1, 1\n"
    with pytest.raises(RecordError, match=re.escape(message)) as caught:
        read_record(_write(tmp_path, text))
    assert "tow1.csv, line 2" in str(caught.value)


def test_conditions_in_their_units_read_as_si(tmp_path):
    text = (
        "# rig = horizontal_tow\n"
        "# cable_mass_per_length [lb/ft] = 1\n"
        "# cable_axial_damping [kN·s] = 21\n"
        "# water_density [kg/m³] = 1025\n"
        "# gravity [m/s²] = 9.81\n"
        "# tow_depth [fathom] = 2\n"
        "# my_note [kn] = 3\n"  # a key the table does not know takes any unit
        "time [s], speed [kn]\n0, 1\n1, 1\n"
    )
    conditions = read_record(_write(tmp_path, text)).conditions
    assert conditions["cable_mass_per_length"] == pytest.approx(POUND / FOOT, rel=1e-15)
    assert conditions["cable_axial_damping"] == pytest.approx(21e3, rel=1e-15)
    assert conditions["water_density"] == 1025.0 and conditions["gravity"] == 9.81
    assert conditions["tow_depth"] == pytest.approx(12 * FOOT, rel=1e-15)
    assert conditions["my_note"] == pytest.approx(3 * KNOT, rel=1e-15)
    # The writer's default is the first unit of each dimension, which must be SI.
    assert all(next(iter(units.values())) == 1.0 for units in UNITS.values())


@pytest.mark.parametrize(
    "unit, dimension, message",
    [
        (
            "kph",
            "velocity",
            "unknown unit 'kph' for value 1.0; known units of velocity: m/s, cm/s, mm/s, km/h, kn, ft/s",
        ),
        ("KN", None, "unknown unit 'KN' for value 1.0; known units are time: s, ms, min, h; velocity:"),
        ("kn", "force", "unit 'kn' of value 1.0 is a unit of velocity, not force"),
        ("kn", "speed", "unknown dimension 'speed'; known dimensions: time, velocity, force"),
    ],
)
def test_to_si_rejects_unknown_or_mismatched_units(unit, dimension, message):
    with pytest.raises(RecordError, match=re.escape(message)):
        to_si(1.0, unit, dimension)


# --------------------------------------------------------------------------------------
# Reading and writing

EXAMPLE = """\
# jaxcable towing record
# rig = horizontal_tow
# cable_length [m] = 200
# end_mass [t] = 0.4
# tow_speed [kn] = 2
# normal_drag = 1.2
# Free text without an equals sign is ignored.

 time[s] ,speed [ kn ],  tension [kN], depth [ft]
0.0, 1.944, 5.10, 600

# a comment among the data
0.5, 2.0, 5.12, 601.5
"""


def test_read_well_formed_record(tmp_path):
    record = read_record(_write(tmp_path, EXAMPLE))
    assert record.name == "tow1.csv"
    np.testing.assert_array_equal(record.times, [0.0, 0.5])
    assert list(record.columns) == ["speed", "tension", "depth"]
    np.testing.assert_allclose(record.columns["speed"], [1.944 * KNOT, 2.0 * KNOT], rtol=1e-15)
    np.testing.assert_allclose(record.columns["tension"], [5100.0, 5120.0], rtol=1e-15)
    np.testing.assert_allclose(record.columns["depth"], [600 * FOOT, 601.5 * FOOT], rtol=1e-15)
    assert all(array.dtype == np.float64 for array in [record.times, *record.columns.values()])
    assert record.conditions == {
        "rig": "horizontal_tow",
        "cable_length": 200.0,
        "end_mass": pytest.approx(400.0, rel=1e-15),
        "tow_speed": pytest.approx(2 * KNOT, rel=1e-15),
        "normal_drag": 1.2,
    }
    assert isinstance(record.conditions["normal_drag"], float)
    assert record.duration == 0.5


def test_read_spreadsheet_export_with_byte_order_mark_and_crlf(tmp_path):
    path = tmp_path / "tow1.csv"
    path.write_bytes("time [s], tension [N]\r\n0, 10\r\n1, 11\r\n".encode("utf-8-sig"))
    record = read_record(path)
    np.testing.assert_array_equal(record.times, [0.0, 1.0])
    np.testing.assert_array_equal(record.columns["tension"], [10.0, 11.0])


def test_round_trip_in_other_units_is_exact_to_rounding(tmp_path):
    rng = np.random.default_rng(0)
    times = np.cumsum(rng.uniform(0.01, 0.2, 50))
    columns = {
        "speed": rng.uniform(0.5, 2.0, 50),
        "tension": rng.uniform(1e3, 2e4, 50),
        "depth": rng.uniform(50, 300, 50),
        "layback": rng.uniform(10, 900, 50),
    }
    conditions = {"rig": "horizontal_tow", "cable_length": 304.8, "end_mass": 400.0, "normal_drag": 1.2}
    record = TowingRecord(times, columns, conditions, name="original")
    path = tmp_path / "tow2.csv"
    units = {"time": "ms", "speed": "kn", "tension": "lbf", "depth": "ft", "layback": "km"}
    write_record(path, record, units=units, condition_units={"cable_length": "ft", "end_mass": "t"})

    text = path.read_text(encoding="utf-8")
    assert "time [ms], speed [kn], tension [lbf], depth [ft], layback [km]" in text
    assert "# cable_length [ft] = " in text and "# rig = horizontal_tow" in text
    # The file holds values in the chosen units, not SI: check one against the definition.
    first_row = text.splitlines()[-50].split(", ")
    assert float(first_row[2]) == pytest.approx(columns["tension"][0] / (POUND * G0), rel=1e-15)

    back = read_record(path)
    assert back.name == "tow2.csv"
    np.testing.assert_allclose(back.times, times, rtol=1e-15, atol=0)
    assert list(back.columns) == list(columns)
    for name, values in columns.items():
        np.testing.assert_allclose(back.columns[name], values, rtol=1e-15, atol=0)
    assert back.conditions == {
        "rig": "horizontal_tow",
        "cable_length": pytest.approx(304.8, rel=1e-15),
        "end_mass": pytest.approx(400.0, rel=1e-15),
        "normal_drag": 1.2,  # written without a unit, so exactly
    }


def test_write_defaults_to_si_and_plain_numbers(tmp_path):
    record = TowingRecord([0.0, 0.1], {"speed": [1.0, 1.1], "tension": [5.0, 6.0]}, {"end_mass": 400.0})
    path = tmp_path / "tow3.csv"
    write_record(path, record)
    assert path.read_text(encoding="utf-8").splitlines() == [
        "# jaxcable towing record",
        "# end_mass = 400.0",
        "time [s], speed [m/s], tension [N]",
        "0.0, 1.0, 5.0",
        "0.1, 1.1, 6.0",
    ]


def test_read_records_reads_each_file(tmp_path):
    first = _write(tmp_path, "time [s], speed [m/s]\n0, 1\n1, 2\n", "a.csv")
    second = _write(tmp_path, "time [s], tension [kN]\n0, 1\n2, 2\n", "b.csv")
    records = read_records([first, second])
    assert [record.name for record in records] == ["a.csv", "b.csv"]
    np.testing.assert_array_equal(records[1].columns["tension"], [1000.0, 2000.0])
    with pytest.raises(TypeError, match="list of paths"):
        read_records(str(first))


@pytest.mark.parametrize(
    "units, condition_units, message",
    [
        ({"speed": "kph"}, None, "unknown unit 'kph' for column 'speed'"),
        ({"tension": "m"}, None, "unit 'm' of column 'tension' is a unit of length, not force"),
        ({"depth": "m"}, None, "a unit is given for column 'depth', which the record does not have"),
        (None, {"rig": "m"}, "a unit is given for condition 'rig', which is not a numeric condition"),
        (None, {"end_mass": "stone"}, "unknown unit 'stone' for condition 'end_mass'"),
        (None, {"end_mass": "kN"}, "unit 'kN' of condition 'end_mass' is a unit of force, not mass"),
    ],
)
def test_write_rejects_bad_units_before_writing(tmp_path, units, condition_units, message):
    record = TowingRecord([0.0, 1.0], {"speed": [1.0, 1.0], "tension": [2.0, 2.0]}, {"rig": "a", "end_mass": 1.0})
    path = tmp_path / "out.csv"
    with pytest.raises(RecordError, match=re.escape(message)):
        write_record(path, record, units=units, condition_units=condition_units)
    assert not path.exists()


# --------------------------------------------------------------------------------------
# Malformed files

GOOD = [
    "# jaxcable towing record",  # line 1
    "# rig = horizontal_tow",  # line 2
    "time [s], speed [kn], tension [kN]",  # line 3
    "0.0, 1.9, 5.1",  # line 4
    "0.1, 1.9, 5.2",  # line 5
    "0.2, 1.9, 5.3",  # line 6
]


def _edit(changes):
    """`GOOD` with the lines numbered in `changes` replaced (by `None`: removed)."""
    lines = [changes.get(number, line) for number, line in enumerate(GOOD, start=1)]
    return "\n".join(line for line in lines if line is not None) + "\n"


def test_good_base_file_reads(tmp_path):
    # The malformed cases below are each one edit away from this file.
    assert read_record(_write(tmp_path, _edit({}))).columns["tension"][2] == pytest.approx(5300.0)


@pytest.mark.parametrize(
    "changes, message",
    [
        pytest.param(
            {3: "speed [kn], tension [kN]"}, "line 3: the first column must be 'time', got 'speed'", id="no-time"
        ),
        pytest.param(
            {3: "speed [kn], time [s], tension [kN]"},
            "line 3: the first column must be 'time', got 'speed'",
            id="time-not-first",
        ),
        pytest.param({3: "time [s], speed, tension [kN]"}, "line 3: column 'speed' has no unit", id="no-unit"),
        pytest.param(
            {3: "time [s], speed [kph], tension [kN]"},
            "line 3: unknown unit 'kph' for column 'speed'; known units of velocity: m/s, cm/s, mm/s, km/h, kn, ft/s",
            id="unknown-unit",
        ),
        pytest.param(
            {3: "time [s], speed [kn], tension [m]"},
            "line 3: unit 'm' of column 'tension' is a unit of length, not force",
            id="wrong-dimension",
        ),
        pytest.param(
            {3: "time [m], speed [kn], tension [kN]"},
            "line 3: unit 'm' of column 'time' is a unit of length, not time",
            id="time-wrong-dimension",
        ),
        pytest.param(
            {3: "time [s], speed [KN], tension [kN]"},
            "line 3: unknown unit 'KN' for column 'speed'",
            id="unit-case-matters",
        ),
        pytest.param(
            {3: "time [s], spd [kn], tension [kN]"},
            "line 3: unknown column 'spd'; known columns: time, speed, tow_load, tension, depth, layback",
            id="unknown-column",
        ),
        pytest.param(
            {3: "time [s], speed [kn], speed [m/s]"}, "line 3: duplicate column 'speed'", id="duplicate-column"
        ),
        pytest.param({3: "time [s]", 4: "0.0", 5: "0.1", 6: "0.2"}, "line 3: no columns besides time", id="only-time"),
        pytest.param({3: None, 4: None, 5: None, 6: None}, "tow1.csv: no column header line", id="no-header"),
        pytest.param({5: "0.1, 1.9"}, "line 5: expected 3 fields (time, speed, tension), got 2", id="too-few"),
        pytest.param({5: "0.1, 1.9, 5.2, 7"}, "line 5: expected 3 fields (time, speed, tension), got 4", id="too-many"),
        pytest.param({5: "0.1, fast, 5.2"}, "line 5: column 'speed' has non-numeric value 'fast'", id="non-numeric"),
        pytest.param({5: "0.1, 1.9, NaN"}, "line 5: column 'tension' is NaN", id="NaN"),
        pytest.param({5: "0.1, 1.9, nan"}, "line 5: column 'tension' is NaN", id="nan"),
        pytest.param({5: "0.1, , 5.2"}, "line 5: column 'speed' is empty", id="empty"),
        pytest.param({5: "0.1, 1.9, inf"}, "line 5: column 'tension' is not finite: 'inf'", id="inf"),
        pytest.param({5: "0.1, 1.9, -inf"}, "line 5: column 'tension' is not finite: '-inf'", id="minus-inf"),
        pytest.param({6: "0.2, 1e400, 5.3"}, "line 6: column 'speed' is not finite: '1e400'", id="overflow"),
        pytest.param({5: "0.0, 1.9, 5.2"}, "line 5: time 0.0 s is not after 0.0 s (line 4)", id="time-repeated"),
        pytest.param({6: "0.05, 1.9, 5.3"}, "line 6: time 0.05 s is not after 0.1 s (line 5)", id="time-decreasing"),
        pytest.param({5: None, 6: None}, "tow1.csv: a towing record needs at least 2 data rows, got 1", id="one-row"),
        pytest.param(
            {2: "# rig = a\n# rig = b"}, "line 3: repeated condition 'rig' (first given on line 2)", id="repeated-key"
        ),
        pytest.param(
            {2: "# cable_length [m] = long"},
            "line 2: condition 'cable_length' has unit 'm' but non-numeric value 'long'",
            id="unit-non-numeric",
        ),
        pytest.param(
            {2: "# cable_length [furlong] = 1"},
            "line 2: unknown unit 'furlong' for condition 'cable_length'",
            id="condition-unknown-unit",
        ),
        pytest.param(
            {2: "# cable length = 200"},
            "line 2: condition key 'cable length' is not an identifier",
            id="key-not-identifier",
        ),
        pytest.param({2: "# normal_drag = nan"}, "line 2: condition 'normal_drag' is NaN", id="condition-nan"),
        pytest.param({2: "# rig ="}, "line 2: condition 'rig' has no value", id="condition-empty"),
    ],
)
def test_malformed_file(tmp_path, changes, message):
    path = _write(tmp_path, _edit(changes))
    with pytest.raises(RecordError, match=re.escape(message)):
        read_record(path)


def test_file_that_is_not_utf8(tmp_path):
    path = tmp_path / "tow1.csv"
    path.write_bytes(_edit({}).encode("utf-16"))
    with pytest.raises(RecordError, match=r"tow1\.csv: not UTF-8 text"):
        read_record(path)


def test_missing_file(tmp_path):
    with pytest.raises(FileNotFoundError, match="nowhere.csv"):
        read_record(tmp_path / "nowhere.csv")


# --------------------------------------------------------------------------------------
# Records built in Python


def test_record_holds_read_only_float64_copies():
    speed = np.array([1, 2, 3])
    record = TowingRecord([0, 1, 2], {"speed": speed}, {"end_mass": 400, "rig": "sled"})
    speed[0] = 99
    assert record.columns["speed"][0] == 1.0
    assert record.times.dtype == np.float64 and record.columns["speed"].dtype == np.float64
    assert type(record.conditions["end_mass"]) is float and record.conditions["rig"] == "sled"
    with pytest.raises(ValueError, match="read-only"):
        record.times[0] = 5.0
    with pytest.raises(dataclasses.FrozenInstanceError):
        record.name = "other"
    assert record.duration == 2.0


_TIMES = [0.0, 0.1, 0.2]
_SPEED = [1.0, 1.0, 1.0]


@pytest.mark.parametrize(
    "times, columns, conditions, message",
    [
        pytest.param(_TIMES, {"tension": [1.0, 2.0, np.nan]}, {}, "column 'tension' is NaN at index 2", id="nan"),
        pytest.param(
            _TIMES, {"tension": [1.0, np.inf, 2.0]}, {}, "column 'tension' is not finite (inf) at index 1", id="inf"
        ),
        pytest.param([0.0, np.nan, 0.2], {"speed": _SPEED}, {}, "times is NaN at index 1", id="nan-time"),
        pytest.param(
            [0.0, 0.1, 0.1],
            {"speed": _SPEED},
            {},
            "times must strictly increase, but times[2] = 0.1 follows times[1] = 0.1",
            id="time-repeated",
        ),
        pytest.param(
            [0.0, 0.2, 0.1],
            {"speed": _SPEED},
            {},
            "times must strictly increase, but times[2] = 0.1 follows times[1] = 0.2",
            id="time-decreasing",
        ),
        pytest.param(
            _TIMES, {"speed": [1.0, 1.0]}, {}, "column 'speed' has shape (2,), but times has shape (3,)", id="shape"
        ),
        pytest.param(
            _TIMES,
            {"spd": _SPEED},
            {},
            "unknown column 'spd'; known columns: speed, tow_load, tension, depth",
            id="unknown",
        ),
        pytest.param(_TIMES, {"time": _TIMES}, {}, "'time' is not one of the columns", id="time-column"),
        pytest.param(_TIMES, {}, {}, "a towing record needs at least one column besides time", id="no-columns"),
        pytest.param([0.0], {"speed": [1.0]}, {}, "a towing record needs at least 2 samples, got 1", id="one-sample"),
        pytest.param([[0.0, 1.0]], {"speed": [[1.0, 1.0]]}, {}, "times must be 1-D, got shape (1, 2)", id="2-d"),
        # Strings where numbers belong, on purpose: the record's own error, which a caller
        # who runs no type checker gets, not the checker's.
        pytest.param(
            _TIMES,
            {"speed": ["a", "b", "c"]},
            {},
            "column 'speed' is not an array of numbers",
            id="text",
            marks=pytest.mark.unchecked,
        ),
        pytest.param(
            _TIMES, {"speed": _SPEED}, {"cable length": 1.0}, "condition key 'cable length' is not", id="bad-key"
        ),
        pytest.param(_TIMES, {"speed": _SPEED}, {"mass": np.nan}, "condition 'mass' is NaN", id="condition-nan"),
        pytest.param(
            _TIMES,
            {"speed": _SPEED},
            {"rig": "12"},
            "string condition 'rig' = '12' reads as a number",
            id="string-number",
        ),
        pytest.param(
            _TIMES,
            {"speed": _SPEED},
            {"rig": "a\nb"},
            "string condition 'rig' = 'a\\nb' must be one line",
            id="newline",
        ),
        pytest.param(
            _TIMES, {"speed": _SPEED}, {"on": True}, "condition 'on' must be a number or a string, got bool", id="bool"
        ),
    ],
)
def test_malformed_record_in_python(times, columns, conditions, message):
    with pytest.raises(RecordError, match=re.escape(f"tow7: {message}")):
        TowingRecord(times, columns, conditions, name="tow7")
