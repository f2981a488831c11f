"""The files that hold a run's output channels (named in `_channels`), and the run as
an `xarray.Dataset`.

Files: `.csv` (comma-separated, one header row of names), `.out` or `.txt` (MoorDyn's
layout: whitespace-separated, a row of names and a row of units), and `.npz` or `.nc`,
which hold everything (all node positions and velocities, segment tensions, support
reactions, the channels) with units in the attributes.
"""

import json
import os
from pathlib import Path

import numpy as np

from ._channels import channel_units
from ._run import SceneRun
from ._scene import SceneError

TABLE_SUFFIXES = (".csv", ".out", ".txt")
ARCHIVE_SUFFIXES = (".npz", ".nc")


def check_writable(path: str | Path, what: str, suffixes: tuple[str, ...] | None = None) -> Path:
    """`path`, once it is known that a file can be written there: before a run, so that
    a typo costs nothing.

    **Arguments:**

    - `path`: the file to write.
    - `what`: how messages name it (`"--out"`, `"output file"`).
    - `suffixes`: the formats allowed, lower-case with the dot; any if `None`.

    **Raises:**

    [`jaxcable.io.SceneError`][] naming `what` and the path for an unknown suffix, a
    path that is a folder, or a folder that does not exist or cannot be written in.
    """
    path = Path(path)
    if path.is_dir():
        raise SceneError(f"{what} {path}: is a folder; give a file name in it")
    suffix = path.suffix.lower()
    if suffixes is not None and suffix not in suffixes:
        raise SceneError(f"{what} {path}: unknown format {suffix or '(no suffix)'!r}; use one of {suffixes}")
    folder = path.parent
    if not folder.is_dir():
        raise SceneError(f"{what} {path}: the folder {folder} does not exist")
    if not os.access(folder, os.W_OK) or (path.exists() and not os.access(path, os.W_OK)):
        raise SceneError(f"{what} {path}: cannot write there (permission denied)")
    return path


def check_output(path: str | Path, what: str = "output file") -> Path:
    """[`check_writable`][jaxcable.io._output.check_writable] for `write`'s formats, and
    scipy present for `.nc`."""
    path = check_writable(path, what, TABLE_SUFFIXES + ARCHIVE_SUFFIXES)
    if path.suffix.lower() == ".nc":
        _netcdf_file(path)
    return path


def _netcdf_file(path: Path):
    try:
        from scipy.io import netcdf_file
    except ImportError:
        raise SceneError(f"writing {path.name} (NetCDF) needs scipy: pip install scipy, or write .npz") from None
    return netcdf_file


def write(path: str | Path, run: SceneRun, names: tuple[str, ...] = ()) -> Path:
    """Write `run` to `path`; the suffix picks the format (see the module docstring).

    **Raises:**

    [`jaxcable.io.SceneError`][] for an unknown suffix, a folder that does not exist,
    a path that is a folder, or `.nc` without scipy (`check_output`).
    """
    path = check_output(path)
    suffix = path.suffix.lower()
    values = _channel_values(run, names)
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


def dataset(run: SceneRun, names: tuple[str, ...] = (), start: float = 0.0):
    """`run` as an `xarray.Dataset` (see [`jaxcable.io.SceneRun.to_dataset`][]): the
    `.nc` file's variables, with `time`, `xyz` and `line` as coordinates, and each line's
    extremes from `start` (s) along `line` (`SceneRun.line_extremes`; NaN where a line
    type gives no minimum breaking load)."""
    try:
        import xarray as xr
    except ImportError:
        raise ImportError('SceneRun.to_dataset needs xarray: pip install xarray (or "jaxcable[xarray]")') from None
    variables = _archive_variables(run, _channel_values(run, names))
    data = {
        name: xr.Variable(dims, np.asarray(values), attrs={"units": unit, "long_name": description})
        for name, (values, dims, unit, description) in variables.items()
        if name != "time"
    }
    rows = run.line_extremes(start)
    per_line = {
        "largest_tension": ("N", "each line's largest segment tension", [r.largest for r in rows]),
        "largest_tension_time": ("s", "when each line's largest tension was", [r.largest_time for r in rows]),
        "largest_tension_segment": ("1", "its segment, from end A, from 1", [r.largest_segment for r in rows]),
        "smallest_tension": ("N", "each line's smallest segment tension", [r.smallest for r in rows]),
        "smallest_tension_time": ("s", "when each line's smallest tension was", [r.smallest_time for r in rows]),
        "end_a_largest_tension": ("N", "the largest tension of each line's end A segment", [r.end_a for r in rows]),
        "end_b_largest_tension": ("N", "the largest tension of each line's end B segment", [r.end_b for r in rows]),
        "minimum_breaking_load": ("N", "each line type's MBL", [r.breaking_load or np.nan for r in rows]),
        "utilisation": (
            "1",
            "largest tension / MBL",
            [np.nan if r.utilisation is None else r.utilisation for r in rows],
        ),
    }
    for name, (unit, description, values) in per_line.items():
        data[name] = xr.Variable(("line",), np.asarray(values), attrs={"units": unit, "long_name": description})
    coords = {
        "time": xr.Variable(("time",), np.asarray(run.times), attrs={"units": "s", "long_name": "output time"}),
        "xyz": ["x", "y", "z"],
        "line": [line.name for line in run.built.scene.lines],
    }
    scene = run.built.scene
    attrs = {"title": f"jaxcable run of {scene.source}" + (f": {scene.title}" if scene.title else "")}
    if run.stepping:
        attrs["stepping"] = run.stepping
    return xr.Dataset(data, coords=coords, attrs=attrs)


def _channel_values(run: SceneRun, names: tuple[str, ...]) -> dict[str, np.ndarray]:
    """The output channels by name, `Time` first (`SceneRun.channels`)."""
    # + 0.0 turns the −0.0 of a slack segment (negative strain times a zero switch) into 0.
    return {name: series + 0.0 for name, series in run.channels(names).items()}


def _write_moordyn_table(path: Path, values: dict[str, np.ndarray]) -> None:
    width = max(14, *(len(n) + 2 for n in values))
    with path.open("w") as f:
        f.write("".join(f"{n:>{width}}" for n in values) + "\n")
        f.write("".join(f"{'(' + channel_units(n) + ')':>{width}}" for n in values) + "\n")
        for row in np.column_stack(list(values.values())):
            f.write("".join(f"{v:>{width}.6e}" for v in row) + "\n")


def _archive_variables(run: SceneRun, values: dict[str, np.ndarray]) -> dict:
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


def _write_netcdf(path: Path, run: SceneRun, variables: dict) -> None:
    netcdf_file = _netcdf_file(path)
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
