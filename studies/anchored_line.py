"""The anchored line (Bezverkhyy & Korniienko) reproduced at the paper's own tension scale, in its waves.

Bezverkhyy & Korniienko anchor a line at H = 200 m, drive its top along x with
T_w = 5.6 s (A = 1.573 m from their amplitude law) in "plane progressive waves", and plot
the tension over t = 30–48 s (Figs. 2–4, in 10⁴ N) and against C_E1 at points of the
line (Fig. 5, on an axis from 4.8 to 6.0 × 10⁴ N). Their text says, figure by figure:

- at α = 30° (Fig. 2) raising C_E1 from 0.1 to 0.2 C_E lowers the peak insignificantly;
- at 45° (Fig. 3) raising C_E1 from 0 to 0.2 C_E lowers the peak by up to 20 % against
  Hooke's law, and the vibrations that follow slackening do not die out;
- from 30° to 45° the tension hardly changes; at 60° (Fig. 4) C_E1 matters little and
  the tension is about 25 % below 30°;
- along the line (Fig. 5) the tension falls with C_E1, unevenly.

They do not give C_E. This module finds it from their own axis (`calibrate_stiffness`:
the peak at 45° with Hooke's law on the top of Fig. 5's axis, 60 kN, by a least-squares
fit of ln peak against ln C_E over a vmapped `jaxcable.sweep`), runs every case with
the wave acting on the line as well as moving its top (`jaxcable.examples._anchored_line`'s
`anchored_line_wave`, phase-locked to the top), maps the effect of C_E1 over (C_E, α), and
tries the readings of C_E1 under which the paper's 20 % could arise (`readings_table`).

Every run is a batch of `batch` cases of one `jaxcable.sweep` (`run_cases`): a case is
(α, C_E, C_E1/C_E, L0/chord), all four swept, and the lines of all three angles are
tabled in every build, so every batch of one configuration, whatever its cases, runs
one compiled program. Each case starts from its own static equilibrium in still water.

"Top", "middle" and "anchor" are the top segment (next to the floating object), the
middle one and the bottom one: the paper's polyline has one tension per segment, and
Fig. 5 names a top and a middle point. Peaks are the largest sample of the resolved
solution in the window: at `sample_rate` = 1 kHz (Dopri5's steps average 0.5–2 ms), the
sampled peak is within 0.01 % of the 4 kHz one (`validation/anchored_line_reproduction.py`
records the check).
"""

import dataclasses
import time
from collections.abc import Sequence

import diffrax
import equinox as eqx
import jax
import jax.numpy as jnp
import numpy as np

import jaxcable as jc
from jaxcable import (
    SolverConfig,
    State,
    _checks,  # the Condition a tension law's `rising` returns
    solve_statics,
    sweep,
)
from jaxcable.examples import floater_amplitude
from jaxcable.examples._anchored_line import AXIAL_STIFFNESS, WAVE_PERIOD, anchored_line

ANGLES = (30.0, 45.0, 60.0)
RATIOS = (0.0, 0.05, 0.1, 0.2)
WINDOW = (30.0, 48.0)
PUBLISHED_SCALE = (48e3, 60e3)
"""The paper's Fig. 5 tension axis, 4.8–6.0 × 10⁴ N (read from the OCR copy,
`seeds/000_*.txt`; the tick labels of Figs. 2–4 are lost): its curves of tension at
points of the line start at its top for C_E1 = 0."""
TARGET_PEAK = PUBLISHED_SCALE[1]
"""What C_E is calibrated to: the top segment's peak at 45°, C_E1 = 0 (N)."""
TARGET_ANGLE = 45.0
MAP_STIFFNESSES = (1e6, 2e6, 3e6, 5e6, 7e6, 1e7, 2e7, 3e7)
"""C_E (N) of the map of the C_E1 effect: soft fibre ropes up to steel."""
FULL = {
    "n_segments": 20,
    "rtol": 1e-8,
    "atol": 1e-8,
    "duration": 48.0,
    "window": WINDOW,
    "sample_rate": 1000.0,
    "batch": 12,
}
"""The configuration `validation/anchored_line_reproduction.py` runs: 20 segments (within 3 %
of 40 in the earlier check), Dopri5 at rtol = atol = 1e-8, sampled at 1 kHz, batches of
12 cases."""
SMALL = {
    "n_segments": 8,
    "rtol": 1e-7,
    "atol": 1e-7,
    "duration": 24.0,
    "window": (12.0, 24.0),
    "sample_rate": 1000.0,
    "batch": 6,
}
"""A configuration small enough for the test suite (the notebook's default)."""
CONVERGENCE_RATES = (200.0, 500.0)
"""Output rates (Hz) at which the peak is re-read, by subsampling, against the run's own."""
VIBRATION_CUTOFF = 1.0
"""Tension above this frequency (Hz), 5.6 times the wave's, counts as the vibration
that follows slackening (`AnchoredLineCase.vibration_persistence`)."""

# A study's first batch runs to this time (s) only: it compiles the program, which the
# timed batches then reuse.
_WARM_UP = 1e-3


# --- Cases ------------------------------------------------------------------------------


@dataclasses.dataclass(frozen=True)
class Spec:
    """One case: α (°), C_E (N), C_E1/C_E (–) and the unstretched length over the chord
    anchor–fairlead (–)."""

    angle: float
    axial_stiffness: float
    ratio: float
    length_factor: float = 1.0


class DomainElastic(jc.AbstractTensionLaw):
    """The anchored-line paper's `T = (C_E ε + C_E1 ε²) H(ε)`, required to rise only up to
    `domain` (–) rather than up to ε = 1.

    For the reading of the law with ε in per cent, C_E1 = −0.2 C_E per %² is
    −20 C_E in strain: the tension peaks at ε = 2.5 %, which `jaxcable.NonlinearElastic`
    rejects. A run with this law is valid only if its strains stay below `domain`,
    which `run_cases` checks (`AnchoredLineCase.in_domain`).
    """

    axial_stiffness: jax.Array
    quadratic_coefficient: jax.Array
    slack_width: jax.Array
    domain: float = eqx.field(static=True)
    damped = False

    def __init__(self, axial_stiffness, quadratic_stiffness, slack_width=1e-5, domain: float = 0.02):
        self.axial_stiffness = jnp.asarray(axial_stiffness, dtype=float)
        self.quadratic_coefficient = jnp.asarray(quadratic_stiffness, dtype=float)
        self.slack_width = jnp.asarray(slack_width, dtype=float)
        self.domain = float(domain)

    def quadratic_stiffness(self):
        return self.quadratic_coefficient

    def damping(self):
        return jnp.zeros_like(self.axial_stiffness)

    def rising(self, name: str) -> _checks.Condition:
        """The slope `C_E + 2 C_E1 ε` is non-negative at ε = `domain`."""
        slope = self.axial_stiffness + 2 * self.quadratic_coefficient * self.domain
        return _checks.Condition(
            f"{name}.quadratic_stiffness",
            slope < 0,
            self.quadratic_coefficient,
            f"must keep the tension rising up to ε = {self.domain:g}",
        )


LAWS = ("paper", "domain")
"""`run_cases`'s tension laws: `jaxcable.NonlinearElastic` (the paper's law), or
`DomainElastic` (the same law, for the per-cent reading's softening sign)."""


def anchored_line_case(
    n_segments: int = 20,
    angle_degrees: float = 30.0,
    quadratic_ratio: float = 0.0,
    axial_stiffness: float = AXIAL_STIFFNESS,
    mass_matrix: str = "lumped",
    slack_width: float = 1e-5,
    period: float = WAVE_PERIOD,
    *,
    waves: bool = True,
    length_factor: float = 1.0,
    law: str = "paper",
    domain: float = 1.0,
):
    """`anchored_line` with C_E = `axial_stiffness`, C_E1 = `quadratic_ratio` × C_E and the
    unstretched length `length_factor` times the chord.

    With `waves` the paper's wave acts on the line and moves its top
    (`anchored_line(..., waves=True)`); without, the line is in still water. `law` is
    one of `LAWS`; `domain` is `DomainElastic`'s.

    **Returns:** `(model, environment)`, as `jaxcable.examples.anchored_line`.
    """
    if law not in LAWS:
        raise ValueError(f"anchored_line_case: law must be one of {LAWS}, got {law!r}")
    model, env = anchored_line(
        n_segments, angle_degrees, quadratic_ratio, period, slack_width, mass_matrix, waves=waves
    )
    if law == "domain":
        model = eqx.tree_at(
            lambda m: m.line.tension_law,
            model,
            DomainElastic(jnp.full(n_segments, AXIAL_STIFFNESS), jnp.zeros(n_segments), slack_width, domain),
        )
    return _with(model, axial_stiffness, quadratic_ratio, length_factor), env


def _with(model, axial_stiffness, ratio, length_factor):
    """`model` with C_E, C_E1 = ratio × C_E and the segment lengths scaled."""
    law = model.line.tension_law
    ones = jnp.ones_like(law.axial_stiffness)
    return eqx.tree_at(
        lambda m: (m.line.tension_law.axial_stiffness, m.line.tension_law.quadratic_coefficient, m.segment_length),
        model,
        (ones * axial_stiffness, ones * ratio * axial_stiffness, model.segment_length * length_factor),
    )


def _sweep_build(angles, n_segments, mass_matrix, slack_width, period, waves, law, domain):
    """`build(angle_degrees, axial_stiffness, quadratic_ratio, length_factor)` for
    `jaxcable.sweep`, as `anchored_line_case`.

    `anchored_line` lays the line out with numpy, which cannot take a traced angle, so
    the line of every angle in `angles` is built here and `build` picks the one nearest
    its angle. Only the float leaves that differ between angles (node positions, segment
    lengths, the wave's phase) are tabled.

    **Returns:** `(build, lines)`, `lines` the `(model, environment)` of each angle.
    """
    lines = [
        anchored_line_case(
            n_segments, a, 0.0, AXIAL_STIFFNESS, mass_matrix, slack_width, period, waves=waves, law=law, domain=domain
        )
        for a in angles
    ]
    arrays = [eqx.filter(line, eqx.is_array) for line in lines]
    rest = eqx.filter(lines[0], eqx.is_array, inverse=True)
    varying = jax.tree.map(lambda first, *others: not all(np.array_equal(first, x) for x in others), *arrays)
    table = jax.tree.map(lambda v, *xs: jnp.stack(xs) if v else xs[0], varying, *arrays)
    angle_table = jnp.asarray(angles, dtype=float)

    def build(angle_degrees, axial_stiffness, quadratic_ratio, length_factor):
        i = jnp.argmin(jnp.abs(angle_table - angle_degrees))
        model, env = eqx.combine(jax.tree.map(lambda v, x: x[i] if v else x, varying, table), rest)
        return _with(model, axial_stiffness, quadratic_ratio, length_factor), env

    return build, lines


def slack_time(times: np.ndarray, tension: np.ndarray, threshold: float = 0.0) -> tuple[float, float]:
    """Time a tension history spends slack (T ≤ `threshold`), from uniform samples.

    **Returns:** `(seconds, fraction)`: the fraction of samples at or below the threshold,
    and that fraction of the sampled span `times[-1] − times[0]`.
    """
    times = np.asarray(times, dtype=float)
    fraction = float(np.mean(np.asarray(tension) <= threshold))
    return fraction * float(times[-1] - times[0]), fraction


def vibration_persistence(times, tension, period: float = WAVE_PERIOD, cutoff: float = VIBRATION_CUTOFF) -> float:
    """How much of the high-frequency tension is left at the end of a history: the RMS
    of its part above `cutoff` (Hz) over the last `period` (s) of the samples, over that
    in the first `period`. About 1 where the vibration is renewed every wave period, and
    well below 1 where it dies out.

    The part above `cutoff` is taken by a fourth-order Butterworth high-pass run forwards
    and backwards (`scipy.signal.sosfiltfilt`), which leaves no phase shift.
    """
    from scipy.signal import butter, sosfiltfilt

    times, tension = np.asarray(times, dtype=float), np.asarray(tension, dtype=float)
    rate = 1 / (times[1] - times[0])
    high = sosfiltfilt(butter(4, cutoff, "highpass", fs=rate, output="sos"), tension)
    first = high[times <= times[0] + period]
    last = high[times >= times[-1] - period]
    return float(np.sqrt(np.mean(last**2)) / np.sqrt(np.mean(first**2)))


@dataclasses.dataclass
class AnchoredLineCase:
    """One simulated case, read inside the window.

    **Attributes:**

    - `spec`: α, C_E, C_E1/C_E and L0/chord (`Spec`).
    - `times`: output times inside the window (s), uniform.
    - `tension`: T (N), shape `(times, segments)`, segment 0 at the anchor.
    - `arc_length`: unstretched arc length from the anchor to each segment's middle (m).
    - `static_tension`: the static equilibrium's T (N) per segment.
    - `peak_strain`: the largest strain anywhere in the window (–).
    - `success`, `steps`, `rejected_steps`: the solver's outcome.
    - `domain`: the strain up to which the law is declared valid (`DomainElastic`'s;
        infinite for the paper's law).
    """

    spec: Spec
    times: np.ndarray
    tension: np.ndarray
    arc_length: np.ndarray
    static_tension: np.ndarray
    peak_strain: float
    success: bool
    steps: int
    rejected_steps: int
    domain: float = np.inf

    @property
    def angle(self) -> float:
        return self.spec.angle

    @property
    def ratio(self) -> float:
        return self.spec.ratio

    @property
    def axial_stiffness(self) -> float:
        return self.spec.axial_stiffness

    @property
    def length_factor(self) -> float:
        return self.spec.length_factor

    @property
    def in_domain(self) -> bool:
        """Whether the strains stayed where the law holds: below `domain` and where its
        tension still rises, `C_E + 2 C_E1 ε > 0`."""
        rising = 1 + 2 * self.ratio * self.peak_strain > 0
        return bool(self.peak_strain < self.domain and rising)

    @property
    def top(self) -> np.ndarray:
        """The top segment's tension history (N)."""
        return self.tension[:, -1]

    @property
    def anchor(self) -> np.ndarray:
        """The anchor segment's tension history (N)."""
        return self.tension[:, 0]

    @property
    def middle(self) -> np.ndarray:
        """The middle segment's tension history (N)."""
        return self.tension[:, self.tension.shape[1] // 2]

    @property
    def peak_top(self) -> float:
        return float(self.top.max())

    @property
    def peak_middle(self) -> float:
        return float(self.middle.max())

    @property
    def peak_anchor(self) -> float:
        return float(self.anchor.max())

    @property
    def min_top(self) -> float:
        return float(self.top.min())

    @property
    def mean_top(self) -> float:
        return float(self.top.mean())

    @property
    def peak_line(self) -> float:
        """The largest tension anywhere on the line inside the window (N)."""
        return float(self.tension.max())

    @property
    def slack_seconds(self) -> float:
        """Seconds of the window during which the top segment is slack."""
        return slack_time(self.times, self.top)[0]

    @property
    def slack_fraction_line(self) -> float:
        """The fraction of (time, segment) samples that are slack."""
        return float(np.mean(self.tension <= 0.0))

    @property
    def vibration_persistence(self) -> float:
        """`vibration_persistence` of the top segment's history."""
        return vibration_persistence(self.times, self.top)

    def peak_top_at(self, rate: float) -> float:
        """The top segment's peak read at `rate` (Hz) by subsampling, from the window's start."""
        stride = max(1, int(round(1 / (rate * (self.times[1] - self.times[0])))))
        return float(self.top[::stride].max())

    def row(self) -> dict:
        """The case's line of the results table (SI units)."""
        return {
            "angle_deg": self.angle,
            "ratio": self.ratio,
            "axial_stiffness_N": self.axial_stiffness,
            "length_factor": self.length_factor,
            "static_top_N": float(self.static_tension[-1]),
            "peak_top_N": self.peak_top,
            "peak_middle_N": self.peak_middle,
            "peak_anchor_N": self.peak_anchor,
            "peak_line_N": self.peak_line,
            "min_top_N": self.min_top,
            "mean_top_N": self.mean_top,
            "peak_strain": self.peak_strain,
            "in_domain": self.in_domain,
            "slack_top_s": self.slack_seconds,
            "slack_line_fraction": self.slack_fraction_line,
            "vibration_persistence": self.vibration_persistence,
            "peak_top_by_rate_N": {f"{r:g}": self.peak_top_at(r) for r in CONVERGENCE_RATES},
            "success": self.success,
            "steps": self.steps,
            "rejected_steps": self.rejected_steps,
        }


@dataclasses.dataclass
class AnchoredLineStudy:
    """A set of cases run with one configuration; see `run_cases`.

    `compile_s` and `run_s` (s) are as `run_cases` returns them.
    """

    cases: list[AnchoredLineCase]
    settings: dict
    compile_s: float
    run_s: float

    def case(
        self, angle: float, ratio: float, axial_stiffness: float | None = None, length_factor: float | None = None
    ) -> AnchoredLineCase:
        """The case at α = `angle`, C_E1/C_E = `ratio` and, where more than one is there,
        C_E = `axial_stiffness` and L0/chord = `length_factor`."""
        found = [
            c
            for c in self.cases
            if np.isclose(c.angle, angle)
            and np.isclose(c.ratio, ratio)
            and (axial_stiffness is None or np.isclose(c.axial_stiffness, axial_stiffness, rtol=1e-9))
            and (length_factor is None or np.isclose(c.length_factor, length_factor))
        ]
        if len(found) != 1:
            raise KeyError(
                f"{len(found)} cases at angle {angle}, ratio {ratio}, C_E {axial_stiffness}, L0/chord "
                f"{length_factor}: give C_E or L0/chord to pick one"
            )
        return found[0]

    @property
    def angles(self) -> list[float]:
        return sorted({c.angle for c in self.cases})

    @property
    def ratios(self) -> list[float]:
        return sorted({c.ratio for c in self.cases})

    @property
    def stiffnesses(self) -> list[float]:
        return sorted({c.axial_stiffness for c in self.cases})

    def table(self) -> list[dict]:
        return [c.row() for c in self.cases]

    def to_dict(self, history_rate: float = 25.0, segments: bool = True) -> dict:
        """A JSON-able record: settings, timings and the table; with `segments`, the
        peak and mean tension of every segment; and the top segment's history resampled
        to `history_rate` Hz from the window's start (rounded to 0.1 N; `0` leaves it
        out)."""
        cases = []
        for c in self.cases:
            record = c.row()
            if segments:
                record |= {
                    "arc_length": np.round(c.arc_length, 3).tolist(),
                    "static_tension": np.round(c.static_tension, 1).tolist(),
                    "segment_peak": np.round(c.tension.max(axis=0), 1).tolist(),
                    "segment_mean": np.round(c.tension.mean(axis=0), 1).tolist(),
                }
            if history_rate > 0:
                stride = max(1, int(round(1 / (history_rate * (c.times[1] - c.times[0])))))
                record |= {
                    "history_start_s": float(c.times[0]),
                    "history_step_s": float(c.times[stride] - c.times[0]),
                    "top": np.round(c.top[::stride], 1).tolist(),
                }
            cases.append(record)
        return {"settings": self.settings, "compile_s": self.compile_s, "run_s": self.run_s, "cases": cases}


def run_cases(
    specs: Sequence[Spec],
    *,
    n_segments: int = 20,
    duration: float = WINDOW[1],
    window: tuple[float, float] = WINDOW,
    sample_rate: float = 1000.0,
    batch: int = 12,
    waves: bool = True,
    law: str = "paper",
    domain: float = 1.0,
    mass_matrix: str = "lumped",
    rtol: float = 1e-8,
    atol: float = 1e-8,
    solver: diffrax.AbstractSolver | None = None,
    max_steps: int = 4_000_000,
    slack_width: float = 1e-5,
    period: float = WAVE_PERIOD,
    verbose: bool = False,
) -> AnchoredLineStudy:
    """Run the anchored-line paper's cases `specs` and read them inside `window`.

    Every case starts from its own static equilibrium in still water at t = 0
    (`jaxcable.solve_statics`, case by case; with `law="domain"`, from that of
    Hooke's law, C_E1 = 0), is simulated to `duration` with the top
    moving and, with `waves`, the wave acting on the line, and is sampled at
    `sample_rate` Hz inside `window`. The cases run as `jaxcable.sweep`s of `batch`
    cases each (the last padded by repeating its last case), sorted by C_E so that a
    batch's lockstep waits on cases of a like stiffness. Every batch of one
    configuration, whatever its cases, runs one compiled program, which later calls
    with the same configuration reuse.

    A snapping line's peak moves by a few per cent with the tolerance (a snap a little
    early or late over a run of several periods); `validation/anchored_line_reproduction.py`
    records how far.

    **Arguments:**

    - `specs`: the cases (`Spec`).
    - `n_segments`, `mass_matrix`, `slack_width`, `period`: as `anchored_line`.
    - `duration`: simulated time (s), at least `window[1]`.
    - `window`: `(start, end)` (s) over which the tension is read.
    - `sample_rate`: output samples per second inside the window.
    - `batch`: cases per sweep.
    - `waves`: the wave acts on the line (`anchored_line_case`).
    - `law`, `domain`: one of `LAWS`; for `"domain"`, the strain up to which
        `DomainElastic` must rise.
    - `rtol`, `atol`, `solver`, `max_steps`: the sweep's `jaxcable.SolverConfig`
        (Dopri5 by default).
    - `verbose`: print one line per batch.

    **Returns:** a `AnchoredLineStudy` with the cases in the order of `specs`, `compile_s` (a
    first batch to 1 ms, which compiles the program or finds it compiled) and `run_s`
    (the timed batches), in seconds. Neither counts the statics.

    **Raises:** `ValueError` for an empty `specs`, a window outside the run, or a
    `batch` below 1.
    """
    if duration < window[1] or window[0] >= window[1]:
        raise ValueError(f"run_cases: need window[0] < window[1] <= duration, got {window}, {duration}")
    if not specs:
        raise ValueError("run_cases: no cases")
    if batch < 1:
        raise ValueError(f"run_cases: batch must be at least 1, got {batch}")
    solver = diffrax.Dopri5() if solver is None else solver
    n_samples = int(round((window[1] - window[0]) * sample_rate)) + 1
    ts = np.linspace(window[0], window[1], n_samples)
    angles = sorted(set(ANGLES) | {float(s.angle) for s in specs})
    build, lines = _sweep_build(angles, n_segments, mass_matrix, slack_width, period, waves, law, domain)
    config = SolverConfig(solver, rtol=rtol, atol=atol, max_steps=max_steps)
    order = sorted(range(len(specs)), key=lambda i: specs[i].axial_stiffness)
    results: dict[int, AnchoredLineCase] = {}
    compile_s = run_s = 0.0
    for start in range(0, len(order), batch):
        members = order[start : start + batch]
        padded = members + [members[-1]] * (batch - len(members))
        group = [specs[i] for i in padded]
        grid = {
            "angle_degrees": np.array([s.angle for s in group], dtype=float),
            "axial_stiffness": np.array([s.axial_stiffness for s in group], dtype=float),
            "quadratic_ratio": np.array([s.ratio for s in group], dtype=float),
            "length_factor": np.array([s.length_factor for s in group], dtype=float),
        }
        # Outside the sweep, statics can fall back on energy descent (and raises if it
        # fails). The line hangs in still water before the waves and the top start.
        statics = []
        for s in group:
            if law == "domain":
                # The statics' continuation in stiffness passes through strains where a
                # softening law of this domain pushes: start from Hooke's equilibrium.
                model, env = anchored_line_case(
                    n_segments,
                    s.angle,
                    0.0,
                    s.axial_stiffness,
                    mass_matrix,
                    slack_width,
                    period,
                    waves=waves,
                    length_factor=s.length_factor,
                )
            else:
                model, env = build(s.angle, s.axial_stiffness, s.ratio, s.length_factor)
            statics.append(solve_statics(model, env.without_waves()))
        initial = State(np.stack([s.state.positions for s in statics]), np.stack([s.state.velocities for s in statics]))
        if start == 0:
            begin = time.perf_counter()
            warm_up = np.linspace(0.0, _WARM_UP, n_samples)
            jax.block_until_ready(sweep(build, grid, _WARM_UP, ts=warm_up, initial=initial, solver=config))
            compile_s = time.perf_counter() - begin
        begin = time.perf_counter()
        result = jax.block_until_ready(sweep(build, grid, float(duration), ts=ts, initial=initial, solver=config))
        elapsed = time.perf_counter() - begin
        run_s += elapsed
        tension = np.asarray(result.simulation.tension)
        strain = np.asarray(result.simulation.strain)
        steps = np.asarray(result.simulation.stats["num_steps"])
        rejected = np.asarray(result.simulation.stats["num_rejected_steps"])
        success = np.asarray(result.success)
        for j, i in enumerate(members):
            spec = specs[i]
            segment_length = np.asarray(lines[angles.index(_nearest(angles, spec.angle))][0].segment_length)
            segment_length = segment_length * spec.length_factor
            results[i] = AnchoredLineCase(
                spec=spec,
                times=ts,
                tension=tension[j],
                arc_length=np.cumsum(segment_length) - segment_length / 2,
                static_tension=np.asarray(statics[j].tension),
                peak_strain=float(strain[j].max()),
                success=bool(success[j]),
                steps=int(steps[j]),
                rejected_steps=int(rejected[j]),
                domain=domain if law == "domain" else np.inf,
            )
        if verbose:
            done = [results[i] for i in members]
            print(
                f"batch {start // batch + 1}/{-(-len(order) // batch)}: {elapsed:.1f} s, C_E "
                f"{min(c.axial_stiffness for c in done):.2g}–{max(c.axial_stiffness for c in done):.2g} N, "
                f"top peaks (kN) {', '.join(f'{c.peak_top / 1e3:.1f}' for c in done)}",
                flush=True,
            )
    settings = {
        "n_segments": n_segments,
        "duration_s": float(duration),
        "window_s": [float(w) for w in window],
        "sample_rate_Hz": float(sample_rate),
        "batch": batch,
        "waves": waves,
        "law": law,
        "domain": domain,
        "mass_matrix": mass_matrix,
        "rtol": rtol,
        "atol": atol,
        "solver": type(solver).__name__,
        "slack_width": slack_width,
        "period_s": period,
    }
    return AnchoredLineStudy([results[i] for i in range(len(specs))], settings, compile_s, run_s)


def _nearest(values, x):
    return values[int(np.argmin(np.abs(np.asarray(values) - x)))]


def anchored_line_study(
    angles: Sequence[float] = ANGLES,
    ratios: Sequence[float] = RATIOS,
    *,
    axial_stiffness: float | Sequence[float] = AXIAL_STIFFNESS,
    length_factor: float = 1.0,
    **config,
) -> AnchoredLineStudy:
    """Every combination of `angles`, `axial_stiffness` (one C_E or several, N) and
    `ratios` (C_E1/C_E), at one `length_factor`: `run_cases` over their product, with
    `config` passed on."""
    stiffnesses = np.atleast_1d(np.asarray(axial_stiffness, dtype=float)).tolist()
    specs = [Spec(float(a), c, float(r), float(length_factor)) for a in angles for c in stiffnesses for r in ratios]
    return run_cases(specs, **config)


# --- Calibration ------------------------------------------------------------------------------


@dataclasses.dataclass
class Calibration:
    """C_E found so that the top peak at `angle`, C_E1 = 0, is `target`.

    **Attributes:**

    - `axial_stiffness`: C_E (N) where the fitted line `ln T = a + b ln C_E` meets
        `target`.
    - `band`: the C_E (N) where the fit shifted by ± 2 × its residual RMS meets it.
    - `slope`, `intercept`: b (–) and a.
    - `residual_rms`: the RMS of the fit's residuals in ln T (–), the snap peaks' scatter.
    - `bracket`: the map's neighbouring C_E (N) between which the peak crosses `target`.
    - `study`: the refining runs.
    """

    target: float
    angle: float
    axial_stiffness: float
    band: tuple[float, float]
    slope: float
    intercept: float
    residual_rms: float
    bracket: tuple[float, float]
    study: AnchoredLineStudy

    def to_dict(self) -> dict:
        return {
            "target_N": self.target,
            "angle_deg": self.angle,
            "axial_stiffness_N": self.axial_stiffness,
            "band_N": list(self.band),
            "slope": self.slope,
            "intercept": self.intercept,
            "residual_rms": self.residual_rms,
            "bracket_N": list(self.bracket),
            "points": [[c.axial_stiffness, c.peak_top] for c in self.study.cases],
        }


def bracket(study: AnchoredLineStudy, target: float = TARGET_PEAK, angle: float = TARGET_ANGLE) -> tuple[float, float]:
    """The neighbouring C_E (N) of `study`'s linear cases at `angle` between which the
    top peak first rises through `target` (N).

    **Raises:** `ValueError` if it never does.
    """
    points = sorted((c.axial_stiffness, c.peak_top) for c in study.cases if c.angle == angle and c.ratio == 0.0)
    for (c0, p0), (c1, p1) in zip(points, points[1:]):
        if p0 <= target < p1:
            return c0, c1
    peaks = ", ".join(f"{c:.2g} N: {p / 1e3:.1f} kN" for c, p in points)
    raise ValueError(f"bracket: the top peak at {angle:g}° never crosses {target / 1e3:g} kN ({peaks})")


def calibrate_stiffness(
    coarse: AnchoredLineStudy,
    *,
    target: float = TARGET_PEAK,
    angle: float = TARGET_ANGLE,
    points: int | None = None,
    **config,
) -> Calibration:
    """Find C_E so that the top peak at `angle` with Hooke's law (C_E1 = 0) is `target`.

    The peak of a snapping line is not a smooth function of C_E (a snap a little early
    or late changes it by a few per cent, and its derivative through the simulation is
    dominated by that: `peak_gradient_check`), so the root is found by regression:

    1. `bracket` finds the neighbouring C_E of `coarse` (a map over C_E) between which
       the peak crosses `target`;
    2. `points` C_E, evenly spaced in ln C_E across the bracket, run as one batch
       (`run_cases`, `config` passed on; `points` is its `batch` by default);
    3. a least-squares line `ln T = a + b ln C_E` through them and the bracket's two
       ends is solved for `ln target`; its residual RMS gives the band.

    **Returns:** a `Calibration`.
    """
    low, high = bracket(coarse, target, angle)
    points = config.get("batch", 12) if points is None else points
    stiffnesses = np.exp(np.linspace(np.log(low), np.log(high), points + 2)[1:-1])
    study = run_cases([Spec(angle, float(c), 0.0) for c in stiffnesses], **config)
    ends = [coarse.case(angle, 0.0, c) for c in (low, high)]
    fit = power_law_root(
        [c.axial_stiffness for c in study.cases + ends], [c.peak_top for c in study.cases + ends], target
    )
    return Calibration(target, angle, *fit, bracket=(low, high), study=study)


def power_law_root(
    stiffnesses: Sequence[float], peaks: Sequence[float], target: float
) -> tuple[float, tuple[float, float], float, float, float]:
    """The C_E at which the least-squares line `ln T = a + b ln C_E` through
    (`stiffnesses`, `peaks`) meets `target`.

    **Returns:** `(root, band, b, a, rms)`: `band` the C_E where the line shifted by
    ± 2 `rms` (its residuals' RMS in ln T) meets `target`.
    """
    x, y = np.log(np.asarray(stiffnesses, dtype=float)), np.log(np.asarray(peaks, dtype=float))
    slope, intercept = np.polyfit(x, y, 1)
    rms = float(np.sqrt(np.mean((y - (intercept + slope * x)) ** 2)))

    def solve(shift):
        return float(np.exp((np.log(target) - intercept - shift) / slope))

    low, high = sorted((solve(2 * rms), solve(-2 * rms)))
    return solve(0.0), (low, high), float(slope), float(intercept), rms


def peak_gradient_check(
    axial_stiffness: float,
    *,
    angle: float = TARGET_ANGLE,
    n_segments: int = 8,
    duration: float = 30.0,
    window: tuple[float, float] = (18.0, 30.0),
    sample_rate: float = 1000.0,
    rtol: float = 1e-7,
    steps: Sequence[float] = (0.1, 0.03, 0.01, 0.001),
) -> dict:
    """The derivative of ln(top peak) in ln C_E at `axial_stiffness`, by `jax.grad`
    through the simulation and by central differences with the `steps` in ln C_E.

    Where they disagree, and the differences change with the step, the peak is no
    smooth function of C_E to calibrate by gradient.

    **Returns:** `{"gradient": ..., "differences": {step: ...}, "peak_N": ...}`.
    """
    model, env = anchored_line_case(n_segments, angle, 0.0, axial_stiffness)
    static = solve_statics(model, env.without_waves())
    ts = np.linspace(window[0], window[1], int(round((window[1] - window[0]) * sample_rate)) + 1)
    config = SolverConfig(rtol=rtol, atol=rtol, max_steps=1_000_000)

    def log_peak(log_c_e):
        changed = _with(model, jnp.exp(log_c_e), 0.0, 1.0)
        return jnp.log(
            jc.simulate(changed, env, duration, ts=ts, initial=static.state, solver=config).tension[:, -1].max()
        )

    value = jax.jit(log_peak)
    x = float(np.log(axial_stiffness))
    gradient = float(jax.jit(jax.grad(log_peak))(x))
    differences = {f"{h:g}": float((value(x + h) - value(x - h)) / (2 * h)) for h in steps}
    return {"gradient": gradient, "differences": differences, "peak_N": float(np.exp(value(x)))}


# --- Readings of C_E1 -------------------------------------------------------------------------

LARGE_STRAINS = (0.2, 0.5, 0.9)
"""Pretension strains ε₀ of the large-strain (polymer rope) reading; `solve_statics`
refuses a line that must stretch by 100 % or more to reach its ends."""
PERCENT_RATIOS = (-20.0, -10.0, 0.0, 20.0)
"""C_E1/C_E in strain for C_E1 = −0.2, −0.1, 0, +0.2 C_E per %² (ε in per cent)."""
PERCENT_DOMAIN = 0.02
"""`DomainElastic`'s domain for the per-cent reading: at C_E1 = −20 C_E its tension
rises up to ε = 2.5 %."""


def large_strain_specs(
    angles: Sequence[float] = (TARGET_ANGLE,),
    strains: Sequence[float] = LARGE_STRAINS,
    ratios: Sequence[float] = (-0.2, 0.0, 0.2),
    target: float = TARGET_PEAK,
) -> list[Spec]:
    """The large-strain reading: a rope so soft that it works at strains ε₀ of tens of
    per cent, made to carry the paper's tension by shortening it.

    For each ε₀ in `strains`: the unstretched length is the chord over 1 + ε₀ and
    C_E = `target` / ε₀, so that the straight line at Hooke's law holds `target` (N);
    the line's weight and motion move its peak from there, which the runs measure."""
    return [Spec(float(a), target / e, float(r), 1 / (1 + e)) for e in strains for a in angles for r in ratios]


def effect(study: AnchoredLineStudy, ratio: float, reference: float = 0.0, key: str = "peak_top", **pick) -> dict:
    """Per angle, `key`(ratio) / `key`(reference) − 1 among `study`'s cases matching
    `pick` (`axial_stiffness`, `length_factor`)."""
    out = {}
    for a in study.angles:
        try:
            out[a] = getattr(study.case(a, ratio, **pick), key) / getattr(study.case(a, reference, **pick), key) - 1
        except KeyError:
            continue
    return out


PAPER_EFFECT = (-0.30, -0.10)
"""The range that counts as the paper's "up to about 20 %" lower peak."""


def readings_table(
    calibrated: AnchoredLineStudy, large: AnchoredLineStudy | None, percent: AnchoredLineStudy | None, c_e: float
) -> list[dict]:
    """The effect on the top peak at each angle of each reading of "C_E1 = 0.2 C_E",
    and whether it is the paper's (`PAPER_EFFECT` at 45°).

    - as written: C_E1 = +0.2 C_E at the calibrated C_E (`calibrated`);
    - softening: C_E1 = −0.2 C_E there;
    - large strain: ±0.2 C_E at each ε₀ of `large` (`large_strain_specs`);
    - per cent: ε in per cent, C_E1 = ±0.2 C_E per %², i.e. ±20 C_E (`percent`).

    **Returns:** one dict per reading: `reading`, `effect` (per angle), `peak_strain`
    (the largest among its cases), `valid` (strains inside the law's domain), `gives`
    (the paper's 20 % at 45°, or `None` where 45° was not run).
    """
    rows = []

    def add(name, study, ratio, reference=0.0, **pick):
        change = effect(study, ratio, reference, **pick)
        cases = [c for c in study.cases if all(np.isclose(getattr(c, k), v) for k, v in pick.items())]
        cases = [c for c in cases if c.ratio in (ratio, reference)]
        at_45 = change.get(TARGET_ANGLE)
        rows.append(
            {
                "reading": name,
                "effect": change,
                "peak_strain": max(c.peak_strain for c in cases),
                "valid": all(c.in_domain and c.success for c in cases),
                "gives": None if at_45 is None else bool(PAPER_EFFECT[0] <= at_45 <= PAPER_EFFECT[1]),
            }
        )

    add("as written: C_E1 = +0.2 C_E", calibrated, 0.2, axial_stiffness=c_e)
    add("softening: C_E1 = −0.2 C_E", calibrated, -0.2, axial_stiffness=c_e)
    if large is not None:
        for factor in sorted({c.length_factor for c in large.cases}, reverse=True):
            e0 = 1 / factor - 1
            for sign in (1, -1):
                add(f"large strain ε₀ = {e0:g}: C_E1 = {0.2 * sign:+g} C_E", large, 0.2 * sign, length_factor=factor)
    if percent is not None:
        for r in sorted((r for r in percent.ratios if r != 0), key=abs):
            add(f"ε in per cent: C_E1 = {r / 100:+g} C_E per %² ({r:+g} C_E)", percent, r)
    return rows


def readings_markdown(rows: list[dict]) -> str:
    out = [
        "| reading | top peak vs C_E1 = 0, 30° / 45° / 60° | largest strain | in the law's domain "
        "| the paper's −20 % at 45° |",
        "|---|---|---|---|---|",
    ]
    for r in rows:
        change = " / ".join(f"{100 * r['effect'][a]:+.1f} %" if a in r["effect"] else "–" for a in ANGLES)
        out.append(
            f"| {r['reading']} | {change} | {r['peak_strain']:.4f} | {'yes' if r['valid'] else 'NO'} | "
            f"{_word(r['gives'])} |"
        )
    return "\n".join(out)


# --- The paper's claims ----------------------------------------------------------------------

INSIGNIFICANT = 0.05
"""A change of C_E1's or the angle's that the paper calls insignificant: under 5 %,
about twice the snap peaks' scatter with the tolerance."""


def claims(
    study: AnchoredLineStudy,
    c_e: float,
    *,
    ratios: tuple[float, float] = (0.1, 0.2),
    length_factor: float | None = None,
    tolerance_study: AnchoredLineStudy | None = None,
) -> list[dict]:
    """The paper's claims against `study` (every angle, C_E1/C_E = 0 and `ratios` at
    least, at C_E = `c_e` and, where given, L0/chord = `length_factor`), each with its
    criterion and a verdict computed from the numbers. With `tolerance_study` (the same
    cases at a tighter tolerance), a verdict that the tolerance flips is reported as not
    robust.

    `ratios` are the C_E1/C_E that the paper's "0.1 C_E" and "0.2 C_E" mean: `(0.1, 0.2)`
    as written; a reading's otherwise (`(-10, -20)` for ε in per cent with a softening
    sign).

    **Returns:** one dict per claim: `claim`, `paper`, `criterion`, `result` (words
    with the numbers), `agrees` (`True`, `False`, or `None` where undecidable), `robust`
    (`None` without `tolerance_study`), `why`.
    """

    def numbers(s):
        pick = {"axial_stiffness": c_e} | ({} if length_factor is None else {"length_factor": length_factor})
        get = lambda a, r, key="peak_top": getattr(s.case(a, r, **pick), key)  # noqa: E731
        out = {}
        out["30: 0.2 vs 0.1"] = get(30.0, r2) / get(30.0, r1) - 1
        out["45: 0.2 vs 0"] = get(45.0, r2) / get(45.0, 0.0) - 1
        out["60: 0.2 vs 0.1"] = get(60.0, r2) / get(60.0, r1) - 1
        out["45 vs 30"] = [get(45.0, r) / get(30.0, r) - 1 for r in (0.0, r1, r2)]
        out["60 vs 30"] = [get(60.0, r) / get(30.0, r) - 1 for r in (0.0, r1, r2)]
        linear, top = s.case(45.0, 0.0, **pick), s.case(45.0, r2, **pick)
        along = top.tension.max(axis=0) / linear.tension.max(axis=0) - 1
        out["along 45: median"] = float(np.median(along))
        out["along 45: spread"] = float(along.max() - along.min())
        out["scale 45"] = [
            min(getattr(s.case(45.0, r, **pick), k) for r in (0.0, r1, r2) for k in ("peak_top", "peak_middle")) / 1e3,
            max(getattr(s.case(45.0, r, **pick), k) for r in (0.0, r1, r2) for k in ("peak_top", "peak_middle")) / 1e3,
        ]
        out["slack 45"] = [s.case(45.0, r, **pick).slack_seconds for r in (0.0, r1, r2)]
        out["vibration 45"] = [s.case(45.0, r, **pick).vibration_persistence for r in (0.0, r1, r2)]
        out["strain"] = {a: s.case(a, r2, **pick).peak_strain for a in ANGLES}
        out["static"] = {a: s.case(a, 0.0, **pick).static_tension[-1] / 1e3 for a in ANGLES}
        out["slack"] = {a: s.case(a, 0.0, **pick).slack_seconds for a in ANGLES}
        return out

    def verdicts(n):
        return {
            "fig2": abs(n["30: 0.2 vs 0.1"]) < INSIGNIFICANT,
            "fig3": PAPER_EFFECT[0] <= n["45: 0.2 vs 0"] <= PAPER_EFFECT[1],
            "angle45": all(abs(v) < INSIGNIFICANT for v in n["45 vs 30"]),
            "fig4": abs(n["60: 0.2 vs 0.1"]) < INSIGNIFICANT,
            "angle60": all(-0.35 <= v <= -0.15 for v in n["60 vs 30"]),
            "fig5": n["along 45: median"] <= -INSIGNIFICANT,
            "scale": PUBLISHED_SCALE[0] / 1e3 * 0.9 <= n["scale 45"][0]
            and n["scale 45"][1] <= PUBLISHED_SCALE[1] / 1e3 * 1.1,
            "vibration": min(n["slack 45"]) > 0 and min(n["vibration 45"]) >= 0.5,
        }

    r1, r2 = ratios
    n = numbers(study)
    v = verdicts(n)
    robust = None
    if tolerance_study is not None:
        tight = verdicts(numbers(tolerance_study))
        robust = {k: tight[k] == v[k] for k in v}

    def share(a):
        """The quadratic term's part of the tension at the peak strain at angle `a`."""
        e = n["strain"][a]
        return f"at the peak strain ε = {e:.4f} the quadratic term changes a tension by {100 * r2 * e:+.2f} %"

    # The top's motion along the chord (m): what the line must follow or go slack.
    along = {a: float(floater_amplitude(WAVE_PERIOD)) * np.cos(np.radians(a)) for a in ANGLES}

    def geometry(a, b):
        return (
            f"{a:g}° / {b:g}°: static top T {n['static'][a]:.1f} / {n['static'][b]:.1f} kN, top's motion along "
            f"the chord A cos α {along[a]:.2f} / {along[b]:.2f} m, top slack {n['slack'][a]:.3f} / "
            f"{n['slack'][b]:.3f} s (C_E1 = 0)"
        )

    pct = lambda x: f"{100 * x:+.1f} %"  # noqa: E731
    rows = [
        (
            "fig2",
            "30° (Fig. 2): C_E1 from 0.1 to 0.2 C_E lowers the peak insignificantly",
            f"|change| < {100 * INSIGNIFICANT:g} %",
            f"top peak {pct(n['30: 0.2 vs 0.1'])}",
            share(30.0),
        ),
        (
            "fig3",
            "45° (Fig. 3): C_E1 = 0.2 C_E lowers the peak by up to 20 % against Hooke's law",
            f"change within {pct(PAPER_EFFECT[0])} … {pct(PAPER_EFFECT[1])}",
            f"top peak {pct(n['45: 0.2 vs 0'])}",
            share(45.0),
        ),
        (
            "angle45",
            "30° → 45°: the tension hardly changes at equal C_E1",
            f"|45° vs 30°| < {100 * INSIGNIFICANT:g} % at C_E1 = 0, 0.1, 0.2 C_E",
            "45° vs 30°: " + " / ".join(pct(x) for x in n["45 vs 30"]),
            geometry(30.0, 45.0),
        ),
        (
            "fig4",
            "60° (Fig. 4): C_E1 changes the peak insignificantly",
            f"|0.2 vs 0.1 C_E| < {100 * INSIGNIFICANT:g} %",
            f"top peak {pct(n['60: 0.2 vs 0.1'])}",
            share(60.0),
        ),
        (
            "angle60",
            "30° → 60°: the tension falls by about 25 %",
            "60° vs 30° within −35 … −15 % at C_E1 = 0, 0.1, 0.2 C_E",
            "60° vs 30°: " + " / ".join(pct(x) for x in n["60 vs 30"]),
            geometry(30.0, 60.0),
        ),
        (
            "fig5",
            "Fig. 5: the tension falls with C_E1 along the line, unevenly",
            f"the median segment's peak at 0.2 C_E at least {100 * INSIGNIFICANT:g} % below C_E1 = 0 (45°)",
            f"median segment {pct(n['along 45: median'])}, spread {100 * n['along 45: spread']:.1f} points",
            "segment peaks move by snap timing, either way",
        ),
        (
            "scale",
            "Fig. 5's axis: peaks at the top and middle within 4.8–6.0 × 10⁴ N",
            "45°, C_E1 = 0–0.2 C_E, within the axis ± 10 %",
            f"{n['scale 45'][0]:.1f}–{n['scale 45'][1]:.1f} kN",
            "C_E is calibrated on the top peak at C_E1 = 0 alone; the middle point is a check",
        ),
        (
            "vibration",
            "the vibrations that follow slackening do not die out",
            "the top segment goes slack in the window and its tension above 1 Hz keeps ≥ half its RMS from "
            "the first period to the last",
            "45°, top slack "
            + " / ".join(f"{x:.3f}" for x in n["slack 45"])
            + " s, vibration kept "
            + " / ".join(f"{x:.2f}" for x in n["vibration 45"])
            + f" at C_E1 = 0 / {r1:g} / {r2:g} C_E",
            "a line that does not go slack has no slackening to renew the vibration each period",
        ),
    ]
    return [
        {
            "key": key,
            "claim": claim,
            "criterion": criterion,
            "result": result,
            "agrees": bool(v[key]),
            "robust": None if robust is None else robust[key],
            "why": why,
        }
        for key, claim, criterion, result, why in rows
    ]


def claims_markdown(rows: list[dict]) -> str:
    out = ["| claim | result | agreement | why |", "|---|---|---|---|"]
    for r in rows:
        robust = "" if r["robust"] in (None, True) else " (not robust: the tighter tolerance flips it)"
        out.append(
            f"| {r['claim']} | {r['result']} (criterion: {r['criterion']}) | "
            f"{'yes' if r['agrees'] else 'no'}{robust} | {r['why']} |"
        )
    return "\n".join(out)


# --- Tables and figures -----------------------------------------------------------------------


def table_markdown(study: AnchoredLineStudy) -> str:
    """The results table as markdown (kN, seconds)."""
    out = [
        "| α | C_E (N) | C_E1/C_E | L0/chord | static top (kN) | peak top (kN) | peak middle (kN) | peak anchor (kN) "
        "| min top (kN) | peak ε | slack top (s) | steps | ok |",
        "|---|---|---|---|---|---|---|---|---|---|---|---|---|",
    ]
    for c in study.cases:
        out.append(
            f"| {c.angle:g}° | {c.axial_stiffness:.3g} | {c.ratio:g} | {c.length_factor:.3g} | "
            f"{c.static_tension[-1] / 1e3:.1f} | {c.peak_top / 1e3:.1f} | {c.peak_middle / 1e3:.1f} | "
            f"{c.peak_anchor / 1e3:.1f} | {c.min_top / 1e3:.2f} | {c.peak_strain:.4f} | {c.slack_seconds:.2f} | "
            f"{c.steps} | {'yes' if c.success and c.in_domain else 'NO'} |"
        )
    return "\n".join(out)


def effect_map(study: AnchoredLineStudy, ratio: float) -> tuple[list[float], list[float], np.ndarray]:
    """`(angles, stiffnesses, change)`: the top peak at C_E1 = `ratio` C_E over that at
    C_E1 = 0, minus 1, shape `(angles, stiffnesses)` (NaN where a case is missing)."""
    angles, stiffnesses = study.angles, study.stiffnesses
    change = np.full((len(angles), len(stiffnesses)), np.nan)
    for i, a in enumerate(angles):
        for j, c in enumerate(stiffnesses):
            try:
                change[i, j] = study.case(a, ratio, c).peak_top / study.case(a, 0.0, c).peak_top - 1
            except KeyError:
                pass
    return angles, stiffnesses, change


def plot_effect_map(study: AnchoredLineStudy, ratio: float, ax, calibrated: float | None = None, limit: float = 20.0):
    """A map of `effect_map` in per cent over (C_E, α), with its colour bar; the
    calibrated C_E as a dashed line."""
    import matplotlib.pyplot as plt

    angles, stiffnesses, change = effect_map(study, ratio)
    edges = np.exp(np.convolve(np.log(stiffnesses), [0.5, 0.5], "valid"))
    x = np.concatenate([[stiffnesses[0] ** 2 / edges[0]], edges, [stiffnesses[-1] ** 2 / edges[-1]]])
    y = np.concatenate([[angles[0] - 7.5], np.convolve(angles, [0.5, 0.5], "valid"), [angles[-1] + 7.5]])
    mesh = ax.pcolormesh(x, y, 100 * change, cmap="RdBu_r", vmin=-limit, vmax=limit)
    for i, a in enumerate(angles):
        for j, c in enumerate(stiffnesses):
            if np.isfinite(change[i, j]):
                ax.text(c, a, f"{100 * change[i, j]:+.1f}", ha="center", va="center", fontsize=7)
    if calibrated is not None:
        ax.axvline(calibrated, color="k", ls="--", lw=1, label=f"calibrated C_E = {calibrated:.3g} N")
        ax.legend(fontsize=7, loc="upper left")
    ax.set_xscale("log")
    ax.set_yticks(angles)
    ax.set_xlabel("C_E (N)")
    ax.set_ylabel("design angle α (°)")
    ax.set_title(f"top peak at C_E1 = {ratio:+g} C_E vs C_E1 = 0", fontsize=9)
    plt.colorbar(mesh, ax=ax, label="change of the top peak (%)")
    return ax


def plot_scale(study: AnchoredLineStudy, ax, calibration: Calibration | None = None):
    """The top peak at C_E1 = 0 against C_E, one curve per angle, over Fig. 5's axis
    (shaded) and the calibration's points and root."""
    for a in study.angles:
        cases = sorted((c for c in study.cases if c.angle == a and c.ratio == 0.0), key=lambda c: c.axial_stiffness)
        ax.plot([c.axial_stiffness for c in cases], [c.peak_top / 1e4 for c in cases], "o-", label=f"α = {a:g}°")
    ax.axhspan(PUBLISHED_SCALE[0] / 1e4, PUBLISHED_SCALE[1] / 1e4, color="0.85", label="paper's Fig. 5 axis")
    if calibration is not None:
        points = calibration.study.cases
        ax.plot(
            [c.axial_stiffness for c in points],
            [c.peak_top / 1e4 for c in points],
            "k.",
            ms=4,
            label=f"calibration runs, {calibration.angle:g}°",
        )
        ax.axvline(
            calibration.axial_stiffness, color="k", ls="--", lw=1, label=f"C_E = {calibration.axial_stiffness:.3g} N"
        )
        ax.axvspan(*calibration.band, color="k", alpha=0.1)
    ax.set_xscale("log")
    ax.set_xlabel("C_E (N)")
    ax.set_ylabel("peak top T at C_E1 = 0 (10⁴ N)")
    ax.set_title("the published scale fixes C_E", fontsize=9)
    ax.legend(fontsize=7)
    return ax


def plot_histories(study: AnchoredLineStudy, angle: float, ax, ratios: Sequence[float] | None = None, **pick):
    """Top tension (10⁴ N, the paper's unit) over the window at one angle, one curve per
    ratio; `pick` chooses C_E / L0 where the study has several."""
    for r in study.ratios if ratios is None else ratios:
        c = study.case(angle, r, **pick)
        ax.plot(c.times, c.top / 1e4, lw=0.8, label=f"C_E1 = {r:g} C_E")
    ax.set_xlabel("t (s)")
    ax.set_ylabel("top T (10⁴ N)")
    return ax


def plot_points(study: AnchoredLineStudy, angle: float, ax, **pick):
    """The paper's Fig. 5: the peak tension at the top, middle and anchor segments
    against C_E1/C_E, over Fig. 5's axis (shaded)."""
    ratios = [r for r in study.ratios if r >= 0]
    for key, label in (("peak_top", "top point"), ("peak_middle", "middle point"), ("peak_anchor", "anchor point")):
        ax.plot(ratios, [getattr(study.case(angle, r, **pick), key) / 1e4 for r in ratios], "o-", label=label)
    ax.axhspan(PUBLISHED_SCALE[0] / 1e4, PUBLISHED_SCALE[1] / 1e4, color="0.85", label="paper's Fig. 5 axis")
    ax.set_xlabel("C_E1 / C_E")
    ax.set_ylabel("peak T (10⁴ N)")
    ax.legend(fontsize=7)
    return ax


def plot_readings(rows: list[dict], ax):
    """The top peak's change at 45° under each reading, against the paper's band."""
    names = [r["reading"] for r in rows]
    values = [100 * r["effect"].get(TARGET_ANGLE, np.nan) for r in rows]
    colours = ["C2" if r["gives"] else ("C3" if not r["valid"] else "C0") for r in rows]
    ax.barh(range(len(rows)), values, color=colours)
    ax.axvspan(100 * PAPER_EFFECT[0], 100 * PAPER_EFFECT[1], color="0.85", label="the paper's −20 % (−30 … −10 %)")
    ax.axvline(0, color="k", lw=0.5)
    ax.set_yticks(range(len(rows)), names, fontsize=7)
    ax.invert_yaxis()
    ax.set_xlabel(f"top peak vs C_E1 = 0 at α = {TARGET_ANGLE:g}° (%)")
    ax.set_title("readings of C_E1 = 0.2 C_E (green: the paper's 20 %; red: outside the law's domain)", fontsize=8)
    ax.legend(fontsize=7, loc="lower right")
    return ax


def _word(flag) -> str:
    return "–" if flag is None else ("yes" if flag else "no")
