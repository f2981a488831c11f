"""Sweeps: a vmapped batch equals its single runs, a failing case stays its own, and
sharding the batch across devices changes nothing but where it runs."""

import functools
import math
import os
import subprocess
import sys
import textwrap

import diffrax
import equinox as eqx
import jax
import jax.numpy as jnp
import numpy as np
import pytest

import jaxcable as jc
from jaxcable import sweep, sweep_grid
from jaxcable._solver.stability import STEP_FRACTION, stable_step
from jaxcable.examples import anchored_line

T1 = 1.0
TS = np.linspace(0.0, T1, 21)
# Cases 0 and 1 take 122 and 169 steps; case 2, a hundred times stiffer, needs 1,163
# (explicit steps are stability-limited there), so it runs out of steps. Case 3's
# segments are a billionth of their length: the line would have to stretch 1e11 % to
# reach its ends, which statics refuse (eagerly before solving; in a batch, as a
# failed case). Case 4's stiffness is negative, which its constructor, under vmap,
# could not see. Case 5's segments are 5 % longer than the straight guess: every
# segment is slack, with no stiffness to move it, and the damped pseudo-time steps
# (inside the batch as in a single call) let it sag to the equilibrium.
MAX_STEPS = 400
CASES = {"stiffness_scale": [1.0, 2.0, 100.0, 1.0, -1.0, 1.0], "stretch": [1.0, 0.999, 1.0, 1e-9, 1.0, 1.05]}


@functools.cache
def base():
    return anchored_line(n_segments=4, mass_matrix="lumped")


def build(stiffness_scale, stretch):
    """The anchored line with C_E scaled and the unstretched lengths scaled: float
    leaves replaced with `eqx.tree_at`, as a sweep over a prebuilt model does."""
    model, env = base()
    law = model.line.tension_law
    model = eqx.tree_at(
        lambda m: (m.line.tension_law.axial_stiffness, m.segment_length),
        model,
        (law.axial_stiffness * stiffness_scale, model.segment_length * stretch),
    )
    return model, env


@pytest.fixture(scope="module")
def swept():
    return sweep(build, CASES, T1, ts=TS, solver=jc.SolverConfig(max_steps=MAX_STEPS))


def case(i):
    return {k: v[i] for k, v in CASES.items()}


@pytest.mark.parametrize("i", [0, 1, 5])
def test_sweep_equals_single_runs(swept, i):
    model, env = build(**case(i))
    # The equilibrium found inside the batch is one: the forces on the free nodes at
    # rest vanish, relative to a segment's weight (an independent check of the
    # batched statics, which never sees this eagerly built model).
    positions = swept.statics.state.positions[i]
    forces = jc.equations.generalised_forces(model, env, 0.0, positions, jnp.zeros_like(positions))[model.free_nodes]
    weight = float(model.line.mass_per_length[0] * env.gravity * model.segment_length[0])
    assert float(jnp.max(jnp.abs(forces))) < 1e-6 * weight
    assert float(swept.statics.residual[i]) < 1e-6 * weight

    config = jc.SolverConfig(max_steps=MAX_STEPS)
    single = jc.simulate(model, env, T1, ts=TS, initial=jc.State(positions, jnp.zeros_like(positions)), solver=config)
    assert bool(single.success) and bool(swept.success[i])
    one = swept.case(i)
    np.testing.assert_allclose(one.tension, single.tension, rtol=1e-8)
    np.testing.assert_allclose(one.positions, single.positions, rtol=1e-10, atol=1e-9)
    np.testing.assert_allclose(one.times, TS)
    assert int(one.stats["num_steps"]) == int(single.stats["num_steps"])
    np.testing.assert_allclose(swept.peak_tension[i], np.max(single.tension), rtol=1e-8)
    # Eager statics finds the same.
    np.testing.assert_allclose(positions, jc.solve_statics(model, env).state.positions, rtol=1e-9, atol=1e-9)
    # The two cases really differ (a build that ignored its parameters would not).
    assert abs(float(swept.peak_tension[1] / swept.peak_tension[0]) - 1) > 0.5


def test_a_sweep_reads_as_a_simulation(swept):
    """The fields of `SimulationResult` are the sweep's too, case axis first."""
    for name in ("times", "positions", "velocities", "strain", "tension", "reactions", "stats", "result"):
        ours, theirs = getattr(swept, name), getattr(swept.simulation, name)
        assert jax.tree.structure(ours) == jax.tree.structure(theirs), name
        for a, b in zip(jax.tree.leaves(ours), jax.tree.leaves(theirs)):
            np.testing.assert_array_equal(a, b)
    assert swept.tension.shape == (6, len(TS), 4)


def test_a_tuple_of_swept_scalars_is_an_array():
    """`current=(c, 0.0, 0.0)`, as the README writes it, with `c` traced (a sweep's
    `vmap`, a derivative)."""
    currents = jax.vmap(lambda c: jc.Environment(current=(c, 0.0, 0.0)).current)(jnp.array([0.1, 0.2]))
    np.testing.assert_array_equal(currents, [[0.1, 0.0, 0.0], [0.2, 0.0, 0.0]])
    assert float(jax.grad(lambda c: jc.Environment(current=[0.0, 2.0 * c, 0.0]).current[1])(0.3)) == 2.0


@pytest.mark.unchecked  # jaxtyping's checker would refuse the string first, by annotation
def test_a_tuple_with_a_word_among_traced_scalars_is_refused_by_name():
    with pytest.raises(ValueError, match="Environment.current must be a number or an array of numbers"):
        jax.vmap(lambda c: jc.Environment(current=(c, "east", 0.0)))(jnp.array([0.1]))


def test_failures_are_reported_per_case(swept):
    assert swept.n_cases == 6
    np.testing.assert_array_equal(swept.success, [True, True, False, False, False, True])
    np.testing.assert_array_equal(swept.failed, [2, 3, 4])
    assert swept.status[:2] == ("successful", "successful")
    assert swept.status[2].startswith("The maximum number of solver steps was reached")
    assert f"after {MAX_STEPS} steps" in swept.status[2]
    assert bool(swept.case(2).result == diffrax.RESULTS.max_steps_reached)
    # diffrax's convention after a failure: states past it are inf (so the tensions
    # computed from them are not finite), those before are kept.
    tension, positions = np.asarray(swept.simulation.tension[2]), np.asarray(swept.simulation.positions[2])
    assert np.all(np.isfinite(tension[0])) and not np.any(np.isfinite(tension[-1]))
    assert np.all(np.isinf(positions[-1][np.asarray(base()[0].free_nodes)]))
    # Case 3's statics failed: reported as such, never integrated, inf throughout.
    assert swept.status[3].startswith(
        "statics failed: solve_statics: the segments between two constrained nodes must stretch 1e+11 %"
    )
    assert bool(swept.case(3).result == diffrax.RESULTS.nonlinear_divergence)
    assert int(swept.simulation.stats["num_steps"][3]) == 0
    assert np.all(np.isinf(np.asarray(swept.simulation.tension[3])))
    assert np.all(np.isnan(np.asarray(swept.peak_tension[2:5])))
    rows = {line.split("|")[1].strip(): line for line in swept.summary().splitlines() if line.startswith("| ")}
    assert "statics failed" in rows["3"]
    # Case 4's values are invalid: reported with the field and value, never integrated,
    # inf throughout, its statics too (they were computed with a valid case's values).
    law = base()[0].line.tension_law
    assert swept.status[4] == (
        "invalid input: case 4: LineType.tension_law.axial_stiffness must be positive, got "
        f"{-float(law.axial_stiffness[0])}"
    )
    assert bool(swept.case(4).result == diffrax.RESULTS.nonfinite_input)
    assert int(swept.simulation.stats["num_steps"][4]) == 0
    assert np.all(np.isinf(np.asarray(swept.simulation.tension[4])))
    assert np.all(np.isinf(np.asarray(swept.statics.tension[4])))
    with pytest.raises(IndexError, match="out of range for 6 cases"):
        swept.case(6)


def test_every_case_invalid_is_an_error():
    with pytest.raises(
        ValueError,
        match="every case is invalid; invalid input: case 0: LineType.tension_law.axial_stiffness must be positive",
    ):
        sweep(build, {"stiffness_scale": [-1.0, -2.0], "stretch": [1.0, 1.0]}, T1, ts=TS)


def test_shared_steps_agree_with_own_steps_to_the_tolerance(swept):
    """`steps="shared"`: one step for the batch, the smallest any case needs. The cases
    that succeed alone agree with their own-step results to the solver's tolerance (not
    to rounding: the steps differ), every case counts the same steps, at least as many
    as the case that needs most, and the invalid and statics-failed cases are reported
    as before without moving or holding back the others. The stiff case 2 is left out:
    with shared steps it would fail the whole batch (as documented)."""
    cases = [0, 1, 3, 4, 5]
    subset = {k: [v[i] for i in cases] for k, v in CASES.items()}
    config = jc.SolverConfig(max_steps=MAX_STEPS)
    shared = sweep(build, subset, T1, ts=TS, solver=config, steps="shared", chunks=1)
    np.testing.assert_array_equal(shared.success, [True, True, False, False, True])
    assert shared.status[2].startswith("statics failed") and shared.status[3].startswith("invalid input: case 3")
    steps = np.asarray(shared.simulation.stats["num_steps"])
    own = np.asarray(swept.simulation.stats["num_steps"])
    assert steps[0] == steps[1] == steps[4] >= max(own[0], own[1], own[5])
    for got, i in ((0, 0), (1, 1), (4, 5)):
        expected = np.asarray(swept.simulation.tension[i])
        scale = np.max(np.abs(expected))
        np.testing.assert_allclose(np.asarray(shared.simulation.tension[got]), expected, rtol=0, atol=1e-4 * scale)
    # Case 1 needs the most steps, so the shared steps are its own; case 0 takes more
    # steps than alone, and its history differs beyond rounding.
    assert steps[0] == own[1] > own[0]
    assert np.max(np.abs(np.asarray(shared.simulation.tension[0]) - np.asarray(swept.simulation.tension[0]))) > 1e-3


def test_default_chunks_are_two_a_core_where_each_keeps_sixteen_cases(monkeypatch):
    """On a CPU the default gives each core two chunks once every chunk would hold at
    least 16 cases, and one chunk a core below that (padding to a multiple of the
    chunks wastes up to a chunk's share less one); one chunk on other devices."""
    monkeypatch.setattr(jc._sweep.devices, "available_cores", lambda: 2)
    cpu = jax.devices("cpu")[:1]
    assert [jc._sweep.devices.check_chunks(None, cpu, n) for n in (1, 6, 63, 64, 256)] == [2, 2, 2, 4, 4]
    assert jc._sweep.devices.check_chunks(3, cpu, 256) == 3

    class Accelerator:
        platform = "gpu"

    assert jc._sweep.devices.check_chunks(None, [Accelerator()], 256) == 1


@pytest.mark.slow  # 24 s of the default suite
def test_chunks_equal_one_batch(swept, monkeypatch):
    """Chunks run on threads change where the cases run, not what they give: six cases
    in four chunks (padded to eight) equal `swept` (one case a chunk by default on one
    CPU device) and one chunk of six, case by case, status included."""
    calls = []
    split = jc._sweep.sweep.split

    def counted(per_case, chunks):
        parts = split(per_case, chunks)
        calls.append([len(part["valid"]) for part in parts])
        return parts

    monkeypatch.setattr(jc._sweep.sweep, "split", counted)
    config = jc.SolverConfig(max_steps=MAX_STEPS)
    four = sweep(build, CASES, T1, ts=TS, solver=config, chunks=4)
    one = sweep(build, CASES, T1, ts=TS, solver=config, chunks=1)
    assert calls == [[2, 2, 2, 2], [6]]
    for result in (four, one):
        assert result.status == swept.status and result.n_cases == 6
        np.testing.assert_array_equal(result.success, swept.success)
        np.testing.assert_array_equal(result.simulation.stats["num_steps"], swept.simulation.stats["num_steps"])
        ok = np.asarray(swept.success)
        np.testing.assert_allclose(result.simulation.tension[ok], swept.simulation.tension[ok], rtol=1e-8)
        np.testing.assert_allclose(result.statics.tension[ok], swept.statics.tension[ok], rtol=1e-9)


@pytest.mark.slow  # 26 s of the default suite
def test_cases_with_their_own_steps_run_in_turn_as_their_single_runs(monkeypatch):
    """On one CPU device, cases with their own adaptive steps are not batched: by
    default each is a chunk of its own, and each equals its single `simulate` run
    bitwise, steps included, over snap loads and slack (the anchored line over 3.5 s:
    over 2,000 steps each), where batched code rounds differently."""
    chunked = []
    split = jc._sweep.sweep.split

    def counted(per_case, chunks):
        chunked.append(chunks)
        return split(per_case, chunks)

    monkeypatch.setattr(jc._sweep.sweep, "split", counted)

    def amplitude_build(amplitude):
        model, env = anchored_line()
        top = list(np.asarray(model.constrained_nodes)).index(1)  # the fairlead's motion
        return eqx.tree_at(lambda m: m.motions[top].amplitude, model, amplitude), env

    amplitudes, ts = np.array([1.2, 2.0]), np.linspace(0.0, 3.5, 351)
    swept = sweep(
        amplitude_build, {"amplitude": amplitudes}, 3.5, ts=ts, solver=jc.SolverConfig(), devices=jax.devices("cpu")[:1]
    )
    assert chunked == [2]
    for i, amplitude in enumerate(amplitudes):
        single = jc.simulate(*amplitude_build(amplitude), t1=3.5, ts=ts)
        assert int(swept.stats["num_steps"][i]) == int(single.stats["num_steps"]) > 2000
        np.testing.assert_array_equal(swept.tension[i], single.tension)
        # The histories went slack: a sensitive window, where rounding would show.
        assert float(jnp.min(single.tension[:, -1])) == 0.0


@pytest.mark.slow  # four sweeps: 30 s of the default suite
def test_shared_steps_are_per_chunk():
    """With chunks, each chunk takes its own shared step: the same as a sweep of its
    cases alone. Case 1 needs more steps than case 0; apart, case 0 keeps its own."""
    config = jc.SolverConfig(max_steps=MAX_STEPS)
    pair = {k: v[:2] for k, v in CASES.items()}
    apart = sweep(build, pair, T1, ts=TS, solver=config, steps="shared", chunks=2)
    together = sweep(build, pair, T1, ts=TS, solver=config, steps="shared", chunks=1)
    for i in range(2):
        alone = sweep(build, {k: v[i : i + 1] for k, v in pair.items()}, T1, ts=TS, solver=config, steps="shared")
        np.testing.assert_allclose(apart.simulation.tension[i], alone.simulation.tension[0], rtol=1e-9)
        assert int(apart.simulation.stats["num_steps"][i]) == int(alone.simulation.stats["num_steps"][0])
    steps = np.asarray(apart.simulation.stats["num_steps"])
    assert steps[0] < steps[1] == int(together.simulation.stats["num_steps"][0])


@pytest.mark.parametrize(
    ("kwargs", "match"),
    [
        ({"steps": "joint"}, "sweep: steps must be one of"),
        ({"steps": "shared", "solver": jc.SolverConfig(diffrax.Kvaerno5())}, "takes an explicit solver, got Kvaerno5"),
    ],
)
def test_shared_steps_input_errors(kwargs, match):
    with pytest.raises(ValueError, match=match):
        sweep(build, GOOD, T1, ts=TS, **kwargs)


_SHARDED = textwrap.dedent(
    """
    import diffrax
    import equinox as eqx
    import jax
    import numpy as np
    from jaxcable import RK4, SolverConfig, sweep
    from jaxcable.examples import anchored_line

    assert len(jax.devices()) == 2, jax.devices()

    base, env = anchored_line(n_segments=4, mass_matrix="lumped")

    def build(amplitude, stiffness_scale):
        law = base.line.tension_law
        model = eqx.tree_at(
            lambda m: (m.motions[1].amplitude, m.line.tension_law.axial_stiffness),
            base,
            (amplitude, law.axial_stiffness * stiffness_scale),
        )
        return model, env

    options = dict(ts=np.linspace(0.0, 1.0, 11), initial="rest", solver=SolverConfig(max_steps=2000))
    odd = {"amplitude": [1.6, 0.8, 2.4], "stiffness_scale": [1.0, 2.0, 0.5]}
    both = sweep(build, odd, 1.0, **options)  # padded to 4 cases, 2 per device
    alone = sweep(build, odd, 1.0, devices=[jax.devices()[0]], **options)
    assert both.n_cases == alone.n_cases == 3
    assert both.simulation.tension.shape == alone.simulation.tension.shape == (3, 11, 4)
    assert all(both.success) and all(alone.success), (both.status, alone.status)
    np.testing.assert_allclose(both.simulation.tension, alone.simulation.tension, rtol=1e-9)
    np.testing.assert_allclose(both.simulation.positions, alone.simulation.positions, rtol=1e-12, atol=1e-9)
    np.testing.assert_array_equal(both.simulation.stats["num_steps"], alone.simulation.stats["num_steps"])
    assert len(set(np.asarray(alone.peak_tension).round())) == 3  # the cases differ
    assert alone.simulation.tension.sharding.device_set == {jax.devices()[0]}

    # Four cases need no padding (and reuse the compiled batch): the outputs stay
    # split by case, two on each device.
    even = {k: v + [v[0]] for k, v in odd.items()}
    split = sweep(build, even, 1.0, **options)
    tension = split.simulation.tension
    assert tension.sharding.device_set == set(jax.devices()), tension.sharding
    assert not tension.sharding.is_fully_replicated, tension.sharding
    assert sorted(s.data.shape[0] for s in tension.addressable_shards) == [2, 2]
    np.testing.assert_allclose(tension[:3], alone.simulation.tension, rtol=1e-9)
    np.testing.assert_allclose(tension[3], tension[0], rtol=1e-12)

    # Two chunks on threads, each split across both devices: the same cases, still split.
    chunked = sweep(build, even, 1.0, chunks=2, **options).simulation.tension
    assert sorted(s.data.shape[0] for s in chunked.addressable_shards) == [2, 2]
    np.testing.assert_allclose(chunked, tension, rtol=1e-9)

    # One shared step for the batch across both devices: the largest that every case's
    # error allows, agreed between the devices at each step.
    both = sweep(build, odd, 1.0, steps="shared", **options)
    alone = sweep(build, odd, 1.0, steps="shared", devices=[jax.devices()[0]], chunks=1, **options)
    assert all(both.success), both.status
    np.testing.assert_array_equal(both.simulation.stats["num_steps"], alone.simulation.stats["num_steps"])
    np.testing.assert_allclose(both.simulation.tension, alone.simulation.tension, rtol=1e-9)

    # Fixed steps, which mask no case, and a shared equilibrium (the stiffness scale is
    # the same in every case, the amplitude does not move the top at t = 0), split
    # across both devices as on one.
    fixed = SolverConfig(RK4(), dt0=0.01, stepsize_controller=diffrax.ConstantStepSize())
    same = {"amplitude": odd["amplitude"], "stiffness_scale": [1.0, 1.0, 1.0]}
    both = sweep(build, same, 1.0, ts=options["ts"], solver=fixed)
    alone = sweep(build, same, 1.0, ts=options["ts"], solver=fixed, devices=[jax.devices()[0]])
    assert both.statics_shared and alone.statics_shared and all(both.success), both.status
    assert both.statics.tension.shape == (3, 4)
    np.testing.assert_array_equal(both.simulation.stats["num_steps"], [100, 100, 100])
    np.testing.assert_allclose(both.simulation.tension, alone.simulation.tension, rtol=1e-9)
    print("sharded sweep OK")
    """
)


@pytest.mark.slow  # a fresh two-device process: 54 s of the default suite
def test_sharded_sweep_equals_unsharded():
    # XLA reads the flag when jax initialises its backends, so it needs a fresh process.
    # Keep the batch small: with as many host devices as cores, jaxlib's batched LU
    # (the mass blocks' inverse) can deadlock once it splits a large batch across the
    # thread pool, and the timeout turns such a hang into a failure.
    env = dict(
        os.environ, XLA_FLAGS="--xla_force_host_platform_device_count=2", JAX_PLATFORMS="cpu", JAX_ENABLE_X64="1"
    )
    run = subprocess.run([sys.executable, "-c", _SHARDED], env=env, capture_output=True, text=True, timeout=300)
    assert run.returncode == 0, run.stdout + run.stderr[-4000:]
    assert "sharded sweep OK" in run.stdout


def test_sweep_grid():
    grid = sweep_grid(a=[1.0, 2.0], b=[10.0, 20.0, 30.0])
    np.testing.assert_array_equal(grid["a"], [1, 1, 1, 2, 2, 2])
    np.testing.assert_array_equal(grid["b"], [10, 20, 30, 10, 20, 30])
    with pytest.raises(ValueError, match="at least one axis"):
        sweep_grid()
    with pytest.raises(ValueError, match="parameter 'b' must be finite, got inf at index 1"):
        sweep_grid(a=[1.0], b=[1.0, np.inf])


def _int_topology(n, stiffness_scale):
    model, env = build(stiffness_scale, 1.0)
    return anchored_line(n_segments=int(n))[0], env


def _batched_topology(stiffness_scale):
    # The topology is static: a constructor given traced segment indices cannot take them.
    model, env = build(stiffness_scale, 1.0)
    nodes = model.segment_nodes + jnp.asarray(0 * stiffness_scale).astype(model.segment_nodes.dtype)
    constraints = dict(zip(model.constrained_nodes.tolist(), model.motions))
    rebuilt = jc.CableNetwork(model.node_positions, nodes, model.segment_length, model.line, constraints)
    return rebuilt, env


def _integer_leaf(stiffness_scale):
    model, env = build(stiffness_scale, 1.0)
    counts = jnp.round(model.segment_length * stiffness_scale).astype(jnp.int32)
    return eqx.tree_at(lambda m: m.segment_length, model, counts), env


def _tracer_dependent_structure(stiffness_scale):
    # Four segments for a concrete value, five when traced: a structure change that
    # only shows under vmap.
    if isinstance(stiffness_scale, jax.core.Tracer):
        return anchored_line(n_segments=5)
    return anchored_line(n_segments=4)


def _not_a_model(stiffness_scale):
    return base()[0]


GOOD = {"stiffness_scale": [1.0, 2.0], "stretch": [1.0, 1.0]}


@pytest.mark.parametrize(
    "kwargs, match",
    [
        (dict(parameters={}), "at least one parameter"),
        pytest.param(dict(parameters=[1.0, 2.0]), "parameters must be a dict", marks=pytest.mark.unchecked),
        (dict(parameters={"stiffness_scale": [1.0, 2.0], "stretch": [1.0]}), "same number of cases"),
        (
            dict(parameters={"stiffness_scale": [[1.0, 2.0]], "stretch": [1.0]}),
            "'stiffness_scale' must be a non-empty 1-D array, got shape \\(1, 2\\)",
        ),
        (dict(parameters={"stiffness_scale": [], "stretch": []}), "'stiffness_scale' must be a non-empty 1-D"),
        (
            dict(parameters={"stiffness_scale": [1.0, np.nan], "stretch": [1.0, 1.0]}),
            "'stiffness_scale' must be finite, got nan at index 1",
        ),
        pytest.param(
            dict(parameters={"stiffness_scale": ["stiff"], "stretch": [1.0]}),
            "'stiffness_scale' must be an array of floats",
            marks=pytest.mark.unchecked,
        ),
        (dict(parameters={**GOOD, "bogus": [1.0, 2.0]}), "parameter 'bogus' is not a keyword of build"),
        (dict(parameters={"stiffness_scale": [1.0]}), "cannot be called with parameters \\['stiffness_scale'\\]"),
        (dict(t1=0.0), "t1 must be greater than t0"),
        (dict(ts=[0.0, 2.0]), "ts must be increasing and lie within"),
        (dict(initial="equilibrium"), "initial must be one of \\('statics', 'rest'\\)"),
        (dict(initial=jc.State(np.zeros((3, 3)), np.zeros((3, 3)))), "must have shape \\(5, 3\\)"),
        (dict(devices=[]), "devices must not be empty"),
        (dict(chunks=0), "chunks must be a positive integer, got 0"),
        pytest.param(dict(chunks=1.5), "chunks must be a positive integer, got 1.5", marks=pytest.mark.unchecked),
        (dict(chunks=True), "chunks must be a positive integer, got True"),
        pytest.param(dict(devices=["cpu"]), "devices must be JAX devices", marks=pytest.mark.unchecked),
        (
            dict(build=_int_topology, parameters={"n": [4.0, 5.0], "stiffness_scale": [1.0, 2.0]}),
            "used the value of parameter 'n' in Python",
        ),
        (
            dict(build=_batched_topology, parameters={"stiffness_scale": [1.0, 2.0]}),
            "used the value of parameter 'stiffness_scale'",
        ),
        (dict(build=_integer_leaf, parameters={"stiffness_scale": [1.0, 2.0]}), "\\.segment_length, an integer"),
        (
            dict(build=_tracer_dependent_structure, parameters={"stiffness_scale": [1.0, 2.0]}),
            "different structure when traced",
        ),
        (
            dict(build=_not_a_model, parameters={"stiffness_scale": [1.0, 2.0]}),
            "must return \\(CableNetwork, Environment\\)",
        ),
    ],
)
def test_input_errors(kwargs, match):
    arguments = dict(build=build, parameters=GOOD, t1=T1)
    arguments.update(kwargs)
    with pytest.raises(ValueError, match=match):
        sweep(arguments.pop("build"), arguments.pop("parameters"), arguments.pop("t1"), **arguments)


def test_a_build_that_ignores_its_parameters_is_refused_by_name():
    """A build whose model and water do not depend on the swept values would give the
    same case again and again: refused, naming the parameter."""

    def ignoring(stiffness_scale):
        return base()

    with pytest.raises(ValueError, match="nothing it returns depends on 'stiffness_scale'"):
        sweep(ignoring, {"stiffness_scale": [1.0, 2.0]}, T1)


def test_build_errors_name_the_first_case():
    # A constructor's own check on a real value still fires (under vmap it could not),
    # and a note says which case raised it.
    def driven(period):
        return anchored_line(n_segments=4, period=period)

    with pytest.raises(ValueError, match="Harmonic.period must be positive, got -1.0") as info:
        sweep(driven, {"period": [-1.0, 5.6]}, T1)
    assert "(the first case)" in "".join(getattr(info.value, "__notes__", []))


def test_sweep_over_wave_steepness_equals_single_runs():
    """The issue's sweep: one compiled batch over Airy wave steepness H/λ, each case a
    wave built from its steepness inside the traced `build`."""
    model, _ = base()
    period, depth = 5.6, 200.0

    def waves(steepness):
        wave = jc.Airy.from_steepness(steepness, period, depth)
        return model, jc.Environment(depth=depth, waves=wave)

    steepness = np.array([0.01, 0.04, 0.07])
    swept = sweep(
        waves, {"steepness": steepness}, 1.5, ts=np.linspace(0.0, 1.5, 7), initial="rest", solver=jc.SolverConfig()
    )
    assert bool(np.all(swept.success))
    for i in (0, 2):
        env = waves(steepness[i])[1]
        assert float(env.waves[0].steepness) == pytest.approx(steepness[i], rel=1e-12)
        single = jc.simulate(model, env, 1.5, ts=np.linspace(0.0, 1.5, 7), initial="rest")
        np.testing.assert_allclose(swept.case(i).tension, single.tension, rtol=1e-8)
    # The steepness reaches the physics: the cases differ (by ~20 N here, the waves
    # stirring only the top of a 200 m line in 1.5 s), far above the 1e-8 agreement.
    difference = np.abs(np.asarray(swept.case(2).tension - swept.case(0).tension)).max()
    assert difference > 1e-5 * float(swept.peak_tension[0])


# A sweep over the top's harmonic amplitude: with zero phase the top is at rest at
# t = 0 (A sin 0 = 0), so every case has the same equilibrium.
AMPLITUDES = {"amplitude": [0.8, 1.6, 2.4]}


def driven(amplitude=1.6, phase=0.0, current=0.0, wave_height=None, length_scale=1.0):
    """`base()` with the top's amplitude A (m) and phase φ (rad), a current along x
    (m/s), an Airy wave of that height (m; none by default) and the segments'
    unstretched lengths scaled."""
    model, env = base()
    model = eqx.tree_at(
        lambda m: (m.motions[1].amplitude, m.motions[1].phase, m.segment_length),
        model,
        (jnp.asarray(amplitude, float), jnp.asarray(phase, float), model.segment_length * length_scale),
    )
    waves = () if wave_height is None else (jc.Airy(wave_height, 5.6, 200.0),)
    current = jnp.stack([jnp.asarray(current, float), 0.0, 0.0])
    return model, jc.Environment(depth=200.0 if waves else None, current=current, waves=waves)


def test_statics_solved_once_where_the_parameters_cannot_change_it(monkeypatch):
    """An amplitude sweep solves statics once, before the batch, and gives every case
    that equilibrium: the same result, to the statics' tolerance, as the per-case
    solves inside the batch (forced here), and each case as its single run from that
    equilibrium."""
    once = sweep(driven, AMPLITUDES, T1, ts=TS, solver=jc.SolverConfig())
    assert once.statics_shared and all(once.success), once.status
    assert once.summary().splitlines()[-1] == "statics solved once: the swept parameters do not change the equilibrium"
    assert once.statics.tension.shape == (3, 4) and once.statics.state.positions.shape == (3, 5, 3)
    model, env = driven(0.8)
    alone = jc.solve_statics(model, env)
    for field in ("positions", "velocities"):
        np.testing.assert_array_equal(getattr(once.statics.state, field), np.stack(3 * [getattr(alone.state, field)]))

    monkeypatch.setattr(jc._sweep.sweep, "statics_differ", lambda *arguments: True)
    per_case = sweep(driven, AMPLITUDES, T1, ts=TS, solver=jc.SolverConfig())
    assert not per_case.statics_shared and all(per_case.success), per_case.status
    assert "statics solved once" not in per_case.summary()
    # Both equilibria leave forces within 1e-6 of the force scale (the statics'
    # tolerance): a position difference of that over the stiffness, and tensions that
    # agree to about that fraction.
    scale = float(alone.force_scale)
    stiffness = float(model.line.tension_law.axial_stiffness[0]) / float(model.segment_length[0])
    np.testing.assert_allclose(
        once.statics.state.positions, per_case.statics.state.positions, atol=1e-6 * scale / stiffness
    )
    np.testing.assert_allclose(once.statics.tension, per_case.statics.tension, atol=1e-6 * scale)
    peak = float(np.max(per_case.peak_tension))
    np.testing.assert_allclose(once.simulation.tension, per_case.simulation.tension, atol=1e-5 * peak)
    # The cases differ (by their amplitude), far beyond that.
    assert abs(float(once.peak_tension[2] / once.peak_tension[0]) - 1) > 0.05

    single = jc.simulate(*driven(2.4), T1, ts=TS, initial=alone.state, solver=jc.SolverConfig())
    np.testing.assert_allclose(once.case(2).tension, single.tension, rtol=1e-8)


def test_statics_refused_before_solving_is_reported_per_case():
    """A shared equilibrium that eager statics refuses (segments a billionth of their
    length: the line would have to stretch 1e11 %) is left to the batch, whose cases
    report it as their own failed statics, as where the cases differ."""

    def short(amplitude):
        return driven(amplitude, length_scale=1e-9)

    result = sweep(short, AMPLITUDES, T1, ts=TS)
    assert not result.statics_shared and not any(result.success)
    for status in result.status:
        assert status.startswith(
            "statics failed: solve_statics: the segments between two constrained nodes must stretch"
        )
    assert np.all(np.asarray(result.simulation.stats["num_steps"]) == 0)


def _differ(build, values, t0=0.0):
    reference = jc._sweep.cases.build_first(build, values)
    batched, unbatched = jc._sweep.cases.build_batch(build, values, reference)
    return jc._sweep.cases.statics_differ(batched, unbatched, t0)


@pytest.mark.parametrize(
    ("parameters", "fixed", "t0", "differ"),
    [
        (AMPLITUDES, {}, 0.0, False),
        # A sin(ω t0) moves the top with A once t0 is not a multiple of the half period.
        (AMPLITUDES, {}, 0.7, True),
        # A phase moves the top at t = 0 (A sin φ), with or without an amplitude swept.
        ({"phase": [0.0, 0.3, 0.6]}, {}, 0.0, True),
        (AMPLITUDES, {"phase": 0.3}, 0.0, True),
        # Loads and the line itself: the current's drag, the waves' at t0, the lengths.
        ({"current": [0.0, 0.5, 1.0]}, {}, 0.0, True),
        ({"wave_height": [1.0, 2.0, 3.0]}, {}, 0.0, True),
        ({"length_scale": [1.0, 1.001, 1.002]}, {}, 0.0, True),
        # Values, not tracers, are compared: a traced leaf equal in every case is shared.
        ({"current": [0.2, 0.2, 0.2], "amplitude": [0.8, 1.6, 2.4]}, {}, 0.0, False),
    ],
)
def test_statics_shared_only_where_no_input_of_statics_differs(parameters, fixed, t0, differ):
    """The decision compares exactly what statics reads: every float leaf of the model
    and the water but the motions, and the supports' positions at t0."""

    def build(**case):
        return driven(**{**fixed, **case})

    assert _differ(build, parameters, t0) is differ


def test_statics_of_differing_cases_solved_per_case(swept):
    # Stiffness and lengths change the equilibrium: each case has its own.
    assert not swept.statics_shared
    assert "statics solved once" not in swept.summary()
    assert abs(float(swept.statics.tension[1, 0] / swept.statics.tension[0, 0]) - 1) > 1e-4


def test_fixed_steps_equal_single_runs():
    """With fixed steps every case takes the same steps and the batch's loops mask no
    case; each case still equals its single run, and the cases that are not integrated
    (statics failed, invalid) are reported as with adaptive steps, with no steps
    counted. RK4 at 10 ms is within its stability limit for every case but the stiff
    case 2 (ω_n = 632 rad/s needs dt < 2.83/ω_n = 4.5 ms), whose state goes non-finite."""
    config = jc.SolverConfig(jc.RK4(), dt0=0.01, stepsize_controller=diffrax.ConstantStepSize())
    fixed = sweep(build, CASES, T1, ts=TS, solver=config)
    assert not fixed.statics_shared
    np.testing.assert_array_equal(fixed.success, [True, True, False, False, False, True])
    assert (
        fixed.status[2] == "Nonfinite (inf or nan) values detected during solve. (stopped after 100 steps, 0 rejected)"
    )
    assert fixed.status[3].startswith("statics failed: solve_statics: the segments between two constrained nodes")
    assert fixed.status[4].startswith("invalid input: case 4: LineType.tension_law.axial_stiffness must be positive")
    steps = np.asarray(fixed.simulation.stats["num_steps"])
    np.testing.assert_array_equal(steps, [100, 100, 100, 0, 0, 100])
    for i in (3, 4):
        assert np.all(np.isinf(np.asarray(fixed.simulation.tension[i])))
    for i in (0, 1, 5):
        model, env = build(**case(i))
        start = jc.State(fixed.statics.state.positions[i], fixed.statics.state.velocities[i])
        single = jc.simulate(model, env, T1, ts=TS, initial=start, solver=config)
        np.testing.assert_allclose(fixed.case(i).tension, single.tension, rtol=1e-10)
        np.testing.assert_allclose(fixed.case(i).positions, single.positions, rtol=1e-12, atol=1e-10)
        np.testing.assert_allclose(fixed.case(i).reactions, single.reactions, rtol=1e-10, atol=1e-6)


def test_the_default_sweep_takes_fixed_rk4_steps_stable_for_every_case():
    """Told nothing, a sweep steps with RK4 at 0.7 of its stability limit at the fastest
    mode of its stiffest case (here the second, at twice the stiffness), or less so that
    each output interval is a whole number of steps, and says so; each case equals its
    single run with those steps."""
    stiffness = {"stiffness_scale": [1.0, 2.0], "stretch": [1.0, 1.0]}
    swept = sweep(build, stiffness, T1, ts=TS)
    assert all(swept.success), swept.status
    stiffest = stable_step(jc.RK4(), *build(2.0, 1.0), duration=T1)
    assert stiffest is not None
    interval = TS[1] - TS[0]
    dt = interval / math.ceil(interval / (STEP_FRACTION * stiffest))
    assert swept.stepping.startswith(f"RK4, fixed steps of {dt:.4g} s (0.7 of its stability limit")
    assert f"stepping: {swept.stepping}" in swept.summary()
    config = jc.SolverConfig(jc.RK4(), dt0=dt, stepsize_controller=diffrax.ConstantStepSize())
    np.testing.assert_array_equal(swept.stats["num_steps"], round(T1 / dt))
    for i in range(2):
        model, env = build(**{k: v[i] for k, v in stiffness.items()})
        start = jc.State(swept.statics.state.positions[i], swept.statics.state.velocities[i])
        single = jc.simulate(model, env, T1, ts=TS, initial=start, solver=config)
        np.testing.assert_allclose(swept.case(i).tension, single.tension, rtol=1e-10)


def test_output_times_after_the_start_are_integrated_to_from_it():
    """Output times that begin after t0 are reached on the same grid of steps as outputs
    from t0 at their spacing: the two sweeps agree to rounding at the times they share
    (another grid would differ by the steps' error, some 1e-6 of the tension)."""
    later = TS[TS >= 0.5]
    config = jc.SolverConfig(jc.RK4(), dt0=0.01, stepsize_controller=diffrax.ConstantStepSize())
    first = {"stiffness_scale": [1.0, 2.0], "stretch": [1.0, 1.0]}
    whole = sweep(build, first, T1, ts=TS, solver=config)
    part = sweep(build, first, T1, ts=later, solver=config)
    np.testing.assert_array_equal(part.times[0], later)
    np.testing.assert_allclose(part.tension, whole.tension[:, TS >= 0.5], rtol=1e-12)
    grid, at = jc._sweep.sweep._grid(0.0, 1.0, np.array([0.5, 0.75, 0.75, 1.0]))
    np.testing.assert_allclose(grid, [0.0, 0.25, 0.5, 0.75, 1.0])
    np.testing.assert_array_equal(at, [2, 3, 3, 4])
