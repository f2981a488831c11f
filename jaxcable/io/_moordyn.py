"""A reader for MoorDyn v2 input files.

MoorDyn's format is sections of whitespace-separated tables, each opened by a header
line containing `---` and the section's name, then a line of column names and a line of
units (`OPTIONS` and `OUTPUTS` have neither). The coefficients map onto jaxcable's one to
one: MoorDyn's `Cd` is referred to d·l and `CdAx` to π·d·l, exactly as K_n and K_τ are,
and `Ca`, `CaAx` are jaxcable's normal and tangential added-mass coefficients on
π d²/4 — so they are copied, not converted. The column `BA/-zeta` is axial damping in
N·s when positive and a fraction of critical damping when negative; the reader turns it
into `axial_damping` or `axial_damping_ratio` (see [`jaxcable.io.LineTypeSpec`][]), with
`slack_damping`, since MoorDyn damps a slack segment's strain rate as a taut one's
(Line.cpp switches only the elastic tension off in compression).

The seabed is MoorDyn's: MoorDyn always has one, flat at `WtrDpth` (0 by default),
which it lowers to the deepest point when a point lies below it (MoorDyn2.cpp, reading
POINTS), and pushes each line node below it up by `(kBot δ − cBot ż) d l` with l the
node's share of unstretched length — jaxcable's [`jaxcable.Seabed`][] on the same
contact area, so `kBot` and `cBot` (3e6 Pa/m and 3e5 Pa·s/m when absent) are copied.
`FrictionCoefficient` μ and `FricDamp` (200 N·s/m when absent) are copied too: MoorDyn's
friction is `μ FricDamp |v|` capped at `μ N` (Line.cpp), which the seabed's
`friction_damping` selects in place of jaxcable's smooth `μ N v / √(v² + v_s²)`.

Features jaxcable does not model raise a [`jaxcable.io.SceneError`][] where leaving them
out would change the system (rods, 6-DOF bodies, nonlinear or viscoelastic stiffness
tables, VIV, constant forces on fixed or coupled points) and are listed in `Scene.notes` where the model is
still meaningful without them (a bending stiffness table, bathymetry files,
static-to-dynamic friction ratios, the wave and current modes jaxcable cannot
represent, its time-step and initial-condition options, but for `TmaxIC = 0`, which
skips statics as it skips MoorDyn's initial-condition solve). Notes on physics left
out (a bending table, bathymetry, waves) are also issued as Python warnings. A
constant `EI` is read as the line type's `bending_stiffness` (`jaxcable._equations.bending`):
MoorDyn's lines end at points, which are pinned, as jaxcable's line ends are. MoorDyn's steady
current profile and its wave spectrum and elevation files are read into the water
(`jaxcable.io._moordyn_water`).

The reader is plain Python and numpy: `parse_moordyn` reads and checks a file without
JAX, and the points' bodies are made when the scene is finished
(`jaxcable.io._scene.ParsedScene`).
"""

import contextlib
import dataclasses
import functools
import math
import re
import warnings
from pathlib import Path

from .._names import DROPPED_KINDS as DROPPED_KINDS
from . import _moordyn_water as moordyn_water
from ._channels import UnknownChannel, parse_channel
from ._parse import is_number, read_text, unique_names
from ._scene import (
    EnginePart,
    LineSpec,
    LineTypeSpec,
    ParsedScene,
    PointSpec,
    RunSettings,
    Scene,
    SceneError,
    SeabedSpec,
    Water,
    located,
    make_body,
)

# Section names as MoorDyn recognises them, most specific first: a header matches the
# first entry any of whose aliases it contains.
_SECTIONS = (
    ("LINE TYPES", ("LINE DICTIONARY", "LINE TYPES")),
    ("ROD TYPES", ("ROD DICTIONARY", "ROD TYPES")),
    ("BODIES", ("BODIES", "BODY LIST", "BODY PROPERTIES")),
    ("RODS", ("RODS", "ROD LIST", "ROD PROPERTIES")),
    ("POINTS", ("POINTS", "POINT LIST", "POINT PROPERTIES", "CONNECTION PROPERTIES", "NODE PROPERTIES")),
    ("LINES", ("LINES", "LINE LIST", "LINE PROPERTIES")),
    ("SYROPE IC", ("SYROPE IC",)),
    ("FAILURE", ("FAILURE",)),
    ("EXTERNAL LOADS", ("EXTERNAL LOADS",)),
    ("OPTIONS", ("OPTIONS",)),
    ("OUTPUTS", ("OUTPUT",)),
)
_UNSUPPORTED_SECTIONS = {
    "ROD TYPES": "rods",
    "RODS": "rods",
    "BODIES": "6-DOF bodies",
    "SYROPE IC": "the Syrope rope model",
    "FAILURE": "line failure",
    "EXTERNAL LOADS": "external loads",
}
_LINE_TYPE_COLUMNS = ("TypeName", "Diam", "Mass/m", "EA", "BA/-zeta", "EI", "Cd", "Ca", "CdAx", "CaAx")
_EXTRA_LINE_TYPE_COLUMNS = ("Cl", "dF", "cF")  # MoorDyn's VIV coefficients
_POINT_COLUMNS = ("ID", "Type", "X", "Y", "Z", "Mass", "Volume", "CdA", "Ca")
_POINT_FORCE_COLUMNS = ("ID", "Type", "X", "Y", "Z", "Mass", "Volume", "FX", "FY", "FZ", "CdA", "Ca")
_LINE_COLUMNS = ("ID", "LineType", "AttachA", "AttachB", "UnstrLen", "NumSegs", "LineOutputs")
_POINT_KINDS = {
    "fixed": ("ANCHOR", "FIXED", "FIX"),
    "coupled": ("FAIRLEAD", "VESSEL", "VES", "COUPLED", "CPLD"),
    "free": ("POINT", "CONNECT", "CON", "FREE"),
}
# Options that tune MoorDyn's initial-condition generator, or its step from a CFL
# number: jaxcable solves statics directly and takes dtM as given, so they do not apply
# (but for TmaxIC = 0, no initial-condition solve at all, which jaxcable honours).
_TMAXIC = ("tmaxic", "ictmax")
_NOT_APPLICABLE = {
    "cfl",
    "dtic",
    "icdt",
    "cdscaleic",
    "icdfac",
    "threshic",
    "icthresh",
    "gendynamicic",
    "icgendynamic",
    "fileic",
    "icfile",
}
_COSMETIC = {"echo", "writelog", "writeunits", "disableoutput", "disableouttime"}
# MoorDyn's step (dtM, or dt) and time scheme: jaxcable takes fixed steps of dtM with
# the explicit method of the same name where it has one, and otherwise with the
# midpoint method, MoorDyn's default RK2.
_STEP, _SCHEME = ("dtm", "dt"), "tscheme"
_SCHEMES = {"rk2": "midpoint", "rk4": "rk4", "heun": "heun", "euler": "euler"}
# Numeric options jaxcable uses, by lower-case name, and the values each may take.
_USED = {
    "g": "positive",
    "gravity": "positive",
    "rho": "positive",
    "wtrdnsty": "positive",
    "wtrdpth": "positive",
    # dtOut = 0 is MoorDyn's "every step": jaxcable then keeps its default interval.
    "dtout": "positive (or 0, MoorDyn's every step)",
    "kbot": "positive",
    "kb": "positive",
    "cbot": "non-negative",
    "cb": "non-negative",
    "frictioncoefficient": "non-negative",
    "fricdamp": "positive",
    "statdynfricscale": "positive",
}
# MoorDyn's defaults (MoorDyn2.cpp): bottom stiffness and damping, friction damping.
_KBOT, _CBOT, _FRICDAMP = 3.0e6, 3.0e5, 200.0
_WAVES = {"wavekin", "dtwave", "currents", "unifycurrentgrid"}
# The WaveKin and Currents modes jaxcable reads (see `_moordyn_water`).
_WATER_MODES = {"wavekin": (2.0, 3.0, 7.0), "currents": (1.0,)}


def read_moordyn(path: str | Path) -> Scene:
    """Read a MoorDyn v2 input file as a [`jaxcable.io.Scene`][].

    Points keep MoorDyn's numbering (point `k` is `scene.points[k - 1]`), as do lines,
    so output channels such as `FairTen1` mean what they mean in MoorDyn. Coupled
    (`Vessel`) points are held at their positions until a motion is given
    ([`jaxcable.io.Scene.with_motion_table`][], or `jaxcable run --motion`). The mass matrix
    is lumped, as MoorDyn's is.

    **Raises:**

    [`jaxcable.io.SceneError`][] naming the file, line number and column for a missing
    section, an unknown point type or line type, a line attached to a point that does
    not exist, a non-positive length, a non-numeric field, or a feature jaxcable does
    not model.
    """
    scene = parse_moordyn(path).finish()
    for _, note in scene.dropped:
        warnings.warn(note, stacklevel=2)
    return scene


def parse_moordyn(path: str | Path) -> ParsedScene:
    """Read and check a MoorDyn v2 input file without JAX: [`jaxcable.read_moordyn`][]
    but for the points' bodies, which `ParsedScene.finish` makes (and checks), and
    without warning of the physics left out (`Scene.dropped`).

    **Raises:**

    [`jaxcable.io.SceneError`][] as [`jaxcable.read_moordyn`][] does, but for a body's
    values, which `finish` refuses.
    """
    path = Path(path)
    lines = read_text(path).splitlines()
    sections = _find_sections(lines)
    source = str(path)
    notes: list[str] = []
    dropped: list[tuple[str, str]] = []

    for name, what in _UNSUPPORTED_SECTIONS.items():
        rows = _rows(lines, sections, name)
        if rows:
            number, _ = rows[0]
            raise SceneError(f"{source}, line {number}: section {name} defines {what}, which jaxcable does not model")
    for required in ("LINE TYPES", "POINTS", "LINES"):
        if required not in sections:
            aliases = " / ".join(dict(_SECTIONS)[required])
            raise SceneError(f"{source}: missing section {required} (a header line with '---' and {aliases})")
    for name in ("LINE TYPES", "POINTS", "LINES"):
        _check_heading_rows(source, lines, sections[name], name)

    line_types = tuple(_line_type(source, n, row, dropped) for n, row in _rows(lines, sections, "LINE TYPES"))
    unique_names(line_types, "line type", source)
    read = [_point(source, n, row, k) for k, (n, row) in enumerate(_rows(lines, sections, "POINTS"))]
    points = tuple(point for point, _ in read)
    bodies = tuple(body for _, body in read if body is not None)
    type_names = [t.name for t in line_types]
    mdlines = tuple(
        _line(source, n, row, k, len(points), type_names) for k, (n, row) in enumerate(_rows(lines, sections, "LINES"))
    )
    if not points:
        raise SceneError(f"{source}: section POINTS has no rows")
    if not mdlines:
        raise SceneError(f"{source}: section LINES has no rows")
    options = _options(source, lines, sections, notes, dropped)
    channels = tuple(_outputs(lines, sections))

    density = options.get("wtrdnsty", options.get("rho", 1025.0))
    gravity = options.get("g", options.get("gravity", 9.80665))
    depth, seabed = _seabed(source, options, points, notes, dropped)
    current, profile, waves = _water(path, options, depth, notes)
    water = Water(
        density=density,
        gravity=gravity,
        depth=depth,
        current=current,
        current_profile=profile,
        waves=waves,
        free_surface=True,  # MoorDyn counts only the submerged part of each segment
        seabed=seabed,
    )
    run = RunSettings(
        dt_out=options.get("dtout") or None,
        mass_matrix="lumped",
        hydrodynamics="nodes",  # MoorDyn lumps drag and added mass at the nodes
        statics="tmaxic" not in options,
        **_stepping(options, notes),
    )
    notes = [note for _, note in dropped] + notes
    scene = Scene(points, line_types, mdlines, water, run, (), tuple(notes), source, _title(lines), tuple(dropped))
    return ParsedScene(_with_outputs(scene, channels), bodies)


def _find_sections(lines: list[str]) -> dict[str, int]:
    """Map each section found to the index of its header line."""
    found = {}
    for i, line in enumerate(lines):
        if "---" not in line:
            continue
        upper = line.upper()
        for name, aliases in _SECTIONS:
            if any(alias in upper for alias in aliases):
                found.setdefault(name, i)
                break
    return found


def _check_heading_rows(source: str, lines: list[str], header: int, name: str) -> None:
    """Refuse a table section whose two rows after its `---` header, which MoorDyn
    skips as the column names and the units, hold a row of data: MoorDyn would skip
    that row of data without a word."""
    heading = [lines[k].split() if k < len(lines) and "---" not in lines[k] else None for k in (header + 1, header + 2)]
    for offset, fields in enumerate(heading, start=1):
        if fields is None:
            return
        if not _is_data_row(fields):
            continue
        if offset == 1:
            what = "rows of column names and units (such as 'ID  LineType ...' and '(#)  (name) ...') are"
        elif _is_units_row(heading[0] or []):
            what = "row of column names (such as 'ID  LineType  AttachA ...') is"
        else:
            what = "row of units (such as '(#)  (name)  (#) ...') is"
        raise SceneError(
            f"{source}, line {header + offset + 1}: section {name}'s {what} missing: MoorDyn reads the two "
            f"rows after a section's header as its column names and units, so it would skip this row of "
            f"data, {' '.join(fields)!r}"
        )


def _is_units_row(fields: list[str]) -> bool:
    """Whether a row holds units: a field in parentheses or brackets, `(m)` or `[m]`."""
    return any(f.startswith(("(", "[")) for f in fields)


def _is_data_row(fields: list[str]) -> bool:
    """Whether a row is data, not names or units: not units, and its first field a
    number (a point's or line's ID) or, for a line type named by a word, its second."""
    return not _is_units_row(fields) and any(is_number(f) for f in fields[:2])


def _rows(lines: list[str], sections: dict[str, int], name: str) -> list[tuple[int, list[str]]]:
    """The non-blank rows of a section as `(line number, fields)`, up to the next `---`."""
    if name not in sections:
        return []
    start = sections[name] + (1 if name in ("OPTIONS", "OUTPUTS") else 3)
    rows = []
    for i in range(start, len(lines)):
        if "---" in lines[i]:
            break
        fields = lines[i].split()
        if fields:
            rows.append((i + 1, fields))
    return rows


def _number(source: str, line: int, column: str, token: str) -> float:
    try:
        value = float(token)
    except ValueError:
        raise SceneError(f"{source}, line {line}, column {column}: {token!r} is not a number") from None
    if not math.isfinite(value):
        raise SceneError(f"{source}, line {line}, column {column}: {token!r} is not a finite number")
    return value


def _require(source: str, line: int, fields: list[str], columns: tuple[str, ...], section: str) -> None:
    if len(fields) < len(columns):
        raise SceneError(
            f"{source}, line {line}: a {section} row needs {len(columns)} fields ({' '.join(columns)}), "
            f"got {len(fields)}"
        )


def _line_type(source: str, line: int, fields: list[str], dropped: list[tuple[str, str]]) -> LineTypeSpec:
    _require(source, line, fields, _LINE_TYPE_COLUMNS, "LINE TYPES")
    where = f"{source}, line {line}"
    name, diameter, mass, ea, ba, ei = fields[:6]
    if "|" in ea or "|" in ba or ea.upper().startswith("SYROPE:"):
        raise SceneError(f"{where}, column EA/BA: viscoelastic or Syrope models ({ea} / {ba}) are not supported")
    for column, token in (("EA", ea), ("BA/-zeta", ba)):
        if not is_number(token):
            raise SceneError(
                f"{where}, column {column}: {token!r} is a lookup table or not a number; nonlinear "
                "tables are not supported (give a constant)"
            )
    if not is_number(ei):
        dropped.append(
            (
                "EI",
                f"{where}: line type {name}: bending stiffness table {ei!r} ignored (jaxcable models a "
                "constant EI; give one to keep bending)",
            )
        )
    values = {c: _number(source, line, c, t) for c, t in zip(_LINE_TYPE_COLUMNS[6:], fields[6:10])}
    for k, token in enumerate(fields[10:]):
        column = f"{11 + k} ({_EXTRA_LINE_TYPE_COLUMNS[k]})" if k < len(_EXTRA_LINE_TYPE_COLUMNS) else str(11 + k)
        if _number(source, line, column, token) != 0:
            raise SceneError(
                f"{where}, column {column}: {token} — vortex-induced vibration and the other columns after "
                "CaAx are not supported"
            )
    damping = _number(source, line, "BA/-zeta", ba)
    with located(where):
        return LineTypeSpec(
            name=name,
            mass_per_length=_number(source, line, "Mass/m", mass),
            diameter=_number(source, line, "Diam", diameter),
            axial_stiffness=_number(source, line, "EA", ea),
            axial_damping=max(damping, 0.0),
            axial_damping_ratio=max(-damping, 0.0),
            normal_drag=values["Cd"],
            tangential_drag=values["CdAx"],
            normal_added_mass=values["Ca"],
            tangential_added_mass=values["CaAx"],
            slack_damping=True,
            bending_stiffness=_number(source, line, "EI", ei) if is_number(ei) else 0.0,
            where=where,
        )


def _point(source: str, line: int, fields: list[str], index: int) -> tuple[PointSpec, EnginePart | None]:
    """The point of a POINTS row, and its body's part, if it has one."""
    _require(source, line, fields, _POINT_COLUMNS, "POINTS")
    where = f"{source}, line {line}"
    columns = _POINT_FORCE_COLUMNS if len(fields) >= len(_POINT_FORCE_COLUMNS) else _POINT_COLUMNS
    values = {c: t for c, t in zip(columns, fields)}
    if not values["ID"].isdigit() or int(values["ID"]) != index + 1:
        raise SceneError(
            f"{where}, column ID: point IDs must run 1, 2, 3, ...; expected {index + 1}, got {values['ID']!r}"
        )
    leading = re.match(r"[A-Za-z]*", values["Type"])
    assert leading is not None  # the pattern matches every string, if only by its empty prefix
    kind_word = leading.group(0).upper()
    if kind_word == "BODY":
        raise SceneError(
            f"{where}, column Type: {values['Type']!r} attaches the point to a 6-DOF body, which jaxcable does not "
            "model"
        )
    kinds = [k for k, words in _POINT_KINDS.items() if kind_word in words]
    if not kinds:
        known = ", ".join(w.capitalize() for words in _POINT_KINDS.values() for w in words)
        raise SceneError(f"{where}, column Type: unknown point type {values['Type']!r}; expected one of {known}")
    number = {c: _number(source, line, c, values[c]) for c in columns[2:]}
    forces = [number.get(c, 0.0) for c in ("FX", "FY", "FZ")]
    if any(forces) and kinds[0] != "free":
        raise SceneError(
            f"{where}, columns FX FY FZ: constant forces {forces} on a {kinds[0]} point act on nothing that moves"
        )
    body = None
    if any(number[c] for c in ("Mass", "Volume", "CdA", "Ca")) or any(forces):
        make = functools.partial(
            make_body,
            mass=number["Mass"],
            volume=number["Volume"],
            drag_area=number["CdA"],
            added_mass=number["Ca"],
            force=forces,
        )
        body = EnginePart(make, where, index, "body")
    position = (number["X"], number["Y"], number["Z"])
    return PointSpec(str(index + 1), kinds[0], position, where=where), body


def _line(source: str, line: int, fields: list[str], index: int, n_points: int, type_names: list[str]) -> LineSpec:
    _require(source, line, fields, _LINE_COLUMNS, "LINES")
    where = f"{source}, line {line}"
    values = dict(zip(_LINE_COLUMNS, fields))
    if not values["ID"].isdigit() or int(values["ID"]) != index + 1:
        raise SceneError(
            f"{where}, column ID: line IDs must run 1, 2, 3, ...; expected {index + 1}, got {values['ID']!r}"
        )
    if values["LineType"] not in type_names:
        raise SceneError(f"{where}, column LineType: unknown line type {values['LineType']!r}; defined: {type_names}")
    ends = []
    for column in ("AttachA", "AttachB"):
        token = values[column]
        match = re.fullmatch(r"(?i)(C|CON|P|POINT)?(\d+)", token)
        if match is None:
            if re.fullmatch(r"(?i)(R|ROD)\d+[AB]?", token):
                raise SceneError(
                    f"{where}, column {column}: {token!r} attaches to a rod, which jaxcable does not model"
                )
            raise SceneError(f"{where}, column {column}: {token!r} is not a point (expected a number such as 1 or P1)")
        k = int(match.group(2))
        if not 1 <= k <= n_points:
            raise SceneError(f"{where}, column {column}: point {k} does not exist ({n_points} points are defined)")
        ends.append(k - 1)
    length = _number(source, line, "UnstrLen", values["UnstrLen"])
    if not length > 0:
        raise SceneError(f"{where}, column UnstrLen: the unstretched length must be positive, got {length:g}")
    if not values["NumSegs"].isdigit() or int(values["NumSegs"]) < 1:
        raise SceneError(f"{where}, column NumSegs: expected a positive integer, got {values['NumSegs']!r}")
    return LineSpec(str(index + 1), values["LineType"], ends[0], ends[1], length, int(values["NumSegs"]), where)


def _options(
    source: str, lines: list[str], sections: dict[str, int], notes: list[str], dropped: list[tuple[str, str]]
) -> dict[str, float]:
    """Numeric options jaxcable uses, by lower-case name, with `where` (the line of each,
    by the same name prefixed with `@`); the rest become notes, or `dropped` where they
    ask for physics jaxcable leaves out."""
    options = {}
    unneeded = {"jaxcable solves statics directly": [], "it sets MoorDyn's wave and current input": []}
    for line, fields in _rows(lines, sections, "OPTIONS"):
        if len(fields) < 2:
            continue
        value, name = fields[0], fields[1]
        key = name.lower()
        where = f"{source}, line {line}"
        if key == _SCHEME:
            options[key] = value
            options["@" + key] = f"{source}, line {line}"
        elif key in _STEP:
            options["dtm"] = step = _number(source, line, name, value)
            options["@dtm"] = f"{source}, line {line}"
            if not step > 0:
                raise SceneError(f"{source}, line {line}: option {name} must be positive, got {value}")
        elif key in _USED:
            options[key] = number = _number(source, line, name, value)
            options["@" + key] = where
            if not (number >= 0 if _USED[key] != "positive" else number > 0):
                raise SceneError(f"{where}: option {name} must be {_USED[key]}, got {value}")
        elif key == "seafloorfile":
            dropped.append(
                (
                    "bathymetry",
                    f"{where}: option {name} = {value} ignored (a bathymetry file; jaxcable's seabed is flat "
                    "at WtrDpth)",
                )
            )
        elif key in _WAVES:
            if is_number(value) and float(value) == 0:
                continue
            if key == "wavekin" and is_number(value) and float(value) == 1:
                # Kinematics a coupled program hands MoorDyn: a standalone run has none.
                notes.append(
                    f"{where}: option {name} = {value}: wave kinematics come from a coupled program, so a "
                    "standalone run, MoorDyn's or jaxcable's, is in still water"
                )
            elif key in _WATER_MODES and is_number(value) and float(value) in _WATER_MODES[key]:
                options[key] = int(float(value))  # read by `_water`
                options["@" + key] = where
            elif key in _WATER_MODES:
                kind = "waves" if key == "wavekin" else "currents"
                honoured = ", ".join(f"{mode:g}" for mode in _WATER_MODES[key])
                dropped.append(
                    (
                        kind,
                        f"{where}: option {name} = {value} ignored (jaxcable reads {name} = {honoured} only; "
                        f"no {kind})",
                    )
                )
            elif key == "dtwave":
                options[key] = _number(source, line, name, value)
                options["@" + key] = where
            else:
                unneeded["it sets MoorDyn's wave and current input"].append(f"{name} = {value} (line {line})")
        elif key in _TMAXIC and is_number(value) and float(value) == 0:
            options["tmaxic"] = 0.0
            notes.append(
                f"{where}: option {name} = {value}: no statics; the run starts from the file's geometry at rest, "
                "lines on MoorDyn's initial catenary (or straight), as MoorDyn's does"
            )
        elif key in _NOT_APPLICABLE or key in _TMAXIC:
            unneeded["jaxcable solves statics directly"].append(f"{name} = {value} (line {line})")
        elif key not in _COSMETIC:
            notes.append(f"{where}: unknown option {name} = {value} ignored")
    # One note for each reason, however many options it covers.
    for why, found in unneeded.items():
        if found:
            notes.append(f"{source}: option{'s' if len(found) > 1 else ''} {', '.join(found)} not needed ({why})")
    return options


def _water(path: Path, options: dict, depth, notes: list[str]):
    """The current and waves of MoorDyn's water files beside `path`, for the `Currents`
    and `WaveKin` options `_options` kept (see `jaxcable.io._moordyn_water`)."""
    folder = path.parent
    current, profile, waves = (0.0, 0.0, 0.0), None, ()
    if "currents" in options:
        with _located_at(options["@currents"]):
            current, profile = moordyn_water.current_profile(folder / "current_profile.txt")
        notes.append(f"{options['@currents']}: Currents = 1, the steady profile of {folder / 'current_profile.txt'}")
    mode = options.get("wavekin")
    if mode is not None:
        if depth is None:
            raise SceneError(f"{options['@wavekin']}: WaveKin = {mode} needs the water depth: give WtrDpth")
        with _located_at(options["@wavekin"]):
            if mode == 3:
                step = options.get("dtwave", 0.25)  # MoorDyn's default dtWave
                wave, more = moordyn_water.elevation_record(folder / "wave_elevation.txt", step)
            else:
                wave, more = moordyn_water.spectrum(folder / "wave_frequencies.txt", mode)
        waves = (wave,)
        notes.extend(more)
        notes.append(f"{options['@wavekin']}: WaveKin = {mode}: {wave.describe()}")
    return current, profile, waves


@contextlib.contextmanager
def _located_at(where: str):
    """Prefix a `SceneError` raised inside with the option's place in the input file."""
    try:
        yield
    except SceneError as error:
        raise SceneError(f"{where}: {error}") from None


def _stepping(options: dict, notes: list[str]) -> dict:
    """The run settings for MoorDyn's `dtM` and `tScheme` (see `_SCHEMES`): fixed steps
    of dtM, or without a dtM none (the scene's default, `auto`); a note says what runs."""
    if "dtm" not in options:
        return {}
    step, scheme = options["dtm"], options.get(_SCHEME, "RK2")
    solver = _SCHEMES.get(scheme.lower(), "midpoint")
    where = options["@dtm"]
    if scheme.lower() in _SCHEMES:
        how = f"tScheme {scheme}: {solver}"
    else:
        how = f"tScheme {scheme}, which jaxcable does not have: {solver}, MoorDyn's RK2, instead"
    notes.append(
        f"{where}: fixed steps of dtM = {step:g} s, {how} (jaxcable run --adaptive steps adaptively "
        "instead; a step beyond the method's stability limit here is replaced by RK4 at a stable step, with a "
        "warning)"
    )
    return {"dt": step, "solver": solver}


def _seabed(source, options, points, notes, dropped) -> tuple[float | None, SeabedSpec | None]:
    """The water depth and MoorDyn's seabed (module docstring)."""
    depth = options.get("wtrdpth", 0.0)
    deepest = min(range(len(points)), key=lambda k: points[k].position[2])
    lowest = -points[deepest].position[2]
    if lowest > depth:
        point = points[deepest]
        stated = f"WtrDpth = {depth:g} m" if "wtrdpth" in options else "no WtrDpth"
        notes.append(
            f"{point.where}: {stated}, but point {point.name} is at z = {-lowest:g} m: MoorDyn then sets the water "
            f"depth to {lowest:g} m, with its seabed there, and so does jaxcable"
        )
        depth = lowest
    if not depth > 0:
        notes.append(f"{source}: no water depth and no point below z = 0: no seabed")
        return None, None

    def given(*keys, default):
        for key in keys:
            if key in options:
                return options[key], options["@" + key]
        return default, None

    stiffness, where_k = given("kbot", "kb", default=_KBOT)
    damping, where_c = given("cbot", "cb", default=_CBOT)
    friction, where_f = given("frictioncoefficient", default=0.0)
    fricdamp, _ = given("fricdamp", default=_FRICDAMP)
    scale, where_s = given("statdynfricscale", default=1.0)
    where = where_k or where_c or where_f or options.get("@wtrdpth") or source
    if scale != 1:
        dropped.append(
            (
                "friction",
                f"{where_s}: option StatDynFricScale = {scale:g} ignored (jaxcable's friction has one coefficient, "
                "without a static-to-dynamic ratio)",
            )
        )
    # `_options` checked the values as the engine's Seabed does; it is made with the scene.
    seabed = SeabedSpec(stiffness, damping, friction, SeabedSpec().friction_speed, where, friction_damping=fricdamp)
    return depth, seabed


def _with_outputs(scene: Scene, names: tuple[str, ...]) -> Scene:
    """`scene` with the channels of its `OUTPUTS` that jaxcable writes; each other name
    skipped with one note, as MoorDyn skips a name it cannot read (an OpenFAST file's
    `Con4Fx` and `Line1NBPZ` are read). A channel naming a line, node or point that does
    not exist is refused, as MoorDyn refuses it."""
    kept, skipped = [], []
    for name in names:
        try:
            parse_channel(name, scene)
        except UnknownChannel:
            skipped.append(name)
        else:
            kept.append(name)
    notes = scene.notes
    if skipped:
        notes += (
            f"{scene.source}: OUTPUTS {', '.join(skipped)} skipped: jaxcable does not write "
            f"{'it' if len(skipped) == 1 else 'them'} (accelerations, rods, bodies and TA/TB/SUB are not modelled)",
        )
    return dataclasses.replace(scene, channels=tuple(kept), notes=notes)


def _outputs(lines: list[str], sections: dict[str, int]):
    """Channel names listed in the OUTPUTS section, up to `END`."""
    for _, fields in _rows(lines, sections, "OUTPUTS"):
        for token in fields:
            if token.upper() == "END":
                return
            yield token


def _title(lines: list[str]) -> str:
    """The first line of text before the first section: MoorDyn files describe
    themselves there."""
    for line in lines:
        if "---" in line and any(alias in line.upper() for _, aliases in _SECTIONS for alias in aliases):
            break
        if line.strip() and "---" not in line:
            return line.strip()
    return ""
