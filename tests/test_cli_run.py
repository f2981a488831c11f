"""The command line a MoorDyn user expects (issue 22): a run from the file's geometry
with no statics (MoorDyn's `TmaxIC = 0`), point channels, progress for a terminal and
a log, a summary that separates statics, compile and run time and calls a held run
steady, and `--help` without JAX. MoorDyn (the `moordyn` package) is the reference
where it is installed."""

import _thread
import contextlib
import os
import signal
import subprocess
import sys
import threading
import time
from pathlib import Path

import numpy as np
import pytest

import jaxcable as jc
from jaxcable._cli import _interruptible
from jaxcable._cli import main as cli_main
from jaxcable._interrupt import StopRequest
from jaxcable._names import DROPPED_KINDS, INTERPOLATIONS, SOLVER_NAMES
from jaxcable.io import _channels, _run
from jaxcable.io._initial_shape import initial_positions

DTM = 5e-4  # s
DURATION = 0.3  # s

_HEADER = """--------------------- MoorDyn Input File ------------------------
{title}
---------------------- LINE TYPES ----------------------
TypeName  Diam    Mass/m   EA      BA/-zeta  EI   Cd   Ca   CdAx  CaAx
(-)       (m)     (kg/m)   (N)     (N-s/-)   (-)  (-)  (-)  (-)   (-)
chain     0.1     150.0    5.0e8   1.0e7     0    1.2  1.0  0.2   0.0
rope      0.05    8.0      2.0e7   2.0e5     0    1.2  1.0  0.2   0.0
---------------------- POINTS ----------------------
ID  Type    X      Y     Z      Mass   Volume  CdA  Ca
(-) (-)     (m)    (m)   (m)    (kg)   (m^3)   (m2) (-)
"""

# A chain from an anchor to a held fairlead, a rope whose end A is above its end B (the
# catenary solved with its ends swapped), a vertical rope (MoorDyn starts it straight),
# and a chain too long to reach its upper end without doubling back on the bed
# (MoorDyn's catenary refuses it, and it starts straight).
GEOMETRY = (
    _HEADER
    + """1   Fixed   -300   0     -100   0      0       0    0
2   Vessel  0      0     0      0      0       0    0
3   Fixed   10     20    -30    0      0       0    0
4   Fixed   0      50    -40    0      0       0    0
5   Fixed   50     0     -60    0      0       0    0
6   Fixed   50     0     -20    0      0       0    0
7   Fixed   100    100   -100   0      0       0    0
8   Fixed   150    100   -60    0      0       0    0
---------------------- LINES ----------------------
ID  LineType  AttachA  AttachB  UnstrLen  NumSegs  LineOutputs
(-) (-)       (-)      (-)      (m)       (-)      (-)
1   chain     1        2        350.0     20       -
2   rope      3        4        40.0      8        -
3   rope      5        6        45.0      6        -
4   chain     7        8        100.0     10       -
---------------------- OPTIONS ----------------------
1025.0   WtrDnsty
9.81     g
{depth}    WtrDpth
0.0005   dtM
0        TmaxIC
---------------------- OUTPUTS ----------------------
FairTen1 Point2PZ
END
--------------------- need this line ------------------------
"""
)

# For the fixed-step runs: the chain, hanging clear of the bed; and a 500 kg weight
# on two ropes between fixed points, dropped from the ropes' catenaries. Both lines have
# drag and added mass, which a MoorDyn file gets lumped at the nodes as MoorDyn lumps
# them (`hydrodynamics="nodes"`); with jaxcable's own segment form instead, the weight
# parts from MoorDyn's by 5 mm and 7 % of its net force in 0.3 s.
HANGING = (
    _HEADER
    + """1   Fixed   -300   0     -100   0      0       0    0
2   Vessel  0      0     0      0      0       0    0
3   Fixed   10     20    -30    0      0       0    0
4   Free    40     -10   -50    500    0       0    0
5   Fixed   0      50    -40    0      0       0    0
---------------------- LINES ----------------------
ID  LineType  AttachA  AttachB  UnstrLen  NumSegs  LineOutputs
(-) (-)       (-)      (-)      (m)       (-)      (-)
1   chain     1        2        350.0     20       -
2   rope      4        3        50.0      10       -
3   rope      5        4        75.0      10       -
---------------------- OPTIONS ----------------------
1025.0   WtrDnsty
9.81     g
300.0    WtrDpth
0.0005   dtM
0        TmaxIC
---------------------- OUTPUTS ----------------------
FairTen1 AnchTen1 Point2FX Point2FZ Point1PX
END
--------------------- need this line ------------------------
"""
)


# A chain resting on the bed (depth 100 m), from MoorDyn's start: its catenary solve
# leaves the touchdown segments compressed by up to 0.28 %, so the start rings there
# first. No drag or added mass (`HANGING` has them), so that the bed and the axial law
# are what is compared.
RESTING = """--------------------- MoorDyn Input File ------------------------
a chain resting on the bed, from MoorDyn's start
---------------------- LINE TYPES ----------------------
TypeName  Diam    Mass/m   EA      BA/-zeta  EI   Cd   Ca   CdAx  CaAx
(-)       (m)     (kg/m)   (N)     (N-s/-)   (-)  (-)  (-)  (-)   (-)
chain     0.1     150.0    5.0e8   1.0e7     0    0.0  0.0  0.0   0.0
---------------------- POINTS ----------------------
ID  Type    X      Y     Z      Mass   Volume  CdA  Ca
(-) (-)     (m)    (m)   (m)    (kg)   (m^3)   (m2) (-)
1   Fixed   -300   0     -100   0      0       0    0
2   Vessel  0      0     0      0      0       0    0
---------------------- LINES ----------------------
ID  LineType  AttachA  AttachB  UnstrLen  NumSegs  LineOutputs
(-) (-)       (-)      (-)      (m)       (-)      (-)
1   chain     1        2        350.0     20       -
---------------------- OPTIONS ----------------------
1025.0   WtrDnsty
9.81     g
100.0    WtrDpth
0.0005   dtM
0        TmaxIC
---------------------- OUTPUTS ----------------------
FairTen1
END
--------------------- need this line ------------------------
"""


@contextlib.contextmanager
def _quiet_fd():
    """Silence MoorDyn, which writes to the process's stdout itself."""
    sys.stdout.flush()
    saved, null = os.dup(1), os.open(os.devnull, os.O_WRONLY)
    os.dup2(null, 1)
    try:
        yield
    finally:
        os.dup2(saved, 1)
        os.close(saved)
        os.close(null)


def _moordyn(path: Path, duration: float, every: float):
    """MoorDyn's run of `path` with its coupled point held, sampled every `every` s
    after the start: `(initial node positions per line, samples)`, each sample the
    fair and anchor tension of line 1, point 2's net force (x, z), and point 4's
    position (x, z), velocity (x, z) and net force (z) where there is a point 4."""
    moordyn = pytest.importorskip("moordyn")
    scene = jc.read_moordyn(path)
    coupled = [float(x) for p in scene.points if p.kind == "coupled" for x in p.position]
    with _quiet_fd():
        system = moordyn.Create(str(path))
        moordyn.Init(system, coupled, [0.0] * len(coupled))
    try:
        lines = [moordyn.GetLine(system, k + 1) for k in range(len(scene.lines))]
        shapes = [np.array([moordyn.GetLineNodePos(x, i) for i in range(moordyn.GetLineN(x) + 1)]) for x in lines]
        samples = []
        stride = round(every / DTM)
        with _quiet_fd():
            for k in range(round(duration / DTM)):
                moordyn.Step(system, coupled, [0.0] * len(coupled), k * DTM, DTM)
                if (k + 1) % stride == 0:
                    force = moordyn.GetPointForce(moordyn.GetPoint(system, 2))
                    line = lines[0]
                    top, bottom = moordyn.GetLineFairTen(line), np.linalg.norm(moordyn.GetLineNodeTen(line, 0))
                    sample = [top, bottom, force[0], force[2]]
                    if len(scene.points) >= 4:
                        point = moordyn.GetPoint(system, 4)
                        position, velocity = moordyn.GetPointPos(point), moordyn.GetPointVel(point)
                        force = moordyn.GetPointForce(point)
                        sample += [position[0], position[2], velocity[0], velocity[2], force[2]]
                    samples.append(sample)
    finally:
        with _quiet_fd():
            moordyn.Close(system)
    return shapes, np.array(samples)


@pytest.fixture(scope="module")
def hanging(tmp_path_factory):
    path = tmp_path_factory.mktemp("moordyn") / "hanging.txt"
    path.write_text(HANGING.format(title="a chain hanging clear of the bed, from its catenary"))
    return path


@pytest.fixture(scope="module")
def moordyn_samples(hanging):
    """MoorDyn's run of `HANGING` (`_moordyn`), every 0.01 s."""
    return _moordyn(hanging, DURATION, 0.01)[1]


@pytest.fixture(scope="module")
def hanging_run(hanging):
    """jaxcable's run of `HANGING`, with no statics (the file's TmaxIC = 0)."""
    return jc.run_scene(jc.read_moordyn(hanging), duration=DURATION, dt_out=0.01)


@pytest.mark.parametrize("depth", ["100.0", "300.0"])
def test_the_start_without_statics_is_moordyns(tmp_path, depth):
    """With TmaxIC = 0 every line starts where MoorDyn starts it: on its elastic
    catenary, resting on the bed (depth 100 m, lines 1 and 4 touch it) or not (300 m),
    solved with its ends swapped where end A is the higher; straight where it is
    vertical or its catenary has no solution."""
    path = tmp_path / "geometry.txt"
    path.write_text(GEOMETRY.format(title="start shapes", depth=depth))
    scene = jc.read_moordyn(path)
    assert not scene.run.statics
    built = scene.build()
    positions, notes = initial_positions(built)
    shapes, _ = _moordyn(path, 0.0, 1.0)
    for k, (nodes, shape) in enumerate(zip(built.line_nodes, shapes)):
        np.testing.assert_allclose(positions[nodes], shape, rtol=0, atol=1e-9, err_msg=f"line {k + 1}")
    vertical = positions[built.line_nodes[2]]
    np.testing.assert_allclose(vertical[:, :2], 50 * np.array([[1.0, 0.0]]).repeat(7, 0), atol=1e-12)
    lowest = float(np.min(positions[built.line_nodes[0], 2]))
    if depth == "100.0":
        assert lowest == pytest.approx(-100.0, abs=1e-9)  # resting on the bed, not in it
    else:
        assert lowest < -110.0  # hanging below its anchor
    assert bool(np.any(positions[built.line_nodes[1], 2] < -40)), "rope 2 sags below its lower end"
    # The too-long chain starts straight only where it rests on the bed.
    straight = [note for note in notes if "line 4 starts straight" in note]
    assert len(straight) == (1 if depth == "100.0" else 0)


def test_a_run_without_statics_agrees_with_moordyn_at_the_same_fixed_step(moordyn_samples, hanging, hanging_run):
    """From the same start at rest, at MoorDyn's dtM with the midpoint method (its RK2),
    the ringing chain's end tensions and the held fairlead's net force (`Point2FX`,
    `Point2FZ`: MoorDyn's `Point::doRHS` sum, same sign) follow MoorDyn's to MoorDyn's
    own integration error. Measured: within 7e-4 of their largest value over 0.3 s of a
    start that rings at the chain's axial frequency (1.5e-3 at the anchor); halving
    MoorDyn's dtM halves that (3.4e-4), halving it again halves it again (1.7e-4),
    while halving jaxcable's step moves jaxcable's by 4e-6. MoorDyn converges, at
    first order, to jaxcable's answer."""
    samples = moordyn_samples
    run = hanging_run
    assert run.static is None
    assert run.stepping == f"Midpoint, fixed steps of {DTM:g} s"
    halved = hanging.with_name("hanging_half_dtm.txt")
    halved.write_text(hanging.read_text().replace("0.0005   dtM", "0.00025  dtM"))
    finer = _moordyn(halved, DURATION, 0.01)[1]
    names = ("FairTen1", "AnchTen1", "Point2FX", "Point2FZ")
    channels = run.channels(names)
    for j, name in enumerate(names):
        ours, theirs = channels[name][1:], samples[:, j]
        scale = float(np.max(np.abs(theirs)))
        assert scale > 1e5, name  # a ringing start, not a trivial one
        np.testing.assert_allclose(ours, theirs, rtol=0, atol=2e-3 * scale, err_msg=name)
        coarse, fine = np.max(np.abs(ours - theirs)), np.max(np.abs(ours - finer[:, j]))
        assert fine < 0.6 * coarse, (name, fine / scale, coarse / scale)


def test_moordyns_rk4_is_read_and_agrees_to_rounding_of_the_models(hanging):
    """`tScheme RK4` runs jaxcable's `rk4` (the classical method, as MoorDyn's
    `RK4Scheme`) at dtM. Both engines then integrate the same equations to fourth order:
    the ringing chain's tensions and the fairlead's force agree within 4e-6 of their
    peaks over 0.3 s (measured; 7e-4 with RK2, MoorDyn's own midpoint error), and the
    dropped weight as with RK2 (1.5e-5 m: the models' small difference)."""
    path = hanging.with_name("hanging_rk4.txt")
    path.write_text(hanging.read_text().replace("0        TmaxIC", "0        TmaxIC\nRK4      tScheme"))
    scene = jc.read_moordyn(path)
    assert (scene.run.solver, scene.run.dt) == ("rk4", DTM)
    assert any("tScheme RK4: rk4" in note for note in scene.notes)
    run = jc.run_scene(scene, duration=DURATION, dt_out=0.01)
    assert run.stepping == f"RK4, fixed steps of {DTM:g} s"
    theirs = _moordyn(path, DURATION, 0.01)[1]
    names = ("FairTen1", "AnchTen1", "Point2FX", "Point2FZ", "Point4PX", "Point4PZ")
    ours = run.channels(names)
    for j, name in enumerate(names):
        scale = float(np.max(np.abs(theirs[:, j])))
        tolerance = 2e-5 * scale if j < 4 else 1e-4
        np.testing.assert_allclose(ours[name][1:], theirs[:, j], rtol=0, atol=tolerance, err_msg=name)


def test_a_dropped_weight_follows_moordyns(moordyn_samples, hanging_run):
    """A free point (`Point4PX`, `PZ`, `VX`, `VZ`, `FZ`) dropped from the file's
    geometry on two ropes with drag and added mass falls as MoorDyn's does at the same
    fixed step. Measured over 0.3 s: within 1.5e-5 m, 7e-4 of its largest speed and
    1e-3 of its largest net force; MoorDyn's own change from halving its dtM twice is
    under 1e-5 of those, so what remains is a small difference of the models (the
    smoothed slack switch, over a strain of 1e-5, is one)."""
    names = ("Point4PX", "Point4PZ", "Point4VX", "Point4VZ", "Point4FZ")
    ours = hanging_run.channels(names)
    theirs = moordyn_samples[:, 4:]
    speed = float(np.max(np.abs(theirs[:, 2:4])))
    force = float(np.max(np.abs(theirs[:, 4])))
    for j, (name, tolerance) in enumerate(zip(names, (1e-4, 1e-4, 3e-3 * speed, 3e-3 * speed, 3e-3 * force))):
        np.testing.assert_allclose(ours[name][1:], theirs[:, j], rtol=0, atol=tolerance, err_msg=name)
    assert float(np.ptp(ours["Point4PZ"])) > 0.3  # it fell
    assert speed > 1.0 and force > 1e3


def test_point_channels_name_the_points_state_and_net_force(hanging_run):
    """`Point<k>PX..VZ` are the point's node; `FX..FZ` the net force on it, every force
    but inertia: on a fixed point, the negative of its support's reaction (which
    `reactions` computes from M a − Q independently)."""
    run = hanging_run
    values = run.channels(("Point1PX", "p1vz", "POINT1FX", "Point1FZ", "P2T", "Point2FX", "Point2FY", "Point2FZ"))
    np.testing.assert_array_equal(values["Point1PX"], -300.0)
    np.testing.assert_array_equal(values["Point1VZ"], 0.0)
    constrained = list(run.built.model.constrained_nodes)
    for k, point in ((1, 0), (2, 1)):
        reaction = run.reactions[:, constrained.index(point)]
        scale = float(np.max(np.abs(reaction)))
        for axis in "XZ":
            got = values.get(f"Point{k}F{axis}")
            if got is not None:
                np.testing.assert_allclose(got, -reaction[:, "XYZ".index(axis)], rtol=0, atol=1e-9 * scale)
    force = np.stack([values[f"Point2F{axis}"] for axis in "XYZ"], axis=-1)
    np.testing.assert_allclose(values["Point2T"], np.linalg.norm(force, axis=-1), rtol=1e-12)


def test_channel_spellings_moordyn_accepts(tmp_path):
    """MoorDyn-C's and MoorDyn-F's spellings, in any case: `P`/`Point` and OpenFAST's
    `Con`/`C`/`Connect` for points, `L`/`Line` with `N<i>`, `NA` or `NB` for nodes, `T`
    or `Ten`; a name jaxcable does not write is an `UnknownChannel`, and a point that
    does not exist is refused, as MoorDyn refuses it."""
    scene = jc.read_moordyn(_write(tmp_path, HANGING.format(title="names")))
    parse = _channels.parse_channel
    spellings = {
        "Point2PZ": "Point2PZ",
        "point2pz": "Point2PZ",
        "P2PZ": "Point2PZ",
        "p2fz": "Point2FZ",
        "Con4Fx": "Point4FX",
        "CON1FX": "Point1FX",
        "C2pz": "Point2PZ",
        "Connect2vx": "Point2VX",
        "Line1N3VX": "L1N3VX",
        "l1n20t": "L1N20T",
        "L1N3Ten": "L1N3T",
        "Line1NBPZ": "L1N20PZ",
        "LINE3NAPZ": "L3N0PZ",
    }
    assert {name: parse(name, scene)[0] for name in spellings} == spellings
    for name in ("Con2AX", "Rod1PX", "Body1PX", "L1N3TA", "Nope", "L1PX", "FairTen1X"):
        with pytest.raises(_channels.UnknownChannel, match="unknown output channel"):
            parse(name, scene)
    for name, message in (("Point6PZ", "point 6 does not exist"), ("Line1N21PZ", "line 1 has nodes 0 to 20")):
        with pytest.raises(jc.io.SceneError, match=message):
            parse(name, scene)
    units = _channels.channel_units
    assert [units(n) for n in ("Point2PZ", "Point2VX", "Point2FZ", "L1N3VZ", "L1N3T")] == ["m", "m/s", "N", "m/s", "N"]
    assert [units(n) for n in ("Line1NBPZ", "Con2Fx", "C2vx", "L1N3Ten", "FairTen1")] == ["m", "N", "m/s", "N", "N"]
    describe = _channels.describe_channel
    assert describe("FairTen1", scene) == "line 1 fairlead tension (end B, at point 2)"
    assert describe("p2fz", scene) == "point 2 net force z"


def test_a_file_from_openfast_runs_its_channels_and_skips_the_others(tmp_path):
    """An OUTPUTS section written for OpenFAST's MoorDyn (`Con4Fx`, `Line1NBPZ`) runs
    and writes those channels; what jaxcable does not write (an acceleration, a rod) is
    skipped with one note naming it, not the whole file refused; a line that does not
    exist is refused, naming the channel."""
    text = HANGING.format(title="openfast").replace(
        "FairTen1 AnchTen1 Point2FX Point2FZ Point1PX", "FairTen1 Con4Fx Line1NBPZ CON2AX Rod1PX"
    )
    scene = jc.read_moordyn(_write(tmp_path, text))
    assert scene.channels == ("FairTen1", "Con4Fx", "Line1NBPZ")
    (note,) = [note for note in scene.notes if "OUTPUTS" in note]
    assert "CON2AX, Rod1PX skipped" in note
    run = jc.run_scene(scene, duration=0.01, dt_out=0.005)
    values = run.channels()
    assert list(values) == ["Time", "FairTen1", "Point4FX", "L1N20PZ"]
    np.testing.assert_array_equal(values["L1N20PZ"], 0.0)  # the vessel's point, held at z = 0
    with pytest.raises(jc.io.SceneError, match="FairTen9.*line 9 does not exist"):
        jc.read_moordyn(_write(tmp_path, text.replace("FairTen1 Con4Fx", "FairTen9 Con4Fx")))


def test_statics_switch_in_files(tmp_path):
    """TmaxIC = 0 skips statics; any other TmaxIC is a note, with statics; a scene
    file says `statics = false` in [simulation]."""
    text = HANGING.format(title="switch")
    assert not jc.read_moordyn(_write(tmp_path, text)).run.statics
    assert jc.read_moordyn(_write(tmp_path, text.replace("0        TmaxIC", "60       TmaxIC"))).run.statics
    scene_text = (jc.examples.scene_path("anchored_line")).read_text()
    assert "[simulation]" in scene_text
    skipped = scene_text.replace("[simulation]", "[simulation]\nstatics = false", 1)
    path = tmp_path / "scene.toml"
    path.write_text(skipped)
    assert not jc.read_scene(path).run.statics
    path.write_text(scene_text.replace("[simulation]", '[simulation]\nstatics = "no"', 1))
    with pytest.raises(jc.io.SceneError, match="statics"):
        jc.read_scene(path)


def test_summary_splits_the_wall_time_and_names_the_peak(hanging_run):
    summary = hanging_run.summary()
    assert "from the file's geometry (statics skipped)" in summary
    assert "at t = " in summary and "steady" not in summary
    timing = summary.splitlines()[-1]
    assert timing.startswith("wall time") and "compile" in timing and "run" in timing
    assert "statics" not in timing  # none was solved


def test_a_held_run_is_steady_not_peaked(hanging):
    """From equilibrium, with nothing moving, the tensions hold to rounding: the summary
    says so instead of naming the time of a rounding-sized peak."""
    scene = jc.read_moordyn(hanging)
    run = jc.run_scene(scene, duration=0.05, dt_out=0.01, statics=True)
    assert run.static is not None and run.steady()
    summary = run.summary()
    assert "tensions steady" in summary and "at t = " not in summary
    assert "statics" in summary.splitlines()[-1]


def test_cli_runs_without_statics_and_writes_point_channels(hanging, hanging_run, tmp_path, capsys):
    out = tmp_path / "run.csv"
    argv = ["run", str(hanging), "--duration", str(DURATION), "--dt-out", "0.01", "--out", str(out)]
    assert cli_main([*argv, "--no-progress"]) == 0
    stdout = capsys.readouterr().out
    assert "statics skipped (the file's TmaxIC = 0)" in stdout
    assert "wall time" in stdout
    table = np.genfromtxt(out, delimiter=",", names=True)
    assert table.dtype.names == ("Time", "FairTen1", "AnchTen1", "Point2FX", "Point2FZ", "Point1PX")
    np.testing.assert_allclose(table["Point2FZ"], hanging_run.channels(("Point2FZ",))["Point2FZ"], rtol=1e-9)


def test_help_and_examples_do_not_import_jax():
    """`jaxcable --help`, `run --help` and `examples` answer without JAX."""
    script = (
        "import sys\n"
        "from jaxcable._cli import main\n"
        "for argv in (['--help'], ['run', '--help']):\n"
        "    try:\n"
        "        main(argv)\n"
        "    except SystemExit:\n"
        "        pass\n"
        "assert main(['examples']) == 0\n"
        "heavy = sorted({'jax', 'diffrax', 'equinox', 'optax'} & set(sys.modules))\n"
        "assert not heavy, heavy\n"
    )
    root = Path(jc.__file__).parent.parent
    env = {**os.environ, "PYTHONPATH": str(root)}
    result = subprocess.run([sys.executable, "-c", script], capture_output=True, text=True, env=env, timeout=60)
    assert result.returncode == 0, result.stderr
    assert "--no-statics" in result.stdout and "anchored_line" in result.stdout


def test_the_command_ends_its_process_with_everything_written(tmp_path):
    """`python -m jaxcable` ends a successful run at once (`os._exit`, skipping the
    interpreter's shutdown): its summary is still printed in full, its output file and
    its kept programs written; a failure exits the usual way, with its status. With the
    caller's XLA flags, not the suite's: a user's process compiles with XLA's defaults."""
    from conftest import DEFAULT_XLA_FLAGS

    root = Path(jc.__file__).parent.parent
    cache = tmp_path / "cache"
    env = {**os.environ, "PYTHONPATH": str(root), "JAXCABLE_CACHE_DIR": str(cache), "XLA_FLAGS": DEFAULT_XLA_FLAGS}
    out = tmp_path / "run.csv"
    argv = [sys.executable, "-m", "jaxcable", "run", "anchored_line", "--segments", "4", "--duration", "0"]
    result = subprocess.run(
        [*argv, "--out", str(out), "--channels", "FairTen1"], capture_output=True, text=True, env=env
    )
    assert result.returncode == 0, result.stderr
    assert "equilibrium:" in result.stdout and result.stdout.endswith("\n")
    assert np.genfromtxt(out, delimiter=",", names=True)["FairTen1"] > 0
    # Statics' one: the fairlead's position at t = 0 (the line is a discrete catenary).
    assert not list(cache.rglob("*.partial")) and len(list(cache.rglob("*.program"))) == 1
    failed = subprocess.run([*argv, "--dt-out", "0"], capture_output=True, text=True, env=env)
    assert failed.returncode == 2 and "--dt-out must be a positive number" in failed.stderr


def test_ctrl_c_ends_the_command_at_once(tmp_path):
    """Ctrl-C (SIGINT) before a run has results to keep (here while it compiles its
    programs, cold) ends `jaxcable` at once, exit status 130, saying so, although the
    main thread would otherwise sit inside XLA's compiler until it ends; the input is
    untouched and nothing half-written is left."""
    root = Path(jc.__file__).parent.parent
    env = {**os.environ, "PYTHONPATH": str(root), "JAXCABLE_CACHE_DIR": str(tmp_path / "cache")}
    out = tmp_path / "run.csv"
    # A test runner's worker may ignore SIGINT, and a child inherits that (a process
    # started in the background should): the child takes Python's own handler back, as
    # a process started from a shell has it, then runs `python -m jaxcable`.
    script = (
        "import runpy, signal, sys\n"
        "signal.signal(signal.SIGINT, signal.default_int_handler)\n"
        f"sys.argv = ['jaxcable', 'run', 'anchored_line', '--duration', '3600', '--out', {str(out)!r}]\n"
        "runpy.run_module('jaxcable', run_name='__main__')\n"
    )
    process = subprocess.Popen(
        [sys.executable, "-c", script], stdout=subprocess.PIPE, stderr=subprocess.PIPE, text=True, env=env
    )
    time.sleep(3.0)  # past JAX's import, into the cold compile (5-10 s on these machines)
    assert process.poll() is None, process.communicate()
    process.send_signal(signal.SIGINT)
    start = time.monotonic()
    _, err = process.communicate(timeout=30)
    assert time.monotonic() - start < 5.0  # well under a second alone; the suite loads the cores
    assert process.returncode == 130 and err.rstrip().endswith("jaxcable: interrupted")
    assert not out.exists()


def test_ctrl_c_in_a_runs_blocks_waits_for_what_it_keeps():
    """Where the run has results to keep, Ctrl-C asks it to stop at the end of its
    block, and the command waits for it to write them (its exit status is the
    command's), not ending the process."""
    stop = StopRequest()
    stop.keeping()  # a block has ended

    def work():
        while not stop.asked:
            time.sleep(0.01)
        return 130

    previous = signal.signal(signal.SIGINT, signal.default_int_handler)  # a test runner's worker ignores it
    try:
        threading.Timer(0.3, _thread.interrupt_main).start()
        assert _interruptible(work, stop) == 130
    finally:
        signal.signal(signal.SIGINT, previous)


def test_a_run_that_fails_or_is_stopped_writes_what_it_computed(tmp_path, capsys):
    """Past --max-steps, and when stopped (Ctrl-C's request), `jaxcable run` writes
    the run up to its last good output time, reports it, and says where it ended."""
    out = tmp_path / "run.csv"
    argv = ["run", "anchored_line", "--duration", "20", "--dt-out", "0.05", "--out", str(out), "--no-progress"]
    assert cli_main([*argv, "--adaptive", "--max-steps", "3000"]) == 1
    stdout, stderr = capsys.readouterr()
    kept = np.genfromtxt(out, delimiter=",", names=True)
    last = kept["Time"][-1]
    assert 0 < last < 20 and np.all(np.isfinite(kept["FairTen1"]))
    assert f"wrote {out} (the run up to t = {last:g} s, where it failed)" in stdout
    assert f"jaxcable: solver failed: simulate failed between t = {last:g} s and t = " in stderr
    assert "The maximum number of solver steps was reached" in stderr and "line  type" in stdout

    stop = StopRequest()
    stop.ask()  # before the run: it stops at the end of its first block
    assert cli_main(argv, stop=stop) == 130
    stdout, stderr = capsys.readouterr()
    kept = np.genfromtxt(out, delimiter=",", names=True)
    assert kept["Time"][-1] == pytest.approx(63 * 0.05)  # the first block: t = 0 and 63 intervals
    assert "where it was interrupted" in stdout
    assert stderr.rstrip().endswith(
        "jaxcable: interrupted at t = 3.15 s; the results above and the files written are the run before it"
    )


def test_info_answers_without_waiting_for_statics(capsys):
    """`jaxcable info --advice-time 0` gives the advice the model alone gives, saying
    that what needs statics is left out; with the default wait it checks them."""
    assert cli_main(["info", "anchored_line", "--advice-time", "0"]) == 0
    out = capsys.readouterr().out
    assert "advice (statics left out by --advice-time 0):" in out
    assert "no mean equilibrium, so no check of the segments or of slack: statics were not solved" in out
    assert "stiffest axial mode" in out
    assert cli_main(["info", "anchored_line"]) == 0
    out = capsys.readouterr().out
    assert "advice:" in out and "statics were not solved" not in out


def test_lazy_names_are_the_modules_own():
    """`jaxcable.X` imports X on first use; it is the defining module's object, and
    the command line's plain lists match the engine's."""
    from jaxcable._model.motion import INTERPOLATIONS as engine_interpolations
    from jaxcable.io._moordyn import DROPPED_KINDS as reader_kinds

    assert jc.simulate is jc._simulation.simulate.simulate
    assert "simulate" in dir(jc) and "io" in dir(jc)
    with pytest.raises(AttributeError, match="no attribute 'nonesuch'"):
        _ = jc.nonesuch  # type: ignore[attr-defined]
    assert tuple(jc.SOLVERS) == SOLVER_NAMES
    assert engine_interpolations is INTERPOLATIONS and reader_kinds is DROPPED_KINDS
    assert jc.examples.anchored_line is jc.examples._anchored_line.anchored_line


def _write(tmp_path: Path, text: str) -> Path:
    path = tmp_path / f"file{len(list(tmp_path.iterdir()))}.txt"
    path.write_text(text)
    return path


def test_compile_time_counts_nested_traces_once():
    """A program traced inside another's trace reports its span inside the outer one:
    the meter counts the union of the spans (1 s + 0.5 s here), not their sum."""
    meter = _run._CompileMeter()
    meter.span("/jax/core/compile/jaxpr_trace_duration", 10.0, 11.0)
    meter.span("/jax/core/compile/jaxpr_trace_duration", 10.2, 10.7)  # nested
    meter.span("/jax/core/compile/backend_compile_duration", 12.0, 12.5)
    meter.span("/jax/some/other_event", 0.0, 100.0)  # not a compile event
    meter.event("/jax/compilation_cache/cache_hits")
    assert meter.seconds == pytest.approx(1.5)
    assert (meter.hits, meter.misses) == (1, 0)


def _moordyn_chain(path: Path, duration: float) -> tuple[np.ndarray, np.ndarray]:
    """MoorDyn's run of a one-chain file (`RESTING`'s line) with its coupled point
    held: node positions, shape `(samples, 21, 3)`, and the fairlead tension from its
    end-of-step state (EA ε + BA ε̇ of the top segment), every 0.01 s."""
    moordyn = pytest.importorskip("moordyn")
    stride = round(0.01 / DTM)
    with _quiet_fd():
        system = moordyn.Create(str(path))
        moordyn.Init(system, [0.0] * 3, [0.0] * 3)
    try:
        line = moordyn.GetLine(system, 1)
        positions, tensions = [], []
        with _quiet_fd():
            for k in range(round(duration / DTM)):
                moordyn.Step(system, [0.0] * 3, [0.0] * 3, k * DTM, DTM)
                if (k + 1) % stride == 0:
                    r = np.array([moordyn.GetLineNodePos(line, i) for i in range(21)])
                    v = np.array([moordyn.GetLineNodeVel(line, i) for i in (19, 20)])
                    chord = r[20] - r[19]
                    stretched = float(np.linalg.norm(chord))
                    rate = float(np.dot(chord / stretched, v[1] - v[0])) / 17.5
                    tensions.append(5.0e8 * max(stretched / 17.5 - 1.0, 0.0) + 1.0e7 * rate)
                    positions.append(r)
    finally:
        with _quiet_fd():
            moordyn.Close(system)
    return np.asarray(positions), np.asarray(tensions)


def test_a_chain_resting_on_the_bed_follows_moordyns(tmp_path):
    """From MoorDyn's start of a chain on the bed, at its dtM, node positions and the
    fairlead tension follow MoorDyn's over 0.3 s. The touchdown segments start slack
    (compressed), and MoorDyn's `BA` damps a slack segment as a taut one, which the
    MoorDyn reader asks of jaxcable's law (`slack_damping`); without that, those nodes
    fell freely, 6 cm apart, and the tension parted from MoorDyn's by 50 % of its peak.
    Measured: positions within 5e-6 m and the tension within 15 N (6e-5 of its peak);
    halving the step moves jaxcable's by 1e-6 m and 3e-5 of the peak. The tension is
    compared with MoorDyn's own end-of-step state (EA ε + BA ε̇ of the top segment, from
    its node positions and velocities): `GetLineFairTen` reports the tension of its
    last right-hand-side evaluation, the midpoint stage, which lags that by up to
    0.5 % of the peak here."""
    path = tmp_path / "resting.txt"
    path.write_text(RESTING)
    positions, tensions = _moordyn_chain(path, DURATION)
    run = jc.run_scene(jc.read_moordyn(path), duration=DURATION, dt_out=0.01)
    nodes = run.built.line_nodes[0]
    assert float(np.min(np.asarray(positions)[:, :, 2])) < -100.0  # in contact with the bed
    np.testing.assert_allclose(run.positions[1:, nodes], np.asarray(positions), rtol=0, atol=2e-5)
    ours, theirs = run.channels(("FairTen1",))["FairTen1"][1:], np.asarray(tensions)
    scale = float(np.max(np.abs(theirs)))
    assert scale > 1e5
    np.testing.assert_allclose(ours, theirs, rtol=0, atol=2e-4 * scale)


@pytest.mark.slow
def test_a_chain_sliding_on_the_bed_with_friction_follows_moordyns(tmp_path):
    """`RESTING` with its anchor free and `FrictionCoefficient` 1: the chain's end slides
    0.8 m along the bed in 1 s against friction. With MoorDyn's friction (the reader
    sets the seabed's `friction_damping` to `FricDamp`), nodes follow MoorDyn's within
    1.3e-4 m at dtM, and again at half of it, as without friction (1.3e-4 m: what
    remains is not friction's). That is within either code's own integration error
    here: halving the step moves MoorDyn's nodes by 3.3e-4 m, and jaxcable's by as much.
    jaxcable's smooth friction with `friction_speed` = N / FricDamp, the former mapping,
    parted by 1.2e-3 m."""
    path = tmp_path / "sliding.txt"
    text = RESTING.replace("1   Fixed   -300", "1   Free    -300").replace(
        "0        TmaxIC", "0        TmaxIC\n1.0      FrictionCoefficient"
    )
    path.write_text(text)
    positions, _ = _moordyn_chain(path, 1.0)
    assert float(np.ptp(positions[:, 0, 0])) > 0.5  # it slid
    scene = jc.read_moordyn(path)
    assert scene.water.seabed.friction_damping == 200.0
    run = jc.run_scene(scene, duration=1.0, dt_out=0.01)
    np.testing.assert_allclose(run.positions[1:, run.built.line_nodes[0]], positions, rtol=0, atol=3e-4)


@pytest.mark.parametrize("package", ["jaxcable", "jaxcable.io"])
def test_the_public_names_are_the_type_checkers_imports(package):
    """A package lists its public names once, as imports under `TYPE_CHECKING`: each
    name is the object those imports name, and `dir` shows those and no other."""
    import ast
    import importlib
    import inspect

    module = importlib.import_module(package)
    tree = ast.parse(inspect.getsource(module))
    (block,) = (n for n in tree.body if isinstance(n, ast.If) and getattr(n.test, "id", "") == "TYPE_CHECKING")
    listed = {alias.asname or alias.name: (node, alias.name) for node in block.body for alias in node.names}
    for name, (node, original) in listed.items():
        if node.module is None:  # a submodule
            assert getattr(module, name).__name__ == f"{package}.{original}"
        else:
            source = importlib.import_module("." * node.level + node.module, package)
            assert getattr(module, name) is getattr(source, original)
    public = {n for n in dir(module) if not n.startswith("_")}
    # `jaxtyping`: the tests' import hook adds it to every module it checks.
    assert public - set(listed) <= {"TYPE_CHECKING", "jaxtyping"}
