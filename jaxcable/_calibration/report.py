"""What a calibration reports: the fitted coefficients' covariance, correlations and
sensitivities, each series' residuals checked for independence, and the warnings on
coefficients the records do not pin down.

After the fit, each series' noise level σ is estimated from what is left of it, and the
coefficients' covariance is the Gauss–Newton sandwich `A⁻¹ B A⁻¹`, with
`A = Jᵀ J` and `B = Jᵀ diag(σ²) J` for the scaled residuals' Jacobian `J` (taken in
forward mode). It is the covariance of the estimator the fit uses, whatever the series'
noise levels; where they are proportional to the series' RMS, as in
[`jaxcable.calibration.synthetic_record`][], it is also the smallest attainable, `(Jᵀ diag(σ⁻²) J)⁻¹`.
(Weighting by the optimum's `1/σ²` while fitting with a common scale per observable
understates the spread, 2.4-fold against 16 refits on fresh noise.) A coefficient
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

import dataclasses
import math
import warnings
from collections.abc import Mapping

import numpy as np

from .problem import solver_tolerances
from .records import TowingRecord
from .towing import COEFFICIENTS, AbstractTowingRig

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
STALL_GAIN = 0.01
"""A fit whose loss settled is called stalled, not converged, when one Gauss–Newton
step with its own Jacobian would still remove more than this share of the squared
residuals (`_linear_gain`). On the sample records that share is 1.5e-6 after a converged
fit, 0.97 at the start, 0.74 where a 40-segment fit's inaccurate gradient stopped it."""

# Flag a coefficient whose one-standard-deviation relative uncertainty exceeds this:
# the records then leave it free to wander by more than the 5-10 % an engineer would
# accept from a calibration.
UNCERTAIN = 0.05


# Flag a pair of coefficients more correlated than this: the records pin a combination
# of them, not each one.
CORRELATED = 0.95


@dataclasses.dataclass(frozen=True)
class CalibrationResult:
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


@dataclasses.dataclass(frozen=True)
class ResidualCheck:
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


def report(problem, start, log_values, losses, steps, converged, stalled, pairs, r, jacobian, successes, tangent_error):
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
            + _stepping(solver_tolerances(problem))
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
        tolerances=solver_tolerances(problem),
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


def _caveats(pairs) -> list[str]:
    """The rigs' caveats on the observables the records measure, one per rig type and
    observable, naming the records."""
    found: dict[str, list[str]] = {}
    for index, (rig, record) in enumerate(pairs):
        for name, caveat in rig.caveats.items():
            if name in record.columns:
                found.setdefault(caveat, []).append(record.name or f"tests[{index}]")
    return [f"{', '.join(names)}: {caveat}" for caveat, names in found.items()]


def _stepping(tolerances: tuple[float, float] | None) -> str:
    return "fixed steps" if tolerances is None else "rtol = {:g}, atol = {:g}".format(*tolerances)
