"""Whether a fixed step is stable: an explicit Runge–Kutta method's stability function
at a scene's fastest modes.

A fixed step (MoorDyn's `dtM`) cannot shrink where the state starts to grow, so a step
beyond the method's stability limit runs to non-finite numbers. On the linear test
equation y' = λ y one step multiplies y by R(λ Δt), with R(z) = 1 + z bᵀ (I − z A)⁻¹ 𝟙
from the method's Butcher tableau (A, b); the step is stable where |R| ≤ 1 at every
fast mode λ of the scene ([`jaxcable._equations.modes.fastest_eigenvalues`][]: the segments'
axial modes, damping included, and the seabed's contact where a segment can reach the
bed over the run, `jaxcable._model.reach`). The two-stage methods
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

A step given by a user or a file is judged at the taut modes ([`fixed_step_growth`][]); a
step chosen for a scene ([`stable_step`][], [`fixed_steps`][]) is also held within the
limit of a segment inside its slack switch's band, which a line that goes slack passes
through (`jaxcable._equations.modes._slack_band_modes`).
"""

from collections.abc import Iterable

import diffrax
import numpy as np

from .._equations.modes import bending_modes, fastest_eigenvalues, unpack
from .._model.network import CableNetwork
from .._sea.environment import Environment
from .config import SolverConfig
from .rk4 import RK4

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
    (`jaxcable._model.reach`). The bending modes
    count only where `steps` steps would grow them by more than `BENDING_RUN_GROWTH`
    (module notes). `None` where the solver has no explicit tableau (see
    `stability_function`)."""
    growth = stability_function(solver, fastest_eigenvalues(model, env, bending=False, duration=steps * dt) * dt)
    if growth is None:
        return None
    largest = float(np.max(np.abs(growth)))
    model, env, _ = unpack(model, env, None)
    if model.line.bending_stiffness is not None:
        at_bending = stability_function(solver, 1j * bending_modes(model, env) * dt)
        assert at_bending is not None  # the solver has a tableau: it gave `growth`
        bending = float(np.max(np.abs(at_bending)))
        if bending**steps > BENDING_RUN_GROWTH:
            largest = max(largest, bending)
    return largest


STEP_FRACTION = 0.7
"""The fraction of the stability limit ([`stable_step`][]) that [`fixed_steps`][] steps
at. The limit is that of the linearised modes, taut and inside the slack switch's band;
a segment crossing the band also stiffens with its strain rate (the damping's `C_v ε̇
H'(ε)`), which no linear mode holds: on a damped rope through its first snap RK4 went
non-finite at the limit and put a spike of 4× the peak tension into the history at
0.95 of it, and ran clean at 0.9 (`tests/test_advice.py`). At 0.7 RK4 also damps the
fastest axial mode rather than leaving it at the edge."""

NO_MODE_STEP = 0.1
"""The step (s) of [`fixed_steps`][] for scenes without a fast mode."""

# |z| = |λ Δt| up to which `stable_step` looks for the edge of a method's stability
# region: beyond every explicit method's (RK4's reaches 2.83 on the imaginary axis and
# 2.79 on the negative real axis; Dopri8's, 4.4 and 6.9), scanned this finely first.
_SCAN_LIMIT, _SCAN_POINTS = 8.0, 4001


def stable_step(solver: diffrax.AbstractSolver, model, env=None, duration: float | None = None) -> float | None:
    """The longest fixed step (s) at which `solver` keeps every fast mode of `model` in
    `env` (or of a built scene alone) from growing: |R(λ Δt)| ≤ 1 for each eigenvalue λ
    of [`jaxcable._equations.modes.fastest_eigenvalues`][] (the axial modes with their damping,
    taut and inside the slack switch's band, where a segment going slack or snapping
    taut is stiffer; the bending modes where the line has EI; and the seabed's modes
    where a segment can reach the bed in a run of `duration` (s; any length where
    `None`)).

    Along each mode's ray z = λ Δt the step grows from 0 until |R(z)| first exceeds 1:
    the stable steps from 0 up to there. Infinite where the scene has no fast mode; 0
    where a mode grows at any step (an undamped mode under a two-stage method, whose
    |R(iy)| exceeds 1 for every y > 0). `None` where the solver has no explicit tableau
    (`stability_function`)."""
    eigenvalues = fastest_eigenvalues(model, env, bending=True, duration=duration, slack_band=True)
    return _stable_step_at(solver, eigenvalues)


def _stable_step_at(solver: diffrax.AbstractSolver, eigenvalues: np.ndarray) -> float | None:
    """[`stable_step`][] at the given eigenvalues (rad/s, complex, any shape)."""
    eigenvalues = np.unique(eigenvalues)
    eigenvalues = eigenvalues[np.abs(eigenvalues) > 0]
    if eigenvalues.size == 0:
        return None if stability_function(solver, np.zeros(1)) is None else float("inf")
    reach = np.linspace(0.0, _SCAN_LIMIT, _SCAN_POINTS)[1:]
    directions = eigenvalues / np.abs(eigenvalues)
    growth = stability_function(solver, directions[:, None] * reach[None, :])
    if growth is None:
        return None
    unstable = np.abs(growth) > STABLE_GROWTH
    # The first unstable point of each ray, and the last stable one before it; then
    # bisection to the edge on every ray at once, to 1e-12 of the scan's spacing.
    crossed = unstable.any(axis=1)
    first = np.where(crossed, np.argmax(unstable, axis=1), 0)
    low, high = np.where(first == 0, 0.0, reach[first - 1]), reach[first]
    for _ in range(40):
        middle = 0.5 * (low + high)
        stable = np.abs(stability_function(solver, directions * middle)) <= STABLE_GROWTH
        low, high = np.where(stable, middle, low), np.where(stable, high, middle)
    edges = np.where(crossed, low, _SCAN_LIMIT)
    return float(np.min(edges / np.abs(eigenvalues)))


def fixed_steps(
    systems: Iterable[tuple[CableNetwork, Environment]], duration: float | None = None, max_steps: int = 1_000_000
) -> SolverConfig:
    """The fixed-step configuration a sweep takes when told nothing: the classical RK4
    ([`jaxcable.RK4`][], MoorDyn's `RK4`) at `STEP_FRACTION` (0.7) of its stability
    limit at the fast modes of every scene in `systems` ([`stable_step`][]), as a
    MoorDyn user picks `dtM` below its limit.

    Explicit steps are limited by the fastest axial mode, ω_n = 2 (N/L) √(EA/m): no
    explicit method steps past its stability limit, and an adaptive Dopri5 at rtol
    1e-6 stepped well below it (the anchored line, 20 segments over 60 s: 17,100–58,700
    steps where RK4 at this step takes 9,000), six field evaluations a step against
    RK4's four. With fixed steps every case of a sweep takes the same steps, so the
    batch runs in lockstep without a mask per case, and the output times end steps.
    A step that is unstable after all (a line that stiffens far beyond C_E) makes the
    state non-finite, which fails the run with `diffrax.RESULTS.nonfinite`.

    **Arguments:**

    - `systems`: each scene's `(model, env)`, concrete (a sweep's cases, say).
    - `duration`: the run's length (s), for which segments can reach the seabed.
    - `max_steps`: the configuration's step limit.

    **Returns:**

    `SolverConfig(RK4(), dt0=Δt, stepsize_controller=diffrax.ConstantStepSize())`.
    Where no scene has a fast mode (no line), Δt is `NO_MODE_STEP`.
    """
    # The least of the scenes' stable steps: the step at the union of their modes.
    eigenvalues = [
        fastest_eigenvalues(model, env, bending=True, duration=duration, slack_band=True) for model, env in systems
    ]
    step = _stable_step_at(RK4(), np.concatenate([np.ravel(e) for e in eigenvalues] or [np.zeros(0)]))
    assert step is not None  # RK4 has a tableau
    dt = NO_MODE_STEP if not np.isfinite(step) else STEP_FRACTION * step
    return SolverConfig(RK4(), dt0=dt, stepsize_controller=diffrax.ConstantStepSize(), max_steps=max_steps)
