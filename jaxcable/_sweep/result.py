"""What a sweep returns: each case's simulation, statics and status, with the tables
and statistics an engineer reads from them."""

from typing import Any

import diffrax
import equinox as eqx
import jax
import jax.numpy as jnp
import numpy as np
from jaxtyping import Array, Bool, Float

from .. import _checks as checks
from .._sea.extremes import ExtremeStatistics, extreme_statistics
from .._simulation.simulate import SimulationResult
from .._statics.solution import StaticSolution
from .._typing import RealLike

# What `SweepResult.summary` says under its table when the statics was solved once.
_SHARED_STATICS = "statics solved once: the swept parameters do not change the equilibrium"


class SweepResult(eqx.Module):
    """What a sweep produced: one simulation per case, with a status for each.

    Every array has a leading case axis of length `cases`, in the order of the
    parameter arrays given to [`jaxcable.sweep`][].

    **Attributes:**

    - `parameters`: the swept values, a dict from each parameter's name to an array of
        shape `(cases,)`.
    - `simulation`: a [`jaxcable.SimulationResult`][] whose arrays carry the case axis
        first: `tension` has shape `(cases, times, segments)`, `positions`
        `(cases, times, nodes, 3)`, `result` one diffrax code per case. After a failure
        a case's times and states are `inf` (diffrax's convention) and the strains and
        tensions computed from them are not finite; a case whose statics failed is
        `inf` throughout and has the statics' code, promoted to diffrax's `RESULTS`.
    - `statics`: with `initial="statics"`, each case's
        [`jaxcable.StaticSolution`][] (`tension` of shape `(cases, segments)`, ...);
        otherwise `None`.
    - `statics_shared`: `True` where the statics was solved once and its equilibrium
        shared by every case, because the swept parameters do not change what
        statics reads (see [`jaxcable.sweep`][]'s `initial`); `statics` then holds
        that one solution for every case.
    - `stepping`: how the cases were integrated, in words (`"RK4, fixed steps of
        0.005 s (chosen for the scene's fastest modes)"`, say).
    - `success`: `True` for a case whose statics (if any) and dynamics both succeeded,
        shape `(cases,)`.
    - `status`: one human-readable line per case: `"successful"`, diffrax's message,
        `"statics failed: ..."`, or `"invalid input: ..."` naming the case, the field
        and the value.

    `times`, `positions`, `velocities`, `strain`, `tension`, `reactions`, `stats` and
    `result` are the simulation's, as a [`jaxcable.SimulationResult`][] names them:
    `result.tension` is `result.simulation.tension`.
    """

    parameters: dict[str, Float[Array, " cases"]]
    simulation: SimulationResult
    statics: StaticSolution | None
    success: Bool[Array, " cases"]
    status: tuple[str, ...] = eqx.field(static=True)
    statics_shared: bool = eqx.field(static=True, default=False)
    stepping: str = eqx.field(static=True, default="")

    @property
    def n_cases(self) -> int:
        """The number of cases."""
        return len(self.status)

    # What a `SimulationResult` exposes, with the case axis first, so that code written
    # for one run reads a sweep as it reads `simulate`'s result.
    @property
    def times(self) -> Float[Array, "cases times"]:
        """The output times (s), shape `(cases, times)` (`simulation.times`)."""
        return self.simulation.times

    @property
    def positions(self) -> Float[Array, "cases times nodes 3"]:
        """The nodes' positions (m), shape `(cases, times, nodes, 3)` (`simulation.positions`)."""
        return self.simulation.positions

    @property
    def velocities(self) -> Float[Array, "cases times nodes 3"]:
        """The nodes' velocities (m/s), shape `(cases, times, nodes, 3)` (`simulation.velocities`)."""
        return self.simulation.velocities

    @property
    def strain(self) -> Float[Array, "cases times segments"]:
        """The segments' axial strain (–), shape `(cases, times, segments)` (`simulation.strain`)."""
        return self.simulation.strain

    @property
    def tension(self) -> Float[Array, "cases times segments"]:
        """The segments' tension (N), shape `(cases, times, segments)` (`simulation.tension`)."""
        return self.simulation.tension

    @property
    def reactions(self) -> Float[Array, "cases times constrained 3"]:
        """The force (N) of each constrained node's support on the network, shape
        `(cases, times, constrained, 3)` (`simulation.reactions`)."""
        return self.simulation.reactions

    @property
    def stats(self) -> dict[str, Any]:
        """diffrax's step counts per case (`simulation.stats`)."""
        return self.simulation.stats

    @property
    def result(self) -> diffrax.RESULTS:
        """diffrax's code per case (`simulation.result`); `success` also counts statics."""
        return self.simulation.result

    @property
    def failed(self) -> np.ndarray:
        """Indices of the cases that failed, as a NumPy integer array."""
        return np.flatnonzero(~np.asarray(self.success))

    @property
    def peak_tension(self) -> Float[Array | np.ndarray, " cases"]:
        """The largest tension (N) in any segment at any output time, shape `(cases,)`;
        `nan` for a failed case, whose history stops early."""
        tension, success = checks.on_host(self.simulation.tension), checks.on_host(self.success)
        xp = jnp if checks.traced((tension, success)) else np  # numpy compiles nothing
        return xp.where(success, xp.max(tension, axis=(1, 2)), np.nan)

    def case(self, index: int) -> SimulationResult:
        """The [`jaxcable.SimulationResult`][] of case `index` alone, as
        [`jaxcable.simulate`][] would return it."""
        if not -self.n_cases <= index < self.n_cases:
            raise IndexError(f"SweepResult.case: index {index} is out of range for {self.n_cases} cases")
        return jax.tree.map(lambda x: x[index], self.simulation)

    def tension_extremes(
        self, start: float | None = None, *, segments: RealLike | None = None, duration: float | None = None
    ) -> ExtremeStatistics:
        """The most probable maximum tension and its distribution, taking each case as
        one realisation of one sea state (a sweep over seeds):
        [`jaxcable.extreme_statistics`][] of each case's largest tension (N) over
        `segments` at each output time.

        **Arguments:**

        - `start`: the first output time (s) kept, to leave out the start-up transient;
            the first by default.
        - `segments`: the segments' indices (an int or an array); all by default.
        - `duration`: D (s) the maximum is for; the kept record's length by default.

        **Raises:**

        `ValueError` if any case failed (naming them) or the sweep has one case.

        For several sea states, seeds in each, reshape the tension of a
        [`jaxcable.sweep_grid`][] (its last axis varies fastest) and call
        [`jaxcable.extreme_statistics`][] on it.
        """
        if self.failed.size:
            raise ValueError(
                f"SweepResult.tension_extremes: cases {self.failed.tolist()} failed ({self.status[self.failed[0]]}); "
                "extremes over realisations need every one"
            )
        tension = self.simulation.tension
        if segments is not None:
            tension = tension[:, :, jnp.atleast_1d(jnp.asarray(segments))]
        return extreme_statistics(
            jnp.max(tension, axis=-1), np.asarray(self.simulation.times[0]), start=start, duration=duration
        )

    def summary(self) -> str:
        """A markdown table: one row per case with its parameters, peak tension (kN) and
        status; below it, how the cases were integrated and, where the statics was
        solved once, a line that says so."""
        names = list(self.parameters)
        values = {k: np.asarray(v) for k, v in self.parameters.items()}
        peak = np.asarray(self.peak_tension)
        lines = [
            "| case | " + " | ".join(names) + " | peak T (kN) | status |",
            "|---" * (len(names) + 3) + "|",
        ]
        for i, status in enumerate(self.status):
            row = [str(i), *(f"{values[k][i]:.6g}" for k in names), f"{peak[i] / 1e3:.2f}", status]
            lines.append("| " + " | ".join(row) + " |")
        if self.stepping:
            lines += ["", f"stepping: {self.stepping}"]
        if self.statics_shared:
            lines += ["", _SHARED_STATICS]
        return "\n".join(lines)
