"""Bending stiffness EI (`jaxcable._equations.bending`) against closed forms and `jax.grad`.

- The written-out bending forces are `−∂Π/∂x` of the hinge energy, against `jax.grad` of
  the whole potential, on a branched 3-D network with a constrained node inside a line.
- A cantilever's tip deflection under a tip load, `P L³ / (3 EI)` (Euler–Bernoulli, small
  deflection), from `solve_statics`, converging with the segment count.
- A pinned–pinned beam-string's natural frequencies under tension T,
  `ω_n = (nπ/L) √((T + EI (nπ/L)²)/μ)`, from the eigenvalues of the linearised forces.
- A line with EI = 0 compiles the program of a line without EI: the same jaxpr.
"""

import jax
import jax.numpy as jnp
import numpy as np
import pytest

import jaxcable as jc
from jaxcable._equations import lagrangian as lag


def _branched():
    """Two lines, one with bending and one without, joined at a free junction; the
    first line's second node is constrained (a hinge all the same)."""
    bent = jc.LineType(20.0, 0.05, jc.LinearElastic(1e7), bending_stiffness=3e4)
    plain = jc.LineType(10.0, 0.04, jc.LinearElastic(5e6))
    junctions = np.array([[0.0, 0.0, -50.0], [60.0, 5.0, -10.0], [90.0, -10.0, 0.0]])
    model = jc.CableNetwork.from_branches(
        junctions,
        [jc.Branch(0, 1, bent, 80.0, 6), jc.Branch(1, 2, plain, 40.0, 3)],
        {0: jc.Fixed(), 2: jc.Fixed(), 3: jc.Fixed()},
    )
    return model


def test_bending_forces_on_segments_in_any_order_and_direction():
    """The bending forces ride on the segments' own tangents, turned where a segment
    runs against its hinge's direction: a line of 6 segments listed out of order, every
    other one reversed, against `jax.grad` of Π and against the same line listed in
    order."""
    line = jc.LineType(20.0, 0.05, jc.LinearElastic(1e7), bending_stiffness=3e4)
    rng = np.random.default_rng(2)
    x = np.cumsum(np.column_stack([np.full(7, 10.0), rng.normal(size=(7, 2))]), axis=0)
    ordered = np.stack([np.arange(6), np.arange(1, 7)], axis=1)
    mixed = ordered[[3, 0, 5, 1, 4, 2]]
    mixed[::2] = mixed[::2, ::-1]
    env = jc.Environment()
    forces = []
    for segments in (ordered, mixed):
        model = jc.CableNetwork(x, segments, np.full(6, 10.5), line, {0: jc.Fixed(), 6: jc.Fixed()}, line_ends=(0, 6))
        written = lag.generalised_forces(model, env, 0.0, x, 0 * x) - lag.nonconservative_forces(
            model, env, 0.0, x, 0 * x
        )
        grad = -jax.grad(lag.potential_energy, argnums=2)(model, env, jnp.asarray(x))
        np.testing.assert_allclose(written, grad, atol=1e-12 * np.abs(grad).max())
        forces.append(written)
    np.testing.assert_allclose(forces[1], forces[0], atol=1e-12 * np.abs(forces[0]).max())


def test_bending_forces_are_minus_the_gradient_of_the_potential():
    model = _branched()
    hinges = model.topology.hinge_nodes
    # Hinges at the bending line's interior nodes only (3 is constrained, and bends);
    # none at the junction (1) nor on the line without EI (its segments have EI = 0,
    # so its hinges carry no energy; they are planned all the same).
    assert 3 in hinges[1] and 1 not in hinges[1]
    env = jc.Environment()
    rng = np.random.default_rng(0)
    x = model.node_positions + rng.normal(scale=0.5, size=model.node_positions.shape)
    written = lag.generalised_forces(model, env, 0.0, x, 0 * x) - lag.nonconservative_forces(model, env, 0.0, x, 0 * x)
    grad = -jax.grad(lag.potential_energy, argnums=2)(model, env, jnp.asarray(x))
    np.testing.assert_allclose(written, grad, atol=1e-12 * np.abs(grad).max())
    # The bending part alone is not negligible here, and it is in the stiff internal part.
    without = jc.CableNetwork.from_branches(
        np.asarray(model.node_positions[:3]),
        [
            jc.Branch(0, 1, jc.LineType(20.0, 0.05, jc.LinearElastic(1e7)), 80.0, 6),
            jc.Branch(1, 2, jc.LineType(10.0, 0.04, jc.LinearElastic(5e6)), 40.0, 3),
        ],
        {0: jc.Fixed(), 2: jc.Fixed(), 3: jc.Fixed()},
    )
    bending = lag.internal_forces(model, x, 0 * x) - lag.internal_forces(without, x, 0 * x)
    assert np.abs(bending).max() > 10.0
    np.testing.assert_allclose(np.sum(bending, axis=0), 0.0, atol=1e-9)  # no net force


def test_zero_bending_stiffness_compiles_no_bending():
    def model(**ei):
        line = jc.LineType(20.0, 0.05, jc.LinearElastic(1e7), **ei)
        return jc.CableNetwork.from_branches(
            np.array([[0.0, 0.0, -40.0], [50.0, 0.0, 0.0]]),
            [jc.Branch(0, 1, line, 70.0, 5)],
            {0: jc.Fixed(), 1: jc.Fixed()},
        )

    plain, zero = model(), model(bending_stiffness=0.0)
    assert zero.line.bending_stiffness is None and zero.topology == plain.topology
    assert zero.topology.hinge_nodes.shape == (3, 0)
    env = jc.Environment(current=[0.5, 0.0, 0.0])
    x = np.asarray(plain.node_positions)

    def program(m):
        return str(jax.make_jaxpr(lambda y: lag.generalised_forces(m, env, 0.0, y, 0 * y))(x))

    assert program(zero) == program(plain)
    assert program(model(bending_stiffness=1e3)) != program(plain)


@pytest.mark.parametrize("value", [-1.0, np.nan, np.inf])
def test_bad_bending_stiffness_is_refused_by_name(value):
    with pytest.raises(ValueError, match="LineType.bending_stiffness"):
        jc.LineType(20.0, 0.05, jc.LinearElastic(1e7), bending_stiffness=value)


CANTILEVER = {"length": 10.0, "bending_stiffness": 2e5, "load": 20.0}


def _cantilever_tip(n: int) -> float:
    """The tip deflection (m) of a horizontal cantilever of `n` free segments under a
    tip load, by `solve_statics`, weightless (g → 0).

    Clamped by prescribing two nodes, at x = ∓h/2: a hinge's curvature stands for the
    half segments on either side of it, so the clamp's hinge at x = h/2 puts the
    clamped section at the prescribed segment's midpoint, x = 0. The first free node
    is then at 3h/2, and the tip at L."""
    length, ei, load = CANTILEVER.values()
    h = length / (n + 0.5)
    x = (np.arange(n + 2) - 0.5) * h
    line = jc.LineType(1e-3, 0.01, jc.LinearElastic(1e9), area=1e-7, bending_stiffness=ei)
    model = jc.CableNetwork(
        np.stack([x, 0 * x, 0 * x], axis=1),
        np.stack([np.arange(n + 1), np.arange(1, n + 2)], axis=1),
        np.full(n + 1, h),
        line,
        {0: jc.Fixed(), 1: jc.Fixed()},
        bodies={n + 1: jc.Body(force=[0.0, 0.0, -load])},
        mass_matrix="lumped",
    )
    start = jc.State(model.node_positions, 0 * model.node_positions)  # not hung along its load
    solution = jc.solve_statics(model, jc.Environment(gravity=1e-9), initial=start)
    return -float(solution.state.positions[-1, 2])


def _cantilever_closed_form() -> float:
    length, ei, load = CANTILEVER.values()
    return load * length**3 / (3 * ei)  # 3.3 mm: PL²/EI = 0.01, small deflection


def test_cantilever_tip_deflection():
    assert _cantilever_tip(8) == pytest.approx(_cantilever_closed_form(), rel=5e-3)


@pytest.mark.slow
def test_cantilever_converges_with_segments():
    errors = [abs(_cantilever_tip(n) / _cantilever_closed_form() - 1) for n in (4, 8, 16)]
    assert errors[2] < 2e-3
    assert errors[0] > 2.5 * errors[1] > 2.5**2 * errors[2]  # about second order


def _beam_string_frequencies(n: int, modes: int, tension: float, ei: float, length: float, mass: float):
    """The lowest transverse natural frequencies (rad/s) of a pinned–pinned line of `n`
    segments held straight at `tension` (N), from the eigenvalues of the Jacobian of
    its forces, weightless; and its mass per stretched length (kg/m)."""
    ea = 1e6  # a strain of 1e-3, well clear of the slack switch's width (1e-5)
    rest = length / (1 + tension / ea) / n
    x = np.linspace(0.0, length, n + 1)
    line = jc.LineType(
        mass, 0.02, jc.LinearElastic(ea), normal_added_mass=0.0, tangential_added_mass=0.0, bending_stiffness=ei
    )
    model = jc.CableNetwork(
        np.stack([x, 0 * x, 0 * x], axis=1),
        np.stack([np.arange(n), np.arange(1, n + 1)], axis=1),
        np.full(n, rest),
        line,
        {0: jc.Fixed(), n: jc.Fixed()},
        mass_matrix="lumped",
    )
    env = jc.Environment(gravity=1e-9)
    free = model.free_nodes
    base = jnp.asarray(model.node_positions)

    def sideways(y):
        positions = base.at[free, 1].add(y)
        return lag.generalised_forces(model, env, 0.0, positions, 0 * positions)[free, 1]

    stiffness = -np.asarray(jax.jit(jax.jacfwd(sideways))(jnp.zeros(free.size)))
    lumped = np.asarray(lag.lumped_blocks(model, env, base))[free, 1, 1]
    omega_squared = np.sort(np.linalg.eigvals(stiffness / lumped[:, None]).real)
    return np.sqrt(omega_squared[:modes]), mass * rest * n / length


def test_beam_string_natural_frequencies():
    # Bending length √(EI/T) = 0.71 m on a 10 m span: mode 3's bending share is 44 %.
    tension, ei, length, mass, modes = 1e3, 500.0, 10.0, 5.0, 3
    errors = []
    for n in (20, 40):
        omega, mu = _beam_string_frequencies(n, modes, tension, ei, length, mass)
        k = np.arange(1, modes + 1) * np.pi / length
        exact = k * np.sqrt((tension + ei * k**2) / mu)
        errors.append(np.abs(omega / exact - 1))
    string = np.arange(1, modes + 1) * np.pi / length * np.sqrt(tension / mu)
    assert exact[-1] > 1.15 * string[-1]  # bending is felt
    assert errors[1].max() < 4e-3
    assert np.all(errors[0] > 3.5 * errors[1])  # second order in the segment length
