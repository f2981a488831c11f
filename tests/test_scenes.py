"""The bundled example scenes: output files read back as a user would, statics checked
against physics computed here from the TOML numbers, and the command line.

Independent references, written out here from the scene files' numbers (read with
`tomllib`, not jaxcable) and the documented conventions (segment weight `(m − ρF) g L`
on the unstretched length, half to each end node; drag `C_n |u_n| u_n + C_τ |u_τ| u_τ`
per stretched length with `C_n = ½ ρ K_n d`, `C_τ = ½ ρ K_τ π d`; body weight
`(M − ρV) g` and drag `½ ρ C_D A |u| u`; tension `C_E ε + C_E1 ε²`):

- Global balance: the supports carry the total wet weight of lines and bodies, less
  the current's drag.
- Node balance: at every free node the forces above sum to zero; at every support they
  sum to minus the reported reaction.
- Still-water lines are Irvine's elastic catenaries (with the quadratic term): each
  line between its equilibrium end points has the segment tensions and node positions
  of the continuum, to O((l/R)²).

Each example is run once (statics and 1 s of motion) and shared by every check.
"""

import dataclasses
import json
import os
import re
import tomllib

import diffrax
import jax
import numpy as np
import pytest
from helpers import ElasticCatenary
from scipy.io import netcdf_file
from scipy.optimize import fsolve

import jaxcable as jc
from jaxcable import examples
from jaxcable._cli import main

NAMES = examples.scene_names()
# irregular_buoy's run compiles a sea of 128 components on top of the scene, and
# buoy_net's is the largest network (a minute of the default suite's 2 cores): their
# checks here run with the slow suite; the sea's own in test_irregular*.py, the net's
# structure in test_jacobian.py.
SLOW_SCENES = {"irregular_buoy", "buoy_net"}


def cases(names: list[str]) -> list:
    """`names` as parameters, those of `SLOW_SCENES` marked slow."""
    return [pytest.param(n, marks=pytest.mark.slow) if n in SLOW_SCENES else n for n in names]


DURATION = 1.0  # s
# The same as y_branch.toml's own dt_out, so that the command-line test on y_branch,
# which runs 1 s at the file's interval, reuses the compiled solve.
DT_OUT = 0.1  # s


def toml(name: str) -> dict:
    return tomllib.loads(examples.scene_path(name).read_text(encoding="utf-8"))


def water(data: dict) -> tuple[float, float, np.ndarray]:
    w = data.get("water", {})
    return w.get("density", 1025.0), w.get("gravity", 9.81), np.array(w.get("current", [0.0, 0.0, 0.0]), float)


def calm(data: dict) -> bool:
    """Whether the scene's statics are those the force balances below compute: on no
    seabed (whose contact forces they leave out). Waves do not matter: `run_scene`
    solves its statics in the current alone. wave_mooring is checked on its own."""
    return "seabed" not in data


def line_type(data: dict, name: str) -> dict:
    """A line type's numbers, with the defaults the format documents."""
    t = data["line_types"][name]
    return {
        "m": t["mass_per_length"],
        "d": t["diameter"],
        "F": t.get("area", np.pi * t["diameter"] ** 2 / 4),
        "EA": t["axial_stiffness"],
        "EA1": t.get("quadratic_stiffness", 0.0),
        "Kn": t.get("normal_drag", 1.2),
        "Kt": t.get("tangential_drag", 0.008),
        "slack_width": t.get("slack_width", 1e-5),
    }


@pytest.fixture(scope="module")
def runs():
    """`runs(name)`: the example's `SceneRun` (statics, then DURATION s), computed once."""
    cache = {}

    def get(name: str) -> jc.io.SceneRun:
        if name not in cache:
            scene = jc.read_scene(examples.scene_path(name))
            cache[name] = jc.run_scene(scene, duration=DURATION, dt_out=DT_OUT)
        return cache[name]

    return get


# ---------------------------------------------------------------------------------------
# Output files, read back with numpy and scipy only.
# ---------------------------------------------------------------------------------------


def expected_channels(name: str, run: jc.io.SceneRun) -> dict[str, np.ndarray]:
    """Every line's FairTen/AnchTen and the scene's own channels, from the run's arrays
    by the MoorDyn definitions: the magnitudes of the end segments' forces and of the
    mean force vector at a node (`Line::getNodeTen(i).norm()`), node positions."""
    data = toml(name)
    points = list(data["points"])
    built = run.built
    values = {"Time": run.times}
    for k, line in enumerate(data["lines"], start=1):
        nodes, segments = built.line_nodes[k - 1], built.line_segments[k - 1]
        # The numbering agrees with the file: end A is `from`, end B is `to`, and the
        # segments chain the line's nodes.
        assert nodes[0] == points.index(line["from"]) and nodes[-1] == points.index(line["to"])
        np.testing.assert_array_equal(np.asarray(built.model.segment_nodes)[segments], np.c_[nodes[:-1], nodes[1:]])
        values[f"FairTen{k}"] = np.abs(run.tension[:, segments[-1]])
        values[f"AnchTen{k}"] = np.abs(run.tension[:, segments[0]])
    for channel in data.get("output", {}).get("channels", []):
        if match := re.fullmatch(r"L(\d+)N(\d+)(PX|PY|PZ|T)", channel):
            k, i, quantity = int(match[1]) - 1, int(match[2]), match[3]
            if quantity == "T":  # |the mean of the adjacent segments' T τ|
                nodes, segments = built.line_nodes[k], built.line_segments[k]
                r = run.positions[:, nodes]
                tangent = np.diff(r, axis=1) / np.linalg.norm(np.diff(r, axis=1), axis=-1, keepdims=True)
                pulls = run.tension[:, segments, None] * tangent
                beside = pulls[:, max(i - 1, 0) : i + 1]
                values[channel] = np.linalg.norm(beside.mean(axis=1), axis=-1)
            else:
                values[channel] = run.positions[:, built.line_nodes[k][i], "XYZ".index(quantity[1])]
    return values


@pytest.mark.parametrize("name", cases(NAMES))
def test_round_trip_through_every_format(name, runs, tmp_path):
    run = runs(name)
    expected = expected_channels(name, run)
    names = tuple(n for n in expected if n != "Time")
    assert run.times.shape == (int(round(DURATION / DT_OUT)) + 1,)

    # CSV: one header row of MoorDyn names, as `np.genfromtxt(..., names=True)` reads.
    csv = jc.io.write_output(tmp_path / "run.csv", run, names)
    assert csv.read_text().splitlines()[0] == ",".join(expected)
    table = np.genfromtxt(csv, delimiter=",", names=True)
    assert table.dtype.names == tuple(expected)
    for channel, values in expected.items():
        np.testing.assert_allclose(table[channel], values, rtol=1e-9, atol=1e-9, err_msg=channel)

    # MoorDyn's .out: a row of names, a row of units, then whitespace-separated values.
    out = jc.io.write_output(tmp_path / "run.out", run, names)
    with out.open() as f:
        header, units = f.readline().split(), f.readline().split()
        rows = np.loadtxt(f, ndmin=2)
    assert header == list(expected)
    assert units == ["(s)"] + ["(m)" if n.endswith(("PX", "PY", "PZ")) else "(N)" for n in names]
    for column, (channel, values) in enumerate(expected.items()):
        np.testing.assert_allclose(rows[:, column], values, rtol=1e-6, atol=1e-9, err_msg=channel)

    # .npz: everything, with a JSON table of units.
    npz = jc.io.write_output(tmp_path / "run.npz", run, names)
    with np.load(npz) as archive:
        units = json.loads(str(archive["units"]))
        for key, values, unit in [
            ("time", run.times, "s"),
            ("positions", run.positions, "m"),
            ("velocities", run.velocities, "m/s"),
            ("tension", run.tension, "N"),
            ("reactions", run.reactions, "N"),
        ]:
            np.testing.assert_array_equal(archive[key], values, err_msg=key)
            assert units[key] == unit
        np.testing.assert_array_equal(archive["constrained_nodes"], np.asarray(run.built.model.constrained_nodes))
        for channel in names:
            np.testing.assert_array_equal(archive[channel], expected[channel], err_msg=channel)

    # NetCDF 3 with units and dimensions on every variable.
    nc = jc.io.write_output(tmp_path / "run.nc", run, names)
    with netcdf_file(nc, "r", mmap=False) as f:
        for key, values, unit, dims in [
            ("time", run.times, "s", ("time",)),
            ("positions", run.positions, "m", ("time", "node", "xyz")),
            ("tension", run.tension, "N", ("time", "segment")),
            ("reactions", run.reactions, "N", ("time", "constrained", "xyz")),
        ]:
            variable = f.variables[key]
            np.testing.assert_array_equal(variable[:], values, err_msg=key)
            assert variable.units.decode() == unit and variable.dimensions == dims
        for channel in names:
            np.testing.assert_array_equal(f.variables[channel][:], expected[channel], err_msg=channel)


@pytest.mark.parametrize("name", cases(NAMES))
def test_run_starts_from_equilibrium_and_supports_follow_their_motions(name, runs):
    """The first output is the statics, and each support is where the file says: an
    anchor at its position, a coupled point at position + A sin(2πt/T + φ) e."""
    run = runs(name)
    np.testing.assert_allclose(run.positions[0], np.asarray(run.static.state.positions), rtol=0, atol=1e-12)
    np.testing.assert_allclose(run.tension[0], np.asarray(run.static.tension), rtol=1e-9)
    assert np.all(np.isfinite(run.tension)) and run.steps > 0
    for k, point in enumerate(toml(name)["points"].values()):
        expected = np.broadcast_to(np.array(point["position"], float), (run.times.size, 3))
        if "motion" in point:
            motion = point["motion"]
            assert motion["type"] == "harmonic"
            e = np.array(motion.get("direction", [1.0, 0.0, 0.0]), float)
            phase = 2 * np.pi * run.times / motion["period"] + motion.get("phase", 0.0)
            expected = expected + motion["amplitude"] * np.sin(phase)[:, None] * e / np.linalg.norm(e)
        if point["type"] != "free":
            np.testing.assert_allclose(run.positions[:, k], expected, rtol=0, atol=1e-9, err_msg=f"point {k}")


@pytest.mark.slow  # a second compile of the net, without waves: 23 s of the default suite
def test_undriven_net_stays_at_equilibrium():
    """buoy_net has no moving support: without its waves, started from its equilibrium
    in the current, it must stay there."""
    assert not any("motion" in p for p in toml("buoy_net")["points"].values())
    scene = jc.read_scene(examples.scene_path("buoy_net"))
    assert scene.water.waves
    calm_water = dataclasses.replace(scene.water, waves=())
    run = jc.run_scene(scene.replace(water=calm_water), duration=DURATION, dt_out=DT_OUT)
    drift = np.abs(run.tension - run.tension[0]).max()
    assert drift < 1e-3 * run.tension[0].max(), drift
    assert np.abs(run.positions - run.positions[0]).max() < 1e-4  # m


# ---------------------------------------------------------------------------------------
# Statics, checked with forces computed here from the TOML numbers.
# ---------------------------------------------------------------------------------------


def node_forces(name: str, run: jc.io.SceneRun) -> np.ndarray:
    """Every force on each node at the equilibrium except its support's, shape
    `(nodes, 3)`: segment tensions, wet weights, drag of the current, bodies."""
    data = toml(name)
    rho, g, current = water(data)
    assert run.static is not None  # these scenes solve statics
    x = np.asarray(run.static.state.positions)
    forces = np.zeros_like(x)
    for k, line in enumerate(data["lines"]):
        t = line_type(data, line["type"])
        nodes = run.built.line_nodes[k]
        a, b = nodes[:-1], nodes[1:]
        length = line["length"] / line["segments"]
        chord = x[b] - x[a]
        stretched = np.linalg.norm(chord, axis=1)
        tangent = chord / stretched[:, None]
        strain = stretched / length - 1
        # Taut beyond the slack switch's band, where the law is exactly C_E ε + C_E1 ε².
        assert np.all(strain > t["slack_width"]), f"line {k + 1} has a slack segment at equilibrium"
        pull = (t["EA"] * strain + t["EA1"] * strain**2)[:, None] * tangent
        np.add.at(forces, a, pull)
        np.add.at(forces, b, -pull)
        weight = (t["m"] - rho * t["F"]) * g * length
        np.add.at(forces[:, 2], a, -weight / 2)
        np.add.at(forces[:, 2], b, -weight / 2)
        u_t = (tangent @ current)[:, None] * tangent
        u_n = current - u_t
        drag = (
            0.5 * rho * t["Kn"] * t["d"] * np.linalg.norm(u_n, axis=1)[:, None] * u_n
            + 0.5 * rho * t["Kt"] * np.pi * t["d"] * np.linalg.norm(u_t, axis=1)[:, None] * u_t
        ) * stretched[:, None]
        np.add.at(forces, a, drag / 2)
        np.add.at(forces, b, drag / 2)
    for k, point in enumerate(data["points"].values()):
        forces[k, 2] -= (point.get("mass", 0.0) - rho * point.get("volume", 0.0)) * g
        forces[k] += 0.5 * rho * point.get("drag_area", 0.0) * np.linalg.norm(current) * current
    return forces


def total_wet_weight(data: dict) -> float:
    """Σ (m − ρF) g L over lines plus Σ (M − ρV) g over bodies (N), from the file alone."""
    rho, g, _ = water(data)
    types = {name: line_type(data, name) for name in data["line_types"]}
    lines = sum(
        (types[line["type"]]["m"] - rho * types[line["type"]]["F"]) * g * line["length"] for line in data["lines"]
    )
    bodies = sum((p.get("mass", 0.0) - rho * p.get("volume", 0.0)) * g for p in data["points"].values())
    return lines + bodies


CALM = [n for n in NAMES if calm(toml(n))]


@pytest.mark.parametrize("name", cases(CALM))
def test_statics_global_balance(name, runs):
    """The supports carry the wet weight of everything, less the current's drag."""
    data = toml(name)
    run = runs(name)
    reactions = np.asarray(run.static.reactions)
    weight = total_wet_weight(data)
    forces = node_forces(name, run)
    # Drag alone: all node forces with no tension (which cancels) and no weight.
    _, _, current = water(data)
    drag = forces.sum(axis=0) + [0.0, 0.0, weight]
    if not np.any(current):
        np.testing.assert_allclose(drag, 0.0, atol=1e-9 * abs(weight))
    else:
        assert drag @ current > 0  # drag acts downstream
    scale = np.abs(reactions).max()
    np.testing.assert_allclose(reactions.sum(axis=0), [0.0, 0.0, weight] - drag, rtol=0, atol=1e-8 * scale)


@pytest.mark.parametrize("name", cases(CALM))
def test_statics_node_balance(name, runs):
    """Every free node is in equilibrium, and each support's reaction is what holds
    its node, with forces computed from the file's numbers and the positions."""
    run = runs(name)
    model = run.built.model
    forces = node_forces(name, run)
    scale = run.static.tension.max()
    free, constrained = np.asarray(model.free_nodes), np.asarray(model.constrained_nodes)
    np.testing.assert_allclose(forces[free], 0.0, rtol=0, atol=1e-7 * scale)
    np.testing.assert_allclose(np.asarray(run.static.reactions), -forces[constrained], rtol=0, atol=1e-7 * scale)


STILL_WATER = [n for n in CALM if not np.any(water(toml(n))[2])]


@pytest.mark.parametrize("name", cases(STILL_WATER))
def test_still_water_lines_are_elastic_catenaries(name, runs):
    """Each line between its equilibrium end points is the continuum's catenary: the
    segment tensions are its tension at mid-segment, the nodes lie on it."""
    assert {"anchored_line", "y_branch"} <= set(STILL_WATER)
    data = toml(name)
    rho, g, _ = water(data)
    run = runs(name)
    x = np.asarray(run.static.state.positions)
    tension = np.asarray(run.static.tension)
    for k, line in enumerate(data["lines"]):
        t = line_type(data, line["type"])
        nodes, segments = run.built.line_nodes[k], run.built.line_segments[k]
        n, length = line["segments"], line["length"]
        a, b = x[nodes[0]], x[nodes[-1]]
        across = np.r_[(b - a)[:2], 0.0]
        span = np.linalg.norm(across)
        chord = x[nodes[1]] - a  # the engine's first segment: only a starting guess
        guess = tension[segments[0]] * np.array([np.linalg.norm(chord[:2]), chord[2]]) / np.linalg.norm(chord)
        catenary = ElasticCatenary(length, (t["m"] - rho * t["F"]) * g, t["EA"], t["EA1"], span, b[2] - a[2], guess)
        mid = (np.arange(n) + 0.5) * length / n
        # The polyline differs from the continuum at O((l/R)²) (l the segment, R = T/w
        # the radius of curvature). The checks are tighter than what a wrong definition
        # would give: tension within 0.3 w l / T (relative) is closer to mid-segment than
        # to either end (FairTen is the end segment's tension, not the end's), and nodes
        # within 0.1 l²/R lie on the curve closer than a segment's own sag, l²/8R.
        w, segment = abs((t["m"] - rho * t["F"]) * g), length / n
        radius = tension[segments].min() / w
        np.testing.assert_allclose(
            tension[segments], catenary.tension(mid), rtol=0.3 * segment / radius, err_msg=f"line {k + 1}"
        )
        shape = np.array([catenary.position(s) for s in np.arange(n + 1) * segment])
        # A vertical line (irregular_buoy's tether) spans nothing: its nodes lie on the
        # vertical through its ends.
        along = (x[nodes] - a)[:, :2] @ (across[:2] / span if span > 0 else np.zeros(2))
        sag = segment**2 / radius
        np.testing.assert_allclose(along, shape[:, 0], rtol=0, atol=0.1 * sag, err_msg=f"line {k + 1}")
        np.testing.assert_allclose(x[nodes, 2] - a[2], shape[:, 1], rtol=0, atol=0.1 * sag, err_msg=f"line {k + 1}")


@pytest.mark.slow  # 35 s of the default suite
def test_buoy_net_waves_are_ramped_on(runs):
    """buoy_net's wave grows from nothing over [water] wave_ramp by the smoothstep
    s³(6s² − 15s + 10) (s = t / ramp, as a harmonic motion's ramp): the water's
    velocity less the current is that times
    Airy's, computed here from the file's H, T and depth; and 1 s in, the net has
    hardly moved."""
    data = toml("buoy_net")
    ramp, depth = data["water"]["wave_ramp"], data["water"]["depth"]
    (wave,) = data["waves"]
    assert wave["theory"] == "airy" and wave.get("heading", 0.0) == 0.0 and wave.get("phase", 0.0) == 0.0
    omega = 2 * np.pi / wave["period"]
    k = fsolve(lambda k: 9.81 * k * np.tanh(k * depth) - omega**2, omega**2 / 9.81, xtol=1e-14)[0]
    env = jc.read_scene(examples.scene_path("buoy_net")).build().environment
    current = np.array(data["water"]["current"])
    x, z = 3.0, -7.6  # m, near the middle float
    for t in (0.0, 1.0, 4.0, ramp, ramp + 3.0):
        s = min(t / ramp, 1.0)
        amplitude = s**3 * (6 * s**2 - 15 * s + 10) * omega * wave["height"] / 2 / np.sinh(k * depth)
        phase = k * x - omega * t
        airy = amplitude * np.array(
            [np.cosh(k * (z + depth)) * np.cos(phase), 0.0, np.sinh(k * (z + depth)) * np.sin(phase)]
        )
        got = np.asarray(env.water_velocity(np.array([x, 0.0, z]), t)) - current
        np.testing.assert_allclose(got, airy, rtol=0, atol=1e-9, err_msg=f"t = {t}")
    run = runs("buoy_net")
    # 1 s in, the ramp is at 1.6 %; the full wave heaves the middle float by ±0.46 m.
    assert np.abs(run.positions - run.positions[0]).max() < 0.05  # m


def test_wave_mooring_chain_rests_on_the_seabed(runs):
    """The lying chain's nodes carry their wet weight w l on the bed's spring k δ d l
    (contact area d per length, MoorDyn's kBot convention): δ = w / (k d). The wave's
    flow on the bed is horizontal, along the lying chain, so it does not change that."""
    data = toml("wave_mooring")
    rho, g, _ = water(data)
    assert data["waves"] and data["seabed"]
    t = line_type(data, "chain")
    depth, stiffness = data["water"]["depth"], data["seabed"]["stiffness"]
    run = runs("wave_mooring")
    z = np.asarray(run.static.state.positions)[run.built.line_nodes[0], 2]
    lying = np.flatnonzero(z < -depth)
    # The chain lies from the anchor over about half its length (header: 13 of 26 nodes).
    assert lying[0] == 1 and 10 <= lying.size <= 16 and np.all(np.diff(lying) == 1)  # node 0: the anchor, at -d
    inner = lying[1:-2]  # away from the anchor and from the touchdown's bend
    penetration = -depth - z[inner]
    np.testing.assert_allclose(penetration, (t["m"] - rho * t["F"]) * g / (stiffness * t["d"]), rtol=1e-4)
    # The suspended part rises to the buoy, the top segment the most loaded.
    tension = np.asarray(run.static.tension)[run.built.line_segments[0]]
    assert np.argmax(tension) == tension.size - 1


def test_anchored_line_file_is_its_builder():
    built = jc.read_scene(examples.scene_path("anchored_line")).build()
    model, env = examples.anchored_line(20, 30, 0.1)
    ours = built.model

    def close(a, b, what):
        np.testing.assert_allclose(np.asarray(a), np.asarray(b), rtol=1e-12, atol=0, err_msg=what)

    close(ours.node_positions, model.node_positions, "node_positions")
    close(ours.segment_length, model.segment_length, "segment_length")
    np.testing.assert_array_equal(ours.segment_nodes, model.segment_nodes)
    np.testing.assert_array_equal(ours.constrained_nodes, model.constrained_nodes)
    for field in (
        "mass_per_length",
        "diameter",
        "area",
        "normal_drag",
        "tangential_drag",
        "normal_added_mass",
        "tangential_added_mass",
    ):
        close(getattr(ours.line, field), getattr(model.line, field), field)
    # The file's law is Kelvin–Voigt with no damping; the builder's is NonlinearElastic.
    law, reference = ours.line.tension_law, model.line.tension_law
    close(law.axial_stiffness, reference.axial_stiffness, "axial_stiffness")
    close(law.quadratic_stiffness(), reference.quadratic_stiffness(), "quadratic_stiffness")
    close(law.slack_width, reference.slack_width, "slack_width")
    np.testing.assert_array_equal(law.damping(), 0.0)
    assert [type(m) for m in ours.motions] == [type(m) for m in model.motions]
    ours_leaves, reference_leaves = jax.tree.leaves(ours.motions), jax.tree.leaves(model.motions)
    assert len(ours_leaves) == len(reference_leaves) == 5  # Harmonic: A, T, e, φ, ramp
    for a, b in zip(ours_leaves, reference_leaves):
        close(a, b, "motions")
    for a, b in zip(jax.tree.leaves(ours.body), jax.tree.leaves(model.body)):
        close(a, b, "body")
    assert ours.mass_matrix == model.mass_matrix
    for field in ("water_density", "gravity", "current"):
        close(getattr(built.environment, field), getattr(env, field), field)


# ---------------------------------------------------------------------------------------
# The command line on bundled examples.
# ---------------------------------------------------------------------------------------


def test_cli_run_bundled_example(runs, tmp_path, capsys):
    csv, png = tmp_path / "o.csv", tmp_path / "o.png"
    status = main(["run", "y_branch", "--duration", "1", "--out", str(csv), "--plot", str(png), "--no-progress"])
    captured = capsys.readouterr()
    assert status == 0, captured.err
    assert csv.exists() and png.exists() and png.stat().st_size > 10_000
    summary, timing = captured.out.strip().splitlines()[-2:]
    assert "peak tension" in summary and summary.startswith("simulated 1.000 s from equilibrium")
    assert timing.startswith("wall time") and "statics" in timing and "compile" in timing
    # y_branch.toml names no channels: every line's end tensions, at the file's dt_out,
    # the same numbers as the library's own run.
    lines = len(toml("y_branch")["lines"])
    table = np.genfromtxt(csv, delimiter=",", names=True)
    assert table.dtype.names == ("Time", *(f"{e}{k}" for k in range(1, lines + 1) for e in ("FairTen", "AnchTen")))
    expected = expected_channels("y_branch", runs("y_branch"))
    for channel in table.dtype.names:
        np.testing.assert_allclose(table[channel], expected[channel], rtol=1e-9, atol=1e-9, err_msg=channel)
    peak = runs("y_branch").tension.max()
    assert f"peak tension {peak / 1e3:.3f} kN" in summary


@pytest.mark.slow
def test_cli_info_bundled_example(capsys):
    assert main(["info", "buoy_net"]) == 0
    out = capsys.readouterr().out
    data = toml("buoy_net")
    points, lines = data["points"], data["lines"]
    nodes = len(points) + sum(line["segments"] - 1 for line in lines)
    free = sum(p["type"] == "free" for p in points.values()) + sum(line["segments"] - 1 for line in lines)
    segments = sum(line["segments"] for line in lines)
    assert f"model: {nodes} nodes ({free} free), {segments} segments, lumped mass matrix" in out
    assert "buoy_net.toml" in out and "current (0.5, 0.0, 0.0) m/s" in out
    for name in points:
        assert f"  {name} (" in out
    for line in lines:
        assert f"  {line['name']}: {line['type']} from {line['from']} to {line['to']}" in out
    assert "advice:" in out and "stiffest axial mode" in out


def test_cli_info_on_the_sea(capsys):
    """wave_mooring's sea and the advice on it, against its file's numbers: the Ursell
    number from the dispersion relation solved here, KC from Airy's surface speed."""
    assert main(["info", "wave_mooring"]) == 0
    out = capsys.readouterr().out
    data = toml("wave_mooring")
    (wave,) = data["waves"]
    h, period, depth = wave["height"], wave["period"], data["water"]["depth"]
    assert f"wave 1: airy, H = {h:g} m, T = {period:g} s, heading 0°" in out
    assert f"seabed: at z = -{depth:g} m, stiffness 3e+06 Pa/m, damping 300000 Pa·s/m, friction μ = 0.5" in out
    omega = 2 * np.pi / period
    k = fsolve(lambda k: 9.81 * k * np.tanh(k * depth) - omega**2, omega**2 / 9.81, xtol=1e-14)[0]
    wavelength = 2 * np.pi / k
    assert f"U = Hλ²/d³ = {h * wavelength**2 / depth**3:.3g}" in out and "Airy fits, which it uses" in out
    speed = omega * h / 2 / np.tanh(k * depth)  # at the surface, where the buoy holds the chain
    diameter = data["line_types"]["chain"]["diameter"]
    assert f"KC = uT/D = {speed * period / diameter:.3g}" in out and "drag dominates" in out
    assert "fluid_inertia = false" in out and "no slack quasi-statically" in out
    # The chain's natural periods, and the wave near one of them: an undamped
    # oscillator's amplification 1/|1 − (T_n/T)²| from the periods it prints.
    listed = re.search(r"natural periods of the mooring about its mean equilibrium \(.*?\): ([0-9., ]+) s", out)
    assert listed is not None
    periods = [float(p) for p in listed[1].split(", ")]
    nearest = max(periods, key=lambda p: 1 / abs(1 - (p / period) ** 2))
    gain = 1 / abs(1 - (nearest / period) ** 2)
    near = re.search(r"is near the natural period ([0-9.]+) s: .*?= ([0-9.]+) times", out)
    assert gain >= 2 and near is not None and float(near[1]) == nearest
    assert float(near[2]) == pytest.approx(gain, rel=0.02)  # from periods printed to 3 digits
    assert "design check's most probable maximum tension needs an irregular sea" in out


def test_cli_statics_only(runs, tmp_path, capsys):
    npz = tmp_path / "s.npz"
    assert main(["run", "anchored_line", "--duration", "0", "--out", str(npz), "--no-progress"]) == 0
    assert capsys.readouterr().out.strip().splitlines()[-2].startswith("statics only; peak tension")
    static = runs("anchored_line").static
    with np.load(npz) as archive:
        np.testing.assert_array_equal(archive["time"], [0.0])
        positions = np.asarray(static.state.positions)[None]
        np.testing.assert_allclose(archive["positions"], positions, rtol=1e-12, atol=1e-12)
        np.testing.assert_array_equal(archive["velocities"], 0.0)
        np.testing.assert_allclose(archive["tension"], np.asarray(static.tension)[None], rtol=1e-10)
        np.testing.assert_allclose(archive["reactions"], np.asarray(static.reactions)[None], rtol=1e-10, atol=1e-9)
        np.testing.assert_allclose(archive["FairTen1"], [static.tension[-1]], rtol=1e-10)


def test_cli_out_writes_the_scenes_channels(tmp_path, capsys):
    """With no --channels, --out writes the channels the scene file's [output] names."""
    csv = tmp_path / "s.csv"
    assert main(["run", "anchored_line", "--duration", "0", "--out", str(csv), "--no-progress"]) == 0
    capsys.readouterr()
    assert csv.read_text().splitlines()[0] == "Time," + ",".join(toml("anchored_line")["output"]["channels"])


def test_run_settings_name_a_solver_configuration():
    """A scene's solver name and tolerances become the `SolverConfig` that runs it; an
    unknown name fails with the choices, from Python as from a file."""
    config = jc.io.RunSettings(solver="kvaerno5", rtol=1e-7, atol=1e-8).solver_config()
    assert isinstance(config.solver, diffrax.Kvaerno5)
    assert float(config.stepsize_controller.rtol) == 1e-7 and float(config.stepsize_controller.atol) == 1e-8
    scene = jc.read_scene(examples.scene_path("anchored_line"))
    bad = scene.replace(run=dataclasses.replace(scene.run, solver="rk5"))
    with pytest.raises(jc.io.SceneError, match=r"solver must be one of \('dopri5'.*, got 'rk5'"):
        jc.run_scene(bad, duration=0.1)


def test_cli_solver_runs_the_named_configuration_at_the_scenes_tolerances(tmp_path, capsys):
    """`--solver tsit5` gives the same tensions as the library's run with
    `SOLVERS["tsit5"]` at the scene file's tolerances."""
    npz = tmp_path / "t.npz"
    argv = ["run", "anchored_line", "--duration", "0.2", "--dt-out", "0.05", "--solver", "tsit5", "--out", str(npz)]
    assert main([*argv, "--no-progress"]) == 0, capsys.readouterr().err
    scene = jc.read_scene(examples.scene_path("anchored_line"))
    config = jc.SOLVERS["tsit5"](rtol=scene.run.rtol, atol=scene.run.atol)
    run = jc.run_scene(scene, duration=0.2, dt_out=0.05, solver=config)
    with np.load(npz) as archive:
        np.testing.assert_allclose(archive["tension"], run.tension, rtol=1e-12, atol=1e-9)


# ---------------------------------------------------------------------------------------
# Fixed steps (MoorDyn's dtM): honoured where the method is stable at the scene's fastest
# modes, replaced by adaptive steps with a note where it is not.


def anchored_line_scene(damping_ratio: float = 0.0, **run) -> jc.io.Scene:
    scene = jc.read_scene(examples.scene_path("anchored_line"))
    rope = dataclasses.replace(scene.line_types[0], axial_damping_ratio=damping_ratio)
    return scene.replace(line_types=(rope,), run=dataclasses.replace(scene.run, **run))


def test_a_damped_scene_takes_its_fixed_steps():
    scene = anchored_line_scene(0.5, solver="midpoint", dt=2e-3)
    run = jc.run_scene(scene, duration=0.2, dt_out=0.05)
    assert run.steps == 100 and run.stepping == "Midpoint, fixed steps of 0.002 s"
    assert not any("stability" in note for note in run.notes)
    assert "in 100 steps (Midpoint, fixed steps of 0.002 s)" in run.summary()


def test_fixed_steps_beyond_the_stability_limit_are_replaced_by_stable_ones():
    # Undamped, the axial mode grows under any two-stage step; damped at ζ = 0.5
    # (ω_n = 514 rad/s with the consistent mass matrix) |R| is 0.35 a step at 2 ms, as
    # above, and 1.63 at 5 ms. RK4 at 0.7 of its own limit takes their place.
    for scene in (
        anchored_line_scene(0.0, solver="midpoint", dt=2e-3),
        anchored_line_scene(0.5, solver="midpoint", dt=5e-3),
    ):
        run = jc.run_scene(scene, duration=0.2, dt_out=0.05)
        stable = jc.fixed_steps([(run.built.model, run.built.environment)], 0.2)
        assert run.stepping == f"RK4, fixed steps of {float(stable.dt0):g} s"  # pyright: ignore[reportArgumentType]
        (note,) = [note for note in run.notes if "stability" in note]
        assert "beyond Midpoint's stability limit here" in note and f"stepped with {run.stepping} instead" in note


def test_fixed_steps_past_max_steps_are_replaced_by_adaptive_ones():
    run = jc.run_scene(anchored_line_scene(0.5, solver="midpoint", dt=2e-3, max_steps=99), duration=0.2, dt_out=0.05)
    assert run.stepping.startswith("Dopri5, adaptive")
    assert any("would take 100 steps, more than max_steps = 99" in note for note in run.notes)


def test_a_scene_that_names_no_solver_steps_auto_and_tolerances_ask_for_dopri5(tmp_path, capsys):
    """Told no solver a scene takes `auto`: RK4 at the fixed step `jc.fixed_steps`
    chooses for it. Tolerances without a solver ask for adaptive Dopri5; with `auto`
    named, the file's key and the flags are refused, as they would be lost."""
    text = examples.scene_path("anchored_line").read_text(encoding="utf-8")
    path = tmp_path / "line.toml"
    path.write_text(text)
    scene = jc.read_scene(path)
    assert scene.run.solver == "auto"
    built = scene.build()
    config = scene.run.solver_config(built, 2.0)
    stable = jc.fixed_steps([(built.model, built.environment)], 2.0)
    assert isinstance(config.solver, jc.RK4) and float(config.dt0) == float(stable.dt0)  # pyright: ignore[reportArgumentType]
    path.write_text(text.replace("[simulation]", "[simulation]\nrtol = 1e-8"))
    run = jc.read_scene(path).run
    assert (run.solver, run.rtol) == ("dopri5", 1e-8)
    path.write_text(text.replace("[simulation]", '[simulation]\nsolver = "auto"\natol = 1e-8'))
    with pytest.raises(jc.io.SceneError, match=r'simulation.atol: sets adaptive steps, but solver "auto" takes fixed'):
        jc.read_scene(path)
    path.write_text(text)
    assert main(["run", str(path), "--duration", "0.1", "--rtol", "1e-7", "--no-progress"]) == 2
    assert "--rtol and --atol set adaptive steps, but solver auto takes fixed steps" in capsys.readouterr().err
    assert main(["run", str(path), "--duration", "0.1", "--adaptive", "--no-progress"]) == 0
    assert "(Dopri5, adaptive (rtol 1e-06, atol 1e-06))" in capsys.readouterr().out


def test_scene_file_fixed_step_and_max_steps(tmp_path):
    text = examples.scene_path("anchored_line").read_text(encoding="utf-8")
    path = tmp_path / "fixed.toml"
    path.write_text(text.replace("[simulation]", '[simulation]\nsolver = "heun"\ndt = 0.001\nmax_steps = 5000'))
    run = jc.read_scene(path).run
    assert (run.solver, run.dt, run.max_steps) == ("heun", 0.001, 5000)
    config = run.solver_config()
    assert isinstance(config.solver, diffrax.Heun) and isinstance(config.stepsize_controller, diffrax.ConstantStepSize)
    assert float(config.dt0) == 0.001 and config.max_steps == 5000
    for bad, message in (("dt = 0.0", "simulation.dt: must be positive"), ("max_steps = 1.5", "expected an integer")):
        path.write_text(text.replace("[simulation]", f"[simulation]\n{bad}"))
        with pytest.raises(jc.io.SceneError, match=message):
            jc.read_scene(path)


@pytest.mark.parametrize(
    "flags, message",
    [
        (["--dt", "0"], "--dt must be a positive number, got 0"),
        (["--rtol=-1e-6"], "--rtol must be a positive number"),
        (["--max-steps", "0"], "--max-steps must be a positive integer, got 0"),
        (["--dt", "0.001", "--adaptive"], "give one of them"),
        (["--dt", "0.001", "--rtol", "1e-5"], r"fixed steps of 0.001 s \(--dt\): add --adaptive"),
    ],
)
def test_cli_stepping_flags_are_checked_before_running(flags, message, capsys):
    assert main(["run", "anchored_line", "--duration", "0.1", "--no-progress", *flags]) == 2
    assert re.search(message, capsys.readouterr().err)


def test_cli_fixed_step_beyond_the_limit_warns_and_takes_a_stable_one(capsys):
    status = main(
        ["run", "anchored_line", "--duration", "0.1", "--solver", "midpoint", "--dt", "0.002", "--no-progress"]
    )
    out, err = capsys.readouterr()
    assert status == 0, err
    assert "warning: fixed steps of 0.002 s are beyond Midpoint's stability limit here" in err
    built = jc.load_scene(examples.scene_path("anchored_line")).build()
    stable = jc.fixed_steps([(built.model, built.environment)], 0.1)
    assert f"(RK4, fixed steps of {float(stable.dt0):g} s)" in out.splitlines()[-2]  # pyright: ignore[reportArgumentType]


def test_cli_runs_xla_on_one_kernel_thread_unless_told_otherwise(monkeypatch):
    """A single run's kernels are too small to gain from XLA's thread pool, so the
    command sets `PJRT_NPROC=1` before the backend starts, and keeps a caller's value."""
    from jaxcable._cli import _one_kernel_thread

    monkeypatch.delenv("PJRT_NPROC", raising=False)
    _one_kernel_thread()
    assert os.environ["PJRT_NPROC"] == "1"
    monkeypatch.setenv("PJRT_NPROC", "4")
    _one_kernel_thread()
    assert os.environ["PJRT_NPROC"] == "4"
