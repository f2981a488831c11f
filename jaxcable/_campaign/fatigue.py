"""Fatigue damage of a tension history: rainflow counting, T–N curves and Miner's rule.

A line's fatigue in a load case is the damage its tension cycles do, summed over them
by Miner's rule, `D = Σ n_i / N(ΔT_i)`: `n_i` cycles of tension range `ΔT_i`, counted
by the rainflow method of ASTM E1049-85 (the `rainflow` package), and `N(ΔT)` the
cycles to failure at that range by the line component's T–N curve. A record of duration
T gives the damage rate `D / T`, so an annual damage and a fatigue life; a design code
asks for that life to exceed the service life times a design fatigue factor (3 to 10 in
DNV-OS-E301, by consequence and access for inspection).

T–N curves come in two forms ([`jaxcable.TNCurve`][]):

- `"stress"`, DNV-OS-E301's: `N = a_D s^(−m)` with `s` the nominal stress range (MPa),
    ΔT over the component's nominal area (for chain two bars, `chain_area(d)`);
- `"ratio"`, API RP 2SK's and 2SM's: `N R^M = K` with `R` the tension range over the
    reference breaking strength (RBS, or the minimum breaking load), where K may fall
    with the mean load over the RBS, `L_m`: `log₁₀ K = log₁₀ K₀ − k L_m` (wire ropes).

[`jaxcable.TN_CURVES`][] holds the standards' curves by name. The damage-equivalent load
([`damage_equivalent_load`][jaxcable.damage_equivalent_load]) is the range that, repeated
a given number of times, does the same damage as the history for an exponent m.

These are numpy functions of saved histories (after a run or a sweep), not traced: the
rainflow count is a sequence of comparisons with no derivative. The module imports no
JAX, so that the scene readers check a curve's name before JAX is imported.
"""

import dataclasses
import math
from typing import SupportsFloat

import numpy as np
import numpy.typing as npt
import rainflow

SECONDS_PER_YEAR = 365.25 * 86400.0
"""A Julian year (s), by which a record's damage rate is made annual."""


@dataclasses.dataclass(frozen=True)
class TNCurve:
    """A T–N curve: the cycles to failure `N` at a tension range ΔT.

    **Fields:**

    - `name`: what it is for, and from which standard.
    - `exponent`: m (DNV's `m`, API's `M`), the slope of log N against log range.
    - `coefficient`: DNV's `a_D` (cycles at 1 MPa, so MPa^m) for `form="stress"`; API's
        `K` (cycles at a range equal to the breaking strength) for `form="ratio"`.
    - `form`: `"stress"` (`N = a_D s^(−m)`, `s = ΔT / area` in MPa) or `"ratio"` (`N =
        K R^(−m)`, `R = ΔT / breaking_load`).
    - `mean_load_slope`: k in `log₁₀ K = log₁₀ coefficient − k L_m` (API RP 2SK's wire
        ropes), `L_m` the mean tension over the breaking load; 0 otherwise.
    """

    name: str
    exponent: float
    coefficient: float
    form: str  # "stress" or "ratio", checked with a message that names the field
    mean_load_slope: float = 0.0

    def __post_init__(self):
        if self.form not in ("stress", "ratio"):
            raise ValueError(f"TNCurve.form must be 'stress' or 'ratio', got {self.form!r}")
        for field in ("exponent", "coefficient"):
            value = getattr(self, field)
            if not (math.isfinite(value) and value > 0):
                raise ValueError(f"TNCurve.{field} must be a positive number, got {value!r}")
        if self.mean_load_slope and self.form != "ratio":
            raise ValueError("TNCurve.mean_load_slope applies to a curve of form 'ratio' (API's K against L_m)")

    def cycles(
        self,
        tension_range: npt.ArrayLike,
        *,
        area: SupportsFloat | None = None,
        breaking_load: SupportsFloat | None = None,
        mean_tension: SupportsFloat = 0.0,
    ) -> np.ndarray:
        """Cycles to failure at each `tension_range` (N): infinite at a zero range.

        **Arguments:**

        - `tension_range`: ΔT (N), any shape.
        - `area`: the nominal area (m²) for `form="stress"` (`chain_area` for chain, the
            metallic area for a wire rope).
        - `breaking_load`: the reference breaking strength (N) for `form="ratio"`.
        - `mean_tension`: the mean tension (N), for `mean_load_slope`.

        **Raises:**

        `ValueError` naming the argument that the form needs and was not given, or not
        positive.
        """
        ranges = np.abs(np.asarray(tension_range, dtype=float))
        if self.form == "stress":
            reference, coefficient = _require("area", area, self.name) * 1e6, self.coefficient  # N per MPa
        else:
            reference = _require("breaking_load", breaking_load, self.name)
            coefficient = self.coefficient * 10.0 ** (-self.mean_load_slope * float(mean_tension) / reference)
        with np.errstate(divide="ignore"):
            return np.asarray(coefficient * (ranges / reference) ** (-self.exponent))


def _require(name: str, value: SupportsFloat | None, curve: str) -> float:
    """`value` as a float, where it is a positive number."""
    if value is None or not (math.isfinite(float(value)) and float(value) > 0):
        raise ValueError(f"the T–N curve {curve!r} needs {name}, a positive number, got {value!r}")
    return float(value)


TN_CURVES: dict[str, TNCurve] = {
    curve.name.split(":")[0]: curve
    for curve in (
        TNCurve("dnv_stud_chain: stud chain, DNV-OS-E301", 3.0, 1.2e11, "stress"),
        TNCurve("dnv_studless_chain: studless (open-link) chain, DNV-OS-E301", 3.0, 6.0e10, "stress"),
        TNCurve("dnv_stranded_rope: stranded steel wire rope, DNV-OS-E301", 4.0, 3.4e14, "stress"),
        TNCurve("dnv_spiral_rope: spiral strand steel wire rope, DNV-OS-E301", 4.8, 1.7e17, "stress"),
        TNCurve("api_stud_chain: common stud chain, API RP 2SK", 3.0, 1000.0, "ratio"),
        TNCurve("api_studless_chain: common studless chain, API RP 2SK", 3.0, 316.0, "ratio"),
        TNCurve("api_multistrand_rope: six/multi-strand wire rope, API RP 2SK", 4.09, 10.0**3.20, "ratio", 2.79),
        TNCurve("api_spiral_rope: spiral strand wire rope, API RP 2SK", 5.05, 10.0**3.25, "ratio", 3.43),
        TNCurve("api_polyester: polyester rope, API RP 2SM", 5.2, 25000.0, "ratio"),
    )
}
"""The standards' T–N curves by name: `dnv_stud_chain`, `dnv_studless_chain`,
`dnv_stranded_rope`, `dnv_spiral_rope` (DNV-OS-E301, stress ranges in MPa on the
nominal area), and `api_stud_chain`, `api_studless_chain`, `api_multistrand_rope`,
`api_spiral_rope` (API RP 2SK) and `api_polyester` (API RP 2SM), ranges over the
breaking strength. The codes' curves for connecting links and the corrections for large
ranges (API TR 2FC-2) are not here: give them as a [`jaxcable.TNCurve`][]."""


def chain_area(nominal_diameter: SupportsFloat) -> float:
    """The nominal area (m²) of chain of nominal (bar) diameter d (m) for a DNV stress
    range: both bars of a link, `2 π d² / 4`."""
    return 2.0 * math.pi * float(nominal_diameter) ** 2 / 4.0


def rainflow_cycles(series: npt.ArrayLike) -> tuple[np.ndarray, np.ndarray, np.ndarray]:
    """The cycles of `series` by rainflow counting (ASTM E1049-85, the `rainflow`
    package): `(ranges, means, counts)`, each shape `(cycles,)`, a count of 1 for a full
    cycle and 0.5 for a half cycle (the residue)."""
    values = np.asarray(series, dtype=float).ravel()
    if not np.all(np.isfinite(values)):
        raise ValueError("rainflow_cycles: the series has non-finite values")
    cycles = [(r, m, c) for r, m, c, _, _ in rainflow.extract_cycles(values.tolist())]
    if not cycles:
        return np.zeros(0), np.zeros(0), np.zeros(0)
    ranges, means, counts = (np.array(column, dtype=float) for column in zip(*cycles))
    return ranges, means, counts


@dataclasses.dataclass(frozen=True)
class FatigueDamage:
    """The fatigue damage of one tension history.

    - `damage`: Miner's sum over the history (–).
    - `duration`: the history's length (s).
    - `annual_damage`: `damage` per year at this rate (1/year).
    - `life`: the fatigue life `1 / annual_damage` (years); infinite without damage.
    - `ranges`, `counts`: the rainflow cycles' tension ranges (N) and counts.
    - `curve`: the T–N curve's name.
    """

    damage: float
    duration: float
    annual_damage: float
    life: float
    ranges: np.ndarray
    counts: np.ndarray
    curve: str

    def equivalent_load(self, exponent: SupportsFloat, equivalent_cycles: SupportsFloat) -> float:
        """The damage-equivalent load (N) of these cycles: as
        [`jaxcable.damage_equivalent_load`][] of the history, without counting it again."""
        return _equivalent_range(self.ranges, self.counts, *_equivalence(exponent, equivalent_cycles))


def fatigue_damage(
    tension: npt.ArrayLike,
    times: npt.ArrayLike,
    curve: TNCurve | str,
    *,
    area: SupportsFloat | None = None,
    breaking_load: SupportsFloat | None = None,
) -> FatigueDamage:
    """Miner's fatigue damage of a tension history by rainflow counting.

    **Arguments:**

    - `tension`: the tension (N) at `times`, shape `(times,)` (a segment's history, say
        `result.tension[:, k]`, or a channel such as `FairTen1`).
    - `times`: (s), increasing, the same shape; only their span is used, for the rate.
    - `curve`: a [`jaxcable.TNCurve`][] or the name of one of [`jaxcable.TN_CURVES`][].
    - `area`: the nominal area (m²) for a DNV curve (`chain_area(d)` for chain).
    - `breaking_load`: the reference breaking strength (N) for an API curve; the mean
        tension over it sets a wire rope's K.

    **Returns:**

    A [`jaxcable.FatigueDamage`][].

    **Raises:**

    `ValueError` for an unknown curve name, a history shorter than two samples or of
    another shape than `times`, non-finite values, or a missing `area` or
    `breaking_load` (naming it).
    """
    if isinstance(curve, str):
        if curve not in TN_CURVES:
            raise ValueError(f"unknown T–N curve {curve!r}; jaxcable has {', '.join(TN_CURVES)}")
        curve = TN_CURVES[curve]
    tension, times = np.asarray(tension, dtype=float), np.asarray(times, dtype=float)
    if tension.ndim != 1 or tension.shape != times.shape or tension.size < 2:
        raise ValueError(
            f"fatigue_damage needs a tension history and its times of one shape (samples,), at least two; got "
            f"{tension.shape} and {times.shape}"
        )
    duration = float(times[-1] - times[0])
    if not (np.all(np.isfinite(times)) and duration > 0):
        raise ValueError(f"fatigue_damage: the times must be finite and span a positive duration, got {duration!r} s")
    ranges, _, counts = rainflow_cycles(tension)
    mean = float(np.mean(tension))
    damage = float(np.sum(counts / curve.cycles(ranges, area=area, breaking_load=breaking_load, mean_tension=mean)))
    annual = damage * SECONDS_PER_YEAR / duration
    return FatigueDamage(damage, duration, annual, 1.0 / annual if annual > 0 else math.inf, ranges, counts, curve.name)


def damage_equivalent_load(tension: npt.ArrayLike, exponent: SupportsFloat, equivalent_cycles: SupportsFloat) -> float:
    """The damage-equivalent load (N): the tension range that, repeated
    `equivalent_cycles` times, does the damage of the history's rainflow cycles under a
    T–N curve of slope `exponent` (m): `(Σ n_i ΔT_i^m / N_eq)^(1/m)`. Independent of
    the curve's coefficient, so a way to compare load cases without one."""
    m, cycles = _equivalence(exponent, equivalent_cycles)
    ranges, _, counts = rainflow_cycles(tension)
    return _equivalent_range(ranges, counts, m, cycles)


def _equivalent_range(ranges: np.ndarray, counts: np.ndarray, m: float, cycles: float) -> float:
    """`(Σ n_i ΔT_i^m / N_eq)^(1/m)` (N) of rainflow cycles."""
    return float((np.sum(counts * ranges**m) / cycles) ** (1.0 / m))


def _equivalence(exponent: SupportsFloat, equivalent_cycles: SupportsFloat) -> tuple[float, float]:
    """A damage-equivalent load's exponent m and equivalent cycles, checked."""
    m, cycles = float(exponent), float(equivalent_cycles)
    if not (math.isfinite(m) and m > 0):
        raise ValueError(f"damage_equivalent_load: exponent must be a positive number, got {exponent!r}")
    if not (math.isfinite(cycles) and cycles > 0):
        raise ValueError(
            f"damage_equivalent_load: equivalent_cycles must be a positive number, got {equivalent_cycles!r}"
        )
    return m, cycles
