"""A campaign's case table: what varies from one load case to the next, read and checked
before any work ([`jaxcable.read_cases`][]), and each case's scene (`case_scene`).
Plain Python and numpy: a table is refused before JAX is imported."""

import csv
import dataclasses
import math
import re
import tomllib
from pathlib import Path

import numpy as np

from ..io._parse import read_text
from ..io._scene import Scene, SceneError, SeaStateSpec, WaveSpec

SEA_STATE = ("significant_height", "peak_period", "peak_enhancement", "seed", "spreading")
REGULAR_WAVE = {"wave_height": "height", "wave_period": "period"}
CURRENT = ("current_speed", "current_heading")
PER_LINE = ("length", "type")
COLUMNS = (
    "case",
    *SEA_STATE,
    "heading",
    *REGULAR_WAVE,
    *CURRENT,
    *(f"{c}.NAME" for c in PER_LINE),
    "removed",
    "motion",
)
"""The columns a case table may have (`.NAME` columns name a line of the scene)."""

_TEXT = ("case", "removed", "motion")  # columns whose values are text, not numbers


@dataclasses.dataclass(frozen=True)
class Case:
    """One row of a case table.

    - `name`: the case's name (its `case` column, or `case0001`... by row).
    - `values`: what the row sets, by column: numbers (float; `seed` an int) or text
        (`type.NAME`, `removed`, `motion`); the columns it leaves empty are absent.
    - `where`: the file and row, for messages.
    """

    name: str
    values: dict[str, float | int | str]
    where: str


def read_cases(path: str | Path) -> tuple[Case, ...]:
    """Read a case table: a CSV file, one case a row under a header of column names, or a
    TOML file with one `[[case]]` table a case (`length = {w = 90}` is the column
    `length.w`). A cell left empty (CSV) or a key left out (TOML) keeps the scene's
    own value. The columns (`.NAME` columns name a line of the scene):

    - `case`: the case's name, unique, used for its result file; `case0001`, `case0002`,
      ... by row where there is no such column.
    - The sea state, applied to every irregular sea of the scene (`[[waves]]` with a
      `spectrum`): `significant_height` (m), `peak_period` (s), `peak_enhancement` (–),
      `seed` (an integer), `spreading` (the cos-2s exponent); `heading` (degrees) applies to
      every wave of the scene, regular or irregular.
    - A regular wave, applied to every regular wave of the scene: `wave_height` (m),
      `wave_period` (s).
    - The current: `current_speed` (m/s) and `current_heading` (degrees, from +x towards
      +y). A uniform current becomes that speed along that heading (horizontal); a current
      profile keeps its shape, scaled so that its fastest speed is `current_speed`.
    - A line: `length.NAME` (m, unstretched), `type.NAME` (a line type the scene defines).
    - The damaged case: `removed`, the names of the lines taken out, separated by spaces or
      `;` (empty: intact). Points that only a removed line joined go too.
    - `motion`: a table of `time x y z` for each coupled point (as `jaxcable run --motion`),
      relative to the case table's folder.

    **Raises:**

    [`jaxcable.io.SceneError`][], naming the file, row and column, for an unknown
    column, a value that is not a number where one is needed (or not finite, or a seed
    that is not a whole number), a repeated case name, or a table with no cases.
    """
    path = Path(path)
    text = read_text(path, "case table")
    if path.suffix.lower() == ".toml":
        rows = _toml_rows(path, text)
    else:
        rows = _csv_rows(path, text)
    if not rows:
        raise SceneError(f"{path}: the case table has no cases")
    cases, seen = [], {}
    for number, (where, row) in enumerate(rows, start=1):
        values = {}
        for column, given in row.items():
            _check_column(column, where)
            if isinstance(given, str) and not given.strip():
                continue  # an empty cell keeps the scene's value
            values[column] = _value(column, given, where)
        name = str(values.pop("case", f"case{number:04d}"))
        if not re.fullmatch(r"[A-Za-z0-9_.+-]+", name):
            raise SceneError(
                f"{where}: case name {name!r} must be letters, digits and _ . + - only (it names the case's file)"
            )
        if name in seen:
            raise SceneError(f"{where}: case {name!r} is named already, at {seen[name]}")
        seen[name] = where
        cases.append(Case(name, values, where))
    return tuple(cases)


def _csv_rows(path: Path, text: str) -> list[tuple[str, dict]]:
    reader = csv.reader(line for line in text.splitlines() if line.strip() and not line.lstrip().startswith("#"))
    try:
        header = [name.strip() for name in next(reader)]
    except StopIteration:
        raise SceneError(f"{path}: the case table is empty") from None
    for k, name in enumerate(header):
        if not name:
            raise SceneError(f"{path}: column {k + 1} of the header has no name")
        if header.index(name) != k:
            raise SceneError(f"{path}: column {name!r} appears twice in the header")
    rows = []
    for number, fields in enumerate(reader, start=1):
        where = f"{path}, case row {number}"
        if len(fields) != len(header):
            raise SceneError(f"{where}: {len(fields)} fields under a header of {len(header)} columns")
        rows.append((where, dict(zip(header, (f.strip() for f in fields)))))
    return rows


def _toml_rows(path: Path, text: str) -> list[tuple[str, dict]]:
    try:
        data = tomllib.loads(text)
    except tomllib.TOMLDecodeError as error:
        raise SceneError(f"{path}: not valid TOML: {error}") from None
    unknown = set(data) - {"case"}
    if unknown:
        raise SceneError(f"{path}: unknown table(s) {sorted(unknown)}; a case table has [[case]] tables only")
    tables = data.get("case", [])
    if not isinstance(tables, list):
        raise SceneError(f"{path}: 'case' must be an array of tables, [[case]]")
    rows = []
    for number, table in enumerate(tables, start=1):
        flat = {}
        for key, value in table.items():  # `length = {tether = 40}` is `length.tether`
            if isinstance(value, dict):
                flat.update({f"{key}.{name}": v for name, v in value.items()})
            else:
                flat[key] = value
        rows.append((f"{path}, [[case]] {number}", flat))
    return rows


def _check_column(column: str, where: str) -> None:
    head, dot, tail = column.partition(".")
    known = head in PER_LINE and dot and tail if dot else column in COLUMNS
    if not known:
        raise SceneError(f"{where}: unknown column {column!r}; the columns a case table may have: {', '.join(COLUMNS)}")


def _value(column: str, given, where: str) -> float | int | str:
    """`given` as the column's value: text for text columns, else a finite number."""
    if column in _TEXT or column.startswith("type."):
        if not isinstance(given, str):
            raise SceneError(f"{where}: {column} must be text, got {given!r}")
        return given.strip()
    try:
        number = float(given) if not isinstance(given, bool) else math.nan
    except (TypeError, ValueError):
        number = math.nan
    if not math.isfinite(number):
        raise SceneError(f"{where}: {column} must be a finite number, got {given!r}")
    if column == "seed":
        if number != int(number) or number < 0:
            raise SceneError(f"{where}: seed must be a whole number from 0, got {given!r}")
        return int(number)
    return number


def case_scene(scene: Scene, case: Case, folder: Path, motion: bool = True) -> Scene:
    """`scene` as `case` sets it; motion tables are read relative to `folder`. Without
    `motion`, a case's motion table is read and checked against the coupled points but
    not made into the points' motions (which needs JAX), for a check before JAX starts.

    **Raises:**

    [`jaxcable.io.SceneError`][] at the case's row for a column the scene cannot take:
    a sea-state column on a scene without an irregular sea, a wave column on one
    without such a wave, a line or line type it does not define, a motion table that
    does not fit its coupled points.
    """
    values = dict(case.values)
    scene = _waves(scene, values, case.where)
    scene = _current(scene, values, case.where)
    scene = _lines(scene, values, case.where)
    if "motion" in values:
        from ..io import read_motion_file

        path = folder / str(values["motion"])
        coupled = scene.coupled_points
        if not coupled:
            raise SceneError(f"{case.where}: motion {path}: the scene has no coupled points to move")
        try:
            times, positions = read_motion_file(path, len(coupled))
        except SceneError as error:
            raise SceneError(f"{case.where}: motion: {error}") from None
        if motion:
            scene = scene.with_motion_table(times, positions, f"{case.where}, motion {path}")
    return scene


def _waves(scene: Scene, values: dict, where: str) -> Scene:
    waves = list(scene.water.waves)
    sea = {c: values[c] for c in SEA_STATE if c in values}
    regular = {REGULAR_WAVE[c]: values[c] for c in REGULAR_WAVE if c in values}
    if sea and not any(isinstance(w, SeaStateSpec) for w in waves):
        raise SceneError(
            f"{where}: {', '.join(sea)} set(s) an irregular sea, but the scene has none ([[waves]] spectrum)"
        )
    if regular and not any(isinstance(w, WaveSpec) for w in waves):
        raise SceneError(
            f"{where}: {', '.join(c for c in REGULAR_WAVE if c in values)} set(s) a regular wave, "
            "but the scene has none"
        )
    if "heading" in values and not waves:
        raise SceneError(f"{where}: heading sets the waves' direction, but the scene has no waves")
    for k, wave in enumerate(waves):
        changes = {}
        if isinstance(wave, SeaStateSpec):
            changes.update(sea)
        if isinstance(wave, WaveSpec):
            changes.update(regular)
            if "height" in regular:
                changes["steepness"] = None  # a height in place of the scene's steepness
        if "heading" in values and hasattr(wave, "heading"):
            changes["heading"] = values["heading"]
        if changes:
            waves[k] = dataclasses.replace(wave, **changes, where=f"{where} (on {wave.where})")
    return scene.replace(water=dataclasses.replace(scene.water, waves=tuple(waves)))


def _current(scene: Scene, values: dict, where: str) -> Scene:
    if not any(c in values for c in CURRENT):
        return scene
    water = scene.water
    profile = water.current_profile
    if profile is not None:
        speeds = np.asarray(profile.speeds, dtype=float)
        fastest = float(np.max(np.abs(speeds)))
        if "current_speed" in values and fastest == 0:
            raise SceneError(f"{where}: current_speed scales the scene's current profile, whose speeds are all 0")
        scale = values["current_speed"] / fastest if "current_speed" in values else 1.0
        changed = dataclasses.replace(
            profile,
            speeds=tuple(float(s) for s in scale * speeds),
            heading=float(values.get("current_heading", profile.heading)),
        )
        return scene.replace(water=dataclasses.replace(water, current_profile=changed))
    current = np.asarray(water.current, dtype=float)
    speed = values.get("current_speed", float(np.hypot(current[0], current[1])))
    heading = values.get("current_heading", float(np.degrees(np.arctan2(current[1], current[0]))))
    angle = np.radians(heading)
    vector = (float(speed * np.cos(angle)), float(speed * np.sin(angle)), float(current[2]))
    return scene.replace(water=dataclasses.replace(water, current=vector))


def _lines(scene: Scene, values: dict, where: str) -> Scene:
    names = [line.name for line in scene.lines]
    types = [t.name for t in scene.line_types]
    lines = list(scene.lines)
    for column, value in values.items():
        head, _, name = column.partition(".")
        if head not in PER_LINE:
            continue
        if name not in names:
            raise SceneError(f"{where}: {column}: the scene has no line {name!r}; its lines: {', '.join(names)}")
        k = names.index(name)
        if head == "length":
            if not value > 0:
                raise SceneError(f"{where}: {column} must be a positive length (m), got {value:g}")
            lines[k] = dataclasses.replace(lines[k], length=float(value))
        else:
            if value not in types:
                raise SceneError(
                    f"{where}: {column}: the scene has no line type {value!r}; its types: {', '.join(types)}"
                )
            lines[k] = dataclasses.replace(lines[k], line_type=str(value))
    removed = [n for n in re.split(r"[;\s]+", str(values.get("removed", ""))) if n]
    for name in removed:
        if name not in names:
            raise SceneError(f"{where}: removed: the scene has no line {name!r}; its lines: {', '.join(names)}")
    if not removed:
        return scene.replace(lines=tuple(lines))
    kept = [line for line in lines if line.name not in removed]
    if not kept:
        raise SceneError(f"{where}: removed takes out every line of the scene")
    # Points that only removed lines joined go with them; the rest are renumbered.
    used = sorted({k for line in kept for k in (line.start, line.end)})
    number = {old: new for new, old in enumerate(used)}
    points = tuple(scene.points[k] for k in used)
    kept = [dataclasses.replace(line, start=number[line.start], end=number[line.end]) for line in kept]
    return scene.replace(points=points, lines=tuple(kept))
