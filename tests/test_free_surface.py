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


BUOY_SCENE = """
[water]
depth = 100.0
free_surface = {free_surface}

[line_types.rope]
mass_per_length = 5.0
diameter = 0.05
axial_stiffness = 2.0e7

[points.anchor]
type = "fixed"
position = [0.0, 0.0, -100.0]

[points.buoy]
type = "free"
position = [20.0, 0.0, 50.0]
mass = 100.0
volume = 5.0{height}

[[lines]]
type = "rope"
from = "anchor"
to = "buoy"
length = 160.0
segments = 8
"""


@pytest.mark.parametrize("free_surface", ["true", "false"])
def test_a_point_buoy_above_the_water_is_reported(tmp_path, free_surface):
    """A free point whose body (5 m³, 50 kN of lift) holds a 160 m line 60 m above the
    sea: a body without a height keeps its whole buoyancy in the air (as MoorDyn's
    points do), which the run says; with a height its buoyancy follows its draft and it
    floats at the surface, with nothing to say."""
    path = tmp_path / "buoy.toml"
    path.write_text(BUOY_SCENE.format(free_surface=free_surface, height=""))
    run = jc.run_scene(jc.read_scene(path), duration=0.0)
    top = float(run.positions[0, 1, 2])
    assert top > 50.0  # the buoy, point 1, hangs the line up into the air
    (note,) = [n for n in run.notes if "point buoy" in n]
    assert note.startswith(
        f"{path}, line 15, key points.buoy: point buoy's body reaches z = {top:.2f} m, above the still-water"
    )
    assert "keeps the buoyancy of its whole volume (5 m³)" in note and "give it a height" in note
    if free_surface == "true":
        path.write_text(BUOY_SCENE.format(free_surface=free_surface, height="\nheight = 2.0"))
        floating = jc.run_scene(jc.read_scene(path), duration=0.0)
        assert -1.0 < float(floating.positions[0, 1, 2]) < 1.0  # at the surface, within its height
        assert not [n for n in floating.notes if "point buoy" in n]
