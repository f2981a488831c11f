"""Scenes: a cable system described as data, as read from a scene or MoorDyn file.

A [`jaxcable.io.Scene`][] is the description a file gives: named points, line types and
lines, the water, run settings and output channels. It holds plain Python numbers and
says where in its file each item came from, so that a bad value is reported against
the line that wrote it. [`jaxcable.io.Scene.build`][] turns it into the engine's
[`jaxcable.CableNetwork`][] and [`jaxcable.Environment`][]; readers
([`jaxcable.read_scene`][], [`jaxcable.read_moordyn`][]) and the command line only ever
produce and consume scenes.

This module is plain Python and numpy: each method that makes an engine object imports
the engine itself, so that a file is read and checked without JAX (`ParsedScene`), and
the command line refuses a malformed one before it imports JAX (1.3 s).
"""

import dataclasses
import warnings
from collections.abc import Callable
from dataclasses import dataclass, field
from typing import TYPE_CHECKING, Any, NamedTuple

import numpy as np

if TYPE_CHECKING:
    from .._advice import Labels
    from .._model.motion import AbstractMotion
    from .._model.network import Body, CableNetwork, LineType
    from .._sea.environment import CurrentProfile, Environment, Seabed
    from .._sea.irregular import WaveComponents
    from .._sea.spectrum import Jonswap
    from .._sea.waves import AbstractWave
    from .._solver.config import SolverConfig

POINT_KINDS = ("fixed", "coupled", "free")
WAVE_THEORIES = ("airy", "cnoidal")
SPECTRA = ("jonswap", "pierson-moskowitz")
START_SPEED = 1e-3
"""The speed (m/s) above which a motion table that starts moving is warned of: a support
set moving at once at t = 0 loads the line as a jolt would (OC4's platform with a 2 m
surge: a 1,634 kN peak at 0.8 s against 1,091 kN held)."""


class SceneError(ValueError):
    """An input that cannot be read as a scene. The message names the file, the line
    (where known) and the key or column at fault."""


@dataclass(frozen=True)
class CurrentProfileSpec:
    """A current whose speed varies over depth ([`jaxcable.CurrentProfile`][]): `speeds`
    (m/s) at `heights` z (m, increasing; z = 0 is the still-water level), flowing
    towards `heading` (degrees, from +x towards +y)."""

    heights: tuple[float, ...]
    speeds: tuple[float, ...]
    heading: float = 0.0
    where: str = ""

    def profile(self) -> "CurrentProfile":
        """The engine's [`jaxcable.CurrentProfile`][]."""
        from .._sea.environment import CurrentProfile

        with located(self.where):
            return CurrentProfile(self.heights, self.speeds, self.heading)


@dataclass(frozen=True)
class WaveSpec:
    """A regular wave, resolved against the water's depth and gravity when the scene is
    built.

    - `theory`: `"airy"` ([`jaxcable.Airy`][]) or `"cnoidal"` ([`jaxcable.Cnoidal`][]).
    - `period`: T (s).
    - `height`: H (m), crest to trough; or `steepness` H/λ (–): exactly one of them.
    - `heading`: β (degrees), the direction of travel from +x towards +y.
    - `phase`: θ₀ (rad); 0 puts a crest at x_β = 0 at t = 0.
    - `wheeler`: Wheeler stretching (Airy only).
    """

    theory: str
    period: float
    height: float | None = None
    steepness: float | None = None
    heading: float = 0.0
    phase: float = 0.0
    wheeler: bool = False
    where: str = ""

    def wave(self, depth: float, gravity: float) -> "AbstractWave":
        """The engine's wave in water of `depth` (m) under `gravity` (m/s²).

        **Raises:**

        [`jaxcable.io.SceneError`][] at `where` for an unknown theory, neither or both of
        height and steepness, Wheeler stretching on a cnoidal wave, or a value the wave
        rejects (non-positive, breaking, a period too short for a cnoidal wave).
        """
        if self.theory not in WAVE_THEORIES:
            raise SceneError(f"{self.where}: unknown wave theory {self.theory!r}; expected one of {WAVE_THEORIES}")
        if (self.height is None) == (self.steepness is None):
            raise SceneError(f"{self.where}: give exactly one of height and steepness")
        if self.wheeler and self.theory != "airy":
            raise SceneError(f"{self.where}: Wheeler stretching applies to Airy waves only")
        from .._sea.cnoidal import Cnoidal
        from .._sea.waves import Airy

        kinds = {"airy": Airy, "cnoidal": Cnoidal}
        kind = kinds[self.theory]
        options = {"gravity": gravity, "heading": self.heading, "phase": self.phase}
        if self.theory == "airy":
            options["wheeler"] = self.wheeler
        with located(self.where):
            if self.height is not None:
                return kind(self.height, self.period, depth, **options)
            return kind.from_steepness(self.steepness, self.period, depth, **options)

    def describe(self) -> str:
        """One line for `jaxcable info`."""
        size = f"H = {self.height:g} m" if self.height is not None else f"H/λ = {self.steepness:g}"
        return f"{self.theory}, {size}, T = {self.period:g} s, heading {self.heading:g}°, phase {self.phase:g} rad" + (
            ", Wheeler stretching" if self.wheeler else ""
        )


@dataclass(frozen=True)
class WaveComponentsSpec:
    """An irregular sea as linear components ([`jaxcable.WaveComponents`][]):
    `amplitudes` a_i (m), `periods` T_i (s), `headings` β_i (degrees; one for all, or
    one each), `phases` θ₀_i (rad), and `wheeler` stretching."""

    amplitudes: tuple[float, ...]
    periods: tuple[float, ...]
    headings: float | tuple[float, ...] = 0.0
    phases: float | tuple[float, ...] = 0.0
    wheeler: bool = False
    where: str = ""

    def wave(self, depth: float, gravity: float) -> "AbstractWave":
        """The engine's [`jaxcable.WaveComponents`][] in water of `depth` (m) under
        `gravity` (m/s²); [`jaxcable.io.SceneError`][] at `where` for a value it rejects."""
        from .._sea.irregular import WaveComponents

        with located(self.where):
            return WaveComponents(
                self.amplitudes,
                self.periods,
                depth,
                gravity=gravity,
                headings=self.headings,
                phases=self.phases,
                wheeler=self.wheeler,
            )

    def describe(self) -> str:
        """One line for `jaxcable info`."""
        a, t = np.asarray(self.amplitudes), np.asarray(self.periods)
        peak = int(np.argmax(a))
        return (
            f"{a.size} linear components from {self.where}, H_s = {4 * np.sqrt(0.5 * np.sum(a**2)):.4g} m, "
            f"periods {t.min():.4g} to {t.max():.4g} s, the largest {a[peak]:.4g} m at {t[peak]:.4g} s"
            + (", Wheeler stretching" if self.wheeler else "")
        )


@dataclass(frozen=True)
class SeaStateSpec:
    """An irregular sea realised from a spectrum
    ([`jaxcable.WaveComponents.from_spectrum`][] of a [`jaxcable.Jonswap`][]).

    - `spectrum`: `"jonswap"` or `"pierson-moskowitz"` (JONSWAP at γ = 1).
    - `significant_height` H_s (m), `peak_period` T_p (s), `peak_enhancement` γ (–,
        JONSWAP only).
    - `components`: N; `frequencies`: (ω_min, ω_max) (rad/s); `seed`: the phases'.
    - `heading`: the mean direction of travel (degrees); `spreading`: the cos-2s
        exponent s, or `None` for a long-crested sea.
    - `wheeler`: Wheeler stretching.
    """

    spectrum: str
    significant_height: float
    peak_period: float
    components: int
    frequencies: tuple[float, float]
    seed: int
    peak_enhancement: float = 3.3
    heading: float = 0.0
    spreading: float | None = None
    wheeler: bool = False
    where: str = ""

    def sea_state(self) -> "Jonswap":
        """The engine's [`jaxcable.Jonswap`][]."""
        from .._sea.spectrum import Jonswap

        if self.spectrum not in SPECTRA:
            raise SceneError(f"{self.where}: unknown spectrum {self.spectrum!r}; expected one of {SPECTRA}")
        gamma = 1.0 if self.spectrum == "pierson-moskowitz" else self.peak_enhancement
        with located(self.where):
            return Jonswap(self.significant_height, self.peak_period, gamma)

    def wave(self, depth: float, gravity: float) -> "WaveComponents":
        """The engine's [`jaxcable.WaveComponents`][], realised in water of `depth` (m)
        under `gravity` (m/s²); [`jaxcable.io.SceneError`][] at `where` for a value it
        rejects (a band that misses the spectrum among them)."""
        from .._sea.irregular import WaveComponents

        spectrum = self.sea_state()
        with located(self.where):
            return WaveComponents.from_spectrum(
                spectrum,
                depth,
                seed=self.seed,
                components=self.components,
                frequencies=self.frequencies,
                heading=self.heading,
                spreading=self.spreading,
                gravity=gravity,
                wheeler=self.wheeler,
            )

    def describe(self) -> str:
        """One line for `jaxcable info`."""
        gamma = "" if self.spectrum == "pierson-moskowitz" else f", γ = {self.peak_enhancement:g}"
        low, high = self.frequencies
        spread = "long-crested" if self.spreading is None else f"cos-2s spreading s = {self.spreading:g}"
        return (
            f"{self.spectrum}, H_s = {self.significant_height:g} m, T_p = {self.peak_period:g} s{gamma}, heading "
            f"{self.heading:g}°, {spread}: {self.components} components on {low:g} to {high:g} rad/s, seed "
            f"{self.seed}, repeating after {2 * np.pi * self.components / (high - low):.4g} s"
            + (", Wheeler stretching" if self.wheeler else "")
        )


@dataclass(frozen=True)
class SeabedSpec:
    """A flat seabed at the water's depth ([`jaxcable.Seabed`][]): `stiffness` (Pa/m)
    and `damping` (Pa·s/m) per unit contact area (MoorDyn's `kBot`, `cBot`), the
    Coulomb `friction` coefficient (–) and the `friction_speed` (m/s) below which
    friction is viscous; or, with `friction_damping` (N·s/m), MoorDyn's friction."""

    stiffness: float = 3.0e6
    damping: float = 3.0e5
    friction: float = 0.0
    friction_speed: float = 0.01
    where: str = ""
    friction_damping: float | None = None

    def seabed(self) -> "Seabed":
        """The engine's [`jaxcable.Seabed`][]."""
        from .._sea.environment import Seabed

        with located(self.where):
            return Seabed(self.stiffness, self.damping, self.friction, self.friction_speed, self.friction_damping)


@dataclass(frozen=True)
class Water:
    """The water (see [`jaxcable.Environment`][]).

    - `density` ρ (kg/m³), `gravity` g (m/s²).
    - `depth` (m, positive), or `None` for water without a bottom (allowed only without
        waves and seabed).
    - `current`: a uniform current (m/s, a 3-vector); or `current_profile`, a
        [`jaxcable.io.CurrentProfileSpec`][] (then `current` must stay zero).
    - `free_surface`: whether lines are in the water only below z = 0.
    - `waves`: regular waves, [`jaxcable.io.WaveSpec`][], linear components,
        [`jaxcable.io.WaveComponentsSpec`][], or irregular seas realised from a
        spectrum, [`jaxcable.io.SeaStateSpec`][], superposed.
    - `seabed`: a [`jaxcable.io.SeabedSpec`][] at z = −depth, or `None`.
    - `fluid_inertia`: whether the waves' acceleration loads lines and bodies.
    - `wave_ramp`: the time (s) over which the waves are switched on from t = 0
        ([`jaxcable.Environment`][]'s `wave_ramp`), so that a run from still-water
        statics starts without a jolt; 0 for none.
    - `where`: where in its file the water was described, for errors.
    """

    density: float = 1025.0
    gravity: float = 9.81
    depth: float | None = None
    current: tuple[float, float, float] = (0.0, 0.0, 0.0)
    free_surface: bool = False
    current_profile: CurrentProfileSpec | None = None
    waves: tuple["WaveSpec | WaveComponentsSpec | SeaStateSpec", ...] = ()
    seabed: SeabedSpec | None = None
    fluid_inertia: bool = True
    wave_ramp: float = 0.0
    where: str = ""

    def environment(self) -> "Environment":
        """The engine's [`jaxcable.Environment`][].

        **Raises:**

        [`jaxcable.io.SceneError`][] naming the item's place in the file for waves or a
        seabed without a depth, both a uniform current and a profile, or a value out of
        range.
        """
        from .._sea.environment import Environment

        where = self.where or "[water]"
        for item, what in ((self.waves[0] if self.waves else None, "waves"), (self.seabed, "a seabed")):
            if item is not None and self.depth is None:
                raise SceneError(f"{item.where or where}: {what} need the water depth: give [water] depth")
        if self.current_profile is not None and any(self.current):
            raise SceneError(
                f"{self.current_profile.where or where}: give a uniform current or a current profile, not both"
            )
        current = self.current if self.current_profile is None else self.current_profile.profile()
        with warnings.catch_warnings():
            # A cnoidal wave of low Ursell number warns; the scene reader notes it, and
            # jaxcable info's advice says which theory fits.
            warnings.filterwarnings("ignore", message="Cnoidal wave of Ursell number", category=UserWarning)
            # Waves without a depth were refused above.
            depth = self.depth
            waves = () if depth is None else tuple(wave.wave(depth, self.gravity) for wave in self.waves)
        seabed = None if self.seabed is None else self.seabed.seabed()
        with located(where):
            return Environment(
                self.density,
                self.gravity,
                current,
                self.free_surface,
                depth=self.depth,
                waves=waves,
                seabed=seabed,
                fluid_inertia=self.fluid_inertia,
                wave_ramp=self.wave_ramp,
            )


@dataclass(frozen=True)
class LineTypeSpec:
    """A named cable type, per unit unstretched length.

    Fields are those of [`jaxcable.LineType`][] and its tension law. Axial damping is
    given one of two ways, never both:

    - `axial_damping`: C_v (N·s), the coefficient of the strain rate in the tension
        (MoorDyn's positive `BA`).
    - `axial_damping_ratio`: ζ (–), a fraction of the critical damping of one segment's
        axial mode, C_v = ζ (L/N) √(EA m) as MoorDyn defines it (its negative `BA`). It
        depends on the segment length, so it is resolved when the scene is built.

    `slack_damping` lets the damping act on a slack segment too, as MoorDyn's does (see
    [`jaxcable.KelvinVoigt`][]); the MoorDyn reader sets it, and every line type of a
    scene must agree on it.

    `minimum_breaking_load` (N), optional, is not physics: a run reports each line's
    largest tension over it, the utilisation, and warns past a safety factor
    (`jaxcable.io._extremes`).

    `fatigue_curve`, optional, names a T–N curve of [`jaxcable.TN_CURVES`][]: a run
    reports each line's fatigue damage and life (`jaxcable.io._line_fatigue`). A DNV
    curve (stress ranges) needs `fatigue_area` (m², the nominal area: 2 π d²/4 for chain
    of nominal diameter d, [`jaxcable.chain_area`][]); an API curve (ranges over the
    breaking strength) needs `minimum_breaking_load`.
    """

    name: str
    mass_per_length: float
    diameter: float
    axial_stiffness: float
    quadratic_stiffness: float = 0.0
    axial_damping: float = 0.0
    axial_damping_ratio: float = 0.0
    normal_drag: float = 1.2
    tangential_drag: float = 0.008
    normal_added_mass: float = 1.0
    tangential_added_mass: float = 0.0
    area: float | None = None
    slack_width: float = 1e-5
    slack_damping: bool = False
    bending_stiffness: float = 0.0
    minimum_breaking_load: float | None = None
    fatigue_curve: str | None = None
    fatigue_area: float | None = None
    where: str = ""

    def __post_init__(self):
        mbl = self.minimum_breaking_load
        if mbl is not None and not (np.isfinite(mbl) and mbl > 0):
            raise SceneError(
                f"{self.where or self.name}: minimum_breaking_load must be a positive number of N, got {mbl:g}"
            )
        curve, area = self.fatigue_curve, self.fatigue_area
        if area is not None and not (np.isfinite(area) and area > 0):
            raise SceneError(f"{self.where or self.name}: fatigue_area must be a positive number of m², got {area:g}")
        if curve is None:
            if area is not None:
                raise SceneError(f"{self.where or self.name}: fatigue_area is for a fatigue_curve; give one")
            return
        from .._campaign.fatigue import TN_CURVES  # numpy and rainflow only

        if curve not in TN_CURVES:
            raise SceneError(
                f"{self.where or self.name}: unknown fatigue_curve {curve!r}; jaxcable has {', '.join(TN_CURVES)}"
            )
        stress = TN_CURVES[curve].form == "stress"
        if stress and area is None:
            raise SceneError(
                f"{self.where or self.name}: fatigue_curve {curve} takes stress ranges on the nominal area: give "
                "fatigue_area (m²; 2 π d²/4 for chain of nominal diameter d)"
            )
        if not stress and area is not None:
            raise SceneError(
                f"{self.where or self.name}: fatigue_curve {curve} takes ranges over the minimum breaking load, not "
                f"a stress on an area: drop fatigue_area ({area:g})"
            )

    def fatigue_problem(self) -> str | None:
        """Why this line type's fatigue cannot be computed, or `None`: an API curve
        without a minimum breaking load (which `--breaking-load` may still give)."""
        if self.fatigue_curve is None or self.fatigue_area is not None or self.minimum_breaking_load is not None:
            return None
        return (
            f"{self.where or self.name}: fatigue_curve {self.fatigue_curve} takes tension ranges over the minimum "
            "breaking load: give minimum_breaking_load (or --breaking-load)"
        )

    def damping_coefficient(self, segment_length: float) -> float:
        """C_v (N·s) for segments of unstretched length `segment_length` (m); NaN for a
        damping ratio on a negative stiffness or mass, which the line type then refuses
        by name (numpy's square root would only warn)."""
        product = self.axial_stiffness * self.mass_per_length
        ratio_part = self.axial_damping_ratio * segment_length * (np.sqrt(product) if product >= 0 else np.nan)
        return self.axial_damping + ratio_part

    def line_type(self, segment_length: float) -> "LineType":
        """The engine's [`jaxcable.LineType`][] for segments of `segment_length` (m)."""
        if self.axial_damping and self.axial_damping_ratio:
            raise SceneError(
                f"{self.where}: give one of axial_damping ({self.axial_damping}) or "
                f"axial_damping_ratio ({self.axial_damping_ratio}), not both"
            )
        from .._model.materials import KelvinVoigt
        from .._model.network import LineType

        with located(self.where):
            law = KelvinVoigt(
                self.axial_stiffness,
                self.quadratic_stiffness,
                self.damping_coefficient(segment_length),
                self.slack_width,
                self.slack_damping,
            )
            return LineType(
                mass_per_length=self.mass_per_length,
                diameter=self.diameter,
                tension_law=law,
                area=self.area,
                normal_drag=self.normal_drag,
                tangential_drag=self.tangential_drag,
                normal_added_mass=self.normal_added_mass,
                tangential_added_mass=self.tangential_added_mass,
                bending_stiffness=self.bending_stiffness,
            )


@dataclass(frozen=True)
class PointSpec:
    """A named point: a line end or a junction.

    - `kind`: `"fixed"` (an anchor), `"coupled"` (driven by `motion`; held where it is
        until a motion is given) or `"free"`.
    - `position`: (m); for a coupled point, the position its motion is measured from.
    - `body`: a [`jaxcable.Body`][] at the point, or `None`.
    - `motion`: a [`jaxcable.AbstractMotion`][] for a coupled point.
    """

    name: str
    kind: str
    position: tuple[float, float, float]
    body: "Body | None" = None
    motion: "AbstractMotion | None" = None
    where: str = ""


@dataclass(frozen=True)
class LineSpec:
    """A line of type `line_type` from point index `start` (end A) to `end` (end B),
    `length` (m) unstretched, divided into `segments` equal segments."""

    name: str
    line_type: str
    start: int
    end: int
    length: float
    segments: int
    where: str = ""


@dataclass(frozen=True)
class RunSettings:
    """How to run a scene: `duration` (s), the output interval `dt_out` (s; `None` for
    0.1 s), the `solver` (`"auto"`, the default, or a name in [`jaxcable.SOLVERS`][]),
    its tolerances, a fixed step `dt` (s; `None` to step adaptively, or for `"auto"` at
    the step it chooses), the most steps
    `max_steps`, the `mass_matrix` (`"consistent"` or `"lumped"`), the
    `hydrodynamics` (`"segments"`, or MoorDyn's `"nodes"`; see
    [`jaxcable.CableNetwork`][]), and whether to solve
    `statics` first (otherwise the run starts from the file's geometry at rest, as
    MoorDyn's with `TmaxIC = 0`). Plain data, as a scene file holds it;
    `solver_config()` makes the [`jaxcable.SolverConfig`][] that runs it."""

    duration: float = 60.0
    dt_out: float | None = None
    solver: str = "auto"
    rtol: float = 1e-6
    atol: float = 1e-6
    dt: float | None = None
    max_steps: int = 1_000_000
    mass_matrix: str = "consistent"
    hydrodynamics: str = "segments"
    statics: bool = True

    def solver_config(self, built: "BuiltScene | None" = None, duration: float | None = None) -> "SolverConfig":
        """`SOLVERS[solver](rtol=rtol, atol=atol, max_steps=max_steps)`, or with `dt`
        fixed steps of `dt` (`dt0=dt`, `diffrax.ConstantStepSize()`; the tolerances
        unused); `ValueError` naming the solver and the choices for an unknown name.

        `"auto"` is RK4 at fixed steps: of `dt` where given, else of 0.7 of RK4's
        stability limit at the fastest modes of the `built` scene over a run of
        `duration` (s) ([`jaxcable.fixed_steps`][]); without a scene, RK4 with no step
        (what the checks of a scene's options need)."""
        import diffrax

        from .._names import AUTO
        from .._solver.config import SOLVERS

        name = "rk4" if self.solver == AUTO else self.solver
        if self.solver == AUTO and self.dt is None:
            if built is None:
                return SOLVERS[name](max_steps=self.max_steps)
            from .._solver.stability import fixed_steps

            return fixed_steps([(built.model, built.environment)], duration, max_steps=self.max_steps)
        if self.dt is not None:
            return SOLVERS[name](dt0=self.dt, stepsize_controller=diffrax.ConstantStepSize(), max_steps=self.max_steps)
        return SOLVERS[name](rtol=self.rtol, atol=self.atol, max_steps=self.max_steps)


@dataclass(frozen=True)
class Scene:
    """A cable system as a file describes it. See the module docstring.

    - `points`, `line_types`, `lines`: the network. Lines refer to points by index and
        to line types by name.
    - `water`, `run`: the environment and run settings.
    - `channels`: output channels requested by the file (MoorDyn names, such as
        `FairTen1` or `L1N3PZ`); empty for the default set.
    - `notes`: what the reader ignored or assumed, for the user to read.
    - `dropped`: the physics the file asks for that jaxcable leaves out, as `(kind,
        note)` with kind one of `jaxcable.io._moordyn.DROPPED_KINDS` (`"EI"`,
        `"waves"`, ...); their notes are among `notes` too.
    - `source`: the file it came from.
    - `title`: a one-line description, for listings and figures.
    """

    points: tuple[PointSpec, ...]
    line_types: tuple[LineTypeSpec, ...]
    lines: tuple[LineSpec, ...]
    water: Water = Water()
    run: RunSettings = RunSettings()
    channels: tuple[str, ...] = ()
    notes: tuple[str, ...] = ()
    source: str = "<scene>"
    title: str = ""
    dropped: tuple[tuple[str, str], ...] = ()

    def __post_init__(self):
        names = [t.name for t in self.line_types]
        for line in self.lines:
            if line.line_type not in names:
                raise SceneError(f"{line.where}: unknown line type {line.line_type!r}; defined: {names}")
            for end in ("start", "end"):
                k = getattr(line, end)
                if not 0 <= k < len(self.points):
                    raise SceneError(f"{line.where}: {end} point {k} does not exist")
            if line.start == line.end:
                raise SceneError(f"{line.where}: line {line.name} joins point {self.points[line.start].name} to itself")
        for point in self.points:
            if point.kind not in POINT_KINDS:
                raise SceneError(f"{point.where}: unknown point type {point.kind!r}; expected one of {POINT_KINDS}")
        if not self.lines:
            raise SceneError(f"{self.source}: the scene has no lines")

    @property
    def coupled_points(self) -> tuple[int, ...]:
        """Indices of the coupled points, in file order (the order of a motion table)."""
        return tuple(i for i, p in enumerate(self.points) if p.kind == "coupled")

    def replace(self, **changes) -> "Scene":
        """A copy with some fields replaced."""
        return dataclasses.replace(self, **changes)

    def with_segments(self, segments: int) -> "Scene":
        """A copy with every line divided into `segments` segments."""
        if not (isinstance(segments, int) and segments >= 1):
            raise SceneError(f"segments must be a positive integer, got {segments!r}")
        return self.replace(lines=tuple(dataclasses.replace(line, segments=segments) for line in self.lines))

    def _by_line_type(self, values: dict, where: str) -> list[tuple["LineTypeSpec", Any]]:
        """Each line type with its entry of `values` (by line type name; the key `None`
        for every type not named; `None` where neither is given), after refusing a name
        the scene does not define, naming `where`."""
        names = [t.name for t in self.line_types]
        for name in values:
            if name is not None and name not in names:
                raise SceneError(f"{where}: the scene has no line type {name!r}; its line types: {', '.join(names)}")
        return [(t, values.get(t.name, values.get(None))) for t in self.line_types]

    def with_breaking_loads(self, loads: dict[str | None, float], where: str = "breaking loads") -> "Scene":
        """A copy whose line types have these minimum breaking loads (N), by line type
        name; the key `None` gives every line type not named its load.

        **Raises:**

        [`jaxcable.io.SceneError`][], naming `where`, for a line type the scene does not
        define or a load that is not a positive number."""
        line_types = []
        for t, load in self._by_line_type(loads, where):
            if load is not None:
                if not (np.isfinite(load) and load > 0):
                    raise SceneError(
                        f"{where}: the minimum breaking load of {t.name} must be a positive number of N, got {load:g}"
                    )
                t = dataclasses.replace(t, minimum_breaking_load=float(load))
            line_types.append(t)
        return self.replace(line_types=tuple(line_types))

    def with_fatigue_curves(
        self, curves: dict[str | None, tuple[str, float | None]], where: str = "fatigue curves"
    ) -> "Scene":
        """A copy whose line types have these T–N curves, by line type name: each a
        `(curve name, nominal area in m² or None)`; the key `None` gives every line type
        not named its curve.

        **Raises:**

        [`jaxcable.io.SceneError`][], naming `where`, for a line type the scene does not
        define, or a curve or area that `LineTypeSpec` refuses."""
        line_types = []
        for t, given in self._by_line_type(curves, where):
            if given is not None:
                # Checked under the flag's name, kept under the file's.
                checked = dataclasses.replace(
                    t, fatigue_curve=given[0], fatigue_area=given[1], where=f"{where}, line type {t.name}"
                )
                t = dataclasses.replace(checked, where=t.where)
            line_types.append(t)
        return self.replace(line_types=tuple(line_types))

    def with_motion_table(
        self,
        times: np.ndarray,
        positions: np.ndarray,
        where: str = "motion table",
        interpolation: str = "cubic",
        ramp: float = 0.0,
    ) -> "Scene":
        """A copy whose coupled points follow a table of absolute positions.

        **Arguments:**

        - `times`: (s), shape `(samples,)`, strictly increasing.
        - `positions`: (m), shape `(samples, coupled, 3)`, for the coupled points in
            file order. Each is interpolated about the point's position in the scene
            ([`jaxcable.Sampled`][]).
        - `where`: the table's name in messages.
        - `interpolation`: `"cubic"` (natural spline), `"pchip"` (monotone) or `"linear"`.
        - `ramp`: the time (s) over which the motion is switched on smoothly (0: none).

        Warns (a `UserWarning`) where a table starts moving faster than
        `START_SPEED` (m/s) without a ramp: the support would jolt the line at t = 0.
        """
        coupled = self.coupled_points
        if positions.shape[1:] != (len(coupled), 3):
            raise SceneError(
                f"{where}: expected positions for {len(coupled)} coupled point(s), got shape {positions.shape[1:]}"
            )
        from .._model.motion import Sampled

        points = list(self.points)
        for column, k in enumerate(coupled):
            displacements = positions[:, column, :] - np.asarray(points[k].position)
            with located(f"{where}, point {points[k].name}"):
                motion = Sampled(times, displacements, interpolation, ramp)
            speed = float(np.linalg.norm(motion.start_velocity()))
            if ramp == 0 and speed > START_SPEED:
                warnings.warn(
                    f"{where}, point {points[k].name}: the table starts moving at {speed:.3g} m/s, which jolts the "
                    "line at t = 0 (its snap load is the table's, not the sea's); a ramp (--ramp S, or "
                    "with_motion_table(..., ramp=S)) starts the motion smoothly over S seconds",
                    stacklevel=2,
                )
            points[k] = dataclasses.replace(points[k], motion=motion)
        return self.replace(points=tuple(points))

    def build(self) -> "BuiltScene":
        """The engine's model and environment for this scene.

        **Raises:**

        [`jaxcable.io.SceneError`][] naming the item's place in the file when a value is
        out of range, or a fixed or coupled point is below the seabed.
        """
        from .._model.motion import Fixed
        from .._model.network import Branch, CableNetwork, below_seabed

        for line in self.lines:
            if not line.length > 0:
                raise SceneError(f"{line.where}: length must be positive, got {line.length}")
            if not (isinstance(line.segments, int) and line.segments >= 1):
                raise SceneError(f"{line.where}: segments must be a positive integer, got {line.segments!r}")
            _check_reach(line, self.points[line.start], self.points[line.end])
        types = {t.name: t for t in self.line_types}
        branches = [
            Branch(
                line.start,
                line.end,
                types[line.line_type].line_type(line.length / line.segments),
                line.length,
                line.segments,
            )
            for line in self.lines
        ]
        constraints = {
            k: (p.motion if p.motion is not None else Fixed()) for k, p in enumerate(self.points) if p.kind != "free"
        }
        bodies = {k: p.body for k, p in enumerate(self.points) if p.body is not None}
        environment = self.water.environment()
        depth = self.water.depth
        if self.water.seabed is not None and depth is not None:
            for point in self.points:
                if point.kind != "free" and below_seabed(np.asarray(point.position[2]), np.asarray(depth)):
                    raise SceneError(
                        f"{point.where}: {point.kind} point {point.name} at z = {point.position[2]:g} m is below the "
                        f"seabed at z = {-depth:g} m ([water] depth = {depth:g} m); the bed's penalty spring would "
                        "pull the line's nodes up out of it: raise the point to the bed or deepen the water"
                    )
        with located(self.source):
            model = CableNetwork.from_branches(
                junctions=np.array([p.position for p in self.points], dtype=float),
                branches=branches,
                constraints=constraints,
                bodies=bodies,
                mass_matrix=self.run.mass_matrix,
                hydrodynamics=self.run.hydrodynamics,
            )
        # `from_branches` keeps point k as node k, then numbers each line's interior
        # nodes and its segments, A to B, line by line.
        line_nodes, line_segments = [], []
        next_node, next_segment = len(self.points), 0
        for line in self.lines:
            n = line.segments
            line_nodes.append(np.array([line.start, *range(next_node, next_node + n - 1), line.end]))
            line_segments.append(np.arange(next_segment, next_segment + n))
            next_node += n - 1
            next_segment += n
        return BuiltScene(self, model, environment, tuple(line_nodes), tuple(line_segments))


class EnginePart(NamedTuple):
    """A part of a scene file that only the engine can make or judge: a point's body or
    motion, or a check of the engine's on a value the reader took (a wave's breaking
    height, a solver's tolerances). See `ParsedScene`.

    - `make`: makes it, importing the engine; its result is kept only for a point's part.
    - `where`: where in the file it was written, for the engine's errors.
    - `point`, `field`: the index of the point whose `field` (`"body"` or `"motion"`) it
        is; `None` for a check alone.
    - `noted`: the place its warnings (a spline's overshoot, a cnoidal wave's low Ursell
        number) are noted at, among the scene's notes; `None` to let them through as
        warnings.
    """

    make: Callable[[], Any]
    where: str
    point: int | None = None
    field: str = ""
    noted: str | None = None


@dataclass(frozen=True)
class ParsedScene:
    """A scene file read and checked in plain Python and numpy, without JAX: every
    refusal that the reader itself makes (syntax, a missing key or section, a number
    that is not one, a name or point that does not exist, a value out of range, an
    unreadable motion table) is made here. The command line reads its input this way
    before it imports JAX, so that a malformed file is answered at once.

    - `scene`: the scene, but for the bodies and motions of its points, which are
        `None` until `finish` makes them.
    - `parts`: what only the engine makes or judges, in file order.
    """

    scene: Scene
    parts: tuple[EnginePart, ...] = ()

    def finish(self) -> Scene:
        """The complete scene: each part made by the engine, its warnings noted.

        **Raises:**

        [`jaxcable.io.SceneError`][] at a part's place in the file for a value the
        engine refuses; [`jaxcable.Float64Error`][] if JAX's float64 is off.
        """
        points, notes = list(self.scene.points), list(self.scene.notes)
        for part in self.parts:
            with warnings.catch_warnings(record=part.noted is not None) as caught:
                if part.noted is not None:
                    warnings.simplefilter("always", UserWarning)
                with located(part.where):
                    made = part.make()
            notes += [f"{part.noted}: {w.message}" for w in caught or ()]
            if part.point is not None:
                points[part.point] = dataclasses.replace(points[part.point], **{part.field: made})
        return self.scene.replace(points=tuple(points), notes=tuple(notes))


def make_body(**values) -> "Body":
    """`jaxcable.Body(**values)`, for a reader's `EnginePart` (the engine is imported
    only when the part is made)."""
    from .._model.network import Body

    return Body(**values)


def _check_reach(line: LineSpec, start: PointSpec, end: PointSpec) -> None:
    """Refuse a line whose ends sit at one point (its start shape has no direction),
    or whose held ends are farther apart than it can reach without stretching more
    than `MAX_REQUIRED_STRAIN`: a length or a position in the wrong unit, most likely,
    which statics would otherwise report only as a failure to converge."""
    from .._statics.solution import MAX_REQUIRED_STRAIN

    chord = float(np.linalg.norm(np.subtract(end.position, start.position)))
    if chord == 0.0:
        raise SceneError(
            f"{line.where}: both ends of line {line.name} are at {list(start.position)} (points {start.name} and "
            f"{end.name}); give them distinct positions"
        )
    if start.kind != "free" and end.kind != "free" and chord > (1 + MAX_REQUIRED_STRAIN) * line.length:
        raise SceneError(
            f"{line.where}: line {line.name} must stretch {100 * (chord / line.length - 1):.3g} % to reach from point "
            f"{start.name} to point {end.name}: its length is {line.length:g} m and they are {chord:g} m apart "
            f"(at most {100 * MAX_REQUIRED_STRAIN:.0f} % is taken as meant)"
        )


@dataclass(frozen=True)
class BuiltScene:
    """A scene with its engine model.

    - `model`, `environment`: for [`jaxcable.solve_statics`][] and
        [`jaxcable.simulate`][].
    - `line_nodes`: per line, the node indices from end A to end B, shape
        `(segments + 1,)`.
    - `line_segments`: per line, the segment indices from end A to end B.
    - `labels`: the names [`jaxcable.advise`][] gives the lines and points.
    """

    scene: Scene
    model: "CableNetwork"
    environment: "Environment"
    line_nodes: tuple[np.ndarray, ...] = field(repr=False)
    line_segments: tuple[np.ndarray, ...] = field(repr=False)

    @property
    def labels(self) -> "Labels":
        """The scene's names for the model's lines, line types and points, for
        [`jaxcable.advise`][]."""
        from .._advice import Labels

        return Labels(
            tuple(
                (line.name, nodes, segments)
                for line, nodes, segments in zip(self.scene.lines, self.line_nodes, self.line_segments)
            ),
            tuple(line.line_type for line in self.scene.lines),
            tuple(point.name for point in self.scene.points),
            self.scene.coupled_points,
        )


class located:
    """Re-raise a `ValueError` from the engine's checks as a `SceneError` prefixed with
    where in the file the offending item was written."""

    def __init__(self, where: str):
        self.where = where

    def __enter__(self):
        return self

    def __exit__(self, kind, error, traceback):
        if kind is not None and issubclass(kind, ValueError) and not isinstance(error, SceneError):
            raise SceneError(f"{self.where}: {error}") from error
        return False
