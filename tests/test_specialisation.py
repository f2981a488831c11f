"""The evaluation's fast paths give the general path's answer, to rounding.

The equations specialise on what is known when tracing (`benchmarks/README.md`, *Where
an evaluation's time goes*): static indices become slices, a law without damping skips
the viscous force, the elastic forces use the tension law as the energy's derivative,
the conservative forces are written out rather than taken by `jax.grad` of the
potential, a model without bodies leaves the bodies' terms out, the lumped solve uses
Woodbury's identity along a line and Cramer's rule at junctions, and statics' forces
leave out what vanishes at rest. Each is checked here
against the general form it replaces, on scenes that exercise it: the anchored-line paper's chain, the
moored net (a graph with junctions, buoys that pierce the surface, waves and a damped
law), a line on a seabed, and a line that pierces the free surface with anisotropic
added mass and a spar buoy.
"""

import equinox as eqx
import jax
import jax.numpy as jnp
import numpy as np
import optimistix as optx
import pytest

import jaxcable as jc
from jaxcable._equations import lagrangian as lag
from jaxcable._model import indexing as _indexing
from jaxcable._model import materials
from jaxcable._model.network import without_absent_bodies
from jaxcable.examples import anchored_line, moored_net


def _seabed_line():
    line = jc.LineType(mass_per_length=20.0, diameter=0.05, tension_law=jc.LinearElastic(1e8))
    model = jc.CableNetwork.from_branches(
        np.array([[0.0, 0.0, -50.0], [80.0, 0.0, 0.0]]),
        [jc.Branch(0, 1, line, 110.0, 8)],
        {0: jc.Fixed(), 1: jc.Fixed()},
        mass_matrix="lumped",
    )
    env = jc.Environment(depth=50.0, seabed=jc.Seabed(friction=0.3), current=[0.3, 0.0, 0.0])
    return model, env


def _surface_line():
    """A line that pierces the free surface, with MoorDyn's default added mass
    (C_a = 1, C_aτ = 0: anisotropic blocks), a spar buoy (a column 10 m tall, with a
    constant force on it) at its node nearest the surface and a damped law."""
    line = jc.LineType(mass_per_length=3.0, diameter=0.08, tension_law=jc.KelvinVoigt(2e6, 1e5, 4e3))
    model = jc.CableNetwork.from_branches(
        np.array([[0.0, 0.0, -30.0], [40.0, 0.0, 2.0]]),
        [jc.Branch(0, 1, line, 52.0, 7)],
        {0: jc.Fixed(), 1: jc.Fixed()},
        bodies={7: jc.Body(mass=50.0, volume=0.3, height=10.0, added_mass=0.8, force=[100.0, 0.0, -50.0])},
        mass_matrix="lumped",
    )
    return model, jc.Environment(free_surface=True, current=[0.4, 0.1, 0.0])


SCENES = {
    "anchored_line chain": lambda: anchored_line(6, mass_matrix="lumped"),
    "surface line": _surface_line,
    "anchored_line consistent": lambda: anchored_line(4, mass_matrix="consistent"),
    "moored net": lambda: moored_net(segments=(1, 2, 2, 1)),
    "seabed": _seabed_line,
}


def _state(model, seed=0):
    rng = np.random.default_rng(seed)
    positions = np.asarray(model.node_positions) + rng.normal(scale=0.3, size=model.node_positions.shape)
    velocities = rng.normal(scale=0.5, size=positions.shape)
    free = model.free_nodes
    return positions[free], velocities[free]


@pytest.mark.parametrize("indices", [[2, 3, 4, 0, 1], [0, -1, -1, 5, 6, 7, -1], [], [4]])
def test_take_moves_values_like_indexing(indices):
    array = np.arange(24.0).reshape(3, 8)
    expected = (
        np.where(np.asarray(indices) < 0, 0.0, array[:, np.asarray(indices, dtype=int)]) if indices else array[:, :0]
    )
    got = np.asarray(_indexing.take(jnp.asarray(array), np.asarray(indices)))
    np.testing.assert_array_equal(got, expected)


def test_take_falls_back_to_a_gather_for_scattered_indices():
    rng = np.random.default_rng(1)
    indices = rng.permutation(60)  # about 60 runs, past the slice limit
    indices[::7] = -1
    array = rng.normal(size=(2, 60))
    got = np.asarray(_indexing.take(jnp.asarray(array), indices))
    np.testing.assert_array_equal(got, np.where(indices < 0, 0.0, array[:, indices]))


def test_sum_into_is_a_segment_sum():
    rng = np.random.default_rng(2)
    targets = rng.integers(0, 9, size=40)
    values = rng.normal(size=(3, 40))
    plan = _indexing.incidence(targets, 9)
    expected = np.zeros((3, 9))
    np.add.at(expected.T, targets, values.T)
    np.testing.assert_allclose(np.asarray(_indexing.sum_into(jnp.asarray(values), plan)), expected, rtol=1e-14)


def test_placement_inverts_free_then_constrained():
    model, _ = moored_net(segments=(1, 2, 2, 1))
    order = np.concatenate([model.free_nodes, model.constrained_nodes])
    np.testing.assert_array_equal(order[model.topology.placement], np.arange(model.n_nodes))


# The moored net's general path compiles for 25 s: it joins the slow suite.
@pytest.mark.parametrize("scene", [pytest.param(s, marks=pytest.mark.slow) if s == "moored net" else s for s in SCENES])
def test_slices_give_the_gathers_answer(scene, monkeypatch):
    """With every static index compiled as a gather (the general path), the free
    accelerations and the reactions are those of the slices."""
    model, env = SCENES[scene]()
    free_positions, free_velocities = _state(model)

    def evaluate():
        a, positions, velocities, accelerations = lag.free_accelerations(
            model, env, 0.7, free_positions, free_velocities
        )
        return np.asarray(a), np.asarray(lag.reactions(model, env, 0.7, positions, velocities, accelerations))

    fast = evaluate()
    monkeypatch.setattr(_indexing, "_MAX_RUNS", -1)
    jax.clear_caches()
    general = evaluate()
    for got, expected in zip(fast, general):
        np.testing.assert_allclose(got, expected, rtol=1e-12, atol=1e-12 * np.max(np.abs(expected)))


@pytest.mark.parametrize("width", [1e-5, 0.0])
def test_energy_density_derivative_is_the_tension_law(width):
    """∂/∂ε ∫₀^ε T_e = T_e(ε) through the slack, the smoothing band and the taut part;
    the parameters' derivatives and the second derivative are those of the quadrature
    itself (autodiff through `_integrated_energy_density`)."""
    law = jc.NonlinearElastic(3e7, 3e6, slack_width=width)
    strain = jnp.array([-1e-3, 0.0, 2e-6, 5e-6, 1e-5, 3e-5, 2e-3])
    grad = jax.vmap(jax.grad(law.elastic_energy_density))(strain)
    np.testing.assert_allclose(np.asarray(grad), np.asarray(law.elastic_tension(strain)), rtol=1e-14, atol=0)

    def by_quadrature(s, c_e, c_e1):
        return materials._integrated_energy_density(s, c_e, c_e1, jnp.asarray(width))

    def by_law(s, c_e, c_e1):
        return jc.NonlinearElastic(c_e, c_e1, slack_width=width).elastic_energy_density(s)

    for s in strain:
        arguments = (s, jnp.asarray(3e7), jnp.asarray(3e6))
        expected = jax.grad(by_quadrature, argnums=(1, 2))(*arguments)
        got = jax.grad(by_law, argnums=(1, 2))(*arguments)
        np.testing.assert_allclose(np.asarray(got), np.asarray(expected), rtol=1e-13, atol=1e-300)
        hessian = jax.grad(jax.grad(by_law))(*arguments)
        np.testing.assert_allclose(float(hessian), float(jax.grad(law.elastic_tension)(s)), rtol=1e-13, atol=1e-300)


def test_undamped_law_skips_the_viscous_force():
    """A law without damping (`damped = False`) gives the forces of a damped law whose
    damping is zero."""
    model, env = anchored_line(5, mass_matrix="lumped")
    law = model.line.tension_law
    zero_damping = jc.KelvinVoigt(law.axial_stiffness, law.quadratic_stiffness(), 0.0, law.slack_width)
    damped = eqx.tree_at(lambda m: m.line.tension_law, model, zero_damping)
    assert not law.damped and zero_damping.damped
    free_positions, free_velocities = _state(model)
    got = lag.free_accelerations(model, env, 0.2, free_positions, free_velocities)[0]
    expected = lag.free_accelerations(damped, env, 0.2, free_positions, free_velocities)[0]
    np.testing.assert_allclose(np.asarray(got), np.asarray(expected), rtol=1e-13, atol=1e-13)


def test_cramer_solve_matches_a_dense_solve():
    rng = np.random.default_rng(3)
    tangent = rng.normal(size=(5, 3))
    tangent /= np.linalg.norm(tangent, axis=1, keepdims=True)
    blocks = 3.0 * np.eye(3) + 0.7 * tangent[:, :, None] * tangent[:, None, :]
    rhs = rng.normal(size=(5, 3))
    got = lag._solve_3x3(jnp.asarray(np.moveaxis(blocks, 0, -1)), jnp.asarray(rhs.T))
    np.testing.assert_allclose(np.asarray(got).T, np.linalg.solve(blocks, rhs[..., None])[..., 0], rtol=1e-13)
    inverse = lag._inverse_3x3(jnp.asarray(np.moveaxis(blocks, 0, -1)))
    np.testing.assert_allclose(np.moveaxis(np.asarray(inverse), -1, 0), np.linalg.inv(blocks), rtol=1e-13)


@pytest.mark.parametrize("scene", ["anchored_line chain", "surface line", "seabed"])
def test_closed_form_lumped_solve_gives_cramers_answer(scene, monkeypatch):
    """Woodbury's closed form for `a I + b₁ τ₁τ₁ᵀ + b₂ τ₂τ₂ᵀ` gives the free
    accelerations of the 3 × 3 blocks and Cramer's rule (the general path, forced by
    allowing no segments at a node for the closed form), and solves the blocks as
    numpy does."""
    model, env = SCENES[scene]()
    free_positions, free_velocities = _state(model)
    assert model.topology.node_sums.shape[1] <= lag._CLOSED_FORM_SEGMENTS

    def evaluate():
        return np.asarray(lag.free_accelerations(model, env, 0.4, free_positions, free_velocities)[0])

    fast = evaluate()
    monkeypatch.setattr(lag, "_CLOSED_FORM_SEGMENTS", 0)
    jax.clear_caches()
    general = evaluate()
    np.testing.assert_allclose(fast, general, rtol=1e-12, atol=1e-12 * np.max(np.abs(general)))

    positions = lag._cm(lag.full_state(model, 0.4, free_positions, free_velocities)[0])
    tangent = lag._geometry(model, positions)[1]
    rhs = np.random.default_rng(4).normal(size=(3, model.free_nodes.size))
    blocks = np.asarray(lag.lumped_blocks(model, env, lag._public(positions)))[model.free_nodes]
    expected = np.linalg.solve(blocks, rhs.T[..., None])[..., 0].T
    got = lag._lumped_solve(model, env, positions, tangent, jnp.asarray(rhs))
    np.testing.assert_allclose(np.asarray(got), expected, rtol=1e-12, atol=1e-14 * np.max(np.abs(expected)))


def test_surface_line_blocks_are_anisotropic():
    """The surface line exercises the rank-one terms: its blocks are not a multiple of
    the identity, and some of its segments are partly out of the water."""
    model, env = _surface_line()
    positions = np.asarray(model.node_positions)
    blocks = np.asarray(lag.lumped_blocks(model, env, positions))[model.free_nodes]
    eigenvalues = np.linalg.eigvalsh(blocks)
    assert np.all(eigenvalues[:, -1] - eigenvalues[:, 0] > 1e-3 * eigenvalues[:, -1])
    assert np.any(positions[:, 2] > 0) and np.any(positions[:, 2] < 0)


@pytest.mark.parametrize("scene", list(SCENES))
def test_conservative_forces_are_the_potentials_gradient(scene):
    """The conservative forces written out are `−∂Π/∂x` by `jax.grad`: elastic,
    weight, buoyancy (with the free surface across segments and floating columns),
    the bodies' constant forces and the seabed's spring."""
    model, env = SCENES[scene]()
    free_positions, free_velocities = _state(model)
    positions = lag._cm(lag.full_state(model, 0.0, free_positions, free_velocities)[0])
    expected = np.asarray(-jax.grad(lag._potential_energy, argnums=2)(model, env, positions))
    got = np.asarray(lag._conservative_forces(model, env, positions))
    np.testing.assert_allclose(got, expected, rtol=1e-12, atol=1e-12 * np.max(np.abs(expected)))


def test_conservative_scenes_exercise_every_term():
    """The scenes above cross the surface with segments and a column, press into the
    seabed and carry bodies' constant forces, so that each term is compared."""
    model, env = _surface_line()
    z = lag._cm(lag.full_state(model, 0.0, *_state(model))[0])[2]
    start, end = z[model.segment_nodes[:, 0]], z[model.segment_nodes[:, 1]]
    assert np.any(np.asarray(start * end) < 0)
    assert abs(float(z[7])) < 0.5 * float(model.body.height[7])
    assert np.any(np.asarray(model.body.force) != 0)
    model, env = _seabed_line()
    assert env.depth is not None
    assert np.any(np.asarray(lag.full_state(model, 0.0, *_state(model))[0])[:, 2] < -env.depth)


@pytest.mark.parametrize("scene", list(SCENES))
def test_static_forces_are_the_forces_at_rest(scene):
    """Statics' forces skip the terms that vanish at rest (the viscous tension, the
    seabed's damping and friction, smooth and MoorDyn's): the same as all the forces
    with every velocity zero, waves and a current acting, nodes pressed into the bed."""
    model, env = SCENES[scene]()
    envs = [env]
    if env.seabed is not None:
        envs = [eqx.tree_at(lambda e: e.seabed, env, jc.Seabed(friction=0.3, friction_damping=c)) for c in (None, 1e3)]
    positions = lag.full_state(model, 0.7, *_state(model))[0]
    rest = jnp.zeros_like(positions)
    for env in envs:
        expected = np.asarray(lag.generalised_forces(model, env, 0.7, positions, rest))
        got = np.asarray(lag.static_forces(model, env, 0.7, positions))
        np.testing.assert_allclose(got, expected, rtol=1e-13, atol=1e-13 * np.max(np.abs(expected)))


def _still(env):
    """`env` without its waves and with its current set to zero (a profile's speeds)."""
    env = env.without_waves()
    if isinstance(env.current, jc.CurrentProfile):
        return eqx.tree_at(lambda e: e.current.speeds, env, jnp.zeros_like(env.current.speeds))
    return eqx.tree_at(lambda e: e.current, env, jnp.zeros(3))


@pytest.mark.parametrize("scene", list(SCENES))
def test_static_forces_in_still_water_leave_out_only_zeros(scene):
    """In still water the water's loads on nodes at rest are zero: statics' forces
    without them (`still=True`) are all the forces at rest, bodies, surface and bed
    included."""
    model, env = SCENES[scene]()
    env = _still(env)
    positions = lag.full_state(model, 0.7, *_state(model))[0]
    expected = np.asarray(lag.generalised_forces(model, env, 0.7, positions, jnp.zeros_like(positions)))
    got = np.asarray(lag.static_forces(model, env, 0.7, positions, still=True))
    np.testing.assert_allclose(got, expected, rtol=1e-13, atol=1e-13 * np.max(np.abs(expected)))


def _lowe_langley():
    from pathlib import Path

    scene = jc.load_scene(Path(__file__).parent / "data" / "lowe_and_langley_2006" / "line.txt")
    built = scene.build()
    return built.model, built.environment


@pytest.mark.parametrize(
    "scene", ["anchored_line chain", "surface line", "moored net", "seabed", "Low & Langley (bending)"]
)
def test_statics_in_still_water_is_the_general_path(scene):
    """Statics in water known to be still, without the water's loads, finds the
    general path's equilibrium: the same positions, reactions and tensions to rounding.
    (Not always in as many steps: the last ones, which take the force from the tolerance
    down to rounding, end where rounding says.)"""
    from jaxcable._statics import solution as _solution
    from jaxcable._statics import solve as _statics

    model, env = _lowe_langley() if scene == "Low & Langley (bending)" else SCENES[scene]()
    env = _still(env)
    assert _solution.still_water(env)
    args = (model, env, model.node_positions, 0.0, _solution.MAX_STEPS, _solution.FORCE_TOLERANCE, True)
    general, still = (_statics._equilibrium(*args, flag, False) for flag in (False, True))
    assert bool(general.result == optx.RESULTS.successful) and bool(still.result == optx.RESULTS.successful)
    scale = float(general.force_scale)
    size = float(np.ptp(np.asarray(general.state.positions)))
    np.testing.assert_allclose(still.state.positions, general.state.positions, rtol=0, atol=1e-9 * size)
    np.testing.assert_allclose(still.reactions, general.reactions, rtol=0, atol=1e-8 * scale)
    np.testing.assert_allclose(still.tension, general.tension, rtol=0, atol=1e-8 * scale)


def test_still_water_is_known_only_before_tracing():
    """Still water is no waves and a concrete current of exactly zero; any current, a
    wave, or a current traced under `jit` (a sweep over it) takes the general path."""
    from jaxcable._statics import solution as _solution

    assert _solution.still_water(jc.Environment())
    assert _solution.still_water(jc.Environment(current=jc.CurrentProfile([-50.0, 0.0], [0.0, 0.0])))
    assert not _solution.still_water(jc.Environment(current=[0.0, 1e-9, 0.0]))
    assert not _solution.still_water(jc.Environment(current=jc.CurrentProfile([-50.0, 0.0], [0.0, 0.1])))
    waves = jc.Environment(depth=50.0, waves=jc.Airy(height=1.0, period=8.0, depth=50.0))
    assert not _solution.still_water(waves)
    assert _solution.still_water(waves.without_waves())
    seen = []
    jax.jit(lambda current: seen.append(_solution.still_water(jc.Environment(current=current))))(jnp.zeros(3))
    assert seen == [False]


@pytest.mark.parametrize("name", ["anchored_line chain", "anchored_line consistent", "seabed"])
def test_a_model_without_bodies_leaves_their_terms_out(name):
    """[`without_absent_bodies`][]: a bare line's `body` becomes None, and its
    accelerations, mass matrix, potential and forces are the body-carrying model's to
    rounding; a model with a body, or with bodies traced, keeps them."""
    model, env = SCENES[name]()
    lean = without_absent_bodies(model)
    assert lean.body is None and model.body is not None
    x, v = _state(model)
    _, positions, velocities, accelerations = lag.free_accelerations(model, env, 0.7, x, v)
    for f in (
        lambda m: lag.free_accelerations(m, env, 0.7, x, v)[0],
        lambda m: lag.generalised_forces(m, env, 0.7, positions, velocities),
        lambda m: lag.inertial_forces(m, env, positions, accelerations),
        lambda m: lag.potential_energy(m, env, positions),
    ):
        np.testing.assert_allclose(f(lean), f(model), rtol=1e-12, atol=1e-9)
    if model.mass_matrix == "lumped":
        np.testing.assert_allclose(lag.lumped_blocks(lean, env, positions), lag.lumped_blocks(model, env, positions))
    buoyed, _ = _surface_line()
    assert without_absent_bodies(buoyed) is buoyed
    clumped = eqx.tree_at(lambda m: m.body.mass, model, model.body.mass.at[2].set(100.0))  # a clump added later
    assert without_absent_bodies(clumped) is clumped
    seen = []

    def traced(scale):
        weighed = eqx.tree_at(lambda m: m.body.mass, model, scale * model.body.mass)
        seen.append(without_absent_bodies(weighed).body)
        return scale

    jax.grad(traced)(1.0)
    assert seen[0] is not None
