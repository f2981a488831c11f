"""Towing records simulated with known coefficients and noise, to test a fit against
values it should find again."""

from collections.abc import Mapping, Sequence

import jax.numpy as jnp
import numpy as np

from .._solver.config import SolverConfig
from .problem import simulate_one
from .records import TowingRecord
from .towing import AbstractTowingRig


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
    run = simulate_one(rig, jnp.asarray(times), {k: jnp.asarray(inputs[k], dtype=float) for k in rig.inputs}, solver)
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
