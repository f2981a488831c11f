"""The advice's stiffest axial mode against the eigenvalues of the linearised model."""

import jax
import jax.numpy as jnp
import numpy as np
import pytest

import jaxcable as jc
from jaxcable import _lagrangian as lag
from jaxcable._advice import advice, stiffest_axial_mode


def taut_line(mass_matrix: str, damping_ratio: float = 0.0) -> jc.BuiltScene:
    # A straight, stretched line between two anchors: its fastest mode is axial.
    rope = jc.LineTypeSpec("rope", mass_per_length=2.0, diameter=0.02, axial_stiffness=4e6,
                           axial_damping_ratio=damping_ratio, tangential_added_mass=0.5)
    points = (jc.PointSpec("a", "fixed", (0.0, 0.0, -50.0)), jc.PointSpec("b", "fixed", (101.0, 0.0, -50.0)))
    lines = (jc.LineSpec("1", "rope", 0, 1, 100.0, 20),)
    scene = jc.Scene(points, (rope,), lines, run=jc.RunSettings(mass_matrix=mass_matrix))
    return scene.build()


def largest_eigenvalue(built: jc.BuiltScene) -> float:
    """|λ|max of the first-order system linearised about the equilibrium at rest."""
    model, env = built.model, built.environment
    static = jc.solve_statics(model, env)
    free = model.free_nodes
    x0 = static.state.positions[free]
    n = x0.size

    def field(y):
        x, v = y[:n].reshape(x0.shape), y[n:].reshape(x0.shape)
        a, *_ = lag.free_accelerations(model, env, 0.0, x, v)
        return jnp.concatenate([v.ravel(), a.ravel()])

    jacobian = jax.jacfwd(field)(jnp.concatenate([x0.ravel(), jnp.zeros(n)]))
    return float(np.abs(np.linalg.eigvals(np.asarray(jacobian))).max())


@pytest.mark.parametrize("mass_matrix", ["lumped", "consistent"])
@pytest.mark.parametrize("damping_ratio", [0.0, 2.0])
def test_stiffest_mode_bounds_the_linearised_spectrum(mass_matrix, damping_ratio):
    # The alternating mode of a chain is the highest: a 20-segment line's largest
    # eigenvalue lies just below the two-node bound the advice quotes (sin(20π/42)
    # of it, undamped), never above it.
    built = taut_line(mass_matrix, damping_ratio)
    _, bound, _ = stiffest_axial_mode(built)
    measured = largest_eigenvalue(built)
    assert 0.97 * bound < measured <= bound * (1 + 1e-6)


def test_advice_counts_steps_from_the_bound():
    built = taut_line("lumped")
    omega, magnitude, _ = stiffest_axial_mode(built)
    # Undamped, lumped: ω_n = 2 √(EA / m) / l with m including tangential added mass.
    m = 2.0 + 1025.0 * np.pi * 0.01**2 * 0.5
    np.testing.assert_allclose(omega, 2 * np.sqrt(4e6 / m) / 5.0, rtol=1e-12)
    assert magnitude == omega
    text = " ".join(advice(built, 10.0))
    assert f"~{int(np.ceil(10.0 / (3.0 / magnitude))):,} steps" in text
