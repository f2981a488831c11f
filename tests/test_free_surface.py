"""The still-water surface (`Environment(free_surface=True)`): buoyancy, drag and added
mass on the submerged part of each segment only, against closed forms."""

import jax
import jax.numpy as jnp
import numpy as np
import pytest

import jaxcable as jc
from jaxcable._equations import lagrangian as lag
from jaxcable._equations.hydro import submerged_interval

RHO, G = 1025.0, 9.81
MASS, DIAMETER, EA = 20.0, 0.1, 1e9  # kg/m, m, N: stiff, so the strain is the chord's
BOTTOM, TOP, LENGTH, SEGMENTS = -10.3, 5.0, 15.0, 12


def vertical_line(current=(0.0, 0.0, 0.0), free_surface=True, axial_stiffness=EA):
    """A taut vertical line from (0, 0, −10.3) to (0, 0, 5), 15 m unstretched: 10.3 m of
    its 15.3 m stretched length under water."""
    line = jc.LineType(MASS, DIAMETER, jc.LinearElastic(axial_stiffness), normal_drag=1.2, tangential_drag=0.0)
    model = jc.CableNetwork.from_branches(
        junctions=[[0.0, 0.0, BOTTOM], [0.0, 0.0, TOP]],
        branches=[jc.Branch(0, 1, line, LENGTH, SEGMENTS)],
        constraints={0: jc.Fixed(), 1: jc.Fixed()},
    )
    env = jc.Environment(water_density=RHO, gravity=G, current=current, free_surface=free_surface)
    return model, env


@pytest.mark.parametrize("free_surface", [True, False])
def test_buoyancy_acts_on_the_submerged_length(free_surface):
    # The supports carry the line's weight less the buoyancy of what is under water. The
    # strain is uniform to ~1e-5 (weight / EA), so the submerged unstretched length is
    # L · 10.3 / 15.3.
    model, env = vertical_line(free_surface=free_surface)
    static = jc.solve_statics(model, env)
    area = np.pi * DIAMETER**2 / 4
    submerged = LENGTH * (-BOTTOM) / (TOP - BOTTOM) if free_surface else LENGTH
    expected = MASS * G * LENGTH - RHO * area * G * submerged
    np.testing.assert_allclose(float(jnp.sum(static.reactions[:, 2])), expected, rtol=1e-6)


def test_drag_acts_on_the_submerged_length():
    # A current across the vertical line: the supports resist C_n U² over the 10.3 m of
    # stretched length below the surface, none over the 5 m above it.
    speed = 1.0
    model, env = vertical_line(current=(speed, 0.0, 0.0))
    static = jc.solve_statics(model, env)
    normal = 0.5 * RHO * 1.2 * DIAMETER
    np.testing.assert_allclose(float(jnp.sum(static.reactions[:, 0])), -normal * speed**2 * -BOTTOM, rtol=1e-6)


def test_potential_is_smooth_across_the_surface():
    # As a node crosses z = 0 the buoyancy's potential and its gradient change
    # continuously: the gradient matches central differences on both sides and at it.
    # A soft line (EA = 1 N), so that gravity and buoyancy dominate the potential.
    model, env = vertical_line(axial_stiffness=1.0)
    positions = np.asarray(model.node_positions).copy()
    node = int(np.argmin(np.abs(positions[:, 2] - 0.0) + 1e9 * (np.arange(len(positions)) < 2)))
    for z in (-1e-3, 0.0, 1e-3):
        positions[node, 2] = z
        grad = jax.grad(lag.potential_energy, argnums=2)(model, env, jnp.asarray(positions))[node, 2]
        h = 1e-6
        up, down = positions.copy(), positions.copy()
        up[node, 2] += h
        down[node, 2] -= h
        fd = (
            lag.potential_energy(model, env, jnp.asarray(up)) - lag.potential_energy(model, env, jnp.asarray(down))
        ) / (2 * h)
        np.testing.assert_allclose(float(grad), float(fd), rtol=1e-6, atol=1e-6)


def test_submerged_interval_cases():
    z_start = jnp.array([-2.0, 1.0, -1.0, 3.0, 0.0, 0.0])
    z_end = jnp.array([-1.0, 2.0, 3.0, -1.0, 0.0, 2.0])
    a, b = submerged_interval(z_start, z_end)
    np.testing.assert_allclose(a, [0.0, 0.0, 0.0, 0.75, 0.0, 0.0])
    np.testing.assert_allclose(b, [1.0, 0.0, 0.25, 1.0, 1.0, 0.0])
