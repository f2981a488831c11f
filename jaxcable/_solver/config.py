"""One solver configuration for every entry point that integrates in time.

[`jaxcable.simulate`][], [`jaxcable.sweep`][], the towing rigs, [`jaxcable.calibrate`][],
the scene runner and the command line all take a [`jaxcable.SolverConfig`][]: the
diffrax solver, its step-size controller, the first step, the step limit and the
adjoint, in one object. Tolerances and the first step are array leaves, not static
fields, so a new value reuses the compiled solve.
"""

from collections.abc import Callable

import diffrax
import equinox as eqx
import numpy as np
import optimistix as optx
from jaxtyping import Array, ArrayLike, Float

from .. import _checks as checks
from .._names import LARGEST_RTOL as LARGEST_RTOL
from .._names import SMALLEST_RTOL as SMALLEST_RTOL
from .picard import PicardTrapezoid
from .rk4 import RK4


def default_solver() -> diffrax.AbstractSolver:
    """`diffrax.Dopri5()`: jaxcable's default, chosen from measurements.

    On the anchored-line paper's taut, snapping line (C_E = 3e7 N) the step size is limited by
    accuracy, not stability: slackening and snap loads need short steps whatever the
    method. With 10 segments over 10 s at rtol = atol = 1e-6, an explicit Runge–Kutta
    method took about as many steps as `Kvaerno5` (Tsit5 4,055; Kvaerno5 with Newton
    3,952) and ran 45× faster, since an implicit step must form and factor the Jacobian.
    Of the explicit methods, Dopri5 took 11–28 % fewer steps than Tsit5 (fewer rejected
    across snap loads) and ran as fast to 1.6× faster at 10–100 segments over 60 s.
    `benchmarks/anchored_line.py` measures these.
    Use [`jaxcable.stiff_solver`][] where stability, not accuracy, limits the step.
    """
    return diffrax.Dopri5()


def stiff_solver() -> diffrax.AbstractSolver:
    """`Kvaerno5` with a full Newton root finder, for stability-limited (stiff) runs.

    diffrax's default root finder for implicit solvers, `VeryChord`, reuses one
    Jacobian across iterations; as segments slacken and re-tension that Jacobian goes
    stale and steps are rejected. On the anchored line (10 segments, 10 s) it took 8,277
    steps where Newton took 3,952, though each was cheaper.

    The root finder's linear solver is lineax's automatic choice, which
    [`jaxcable.simulate`][] replaces with [`jaxcable.NetworkJacobian`][] for a
    lumped-mass model, so that each Newton iteration costs O(N), not the O(N³) of a
    dense LU.
    """
    return diffrax.Kvaerno5(root_finder=diffrax.with_stepsize_controller_tols(optx.Newton)())


def kencarp4_newton() -> diffrax.AbstractSolver:
    """`KenCarp4` with a full Newton root finder: the `kencarp4` preset.

    With diffrax's default `VeryChord`, whose one Jacobian a step goes stale as the
    implicit axial forces stiffen, the anchored line (6 segments, 2 s, rtol 1e-7) took
    369,274 steps, 217,351 of them rejected, and 110 s; with Newton, 517 steps and
    0.24 s, within 2.2e-5 of the peak tension of Dopri5 at 1e-10 (`tests/test_imex.py`).
    """
    return diffrax.KenCarp4(root_finder=diffrax.with_stepsize_controller_tols(optx.Newton)())


class SolverConfig(eqx.Module):
    """How to integrate in time: the diffrax solver, step-size controller, first step,
    step limit and adjoint.

    `rtol`, `atol` and `dt0` are stored as float64 array leaves, not static fields, so a
    work-precision study or a sweep over tolerances compiles once. `max_steps` is static:
    diffrax sizes its loop and checkpoints by it.

    For example `SolverConfig(rtol=1e-8)`, `SolverConfig(jaxcable.stiff_solver())`, or
    fixed steps as MoorDyn takes them:
    `SolverConfig(diffrax.Tsit5(), dt0=1e-3, stepsize_controller=diffrax.ConstantStepSize())`.

    **Arguments:**

    - `solver`: any diffrax solver; [`jaxcable.default_solver`][] (Dopri5) by default,
        or [`jaxcable.stiff_solver`][] (Kvaerno5 with Newton) where stiffness, not
        accuracy, limits the step. Implicit–explicit solvers (`KenCarp3/4/5`, `Sil3`)
        get the line's axial forces implicitly and the rest explicitly. An implicit
        solver's linear solver lives in its root finder, as in diffrax: lineax's
        automatic choice (the default) is replaced by [`jaxcable.NetworkJacobian`][]
        for a lumped-mass model; pass `lineax.LU()` there for a dense solve, or
        `NetworkJacobian(model)` to insist on the structured one.
    - `rtol`, `atol`: the default `diffrax.PIDController`'s tolerances (–; atol in m
        and m/s, on positions and velocities); 1e-6 each. An implicit solver's root
        finder built with `diffrax.with_stepsize_controller_tols` takes them too.
    - `dt0`: the first step (s), or with a fixed step the step; chosen by diffrax by
        default.
    - `stepsize_controller`: any diffrax step-size controller instead of the
        PIDController, such as `diffrax.ConstantStepSize()` with `dt0`. It carries its
        own tolerances, so `rtol` and `atol` may not be given with it; an implicit
        solver then needs a root finder with tolerances of its own.
    - `max_steps`: the most steps before a solve is declared failed; 1,000,000 by
        default.
    - `adjoint`: how reverse-mode gradients go through the solve;
        `diffrax.RecursiveCheckpointAdjoint()` by default. `diffrax.ForwardMode()`
        for forward-mode derivatives (`jax.jacfwd`), which [`jaxcable.calibrate`][]
        also reads as its choice of gradient mode.

    **Raises:**

    `ValueError` naming the field and the value for a solver, controller or adjoint
    that is not diffrax's, a non-positive or non-finite `rtol`, `atol` or `dt0`, an
    `rtol` below `SMALLEST_RTOL` (1e-13, which float64 cannot meet) or above
    `LARGEST_RTOL` (0.1, a tenth of the state per step), a
    `max_steps` that is not a positive integer, or tolerances given together with a
    `stepsize_controller`.
    """

    solver: diffrax.AbstractSolver
    stepsize_controller: diffrax.AbstractStepSizeController
    dt0: Float[Array, ""] | None
    adjoint: diffrax.AbstractAdjoint
    max_steps: int = eqx.field(static=True)

    def __init__(
        self,
        solver: diffrax.AbstractSolver | None = None,
        *,
        rtol: Float[ArrayLike, ""] | None = None,
        atol: Float[ArrayLike, ""] | None = None,
        dt0: Float[ArrayLike, ""] | None = None,
        stepsize_controller: diffrax.AbstractStepSizeController | None = None,
        max_steps: int = 1_000_000,
        adjoint: diffrax.AbstractAdjoint | None = None,
    ):
        self.solver = default_solver() if solver is None else solver
        _check_type("solver", self.solver, diffrax.AbstractSolver, "diffrax.Tsit5()")
        if stepsize_controller is None:
            rtol = _positive("rtol", 1e-6 if rtol is None else rtol)
            checks.enforce(
                [
                    checks.Condition(
                        "SolverConfig.rtol",
                        checks.on_host(rtol) < SMALLEST_RTOL,
                        rtol,
                        f"must be at least {SMALLEST_RTOL:g}, below which float64 rounding (ε = 2.2e-16) "
                        "exceeds the error the controller allows and the step shrinks without end",
                    ),
                    checks.Condition(
                        "SolverConfig.rtol",
                        checks.on_host(rtol) > LARGEST_RTOL,
                        rtol,
                        f"must be at most {LARGEST_RTOL:g}: a looser step's error is as large as the solution",
                    ),
                ]
            )
            self.stepsize_controller = diffrax.PIDController(
                rtol=rtol,
                atol=_positive("atol", 1e-6 if atol is None else atol),
            )
        else:
            if rtol is not None or atol is not None:
                raise ValueError(
                    "SolverConfig: rtol and atol set the default PIDController's tolerances; with "
                    f"stepsize_controller={stepsize_controller!r}, give them to that controller instead"
                )
            _check_type(
                "stepsize_controller",
                stepsize_controller,
                diffrax.AbstractStepSizeController,
                "diffrax.ConstantStepSize()",
            )
            self.stepsize_controller = stepsize_controller
        self.dt0 = None if dt0 is None else _positive("dt0", dt0)
        if isinstance(max_steps, bool) or not isinstance(max_steps, int) or max_steps < 1:
            raise ValueError(f"SolverConfig.max_steps must be a positive integer, got {max_steps!r}")
        self.max_steps = max_steps
        self.adjoint = diffrax.RecursiveCheckpointAdjoint() if adjoint is None else adjoint
        _check_type("adjoint", self.adjoint, diffrax.AbstractAdjoint, "diffrax.ForwardMode()")


def describe_stepping(solver: SolverConfig) -> str:
    """How `solver` steps, in words: its method and fixed step or tolerances."""
    method = type(solver.solver).__name__
    controller = solver.stepsize_controller
    if isinstance(controller, diffrax.ConstantStepSize) and solver.dt0 is not None:
        return f"{method}, fixed steps of {float(np.asarray(solver.dt0)):g} s"
    if isinstance(controller, diffrax.PIDController):
        rtol, atol = (float(np.asarray(x)) for x in (controller.rtol, controller.atol))
        return f"{method}, adaptive (rtol {rtol:g}, atol {atol:g})"
    return f"{method}, {type(controller).__name__}"


def _check_type(field: str, value, kind: type, example: str) -> None:
    if not isinstance(value, kind):
        raise ValueError(
            f"SolverConfig.{field} must be a {kind.__module__.split('.')[0]}.{kind.__name__} "
            f"(such as {example}), got {value!r}"
        )


def _positive(field: str, value: Float[ArrayLike, ""]) -> Float[Array, ""]:
    array = checks.float_array(f"SolverConfig.{field}", value, ())
    checks.positive(f"SolverConfig.{field}", array)
    return array


class _Presets(dict):
    """A dict of factories by name whose failed lookup is a `ValueError` naming the
    field, the value and the choices, as every option error in jaxcable is."""

    def __init__(self, field: str, entries: dict):
        super().__init__(entries)
        self.field = field

    def __missing__(self, name):
        raise ValueError(f"{self.field} must be one of {tuple(self)}, got {name!r}")


def _preset(make_solver: Callable[[], diffrax.AbstractSolver]) -> Callable[..., SolverConfig]:
    def factory(**options) -> SolverConfig:
        return SolverConfig(make_solver(), **options)

    factory.__doc__ = f"`SolverConfig({make_solver.__name__}(), **options)`."
    return factory


SOLVERS: dict[str, Callable[..., SolverConfig]] = _Presets(
    "solver",
    {
        "dopri5": _preset(default_solver),
        "tsit5": _preset(diffrax.Tsit5),
        "bosh3": _preset(diffrax.Bosh3),
        "rk4": _preset(RK4),
        "dopri8": _preset(diffrax.Dopri8),
        "midpoint": _preset(diffrax.Midpoint),
        "heun": _preset(diffrax.Heun),
        "euler": _preset(diffrax.Euler),
        "kvaerno5": _preset(stiff_solver),
        "kencarp4": _preset(kencarp4_newton),
        "picard": _preset(PicardTrapezoid),
    },
)
"""Solver configurations by the names scene files and the command line use, each a
factory `SOLVERS[name](**options) -> SolverConfig` taking [`jaxcable.SolverConfig`][]'s
keyword arguments (`rtol`, `atol`, ...): explicit Runge–Kutta `dopri5` (the default),
`tsit5`, `bosh3` (three stages, third order: at a fixed step near its stability limit
the cheapest per simulated second where an error of about 1 % of the peak will do,
`benchmarks/speed.py`), `rk4` (the classical four-stage method,
[`jaxcable.RK4`][], MoorDyn's `RK4`: at a fixed step near its stability limit, which
is 1.6 times Bosh3's, cheaper still) and `dopri8`; the two-stage `midpoint` and `heun` and the one-stage `euler`,
for fixed steps as MoorDyn takes them (its `RK2` is the midpoint method) with
`dt0=` and `stepsize_controller=diffrax.ConstantStepSize()`; implicit `kvaerno5`
([`jaxcable.stiff_solver`][]),
implicit–explicit `kencarp4` (the line's axial forces implicit, the rest explicit; with Newton's
root finder, as `kvaerno5`), and
`picard`, Zhukov's Picard–trapezoid iteration ([`jaxcable.PicardTrapezoid`][]), the
historical baseline. An unknown name raises `ValueError` naming it and the choices."""
