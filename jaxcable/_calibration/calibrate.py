"""Calibration: fit drag coefficients to towing records by gradients through the
simulation.

The fit minimises the mean squared residual between the records' observables and the
rigs' simulations of them, each record's series scaled by its own root-mean-square
value, so that tensions (N) and depths (m), and a light tow's small tensions and a heavy
one's large, weigh alike. The coefficients are fitted in logs, which keeps them positive
and makes a step a relative change. Records on rigs of the same structure are padded to
one length and simulated as one `vmap`ped batch.

After the fit, `report` gives the coefficients' covariance and the warnings
(`jaxcable._calibration.report`); `discretisation_check` asks whether the segmentation
was fine enough (`jaxcable._calibration.discretisation`).
"""

import functools
import math
from collections.abc import Mapping, Sequence

import diffrax
import equinox as eqx
import jax
import jax.numpy as jnp
import numpy as np
import optax

from .._solver.config import SolverConfig
from .problem import FittingProblem, evaluate, fitting_problem, residual_jacobian, solver_tolerances
from .records import TowingRecord
from .report import STALL_GAIN, TANGENT_TOLERANCE, TIGHTEST_TOLERANCE, CalibrationResult, report
from .towing import COEFFICIENTS, AbstractTowingRig, rig_solver

# The central differences' step in each log coefficient, 1 %: large enough that a solve's
# own error hardly moves the difference (on the sample records at rtol = 1e-6 the
# forward-mode derivatives differed from it by 2.8 % and 5.4 % with a 0.1 % step, from
# the solves' noise over the step, and by 0.26 % and 0.42 % with 1 %), small enough that
# its truncation error (~1e-4 of the derivative) is not.
_DIFFERENCE_STEP = 1e-2


def calibration_solver(**options) -> SolverConfig:
    """[`jaxcable.calibrate`][]'s default [`jaxcable.SolverConfig`][]: the rigs'
    ([`jaxcable.calibration.rig_solver`][]) with `adjoint=diffrax.ForwardMode()`, which makes the
    fit's gradient forward mode. `options` are `SolverConfig`'s keyword arguments,
    replacing these defaults: `calibration_solver(rtol=1e-8)`."""
    return rig_solver(**{"adjoint": diffrax.ForwardMode(), **options})


def calibrate(
    tests: Sequence[TowingRecord | tuple[AbstractTowingRig, TowingRecord]],
    start: Mapping[str, float],
    *,
    optimizer: optax.GradientTransformation | None = None,
    max_steps: int = 50,
    tolerance: float = 1e-6,
    solver: SolverConfig | None = None,
    progress: bool = True,
) -> CalibrationResult:
    """Fit drag coefficients to towing records.

    **Arguments:**

    - `tests`: the records, each either a [`jaxcable.io.TowingRecord`][] whose header names
        its rig (see [`jaxcable.calibration.rig_from_conditions`][]), or a pair `(rig, record)`.
        All are fitted jointly.
    - `start`: the coefficients to fit, by name (`"normal_drag"` K_n,
        `"tangential_drag"` K_τ, `"specific_drag"` k₀), with their starting values.
        Every other coefficient stays as the rig has it.
    - `optimizer`: any optax `GradientTransformation`, stepping in the log of each
        coefficient (so `optax.adam(0.05)` changes each by about 5 % a step).
        [`jaxcable.calibration.default_optimizer`][]`()` by default: L-BFGS with a backtracking
        line search. It is called with the extra arguments `value`, `grad` and
        `value_fn` (the loss), which L-BFGS's line search needs and others ignore.
        Reuse one object across fits to reuse their compilation.
    - `max_steps`: the most optimizer iterations.
    - `tolerance`: stop when the loss falls by less than this, relative, over an
        iteration.
    - `solver`: how each simulation is integrated, a [`jaxcable.SolverConfig`][]. Its
        adjoint is also the gradient mode: `diffrax.ForwardMode()` takes the
        residuals' Jacobian in forward mode, one tangent per coefficient; any other
        adjoint (`diffrax.RecursiveCheckpointAdjoint()`, say) takes the loss's gradient
        in reverse mode through it. With a few coefficients forward mode is the
        cheaper, and it yields the Jacobian that the uncertainty needs anyway
        (`benchmarks/calibration.py` measures both), so the default is
        [`jaxcable.calibration.calibration_solver`][]`()`.
    - `progress`: show a progress bar over iterations.

    **Returns:**

    A [`jaxcable.CalibrationResult`][].

    **Raises:**

    `ValueError` for an unknown coefficient, an optimizer that is not an optax
    `GradientTransformation`, a `solver` that is not a `SolverConfig`, a non-positive
    start, a record that lacks its rig's inputs or has none of its observables, or a
    coefficient that no record's rig depends on. `RuntimeError` if a simulation fails
    at the starting values.
    """
    names = tuple(start)
    for name in names:
        if name not in COEFFICIENTS:
            raise ValueError(f"calibrate: unknown coefficient {name!r}; known: {', '.join(COEFFICIENTS)}")
        if not (math.isfinite(start[name]) and start[name] > 0):
            raise ValueError(f"calibrate: start[{name!r}] must be positive and finite, got {start[name]}")
    if not names:
        raise ValueError("calibrate: start names no coefficient to fit")
    optimizer = default_optimizer() if optimizer is None else optimizer
    if not isinstance(optimizer, optax.GradientTransformation):
        raise ValueError(
            "calibrate: optimizer must be an optax GradientTransformation, such as optax.lbfgs() or "
            f"optax.adam(0.05), got {optimizer!r}"
        )
    solver = calibration_solver() if solver is None else solver
    if not isinstance(solver, SolverConfig):
        raise ValueError(f"calibrate: solver must be a jaxcable.SolverConfig, got {solver!r}")
    problem, pairs = fitting_problem(tests, names, solver)
    log_values = jnp.log(jnp.array([start[n] for n in names], dtype=float))
    problem, tangent_error = _trusted_tangents(problem, log_values)
    log_values, losses, converged, stalled, steps, (jacobian, r, successes) = _optimise(
        problem, log_values, optax.with_extra_args_support(optimizer), max_steps, tolerance, progress
    )
    return report(
        problem, start, log_values, losses, steps, converged, stalled, pairs, r, jacobian, successes, tangent_error
    )


@functools.cache
def default_optimizer() -> optax.GradientTransformationExtraArgs:
    """[`jaxcable.calibrate`][]'s default: optax's L-BFGS with a backtracking line search.

    L-BFGS backtracks on the loss alone: optax's default zoom line search also needs
    gradients at its trial points, which cost 3.6-5.9x a loss each (measured in
    `benchmarks/calibration.py`). Always the same object, so that fits reuse their
    compiled steps."""
    return optax.lbfgs(linesearch=optax.scale_by_backtracking_linesearch(max_backtracking_steps=20))


@eqx.filter_jit
def _update(log_values, state, value, grad, problem: FittingProblem, opt):
    """One optimizer update from the loss and gradient at `log_values`."""
    updates, state = opt.update(grad, state, log_values, value=value, grad=grad, value_fn=problem.loss)
    return optax.apply_updates(log_values, updates), state


def _optimise(problem, log_values, opt, max_steps, tolerance, progress):
    """Run optax from `log_values`. Returns the best iterate's log values, the losses
    up to it, whether the loss settled, whether the optimizer stalled (took no step),
    the iterations taken, and the best iterate's Jacobian, residuals and successes."""
    # Optax's initial states hold weakly typed leaves (L-BFGS's line search: an integer)
    # that the states its updates return do not: left so, `_update` compiled twice, once
    # for each, 18-20 s each on the calibration notebook's records.
    state = jax.tree.map(lambda x: jnp.asarray(x, dtype=jnp.asarray(x).dtype), opt.init(log_values))
    evaluated = []  # (log values, loss, report data)
    bar = _bar(max_steps, progress)
    converged, stalled, steps = False, False, 0
    for steps in range(1, max_steps + 1):
        value, grad, data = evaluate(log_values, problem)
        evaluated.append((log_values, float(value), data))
        if not math.isfinite(evaluated[0][1]):
            raise RuntimeError("calibrate: a simulation failed at the starting values; check the rigs and records")
        if bar is not None:
            if steps == 1:
                # The first iteration compiles the simulations (most of a minute): its
                # time would make the first estimate of the rest hours long.
                bar.reset()
                bar.set_description("calibrate")
            bar.update(1)
            bar.set_postfix(loss=f"{float(value):.4g}")
        if len(evaluated) > 1:
            previous, latest = evaluated[-2][1], evaluated[-1][1]
            if math.isfinite(latest) and previous - latest <= tolerance * latest:
                converged = True
                break
        if steps < max_steps:
            previous = log_values
            log_values, state = _update(log_values, state, value, grad, problem, opt)
            if np.array_equal(np.asarray(log_values), np.asarray(previous)):
                stalled = True  # evaluating the same point again would "converge"
                break
    if bar is not None:
        bar.close()
    losses = np.array([e[1] for e in evaluated])
    best = int(np.nanargmin(np.where(np.isfinite(losses), losses, np.nan)))
    log_values, _, data = evaluated[best]
    if data is None:
        jacobian, (r, successes) = residual_jacobian(log_values, problem)
    else:
        jacobian, r, successes = data
    if converged and _linear_gain(np.asarray(jacobian), np.asarray(r)) > STALL_GAIN:
        # The loss settled where, by its own Jacobian, one Gauss–Newton step would still
        # lower it: a line search that found no descent (an inaccurate gradient), not a
        # minimum.
        converged, stalled = False, True
    return (
        log_values,
        losses[: best + 1],
        converged,
        stalled,
        steps,
        (np.asarray(jacobian), np.asarray(r), successes),
    )


def _tangent_error(problem: FittingProblem, log_values) -> np.ndarray:
    """Per coefficient, `‖J_k − D_k‖ / ‖D_k‖`: the residuals' forward-mode derivative
    `J` against their central difference `D` in the log coefficient. The differences
    come out of the Jacobian's own compiled program, so the check compiles nothing."""
    jacobian, (r, successes) = residual_jacobian(log_values, problem)
    errors = []
    for k in range(len(problem.names)):
        step = jnp.zeros_like(log_values).at[k].set(_DIFFERENCE_STEP)
        _, (plus, ok_plus) = residual_jacobian(log_values + step, problem)
        _, (minus, ok_minus) = residual_jacobian(log_values - step, problem)
        if not all(bool(jnp.all(ok)) for ok in (*successes, *ok_plus, *ok_minus)):
            raise RuntimeError("calibrate: a simulation failed at the starting values; check the rigs and records")
        difference = (np.asarray(plus) - np.asarray(minus)) / (2 * _DIFFERENCE_STEP)
        scale = float(np.linalg.norm(difference))
        gap = float(np.linalg.norm(np.asarray(jacobian)[:, k] - difference))
        errors.append(gap / scale if scale > 0 else (0.0 if gap == 0 else math.inf))
    return np.asarray(errors)


def _trusted_tangents(problem: FittingProblem, log_values) -> tuple[FittingProblem, dict[str, float]]:
    """`problem` at a solver tolerance where its forward-mode derivatives agree with
    central differences within `TANGENT_TOLERANCE` at `log_values`, tightening rtol
    and atol 100-fold at a time down to `TIGHTEST_TOLERANCE` (the tolerances are data:
    nothing recompiles); and the agreement reached, by coefficient. Where it cannot
    be reached, the fit goes on at the tolerance that came closest, and the report warns."""
    errors = _tangent_error(problem, log_values)
    tried = [(float(errors.max()), problem, errors)]
    while errors.max() > TANGENT_TOLERANCE and (tolerances := solver_tolerances(problem)) is not None:
        if tolerances[0] <= TIGHTEST_TOLERANCE:
            break
        rtol, atol = (max(t / 100, TIGHTEST_TOLERANCE) for t in tolerances)
        problem = eqx.tree_at(
            lambda p: (
                p.solver.stepsize_controller.rtol,
                p.solver.stepsize_controller.atol,
                p.forward.stepsize_controller.rtol,
                p.forward.stepsize_controller.atol,
            ),
            problem,
            tuple(jnp.asarray(x) for x in (rtol, atol, rtol, atol)),
        )
        errors = _tangent_error(problem, log_values)
        tried.append((float(errors.max()), problem, errors))
    # Tighter is not always better: on the sample records the derivatives at rtol = 1e-9
    # were 1.4 and 33 times off where 1e-8's were within 0.05 %.
    _, problem, errors = min(tried, key=lambda t: t[0])
    return problem, {n: float(e) for n, e in zip(problem.names, errors)}


def _linear_gain(jacobian: np.ndarray, r: np.ndarray) -> float:
    """The share of the squared residuals `r` that one Gauss–Newton step with
    `jacobian` would remove, `gᵀ (JᵀJ)⁺ g / rᵀr` with `g = Jᵀr`: zero at a least-squares
    minimum (Jᵀr = 0), near one far from it."""
    g = jacobian.T @ r
    total = float(r @ r)
    return float(g @ np.linalg.pinv(jacobian.T @ jacobian) @ g) / total if total > 0 else 0.0


def _bar(total, progress):
    """A bar over at most `total` iterations, started as compiling (see `_optimise`)."""
    if not progress:
        return None
    from tqdm.auto import tqdm

    return tqdm(total=total, desc="calibrate (compiling)", unit="it")


"""A discretisation shift, in noise standard deviations, above which the model's own
discretisation error is comparable to the noise, and the fitted values carry it."""
