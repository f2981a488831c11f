"""Calibration: fit drag coefficients to towing records by gradients through the
simulation.

The fit minimises the mean squared residual between the records' observables and the
rigs' simulations of them, each record's series scaled by its own root-mean-square
value, so that tensions (N) and depths (m), and a light tow's small tensions and a heavy
one's large, weigh alike. The coefficients are fitted in logs, which keeps them positive
and makes a step a relative change. Records on rigs of the same structure are padded to
one length and simulated as one `vmap`ped batch.

After the fit, each series' noise level σ is estimated from what is left of it, and the
coefficients' covariance is the Gauss–Newton sandwich `A⁻¹ B A⁻¹`, with
`A = Jᵀ J` and `B = Jᵀ diag(σ²) J` for the scaled residuals' Jacobian `J` (taken in
forward mode). It is the covariance of the estimator the fit uses, whatever the series'
noise levels; where they are proportional to the series' RMS, as in
[`jaxcable.calibration.synthetic_record`][], it is also the smallest attainable, `(Jᵀ diag(σ⁻²) J)⁻¹`.
(Weighting by the optimum's `1/σ²` while fitting with a common scale per observable
understated the spread of 16 refits on fresh noise 2.4-fold, measured.) A coefficient
whose uncertainty is large, or that is strongly correlated with another, is flagged:
the records do not pin it down.

That covariance assumes independent noise. Each series' residuals are checked for it
(`residual_check`: lag-1 autocorrelation, runs, mean offset); a series whose residuals
are correlated carries n_eff = n (1 − ρ)/(1 + ρ) samples' worth of information, and its
rows' share of `B` grows by n / n_eff; a warning says when the residuals show model
discrepancy rather than noise. Discrepancy that hides under the noise is what
`discretisation_check` looks for: it re-predicts at finer segmentation and gives the
linearised move of each fitted value.
"""

import functools
import math
import warnings
from collections.abc import Mapping, Sequence
from typing import NamedTuple

import diffrax
import equinox as eqx
import jax
import jax.numpy as jnp
import numpy as np
import optax

from .._solver.config import SolverConfig
from .records import TowingRecord
from .towing import COEFFICIENTS, AbstractTowingRig, rig_from_conditions, rig_solver

# Flag a coefficient whose one-standard-deviation relative uncertainty exceeds this:
# the records then leave it free to wander by more than the 5-10 % an engineer would
# accept from a calibration.
UNCERTAIN = 0.05
# Flag a pair of coefficients more correlated than this: the records pin a combination
# of them, not each one.
CORRELATED = 0.95
STALLED = (
    "the optimizer stalled after {iterations} iteration(s): it took no step, or the loss settled where its own "
    "Jacobian says one Gauss-Newton step would still lower it, so the values reported (the best iterate's) are "
    "not a fit. The derivatives were checked against central differences at the start (tangent_error), so the "
    "likelier causes are an optimizer that hovers near the minimum rather than reaching it (a fixed learning "
    "rate, as Adam's: raise max_steps, or use the default L-BFGS) or derivatives that went wrong away from the "
    "start: refit from the values found."
)
"""The warning of a stalled fit. Before the derivative check (`TANGENT_TOLERANCE`) its
usual cause was an inaccurate gradient: 40 segments of the sample records' 2e6 N cable,
where the tow-point load's forward-mode derivative was 3,000 times its central
difference at rtol = atol = 1e-6. Adam at a learning rate of 0.05 on the vertical tows
still ends this way (near the minimum, within 5 % of the truth)."""
TANGENT_TOLERANCE = 0.05
"""The largest difference, per coefficient, between the residuals' forward-mode
derivative and their central difference (as a share of the difference's norm) that a
fit accepts. Forward-mode tangents ride along with the simulation, whose step-size
controller sees only the states' error, so at a loose tolerance they can be far off
while the states are right; [`jaxcable.calibrate`][] then tightens the tolerance 100-fold
until they agree, down to `TIGHTEST_TOLERANCE`."""
TIGHTEST_TOLERANCE = 1e-10
# The central differences' step in each log coefficient, 1 %: large enough that a solve's
# own error hardly moves the difference (on the sample records at rtol = 1e-6 the
# forward-mode derivatives differed from it by 2.8 % and 5.4 % with a 0.1 % step, from
# the solves' noise over the step, and by 0.26 % and 0.42 % with 1 %), small enough that
# its truncation error (~1e-4 of the derivative) is not.
_DIFFERENCE_STEP = 1e-2
STALL_GAIN = 0.01
"""A fit whose loss settled is called stalled, not converged, when one Gauss–Newton
step with its own Jacobian would still remove more than this share of the squared
residuals (`_linear_gain`). Measured on the sample records: 1.5e-6 after a converged
fit, 0.97 at the start, 0.74 where a 40-segment fit's inaccurate gradient stopped it."""
# Padded samples sit this far (s) apart past a record's end, so that padded times stay
# strictly increasing (a tow speed's knots must) while simulating no further, to
# within microseconds.
_PAD_STEP = 1e-6


class CalibrationResult(NamedTuple):
    """What a calibration found.

    **Attributes:**

    - `values`: the fitted coefficients by name (SI: K_n and K_τ –, k₀ s²/m²).
    - `start`: where the fit started.
    - `uncertainty`: one standard deviation of each fitted value, from the Gauss–Newton
        sandwich covariance with each series' noise estimated from its residuals (same
        units as `values`).
    - `relative_uncertainty`: `uncertainty / values`, the standard deviation of the
        coefficient's log.
    - `correlation`: the coefficients' correlation matrix, in the order of `values`.
    - `sensitivity`: by name, how far a 10 % change of the coefficient moves the
        observables, as the root mean square over all samples in units of their
        estimated noise. Below about 0.1 the records hardly see the coefficient.
    - `noise`: the estimated noise standard deviation (SI) of each record's
        observables, from its residuals, by `(record name, observable)`. The
        uncertainties weigh each residual by it.
    - `loss`: the loss at each iterate, from the start to the best (the fitted values).
    - `iterations`: iterates evaluated.
    - `converged`: whether the loss stopped changing (relative change below the
        tolerance) before the iteration limit.
    - `stalled`: whether the optimizer stopped without reaching a minimum: it took no
        step, or the loss settled where one Gauss–Newton step would still lower it
        (`STALL_GAIN`); not convergence, and warned of.
    - `records`: the records fitted, in order.
    - `predictions`: for each record, the fitted model's observables at the record's
        times (SI), by name; NaN for a record whose simulation failed.
    - `residuals`: for each record, measured minus predicted, by name.
    - `success`: for each record, whether its final simulation reached the end.
    - `warnings`: the warnings, as sentences (observables that are not what an
        instrument reads, residuals that show model discrepancy rather than noise,
        coefficients the records do not pin down); also issued as `UserWarning`s.
    - `residual_checks`: by `(record name, observable)`, what the residuals say about
        the noise model: a [`jaxcable.calibration.ResidualCheck`][].
    - `inflation`: by coefficient, the factor by which the residuals' correlation
        widened its uncertainty over the one that independent noise would give; 1
        where every series' residuals look like independent noise.
    - `rigs`: the rigs the records were fitted on, in order, with their coefficients
        as they started (`rig.with_coefficients(values)` is the fitted model).
    - `jacobian`: for each record, by observable, the derivative of the prediction in
        the log of each coefficient at the fitted values (SI units of the observable),
        shape `(samples, coefficients)`, coefficients in the order of `values`.
    - `tangent_error`: by coefficient, how far the residuals' forward-mode derivative at
        the start lay from their central difference, as a share of the difference's
        norm, at the tolerance the fit ran at (`TANGENT_TOLERANCE`).
    - `tolerances`: `(rtol, atol)` the simulations ran at: the solver's own, or
        tighter where the tangents needed it; `None` for fixed steps.
    """

    values: dict[str, float]
    start: dict[str, float]
    uncertainty: dict[str, float]
    relative_uncertainty: dict[str, float]
    correlation: np.ndarray
    sensitivity: dict[str, float]
    noise: dict[tuple[str, str], float]
    loss: np.ndarray
    iterations: int
    converged: bool
    stalled: bool
    records: list[TowingRecord]
    predictions: list[dict[str, np.ndarray]]
    residuals: list[dict[str, np.ndarray]]
    success: list[bool]
    warnings: list[str]
    residual_checks: dict[tuple[str, str], "ResidualCheck"]
    inflation: dict[str, float]
    rigs: list[AbstractTowingRig]
    jacobian: list[dict[str, np.ndarray]]
    tangent_error: dict[str, float]
    tolerances: tuple[float, float] | None

    def summary(self) -> str:
        """A table of the fitted values with their uncertainties, then the warnings."""
        lines = [f"{'coefficient':<16} {'start':>10} {'fitted':>12} {'± 1σ':>11} {'(%)':>7} {'10% moves':>10}"]
        for name, value in self.values.items():
            lines.append(
                f"{name:<16} {self.start[name]:>10.4g} {value:>12.5g} {self.uncertainty[name]:>11.3g} "
                f"{100 * self.relative_uncertainty[name]:>7.2f} {self.sensitivity[name]:>9.3g}σ"
                + (
                    f"  (±1σ widened {self.inflation[name]:.3g}x for correlated residuals)"
                    if self.inflation[name] > 1.05
                    else ""
                )
            )
        state = (
            "stalled: no step lowered the loss"
            if self.stalled
            else "converged"
            if self.converged
            else "stopped at the iteration limit"
        )
        lines.append(f"{self.iterations} iterations ({state}); loss {self.loss[0]:.4g} -> {self.loss[-1]:.4g}")
        if self.tangent_error:
            worst = max(self.tangent_error.values())
            lines.append(
                f"derivatives within {100 * worst:.2g} % of central differences at the start "
                f"({_stepping(self.tolerances)})"
            )
        failed = [r.name for r, ok in zip(self.records, self.success) if not ok]
        if failed:
            lines.append(f"simulations that failed: {', '.join(failed)}")
        lines += [f"warning: {w}" for w in self.warnings]
        return "\n".join(lines)


class ResidualCheck(NamedTuple):
    """What one series' residuals (measured minus predicted, at the fitted values) say
    about the noise model: independent noise leaves no autocorrelation, no mean
    offset and about `n/2` runs of one sign.

    - `samples`: n.
    - `lag1`: the lag-1 autocorrelation ρ of the residuals, taken about zero rather
        than their mean, so that an offset counts as correlation (±`1/√n` for
        independent noise).
    - `mean_offset`: the residuals' mean over the series' RMS value (a relative bias;
        −0.01 is a model reading 1 % high).
    - `runs`, `expected_runs`: runs of one sign, counted and as independent noise
        would give them (`1 + 2 n₊ n₋ / n`).
    - `runs_z`: the runs' standard score; far below 0 when residuals drift.
    - `effective_samples`: n_eff = `n (1 − ρ)/(1 + ρ)`, between 1 and n, for an
        autocorrelation above `2/√n`; n otherwise.
    - `discrepancy`: whether the residuals show model discrepancy rather than noise:
        ρ above `3/√n`, runs below 3 standard deviations of their expectation, or a
        mean offset beyond 3 standard errors (with n_eff samples).
    """

    samples: int
    lag1: float
    mean_offset: float
    runs: int
    expected_runs: float
    runs_z: float
    effective_samples: float
    discrepancy: bool


def residual_check(residuals, scale: float = 1.0) -> ResidualCheck:
    """The [`jaxcable.calibration.ResidualCheck`][] of one series' residuals, shape
    `(n,)`, whose RMS value is `scale` (for the mean offset; the rest is
    scale-free)."""
    e = np.asarray(residuals, dtype=float)
    n = e.size
    energy = float(np.sum(e**2))
    rho = float(np.sum(e[1:] * e[:-1]) / energy) if n > 2 and energy > 0 else 0.0
    signs = e[e != 0] > 0
    m = signs.size
    positive = int(np.sum(signs))
    runs = int(1 + np.count_nonzero(signs[1:] != signs[:-1])) if m else 0
    expected = 1 + 2 * positive * (m - positive) / m if m else 0.0
    variance = (expected - 1) * (expected - 2) / (m - 1) if m > 1 else 0.0
    runs_z = (runs - expected) / math.sqrt(variance) if variance > 0 else 0.0
    # Below 2/√n a positive ρ is within independent noise's sampling spread.
    correlated = rho > 2 / math.sqrt(n)
    effective = min(max(n * (1 - rho) / (1 + rho), 1.0), n) if correlated else float(n)
    sigma = math.sqrt(energy / n) if n else 0.0
    mean = float(np.mean(e)) if n else 0.0
    offset_z = abs(mean) / (sigma / math.sqrt(effective)) if sigma > 0 else 0.0
    discrepancy = rho > 3 / math.sqrt(n) or runs_z < -3 or offset_z > 3
    return ResidualCheck(n, rho, mean / scale, runs, expected, runs_z, effective, bool(discrepancy))


class _Group(NamedTuple):
    """Records on rigs of one structure, padded to one length and stacked."""

    indices: tuple[int, ...]  # into the list of records
    lengths: tuple[int, ...]  # unpadded samples per record
    names: tuple[str, ...]  # observables measured by at least one record
    rigs: AbstractTowingRig  # leaves stacked over records
    times: jax.Array  # (records, samples)
    inputs: dict  # name -> (records, samples)
    observed: dict  # name -> (records, samples)
    mask: dict  # name -> (records, samples), 1 where measured
    scale: dict  # name -> (records,): each record's RMS of its measured values (SI)


def synthetic_record(
    rig: AbstractTowingRig,
    times,
    inputs: Mapping[str, np.ndarray] | None = None,
    *,
    noise: float = 0.02,
    seed: int = 0,
    observables: Sequence[str] | None = None,
    name: str = "synthetic",
    solver: SolverConfig | None = None,
) -> TowingRecord:
    """A towing record simulated on `rig`, with noise: for tests and examples.

    The noise model: each observable gets independent Gaussian noise of standard
    deviation `noise` × its root-mean-square value over the record, from
    `numpy.random.default_rng(seed)`. The inputs (the tow speed) are exact: in a test
    they are the controlled quantity.

    **Arguments:**

    - `rig`: the rig, with the true coefficients.
    - `times`: sample times (s), shape `(samples,)`, strictly increasing.
    - `inputs`: the rig's inputs at `times` (for [`jaxcable.calibration.HorizontalTow`][], the
        tow speed `"speed"` in m/s).
    - `noise`: the relative noise level; 0 for exact data.
    - `seed`: the random seed.
    - `observables`: which to record; by default all the rig's but those with
        `caveats` (HorizontalTow's `tension`: a load cell reads `tow_load`).
    - `name`: the record's name.
    - `solver`: how to integrate, a [`jaxcable.SolverConfig`][];
        [`jaxcable.calibration.rig_solver`][]`()` by default.

    **Returns:**

    A [`jaxcable.io.TowingRecord`][] whose conditions describe the rig (`rig.conditions()`).

    **Raises:**

    `ValueError` for an unknown observable, a missing input, or a negative noise level;
    `RuntimeError` if the simulation fails.
    """
    if not noise >= 0:
        raise ValueError(f"synthetic_record: noise must be non-negative, got {noise}")
    if observables is None:  # what instruments measure: not the observables with caveats
        observables = tuple(k for k in rig.observables if k not in rig.caveats)
    observables = tuple(observables)
    unknown = [o for o in observables if o not in rig.observables]
    if unknown:
        raise ValueError(
            f"synthetic_record: {type(rig).__name__} has no observable {unknown[0]!r}; it has {rig.observables}"
        )
    inputs = dict(inputs or {})
    missing = [i for i in rig.inputs if i not in inputs]
    if missing:
        raise ValueError(f"synthetic_record: {type(rig).__name__} needs input {missing[0]!r}")
    times = np.asarray(times, dtype=float)
    run = _simulate_one(rig, jnp.asarray(times), {k: jnp.asarray(inputs[k], dtype=float) for k in rig.inputs}, solver)
    if not bool(run.success):
        raise RuntimeError(
            f"synthetic_record: the simulation failed (starting equilibrium or run; diffrax: {run.simulation.result})"
        )
    clean = run.observables
    rng = np.random.default_rng(seed)
    columns = {k: np.asarray(inputs[k], dtype=float) for k in rig.inputs}
    for key in observables:
        values = np.asarray(clean[key])
        columns[key] = values + noise * np.sqrt(np.mean(values**2)) * rng.standard_normal(values.shape)
    return TowingRecord(times=times, columns=columns, conditions=rig.conditions(), name=name)


def calibration_solver(**options) -> SolverConfig:
    """[`jaxcable.calibrate`][]'s default [`jaxcable.SolverConfig`][]: the rigs'
    ([`jaxcable.calibration.rig_solver`][]) with `adjoint=diffrax.ForwardMode()`, which makes the
    fit's gradient forward mode. `options` are `SolverConfig`'s keyword arguments,
    replacing these defaults: `calibration_solver(rtol=1e-8)`."""
    return rig_solver(**{"adjoint": diffrax.ForwardMode(), **options})


@eqx.filter_jit
def _simulate_one(rig, times, inputs, solver):
    return rig.simulate(times, inputs, solver)


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
    problem, pairs = _problem(tests, names, solver)
    log_values = jnp.log(jnp.array([start[n] for n in names], dtype=float))
    problem, tangent_error = _trusted_tangents(problem, log_values)
    log_values, losses, converged, stalled, steps, (jacobian, r, successes) = _optimise(
        problem, log_values, optax.with_extra_args_support(optimizer), max_steps, tolerance, progress
    )
    return _report(
        problem, start, log_values, losses, steps, converged, stalled, pairs, r, jacobian, successes, tangent_error
    )


def _caveats(pairs) -> list[str]:
    """The rigs' caveats on the observables the records measure, one per rig type and
    observable, naming the records."""
    found: dict[str, list[str]] = {}
    for index, (rig, record) in enumerate(pairs):
        for name, caveat in rig.caveats.items():
            if name in record.columns:
                found.setdefault(caveat, []).append(record.name or f"tests[{index}]")
    return [f"{', '.join(names)}: {caveat}" for caveat, names in found.items()]


def _pair(test, index) -> tuple[AbstractTowingRig, TowingRecord]:
    if isinstance(test, TowingRecord):
        rig, record = rig_from_conditions(test.conditions, test.name or f"record {index}"), test
    else:
        rig, record = test
    if not isinstance(rig, AbstractTowingRig):
        raise ValueError(f"calibrate: tests[{index}] must pair a towing rig with a record, got {rig!r}")
    if not isinstance(record, TowingRecord):
        raise ValueError(f"calibrate: tests[{index}] must pair a rig with a TowingRecord, got {record!r}")
    label = record.name or f"tests[{index}]"
    missing = [k for k in rig.inputs if k not in record.columns]
    if missing:
        raise ValueError(f"calibrate: {label} has no {missing[0]!r} column, which {type(rig).__name__} needs as input")
    if not any(k in record.columns for k in rig.observables):
        raise ValueError(f"calibrate: {label} measures none of {type(rig).__name__}'s observables {rig.observables}")
    return rig, record


def _groups(pairs) -> list[_Group]:
    """Stack the records rig structure by rig structure, padding each group to its
    longest record: repeated final values, at times `_PAD_STEP` apart."""
    by_structure: dict = {}
    for i, (rig, _) in enumerate(pairs):
        by_structure.setdefault(jax.tree.structure(rig), []).append(i)
    groups = []
    for indices in by_structure.values():
        rigs = [pairs[i][0] for i in indices]
        records = [pairs[i][1] for i in indices]
        lengths = tuple(len(r.times) for r in records)
        size = max(lengths)
        names = tuple(k for k in rigs[0].observables if any(k in r.columns for r in records))

        def pad(values, n):
            return np.concatenate([values, np.full(size - n, values[-1])])  # noqa: B023 (called within this iteration)

        times = np.stack(
            [
                np.concatenate([r.times, r.times[-1] + _PAD_STEP * np.arange(1, size - len(r.times) + 1)])
                for r in records
            ]
        )
        inputs = {k: np.stack([pad(r.columns[k], len(r.times)) for r in records]) for k in rigs[0].inputs}
        observed, mask, scale = {}, {}, {}
        for k in names:
            observed[k] = np.stack(
                [pad(r.columns[k], len(r.times)) if k in r.columns else np.zeros(size) for r in records]
            )
            mask[k] = np.stack([(np.arange(size) < len(r.times)) & (k in r.columns) for r in records]).astype(float)
            scale[k] = jnp.asarray(
                [max(float(np.sqrt(np.mean(r.columns[k] ** 2))), 1e-12) if k in r.columns else 1.0 for r in records]
            )
        stacked = jax.tree.map(lambda *leaves: jnp.stack(leaves), *rigs)
        groups.append(
            _Group(
                tuple(indices),
                lengths,
                names,
                stacked,
                jnp.asarray(times),
                {k: jnp.asarray(v) for k, v in inputs.items()},
                {k: jnp.asarray(v) for k, v in observed.items()},
                {k: jnp.asarray(v) for k, v in mask.items()},
                scale,
            )
        )
    return groups


class _Problem(eqx.Module):
    """A calibration's data and settings, as one argument for the compiled steps, so
    that fits of the same structure reuse their compilation."""

    names: tuple[str, ...] = eqx.field(static=True)
    groups: tuple[_Group, ...]
    samples: jax.Array  # measured samples in all, for the mean
    solver: SolverConfig
    forward: SolverConfig  # `solver` with diffrax.ForwardMode, for the Jacobian

    @property
    def gradient(self) -> str:
        """`"forward"` or `"reverse"`: the gradient mode that `solver`'s adjoint asks for."""
        return "forward" if isinstance(self.solver.adjoint, diffrax.ForwardMode) else "reverse"

    def residuals(self, log_values, solver=None):
        """All scaled residuals, predicted minus measured over the RMS, masked, flat;
        and each group's per-record success. A failed simulation's residuals are
        zeroed, not NaN, so that gradients stay finite; `loss` reports the failure as
        infinite instead."""
        parts, successes = [], []
        predicted = _predict(log_values, self.names, self.groups, self.solver if solver is None else solver)
        for group, (observables, success) in zip(self.groups, predicted):
            successes.append(success)
            for k in group.names:
                scaled = (observables[k] - group.observed[k]) / group.scale[k][:, None]
                parts.append(jnp.where(success[:, None] & (group.mask[k] > 0), scaled, 0.0).reshape(-1))
        return jnp.concatenate(parts), tuple(successes)

    def loss_of(self, r, successes):
        """Half the mean squared scaled residual; infinite if a simulation failed."""
        ok = jnp.all(jnp.concatenate(successes))
        return jnp.where(ok, 0.5 * jnp.sum(r**2) / self.samples, jnp.inf)

    def loss(self, log_values, solver=None):
        return self.loss_of(*self.residuals(log_values, solver))


def _problem(tests, names, solver) -> tuple[_Problem, list]:
    """Check the records against their rigs, and group, pad and stack them."""
    pairs = [_pair(test, i) for i, test in enumerate(tests)]
    if not pairs:
        raise ValueError("calibrate: no records to fit")
    for name in names:
        if not any(name in rig.coefficients for rig, _ in pairs):
            raise ValueError(f"calibrate: no record's rig depends on {name!r}, so no record can fit it")
    groups = _groups(pairs)
    problem = _Problem(
        names=names,
        groups=tuple(groups),
        samples=jnp.asarray(sum(float(np.sum(m)) for g in groups for m in g.mask.values())),
        solver=solver,
        # The Jacobian needs forward mode whichever way the fit's gradient goes.
        forward=eqx.tree_at(lambda s: s.adjoint, solver, diffrax.ForwardMode()),
    )
    return problem, pairs


def _predict(log_values, names, groups, solver):
    """Each group's observables, name -> (records, samples), and per-record success."""
    values = dict(zip(names, jnp.exp(log_values)))
    out = []
    for group in groups:

        def one(rig, times, inputs):
            run = rig.with_coefficients(values).simulate(times, inputs, solver)
            return run.observables, run.success

        out.append(jax.vmap(one)(group.rigs, group.times, group.inputs))
    return out


@eqx.filter_jit
def _jacobian(log_values, problem: _Problem):
    """The residuals' Jacobian in the log coefficients, shape `(residuals, p)`, in
    forward mode; and (residuals, successes)."""

    def residuals(p):
        r, successes = problem.residuals(p, problem.forward)
        return r, (r, successes)

    return jax.jacfwd(residuals, has_aux=True)(log_values)


@eqx.filter_jit
def _reverse(log_values, problem: _Problem):
    return jax.value_and_grad(problem.loss)(log_values)


def _evaluate(log_values, problem: _Problem):
    """The loss and its gradient at `log_values`, and, in forward mode, what the
    report needs there: the Jacobian, residuals and successes. Each mode runs one
    compiled program, which the report reuses rather than compiling its own (every
    compiled program maps thousands of memory regions, and a process may hold only
    about 65,000: measured, 3,500 for a vertical-tow fit)."""
    if problem.gradient == "reverse":
        value, grad = _reverse(log_values, problem)
        return value, grad, None
    jacobian, (r, successes) = _jacobian(log_values, problem)
    return problem.loss_of(r, successes), jacobian.T @ r / problem.samples, (jacobian, r, successes)


@functools.cache
def default_optimizer() -> optax.GradientTransformationExtraArgs:
    """[`jaxcable.calibrate`][]'s default: optax's L-BFGS with a backtracking line search.

    L-BFGS backtracks on the loss alone: optax's default zoom line search also needs
    gradients at its trial points, which cost 3.6-5.9x a loss each (measured in
    `benchmarks/calibration.py`). Always the same object, so that fits reuse their
    compiled steps."""
    return optax.lbfgs(linesearch=optax.scale_by_backtracking_linesearch(max_backtracking_steps=20))


@eqx.filter_jit
def _update(log_values, state, value, grad, problem: _Problem, opt):
    """One optimizer update from the loss and gradient at `log_values`."""
    updates, state = opt.update(grad, state, log_values, value=value, grad=grad, value_fn=problem.loss)
    return optax.apply_updates(log_values, updates), state


def _optimise(problem, log_values, opt, max_steps, tolerance, progress):
    """Run optax from `log_values`. Returns the best iterate's log values, the losses
    up to it, whether the loss settled, whether the optimizer stalled (took no step),
    the iterations taken, and the best iterate's Jacobian, residuals and successes."""
    state = opt.init(log_values)
    evaluated = []  # (log values, loss, report data)
    bar = _bar(max_steps, progress)
    converged, stalled, steps = False, False, 0
    for steps in range(1, max_steps + 1):
        value, grad, data = _evaluate(log_values, problem)
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
        jacobian, (r, successes) = _jacobian(log_values, problem)
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


def _tolerances(problem: _Problem) -> tuple[float, float] | None:
    """The fit's step-size controller's `(rtol, atol)`; `None` if it has none (fixed
    steps)."""
    controller = problem.forward.stepsize_controller
    if not isinstance(controller, diffrax.PIDController):
        return None
    return float(controller.rtol), float(controller.atol)


def _stepping(tolerances: tuple[float, float] | None) -> str:
    return "fixed steps" if tolerances is None else "rtol = {:g}, atol = {:g}".format(*tolerances)


def _tangent_error(problem: _Problem, log_values) -> np.ndarray:
    """Per coefficient, `‖J_k − D_k‖ / ‖D_k‖`: the residuals' forward-mode derivative
    `J` against their central difference `D` in the log coefficient. The differences
    come out of the Jacobian's own compiled program, so the check compiles nothing."""
    jacobian, (r, successes) = _jacobian(log_values, problem)
    errors = []
    for k in range(len(problem.names)):
        step = jnp.zeros_like(log_values).at[k].set(_DIFFERENCE_STEP)
        _, (plus, ok_plus) = _jacobian(log_values + step, problem)
        _, (minus, ok_minus) = _jacobian(log_values - step, problem)
        if not all(bool(jnp.all(ok)) for ok in (*successes, *ok_plus, *ok_minus)):
            raise RuntimeError("calibrate: a simulation failed at the starting values; check the rigs and records")
        difference = (np.asarray(plus) - np.asarray(minus)) / (2 * _DIFFERENCE_STEP)
        scale = float(np.linalg.norm(difference))
        gap = float(np.linalg.norm(np.asarray(jacobian)[:, k] - difference))
        errors.append(gap / scale if scale > 0 else (0.0 if gap == 0 else math.inf))
    return np.asarray(errors)


def _trusted_tangents(problem: _Problem, log_values) -> tuple[_Problem, dict[str, float]]:
    """`problem` at a solver tolerance where its forward-mode derivatives agree with
    central differences within `TANGENT_TOLERANCE` at `log_values`, tightening rtol
    and atol 100-fold at a time down to `TIGHTEST_TOLERANCE` (the tolerances are data:
    nothing recompiles); and the agreement reached, by coefficient. Where it cannot
    be reached, the fit goes on at the tolerance that came closest, and the report warns."""
    errors = _tangent_error(problem, log_values)
    tried = [(float(errors.max()), problem, errors)]
    while errors.max() > TANGENT_TOLERANCE and (tolerances := _tolerances(problem)) is not None:
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


def _report(
    problem, start, log_values, losses, steps, converged, stalled, pairs, r, jacobian, successes, tangent_error
):
    """Unpad the predictions and residuals, estimate the noise, and form the
    Gauss–Newton covariance and the warnings."""
    names, groups = problem.names, problem.groups
    p = len(names)
    values = {n: float(v) for n, v in zip(names, np.exp(np.asarray(log_values)))}
    records = [record for _, record in pairs]
    predictions: list[dict] = [{} for _ in pairs]
    residuals: list[dict] = [{} for _ in pairs]
    derivatives: list[dict] = [{} for _ in pairs]
    success = [True] * len(pairs)
    noise: dict[tuple[str, str], float] = {}
    weights = np.zeros_like(r)
    widen = np.ones_like(r)
    checks: dict[tuple[str, str], ResidualCheck] = {}
    valid = sum(int(np.sum(np.asarray(m))) for g in groups for m in g.mask.values())
    offset = 0
    for group, ok in zip(groups, successes):
        size = group.times.shape[1]
        for k in group.names:
            for j, (i, n) in enumerate(zip(group.indices, group.lengths)):  # laid out (records, samples)
                block = slice(offset + j * size, offset + (j + 1) * size)
                success[i] = bool(ok[j])
                if k not in records[i].columns:
                    continue
                # r = (predicted − measured) / scale, so the predictions come back from it.
                scaled = r[block][:n] if success[i] else np.full(n, np.nan)
                predictions[i][k] = records[i].columns[k] + scaled * float(group.scale[k][j])
                derivatives[i][k] = jacobian[block][:n] * float(group.scale[k][j])
                residuals[i][k] = -scaled * float(group.scale[k][j])
                if not success[i]:
                    continue
                # Each record's own noise level: tests differ in their instruments. The
                # p fitted coefficients' share of the degrees of freedom is taken out in
                # proportion to the record's samples.
                dof = max(n * (1 - p / valid), 1.0)
                sigma = max(float(np.sqrt(np.sum(r[block][:n] ** 2) / dof)), 1e-12)
                weights[block][:n] = 1 / sigma
                noise[(records[i].name, k)] = sigma * float(group.scale[k][j])
                check = residual_check(-r[block][:n])  # scaled by the series' RMS already
                checks[(records[i].name, k)] = check
                # Correlated residuals carry n_eff samples' worth of information, not
                # n: their rows' share of the spread grows by n / n_eff (exact for a
                # Jacobian that varies slowly over the correlation length).
                widen[block][:n] = math.sqrt(n / check.effective_samples)
            offset += len(group.indices) * size
    measured = weights > 0
    jacobian = np.where(measured[:, None], jacobian, 0.0)  # a failed record's rows count for nothing
    inner = np.linalg.pinv(jacobian.T @ jacobian)
    noisy = jacobian / np.where(measured, weights, 1.0)[:, None]  # rows times σ
    white = np.sqrt(np.maximum(np.diag(inner @ (noisy.T @ noisy) @ inner), 0.0))
    noisy = noisy * widen[:, None]
    covariance = inner @ (noisy.T @ noisy) @ inner
    weighted = jacobian * weights[:, None]  # rows in units of their noise
    spread = np.sqrt(np.maximum(np.diag(covariance), 0.0))
    with np.errstate(invalid="ignore", divide="ignore"):
        correlation = covariance / np.outer(spread, spread)
    rows = max(int(np.count_nonzero(weights)), 1)
    sensitivity = np.sqrt(np.sum((weighted * math.log(1.1)) ** 2, axis=0) / rows)
    with np.errstate(invalid="ignore", divide="ignore"):
        inflation = np.where(white > 0, spread / white, 1.0)
    worst = max(tangent_error, key=tangent_error.__getitem__)
    rough = (
        [
            f"the derivatives of the residuals in {worst} differ from their central difference by "
            f"{100 * tangent_error[worst]:.3g} % at the start, at "
            + _stepping(_tolerances(problem))
            + f" (more than {100 * TANGENT_TOLERANCE:g} %): the fit's steps and its uncertainties rest on them. "
            "Use an adaptive solver, or one with tighter tolerances, or more samples in the records"
        ]
        if tangent_error[worst] > TANGENT_TOLERANCE
        else []
    )
    messages = (
        ([STALLED.format(iterations=steps)] if stalled else [])
        + rough
        + _caveats(pairs)
        + _discrepancy(checks)
        + _warnings(names, values, spread, correlation, sensitivity, weighted.T @ weighted)
    )
    for message in messages:
        warnings.warn(message, UserWarning, stacklevel=3)
    return CalibrationResult(
        values=values,
        start={n: float(start[n]) for n in names},
        uncertainty={n: values[n] * float(s) for n, s in zip(names, spread)},
        relative_uncertainty={n: float(s) for n, s in zip(names, spread)},
        correlation=correlation,
        sensitivity={n: float(s) for n, s in zip(names, sensitivity)},
        noise=noise,
        loss=losses,
        iterations=steps,
        converged=converged,
        stalled=stalled,
        records=records,
        predictions=predictions,
        residuals=residuals,
        success=success,
        warnings=messages,
        residual_checks=checks,
        inflation={n: float(f) for n, f in zip(names, inflation)},
        rigs=[rig for rig, _ in pairs],
        jacobian=derivatives,
        tangent_error=tangent_error,
        tolerances=_tolerances(problem),
    )


def _discrepancy(checks: Mapping[tuple[str, str], ResidualCheck]) -> list[str]:
    """One warning naming the series whose residuals are not noise, worst first."""
    bad = sorted(((key, c) for key, c in checks.items() if c.discrepancy), key=lambda kc: -kc[1].lag1)
    if not bad:
        return []
    described = [
        f"{observable} in {record} (lag-1 autocorrelation {c.lag1:.3f}, mean offset {100 * c.mean_offset:+.2g} % "
        f"of its RMS, {c.runs} runs of one sign where noise would give about {c.expected_runs:.0f})"
        for (record, observable), c in bad[:3]
    ]
    more = f", and {len(bad) - 3} more series" if len(bad) > 3 else ""
    return [
        f"the residuals of {'; '.join(described)}{more} are not independent noise: the model misses something "
        "the records hold (too few segments, an observable measured elsewhere than the model takes it, a force "
        "the rig lacks). The fitted values absorb that discrepancy, so they may be biased beyond their "
        "uncertainties, which are widened for the correlation (effective samples n(1−ρ)/(1+ρ)) but are then "
        "at best rough. Check the rig against the test, and refit with more segments."
    ]


def _warnings(names, values, spread, correlation, sensitivity, fisher) -> list[str]:
    messages = []
    for i, name in enumerate(names):
        if not np.isfinite(spread[i]) or spread[i] > UNCERTAIN or fisher[i, i] == 0:
            messages.append(
                f"{name} ({COEFFICIENTS[name].split(',')[0]}) is poorly identified: the records pin it only to "
                f"±{100 * spread[i]:.3g} % (1σ), and a 10 % change moves the observables by "
                f"{sensitivity[i]:.3g} noise standard deviations (RMS). Its fitted value, "
                f"{values[name]:.4g}, cannot be trusted; add records that load it"
                + (" (a cable towed nearly along the flow)" if name == "tangential_drag" else "")
                + ", or fix it."
            )
    for i in range(len(names)):
        for j in range(i + 1, len(names)):
            if abs(correlation[i, j]) > CORRELATED:
                messages.append(
                    f"{names[i]} and {names[j]} are correlated ({correlation[i, j]:+.3f}): the records pin a "
                    "combination of them rather than each."
                )
    return messages


class DiscretisationCheck(NamedTuple):
    """How far a finer segmentation moves a calibration's predictions.

    - `segments`: by record name, the fitted rig's segments and the finer one's.
    - `shift`: by `(record name, observable)`, the RMS change of the prediction from
        the fitted rig to the finer one, with the fitted values, in units of the
        series' estimated noise σ.
    - `moves`: by coefficient, how far a refit at the finer segmentation would move
        its fitted value, relative (a change of its log), from the linearised refit
        `−(J̃ᵀJ̃)⁻¹ J̃ᵀ Δ̃` with the fit's own weighting (each series over its RMS).
    - `predictions`: for each record, the finer rig's observables (SI), by name.
    - `warnings`: sentences for the series that move by more than `COMPARABLE` σ, and
        the coefficients that would move by more than `COMPARABLE` of their standard
        deviation; also issued as `UserWarning`s.
    """

    segments: dict[str, tuple[int, int]]
    shift: dict[tuple[str, str], float]
    moves: dict[str, float]
    predictions: list[dict[str, np.ndarray]]
    warnings: list[str]


COMPARABLE = 0.5
"""A discretisation shift, in noise standard deviations, above which the model's own
discretisation error is comparable to the noise, and the fitted values carry it."""


def discretisation_check(
    result: CalibrationResult, factor: int = 2, solver: SolverConfig | None = None
) -> DiscretisationCheck:
    """Re-predict each record at `factor` × its rig's segments, with the fitted values,
    and compare with the fitted predictions in units of each series' noise.

    A shift well below the noise says the segmentation is fine enough for these records;
    one comparable to the noise says the fit absorbed discretisation error into the
    coefficients: refit with more segments. A shift far below the noise can still
    move the coefficients by more than their uncertainty, since every sample carries
    it the same way; `moves` says by how much, without refitting.

    **Arguments:**

    - `result`: a [`jaxcable.CalibrationResult`][].
    - `factor`: how many times finer (an integer ≥ 2).
    - `solver`: how to integrate; [`jaxcable.calibration.rig_solver`][]`()` by default.

    **Returns:**

    A [`jaxcable.calibration.DiscretisationCheck`][].

    **Raises:**

    `ValueError` for a factor that is not an integer ≥ 2; `RuntimeError` if a finer
    simulation fails.
    """
    if not (isinstance(factor, int) and factor >= 2):
        raise ValueError(f"discretisation_check: factor must be an integer >= 2, got {factor!r}")
    segments, shift, predictions, messages = {}, {}, [], []
    names = list(result.values)
    normal = np.zeros((len(names), len(names)))  # J̃ᵀJ̃
    projected = np.zeros(len(names))  # J̃ᵀΔ̃
    for rig, record, fitted, jacobian in zip(result.rigs, result.records, result.predictions, result.jacobian):
        conditions = rig.conditions()
        coarse = int(conditions["segments"])
        finer = rig_from_conditions({**conditions, "segments": coarse * factor}, record.name)
        finer = finer.with_coefficients(result.values)
        inputs = {k: jnp.asarray(record.columns[k]) for k in rig.inputs}
        run = _simulate_one(finer, jnp.asarray(record.times), inputs, solver)
        if not bool(run.success):
            raise RuntimeError(
                f"discretisation_check: {record.name}: the simulation at {coarse * factor} segments failed "
                f"(diffrax: {run.simulation.result}); finer segments are stiffer, so give a solver with more "
                "steps, e.g. solver=jaxcable.calibration.rig_solver(max_steps=1_000_000)"
            )
        segments[record.name] = (coarse, coarse * factor)
        predicted = {}
        for k in fitted:
            predicted[k] = np.asarray(run.observables[k])
            sigma = result.noise.get((record.name, k))
            if sigma is None:
                continue
            change = predicted[k] - fitted[k]
            scale = max(float(np.sqrt(np.mean(record.columns[k] ** 2))), 1e-12)  # as the fit weighs it
            normal += jacobian[k].T @ jacobian[k] / scale**2
            projected += jacobian[k].T @ change / scale**2
            moved = float(np.sqrt(np.mean(change**2))) / sigma
            shift[(record.name, k)] = moved
            if moved > COMPARABLE:
                messages.append(
                    f"{record.name}: at {coarse * factor} segments instead of {coarse}, the prediction of {k} moves "
                    f"by {moved:.2g} times its noise (RMS): the model's discretisation error is comparable to the "
                    "noise, and the fitted values carry it; refit with more segments."
                )
        predictions.append(predicted)
    step = -np.linalg.pinv(normal) @ projected
    moves = {name: float(d) for name, d in zip(names, step)}
    for name, d in moves.items():
        spread = result.relative_uncertainty[name]
        if abs(d) > COMPARABLE * spread:
            messages.append(
                f"refitted at {factor}x the segments, {name} would move by {100 * d:+.3g} % (linearised), "
                f"{abs(d) / spread:.2g} times its standard deviation: the discretisation error is comparable to "
                "what the records resolve; refit with more segments."
            )
    for message in messages:
        warnings.warn(message, UserWarning, stacklevel=2)
    return DiscretisationCheck(segments, shift, moves, predictions, messages)
