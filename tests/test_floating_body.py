"""A body with a height floats: buoyancy, added mass and drag on its submerged part.

References, independent of jaxcable's Lagrangian: the column's submerged fraction and
buoyancy potential in closed form, a moored buoy's static draft from a scalar force
balance solved by scipy's brentq, and its small heave oscillation's period,
2π √(m / k) with k = ρ g A + EA / L.
"""

import equinox as eqx
import jax
import jax.numpy as jnp
import numpy as np
import pytest
from scipy.optimize import brentq

import jaxcable as jc
from jaxcable._equations.lagrangian import column_buoyancy_potential, column_submerged_fraction

RHO, G = 1025.0, 9.81
HEIGHT, VOLUME, MASS = 2.0, 1.0, 300.0  # a 2 m tall float of 1 m³
ANCHOR, LENGTH, EA = -20.0, 19.0, 2.0e4  # a soft, taut, weightless mooring


def test_column_fraction_and_potential():
    z = jnp.linspace(-3.0, 3.0, 601)
    fraction = column_submerged_fraction(z, HEIGHT)
    expected = np.clip((HEIGHT / 2 - np.asarray(z)) / HEIGHT, 0.0, 1.0)
    np.testing.assert_allclose(fraction, expected, atol=1e-15)
    slope = jax.vmap(jax.grad(column_buoyancy_potential), in_axes=(0, None))(z, HEIGHT)
    np.testing.assert_allclose(slope, -expected, atol=1e-12)
    potential = column_buoyancy_potential(z, HEIGHT)
    np.testing.assert_allclose(potential[z <= -1.0], -z[z <= -1.0], atol=1e-12)
    np.testing.assert_allclose(potential[z >= 1.0], 0.0, atol=1e-12)
    # A point body is submerged everywhere.
    np.testing.assert_allclose(column_submerged_fraction(z, 0.0), 1.0)
    np.testing.assert_allclose(column_buoyancy_potential(z, 0.0), -z)


def moored_float(added_mass=0.0):
    area = 1e-4
    line = jc.LineType(
        RHO * area * 1e-3,
        0.01,
        jc.LinearElastic(EA),
        area=area * 1e-3,
        normal_drag=0.0,
        tangential_drag=0.0,
        normal_added_mass=0.0,
    )
    model = jc.CableNetwork.from_branches(
        np.array([[0.0, 0.0, ANCHOR], [0.0, 0.0, -0.5]]),
        [jc.Branch(0, 1, line, LENGTH, 1)],
        constraints={0: jc.Fixed()},
        bodies={1: jc.Body(mass=MASS, volume=VOLUME, height=HEIGHT, added_mass=added_mass)},
        mass_matrix="lumped",
    )
    return model, jc.Environment(water_density=RHO, gravity=G)


def draft_reference():
    """The float's centre height z from ρ g V f(z) = M g + EA ((z − anchor)/L − 1)."""

    def balance(z):
        wet = np.clip((HEIGHT / 2 - z) / HEIGHT, 0.0, 1.0)
        return RHO * G * VOLUME * wet - MASS * G - EA * ((z - ANCHOR) / LENGTH - 1)

    return brentq(balance, -HEIGHT / 2, HEIGHT / 2, xtol=1e-14)


def test_float_static_draft():
    model, env = moored_float()
    static = eqx.filter_jit(jc.solve_statics)(model, env)
    z = draft_reference()
    assert -HEIGHT / 2 < z < HEIGHT / 2  # it pierces the surface
    np.testing.assert_allclose(float(static.state.positions[1, 2]), z, atol=1e-9)


@pytest.mark.parametrize("added", [0.0, 0.5])
def test_float_heave_period(added):
    # Undamped (no drag), released 5 cm above its equilibrium: it heaves at
    # ω² = (ρ g A + EA/L) / (M + C_a ρ V f), f its equilibrium's submerged fraction,
    # while it stays within the linear range of the waterline.
    model, env = moored_float(added)
    z0 = draft_reference()
    wet = (HEIGHT / 2 - z0) / HEIGHT
    stiffness = RHO * G * VOLUME / HEIGHT + EA / LENGTH
    mass = MASS + added * RHO * VOLUME * wet + 0.5 * float(model.line.mass_per_length[0]) * LENGTH
    period = 2 * np.pi * np.sqrt(mass / stiffness)
    positions = model.node_positions.at[1].set(jnp.array([0.0, 0.0, z0 + 0.05]))
    initial = jc.State(positions, jnp.zeros_like(positions))
    ts = np.linspace(0.0, 5 * period, 2001)
    result = jc.simulate(model, env, ts[-1], ts=ts, initial=initial, solver=jc.SolverConfig(rtol=1e-10, atol=1e-10))
    z = np.asarray(result.positions[:, 1, 2]) - z0
    # Upward zero crossings, interpolated, give the period.
    k = np.flatnonzero((z[:-1] < 0) & (z[1:] >= 0))
    crossings = ts[k] - z[k] * (ts[k + 1] - ts[k]) / (z[k + 1] - z[k])
    measured = np.mean(np.diff(crossings))
    np.testing.assert_allclose(measured, period, rtol=2e-3)
    if added == 0.0:
        # A linear oscillator keeps its amplitude. With added mass it does not quite: the
        # added mass C_a ρ V f(z) changes with the draft, and jaxcable, like MoorDyn,
        # applies it as Morison's inertia force, not through a kinetic energy.
        np.testing.assert_allclose(np.max(np.abs(z)), 0.05, rtol=1e-3)


def test_float_heaves_on_the_wave_surface():
    # In a wave, the float is wet up to the surface η, not to z = 0: with no drag and no
    # fluid inertia, buoyancy to η is the only wave force, and the heave solves
    # M z'' = ρ g V f(z − η(t)) − M g − EA ((z − anchor)/L − 1), f the wet fraction.
    # scipy integrates that scalar equation; buoyancy to z = 0 would leave the float at
    # rest.
    from scipy.integrate import solve_ivp

    model, _ = moored_float()
    wave = jc.Airy(0.4, 8.0, 50.0)
    env = jc.Environment(water_density=RHO, gravity=G, depth=50.0, waves=(wave,), fluid_inertia=False)
    z0 = draft_reference()
    mass = MASS + 0.5 * float(model.line.mass_per_length[0]) * LENGTH
    omega = 2 * np.pi / 8.0

    def heave(t, y):
        eta = 0.2 * np.cos(-omega * t)  # the crest is at x = 0 at t = 0
        wet = np.clip((HEIGHT / 2 - (y[0] - eta)) / HEIGHT, 0.0, 1.0)
        force = RHO * G * VOLUME * wet - MASS * G - EA * ((y[0] - ANCHOR) / LENGTH - 1)
        return [y[1], force / mass]

    ts = np.linspace(0.0, 24.0, 481)
    reference = solve_ivp(heave, (0.0, 24.0), [z0, 0.0], t_eval=ts, rtol=1e-11, atol=1e-12, method="DOP853").y[0]
    positions = model.node_positions.at[1].set(jnp.array([0.0, 0.0, z0]))
    config = jc.SolverConfig(rtol=1e-10, atol=1e-10)
    result = jc.simulate(model, env, 24.0, ts=ts, initial=jc.State(positions, jnp.zeros_like(positions)), solver=config)
    z = np.asarray(result.positions[:, 1, 2])
    assert np.ptp(reference) > 0.3  # it heaves, by about the wave's height
    np.testing.assert_allclose(z, reference, atol=1e-6)
    np.testing.assert_allclose(np.asarray(result.positions[:, 1, :2]), 0.0, atol=1e-9)
