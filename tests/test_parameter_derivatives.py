"""Every physical parameter is differentiable from the public API: a scene built from
plain floats by its constructors, differentiated with `jax.grad` through statics and a
second of dynamics, against central differences (`jc.check_derivative`). The quick
test builds a smaller scene the same way, under `jax.grad`.

The scene: a line from an anchor on the seabed, part of it resting there, through a
buoy to a fairlead driven in surge, in a current and a regular wave. Over its first
second nothing goes slack, so every derivative is well conditioned and must agree to
0.1 %."""

import jax
import jax.numpy as jnp
import pytest

import jaxcable as jc

DEPTH = 50.0
NOMINAL = {
    "length": 80.0,  # m, the lower branch (Branch.length)
    "anchor_x": 0.0,  # m (the junctions)
    "fairlead_z": 0.0,  # m
    "axial_stiffness": 5e6,  # N, C_E
    "quadratic_stiffness": 1e6,  # N, C_E1
    "axial_damping": 2e4,  # N·s, C_v
    "diameter": 0.05,  # m
    "mass_per_length": 8.0,  # kg/m
    "normal_drag": 1.2,
    "tangential_drag": 0.02,
    "normal_added_mass": 1.0,
    "tangential_added_mass": 0.1,
    "buoy_mass": 20.0,  # kg
    "buoy_volume": 0.05,  # m³
    "buoy_drag_area": 0.1,  # m²
    "buoy_added_mass": 10.0,  # kg
    "current": 0.4,  # m/s
    "wave_height": 1.5,  # m
    "wave_period": 7.0,  # s
    "seabed_stiffness": 1e5,  # N/m per metre of line
    "seabed_damping": 1e4,  # N·s/m per metre
    "seabed_friction": 0.5,
    "amplitude": 1.0,  # m, the fairlead's surge
    "motion_period": 6.0,  # s
}


def scene(**values):
    """The model and water with `values` in place of the nominal ones."""
    p = {**NOMINAL, **values}
    law = jc.KelvinVoigt(p["axial_stiffness"], p["quadratic_stiffness"], p["axial_damping"])
    line = jc.LineType(
        mass_per_length=p["mass_per_length"],
        diameter=p["diameter"],
        tension_law=law,
        normal_drag=p["normal_drag"],
        tangential_drag=p["tangential_drag"],
        normal_added_mass=p["normal_added_mass"],
        tangential_added_mass=p["tangential_added_mass"],
    )
    junctions = jnp.array(
        [[p["anchor_x"], 0.0, -DEPTH], [60.0, 0.0, -25.0], [100.0, 0.0, p["fairlead_z"]]], dtype=float
    )
    buoy = jc.Body(
        mass=p["buoy_mass"], volume=p["buoy_volume"], drag_area=p["buoy_drag_area"], added_mass=p["buoy_added_mass"]
    )
    model = jc.CableNetwork.from_branches(
        junctions=junctions,
        branches=[jc.Branch(0, 1, line, p["length"], 8), jc.Branch(1, 2, line, 48.0, 4)],
        constraints={0: jc.Fixed(), 2: jc.Harmonic(p["amplitude"], p["motion_period"])},
        bodies={1: buoy},
    )
    env = jc.Environment(
        current=(p["current"], 0.0, 0.0),
        depth=DEPTH,
        waves=(jc.Airy(p["wave_height"], p["wave_period"], DEPTH),),
        seabed=jc.Seabed(stiffness=p["seabed_stiffness"], damping=p["seabed_damping"], friction=p["seabed_friction"]),
    )
    return model, env


TIGHT = jc.SolverConfig(rtol=1e-10, atol=1e-10)  # at 1e-6 the derivative is off by ~0.3 %
NAMES = tuple(NOMINAL)


def values_of(u):
    """The parameters from `u`, one entry per name, 1 at the nominal scene: a factor on
    each nominal value, or for a position whose nominal value is 0, an offset of `u - 1`
    metres. Every parameter is traced in every derivative, so that one compiled program
    serves them all (a derivative in one of them alone would compile its own)."""
    return {n: NOMINAL[n] * u[i] if NOMINAL[n] != 0 else u[i] - 1.0 for i, n in enumerate(NAMES)}


def fairlead_tension(u):
    """The fairlead segment's tension (N) after 1 s, from the scene's statics."""
    model, env = scene(**values_of(u))
    return jc.simulate(model, env, 1.0, ts=[1.0], solver=TIGHT).tension[-1, -1]


@pytest.mark.slow
def test_the_scene_rests_on_the_bed_and_stays_taut():
    model, env = scene()
    result = jc.simulate(model, env, 1.0, ts=jnp.linspace(0.0, 1.0, 11), solver=TIGHT)
    free = jnp.asarray(model.free_nodes)
    on_bed = jnp.sum(result.positions[:, free, 2] < -DEPTH + 0.05, axis=1)
    assert int(jnp.min(on_bed)) >= 3  # free nodes resting on the bed throughout
    assert float(jnp.min(result.tension)) > 100.0  # N: taut throughout


@pytest.mark.slow  # 3.5 min on 2 cores: 100 s compiling the gradient, 4.6 s a gradient, 1 s a run
def test_derivatives_in_every_physical_parameter():
    """One gradient in all 24 parameters, each component against its central differences
    (`jc.check_gradient`). The steps stop at 1e-4: the weakest parameters here (C_E1,
    K_τ) move the tension by 1e-4 of itself, and below that the solve's rounding swamps
    their differences. A parameter whose derivative is zero would agree trivially: each
    must reach the physics."""
    checks = jc.check_gradient(fairlead_tension, jnp.ones(len(NAMES)), steps=[1e-2, 1e-3, 1e-4], rtol=1e-3, warn=False)
    bad = [
        f"{name}: {check}"
        for name, check in zip(NAMES, checks)
        if not check.trusted or abs(check.derivative) < 1e-6 * abs(check.value)
    ]
    assert not bad, "\n".join(bad)


def test_a_model_built_from_a_traced_length_and_junction():
    """`Branch(length=L)` and the junctions inside `jax.grad`: the derivative of the
    statics' fairlead tension against central differences."""
    line = jc.LineType(mass_per_length=2.0, diameter=0.03, tension_law=jc.LinearElastic(2e6))

    def fairlead_tension(p):
        model = jc.CableNetwork.from_branches(
            [[0.0, 0.0, -30.0], [p[1], 0.0, 0.0]], [jc.Branch(0, 1, line, p[0], 4)], {0: jc.Fixed(), 1: jc.Fixed()}
        )
        return jc.solve_statics(model, jc.Environment(current=(0.3, 0.0, 0.0))).tension[-1]

    for direction in ([1.0, 0.0], [0.0, 1.0]):
        check = jc.check_derivative(fairlead_tension, jnp.array([43.0, 30.0]), direction=jnp.array(direction))
        assert check.trusted, check
        assert abs(check.derivative) > 1.0, check  # N/m: both reach the tension


def test_a_derivative_where_a_node_is_held_by_nothing_names_the_node():
    """A line lying slack on a frictionless seabed between two supports has an
    equilibrium (found, without a derivative) but no derivative of it: nothing holds its
    nodes sideways. `jax.grad` says so, naming the first such node (node 2, the first of
    the branch's own nodes after the two junctions), in place of lineax's "operator is
    singular"."""
    line = jc.LineType(mass_per_length=50.0, diameter=0.08, tension_law=jc.LinearElastic(5e8))
    env = jc.Environment(depth=DEPTH, seabed=jc.Seabed(stiffness=1e5, damping=0.0, friction=0.0))

    def lowest(length):
        ends = [[0.0, 0.0, -DEPTH], [90.0, 0.0, -DEPTH]]
        held = {0: jc.Fixed(), 1: jc.Fixed()}
        model = jc.CableNetwork.from_branches(ends, [jc.Branch(0, 1, line, length, 10)], held)
        solution = jc.solve_statics(model, env)
        return jnp.sum(solution.state.positions[:, 2]), solution

    _, solution = lowest(100.0)  # 10 m longer than the supports are apart
    assert bool(jnp.all(solution.tension == 0.0))
    with pytest.raises(Exception, match="every segment at node 2 is slack, so nothing holds that node sideways"):
        jax.grad(lambda length: lowest(length)[0])(100.0)
