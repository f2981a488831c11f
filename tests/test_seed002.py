"""Seed 002's towed trawl in steady tow: the static equilibrium in the tow's frame, and
the dynamics that must keep it.

The reference is the discrete equilibrium written out by hand with numpy, independent of
jaxcable's Lagrangian: at every free node (the branch point, the two diverters, the buoy
and the cable's interior nodes), Hooke's-law tensions along the solved segments, half of
each adjacent segment's submerged weight and drag, and the body's net weight, drag and
constant force must sum to zero.
"""

import numpy as np
import pytest

import jaxcable as jc
from jaxcable.examples._seed002 import (
    BUOY,
    DIVERTER,
    DIVERTER_FORCE,
    STEP_TIME,
    VEHICLE,
    steady_tow,
    towed_trawl,
)

SPEED = 1.0  # m/s


@pytest.fixture(scope="module")
def trawl():
    model, env = towed_trawl((SPEED, 3.0), segments=(10, 5))
    state, statics = steady_tow(model, env, SPEED, STEP_TIME - 20.0)
    return model, env, state, statics


def test_trawl_nodes_balance_by_hand(trawl):
    model, env, _, statics = trawl
    rho, g = float(env.water_density), float(env.gravity)
    line = model.line
    positions = np.asarray(statics.state.positions)
    ends = np.asarray(model.segment_nodes)
    chord = positions[ends[:, 1]] - positions[ends[:, 0]]
    stretched = np.linalg.norm(chord, axis=1)
    tau = chord / stretched[:, None]
    length = np.asarray(model.segment_length)
    tension = np.asarray(line.tension_law.axial_stiffness) * (stretched / length - 1)
    np.testing.assert_allclose(np.asarray(statics.tension), tension, rtol=1e-6)

    # Drag per stretched length on the water flowing past at −SPEED along x, uniform
    # along a straight segment: C_n |u_n| u_n + C_τ |u_τ| u_τ.
    u = np.array([-SPEED, 0.0, 0.0])
    diameter = np.asarray(line.diameter)
    c_n = 0.5 * rho * np.asarray(line.normal_drag) * diameter
    c_t = 0.5 * rho * np.asarray(line.tangential_drag) * np.pi * diameter
    u_t = (tau @ u)[:, None] * tau
    u_n = u - u_t
    drag = (c_n * np.linalg.norm(u_n, axis=1))[:, None] * u_n + (c_t * np.linalg.norm(u_t, axis=1))[:, None] * u_t
    per_end = 0.5 * drag * stretched[:, None]
    per_end[:, 2] -= 0.5 * (np.asarray(line.mass_per_length) - rho * np.asarray(line.area)) * g * length

    force = np.zeros_like(positions)
    np.add.at(force, ends[:, 0], tension[:, None] * tau + per_end)
    np.add.at(force, ends[:, 1], -tension[:, None] * tau + per_end)
    for node, body, push in ((1, VEHICLE, 0.0), (2, DIVERTER, DIVERTER_FORCE), (3, DIVERTER, -DIVERTER_FORCE), (4, BUOY, 0.0)):
        # The floating buoy's buoyancy, drag and added mass act on its part below z = 0.
        height = body.get("height", 0.0)
        wet = np.clip((height / 2 - positions[node, 2]) / height, 0.0, 1.0) if height else 1.0
        force[node, 2] -= (body["mass"] - rho * body["volume"] * wet) * g
        force[node] += 0.5 * rho * body["drag_area"] * wet * np.linalg.norm(u) * u
        force[node, 1] += push
    free = np.asarray(model.free_nodes)
    scale = np.max(np.abs(tension))
    assert np.max(np.abs(force[free])) < 1e-7 * scale


def test_trawl_is_symmetric_and_floats(trawl):
    # The diverters' opposite forces spread the sweep branches symmetrically about the
    # tow's vertical plane, and the buoy floats, piercing the surface, with the branch
    # point hanging nearly a branch's length below it.
    _, _, state, statics = trawl
    p = np.asarray(statics.state.positions)
    np.testing.assert_allclose(p[2] * [1, -1, 1], p[3], atol=1e-6)
    assert p[2, 1] > 50.0
    assert -BUOY["height"] / 2 < p[4, 2] < BUOY["height"] / 2
    assert p[1, 2] < -90.0
    np.testing.assert_allclose(np.asarray(state.velocities)[:, 0], SPEED)


def test_steady_tow_stays_steady(trawl):
    # Galilean invariance: statics in a current −V, started moving at V behind a tow point
    # moving at V, is a solution of the dynamics. Until the step at 300 s the trawl must
    # keep its tensions and its shape relative to the tow point.
    model, env, state, statics = trawl
    ts = np.linspace(STEP_TIME - 20.0, STEP_TIME - 5.0, 4)
    result = jc.simulate(model, env, ts[-1], t0=ts[0], ts=ts, initial=state, rtol=1e-9, atol=1e-9)
    tension = np.asarray(result.tension)
    np.testing.assert_allclose(tension, np.broadcast_to(np.asarray(statics.tension), tension.shape), rtol=1e-6)
    shift = SPEED * (ts - ts[0])
    moved = np.asarray(result.positions) - np.asarray(statics.state.positions)[None]
    np.testing.assert_allclose(moved[..., 0], np.broadcast_to(shift[:, None], moved.shape[:2]), atol=1e-6)
    np.testing.assert_allclose(moved[..., 1:], 0.0, atol=1e-6)
