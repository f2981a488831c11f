"""Statics on random legal scenes (`benchmarks/statics_fuzz.py`): every scene's
equilibrium is checked by a force balance written with numpy from the positions, not
by jaxcable's equations, and where one applies against Irvine's elastic catenary.

The default suite solves a few scenes of the kinds that the previous solver
(Levenberg–Marquardt with an energy-descent fallback) failed on; `-m slow` runs 200.
"""

import equinox as eqx
import jax
import numpy as np
import optimistix as optx
import pytest

import jaxcable as jc
from benchmarks import statics_fuzz

# Seed 0: a buoyant slack line whose catenary guess sags the wrong way, so that the
# whole line must float up through slack; seed 7: a light (0.1 kg/m), stiff (EA 3.8e9
# N) riser that a 1.6 m/s current must swing tens of metres from vertical; seed 8: a
# clump weight hanging in a current. Few segments each, to keep compilation short.
QUICK = (0, 7, 8)


def solve_and_check(seed):
    fuzz = statics_fuzz.scene(seed)
    solution = jc.solve_statics(fuzz.model, fuzz.env, throw=False)
    return fuzz, solution, statics_fuzz.check(fuzz, solution)


@pytest.mark.parametrize("seed", QUICK)
def test_fuzz_scenes_reach_equilibrium(seed):
    fuzz, solution, verdict = solve_and_check(seed)
    assert solution.result == optx.RESULTS.successful, statics_fuzz.describe(fuzz)
    assert verdict["equilibrium"], verdict
    # The check is not vacuous: the starting shape is far from equilibrium by it.
    start, scale = statics_fuzz.node_forces(fuzz, np.asarray(fuzz.model.node_positions))
    assert np.max(np.abs(start[np.asarray(fuzz.model.free_nodes)])) / scale > 1e3 * verdict["relative_residual"]


@pytest.mark.slow
def test_fuzz_scene_is_the_same_under_jit_and_vmap():
    """One scene eagerly, under `jit` and as a batch of two (itself and the same scene
    with a 10 % stronger current) under `vmap`: the same equilibrium, and the batch's
    second case is an equilibrium of its own water."""
    fuzz = statics_fuzz.scene(7)
    eager = jc.solve_statics(fuzz.model, fuzz.env)
    traced = jax.jit(lambda m, e: jc.solve_statics(m, e))(fuzz.model, fuzz.env)
    np.testing.assert_allclose(traced.state.positions, eager.state.positions, rtol=1e-12, atol=1e-9)

    current = fuzz.env.current
    assert not isinstance(current, jc.CurrentProfile)  # the fuzz draws uniform currents
    stronger = eqx.tree_at(lambda e: e.current, fuzz.env, 1.1 * current)
    envs = jax.tree.map(lambda a, b: np.stack([a, b]), fuzz.env, stronger)
    batch = jax.vmap(lambda e: jc.solve_statics(fuzz.model, e, throw=False))(envs)
    np.testing.assert_allclose(batch.state.positions[0], eager.state.positions, rtol=1e-12, atol=1e-9)
    second = statics_fuzz.FuzzScene(fuzz.seed, fuzz.kind, fuzz.model, stronger, fuzz.bodies, fuzz.features)
    assert statics_fuzz.check(second, jax.tree.map(lambda x: x[1], batch))["equilibrium"]
    assert np.max(np.abs(batch.state.positions[1] - batch.state.positions[0])) > 0.1  # the current moved it


# The phrases that name a failure's cause (`jaxcable._statics.solve.failure_message`).
CAUSES = ("lies on the seabed", "is on slack line", "close to it", "far from it", "must stretch", "still stretching")


@pytest.mark.slow
def test_fuzz_200_scenes():
    """200 scenes: the engine's verdict is the independent check's on every one (no
    equilibrium claimed that the check refuses), every catenary found is within its
    O(1/N²) bound (`statics_fuzz.CATENARY_CONSTANT`), at least 198 are found, and every
    failure names its cause. At the commit that measured it 199 of these 200 were
    found; the one left (seed 153, a heavy line hanging onto the bed in a weak current)
    is still being laid out along the bed when its steps run out
    (`benchmarks/README.md`, *Statics on random scenes*)."""
    records = statics_fuzz.run(range(200))
    assert all(r["converged"] == r["equilibrium"] for r in records)
    assert sum(r["equilibrium"] for r in records) >= 198
    failed = [r["message"] for r in records if not r["converged"]]
    assert all("solve_statics found no equilibrium: " in m and any(c in m for c in CAUSES) for m in failed)
    catenaries = [r for r in records if "catenary_error" in r and r["equilibrium"]]
    assert catenaries
    bound = statics_fuzz.CATENARY_CONSTANT
    assert all(r["catenary_error"] <= bound * r["catenary_bound"] for r in catenaries)
