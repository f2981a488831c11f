"""The implicit–explicit split: its stiff part against the energy's gradient, and a
KenCarp run against a tight explicit reference."""

import equinox as eqx
import jax
import jax.numpy as jnp
import numpy as np
import pytest

import jaxcable as jc
from jaxcable._equations import lagrangian as lag
from jaxcable._simulation.simulate import nonstiff_field, stiff_field, vector_field
from jaxcable.examples import anchored_line


def _moving_state(model, seed=0):
    rng = np.random.default_rng(seed)
    free = model.free_nodes
    return (
        model.node_positions[free] + 0.05 * rng.normal(size=(free.size, 3)),
        jnp.asarray(0.2 * rng.normal(size=(free.size, 3))),
    )


@pytest.mark.parametrize("mass_matrix", ["lumped", "consistent"])
def test_internal_forces_are_the_elastic_gradient_plus_viscous_pull(mass_matrix):
    """`internal_forces` written directly as T τ equals −∂/∂x of the elastic energy
    Σ L W(ε) (by `jax.grad`) plus the viscous tension along each segment."""
    model, env = anchored_line(5, mass_matrix=mass_matrix)
    law = jc.KelvinVoigt(3e7, 3e6, 2e5)
    model = eqx.tree_at(lambda m: m.line.tension_law, model, jax.tree.map(lambda x: jnp.broadcast_to(x, (5,)), law))
    positions, velocities = lag.full_state(model, 0.4, *_moving_state(model))

    def elastic(p):
        _, _, strain = lag.segment_geometry(model, p)
        return jnp.sum(model.segment_length * model.line.tension_law.elastic_energy_density(strain))

    _, tangent, strain = lag.segment_geometry(model, positions)
    viscous = model.line.tension_law.tension(
        strain, lag.strain_rate(model, positions, velocities)
    ) - model.line.tension_law.elastic_tension(strain)
    pull = np.zeros(positions.shape)
    ends = np.asarray(model.segment_nodes)
    for s, (i, j) in enumerate(ends):
        pull[i] += viscous[s] * tangent[s]
        pull[j] -= viscous[s] * tangent[s]
    expected = -jax.grad(elastic)(positions) + pull
    np.testing.assert_allclose(lag.internal_forces(model, positions, velocities), expected, rtol=1e-10, atol=1e-6)


@pytest.mark.parametrize("mass_matrix", ["lumped", "consistent"])
def test_split_fields_sum_to_the_whole(mass_matrix):
    model, env = anchored_line(5, mass_matrix=mass_matrix)
    y = _moving_state(model, 3)
    whole = vector_field(0.7, y, (model, env))
    parts = jax.tree.map(jnp.add, stiff_field(0.7, y, (model, env)), nonstiff_field(0.7, y, (model, env)))
    for a, b in zip(parts, whole):
        np.testing.assert_allclose(a, b, rtol=1e-9, atol=1e-9 * float(jnp.max(jnp.abs(b))))


def test_a_misspelt_part_is_an_error_not_all_forces():
    model, env = anchored_line(3, mass_matrix="lumped")
    with pytest.raises(ValueError, match=r"part must be one of \('all', 'internal', 'external'\), got 'intrenal'"):
        lag.free_accelerations(model, env, 0.0, *_moving_state(model), part="intrenal")


@pytest.mark.slow
def test_kencarp_follows_a_tight_reference():
    """KenCarp4 (axial forces implicit, the rest explicit), the `kencarp4` preset, on the
    anchored line over 2 s against Dopri5 at rtol = 1e-10, in hundreds of steps: with
    diffrax's default root finder (VeryChord) it took 369,274 (`kencarp4_newton`)."""
    model, env = anchored_line(6, mass_matrix="lumped")
    static = jc.solve_statics(model, env)
    ts = np.linspace(0.0, 2.0, 21)
    tight, kencarp = jc.SolverConfig(rtol=1e-10, atol=1e-10), jc.SOLVERS["kencarp4"](rtol=1e-7, atol=1e-7)
    reference = jc.simulate(model, env, 2.0, ts=ts, initial=static.state, solver=tight)
    run = jc.simulate(model, env, 2.0, ts=ts, initial=static.state, solver=kencarp)
    assert bool(run.success)
    assert int(run.stats["num_steps"]) < 2_000
    peak = float(jnp.max(reference.tension))
    assert float(jnp.max(jnp.abs(run.tension - reference.tension))) < 1e-3 * peak
