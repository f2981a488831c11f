"""jaxcable's own scene files, in TOML.

A scene file names its points and line types and lists its lines::

    title = "An anchored line driven at its top"

    [water]                      # all optional
    density = 1025.0             # kg/m³
    gravity = 9.81               # m/s²
    depth = 200.0                # m; required with [[waves]] or [seabed]
    current = [0.5, 0.0, 0.0]    # m/s, uniform
    free_surface = false         # true: only the part below z = 0 is in the water
    fluid_inertia = true         # false: waves load lines and bodies by drag only
    wave_ramp = 0.0              # s: switch the waves on smoothly over this time

    [water.current_profile]      # instead of a uniform current: speed over depth
    heights = [-200.0, -50.0, 0.0]   # z (m), increasing; linear between, held beyond
    speeds = [0.1, 0.4, 0.6]         # m/s
    heading = 0.0                    # deg, the direction it flows towards (+x to +y)

    [[waves]]                    # zero or more regular waves, superposed
    theory = "airy"              # or "cnoidal"
    height = 4.0                 # H (m), crest to trough; or steepness = H/λ (–)
    period = 10.0                # T (s)
    heading = 0.0                # deg, the direction of travel; optional
    phase = 0.0                  # rad, 0: a crest at x = 0 at t = 0; optional
    wheeler = false              # Wheeler stretching (airy only); optional

    [[waves]]                    # or an irregular sea, realised from a spectrum
    spectrum = "jonswap"         # or "pierson-moskowitz" (JONSWAP at γ = 1)
    significant_height = 3.0     # H_s (m)
    peak_period = 10.0           # T_p (s)
    peak_enhancement = 3.3       # γ (jonswap only); optional, 3.3
    components = 200             # N, on equal frequency steps
    frequencies = [0.35, 3.0]    # (ω_min, ω_max) (rad/s): must hold H_s²/16 within 1 %
    seed = 1                     # the random phases'
    heading = 0.0                # deg, the mean direction of travel; optional
    spreading = 10.0             # cos-2s exponent s; optional (long-crested without)
    wheeler = false              # optional
                                 # the sea repeats after 2π N/(ω_max − ω_min) s

    [seabed]                     # a flat bed at z = −depth; all keys optional
    stiffness = 3.0e6            # Pa/m per contact area (MoorDyn's kBot)
    damping = 3.0e5              # Pa·s/m (MoorDyn's cBot)
    friction = 0.0               # Coulomb coefficient μ (–)
    friction_speed = 0.01        # m/s, below which friction is viscous
                                 # friction_damping (N·s/m): MoorDyn's FricDamp form

    [simulation]                 # all optional
    duration = 30.0              # s
    dt_out = 0.05                # s
    solver = "auto"              # fixed RK4 steps chosen for the scene's fastest
                                 # modes (jaxcable.fixed_steps); or a name in
                                 # jaxcable.SOLVERS ("dopri5" where rtol or atol
                                 # is given)
    # rtol = 1e-6                # adaptive steps' tolerances
    # atol = 1e-6
    # dt = 0.001                 # s: fixed steps (as MoorDyn's dtM) instead of adaptive;
    #                            # with solver = "midpoint", "heun" or "euler", say
    max_steps = 1000000
    mass_matrix = "consistent"   # or "lumped"
    hydrodynamics = "segments"   # or "nodes": drag and added mass lumped at the
                                 # nodes, as MoorDyn (needs mass_matrix = "lumped")
    statics = true               # false: start from the points' positions at rest,
                                 # lines as MoorDyn lays them (its TmaxIC = 0)

    [line_types.rope]
    mass_per_length = 3.0        # kg/m
    diameter = 0.0195            # m
    axial_stiffness = 3.0e7      # C_E = EA (N)
    quadratic_stiffness = 3.0e6  # C_E1 (N), optional
    axial_damping = 0.0          # C_v (N·s), or axial_damping_ratio (–), optional
    normal_drag = 1.2            # K_n; also tangential_drag, normal_added_mass,
                                 # tangential_added_mass, area, slack_width,
                                 # bending_stiffness (EI, N·m²);
                                 # slack_damping = true damps slack segments too
    minimum_breaking_load = 2.0e6  # MBL (N), optional: utilisation in the results
    fatigue_curve = "api_multistrand_rope"  # optional: fatigue damage in the results,
                                 # a name of jaxcable.TN_CURVES; a DNV curve also
                                 # needs fatigue_area (m², the nominal area)

    [points.anchor]
    type = "fixed"               # "fixed", "coupled" or "free"
    position = [0.0, 0.0, -200.0]

    [points.fairlead]
    type = "coupled"
    position = [346.4, 0.0, 0.0]
    motion = { type = "harmonic", amplitude = 1.57, period = 5.6, direction = [1, 0, 0] }
    # optional: phase (rad), ramp (s, switches the motion on smoothly)
    # or: motion = { type = "table", file = "fairlead.csv" }  (time x y z, absolute)
    # optional: interpolation = "cubic" (natural spline, the default), "pchip" (monotone)
    # or "linear"

    [points.buoy]                # a free point may carry a body:
    type = "free"                # mass, volume, drag_area, specific_drag,
    position = [...]             # organism_mass, added_mass, height (m, to float),
                                 # force = [fx, fy, fz] (N, constant)

    [[lines]]
    type = "rope"
    from = "anchor"              # end A
    to = "fairlead"              # end B
    length = 400.0               # m, unstretched
    segments = 20

    [output]
    channels = ["FairTen1", "AnchTen1", "L1N10PZ"]

Lines are numbered from 1 in the order written, for channels such as `FairTen1`.
Errors name the file, the line and the key. Waves take the water's depth and gravity;
see [`jaxcable.Environment`][], [`jaxcable.Airy`][], [`jaxcable.Cnoidal`][],
[`jaxcable.Jonswap`][], [`jaxcable.WaveComponents.from_spectrum`][] and
[`jaxcable.Seabed`][] for the physics.

The reader is plain Python: `parse_scene` reads and checks a file without JAX, and the
engine's objects (bodies, motions) and checks (waves, tolerances) are made when the
scene is finished (`jaxcable.io._scene.ParsedScene`).
"""

import functools
import math
import tomllib
from collections.abc import Callable
from pathlib import Path
from typing import TYPE_CHECKING, Any

from .._names import AUTO, HYDRODYNAMICS, MASS_MATRICES, SOLVER_NAMES
from ._motion_file import read_motion_file
from ._parse import read_text, unique_names
from ._scene import (
    POINT_KINDS,
    SPECTRA,
    WAVE_THEORIES,
    CurrentProfileSpec,
    EnginePart,
    LineSpec,
    LineTypeSpec,
    ParsedScene,
    PointSpec,
    RunSettings,
    Scene,
    SceneError,
    SeabedSpec,
    SeaStateSpec,
    Water,
    WaveSpec,
    make_body,
)

if TYPE_CHECKING:
    from .._model.motion import AbstractMotion, Harmonic, Sampled

_TOP = ("title", "water", "waves", "seabed", "simulation", "line_types", "points", "lines", "output")
_WATER = ("density", "gravity", "depth", "current", "current_profile", "free_surface", "fluid_inertia", "wave_ramp")
_CURRENT_PROFILE = ("heights", "speeds", "heading")
_WAVE = ("theory", "height", "steepness", "period", "heading", "phase", "wheeler")
_SEA_STATE = (
    "spectrum",
    "significant_height",
    "peak_period",
    "peak_enhancement",
    "components",
    "frequencies",
    "seed",
    "heading",
    "spreading",
    "wheeler",
)
_SEABED = ("stiffness", "damping", "friction", "friction_speed", "friction_damping")
_SIMULATION = (
    "duration",
    "dt_out",
    "solver",
    "rtol",
    "atol",
    "dt",
    "max_steps",
    "mass_matrix",
    "hydrodynamics",
    "statics",
)
_LINE_TYPE_REQUIRED = ("mass_per_length", "diameter", "axial_stiffness")
_LINE_TYPE_OPTIONAL = (
    "quadratic_stiffness",
    "axial_damping",
    "axial_damping_ratio",
    "normal_drag",
    "tangential_drag",
    "normal_added_mass",
    "tangential_added_mass",
    "area",
    "slack_width",
    "bending_stiffness",
    "minimum_breaking_load",
    "fatigue_area",
)
_LINE_TYPE_FLAGS = ("slack_damping",)  # true or false
_BODY = ("mass", "volume", "drag_area", "specific_drag", "organism_mass", "added_mass", "height")
_BODY_VECTORS = ("force",)
_HARMONIC = ("type", "amplitude", "period", "direction", "phase", "ramp")
_LINE = ("name", "type", "from", "to", "length", "segments")


def read_scene(path: str | Path) -> Scene:
    """Read a jaxcable scene file (TOML) as a [`jaxcable.io.Scene`][]. The format is in
    this module's docstring; `jaxcable/examples/scenes/` has complete examples.

    **Raises:**

    [`jaxcable.io.SceneError`][] naming the file, line and key for TOML syntax errors,
    unknown or missing keys, values of the wrong type, points or line types that do
    not exist, and values out of range.
    """
    return parse_scene(path).finish()


def parse_scene(path: str | Path) -> ParsedScene:
    """Read and check a jaxcable scene file (TOML) without JAX: [`jaxcable.read_scene`][]
    but for the engine's parts, which `ParsedScene.finish` makes.

    **Raises:**

    [`jaxcable.io.SceneError`][] as [`jaxcable.read_scene`][] does, but for the values
    only the engine judges (a wave's breaking height, a body's or a motion's values, a
    solver's tolerances), which `finish` refuses.
    """
    path = Path(path)
    text = read_text(path)
    try:
        data = tomllib.loads(text)
    except tomllib.TOMLDecodeError as error:
        raise SceneError(f"{path}: {error}") from error
    reader = _Reader(path, text)
    reader.keys(data, (), _TOP)

    parts: list[EnginePart] = []  # in file order: the water's, the run's, the points'
    water_spec = _water(reader, data, parts)

    simulation = reader.table(data, ("simulation",))
    reader.keys(simulation, ("simulation",), _SIMULATION)
    defaults = RunSettings()
    # Tolerances without a solver ask for adaptive steps: Dopri5's, not auto's fixed ones.
    tolerances = [key for key in ("rtol", "atol") if key in simulation]
    run = RunSettings(
        duration=reader.number(simulation, ("simulation", "duration"), defaults.duration),
        dt_out=reader.number(simulation, ("simulation", "dt_out"), None),
        solver=reader.string(simulation, ("simulation", "solver"), "dopri5" if tolerances else defaults.solver),
        rtol=reader.number(simulation, ("simulation", "rtol"), defaults.rtol),
        atol=reader.number(simulation, ("simulation", "atol"), defaults.atol),
        dt=reader.number(simulation, ("simulation", "dt"), None),
        max_steps=reader.integer(simulation, ("simulation", "max_steps"), defaults.max_steps),
        mass_matrix=reader.string(simulation, ("simulation", "mass_matrix"), defaults.mass_matrix),
        hydrodynamics=reader.string(simulation, ("simulation", "hydrodynamics"), defaults.hydrodynamics),
        statics=reader.boolean(simulation, ("simulation", "statics"), defaults.statics),
    )
    solvers = (AUTO, *SOLVER_NAMES)
    for key, allowed in (("solver", solvers), ("mass_matrix", MASS_MATRICES), ("hydrodynamics", HYDRODYNAMICS)):
        if getattr(run, key) not in allowed:
            raise SceneError(
                f"{reader.where(('simulation', key))}: must be one of {allowed}, got {getattr(run, key)!r}"
            )
    if run.solver == AUTO and run.dt is None and tolerances:
        raise SceneError(
            f'{reader.where(("simulation", tolerances[0]))}: sets adaptive steps, but solver "auto" takes fixed '
            'steps chosen for the scene: name an adaptive solver (solver = "dopri5"), or leave it out'
        )
    if run.hydrodynamics == "nodes" and run.mass_matrix != "lumped":
        raise SceneError(
            f'{reader.where(("simulation", "hydrodynamics"))}: "nodes" (MoorDyn\'s lumped form) needs '
            f'mass_matrix = "lumped", got {run.mass_matrix!r}'
        )
    for key in ("dt_out", "rtol", "atol", "dt", "max_steps"):
        value = getattr(run, key)
        if value is not None and not value > 0:
            raise SceneError(f"{reader.where(('simulation', key))}: must be positive, got {value:g}")
    # The solver's own checks on its tolerances, when the scene is finished, not when the run starts.
    parts.append(EnginePart(run.solver_config, reader.where(("simulation",))))
    if not run.duration >= 0:
        raise SceneError(f"{reader.where(('simulation', 'duration'))}: must not be negative, got {run.duration:g}")

    line_types = []
    line_type_tables = reader.table(data, ("line_types",), required=True)
    for name in line_type_tables:
        keys = ("line_types", name)
        table = reader.table(line_type_tables, keys, required=True)
        reader.keys(table, keys, _LINE_TYPE_REQUIRED + _LINE_TYPE_OPTIONAL + _LINE_TYPE_FLAGS + ("fatigue_curve",))
        values = {k: reader.number(table, (*keys, k)) for k in _LINE_TYPE_REQUIRED}
        values |= {k: reader.number(table, (*keys, k)) for k in _LINE_TYPE_OPTIONAL if k in table}
        slack = reader.boolean(table, (*keys, "slack_damping"), False)
        curve = reader.string(table, (*keys, "fatigue_curve")) if "fatigue_curve" in table else None
        line_types.append(
            LineTypeSpec(name=name, where=reader.where(keys), slack_damping=slack, fatigue_curve=curve, **values)
        )
    unique_names(line_types, "line type", str(path))

    points = []
    point_tables = reader.table(data, ("points",), required=True)
    for name in point_tables:
        keys = ("points", name)
        table = reader.table(point_tables, keys, required=True)
        reader.keys(table, keys, ("type", "position", "motion") + _BODY + _BODY_VECTORS)
        kind = reader.string(table, (*keys, "type"))
        if kind not in POINT_KINDS:
            raise SceneError(
                f"{reader.where((*keys, 'type'))}: unknown point type {kind!r}; expected one of {POINT_KINDS}"
            )
        position = reader.vector(table, (*keys, "position"))
        if any(k in table for k in _BODY + _BODY_VECTORS):
            numbers = {k: reader.number(table, (*keys, k)) for k in _BODY if k in table}
            vectors = {k: reader.vector(table, (*keys, k)) for k in _BODY_VECTORS if k in table}
            make = functools.partial(make_body, **numbers, **vectors)
            parts.append(EnginePart(make, reader.where(keys), len(points), "body"))
        if "motion" in table:
            if kind != "coupled":
                raise SceneError(f"{reader.where((*keys, 'motion'))}: only a coupled point can have a motion")
            make, where = reader.motion(table, (*keys, "motion"), position)
            # A spline's overshoot is noted at the motion's key.
            parts.append(EnginePart(make, where, len(points), "motion", reader.where((*keys, "motion"))))
        points.append(PointSpec(name, kind, position, where=reader.where(keys)))
    index = {p.name: k for k, p in enumerate(points)}

    lines = []
    rows = data.get("lines")
    if not isinstance(rows, list) or not rows:
        raise SceneError(f"{reader.where(('lines',))}: expected one or more [[lines]] tables")
    for k, row in enumerate(rows):
        keys = ("lines", k)
        if not isinstance(row, dict):
            raise SceneError(f"{reader.where(keys)}: expected a [[lines]] table")
        reader.keys(row, keys, _LINE)
        ends = []
        for end in ("from", "to"):
            point = reader.string(row, (*keys, end))
            if point not in index:
                raise SceneError(
                    f"{reader.where((*keys, end))}: point {point!r} does not exist; defined: {list(index)}"
                )
            ends.append(index[point])
        line_type = reader.string(row, (*keys, "type"))
        if line_type not in {t.name for t in line_types}:
            raise SceneError(
                f"{reader.where((*keys, 'type'))}: line type {line_type!r} does not exist; "
                f"defined: {[t.name for t in line_types]}"
            )
        length = reader.number(row, (*keys, "length"))
        if not length > 0:
            raise SceneError(
                f"{reader.where((*keys, 'length'))}: the unstretched length must be positive, got {length:g}"
            )
        segments = row.get("segments")
        if not (type(segments) is int and segments >= 1):
            raise SceneError(f"{reader.where((*keys, 'segments'))}: expected a positive integer, got {segments!r}")
        name = reader.string(row, (*keys, "name"), str(k + 1))
        lines.append(LineSpec(name, line_type, ends[0], ends[1], length, segments, reader.where(keys)))

    output = reader.table(data, ("output",))
    reader.keys(output, ("output",), ("channels",))
    channels = output.get("channels", [])
    if not (isinstance(channels, list) and all(isinstance(c, str) for c in channels)):
        raise SceneError(f"{reader.where(('output', 'channels'))}: expected a list of channel names")
    title = reader.string(data, ("title",), "")
    scene = Scene(
        tuple(points), tuple(line_types), tuple(lines), water_spec, run, tuple(channels), (), str(path), title
    )
    return ParsedScene(scene, tuple(parts))


def _water(reader: "_Reader", data: dict, parts: list[EnginePart]) -> Water:
    """`[water]`, its current profile, `[[waves]]` and `[seabed]`; the engine's checks
    of the profile and the waves are added to `parts`."""
    water = reader.table(data, ("water",))
    reader.keys(water, ("water",), _WATER)
    depth = reader.number(water, ("water", "depth"), None)
    if depth is not None and not depth > 0:
        raise SceneError(f"{reader.where(('water', 'depth'))}: must be positive, got {depth}")
    gravity = reader.number(water, ("water", "gravity"), 9.81)
    current = reader.vector(water, ("water", "current"), (0.0, 0.0, 0.0))

    profile = None
    if "current_profile" in water:
        keys = ("water", "current_profile")
        table = reader.table(water, keys)
        reader.keys(table, keys, _CURRENT_PROFILE)
        if "current" in water:
            raise SceneError(f"{reader.where(keys)}: give a uniform current or a current profile, not both")
        profile = CurrentProfileSpec(
            heights=reader.numbers(table, (*keys, "heights")),
            speeds=reader.numbers(table, (*keys, "speeds")),
            heading=reader.number(table, (*keys, "heading"), 0.0),
            where=reader.where(keys),
        )
        parts.append(EnginePart(profile.profile, profile.where))  # the engine's checks: lengths match, heights increase

    waves = []
    rows = data.get("waves", [])
    if not isinstance(rows, list):
        raise SceneError(f"{reader.where(('waves',))}: expected [[waves]] tables, one per wave")
    for k, row in enumerate(rows):
        keys = ("waves", k)
        if not isinstance(row, dict):
            raise SceneError(f"{reader.where(keys)}: expected a [[waves]] table")
        if "spectrum" in row:
            waves.append(_sea_state(reader, row, keys, depth, gravity, parts))
            continue
        reader.keys(row, keys, _WAVE)
        theory = reader.string(row, (*keys, "theory"))
        if theory not in WAVE_THEORIES:
            raise SceneError(
                f"{reader.where((*keys, 'theory'))}: unknown wave theory {theory!r}; expected one of {WAVE_THEORIES}"
            )
        given = [key for key in ("height", "steepness") if key in row]
        if len(given) != 1:
            at = reader.where((*keys, given[-1])) if given else reader.where(keys)
            raise SceneError(f"{at}: give exactly one of height (m) and steepness (H/λ), got {len(given)}")
        values = {key: reader.number(row, (*keys, key)) for key in (*given, "period")}
        for key, value in values.items():
            if not value > 0:
                raise SceneError(f"{reader.where((*keys, key))}: must be positive, got {value:g}")
        wheeler = reader.boolean(row, (*keys, "wheeler"), False)
        if "wheeler" in row and theory != "airy":
            raise SceneError(f"{reader.where((*keys, 'wheeler'))}: Wheeler stretching applies to airy waves only")
        if depth is None:
            raise SceneError(f"{reader.where(keys)}: waves need the water depth: give [water] depth")
        spec = WaveSpec(
            theory=theory,
            heading=reader.number(row, (*keys, "heading"), 0.0),
            phase=reader.number(row, (*keys, "phase"), 0.0),
            wheeler=wheeler,
            where=reader.where(keys),
            **values,
        )
        # The engine's checks: breaking, period range; its warnings (a cnoidal wave's
        # low Ursell number) are noted.
        parts.append(EnginePart(functools.partial(spec.wave, depth, gravity), spec.where, noted=spec.where))
        waves.append(spec)

    seabed = None
    if "seabed" in data:
        keys = ("seabed",)
        table = reader.table(data, keys)
        reader.keys(table, keys, _SEABED)
        defaults = SeabedSpec()
        values = {key: reader.number(table, (*keys, key), getattr(defaults, key)) for key in _SEABED}
        for key, value in values.items():
            if value is None:  # friction_damping not given: the smooth friction
                continue
            positive = key in ("stiffness", "friction_speed", "friction_damping")
            if not (value > 0 if positive else value >= 0):
                kind = "positive" if positive else "non-negative"
                raise SceneError(f"{reader.where((*keys, key))}: must be {kind}, got {value:g}")
        if depth is None:
            raise SceneError(f"{reader.where(keys)}: a seabed needs the water depth: give [water] depth")
        seabed = SeabedSpec(**values, where=reader.where(keys))  # its values checked above, as the engine's Seabed does

    wave_ramp = reader.number(water, ("water", "wave_ramp"), 0.0)
    if wave_ramp < 0:
        raise SceneError(f"{reader.where(('water', 'wave_ramp'))}: must be non-negative, got {wave_ramp:g}")
    return Water(
        density=reader.number(water, ("water", "density"), 1025.0),
        gravity=gravity,
        depth=depth,
        current=current,
        free_surface=reader.boolean(water, ("water", "free_surface"), False),
        current_profile=profile,
        waves=tuple(waves),
        seabed=seabed,
        fluid_inertia=reader.boolean(water, ("water", "fluid_inertia"), True),
        wave_ramp=wave_ramp,
        where=reader.where(("water",)),
    )


def _sea_state(
    reader: "_Reader", row: dict, keys: tuple, depth: float | None, gravity: float, parts: list[EnginePart]
) -> SeaStateSpec:
    """A `[[waves]]` table with a `spectrum`: an irregular sea; the engine's check of it
    is added to `parts`."""
    reader.keys(row, keys, _SEA_STATE)
    spectrum = reader.string(row, (*keys, "spectrum"))
    if spectrum not in SPECTRA:
        raise SceneError(
            f"{reader.where((*keys, 'spectrum'))}: unknown spectrum {spectrum!r}; expected one of {SPECTRA}"
        )
    if spectrum == "pierson-moskowitz" and "peak_enhancement" in row:
        raise SceneError(
            f"{reader.where((*keys, 'peak_enhancement'))}: a Pierson–Moskowitz spectrum has none (γ = 1): "
            'use spectrum = "jonswap" to give one'
        )
    values = {key: reader.number(row, (*keys, key)) for key in ("significant_height", "peak_period")}
    for key, value in values.items():
        if not value > 0:
            raise SceneError(f"{reader.where((*keys, key))}: must be positive, got {value:g}")
    frequencies = reader.numbers(row, (*keys, "frequencies"))
    if len(frequencies) != 2 or not 0 < frequencies[0] < frequencies[1]:
        raise SceneError(
            f"{reader.where((*keys, 'frequencies'))}: expected [ω_min, ω_max] in rad/s, 0 < ω_min < ω_max, "
            f"got {list(frequencies)}"
        )
    counts = {}
    for key, lowest in (("components", 1), ("seed", 0)):
        value = reader.integer(row, (*keys, key))
        if not (lowest <= value < 2**32):
            raise SceneError(
                f"{reader.where((*keys, key))}: expected an integer from {lowest} to 2**32 - 1, got {value}"
            )
        counts[key] = value
    spreading = reader.number(row, (*keys, "spreading"), None)
    if spreading is not None and not spreading > 0:
        raise SceneError(f"{reader.where((*keys, 'spreading'))}: must be positive, got {spreading:g}")
    if depth is None:
        raise SceneError(f"{reader.where(keys)}: waves need the water depth: give [water] depth")
    spec = SeaStateSpec(
        spectrum=spectrum,
        frequencies=(frequencies[0], frequencies[1]),
        peak_enhancement=reader.number(row, (*keys, "peak_enhancement"), 3.3),
        heading=reader.number(row, (*keys, "heading"), 0.0),
        spreading=spreading,
        wheeler=reader.boolean(row, (*keys, "wheeler"), False),
        where=reader.where(keys),
        **values,
        **counts,
    )
    # The engine's checks, when the scene is finished: γ, breaking, the band against m₀.
    parts.append(EnginePart(functools.partial(spec.wave, depth, gravity), spec.where))
    return spec


class _Reader:
    """Typed access to the parsed TOML, with errors located in the source text.

    `tomllib` reports syntax errors with their line but does not keep positions, so
    keys are located by scanning the text: each `[table]` / `[[array]]` header and each
    `key =` line is recorded under its full key path.
    """

    def __init__(self, path: Path, text: str):
        self.path = path
        self.lines: dict[tuple, int] = {}
        header: tuple = ()
        arrays: dict[tuple, int] = {}
        for number, raw in enumerate(text.splitlines(), start=1):
            line = raw.strip()
            if line.startswith("[["):
                name = _split_key(line[2:].split("]]")[0])
                arrays[name] = arrays.get(name, -1) + 1
                header = (*name, arrays[name])
                self.lines.setdefault(header, number)
            elif line.startswith("["):
                header = _split_key(line[1:].split("]")[0])
                self.lines.setdefault(header, number)
            elif "=" in line and not line.startswith("#"):
                self.lines.setdefault((*header, *_split_key(line.split("=")[0])), number)

    def where(self, keys: tuple) -> str:
        """`file, line N, key a.b.c`, with the line of the key or of its nearest
        enclosing table that the text shows."""
        shown = ".".join(str(k) if not isinstance(k, int) else f"[{k}]" for k in keys).replace(".[", "[")
        for n in range(len(keys), 0, -1):
            if keys[:n] in self.lines:
                return f"{self.path}, line {self.lines[keys[:n]]}, key {shown}"
        return f"{self.path}, key {shown}"

    def keys(self, table: dict, keys: tuple, allowed: tuple[str, ...]) -> None:
        for key in table:
            if key not in allowed:
                raise SceneError(f"{self.where((*keys, key))}: unknown key; expected one of {', '.join(allowed)}")

    def table(self, parent: dict, keys: tuple, required: bool = False) -> dict:
        """The table at `keys[-1]` of `parent` (`{}` if absent and not `required`)."""
        if keys[-1] not in parent:
            if required:
                raise SceneError(f"{self.where(keys)}: missing table [{'.'.join(map(str, keys))}]")
            return {}
        value = parent[keys[-1]]
        if not isinstance(value, dict):
            raise SceneError(f"{self.where(keys)}: expected a table, got {value!r}")
        return value

    def _value(self, table: dict, keys: tuple, default, kind: str):
        if keys[-1] in table:
            return table[keys[-1]], True
        if default is _REQUIRED:
            raise SceneError(f"{self.where(keys)}: missing required key ({kind})")
        return default, False

    def number(self, table: dict, keys: tuple, default: Any = ...):
        value, given = self._value(table, keys, default, "a number")
        if given and (isinstance(value, bool) or not isinstance(value, int | float) or not math.isfinite(value)):
            raise SceneError(f"{self.where(keys)}: expected a finite number, got {value!r}")
        return float(value) if given else value

    def integer(self, table: dict, keys: tuple, default: Any = ...) -> int:
        value, given = self._value(table, keys, default, "an integer")
        if given and type(value) is not int:
            raise SceneError(f"{self.where(keys)}: expected an integer, got {value!r}")
        return value

    def boolean(self, table: dict, keys: tuple, default: Any = ...) -> bool:
        value, given = self._value(table, keys, default, "true or false")
        if given and not isinstance(value, bool):
            raise SceneError(f"{self.where(keys)}: expected true or false, got {value!r}")
        return value

    def string(self, table: dict, keys: tuple, default: Any = ...) -> str:
        value, given = self._value(table, keys, default, "a string")
        if given and not isinstance(value, str):
            raise SceneError(f"{self.where(keys)}: expected a string, got {value!r}")
        return value

    def numbers(self, table: dict, keys: tuple, default: Any = ...) -> tuple[float, ...]:
        value, given = self._value(table, keys, default, "a list of numbers")
        if given and not (
            isinstance(value, list)
            and value
            and all(isinstance(v, int | float) and not isinstance(v, bool) and math.isfinite(v) for v in value)
        ):
            raise SceneError(f"{self.where(keys)}: expected a list of finite numbers, got {value!r}")
        if not given:
            return default
        return tuple(float(v) for v in value)

    def vector(self, table: dict, keys: tuple, default: Any = ...) -> tuple[float, float, float]:
        value, given = self._value(table, keys, default, "[x, y, z]")
        if given and not (
            isinstance(value, list)
            and len(value) == 3
            and all(isinstance(v, int | float) and not isinstance(v, bool) and math.isfinite(v) for v in value)
        ):
            raise SceneError(f"{self.where(keys)}: expected three numbers [x, y, z], got {value!r}")
        if not given:
            return default
        x, y, z = value
        return float(x), float(y), float(z)

    def motion(
        self, table: dict, keys: tuple, position: tuple[float, float, float]
    ) -> tuple[Callable[[], "AbstractMotion"], str]:
        """A point's `motion = { ... }`: a function that makes the engine's motion, and
        the place its errors are reported at."""
        spec = table[keys[-1]]
        if not isinstance(spec, dict):
            raise SceneError(f'{self.where(keys)}: expected a table such as {{ type = "harmonic", ... }}')
        kind = self.string(spec, (*keys, "type"))
        if kind == "harmonic":
            self.keys(spec, keys, _HARMONIC)
            values = dict(
                amplitude=self.number(spec, (*keys, "amplitude")),
                period=self.number(spec, (*keys, "period")),
                direction=self.vector(spec, (*keys, "direction"), (1.0, 0.0, 0.0)),
                phase=self.number(spec, (*keys, "phase"), 0.0),
                ramp=self.number(spec, (*keys, "ramp"), 0.0),
            )
            return functools.partial(_harmonic, **values), self.where(keys)
        if kind == "table":
            self.keys(spec, keys, ("type", "file", "interpolation"))
            file = self.path.parent / self.string(spec, (*keys, "file"))
            interpolation = self.string(spec, (*keys, "interpolation"), "cubic")
            try:
                times, positions = read_motion_file(file, 1)
            except SceneError as error:  # its own messages name the table's file and line, not this key
                raise SceneError(f"{self.where((*keys, 'file'))}: {error}") from None
            make = functools.partial(_sampled, times, positions[:, 0, :] - tuple(position), interpolation)
            return make, self.where((*keys, "interpolation") if "interpolation" in spec else keys)
        raise SceneError(f"{self.where((*keys, 'type'))}: unknown motion type {kind!r}; expected 'harmonic' or 'table'")


def _harmonic(**values) -> "Harmonic":
    """`jaxcable.Harmonic(**values)`, imported only when the scene is finished."""
    from .._model.motion import Harmonic

    return Harmonic(**values)


def _sampled(times, displacements, interpolation: str) -> "Sampled":
    """`jaxcable.Sampled(times, displacements, interpolation)` (s, m), imported only when
    the scene is finished."""
    from .._model.motion import Sampled

    return Sampled(times, displacements, interpolation)


_REQUIRED = ...  # the default of a key that must be given


def _split_key(key: str) -> tuple[str, ...]:
    return tuple(part.strip().strip("\"'") for part in key.split("."))
