"""Whether a fit's segmentation is fine enough: its records re-predicted at finer
segments, against their noise, and the linearised move of each fitted coefficient."""

import dataclasses
import warnings

import jax.numpy as jnp
import numpy as np

from .._solver.config import SolverConfig
from .problem import simulate_one
from .report import CalibrationResult
from .towing import rig_from_conditions


@dataclasses.dataclass(frozen=True)
class DiscretisationCheck:
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
        run = simulate_one(finer, jnp.asarray(record.times), inputs, solver)
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
