"""Output channels with MoorDyn's names, and the files that hold them.

Channels (names are case-insensitive on input, written as below):

- `Time` (s).
- `FairTen<k>`, `AnchTen<k>` (N): the tension in the segment at end B and at end A of
    line k, as MoorDyn defines them (the end segment's tension, damping included).
- `L<k>N<i>PX`, `PY`, `PZ` (m): the position of node i of line k, i = 0 at end A.
- `L<k>N<i>T` (N): the tension at node i, the mean of the adjacent segments' (the end
    segment's at an end), as MoorDyn's.

Files: `.csv` (comma-separated, one header row of names), `.out` or `.txt` (MoorDyn's
layout: whitespace-separated, a row of names and a row of units), and `.npz` or `.nc`,
which hold everything (all node positions and velocities, segment tensions, support
reactions, the channels) with units in the attributes.
"""

import json
import re
from pathlib import Path
from typing import TYPE_CHECKING

import numpy as np

from ._scene import SceneError

if TYPE_CHECKING:
    from ._run import SceneRun
    from ._scene import Scene

TABLE_SUFFIXES = (".csv", ".out", ".txt")
ARCHIVE_SUFFIXES = (".npz", ".nc")

_END_TENSION = re.compile(r"(?i)(fairten|anchten)(\d+)")
_NODE = re.compile(r"(?i)l(\d+)n(\d+)(px|py|pz|t)")


def default_channels(scene: "Scene") -> tuple[str, ...]:
    """The scene's own channels, or `FairTen<k>` and `AnchTen<k>` for every line."""
    if scene.channels:
        return tuple(scene.channels)
    return tuple(f"{kind}{k}" for k in range(1, len(scene.lines) + 1) for kind in ("FairTen", "AnchTen"))


def channel_units(name: str) -> str:
    """The unit of channel `name`: `s`, `N` or `m`."""
    if name == "Time":
        return "s"
    match = _NODE.fullmatch(name)
    return "m" if match and match.group(3).lower() != "t" else "N"


def parse_channel(name: str, scene: "Scene") -> tuple[str, str, int, int]:
    """`(canonical name, quantity, line index, node index)` of channel `name`, with
    quantity one of `FairTen`, `AnchTen`, `PX`, `PY`, `PZ`, `T` and indices from 0
    (node −1 for the end tensions).

    **Raises:**

    [`jaxcable.SceneError`][] naming a channel that is unknown or refers to a line or
    node that does not exist.
    """
    count = len(scene.lines)
    if match := _END_TENSION.fullmatch(name):
        kind = "FairTen" if match.group(1).lower() == "fairten" else "AnchTen"
        k = _line_index(name, int(match.group(2)), count)
        return f"{kind}{k + 1}", kind, k, -1
    if match := _NODE.fullmatch(name):
        k = _line_index(name, int(match.group(1)), count)
        i, quantity = int(match.group(2)), match.group(3).upper()
        last = scene.lines[k].segments
        if i > last:
            raise SceneError(f"output channel {name!r}: line {k + 1} has nodes 0 to {last}")
        return f"L{k + 1}N{i}{quantity}", quantity, k, i
    raise SceneError(
        f"unknown output channel {name!r}; jaxcable writes FairTen<k>, AnchTen<k>, "
        "L<k>N<i>PX / PY / PZ and L<k>N<i>T"
    )


def channels(run: "SceneRun", names: tuple[str, ...] = ()) -> dict[str, np.ndarray]:
    """Channel values over `run.times`, by name, `Time` first; `names` defaults to
    [`default_channels`][].

    **Raises:**

    [`jaxcable.SceneError`][], as [`parse_channel`][].
    """
    scene = run.built.scene
    values = {"Time": run.times}
    for name in tuple(names) or default_channels(scene):
        canonical, quantity, k, i = parse_channel(name, scene)
        nodes, segments = run.built.line_nodes[k], run.built.line_segments[k]
        if quantity in ("FairTen", "AnchTen"):
            values[canonical] = run.tension[:, segments[-1] if quantity == "FairTen" else segments[0]]
        elif quantity == "T":
            adjacent = segments[max(i - 1, 0) : min(i, segments.size - 1) + 1]
            values[canonical] = run.tension[:, adjacent].mean(axis=1)
        else:
            values[canonical] = run.positions[:, nodes[i], "XYZ".index(quantity[1])]
    return values


def _line_index(name: str, k: int, count: int) -> int:
    if not 1 <= k <= count:
        raise SceneError(f"output channel {name!r}: line {k} does not exist ({count} lines)")
    return k - 1


def write(path: str | Path, run: "SceneRun", names: tuple[str, ...] = ()) -> Path:
    """Write `run` to `path`; the suffix picks the format (see the module docstring).

    **Raises:**

    [`jaxcable.SceneError`][] for an unknown suffix, or `.nc` without scipy.
    """
    path = Path(path)
    suffix = path.suffix.lower()
    if suffix not in TABLE_SUFFIXES + ARCHIVE_SUFFIXES:
        raise SceneError(f"output file {path}: unknown format {suffix!r}; use one of {TABLE_SUFFIXES + ARCHIVE_SUFFIXES}")
    # + 0.0 turns the −0.0 of a slack segment (negative strain times a zero switch) into 0.
    values = {name: series + 0.0 for name, series in channels(run, names).items()}
    if suffix == ".csv":
        table = np.column_stack(list(values.values()))
        np.savetxt(path, table, delimiter=",", header=",".join(values), comments="", fmt="%.10g")
    elif suffix in (".out", ".txt"):
        _write_moordyn_table(path, values)
    else:
        variables = _archive_variables(run, values)
        if suffix == ".npz":
            units = {name: unit for name, (_, _, unit, _) in variables.items()}
            arrays = {name: data for name, (data, _, _, _) in variables.items()}
            np.savez(path, units=json.dumps(units), **arrays)
        else:
            _write_netcdf(path, run, variables)
    return path


def _write_moordyn_table(path: Path, values: dict[str, np.ndarray]) -> None:
    width = max(14, *(len(n) + 2 for n in values))
    with path.open("w") as f:
        f.write("".join(f"{n:>{width}}" for n in values) + "\n")
        f.write("".join(f"{'(' + channel_units(n) + ')':>{width}}" for n in values) + "\n")
        for row in np.column_stack(list(values.values())):
            f.write("".join(f"{v:>{width}.6e}" for v in row) + "\n")


def _archive_variables(run: "SceneRun", values: dict[str, np.ndarray]) -> dict:
    """Everything in a run: name → (data, dimensions, units, description)."""
    model = run.built.model
    variables = {
        "time": (run.times, ("time",), "s", "output time"),
        "positions": (run.positions, ("time", "node", "xyz"), "m", "node positions"),
        "velocities": (run.velocities, ("time", "node", "xyz"), "m/s", "node velocities"),
        "tension": (run.tension, ("time", "segment"), "N", "segment tension"),
        "reactions": (run.reactions, ("time", "constrained", "xyz"), "N", "force of each support on the network"),
        "constrained_nodes": (np.asarray(model.constrained_nodes), ("constrained",), "1", "node index of each support"),
        "segment_nodes": (np.asarray(model.segment_nodes), ("segment", "end"), "1", "the two nodes of each segment"),
        "segment_length": (np.asarray(model.segment_length), ("segment",), "m", "unstretched segment length"),
        "segment_line": (
            np.concatenate([np.full(s.size, k + 1) for k, s in enumerate(run.built.line_segments)]),
            ("segment",),
            "1",
            "the line (numbered from 1) each segment belongs to",
        ),
    }
    for name, data in values.items():
        if name != "Time":
            variables[name] = (data, ("time",), channel_units(name), "MoorDyn output channel")
    return variables


def _write_netcdf(path: Path, run: "SceneRun", variables: dict) -> None:
    try:
        from scipy.io import netcdf_file
    except ImportError:
        raise SceneError(f"writing {path.name} (NetCDF) needs scipy: pip install scipy, or write .npz") from None
    sizes = {}
    for data, dims, _, _ in variables.values():
        sizes.update(zip(dims, np.shape(data)))
    with netcdf_file(path, "w") as f:
        scene = run.built.scene
        title = f"jaxcable run of {scene.source}" + (f": {scene.title}" if scene.title else "")
        f.title = title.encode("ascii", "replace").decode()  # NetCDF 3 attributes are ASCII
        for dim, size in sizes.items():
            f.createDimension(dim, size)
        for name, (data, dims, unit, description) in variables.items():
            data = np.asarray(data)
            kind = "i4" if np.issubdtype(data.dtype, np.integer) else "f8"
            variable = f.createVariable(name, kind, dims)
            variable[...] = data
            variable.units = unit
            variable.long_name = description
