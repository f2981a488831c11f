"""A catalogue of bad input, each refused before any work with a message that names the
field, key or flag and the value (or warned of, where the input is legal but likely a
mistake): scene files, MoorDyn files, towing records, motion tables, command-line flags
and the Python API.

Each case must end within seconds and write nothing but its message: the command-line
cases run in an empty folder that must stay empty, and every case is timed. Checks on
the readers' own syntax (a missing key, a non-numeric field, ...) live in
`test_readers.py` and `test_records.py`; here are the values that read well but cannot
be run.
"""

import re
import subprocess
import sys
import time
import warnings
from pathlib import Path

import diffrax
import equinox as eqx
import helpers
import jax
import numpy as np
import pytest

import jaxcable as jc
from jaxcable._cli import main
from jaxcable.io import SceneError
from jaxcable.io._run import check_size, run_scene

SECONDS = 20.0  # what "within seconds" means here, with a loaded 2-core machine's margin

# --------------------------------------------------------------------------------------
# Inputs, each one edit away from one that runs.

# The readers' small scene, on a seabed: an anchor at z = −100 m in 150 m of water, a
# rope of 190 m in 10 segments to a coupled float at (150, 0, 0).
SCENE = helpers.SCENE + "\n[seabed]\n"

MOORDYN = """\
--------------------- MoorDyn Input File ------------------------
bad input
---------------------- LINE TYPES ----------------------
TypeName   Diam    Mass/m   EA       BA/-zeta  EI       Cd     Ca     CdAx   CaAx
(name)     (m)     (kg/m)   (N)      (N-s/-)   (N-m^2)  (-)    (-)    (-)    (-)
chain      0.1     20.0     1.0e9    -0.5      0        1.2    1.0    0.05   0.0
---------------------- POINTS ----------------------
ID   Type      X       Y      Z       Mass    Volume   CdA    Ca
(#)  (-)       (m)     (m)    (m)     (kg)    (m^3)    (m^2)  (-)
1    Fixed     0.0     0.0    -100.0  0       0        0      0
2    Vessel    200.0   0.0    0.0     0       0        0      0
---------------------- LINES ----------------------
ID   LineType  AttachA  AttachB  UnstrLen  NumSegs  LineOutputs
(#)  (name)    (#)      (#)      (m)       (-)      (-)
1    chain     1        2        250.0     10       -
---------------------- OPTIONS ----------------------
1025.0   WtrDnsty
150.0    WtrDpth
0.5      dtOut
--------------------- need this line ------------------------
"""

# A table that steps 0 → 100 m along x in one interval: the natural spline overshoots.
STEP_TABLE = "time x y z\n" + "".join(
    f"{t:g} {150.0 + x:g} 0 0\n" for t, x in zip(range(6), (0.0, 0.0, 0.0, 100.0, 100.0, 100.0))
)
RECORD = "# rig = horizontal_tow\ntime [s], speed [kn], tension [kN]\n0.0, 1.9, 5.1\n0.1, 1.9, 5.2\n0.2, 1.9, 5.3\n"


def edited(old: str, new: str, text: str = SCENE) -> str:
    assert text.count(old) == 1, old
    return text.replace(old, new)


WAVE = '\n[[waves]]\ntheory = "airy"\nperiod = 5.6\n'
TABLE_MOTION = 'motion = { type = "table", file = "step.txt"'

# --------------------------------------------------------------------------------------
# The command line, in process: exit status 2, one line on stderr naming the flag, key
# or field, no traceback, nothing written.


@pytest.fixture
def cli(tmp_path, monkeypatch, capsys):
    """Run `jaxcable ARGS` in process in `tmp_path`, with the given input files written
    there first; returns `(status, stdout, stderr)` after checking that the command
    wrote no file and took seconds at most."""
    monkeypatch.chdir(tmp_path)
    monkeypatch.setenv("JAXCABLE_CACHE_DIR", "")  # the command would point JAX's cache at ~/.cache
    monkeypatch.setenv("XLA_FLAGS", "")

    def run(args, files=()):
        for name, text in dict(files).items():
            (tmp_path / name).write_text(text)
        before = sorted(tmp_path.rglob("*"))
        start = time.perf_counter()
        status = main([str(a) for a in args])
        elapsed = time.perf_counter() - start
        out, err = capsys.readouterr()
        assert sorted(tmp_path.rglob("*")) == before, "the command wrote a file"
        assert elapsed < SECONDS, f"took {elapsed:.1f} s"
        assert "Traceback" not in err
        return status, out, err

    return run


def error_line(err: str) -> str:
    """The one error line a refused command prints."""
    lines = [line for line in err.splitlines() if line.startswith("jaxcable: error:")]
    assert len(lines) == 1, err
    return lines[0]


CLI_CASES = [
    # Numbers out of range, by flag.
    (["run", "anchored_line", "--dt-out", "0"], r"--dt-out must be a positive number of seconds, got 0$"),
    (["run", "anchored_line", "--dt-out", "-0.1"], r"--dt-out must be a positive number of seconds, got -0.1$"),
    (["run", "anchored_line", "--dt-out", "nan"], r"--dt-out must be a positive number of seconds, got nan$"),
    (["run", "anchored_line", "--duration", "-1"], r"--duration must be a non-negative number of seconds, got -1$"),
    (["run", "anchored_line", "--duration", "inf"], r"--duration must be a non-negative number of seconds, got inf$"),
    (["info", "anchored_line", "--duration", "-5"], r"--duration must be a non-negative number of seconds, got -5$"),
    (["run", "anchored_line", "--segments", "0"], r"--segments must be a positive integer, got 0$"),
    (["info", "anchored_line", "--segments", "-3"], r"--segments must be a positive integer, got -3$"),
    # Too large to fit in memory, refused before statics.
    (["run", "anchored_line", "--segments", "1000000"], r"1,000,000 segments .* need about [\d,.]+ GiB .*--segments"),
    (["info", "anchored_line", "--segments", "1000000"], r"1,000,000 segments .* more than this machine's"),
    (["run", "anchored_line", "--duration", "1e9"], r"over 1e\+09 s need about .* output times every 0.05 s"),
    # Output and plot files that could not be written at the end.
    (["run", "anchored_line", "--out", "missing/run.csv"], r"--out missing/run.csv: the folder missing does not exist"),
    (["run", "anchored_line", "--out", "."], r"--out \.: is a folder"),
    (["run", "anchored_line", "--out", "run.xlsx"], r"--out run.xlsx: unknown format '.xlsx'; use one of .*'.csv'"),
    (["run", "anchored_line", "--out", "run"], r"--out run: unknown format '\(no suffix\)'"),
    (["run", "anchored_line", "--plot", "x.foo"], r"--plot x.foo: unknown format '.foo'; use one of .*'.png'"),
    (["run", "anchored_line", "--plot", "missing/x.png"], r"--plot missing/x.png: the folder missing does not exist"),
    (["run", "anchored_line", "--plot", "."], r"--plot \.: is a folder"),
    # Inputs that are not there, or not files.
    (["run", "."], r"cannot read \.: Is a directory"),
    (["run", "nowhere.toml"], r"cannot read nowhere.toml: No such file or directory"),
    (["run", "anchored_line", "--motion", "."], r"cannot read motion file \.: Is a directory"),
    # Calibration: records and flags.
    (["calibrate", "nowhere.csv", "--fit", "normal_drag=1.2"], r"cannot read nowhere.csv: No such file"),
    (["calibrate", ".", "--fit", "normal_drag=1.2"], r"cannot read \.: Is a directory"),
    (["calibrate", "r.csv", "--fit", "normal_drag=1.2", "--out", "."], r"--out \.: is a folder"),
    (["calibrate", "r.csv", "--fit", "normal_drag=1.2", "--out", "no/fit.json"], r"--out no/fit.json: the folder no"),
    (["calibrate", "r.csv", "--fit", "normal_drag=1.2", "--plot", "fit.foo"], r"--plot fit.foo: unknown format"),
    (["calibrate", "r.csv", "--fit", "normal_drag=1.2", "--max-steps", "0"], r"--max-steps must be a positive integer"),
    (
        ["calibrate", "r.csv", "--fit", "normal_drag=1.2", "--learning-rate", "0"],
        r"--learning-rate must be a positive number, got 0",
    ),
    (["calibrate", "r.csv", "--fit", "normal_drag=1.2", "--rtol", "-1"], r"--rtol must be a positive number, got -1"),
    # A tolerance float64 cannot meet: the step would shrink without end.
    (["run", "anchored_line", "--adaptive", "--rtol", "1e-300"], r"--rtol must be at least 1e-13, .* got 1e-300$"),
    (["calibrate", "r.csv", "--fit", "normal_drag=1.2", "--rtol", "1e-300"], r"--rtol must be at least 1e-13"),
    (["calibrate", "r.csv", "--fit", "normal_drag=1.2", "--atol", "nan"], r"--atol must be a positive number, got nan"),
    # A ramp: a non-negative time, and only for a motion table.
    (["run", "anchored_line", "--ramp", "-1"], r"--ramp must be a non-negative number of seconds, got -1$"),
    (["run", "anchored_line", "--ramp", "5"], r"--ramp switches a --motion table on smoothly: give the table"),
    # A tolerance so loose that the steps' error is the solution's size.
    (["run", "anchored_line", "--adaptive", "--rtol", "5"], r"--rtol must be at most 0.1: .* got 5$"),
    # An output onto an input or onto the other output: the run would overwrite it.
    (
        ["run", "line.txt", "--out", "line.txt"],
        r"--out line.txt is the input file \(line.txt\): the run would overwrite",
    ),
    (["run", "anchored_line", "--motion", "t.csv", "--out", "t.csv"], r"--out t.csv is --motion \(t.csv\)"),
    (["run", "anchored_line", "--out", "x.png", "--plot", "x.png"], r"--plot x.png is --out \(x.png\)"),
    (["calibrate", "r.csv", "--fit", "normal_drag=1.2", "--out", "r.csv"], r"--out r.csv is a towing record"),
]


@pytest.mark.parametrize("args, message", CLI_CASES, ids=lambda x: " ".join(x) if isinstance(x, list) else None)
def test_cli_refuses_before_any_work(cli, args, message):
    status, _, err = cli(args, {"r.csv": RECORD})
    assert status == 2
    assert re.search(message, error_line(err)), err


# Towing records and motion tables (their readers' own tests are `test_records.py` and
# `test_readers.py`): (the file's text, the command, the error's words).
RECORD_HEAD = "# rig = horizontal_tow\ntime [s], speed [kn], tension [kN]\n"
FILE_CASES = [
    (
        RECORD_HEAD + "0.0, 1.9, 5.1\n0.1, 1.9, nan\n0.2, 1.9, 5.3\n",
        "calibrate",
        r"f, line 4: column 'tension' is NaN$",
    ),
    (
        RECORD_HEAD + "0.0, 1.9, 5.1\n0.2, 1.9, 5.2\n0.1, 1.9, 5.3\n",
        "calibrate",
        r"f, line 5: time 0.1 s is not after 0.2 s \(line 4\); times must strictly increase$",
    ),
    ("time x y z\n0 0 0 0\n1 0 0 0\n1 1 0 0\n2 0 0 0\n", "run", r"f, line 4: the time column must increase"),
    ("time x y z\n0 0 0 0\n1 nan 0 0\n2 0 0 0\n", "run", r"f, line 3: non-finite value$"),
    ("time x y\n0 0 0\n1 0 0\n", "run", r"f, line 2: expected 4 columns \(time, then x y z .*\), got 3$"),
]


@pytest.mark.parametrize("text, command, message", FILE_CASES)
def test_records_and_motion_tables_are_refused_by_line(cli, text, command, message):
    args = ["calibrate", "f", "--fit", "normal_drag=1.2"] if command == "calibrate" else ["run", "anchored_line"]
    status, _, err = cli(args + ([] if command == "calibrate" else ["--motion", "f"]), {"f": text})
    assert status == 2
    assert re.search(message, error_line(err)), err


# Scene files: (edit of SCENE, the error's words). Read, and for values that only
# the engine can judge, built, as `jaxcable info` does.
SCENE_CASES = [
    (edited("depth = 150.0", "depth = 90.0"), r"fixed point anchor at z = -100 m is below the seabed at z = -90 m"),
    (
        edited("position = [150.0, 0.0, 0.0]", "position = [150.0, 0.0, -151.0]"),
        r"coupled point float at z = -151 m is below the seabed at z = -150 m \(\[water\] depth = 150 m\)",
    ),
    (edited("dt_out = 0.5", "dt_out = 0.5\nrtol = 1e-300"), r"simulation.*SolverConfig.rtol must be at least 1e-13"),
    (edited("dt_out = 0.5", "dt_out = 0.0"), r"simulation.dt_out.*must be positive, got 0"),
    (SCENE + WAVE + "height = 60.0\n", r"waves\[0\].*Airy.height must be at most the breaking height 6.9\d+ m, got 60"),
    (SCENE + WAVE + "steepness = 0.2\n", r"waves\[0\].*Airy.height must be at most the breaking height"),
    (
        SCENE + WAVE.replace("5.6", "12.0") + "height = 118.0\n",
        r"H/d = 0.787 against McCowan's 0.78",
    ),
    (
        edited("axial_stiffness = 3.0e7", "axial_stiffness = 3.0e7\nquadratic_stiffness = -3.0e8"),
        r"line_types.rope.*quadratic_stiffness C_E1 = -3e\+08 N with C_E = 3e\+07 N makes the tension fall beyond "
        r"ε = 0.05 and turn negative beyond ε = 0.1",
    ),
    (
        edited("axial_stiffness = 3.0e7", "axial_stiffness = -3.0e7"),
        r"line_types.rope: LineType.tension_law.axial_stiffness must be positive, got -30000000.0",
    ),
    (
        edited('type = "coupled"', f'type = "coupled"\n{TABLE_MOTION}, interpolation = "spline" }}'),
        r"points.float.motion.interpolation.*Sampled.interpolation must be one of \('cubic', 'pchip', 'linear'\)",
    ),
    (
        edited('type = "coupled"', f'type = "coupled"\n{TABLE_MOTION.replace("step", "gone")} }}'),
        r"points.float.motion.file: cannot read motion file .*gone.txt: No such file",
    ),
]


@pytest.mark.parametrize("text, message", SCENE_CASES)
def test_scene_file_values_are_refused_by_key(tmp_path, text, message):
    (tmp_path / "scene.toml").write_text(text)
    (tmp_path / "step.txt").write_text(STEP_TABLE)
    start = time.perf_counter()
    with pytest.raises(SceneError, match=message) as error:
        jc.read_scene(tmp_path / "scene.toml").build()
    assert time.perf_counter() - start < SECONDS
    assert str(tmp_path / "scene.toml") in str(error.value)


def test_scene_file_segment_count_that_cannot_fit_is_refused_before_statics(cli):
    # Outputs every millisecond make the estimate terabytes, beyond any machine's memory;
    # the statics alone (about 20 GB) would fit some, and the run would go on.
    scene = edited("segments = 10", "segments = 1000000")
    status, _, err = cli(["run", "scene.toml", "--dt-out", "0.001"], {"scene.toml": scene})
    assert status == 2
    assert re.search(r"scene.toml: 1,000,000 segments .* more than this machine's .* GiB: use fewer", error_line(err))


# MoorDyn files: (row replaced, its replacement, the error's words).
MOORDYN_CASES = [
    (
        "1.0e9    -0.5",
        "-1.0e9   -0.5",
        r"line 6: LineType.tension_law.axial_stiffness must be positive, got -1000000000.0",
    ),
    ("0.1     20.0", "0.0     20.0", r"LineType.diameter must be positive, got 0"),
    ("0.1     20.0", "0.1     -20.0", r"LineType.mass_per_length must be positive, got -20"),
    ("1.2    1.0    0.05", "-1.2   1.0    0.05", r"LineType.normal_drag must be non-negative, got -1.2"),
    ("1.2    1.0    0.05", "1.2    -1.0   0.05", r"LineType.normal_added_mass must be non-negative, got -1"),
    ("0.5      dtOut", "-0.5     dtOut", r"dtOut must be positive \(or 0, MoorDyn's every step\)"),
    ("150.0    WtrDpth", "-150.0   WtrDpth", r"WtrDpth must be positive"),
    ("1025.0   WtrDnsty", "0   WtrDnsty", r"WtrDnsty must be positive"),
    # Degenerate geometry, named before statics: a 1 mm line over a 224 m chord, and a
    # line whose ends are one point.
    ("250.0     10 ", "0.001     10 ", r"line 1 must stretch 2.24e\+07 % to reach from point 1 to point 2"),
    (
        "Vessel    200.0   0.0    0.0 ",
        "Vessel    0.0     0.0    -100.0",
        r"both ends of line 1 are at \[0.0, 0.0, -100.0\]",
    ),
]


@pytest.mark.parametrize("old, new, message", MOORDYN_CASES)
def test_moordyn_values_are_refused_by_column(tmp_path, old, new, message):
    path = tmp_path / "system.txt"
    path.write_text(edited(old, new, MOORDYN))
    start = time.perf_counter()
    with pytest.raises(SceneError, match=message) as error:
        jc.read_moordyn(path).build()
    assert time.perf_counter() - start < SECONDS
    assert str(path) in str(error.value)


def test_moordyn_segment_count_that_cannot_fit_is_refused_before_statics(cli):
    text = edited("250.0     10 ", "250.0     1000000 ", MOORDYN)
    status, _, err = cli(["info", "system.txt"], {"system.txt": text})
    assert status == 2
    assert "1,000,000 segments" in error_line(err) and "GiB" in error_line(err)


# --------------------------------------------------------------------------------------
# Motion tables on the command line. `--channels Nope` stops each run after the scene's
# notes and the motion's warnings are printed and before statics, so nothing runs.


def test_motion_table_that_makes_the_spline_overshoot_is_warned_of(cli):
    status, _, err = cli(
        ["run", "anchored_line", "--motion", "step.txt", "--channels", "Nope"], {"step.txt": STEP_TABLE}
    )
    assert status == 2 and "unknown output channel 'Nope'" in error_line(err)
    (warning,) = [line for line in err.splitlines() if line.startswith("warning:") and "strays" in line]
    assert re.search(r"warning: --motion step.txt: .*strays from .* m in x between t = 1 and 2 s", warning)
    assert "interpolation='pchip'" in warning


MOVING_TABLE = "time x y z\n" + "".join(
    f"{t:g} {346.4101615137755 + 2.0 * np.sin(2 * np.pi * t / 5.6):.9g} 0 0\n" for t in np.arange(0.0, 10.01, 0.1)
)


@pytest.mark.parametrize("ramp", [None, "3"])
def test_motion_table_that_starts_moving_is_warned_of_unless_ramped(cli, ramp):
    """A table that starts at 2.2 m/s would jolt the line at t = 0: a warning says so
    and offers --ramp; with --ramp there is none."""
    args = ["run", "anchored_line", "--motion", "moving.txt", "--channels", "Nope"]
    status, _, err = cli(args + (["--ramp", ramp] if ramp else []), {"moving.txt": MOVING_TABLE})
    assert status == 2 and "unknown output channel 'Nope'" in error_line(err)
    warned = [line for line in err.splitlines() if "starts moving" in line]
    if ramp:
        assert warned == []
    else:
        (line,) = warned
        assert re.search(r"^warning: --motion moving.txt, point float: the table starts moving at 2.2\d m/s", line)
        assert "--ramp S" in line


@pytest.mark.parametrize("interpolation", ["pchip", "linear"])
def test_monotone_motion_interpolation_is_not_warned_of(cli, interpolation):
    args = [
        "run",
        "anchored_line",
        "--motion",
        "step.txt",
        "--motion-interpolation",
        interpolation,
        "--channels",
        "Nope",
    ]
    status, _, err = cli(args, {"step.txt": STEP_TABLE})
    assert status == 2 and not [line for line in err.splitlines() if line.startswith("warning:")]


def test_unknown_motion_interpolation_is_an_argument_error(cli):
    with pytest.raises(SystemExit) as exit_:
        cli(
            ["run", "anchored_line", "--motion", "step.txt", "--motion-interpolation", "spline"],
            {"step.txt": STEP_TABLE},
        )
    assert exit_.value.code == 2


@pytest.mark.parametrize("motion", [False, True])
def test_held_coupled_point_note_only_without_a_motion(cli, motion):
    args = ["run", "system.txt", "--channels", "Nope"] + (["--motion", "m.txt"] if motion else [])
    table = "0 200 0 0\n100 200 0 0\n"
    status, _, err = cli(args, {"system.txt": MOORDYN, "m.txt": table})
    assert status == 2
    held = [line for line in err.splitlines() if "held where they are" in line]
    assert held == ([] if motion else ["note: coupled point(s) 2 have no motion and are held where they are; give a "
                                       "motion table with --motion"])  # fmt: skip


def test_scene_file_motion_table_overshoot_is_a_note(tmp_path):
    (tmp_path / "step.txt").write_text(STEP_TABLE)
    (tmp_path / "scene.toml").write_text(edited('type = "coupled"', f'type = "coupled"\n{TABLE_MOTION} }}'))
    scene = jc.read_scene(tmp_path / "scene.toml")
    (note,) = [n for n in scene.notes if "strays" in n]
    assert "points.float.motion" in note and "strays from -10.92 to 0 m in x between t = 1 and 2 s" in note


# --------------------------------------------------------------------------------------
# Two through a real process: the exit status and the one line a shell user sees.


@pytest.mark.parametrize(
    "args, message",
    [
        (["run", "anchored_line", "--dt-out", "0"], "--dt-out must be a positive number of seconds, got 0"),
        (
            ["run", "anchored_line", "--out", "missing/out.csv"],
            "--out missing/out.csv: the folder missing does not exist",
        ),
    ],
)
def test_cli_in_a_process(tmp_path, args, message):
    start = time.perf_counter()
    done = subprocess.run(
        [sys.executable, "-m", "jaxcable", *args],
        cwd=tmp_path,
        capture_output=True,
        text=True,
        timeout=120,
        env={"JAXCABLE_CACHE_DIR": "", "PYTHONPATH": str(Path(jc.__file__).parents[1]), "PATH": ""},
    )
    assert time.perf_counter() - start < 2 * SECONDS
    assert done.returncode == 2
    assert done.stderr == f"jaxcable: error: {message}\n" and done.stdout == "" and not list(tmp_path.iterdir())


# --------------------------------------------------------------------------------------
# Refused before JAX is imported: what the input files and flags alone decide is read
# and checked in plain Python and numpy, so that a refusal is answered at once (JAX's
# import is 1.3 s of a refusal's 1.5 s otherwise). Each case runs `jaxcable` in a fresh
# process through its entry point, and then looks for JAX among its modules. A point
# with a body or a motion, which the engine makes, is in a file refused for its lines.

# The command line's entry in a fresh process, its arguments after `-c CODE`: prints
# the exit status and whether JAX was imported.
ENTRY = """
import sys
sys.argv = ["jaxcable", *sys.argv[1:]]
from jaxcable._cli import command
try:
    command()
except SystemExit as exit_:
    print(exit_.code, "jax" in sys.modules)
"""
HARMONIC = 'type = "coupled"\nmotion = { type = "harmonic", amplitude = 1.0, period = 5.0 }'
MOORDYN_BODY = edited("Vessel    200.0   0.0    0.0     0 ", "Vessel    200.0   0.0    0.0     50 ", MOORDYN)
BEFORE_JAX_CASES = [
    (
        ["run", "system.txt"],
        {"system.txt": edited("0.1     20.0", "0.1     heavy", MOORDYN)},
        r"system.txt, line 6, column Mass/m: 'heavy' is not a number",
    ),
    (
        ["info", "system.txt"],
        {"system.txt": edited("chain     1        2 ", "chain     1        3 ", MOORDYN_BODY)},
        r"system.txt, line 15, column AttachB: point 3 does not exist \(2 points are defined\)",
    ),
    (
        ["run", "system.txt"],
        {"system.txt": edited("150.0    WtrDpth", "-150.0   WtrDpth", MOORDYN)},
        r"system.txt, line 18: option WtrDpth must be positive, got -150.0",
    ),
    (
        ["run", "scene.toml"],
        {"scene.toml": edited("length = 190.0", "length = -190.0")},
        r"scene.toml, line 29, key lines\[0\].length: the unstretched length must be positive, got -190",
    ),
    (
        ["info", "scene.toml"],
        {"scene.toml": edited('type = "rope"\nfrom', 'type = "chain"\nfrom', edited('type = "coupled"', HARMONIC))},
        r"scene.toml, line 2\d, key lines\[0\].type: line type 'chain' does not exist; defined: \['rope'\]",
    ),
    (
        ["run", "system.txt", "--motion", "m.txt"],
        {"system.txt": MOORDYN, "m.txt": "0 200 0 0\n1 far 0 0\n"},
        r"m.txt, line 2: non-numeric field in '1 far 0 0'",
    ),
    (["info", "nowhere.txt"], {}, r"cannot read nowhere.txt: No such file or directory"),
    (
        ["run", "system.txt", "--segments", "0"],
        {"system.txt": MOORDYN},
        r"--segments must be a positive integer, got 0",
    ),
    (
        ["run", "system.txt", "--dt", "0.01", "--adaptive"],
        {"system.txt": MOORDYN},
        r"--dt asks for fixed steps and --adaptive for adaptive ones",
    ),
]


@pytest.mark.parametrize(
    "args, files, message", BEFORE_JAX_CASES, ids=lambda x: " ".join(x) if isinstance(x, list) else ""
)
def test_input_files_and_flags_are_refused_before_jax_is_imported(tmp_path, args, files, message):
    for name, text in files.items():
        (tmp_path / name).write_text(text)
    done = subprocess.run(
        [sys.executable, "-c", ENTRY, *args],
        cwd=tmp_path,
        capture_output=True,
        text=True,
        timeout=120,
        env={"JAXCABLE_CACHE_DIR": "", "PYTHONPATH": str(Path(jc.__file__).parents[1]), "PATH": ""},
    )
    assert done.stdout == "2 False\n", (done.stdout, done.stderr)  # refused (2), JAX not imported
    assert re.fullmatch(f"jaxcable: error: {message}.*\n", done.stderr), done.stderr
    assert sorted(path.name for path in tmp_path.iterdir()) == sorted(files)


# --------------------------------------------------------------------------------------
# The Python API: refused at construction or at the entry of `simulate`, before any
# compilation.


def small_line(law=None, seabed=None, anchor_z=-30.0):
    """A four-segment line from an anchor to a driven top, and its water."""
    line = jc.LineType(mass_per_length=2.0, diameter=0.03, tension_law=law or jc.LinearElastic(2e6))
    model = jc.CableNetwork.from_branches(
        [[0.0, 0.0, anchor_z], [30.0, 0.0, 0.0]],
        [jc.Branch(0, 1, line, 43.0, 4)],
        {0: jc.Fixed(), 1: jc.Harmonic(0.5, 4)},
    )
    env = jc.Environment(current=(0.3, 0.0, 0.0), depth=None if seabed is None else 30.0, seabed=seabed)
    return model, env


def line_between(anchor, top, length):
    """`small_line`'s rope, `length` (m) in four segments between two fixed points."""
    line = jc.LineType(mass_per_length=2.0, diameter=0.03, tension_law=jc.LinearElastic(2e6))
    model = jc.CableNetwork.from_branches(
        [anchor, top], [jc.Branch(0, 1, line, length, 4)], {0: jc.Fixed(), 1: jc.Fixed()}
    )
    return model, jc.Environment()


def simulate_from(positions=None, velocities=None):
    model, env = small_line()
    initial = jc.State(
        model.node_positions if positions is None else positions,
        np.zeros_like(model.node_positions) if velocities is None else velocities,
    )
    return jc.simulate(model, env, 1.0, initial=initial, throw=False)


def nan_at(array, index):
    array = np.array(array)
    array[index] = np.nan
    return array


def with_quadratic(c_e1):
    model, _ = small_line(jc.NonlinearElastic(2e6, 0.0))
    return eqx.tree_at(lambda m: m.line.tension_law.quadratic_coefficient, model, c_e1 * np.ones(4))


API_CASES = {
    "constraint on a node that does not exist": (
        lambda: jc.CableNetwork.from_branches(
            [[0.0, 0.0, -100.0], [100.0, 0.0, 0.0]],
            [jc.Branch(0, 1, jc.LineType(3.0, 0.02, jc.LinearElastic(1e8)), 150.0, 10)],
            constraints={0: jc.Fixed(), 11: jc.Fixed()},
        ),
        r"from_branches constraints: key 11 is not a node; junction k is node k \(0 to 1 here\) .* to 10",
    ),
    "body on a node that does not exist": (
        lambda: jc.CableNetwork.from_branches(
            [[0.0, 0.0, -100.0], [100.0, 0.0, 0.0]],
            [jc.Branch(0, 1, jc.LineType(3.0, 0.02, jc.LinearElastic(1e8)), 150.0, 10)],
            constraints={0: jc.Fixed(), 1: jc.Fixed()},
            bodies={-1: jc.Body(mass=10.0)},
        ),
        r"from_branches bodies: key -1 is not a node",
    ),
    "breaking Airy wave (Miche)": (
        lambda: jc.Airy(60.0, 5.6, 100.0),
        r"Airy.height must be at most the breaking height",
    ),
    "breaking Airy wave (McCowan)": (lambda: jc.Airy(8.0, 12.0, 10.0), r"H/d = 0.8 against McCowan's 0.78"),
    "breaking Airy steepness": (lambda: jc.Airy.from_steepness(0.2, 8.0, 100.0), r"Miche's 0.142 tanh\(2πd/λ\)"),
    "Cnoidal past McCowan": (lambda: jc.Cnoidal(9.0, 20.0, 10.0), r"Cnoidal.height must be at most 0.78 times"),
    "Cnoidal past Miche": (
        lambda: jc.Cnoidal(6.0, 6.5, 10.0),
        r"Cnoidal.height must be at most the breaking height 5.8\d+ m, got 6 m .* H/λ = 0.128 against Miche's",
    ),
    "falling tension law": (
        lambda: small_line(jc.NonlinearElastic(3e7, -3e8)),
        r"quadratic_stiffness C_E1 = -3e\+08 N with C_E = 3e\+07 N makes the tension fall beyond ε = 0.05",
    ),
    "falling law in one segment": (
        lambda: jc.LineType(3.0, 0.02, jc.KelvinVoigt([3e7, 3e7], [0.0, -1.6e7], 0.0)),
        r"C_E1 = -1.6e\+07 N with C_E = 3e\+07 N at index 1 .* at least −C_E/2 = -1.5e\+07 N",
    ),
    "falling law edited in": (
        lambda: jc.simulate(with_quadratic(-1e7), small_line()[1], 1.0),
        r"LineType.tension_law.quadratic_stiffness C_E1 = -1e\+07 N",
    ),
    "anchor below the seabed": (
        lambda: jc.simulate(*small_line(seabed=jc.Seabed(), anchor_z=-60.0), 1.0),
        r"constrained node 0 is at z = -60 m, below the seabed at z = -30 m \(Environment.depth = 30 m\)",
    ),
    "statics with an anchor below the seabed": (
        lambda: jc.solve_statics(*small_line(seabed=jc.Seabed(), anchor_z=-60.0)),
        r"constrained node 0 is at z = -60 m, below the seabed at z = -30 m \(Environment.depth = 30 m\)",
    ),
    "rtol below rounding": (lambda: jc.SolverConfig(rtol=1e-300), r"SolverConfig.rtol must be at least 1e-13"),
    "rtol above a tenth": (lambda: jc.SolverConfig(rtol=5.0), r"SolverConfig.rtol must be at most 0.1"),
    "negative ramp of a table": (lambda: jc.Sampled([0.0, 1.0], np.zeros((2, 3)), ramp=-1.0), r"Sampled.ramp must be"),
    "line with both ends at one point": (
        lambda: jc.solve_statics(*line_between([0.0, 0.0, -30.0], [0.0, 0.0, -30.0], 43.0)),
        r"segment 0 joins nodes 0 and 2, which start at the same point \[0.0, 0.0, -30.0\] m",
    ),
    "1e-6 m line between points 400 m apart": (
        lambda: jc.solve_statics(*line_between([0.0, 0.0, -30.0], [400.0, 0.0, -30.0], 1e-6)),
        r"constrained nodes 0 and 1 are 400 m apart, but .* 1e-06 m long unstretched: it must stretch 4e\+10 %",
    ),
    "NaN initial position": (
        lambda: simulate_from(positions=nan_at(small_line()[0].node_positions, (2, 0))),
        r"simulate: initial.positions must be finite, got nan at index 2, 0",
    ),
    "NaN initial velocity": (
        lambda: simulate_from(velocities=nan_at(np.zeros((5, 3)), (3, 2))),
        r"simulate: initial.velocities must be finite, got nan at index 3, 2",
    ),
    "infinite t1": (lambda: jc.simulate(*small_line(), np.inf), r"simulate: t1 must be finite, got inf"),
    "NaN output time": (lambda: jc.simulate(*small_line(), 1.0, ts=[0.0, np.nan]), r"simulate: ts must be finite"),
    "output times backwards": (
        lambda: jc.simulate(*small_line(), 1.0, ts=[0.5, 0.2]),
        r"simulate: ts must be strictly increasing, got 0.2 at index 1",
    ),
    "unknown interpolation": (
        lambda: jc.Sampled([0.0, 1.0], np.zeros((2, 3)), interpolation="spline"),
        r"Sampled.interpolation must be one of \('cubic', 'pchip', 'linear'\), got 'spline'",
    ),
    "sweep of falling laws": (
        lambda: jc.sweep(lambda c: (with_quadratic(c), small_line()[1]), {"c": [-2e6, -4e6]}, 1.0),
        r"every case is invalid; invalid input: case 0: LineType.tension_law.quadratic_stiffness must be at least "
        r"−C_E/2",
    ),
}


@pytest.mark.parametrize("make, message", API_CASES.values(), ids=API_CASES.keys())
def test_api_refuses_at_construction_or_entry(make, message):
    start = time.perf_counter()
    with pytest.raises(ValueError, match=message):
        make()
    assert time.perf_counter() - start < SECONDS


@pytest.mark.unchecked  # jaxtyping's checker would refuse these first, by annotation
def test_simulate_names_an_argument_of_the_wrong_type():
    model, env = small_line()
    with pytest.raises(ValueError, match=r"simulate: env must be a jaxcable.Environment, got str"):
        jc.simulate(model, "water", 1.0)  # pyright: ignore[reportArgumentType]
    with pytest.raises(ValueError, match=r"simulate: model must be a jaxcable.CableNetwork, got NoneType"):
        jc.simulate(None, env, 1.0)  # pyright: ignore[reportArgumentType]


@pytest.mark.unchecked
def test_solver_tolerance_that_is_not_a_number_is_named():
    with pytest.raises(ValueError, match=r"SolverConfig.rtol must be a number or an array of numbers, got 'tight'"):
        jc.SolverConfig(rtol="tight")  # pyright: ignore[reportArgumentType]


@pytest.mark.unchecked
def test_simulate_names_an_initial_state_that_is_not_a_state():
    with pytest.raises(
        ValueError, match=r"simulate: initial must be 'statics', 'rest' or a jaxcable.State, got ndarray"
    ):
        jc.simulate(*small_line(), 1.0, initial=np.zeros((5, 3)))  # pyright: ignore[reportArgumentType]


def test_forward_mode_derivative_says_which_adjoint_to_pass():
    model, env = small_line()

    def tension(scale):
        scaled = eqx.tree_at(lambda m: m.line.normal_drag, model, scale * model.line.normal_drag)
        return jc.simulate(scaled, env, 0.5, ts=[0.5], initial="rest").tension[-1, 0]

    with pytest.raises(TypeError, match=r"needs solver=SolverConfig\(adjoint=diffrax.ForwardMode\(\)\)"):
        jax.jacfwd(tension)(1.0)


def test_run_scene_refuses_a_zero_output_interval(tmp_path):
    (tmp_path / "scene.toml").write_text(SCENE)
    scene = jc.read_scene(tmp_path / "scene.toml")
    for dt_out in (0.0, -0.1):
        with pytest.raises(SceneError, match=rf"dt_out must be a positive number of seconds, got {dt_out}"):
            run_scene(scene, dt_out=dt_out)


def test_a_run_of_hours_is_warned_of_before_it_starts(tmp_path):
    """2,500 segments over 30 s take hours by the estimate's stated costs (checked by
    hand below); the warning, made an error here, stops the run before statics."""
    (tmp_path / "scene.toml").write_text(edited("duration = 10.0", "duration = 30.0"))
    scene = jc.read_scene(tmp_path / "scene.toml").with_segments(2500)
    start = time.perf_counter()
    with warnings.catch_warnings():
        warnings.simplefilter("error", UserWarning)
        with pytest.raises(UserWarning, match=r"2,500 segments \(lines of 2500\) would take some [\d.]+ h .*statics"):
            run_scene(scene)
    assert time.perf_counter() - start < SECONDS


def test_size_estimate_follows_its_stated_costs(tmp_path):
    # The warning's figures by hand: statics 35 s + 400 steps × 16 µs × F, dynamics at the stable
    # step 1.7/|λ| with |λ| = 2 √3 √(EA/m) / l (consistent mass; ζ = 0.2 leaves the
    # mode underdamped, so damping does not change |λ|), each step
    # 13.5 µs + 6 × 144 ns per node.
    (tmp_path / "scene.toml").write_text(edited("duration = 10.0", "duration = 30.0"))
    built = jc.read_scene(tmp_path / "scene.toml").with_segments(2500).build()
    (warning,) = check_size(built, 30.0, 0.5, jc.SolverConfig())
    free, nodes = 2499, 2501
    magnitude = 2 * np.sqrt(3) * np.sqrt(3.0e7 / 3.0) / (190.0 / 2500)
    steps = 30.0 * magnitude / 1.7
    hours = (35.0 + 400 * 16e-6 * free + steps * (13.5e-6 + 6 * 144e-9 * nodes)) / 3600
    assert f"would take some {hours:,.2g} h" in warning and f"about {steps:,.0f} steps" in warning
    assert check_size(jc.read_scene(tmp_path / "scene.toml").build(), 30.0, 0.5, jc.SolverConfig()) == ()


def with_law(c_e, c_e1):
    """`small_line` with the tension law `C_E ε + C_E1 ε²`, edited in as a sweep's
    traced build would, past the constructor's checks."""
    model = with_quadratic(c_e1)
    return eqx.tree_at(lambda m: m.line.tension_law.axial_stiffness, model, c_e * np.ones(4))


def test_sweep_reports_later_cases_with_a_falling_law_or_a_negative_stiffness_as_invalid():
    """The first case is sound and built concretely; the second and third, built under
    `vmap`, have a tension law that turns negative at ε = 0.1 and a negative axial
    stiffness (reported as a "successful" run with a -48.7 kN statics tension before
    these checks, issue 23): each is reported, not run."""
    swept = jc.sweep(
        lambda c_e, c_e1: (with_law(c_e, c_e1), small_line()[1]),
        {"c_e": [2e6, 2e6, -2e6], "c_e1": [0.0, -2e7, 0.0]},
        0.2,
        ts=[0.0, 0.2],
        initial="rest",
    )
    assert swept.status[0] == "successful"
    assert swept.status[1] == (
        "invalid input: case 1: LineType.tension_law.quadratic_stiffness must be at least −C_E/2, so that the "
        "tension rises up to ε = 1, got -20000000.0"
    )
    assert swept.status[2].startswith(
        "invalid input: case 2: LineType.tension_law.axial_stiffness must be positive, got -2000000.0"
    )
    for case in (1, 2):
        assert bool(swept.case(case).result == diffrax.RESULTS.nonfinite_input)
        assert not np.any(np.isfinite(np.asarray(swept.simulation.tension[case])))


def test_segment_count_of_hours_is_warned_of_before_any_work(tmp_path, monkeypatch):
    """`--segments 100000` once hung with no message: now the size check says before
    statics that the run would take hours (the warning, made an error here, stops it)."""
    monkeypatch.chdir(tmp_path)
    monkeypatch.setenv("JAXCABLE_CACHE_DIR", "")
    start = time.perf_counter()
    with warnings.catch_warnings():
        warnings.simplefilter("error", UserWarning)
        with pytest.raises(UserWarning, match=r"100,000 segments .* would take some [\d.,]+ h"):
            main(["run", "anchored_line", "--segments", "100000", "--duration", "1"])
    assert time.perf_counter() - start < SECONDS
    assert not list(tmp_path.iterdir())
