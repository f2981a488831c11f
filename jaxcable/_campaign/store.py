"""A campaign's folder: one netCDF file a finished case, written whole or not at all, and
the tables made from them.

    FOLDER/campaign.json       what the campaign is: the scene's and settings' fingerprint
    FOLDER/cases/NAME.nc       a finished case: its run (`SceneRun.to_dataset`), its
                               statistics, the case row, the software's version
    FOLDER/failed/NAME.txt     a case that failed, and why
    FOLDER/summary.csv         a row per case (`summary_rows`), and the failed ones
    FOLDER/groups.csv          a row per group of cases that differ only in their seed
                               (`group_rows`)

A case's file is written under a temporary name and renamed into place, so that a
campaign killed at any moment leaves every finished case whole and no half-written
one; a restart skips the cases whose files are there. Each file carries the digest of
the scene and settings it was run with and of its own case row: a restart with another
scene, other settings or another row under the same name is refused, so that no
result is overwritten and no table mixes two campaigns.
"""

import csv
import dataclasses
import hashlib
import json
import math
import os
from collections.abc import Sequence
from pathlib import Path
from typing import Any

import numpy as np

from ..io._scene import SceneError
from .cases import Case

CASES, FAILED = "cases", "failed"


def fingerprint(value: Any) -> Any:
    """A JSON-able description of a scene (or any tree of dataclasses, tuples, numbers,
    text and arrays) by its values: arrays by the digest of their bytes. Fields that
    only say where a value was written (`where`, `source`, `notes`, `title`) are left
    out, so that the same scene read from a moved or reordered file is the same."""
    if dataclasses.is_dataclass(value) and not isinstance(value, type):
        skip = {"where", "source", "notes", "title"}
        return {
            "type": type(value).__name__,
            **{f.name: fingerprint(getattr(value, f.name)) for f in dataclasses.fields(value) if f.name not in skip},
        }
    if isinstance(value, dict):
        return {str(k): fingerprint(v) for k, v in value.items()}
    if isinstance(value, (list, tuple)):
        return [fingerprint(v) for v in value]
    if isinstance(value, (str, bool, int)) or value is None:
        return value
    if isinstance(value, float):
        return repr(value)
    array = np.asarray(value)
    if array.dtype == object:
        raise TypeError(f"fingerprint: cannot describe {type(value).__name__}")
    return {"array": hashlib.sha256(np.ascontiguousarray(array).tobytes()).hexdigest(), "shape": list(array.shape)}


def digest(value: Any) -> str:
    """The SHA-256 of `fingerprint(value)`'s JSON."""
    return hashlib.sha256(json.dumps(fingerprint(value), sort_keys=True).encode()).hexdigest()


class Store:
    """The campaign's folder (see the module's notes).

    **Arguments:**

    - `folder`: the folder; made where absent.
    - `identity`: what the campaign is (the scene and settings), as a JSON-able
        mapping; a folder that holds another campaign is refused.
    - `create`: start a campaign in a folder that holds none; otherwise refuse it.

    **Raises:**

    [`jaxcable.io.SceneError`][] for a folder that holds another campaign, or a path
    that is not a folder.
    """

    def __init__(self, folder: str | Path, identity: dict, create: bool = True):
        self.folder = Path(folder)
        if self.folder.exists() and not self.folder.is_dir():
            raise SceneError(f"campaign folder {self.folder} is a file, not a folder")
        self.identity = identity
        self.key = hashlib.sha256(json.dumps(identity, sort_keys=True).encode()).hexdigest()
        marker = self.folder / "campaign.json"
        if not create and not marker.exists():
            raise SceneError(f"{self.folder} holds no campaign (no campaign.json): run one into it first")
        if marker.exists():
            held = json.loads(marker.read_text())
            if held.get("key") != self.key:
                raise SceneError(
                    f"campaign folder {self.folder} holds a campaign of another scene or other settings "
                    f"({held.get('describe', 'see its campaign.json')}); its results are kept: give another folder"
                )
        else:
            (self.folder / CASES).mkdir(parents=True, exist_ok=True)
            _write_atomic(marker, json.dumps({"key": self.key, **identity}, indent=1, sort_keys=True).encode())
        (self.folder / CASES).mkdir(exist_ok=True)

    def case_key(self, case: Case) -> str:
        """The digest of `case`'s row within this campaign."""
        return hashlib.sha256(json.dumps([self.key, case.values], sort_keys=True).encode()).hexdigest()

    def finished(self, case: Case) -> bool:
        """Whether `case` has a result here (finished or failed); `SceneError` where the
        result there is of another row under the same name."""
        import xarray as xr

        path = self.folder / CASES / f"{case.name}.nc"
        failed = self.folder / FAILED / f"{case.name}.txt"
        if path.exists():
            with xr.open_dataset(path) as held:
                key = held.attrs.get("case_key")
        elif failed.exists():
            key = failed.read_text().split("\n", 1)[0].removeprefix("case_key: ")
        else:
            return False
        if key != self.case_key(case):
            raise SceneError(
                f"{case.where}: campaign folder {self.folder} holds a result for case {case.name!r} of another row; "
                "it is kept: rename the case, or give another folder"
            )
        return True

    def write(self, case: Case, dataset) -> Path:
        """Write `case`'s result (an `xarray.Dataset`), whole or not at all."""
        dataset = dataset.copy()
        dataset.attrs.update(
            case=case.name,
            case_values=json.dumps(case.values),
            case_key=self.case_key(case),
            campaign=json.dumps(self.identity, sort_keys=True),
        )
        path = self.folder / CASES / f"{case.name}.nc"
        _write_atomic(path, bytes(dataset.to_netcdf()))
        return path

    def write_failure(self, case: Case, message: str) -> Path:
        """Record that `case` failed, and why."""
        path = self.folder / FAILED / f"{case.name}.txt"
        path.parent.mkdir(exist_ok=True)
        _write_atomic(path, f"case_key: {self.case_key(case)}\n{message}\n".encode())
        return path

    def failures(self) -> dict[str, str]:
        """Every failed case's message, by name."""
        folder = self.folder / FAILED
        if not folder.exists():
            return {}
        return {p.stem: p.read_text().split("\n", 1)[1].strip() for p in sorted(folder.glob("*.txt"))}

    def case_files(self) -> list[Path]:
        """Every finished case's file, by name."""
        return sorted((self.folder / CASES).glob("*.nc"))


def _write_atomic(path: Path, data: bytes) -> None:
    """Write `data` to `path` under a temporary name first, then rename it into place."""
    temporary = path.with_name(f".{path.name}.{os.getpid()}.tmp")
    temporary.write_bytes(data)
    os.replace(temporary, path)


def summary_rows(files: list[Path]) -> tuple[list[dict[str, Any]], list[str]]:
    """A row per case file: the case, its values, and per line (by name) the largest
    tension (N), its utilisation, the largest at each end, the fatigue damage and the
    damage-equivalent load (N, 1 Hz); per channel its maximum, minimum, mean and
    standard deviation. With the columns of the
    case table that the rows have, in order of appearance."""
    import xarray as xr

    rows, given = [], {}
    for path in files:
        with xr.open_dataset(path) as case:
            values = json.loads(case.attrs["case_values"])
            given.update(dict.fromkeys(values))
            row: dict[str, Any] = {"case": case.attrs["case"], **values}
            for k, line in enumerate(case["line"].values):
                for variable in ("largest_tension", "utilisation", "end_a_largest_tension", "end_b_largest_tension"):
                    row[f"{variable}.{line}"] = float(case[variable].values[k])
                # The line's safety factor against its breaking load, as API RP 2SK and
                # DNV-OS-E301 judge it: MBL over the largest tension.
                row[f"safety_factor.{line}"] = _ratio(
                    case["minimum_breaking_load"].values[k], row[f"largest_tension.{line}"]
                )
                for variable in ("fatigue_damage", "fatigue_equivalent_load"):
                    if variable in case:
                        row[f"{variable}.{line}"] = float(case[variable].values[k])
            if "channel" in case.coords:
                for k, channel in enumerate(case["channel"].values):
                    for statistic in ("maximum", "minimum", "mean", "std"):
                        row[f"{statistic}.{channel}"] = float(case[f"channel_{statistic}"].values[k])
            rows.append(row)
    return rows, list(given)


def write_table(path: Path, rows: list[dict[str, Any]], first: Sequence[str] = ()) -> None:
    """`rows` as a CSV table: the columns `first` that some row has, then the rest of
    the union of their columns in order of appearance (an empty cell where a row has
    none: a removed line's, say)."""
    columns: dict[str, None] = {}
    for row in rows:
        columns.update(dict.fromkeys(row))
    columns = {**dict.fromkeys(c for c in first if c in columns), **columns}
    lines = []
    for row in rows:
        lines.append([cell(row.get(c)) for c in columns])
    buffer = [list(columns), *lines]
    temporary = path.with_name(f".{path.name}.{os.getpid()}.tmp")
    with temporary.open("w", newline="") as f:
        csv.writer(f).writerows(buffer)
    os.replace(temporary, path)


def cell(value: Any, digits: int = 8) -> str:
    """A table's cell: a float to `digits` significant digits, empty where there is
    none or it is NaN, anything else as text."""
    if value is None or (isinstance(value, float) and math.isnan(value)):
        return ""
    if isinstance(value, float):
        return f"{value:.{digits}g}"
    return str(value)


def group_rows(files: list[Path], start: float) -> list[dict[str, Any]]:
    """A row per group of two or more cases that differ only in their `seed`: each
    line's most probable maximum tension (N) over the record from `start` (s), by a
    Gumbel fit to the seeds' maxima ([`jaxcable.extreme_statistics`][]), with its
    standard error and its utilisation and safety factor where the line has a minimum
    breaking load, and the mean fatigue damage over the seeds; and each output
    channel's most probable maximum, in its units."""
    import xarray as xr

    from .._sea.extremes import extreme_statistics

    groups: dict[str, list[Path]] = {}
    for path in files:
        with xr.open_dataset(path) as case:
            values = json.loads(case.attrs["case_values"])
        if "seed" in values:
            values.pop("seed")
            groups.setdefault(json.dumps(values, sort_keys=True), []).append(path)
    rows = []
    for key, members in groups.items():
        if len(members) < 2:
            continue
        histories: dict[str, list[np.ndarray]] = {}
        channels: dict[str, list[np.ndarray]] = {}
        damage: dict[str, list[float]] = {}
        breaking: dict[str, float] = {}
        for path in members:
            with xr.open_dataset(path) as case:
                times = case["time"].values
                tension = case["tension"].values
                owner = case["segment_line"].values
                for k, line in enumerate(case["line"].values):
                    histories.setdefault(line, []).append(np.max(tension[:, owner == k + 1], axis=1))
                    breaking[line] = float(case["minimum_breaking_load"].values[k])
                    if "fatigue_damage" in case:
                        damage.setdefault(line, []).append(float(case["fatigue_damage"].values[k]))
                for channel in case["channel"].values if "channel" in case.coords else ():
                    channels.setdefault(str(channel), []).append(case[str(channel)].values)
        row: dict[str, Any] = {"cases": " ".join(p.stem for p in members), "seeds": len(members), **json.loads(key)}
        for line, records in histories.items():
            if len(records) < 2:
                continue
            fit = extreme_statistics(np.stack(records), times, start=start)
            mpm = float(fit.most_probable_maximum)
            row[f"mpm_tension.{line}"] = mpm
            row[f"mpm_standard_error.{line}"] = float(fit.standard_error)
            row[f"mpm_utilisation.{line}"] = mpm / breaking[line] if np.isfinite(breaking[line]) else math.nan
            row[f"mpm_safety_factor.{line}"] = _ratio(breaking[line], mpm)
            if line in damage:
                row[f"mean_fatigue_damage.{line}"] = float(np.mean(damage[line]))
        for channel, records in channels.items():
            if len(records) == len(members):
                fit = extreme_statistics(np.stack(records), times, start=start)
                row[f"mpm.{channel}"] = float(fit.most_probable_maximum)
        rows.append(row)
    return rows


def _ratio(breaking_load: float, tension: float) -> float:
    """MBL over a tension, NaN where there is no MBL or no tension."""
    if not (np.isfinite(breaking_load) and tension > 0):
        return math.nan
    return float(breaking_load / tension)


def shortfalls(rows: list[dict[str, Any]], required: float, prefix: str = "safety_factor.") -> list[str]:
    """Each line of each row (a case's, or a group's with `prefix="mpm_safety_factor."`)
    whose safety factor falls below `required`, in words."""
    found = []
    for row in rows:
        name = row.get("case") or row.get("cases")
        for column, value in row.items():
            if column.startswith(prefix) and isinstance(value, float) and value < required:
                line = column.removeprefix(prefix)
                what = "most probable maximum" if prefix.startswith("mpm") else "largest tension"
                found.append(
                    f"{name}: line {line}'s {what} leaves a safety factor of {value:.3g} against its breaking load, "
                    f"below {required:g}"
                )
    return found
