"""The towed trawl in steady tow: the static equilibrium in the tow's frame, and
the dynamics that must keep it.

The reference is the discrete equilibrium written out by hand with numpy, independent of
jaxcable's Lagrangian: at every free node (the branch point, the two diverters, the buoy
and the cable's interior nodes), Hooke's-law tensions along the solved segments, half of
each adjacent segment's submerged weight and drag, and the body's net weight, drag and
constant force must sum to zero.
"""

import numpy as np
import pytest
from helpers import hand_forces

import jaxcable as jc
from jaxcable.examples._towed_trawl import (
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
    positions = np.asarray(statics.state.positions)
    # The water flows past at −SPEED along x; the floating buoy's buoyancy and drag act
    # on its part below z = 0, and each diverter pushes its way across.
    bodies = {1: VEHICLE, 2: DIVERTER, 3: DIVERTER, 4: BUOY}
    tension, force = hand_forces(model, env, positions, bodies, flow=(-SPEED, 0.0, 0.0))
    np.testing.assert_allclose(np.asarray(statics.tension), tension, rtol=1e-6)
    force[2, 1] += DIVERTER_FORCE
    force[3, 1] -= DIVERTER_FORCE
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
    config = jc.SolverConfig(rtol=1e-9, atol=1e-9)
    result = jc.simulate(model, env, ts[-1], t0=ts[0], ts=ts, initial=state, solver=config)
    tension = np.asarray(result.tension)
    np.testing.assert_allclose(tension, np.broadcast_to(np.asarray(statics.tension), tension.shape), rtol=1e-6)
    shift = SPEED * (ts - ts[0])
    moved = np.asarray(result.positions) - np.asarray(statics.state.positions)[None]
    np.testing.assert_allclose(moved[..., 0], np.broadcast_to(shift[:, None], moved.shape[:2]), atol=1e-6)
    np.testing.assert_allclose(moved[..., 1:], 0.0, atol=1e-6)
