"""Advice on a model before running it: which wave theory and loads fit the sea, how
many segments the lines' shapes need, whether lines may go slack, and what limits an
explicit step.

[`advise`][jaxcable._advice.advise] returns an [`Advice`][jaxcable._advice.Advice] of numbers;
[`jaxcable.io.advice_lines`][] (`io/_advice_text.py`) says them in the words that
`jaxcable info` prints. It costs a few static solves: one
for the mean equilibrium (the lines' curvature, and where they are shallowest), and two
for each moving support (slack). The criteria, and where they come from:

- **Wave theory.** The Ursell number U = H λ²/d³ weighs nonlinearity H/d against
  dispersion (d/λ)². Stokes' second-order profile grows a second crest in its trough
  when U > 8π²/3 ≈ 26 (its second harmonic is 3U/(32π²) of the first in shallow
  water), so below that linear or Stokes theory holds (Airy is jaxcable's); above it,
  in water shallow enough for the long-wave approximation, λ > 8 d (Fenton 1999, "The
  cnoidal theory of water waves"), cnoidal theory does. A wave breaks beyond
  H/d = 0.78 (McCowan 1894) or H/λ = 0.142 tanh(2π d/λ) (Miche 1944): no regular
  theory then, and the waves refuse such heights when they are built.
- **Fluid inertia.** The Keulegan–Carpenter number KC = u T / D (u the water's
  speed amplitude where the element is shallowest, T the period, D the diameter;
  (6V/π)^⅓ for a body) sets the balance in Morison's equation. In sinusoidal flow the
  peak inertia force (Froude–Krylov plus added mass) over the peak drag force is
  r = 4π V C_M / (C_D A u T) per element (V the displaced volume, C_M = 1 + C_a, C_D A
  the drag area; for a line per unit length, V = F and C_D A = K_n d, so
  r = π² C_M / (K_n KC) when F = π d²/4). The peak of the sum is the drag peak times
  1 + r²/4 for r ≤ 2: inertia adds less than 6 % when r < 0.5, and dominates when
  r > 2. With C_M = 2 and K_n = 1.2 these are KC > 33 and KC < 8, within the usual
  rules of thumb (drag dominant above KC of about 25 to 45, inertia below about 3 to
  10; e.g. Sarpkaya & Isaacson 1981, Journée & Massie 2001), here on each element's own
  coefficients. When every element is drag-dominated, `fluid_inertia = false` loses
  little.
- **Segments.** A polyline of segments h = L/N through a smooth curve of curvature κ
  deviates from it by at most √2/8 · h² · max κ (linear interpolation's error bound,
  h²/8 · max |r''| per component, on the two components of the curve's plane). The
  curvature is estimated at each interior node of the mean equilibrium as the turning
  angle over the mean of the adjacent segments' lengths, which under-resolves a peak
  narrower than a segment: where more segments are needed, the count is a lower bound.
- **Slack.** Each moving support is held at either extreme of its motion (a harmonic
  motion's ±amplitude along its direction; a table's extreme samples) and the statics
  solved: a line goes slack quasi-statically when a segment's tension falls below 1 %
  of the largest at rest, or no taut equilibrium exists. Dynamics make slack more
  likely than this: a line falls sideways no faster than its terminal speed
  √(2 w / (ρ K_n d)) (wet weight w per length against drag), and a support moving
  faster than that outruns it and loads it by snap.
- **Irregular seas.** A regular wave loads a mooring at one period; near one of the
  mooring's natural periods T_n its response hinges on damping. The natural periods
  come from the stiffness K = −∂Q/∂x of the free nodes at the mean equilibrium (still
  water, supports held) against their mass matrix M (added mass included): the
  generalised eigenvalues ω² of K v = ω² M v, undamped. A linear oscillator forced at
  period T amplifies 1/|1 − (T_n/T)²| (undamped), at least twice when
  0.71 T ≤ T_n ≤ 1.22 T: such a wave is near resonance, and a sea of the same energy,
  spread over periods, loads it differently. And a design check's most probable
  maximum needs an irregular sea, over several seeds, in any case. An irregular sea
  on equal frequency steps Δω repeats after 2π/Δω
  ([`repeat_period`][jaxcable._sea.irregular.repeat_period]): a longer run repeats its
  statistics.
- **Stiffness** (when asked for: it compiles a program of its own). The stiffness of
  each coupled point (or, without a scene's names, each moving support) at the mean
  equilibrium, K = ∂R/∂x = −∂F/∂x ([`jaxcable.stiffness`][]), by which a coupled
  program's floater feels its lines; its diagonal is what `jaxcable info --stiffness`
  reports.
- **Explicit step.** Explicit Runge–Kutta methods of order 4–5 are stable for |λ Δt|
  up to about 3, with |λ| the fastest of the lines' axial mode
  ([`stiffest_axial_mode`][jaxcable._equations.modes.stiffest_axial_mode]) and, where lines
  can reach a seabed ([`seabed_reach`][jaxcable._model.reach.seabed_reach]), of its contact
  ([`seabed_mode`][jaxcable._equations.modes.seabed_mode]).

Statics here leave the waves out (their drag and inertia at one instant are no mean
load) and hold every support at its reference position.
"""

from dataclasses import dataclass

import equinox as eqx
import jax
import jax.numpy as jnp
import lineax as lx
import numpy as np
import optimistix as optx

from ._equations.modes import (
    bending_modes,
    natural_periods,
    seabed_mode,
    stiffest_axial_mode,
    unpack,
)
from ._model.motion import Fixed, Harmonic, Sampled
from ._model.network import CableNetwork
from ._model.reach import seabed_reach
from ._model.state import State
from ._sea.cnoidal import Cnoidal
from ._sea.environment import Environment
from ._sea.irregular import WaveComponents, repeat_period
from ._sea.waves import AbstractWave, Airy
from ._statics.solution import FORCE_TOLERANCE, MAX_STEPS
from ._statics.solve import solve_statics
from ._statics.stiffness import stiffness_and_statics

# Stokes' second harmonic reaches a quarter of the first (a second crest in the
# trough) at U = 8π²/3.
URSELL_LIMIT = 8 * np.pi**2 / 3
# Cnoidal theory for waves longer than 8 depths (Fenton 1999).
CNOIDAL_RELATIVE_DEPTH = 1 / 8
DEEP_RELATIVE_DEPTH, SHALLOW_RELATIVE_DEPTH = 0.5, 0.05
# Peak inertia over peak drag: below, inertia adds < 6 % to the peak force; above the
# other, inertia dominates.
DRAG_DOMINATES, INERTIA_DOMINATES = 0.5, 2.0
# A segment is slack when its tension is below this fraction of the largest at rest.
SLACK_FRACTION = 0.01
# The largest stable |λ Δt| of Dopri5 and Tsit5 measured on the anchored line
# (`benchmarks/stability.py`): 1.68–1.92 where the axial mode is fast (ω_n ≥ 300 rad/s),
# 3–4 only where drag damps it (ω_n ≤ 235 rad/s). The lower figure is the safe one.
STABLE_STEP = 1.7
DEFAULT_TOLERANCE = 0.01  # of each line's length
# A wave is near resonance where an undamped oscillator amplifies it at least this much.
RESONANT_AMPLIFICATION = 2.0


@dataclass(frozen=True)
class Labels:
    """What a scene calls the parts of a model, so that advice names them as the scene
    does ([`jaxcable.io.BuiltScene`][]'s `labels`).

    - `lines`: `(name, nodes, segments)` of each line, nodes and segments from end A to
        end B.
    - `line_types`: each line's type, in the order of `lines`.
    - `points`: the names of the first nodes, in node order.
    - `coupled`: the nodes of the scene's coupled points (those a coupled program or a
        motion moves), whose stiffness the advice can report.
    """

    lines: tuple[tuple[str, np.ndarray, np.ndarray], ...]
    line_types: tuple[str, ...]
    points: tuple[str, ...]
    coupled: tuple[int, ...] = ()


@dataclass(frozen=True)
class BendingCheck:
    """Whether a line's bending stiffness shapes it, at the mean equilibrium.

    - `bending_stiffness`: EI (N·m²), the largest.
    - `bending_length`: √(EI/T) (m), the longest over the segments (at the lowest
        tension; infinite where a segment is slack): the length over which bending
        bends the line near a support or a load.
    - `segment_length`: ℓ (m) of that segment.
    - `omega`: ω_b (rad/s), the fastest bending mode ([`bending_modes`][jaxcable._equations.modes.bending_modes]).
    """

    bending_stiffness: float
    bending_length: float
    segment_length: float
    omega: float

    @property
    def matters(self) -> bool:
        """Whether the bending length reaches a tenth of a segment: shorter, the
        curvature it resolves at the supports lies inside one segment, and EI changes
        the forces little."""
        return self.bending_length > 0.1 * self.segment_length


def _bending_check(model: CableNetwork, env: Environment, tension: np.ndarray | None) -> BendingCheck | None:
    ei = model.line.bending_stiffness
    if ei is None:
        return None
    ei = np.broadcast_to(np.asarray(ei), (model.n_segments,))
    omega = bending_modes(model, env)
    if tension is None:
        length = np.full(model.n_segments, np.nan)
    else:
        with np.errstate(divide="ignore"):
            length = np.where(tension > 0, np.sqrt(ei / np.maximum(tension, 0.0)), np.inf)
    s = int(np.argmax(ei)) if tension is None else int(np.argmax(length))
    return BendingCheck(
        float(ei.max()), float(length[s]), float(np.asarray(model.segment_length)[s]), float(omega.max())
    )


# --------------------------------------------------------------------------------------
# The parts of the advice


@dataclass(frozen=True)
class WaveFit:
    """Which wave theory fits one wave (module docstring).

    - `index`: the wave's place in `Environment.waves`.
    - `theory`: what the model uses, `"airy"` or `"cnoidal"`.
    - `height` H, `period` T, `wavelength` λ, `depth` d: (m, s, m, m).
    - `ursell`: U = H λ²/d³; `relative_depth`: d/λ; `height_ratio`: H/d;
        `steepness`: H/λ.
    - `regime`: `"deep"` (d/λ > 0.5), `"intermediate"` or `"shallow"` (d/λ < 0.05).
    - `fits`: `"airy"`, `"cnoidal"` or `"none"`
        (between the theories jaxcable has).
    - `reason`: why, in words.
    - `irregular`: whether the wave is an irregular sea of Airy components
        ([`jaxcable.WaveComponents`][]); `height` is then its H_s, `period` its most
        energetic component's, and `repeat_period` (s) the time after which it repeats
        (`inf` for a regular wave).
    """

    index: int
    theory: str
    height: float
    period: float
    wavelength: float
    depth: float
    ursell: float
    relative_depth: float
    height_ratio: float
    steepness: float
    regime: str
    fits: str
    reason: str
    irregular: bool = False
    repeat_period: float = float("inf")

    @property
    def uses_fitting_theory(self) -> bool:
        """Whether the model's theory is the one that fits."""
        return self.theory == self.fits


@dataclass(frozen=True)
class InertiaCheck:
    """Drag against fluid inertia on one element in one wave (module docstring).

    - `element`: what it is (`"line type chain"`, `"body at point buoy"`, ...).
    - `wave`: the wave's index; `period` T (s).
    - `depth`: z (m) where the element is shallowest, at which `speed` u (m/s), the
        water's speed amplitude, is taken.
    - `diameter`: D (m), a line's, or a body's volume-equivalent (6V/π)^⅓.
    - `keulegan_carpenter`: KC = u T / D.
    - `inertia_ratio`: r, the peak inertia force over the peak drag force.
    """

    element: str
    wave: int
    period: float
    depth: float
    speed: float
    diameter: float
    keulegan_carpenter: float
    inertia_ratio: float

    @property
    def regime(self) -> str:
        """`"drag"` (r < 0.5), `"inertia"` (r > 2) or `"both"`."""
        if self.inertia_ratio < DRAG_DOMINATES:
            return "drag"
        return "inertia" if self.inertia_ratio > INERTIA_DOMINATES else "both"


@dataclass(frozen=True)
class Discretisation:
    """Whether a line's segments follow its mean shape.

    - `line`: its name; `length` L (m, unstretched); `segments` N.
    - `curvature`: κ_max (1/m), the largest turning angle per length at an interior
        node; `node`: that node's index in the model (−1 for a single segment).
    - `deviation`: √2/8 · (L/N)² · κ_max (m), the polyline's error bound now.
    - `tolerance`: (m), the deviation allowed.
    - `needed`: the N that meets it.
    """

    line: str
    length: float
    segments: int
    curvature: float
    node: int
    deviation: float
    tolerance: float
    needed: int


@dataclass(frozen=True)
class SlackCheck:
    """One moving support held at one extreme of its motion.

    - `point`: its name; `node`: its index in the model.
    - `displacement`: (m), from its reference position.
    - `converged`: whether the statics found an equilibrium there.
    - `min_tension`: (N), the smallest segment tension (NaN if not converged);
        `line`: the line with that segment, `segment`: the model's segment index.
    - `slack`: whether a segment goes slack (module docstring).
    - `speed`: the support's largest speed (m/s); `terminal_speed`: the slowest
        terminal speed (m/s) at which the lines it holds fall sideways, or NaN for a
        buoyant line.
    """

    point: str
    node: int
    displacement: tuple[float, float, float]
    converged: bool
    min_tension: float
    line: str
    segment: int
    slack: bool
    speed: float
    terminal_speed: float


@dataclass(frozen=True)
class SupportStiffness:
    """A support's stiffness at the mean equilibrium ([`jaxcable.stiffness`][]).

    - `point`: its name; `node`: its index in the model.
    - `matrix`: K = ∂R/∂x (N/m), rows and columns x, y, z: the change of the force
        its support exerts on the lines as it moves, the lines' restoring force per
        metre.
    """

    point: str
    node: int
    matrix: tuple[tuple[float, float, float], ...]

    @property
    def diagonal(self) -> tuple[float, float, float]:
        """K_xx, K_yy, K_zz (N/m)."""
        return (self.matrix[0][0], self.matrix[1][1], self.matrix[2][2])


@dataclass(frozen=True)
class Advice:
    """What [`advise`][jaxcable._advice.advise] found. The fields hold numbers;
    [`jaxcable.io.advice_lines`][] says them.

    - `omega`, `eigenvalue`, `segment`: [`stiffest_axial_mode`][jaxcable._equations.modes.stiffest_axial_mode].
    - `seabed_eigenvalue`, `seabed_limit`: [`seabed_mode`][jaxcable._equations.modes.seabed_mode]
        on the segments that touch the bed at rest (0 and `""` if none).
    - `explicit_step`: 1.7/|λ| (s), the longest stable step of an explicit solver, |λ|
        the largest of the axial, the bending and the seabed's.
    - `duration`: (s) or `None`; `steps`: the explicit steps it needs at least.
    - `waves`: a [`WaveFit`][jaxcable._advice.WaveFit] per wave.
    - `inertia`: an [`InertiaCheck`][jaxcable._advice.InertiaCheck] per element and
        wave; `fluid_inertia`: whether the model has fluid inertia switched on.
    - `discretisation`: a [`Discretisation`][jaxcable._advice.Discretisation] per line.
    - `rest_min_tension`, `rest_max_tension`: (N) at the mean equilibrium.
    - `slack`: a [`SlackCheck`][jaxcable._advice.SlackCheck] per extreme of each moving
        support.
    - `statics_error`: why the mean equilibrium was not found, or `None`.
    - `natural_periods`: (s) the mooring's longest natural periods about the mean
        equilibrium ([`natural_periods`][jaxcable._equations.modes.natural_periods]), with
        waves only; empty otherwise.
    - `stiffness_points`: the points whose stiffness applies (the coupled points, or
        the moving supports); `stiffness`: a
        [`SupportStiffness`][jaxcable._advice.SupportStiffness] for each, where asked
        for and the equilibrium found.
    - `bending`: a [`BendingCheck`][jaxcable._advice.BendingCheck] where the line has
        EI, `None` otherwise.
    """

    omega: float
    eigenvalue: float
    segment: int
    seabed_eigenvalue: float
    seabed_limit: str
    explicit_step: float
    duration: float | None
    steps: int | None
    waves: tuple[WaveFit, ...]
    inertia: tuple[InertiaCheck, ...]
    fluid_inertia: bool
    discretisation: tuple[Discretisation, ...]
    rest_min_tension: float | None
    rest_max_tension: float | None
    slack: tuple[SlackCheck, ...]
    statics_error: str | None
    natural_periods: tuple[float, ...] = ()
    stiffness_points: tuple[str, ...] = ()
    stiffness: tuple[SupportStiffness, ...] = ()
    bending: BendingCheck | None = None

    @property
    def drag_dominates(self) -> bool | None:
        """Whether drag dominates on every element in every wave (`None` without waves)."""
        if not self.inertia:
            return None
        return bool(all(check.regime == "drag" for check in self.inertia))

    @property
    def slack_expected(self) -> bool | None:
        """Whether any extreme of any moving support slackens a line quasi-statically
        (`None` without moving supports or without an equilibrium)."""
        if not self.slack:
            return None
        return bool(any(check.slack for check in self.slack))

    @property
    def snap_possible(self) -> bool | None:
        """Whether a support moves faster than a line it holds can fall sideways."""
        checks = [c for c in self.slack if np.isfinite(c.terminal_speed)]
        if not checks:
            return None
        return bool(any(c.speed > c.terminal_speed for c in checks))


# --------------------------------------------------------------------------------------
# The criteria, one at a time


def wave_fit(wave: AbstractWave, index: int = 0) -> WaveFit:
    """The [`WaveFit`][jaxcable._advice.WaveFit] of `wave` (module docstring)."""
    height, period, depth = float(wave.height), float(wave.period), float(wave.depth)
    length = float(wave.wavelength)
    ursell = height * length**2 / depth**3
    relative = depth / length
    regime = (
        "deep" if relative > DEEP_RELATIVE_DEPTH else "shallow" if relative < SHALLOW_RELATIVE_DEPTH else "intermediate"
    )
    # A breaking wave never gets here: the waves refuse heights past the breaking limit
    # (`jaxcable._sea.waves.breaking_height`).
    if ursell < URSELL_LIMIT:
        fits = "airy"
        reason = (
            "U < 8π²/3 ≈ 26, where Stokes' second harmonic stays below a quarter of the first: linear or "
            "Stokes theory, and Airy is jaxcable's"
        )
    elif relative < CNOIDAL_RELATIVE_DEPTH:
        fits = "cnoidal"
        reason = "U > 26 and λ > 8d: long waves, cnoidal theory (Fenton 1999)"
    else:
        fits = "none"
        reason = (
            "U > 26 but λ < 8d: a higher-order Stokes or stream-function wave fits, which jaxcable does not have; "
            "Airy understates the crest's kinematics, and cnoidal's long-wave approximation is weak"
        )
    irregular = isinstance(wave, WaveComponents)
    kinds = ((Cnoidal, "cnoidal"), (Airy, "airy"), (WaveComponents, "airy"))
    theory = next((name for kind, name in kinds if isinstance(wave, kind)), type(wave).__name__)
    return WaveFit(
        index,
        theory,
        height,
        period,
        length,
        depth,
        ursell,
        relative,
        height / depth,
        height / length,
        regime,
        fits,
        reason,
        irregular,
        repeat_period(wave) if irregular else float("inf"),
    )


def resonant_amplification(natural_period: float, period: float) -> float:
    """1/|1 − (T_n/T)²|: how much an undamped linear oscillator of natural period T_n
    (s) amplifies a force of period T (s) over its static response."""
    return 1.0 / abs(1.0 - (natural_period / period) ** 2)


def particle_speed(wave: AbstractWave, position, samples: int = 720) -> float:
    """The water's largest speed (m/s) over one period at `position` (m): for an Airy
    wave, its horizontal amplitude (H/2) ω cosh k(z + d) / sinh kd."""
    times = jnp.arange(samples) * (wave.period / samples)
    position = jnp.asarray(position, dtype=float)
    velocities = jax.vmap(lambda t: wave.velocity(position, t))(times)
    return float(jnp.max(jnp.linalg.norm(velocities, axis=-1)))


def inertia_ratio(volume: float, added_mass: float, drag_area: float, speed: float, period: float) -> float:
    """r = 4π V (1 + C_a) / (C_D A u T): the peak of Morison's inertia force (Froude–
    Krylov plus added mass) over the peak of its drag force, in sinusoidal flow of speed
    amplitude `speed` u and `period` T, on an element of displaced `volume` V, added
    mass coefficient C_a and `drag_area` C_D A (per unit length for a line: V = F and
    C_D A = K_n d)."""
    if drag_area <= 0 or speed <= 0:
        return float("inf")
    return 4 * np.pi * volume * (1 + added_mass) / (drag_area * speed * period)


def polyline_curvature(positions) -> np.ndarray:
    """The curvature (1/m) at each interior point of a polyline, shape `(points − 2,)`:
    the turning angle between its two segments over their mean length."""
    x = np.asarray(positions, dtype=float)
    chords = np.diff(x, axis=0)
    lengths = np.linalg.norm(chords, axis=1)
    a, b = chords[:-1], chords[1:]
    angle = np.arctan2(np.linalg.norm(np.cross(a, b), axis=1), np.sum(a * b, axis=1))
    return angle / (0.5 * (lengths[:-1] + lengths[1:]))


def segments_needed(length: float, curvature: float, tolerance: float) -> int:
    """The least N with √2/8 · (L/N)² · κ ≤ `tolerance` (m), for a line of `length` L (m)
    and largest `curvature` κ (1/m); at least 1."""
    if curvature <= 0:
        return 1
    return max(1, int(np.ceil(length * np.sqrt(np.sqrt(2) * curvature / (8 * tolerance)) - 1e-9)))


def terminal_speed(
    mass_per_length: float, area: float, diameter: float, normal_drag: float, density: float, gravity: float
) -> float:
    """√(2 w / (ρ K_n d)) (m/s): how fast a line of wet weight w = (m − ρF) g per length
    falls sideways through still water; NaN for a buoyant or weightless line."""
    w = (mass_per_length - density * area) * gravity
    if w <= 0 or normal_drag <= 0:
        return float("nan")
    return float(np.sqrt(2 * w / (density * normal_drag * diameter)))


# --------------------------------------------------------------------------------------
# All together


def advise(
    model,
    env: Environment | None = None,
    *,
    duration: float | None = None,
    tolerance: float = DEFAULT_TOLERANCE,
    absolute_tolerance: float | None = None,
    labels: Labels | None = None,
    stiffness: bool = False,
    statics: bool = True,
) -> Advice:
    """Advice on a model before running it (module docstring): wave theory, drag
    against fluid inertia, segment counts, slack, the explicit step, and where asked
    for the coupled points' stiffness.

    **Arguments:**

    - `model`, `env`: the network and the water; or a built scene alone
        ([`jaxcable.io.BuiltScene`][]: anything with `model`, `environment` and
        `labels`), whose lines, line types and points then name the advice's items.
    - `duration`: (s) the run's length, for a count of explicit steps.
    - `tolerance`: the polyline's allowed deviation from the lines' smooth shape, as a
        fraction of each line's length; 1 % by default.
    - `absolute_tolerance`: the same in metres, if tighter.
    - `labels`: the names of the lines, line types and points (a built scene's own by
        default); without them, lines are the chains between supports, bodies and
        junctions, numbered from 1.
    - `stiffness`: also the stiffness of each coupled point (the scene's; without
        labels, each moving support) at the mean equilibrium. The statics are then
        solved by [`jaxcable.stiffness`][]'s program, which compiles for longer.
    - `statics`: whether to solve the mean equilibrium (default). Without it the
        advice is what the model alone gives (the modes, the step, the waves, drag
        against inertia), as where statics find no equilibrium: a quick answer where
        statics take long.

    **Returns:**

    An [`Advice`][jaxcable._advice.Advice]; [`jaxcable.io.advice_lines`][] says it in words.
    """
    model, env, labels = unpack(model, env, labels)
    omega, magnitude, segment = stiffest_axial_mode(model, env)

    chains = _chains(model, labels)
    still = env.without_waves()
    held = _held(model)
    supports = _coupled(model, labels)
    static = matrix = None
    if statics and stiffness and supports:
        # One solve for the equilibrium and its stiffness together.
        matrix, static, _ = stiffness_and_statics(held, still, 0.0, None, MAX_STEPS, FORCE_TOLERANCE)
    elif statics:
        static = solve_statics(held, still, throw=False)
    statics_error = None
    if static is None:
        statics_error = "statics were not solved"
    elif static.result != optx.RESULTS.successful:
        statics_error = f"the largest force left on a free node is {float(static.residual):.3g} N"
    solved = static if statics_error is None else None  # the mean equilibrium, where found
    positions = np.asarray(model.node_positions if solved is None else solved.state.positions)

    bed, limit = seabed_mode(model, env, seabed_reach(model, env, duration))
    step = STABLE_STEP / max(magnitude, bed, float(bending_modes(model, env).max()))
    steps = None if duration is None else int(np.ceil(duration / step))

    waves = tuple(wave_fit(wave, k) for k, wave in enumerate(env.waves))
    inertia = _inertia(model, env, labels, chains, positions)
    discretisation, slack, stiffnesses = (), (), ()
    rest_min = rest_max = None
    if solved is not None:
        if stiffness and supports:
            rows = np.searchsorted(np.asarray(model.constrained_nodes), supports)
            blocks = np.asarray(matrix)[rows, :, rows, :]
            stiffnesses = tuple(
                SupportStiffness(_point_name(labels, node), node, tuple(map(tuple, block.tolist())))
                for node, block in zip(supports, blocks)
            )
        discretisation = tuple(
            _discretisation(name, nodes, segments, model, positions, tolerance, absolute_tolerance)
            for name, nodes, segments in chains
        )
        tension = np.asarray(solved.tension)
        rest_min, rest_max = float(tension.min()), float(tension.max())
        slack = _slack(model, held, still, labels, chains, solved, rest_max)
    bending = _bending_check(model, env, None if solved is None else np.asarray(solved.tension))
    # The modes matter only to waves, and cost a Jacobian's compile: not without them.
    periods = natural_periods(held, still, positions) if env.waves and solved is not None else np.zeros(0)
    return Advice(
        omega,
        magnitude,
        segment,
        bed,
        limit,
        step,
        duration,
        steps,
        waves,
        inertia,
        env.fluid_inertia,
        discretisation,
        rest_min,
        rest_max,
        slack,
        statics_error,
        tuple(float(p) for p in periods),
        tuple(_point_name(labels, node) for node in supports),
        stiffnesses,
        bending,
    )


def _coupled(model: CableNetwork, labels: Labels | None) -> list[int]:
    """The nodes whose stiffness the advice reports: a scene's coupled points, or
    without its names every support that moves."""
    if labels is not None:
        return sorted(labels.coupled)
    moving = [not isinstance(motion, Fixed) for motion in model.motions]
    return [int(k) for k, moves in zip(np.asarray(model.constrained_nodes), moving) if moves]


def _point_name(labels: Labels | None, node: int) -> str:
    return labels.points[node] if labels is not None and node < len(labels.points) else str(node)


def _held(model: CableNetwork) -> CableNetwork:
    """The model with every support held at its reference position."""
    return eqx.tree_at(lambda m: m.motions, model, tuple(Fixed() for _ in model.motions))


def _chains(model: CableNetwork, labels: Labels | None) -> list[tuple[str, np.ndarray, np.ndarray]]:
    """`(name, nodes, segments)` of each line, from end A to end B: a scene's lines, or
    the chains of the graph between nodes that are not plain interior nodes (supports,
    bodies, junctions, ends)."""
    if labels is not None:
        return [(name, np.asarray(n), np.asarray(s)) for name, n, s in labels.lines]
    edges = np.asarray(model.segment_nodes)
    n_nodes = model.n_nodes
    incident = [[] for _ in range(n_nodes)]
    for s, (a, b) in enumerate(edges):
        incident[a].append(s)
        incident[b].append(s)
    body = model.body
    carries = np.zeros(n_nodes, bool) if body is None else (np.asarray(body.volume) != 0) | (np.asarray(body.mass) != 0)
    stops = {int(k) for k in np.asarray(model.constrained_nodes)}
    stops |= {k for k in range(n_nodes) if len(incident[k]) != 2 or carries[k]}
    seen, chains = set(), []
    starts = sorted(stops) or [int(edges[0, 0])]  # a closed loop of plain nodes starts anywhere
    for start in starts:
        for first in incident[start]:
            if first in seen:
                continue
            nodes, segments, node, s = [start], [], start, first
            while True:
                seen.add(s)
                segments.append(s)
                a, b = edges[s]
                node = int(b if a == node else a)
                nodes.append(node)
                if node in stops or node == start:
                    break
                s = next(t for t in incident[node] if t != s)
            chains.append((f"{len(chains) + 1}", np.array(nodes), np.array(segments)))
    return chains


def _discretisation(name, nodes, segments, model, positions, tolerance, absolute_tolerance) -> Discretisation:
    length = float(np.sum(np.asarray(model.segment_length)[segments]))
    n = len(segments)
    allowed = tolerance * length if absolute_tolerance is None else min(tolerance * length, absolute_tolerance)
    curvature = polyline_curvature(positions[nodes]) if n > 1 else np.zeros(0)
    k = int(np.argmax(curvature)) if curvature.size else -1
    kappa = float(curvature[k]) if curvature.size else 0.0
    deviation = np.sqrt(2) / 8 * (length / n) ** 2 * kappa
    return Discretisation(
        name,
        length,
        n,
        kappa,
        int(nodes[k + 1]) if k >= 0 else -1,
        deviation,
        allowed,
        segments_needed(length, kappa, allowed),
    )


def _inertia(model, env, labels, chains, positions) -> tuple[InertiaCheck, ...]:
    """KC and the inertia ratio for each kind of line and each body, in each wave."""
    if not env.waves:
        return ()
    line = model.line
    rho = float(env.water_density)
    fields = {
        name: np.asarray(getattr(line, name)) for name in ("diameter", "area", "normal_drag", "normal_added_mass")
    }
    groups: dict[str, list[int]] = {}  # element name → its segments
    if labels is not None:
        for line_type, (_, _, segments) in zip(labels.line_types, chains):
            groups.setdefault(f"line type {line_type}", []).extend(segments.tolist())
    else:
        keys = {}
        for s in range(model.n_segments):
            key = tuple(float(fields[f][s]) for f in fields)
            keys.setdefault(key, []).append(s)
        for (d, *_), segments in keys.items():
            groups[f"segments of d = {d:.4g} m"] = segments
    edges = np.asarray(model.segment_nodes)
    elements = []
    for name, segments in groups.items():
        s = segments[0]
        nodes = np.unique(edges[segments])
        top = nodes[np.argmax(positions[nodes, 2])]
        elements.append(
            (
                name,
                positions[top],
                fields["diameter"][s],
                fields["area"][s],
                fields["normal_added_mass"][s],
                fields["normal_drag"][s] * fields["diameter"][s],
            )
        )
    body = model.body
    volume = np.asarray(body.volume)
    for k in np.flatnonzero(volume > 0):
        name = (
            f"body at point {labels.points[k]}"
            if labels is not None and k < len(labels.points)
            else f"body at node {k}"
        )
        drag_area = (
            float(body.drag_area[k])
            + 2 * float(body.specific_drag[k] * body.organism_mass[k]) * float(env.gravity) / rho
        )
        elements.append(
            (name, positions[k], (6 * volume[k] / np.pi) ** (1 / 3), volume[k], float(body.added_mass[k]), drag_area)
        )
    checks = []
    for w, wave in enumerate(env.waves):
        period = float(wave.period)
        for name, position, diameter, v, added, drag_area in elements:
            speed = particle_speed(wave, position)
            checks.append(
                InertiaCheck(
                    name,
                    w,
                    period,
                    float(min(position[2], 0.0)),
                    speed,
                    float(diameter),
                    speed * period / diameter,
                    inertia_ratio(float(v), float(added), float(drag_area), speed, period),
                )
            )
    return tuple(checks)


def _extremes(motion) -> list[np.ndarray]:
    """The displacements (m) at the extremes of a support's motion: a harmonic one's
    ±A e, a table's samples furthest apart along its largest excursion."""
    if isinstance(motion, Harmonic):
        shift = float(motion.amplitude) * np.asarray(motion.direction)
        return [shift, -shift] if float(motion.amplitude) else []
    if isinstance(motion, Sampled):
        samples = np.asarray(motion.displacements)
        largest = samples[np.argmax(np.linalg.norm(samples, axis=1))]
        if not np.any(largest):
            return []
        along = samples @ largest
        return [samples[np.argmax(along)], samples[np.argmin(along)]]
    return []


def _peak_speed(motion) -> float:
    if isinstance(motion, Harmonic):
        return abs(float(motion.amplitude)) * 2 * np.pi / float(motion.period)
    if isinstance(motion, Sampled):
        times = np.asarray(motion.times)
        t = np.linspace(times[0], times[-1], 20 * times.size)
        velocity = jax.vmap(lambda s: motion.kinematics(s)[1])(jnp.asarray(t))
        return float(jnp.max(jnp.linalg.norm(velocity, axis=-1)))
    return 0.0


def _slack(model, held, still, labels, chains, static, rest_max) -> tuple[SlackCheck, ...]:
    line = model.line
    rho, g = float(still.water_density), float(still.gravity)
    edges = np.asarray(model.segment_nodes)
    segment_line = np.empty(model.n_segments, dtype=object)
    for name, _, segments in chains:
        segment_line[segments] = name
    checks = []
    for node, motion in zip(np.asarray(model.constrained_nodes), model.motions):
        node = int(node)
        extremes = _extremes(motion)
        if not extremes:
            continue
        name = _point_name(labels, node)
        attached = np.flatnonzero((edges[:, 0] == node) | (edges[:, 1] == node))

        def value(field, s):
            return float(np.asarray(getattr(line, field))[s])

        speeds = [
            terminal_speed(
                value("mass_per_length", s), value("area", s), value("diameter", s), value("normal_drag", s), rho, g
            )
            for s in attached
        ]
        speeds = [v for v in speeds if np.isfinite(v)]
        fall = min(speeds) if speeds else float("nan")
        share = _harmonic_share(model, node)
        for shift in extremes:
            moved = eqx.tree_at(lambda m: m.node_positions, held, held.node_positions.at[node].add(shift))
            # The rest at equilibrium, each free node moved by its share of the shift:
            # a start near the new equilibrium (on a catenary, a third of the
            # iterations that moving the support alone takes).
            start = static.state.positions + jnp.asarray(share[:, None] * shift)
            solution = solve_statics(moved, still, initial=State(start, jnp.zeros_like(start)), throw=False)
            converged = bool(solution.result == optx.RESULTS.successful)
            tension = np.asarray(solution.tension)
            s = int(np.argmin(tension))
            slack = not converged or bool(tension[s] < SLACK_FRACTION * rest_max)
            checks.append(
                SlackCheck(
                    name,
                    node,
                    (float(shift[0]) + 0.0, float(shift[1]) + 0.0, float(shift[2]) + 0.0),
                    converged,
                    float(tension[s]) if converged else float("nan"),
                    str(segment_line[s]),
                    s,
                    slack,
                    _peak_speed(motion),
                    fall,
                )
            )
    return tuple(checks)


def _harmonic_share(model: CableNetwork, node: int) -> np.ndarray:
    """φ on the nodes: 1 at `node`, 0 at the other supports, and on each free node the
    mean of its neighbours' (the graph's discrete harmonic function), by lineax's
    conjugate gradients on the graph Laplacian of the free nodes (positive definite:
    every part of the network is held)."""
    edges = np.asarray(model.segment_nodes)
    n = model.n_nodes
    free = np.sort(np.asarray(model.free_nodes))
    phi = np.zeros(n)
    phi[node] = 1.0
    if free.size == 0:
        return phi

    def laplacian(x):  # L x on every node
        difference = x[edges[:, 0]] - x[edges[:, 1]]
        return jnp.zeros(n, x.dtype).at[edges[:, 0]].add(difference).at[edges[:, 1]].add(-difference)

    def on_free(y):  # L restricted to the free nodes
        return laplacian(jnp.zeros(n, y.dtype).at[free].set(y))[free]

    b = -laplacian(jnp.asarray(phi))[free]
    operator = lx.FunctionLinearOperator(on_free, jax.ShapeDtypeStruct(b.shape, b.dtype), lx.positive_semidefinite_tag)
    # The residual to 1e-12 of φ's scale (1), as the hand-written loop this replaces; its
    # 4 n steps are a bound, not reached on a held network.
    solver = lx.CG(rtol=1e-12, atol=1e-12, max_steps=4 * n)
    phi[free] = np.asarray(lx.linear_solve(operator, b, solver, throw=False).value)
    return phi
