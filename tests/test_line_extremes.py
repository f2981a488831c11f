"""What an engineer reads first of a run (issue 37, item 5): each line's largest and
smallest tension with segment and time, its ends' largest, its utilisation against the
line type's minimum breaking load with a warning past a safety factor, each output
channel's statistics, the figure, and the run as an `xarray.Dataset`. The extremes are
checked on planted tensions, where each answer is known."""

import re

import numpy as np
import pytest

import jaxcable as jc
from jaxcable._cli import main as cli_main
from jaxcable.io import SceneError, SceneRun
from jaxcable.io._extremes import overloads, table
from jaxcable.io._line_fatigue import table as fatigue_table

# Two line types, three lines: 4, 3 and 2 segments.
SCENE = """
[water]
depth = 100.0

[line_types.chain]
mass_per_length = 100.0
diameter = 0.08
axial_stiffness = 5.0e8
{chain_mbl}

[line_types.rope]
mass_per_length = 5.0
diameter = 0.05
axial_stiffness = 2.0e7

[points.a]
type = "fixed"
position = [-200.0, 0.0, -100.0]

[points.b]
type = "fixed"
position = [0.0, 0.0, -10.0]

[points.c]
type = "fixed"
position = [0.0, 50.0, -90.0]

[[lines]]
name = "west"
type = "chain"
from = "a"
to = "b"
length = 230.0
segments = 4

[[lines]]
name = "north"
type = "rope"
from = "c"
to = "b"
length = 90.0
segments = 3

[[lines]]
name = "short"
type = "rope"
from = "a"
to = "c"
length = 215.0
segments = 2
"""


def _scene(tmp_path, chain_mbl: str = "minimum_breaking_load = 2.0e6"):
    path = tmp_path / "three.toml"
    path.write_text(SCENE.format(chain_mbl=chain_mbl))
    return path


def _at_rest(built, times: np.ndarray) -> tuple[np.ndarray, np.ndarray]:
    """Positions and velocities, shape `(times, nodes, 3)`, of the nodes at rest where
    the scene puts them."""
    nodes = np.asarray(built.model.node_positions)
    positions = np.broadcast_to(nodes, (times.size, *nodes.shape)).copy()
    return positions, np.zeros_like(positions)


def _no_reactions(built, times: np.ndarray) -> np.ndarray:
    return np.zeros((times.size, len(built.model.constrained_nodes), 3))


def _run_with(built, tension: np.ndarray) -> SceneRun:
    """A `SceneRun` of `built` holding `tension` (N), shape `(times, segments)`, every
    0.5 s, with the nodes at rest where the scene puts them."""
    times = 0.5 * np.arange(tension.shape[0])
    reactions = _no_reactions(built, times)
    return SceneRun(built, None, times, *_at_rest(built, times), tension, reactions, 10, "planted", 0.0, 0.0, ())


@pytest.fixture
def planted(tmp_path):
    """A run of the three-line scene whose tensions are planted: 1 kN everywhere, the
    west chain's largest (1.5 MN) in its third segment at t = 1.5 s and smallest (−20 N)
    in its first at t = 0.5 s, its end B 0.9 MN at t = 2 s; the north rope's largest
    (40 kN) at end A at t = 1 s."""
    built = jc.read_scene(_scene(tmp_path)).build()
    west, north, short = (np.asarray(s) for s in built.line_segments)
    assert (west.size, north.size, short.size) == (4, 3, 2)
    tension = np.full((5, built.model.segment_length.shape[0]), 1e3)
    tension[3, west[2]] = 1.5e6
    tension[1, west[0]] = -20.0
    tension[4, west[3]] = 0.9e6
    tension[2, north[0]] = 4e4
    return _run_with(built, tension)


def test_each_lines_extremes_are_where_and_when_they_were(planted):
    west, north, short = planted.line_extremes()
    assert (west.line, west.line_type, west.segments) == ("west", "chain", 4)
    assert (west.largest, west.largest_time, west.largest_segment) == (1.5e6, 1.5, 3)
    assert (west.smallest, west.smallest_time, west.smallest_segment) == (-20.0, 0.5, 1)
    assert (west.end_a, west.end_b) == (1e3, 0.9e6)
    assert (north.largest, north.largest_time, north.largest_segment) == (4e4, 1.0, 1)
    assert (north.end_a, north.end_b) == (4e4, 1e3)
    assert short.largest == short.smallest == 1e3 and short.largest_segment == 1  # the first of equals
    assert west.breaking_load == 2.0e6 and west.utilisation == pytest.approx(0.75, rel=1e-15)
    assert north.breaking_load is None and north.utilisation is None


def test_extremes_from_a_start_leave_the_transient_out(planted):
    west, north, _ = planted.line_extremes(start=2.0)  # the outputs at 2.0 s on: the last
    assert (west.largest, west.largest_time, west.largest_segment) == (0.9e6, 2.0, 4)
    assert (west.smallest, west.smallest_time) == (1e3, 2.0)
    assert north.largest == 1e3 and west.utilisation == pytest.approx(0.45, rel=1e-15)
    assert planted.line_extremes(start=1.5 - 1e-12)[0].largest == 1.5e6  # an output within rounding counts


def test_a_line_past_its_safety_factor_is_warned_of(planted):
    rows = planted.line_extremes()
    (warning,) = overloads(rows)  # 75 % of MBL, past 1/1.67 = 59.9 %; the ropes have no MBL
    assert warning.startswith("line west (chain): largest tension 1500.000 kN at t = 1.500 s, segment 3/4")
    assert "75.0% of its minimum breaking load 2000.0 kN, above 1/1.67 = 59.9%" in warning
    assert overloads(rows, safety_factor=1.3) == []  # 75 % < 1/1.3 = 76.9 %
    scene = planted.built.scene.with_breaking_loads({"chain": 1.2e6})
    (warning,) = overloads(_run_with(scene.build(), planted.tension).line_extremes())
    assert "125.0% of its minimum breaking load 1200.0 kN, beyond its minimum breaking load" in warning


def test_the_table_lists_lines_with_utilisation_where_an_mbl_is_given(planted, tmp_path):
    text = table(planted.line_extremes())
    heading, west, north, short = text.splitlines()
    assert heading.split()[:3] == ["line", "type", "largest"] and heading.endswith("MBL kN  utilisation")
    assert west.split() == ["west", "chain", "1500.000", "1.500", "3/4", "-0.020", "0.500", "1.000", "900.000"] + [
        "2000.0",
        "75.0%",
    ]
    assert north.split()[-2:] == ["-", "-"]
    bare = jc.read_scene(_scene(tmp_path, chain_mbl="")).build()
    without = table(_run_with(bare, planted.tension).line_extremes())
    assert "utilisation" not in without and "MBL" not in without
    shortened = table(planted.line_extremes(), limit=1).splitlines()
    assert shortened[1].startswith("west") and shortened[-1] == "... and 2 more lines (all in SceneRun.line_extremes())"


def test_breaking_loads_are_given_by_line_type_and_checked(tmp_path):
    scene = jc.read_scene(_scene(tmp_path))
    assert [t.minimum_breaking_load for t in scene.line_types] == [2.0e6, None]
    every = scene.with_breaking_loads({None: 5e5, "chain": 3e6})
    assert [t.minimum_breaking_load for t in every.line_types] == [3e6, 5e5]
    with pytest.raises(SceneError, match=r"loads: the scene has no line type 'wire'; its line types: chain, rope"):
        scene.with_breaking_loads({"wire": 1e6}, "loads")
    with pytest.raises(SceneError, match=r"the minimum breaking load of rope must be a positive number of N, got -1"):
        scene.with_breaking_loads({"rope": -1.0})
    with pytest.raises(
        SceneError, match=r"line_types\.chain.*minimum_breaking_load must be a positive number of N, got 0"
    ):
        jc.read_scene(_scene(tmp_path, "minimum_breaking_load = 0.0"))


@pytest.mark.parametrize(
    "flags, message",
    [
        (
            ["--breaking-load", "wire=1e6"],
            "--breaking-load: the scene has no line type 'wire'; its line types: chain, rope",
        ),
        (["--breaking-load", "chain=strong"], "--breaking-load chain=strong: expected TYPE=N or N, a load in newtons"),
        (["--breaking-load", "1e6", "2e6"], "--breaking-load 1e6: name the line type (TYPE=N)"),
        (["--breaking-load", "rope=1e6", "rope=2e6"], "--breaking-load names line type rope twice"),
        (["--breaking-load", "rope=-3"], "the minimum breaking load of rope must be a positive number of N, got -3"),
        (
            ["--safety-factor", "0.8"],
            "--safety-factor must be a number of at least 1 (1: up to the breaking load), got 0.8",
        ),
    ],
)
def test_bad_breaking_loads_are_refused_before_any_work(tmp_path, capsys, flags, message):
    assert cli_main(["run", str(_scene(tmp_path)), "--duration", "0", *flags]) == 2
    assert message in capsys.readouterr().err


def test_the_command_prints_the_table_and_warns_past_the_safety_factor(capsys):
    """The bundled Y-branch gives its ropes' breaking loads; statics' tensions (5.5 kN
    in a 250 kN polyester leg) pass a 50× safety factor, not the default 1.67."""
    assert cli_main(["run", "y_branch", "--duration", "0", "--no-progress", "--safety-factor", "50"]) == 0
    out, err = capsys.readouterr()
    rows = {line.split()[0]: line.split() for line in out.splitlines() if line.split()[:1] in (["leg_west"], ["riser"])}
    assert rows["leg_west"][1] == "polyester" and rows["leg_west"][-2:] == ["250.0", "2.2%"]
    assert rows["riser"][-2] == "400.0"
    assert "warning: line leg_west (polyester): largest tension 5.45" in err and "above 1/50 = 2.0%" in err
    assert "line riser" not in err


def test_a_run_is_an_xarray_dataset(planted):
    xr = pytest.importorskip("xarray")
    data = planted.to_dataset(("FairTen1",))
    assert isinstance(data, xr.Dataset)
    np.testing.assert_array_equal(data["tension"].values, planted.tension)
    assert data["tension"].dims == ("time", "segment") and data["tension"].attrs["units"] == "N"
    assert data["positions"].dims == ("time", "node", "xyz") and list(data["xyz"].values) == ["x", "y", "z"]
    np.testing.assert_array_equal(data["time"].values, planted.times)
    assert list(data["line"].values) == ["west", "north", "short"]
    assert data["largest_tension"].sel(line="west").item() == 1.5e6
    assert data["utilisation"].sel(line="west").item() == pytest.approx(0.75)
    assert np.isnan(data["minimum_breaking_load"].sel(line="north").item())
    np.testing.assert_array_equal(data["FairTen1"].values, planted.channels(("FairTen1",))["FairTen1"])
    assert data["segment_line"].values.tolist() == [1, 1, 1, 1, 2, 2, 2, 3, 3]


def test_channels_read_as_moordyn_writes_them(planted):
    """`FairTen`/`AnchTen` are the magnitude of the end segment's force and `L<k>N<i>T`
    that of the mean of the force vectors beside node i (MoorDyn's
    `getNodeTen(i).norm()`): a slack segment its damping pushes (−20 N here) reads
    +20 N at the end, and beside a 1 kN segment, |(−20 τ₁ + 1000 τ₂)/2|: between 490 N
    (the two in line) and 510 N."""
    values = planted.channels(("AnchTen1", "L1N1T", "L1N0T", "FairTen1"))
    assert values["AnchTen1"][1] == 20.0 and values["L1N0T"][1] == 20.0
    r = planted.positions[1][planted.built.line_nodes[0][:3]]
    first, second = (r[1] - r[0]) / np.linalg.norm(r[1] - r[0]), (r[2] - r[1]) / np.linalg.norm(r[2] - r[1])
    expected = np.linalg.norm(-20.0 * first + 1e3 * second) / 2
    assert 490.0 < expected < 510.0 and values["L1N1T"][1] == pytest.approx(expected, rel=1e-14)
    assert values["FairTen1"][4] == 0.9e6


def test_channel_statistics_are_time_averages_with_the_extremes_and_their_times(planted):
    """On a sine over whole periods, the trapezoidal time averages are the closed form's
    (mean c, standard deviation A/√2); `start` leaves a transient out; a short last
    output interval weighs for its length."""
    from jaxcable.io._statistics import channel_statistics
    from jaxcable.io._statistics import table as statistics_table

    t = np.linspace(0.0, 20.0, 2001)
    sine = 3.0 + 2.0 * np.sin(2 * np.pi * t / 5.0)
    step = np.where(t < 5.0, 100.0, 1.0)
    (s, k) = channel_statistics({"Time": t, "L1N3PZ": sine, "FairTen1": step}, {"L1N3PZ": "m", "FairTen1": "N"})
    assert (s.name, s.units, s.start, s.end) == ("L1N3PZ", "m", 0.0, 20.0)
    assert s.mean == pytest.approx(3.0, abs=1e-12) and s.std == pytest.approx(2.0 / np.sqrt(2.0), rel=1e-12)
    assert (s.maximum, s.maximum_time, s.minimum_time) == (5.0, 1.25, 3.75)
    assert k.maximum == 100.0 and k.maximum_time == 0.0
    (_, k) = channel_statistics({"Time": t, "L1N3PZ": sine, "FairTen1": step}, {"L1N3PZ": "m", "FairTen1": "N"}, 5.0)
    assert (k.mean, k.std, k.maximum, k.start) == (1.0, 0.0, 1.0, 5.0)
    (last,) = channel_statistics({"Time": np.array([0.0, 1.0, 2.0, 2.5]), "X": np.array([0, 0, 0, 10.0])}, {"X": "m"})
    assert last.mean == pytest.approx(0.5 * 10.0 * 0.5 / 2.5, rel=1e-15)
    for start in (-1.0, 20.0, np.nan):
        with pytest.raises(ValueError, match="statistics start at"):
            channel_statistics({"Time": t, "X": sine}, {"X": "m"}, start)
    text = statistics_table(planted.channel_statistics(("FairTen1", "AnchTen2"), start=1.0)).splitlines()
    assert text[0] == "statistics over t = 1 to 2 s:" and text[1].split() == [
        *("channel", "units", "mean", "std", "min", "t", "s", "max", "t", "s")
    ]
    assert text[2].split()[:2] == ["FairTen1", "N"] and text[2].split()[-2:] == ["900000", "2.000"]


def test_the_command_prints_channel_statistics_and_checks_their_start(tmp_path, capsys):
    assert cli_main(["run", "anchored_line", "--duration", "2", "--no-progress", "--statistics-from", "1"]) == 0
    out = capsys.readouterr().out
    assert "statistics over t = 1 to 2 s:" in out
    # The lines' extremes leave the same transient out.
    lines = out.splitlines()
    at = lines.index("line tensions over t = 1 to 2 s:")
    assert lines[at + 1].split()[:3] == ["line", "type", "largest"]
    assert 1.0 <= float(lines[at + 2].split()[3]) <= 2.0  # line 1's largest tension's time
    assert [line.split()[0] for line in out.splitlines() if line.startswith(("FairTen1", "AnchTen1"))] == [
        "FairTen1",
        "AnchTen1",
    ]
    assert cli_main(["run", str(_scene(tmp_path)), "--duration", "3", "--statistics-from", "3"]) == 2
    assert "--statistics-from 3 s leaves nothing of a 3 s run" in capsys.readouterr().err


def test_the_figure_draws_plan_and_elevation_at_the_extreme_tensions_with_legends_off_the_data(planted, tmp_path):
    """Three panels (tension history, plan x–y, elevation x–z); the shapes at the start
    and at the times of the largest (1.5 MN, t = 1.5 s) and smallest (−20 N, t = 0.5 s)
    tensions; every point marked by kind; each legend below its panel. Ends are named
    fairlead or anchor only where their points are coupled or fixed."""
    pytest.importorskip("matplotlib")
    from jaxcable.io._channels import describe_channel
    from jaxcable.plot import plot_run

    figure = plot_run(planted, tmp_path / "run.png", snapshots=5)
    assert (tmp_path / "run.png").stat().st_size > 10_000
    history, plan, elevation = figure.axes
    assert [a.get_title() for a in figure.axes] == ["Tension history", "Plan, x–y", "Elevation, x–z"]
    labels = [t.get_text() for t in plan.get_legend().get_texts()]
    assert labels[:4] == [
        "evenly spaced times",  # once, for t = 1 and 2 s (the others are marked)
        "start",
        "largest tension, 1500 kN in line west (t = 1.50 s)",
        "smallest tension, -0.02 kN (t = 0.50 s)",
    ]
    assert labels[4:] == ["fixed point"]  # the planted scene's three points are fixed
    assert len(plan.lines) == 3 * 5 + 1  # three lines at five times, and the points
    from matplotlib.backends.backend_agg import FigureCanvasAgg

    renderer = FigureCanvasAgg(figure).get_renderer()  # the figure was saved and closed
    for axes in figure.axes:
        legend, frame = axes.get_legend().get_window_extent(renderer), axes.get_window_extent(renderer)
        assert legend.y1 <= frame.y0  # wholly below the panel
    scene = planted.built.scene  # west: a (fixed) to b (fixed)
    assert describe_channel("AnchTen1", scene) == "line west anchor tension (end A, at point a)"
    assert describe_channel("FairTen1", scene) == "line west end B tension (at point b)"


def test_each_lines_fatigue_is_its_worst_segments_miner_damage(tmp_path):
    """A planted history: 1 kN everywhere but the west chain's third segment, a cosine of
    range 100 kN about 100 kN, ten cycles crest to crest in 20 s. Under API RP 2SK's stud
    chain curve (N = 1000 R⁻³, R over the 2 MN MBL) that is 10 (0.05)³ / 1000 = 1.25e-6,
    a life of 20 s / 1.25e-6; counted from 10 s, half of it."""
    scene = jc.read_scene(_scene(tmp_path)).with_fatigue_curves({"chain": ("api_stud_chain", None)}, "--fatigue")
    built = scene.build()
    times = np.linspace(0.0, 20.0, 401)
    tension = np.full((times.size, built.model.segment_length.shape[0]), 1e3)
    tension[:, np.asarray(built.line_segments[0])[2]] = 1e5 + 5e4 * np.cos(2 * np.pi * times / 2.0)
    run = SceneRun(built, None, times, *_at_rest(built, times), tension, _no_reactions(built, times), 10, "", 0, 0, ())
    (west,) = run.line_fatigue()  # the ropes name no curve
    assert (west.line, west.curve, west.segment, west.segments) == ("west", "api_stud_chain", 3, 4)
    assert west.damage == pytest.approx(10 * 0.05**3 / 1000, rel=1e-12)
    assert west.life == pytest.approx(20.0 / (west.damage * 365.25 * 86400), rel=1e-12)
    assert run.line_fatigue(start=10.0)[0].damage == pytest.approx(west.damage / 2, rel=1e-12)
    # Ten cycles of 100 kN in 20 s at m = 3, as twenty equivalent cycles (1 Hz).
    assert west.equivalent_load == pytest.approx(1e5 * (10 / 20) ** (1 / 3), rel=1e-12)
    assert run.line_fatigue(start=10.0)[0].equivalent_load == pytest.approx(west.equivalent_load, rel=1e-12)
    text = fatigue_table(run.line_fatigue()).splitlines()
    assert text[0] == "fatigue over t = 0 to 20 s (Miner's rule, rainflow counting):"
    assert text[1].rstrip().endswith("DEL kN (1 Hz)")
    assert text[2].split()[:5] == ["west", "chain", "api_stud_chain", "1.250e-06", "3/4"]
    assert float(text[2].split()[-1]) == pytest.approx(79.37, abs=0.01)


@pytest.mark.parametrize(
    "extra, message",
    [
        ('fatigue_curve = "chain"', "unknown fatigue_curve 'chain'; jaxcable has dnv_stud_chain"),
        ('fatigue_curve = "dnv_studless_chain"', "takes stress ranges on the nominal area: give fatigue_area"),
        ("fatigue_area = 0.01", "fatigue_area is for a fatigue_curve; give one"),
        ('fatigue_curve = "api_stud_chain"\nfatigue_area = 0.01', "drop fatigue_area"),
        ('fatigue_curve = "dnv_stud_chain"\nfatigue_area = -1.0', "fatigue_area must be a positive number"),
    ],
)
def test_a_scene_files_fatigue_curve_is_checked(tmp_path, extra, message):
    with pytest.raises(SceneError, match=r"line_types\.chain.*" + re.escape(message)):
        jc.read_scene(_scene(tmp_path, f"minimum_breaking_load = 2.0e6\n{extra}"))


def test_fatigue_curves_on_the_command_line(tmp_path, capsys):
    """`--fatigue` names a curve per line type, checked before any work; a scene file's
    `fatigue_curve` with its area is read."""
    good = jc.read_scene(_scene(tmp_path, 'fatigue_curve = "dnv_stud_chain"\nfatigue_area = 0.00907'))
    assert (good.line_types[0].fatigue_curve, good.line_types[0].fatigue_area) == ("dnv_stud_chain", 0.00907)
    for flags, message in (
        (["--fatigue", "rope=api_polyester"], "fatigue_curve api_polyester takes tension ranges over the minimum"),
        (["--fatigue", "wire=api_polyester"], "--fatigue: the scene has no line type 'wire'"),
        (["--fatigue", "api_polyester", "chain=api_stud_chain"], "name the line type (TYPE=CURVE)"),
        (["--fatigue", "chain=dnv_stud_chain:big"], "expected [TYPE=]CURVE[:AREA]"),
        (["--fatigue", "chain=dnv_stud_chain"], "--fatigue, line type chain: fatigue_curve dnv_stud_chain takes"),
    ):
        assert cli_main(["run", str(_scene(tmp_path)), "--duration", "1", *flags]) == 2
        assert message in capsys.readouterr().err
