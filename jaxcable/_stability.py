"""Whether a fixed step is stable: an explicit Runge–Kutta method's stability function
at a scene's fastest modes.

A fixed step (MoorDyn's `dtM`) cannot shrink where the state starts to grow, so a step
beyond the method's stability limit runs to non-finite numbers. On the linear test
equation y' = λ y one step multiplies y by R(λ Δt), with R(z) = 1 + z bᵀ (I − z A)⁻¹ 𝟙
from the method's Butcher tableau (A, b); the step is stable where |R| ≤ 1 at every
fast mode λ of the scene ([`jaxcable._advice.fastest_eigenvalues`][]: the segments'
axial modes, damping included, and the seabed's contact where a segment can reach the
bed over the run, `jaxcable._reach`). The two-stage methods
(midpoint, Heun) have R(z) = 1 + z + z²/2: on the imaginary axis |R|² = 1 + (ωΔt)⁴/4
grows a little every step, so an undamped axial mode is never strictly stable, and the
damping of MoorDyn's `BA/-zeta` is what lets MoorDyn run such steps. The slow transverse
modes are undamped too when linearised at rest, but grow by (ωΔt)⁴/8 a step, 1e-4 or
less at the steps the fast modes allow, and quadratic drag holds them (as in MoorDyn):
the check is on the fast modes only. A line's bending modes (where it has EI) are
transverse modes too, undamped at rest, but may be fast where segments are short and
stiff in bending: they count where a run's fixed steps would grow them by more than
`BENDING_RUN_GROWTH` (the Low & Langley jumper's fastest, 13 rad/s, grows by 4e-9 a
midpoint step of 1 ms, 4e-4 over its 107,000 steps).
"""

import diffrax
import numpy as np

from ._advice import _unpack, bending_modes, fastest_eigenvalues

STABLE_GROWTH = 1.0 + 1e-9
"""The largest |R(λ Δt)| accepted as stable: 1, with room for rounding in R."""

BENDING_RUN_GROWTH = 1.01
"""The most an undamped bending mode may grow over a run's fixed steps, |R|ⁿ, and
not count against the step: 1 %, before drag damps it."""


def stability_function(solver: diffrax.AbstractSolver, z: np.ndarray) -> np.ndarray | None:
    """R(z) of an explicit Runge–Kutta `solver` at the complex `z` (any shape), from its
    Butcher tableau; `None` for a solver without one (implicit and implicit–explicit
    methods, whose fixed steps this check does not cover)."""
    z = np.asarray(z, dtype=complex)
    if isinstance(solver, diffrax.Euler):  # diffrax writes it out, without a tableau
        return 1 + z
    tableau = getattr(solver, "tableau", None)
    if not isinstance(solver, diffrax.AbstractERK) or not isinstance(tableau, diffrax.ButcherTableau):
        return None
    stages = tableau.num_stages
    a = np.zeros((stages, stages))
    for i, row in enumerate(tableau.a_lower, start=1):
        a[i, : len(row)] = row
    b = np.asarray(tableau.b_sol, dtype=float)
    # Explicit: A is strictly lower triangular, so (I − z A)⁻¹ 𝟙 is the stage sums by
    # forward substitution, one stage at a time for every z at once.
    sums = []
    for i in range(stages):
        sums.append(1 + z * sum(a[i, j] * sums[j] for j in range(i)))
    return 1 + z * sum(b[i] * sums[i] for i in range(stages))


def fixed_step_growth(solver: diffrax.AbstractSolver, dt: float, model, env=None, steps: int = 1) -> float | None:
    """The largest |R(λ Δt)| of `solver` at step `dt` (s) over the fastest modes of
    `model` in `env` (or of a built scene alone) in a run of `steps` steps: ≤ 1 is
    stable. The seabed's modes count for the segments that can reach it in that time
    (`jaxcable._reach`). The bending modes
    count only where `steps` steps would grow them by more than `BENDING_RUN_GROWTH`
    (module notes). `None` where the solver has no explicit tableau (see
    `stability_function`)."""
    growth = stability_function(solver, fastest_eigenvalues(model, env, bending=False, duration=steps * dt) * dt)
    if growth is None:
        return None
    largest = float(np.max(np.abs(growth)))
    model, env, _ = _unpack(model, env, None)
    if model.line.bending_stiffness is not None:
        at_bending = stability_function(solver, 1j * bending_modes(model, env) * dt)
        assert at_bending is not None  # the solver has a tableau: it gave `growth`
        bending = float(np.max(np.abs(at_bending)))
        if bending**steps > BENDING_RUN_GROWTH:
            largest = max(largest, bending)
    return largest
