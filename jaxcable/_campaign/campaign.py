"""Design-load campaigns: one scene run over a table of load cases, each case reduced to
the numbers a standard asks for and kept in a folder that survives a crash.

Every case is built and checked before any runs, so a bad row is refused at once,
naming it. Cases whose models have the same structure (the same lines, segments, waves'
component counts, options: only values differ) run together as one [`jaxcable.sweep`][]
of `batch` cases at a time, each from its own static equilibrium (solved as `jaxcable
run` solves it, in still water with the current) and with the steps `jaxcable run`
would choose for it (cases that need other steps run apart). A case whose statics or
integration fails is recorded as failed and the others go on. A case's answer does not
depend on its batch: its run agrees with its own `jaxcable run` to rounding.

Each finished case's results are written at once (`jaxcable._campaign.store`), so a
campaign killed part-way loses at most its running batch, and a restart runs only the
cases without results. `shard=(i, n)` runs every n-th case from the i-th, for job
arrays: shards write into one folder (on a shared file system) or into several, whose
case files can be put together in one, and the tables are made from whatever cases the
folder holds. Processes joined by JAX's multi-controller runtime (`jax.distributed`) run
one campaign together, each batch split across all their devices (`_Processes`).
"""

import dataclasses
import importlib.metadata
import json
import sys
import time
from collections.abc import Callable, Sequence
from pathlib import Path
from typing import TYPE_CHECKING

import numpy as np

from .._names import DEFAULT_SAFETY_FACTOR
from ..io._scene import Scene, SceneError
from .cases import Case, case_scene
from .report import write_report
from .store import Store, digest, group_rows, shortfalls, summary_rows, write_table

if TYPE_CHECKING:
    from .._model.network import CableNetwork
    from .._sea.environment import Environment
    from .._solver.config import SolverConfig
    from ..io._scene import BuiltScene

DEFAULT_BATCH = 32
"""Cases run together in one sweep, at most: enough to keep a CPU's cores busy, few
enough that a batch's histories fit in memory and a killed campaign loses little."""


@dataclasses.dataclass(frozen=True)
class CampaignResult:
    """What a campaign run did.

    - `folder`: the campaign's folder.
    - `ran`, `skipped`: the cases run now, and those of this shard that the folder held
        results for already, by name.
    - `failed`: the cases that failed now, with why.
    - `summary`: the table of every finished case in the folder (`summary.csv`).
    - `groups`: the table of groups of cases that differ only in their seed
        (`groups.csv`), or `None` where there are none.
    - `report`: the short report (`report.html`).
    - `shortfalls`: each line of a case (or a group's most probable maximum) whose
        safety factor falls below the required one, in words.
    """

    folder: Path
    ran: tuple[str, ...]
    skipped: tuple[str, ...]
    failed: dict[str, str]
    summary: Path
    groups: Path | None
    report: Path
    shortfalls: tuple[str, ...]


def case_scenes(
    scene: Scene, cases: Sequence[Case], table_folder: str | Path = ".", motion: bool = True
) -> list[Scene]:
    """Each case's scene (`jaxcable._campaign.cases.case_scene`), all checked before any
    work; without `motion`, in plain Python (no JAX), motion tables read and checked
    but not made into motions."""
    return [case_scene(scene, case, Path(table_folder), motion) for case in cases]


def run_campaign(
    scene: Scene,
    cases: Sequence[Case],
    folder: str | Path,
    *,
    table_folder: str | Path = ".",
    duration: float | None = None,
    dt_out: float | None = None,
    statistics_from: float = 0.0,
    channels: Sequence[str] = (),
    shard: tuple[int, int] = (0, 1),
    batch: int = DEFAULT_BATCH,
    safety_factor: float = DEFAULT_SAFETY_FACTOR,
    progress: bool = False,
    log: Callable[[str], None] | None = None,
) -> CampaignResult:
    """Run `scene` over `cases` ([`jaxcable.read_cases`][]), keeping each case's results
    in `folder`.

    Every case is built and checked first; then cases of one structure run together
    as a [`jaxcable.sweep`][] of up to `batch` cases, each from its own equilibrium and
    with the steps its own `jaxcable run` would take (cases that need other steps run
    apart), so that a case's answer does not depend on its batch or shard: it agrees
    with [`jaxcable.run_scene`][] of its scene to rounding. A case that fails (statics
    that finds no equilibrium, a run that goes non-finite) is recorded with why, and
    the others go on.

    The folder holds a netCDF file a finished case (its run as
    [`jaxcable.io.SceneRun.to_dataset`][] gives it, with each channel's statistics and
    each line's fatigue damage, the case row and the software's version), written
    whole or not at all, so that a campaign killed part-way loses only its running
    batch; run again, it skips the cases with results. `summary.csv` has a row a case
    (its values, each line's largest tension, utilisation, fatigue damage and
    damage-equivalent load, each
    channel's maximum, minimum, mean and standard deviation; a failed case's message),
    and `groups.csv` a row for each group of cases that differ only in `seed`: each
    line's most probable maximum tension by a Gumbel fit to the seeds' maxima
    ([`jaxcable.extreme_statistics`][]), its standard error, utilisation and safety
    factor, and the mean fatigue damage; `report.html` judges every line's safety factor
    (minimum breaking load over largest tension) against `safety_factor`, with a figure
    and the tables. A folder that holds another campaign (another scene or
    settings), or another row under a case's name, is refused: nothing is
    overwritten.

    **Arguments:**

    - `scene`: the [`jaxcable.io.Scene`][] every case changes.
    - `cases`: the case table's rows.
    - `folder`: where the results go; a folder that holds results of this campaign is
        continued, one of another campaign refused.
    - `table_folder`: the folder motion tables named in the cases are relative to.
    - `duration`, `dt_out`: simulated time and output interval (s); the scene's by default
        (0.1 s for an interval it does not give).
    - `statistics_from`: the first time (s) of each case's extremes, statistics and
        fatigue and of the extremes over seeds, leaving a start-up transient out.
    - `channels`: output channels (MoorDyn names) kept with each case; the scene's by
        default. A case that lacks one (its line removed) keeps the others.
    - `shard`: `(i, n)`, run the cases whose position in the table is i modulo n
        (from 0).
    - `batch`: the most cases run together in one sweep.
    - `safety_factor`: the factor the report (`report.html`) requires of each line's
        minimum breaking load over its largest tension (1.67 by default, API RP 2SK's
        for an intact mooring analysed dynamically).
    - `progress`: show each batch's progress bar in simulated seconds.
    - `log`: called with a line of text as each batch starts and ends.

    **Returns:**

    A [`jaxcable.CampaignResult`][].

    **Raises:**

    [`jaxcable.io.SceneError`][], before any case runs, for a bad duration, interval,
    shard or batch, a case whose scene cannot be built (naming the case), a channel the
    scene does not have, or a folder that holds another campaign.
    """
    say = log or (lambda line: None)
    settings = identity(scene, duration, dt_out, statistics_from, channels)
    length, interval, names = float(settings["duration"]), float(settings["dt_out"]), tuple(settings["channels"])
    check_settings(length, interval, statistics_from, shard, batch)
    scenes = case_scenes(scene, cases, table_folder)
    store = Store(folder, settings)
    index, count = shard
    mine = [(case, s) for k, (case, s) in enumerate(zip(cases, scenes)) if k % count == index]
    skipped = tuple(case.name for case, _ in mine if store.finished(case))
    pending = [(case, s) for case, s in mine if case.name not in skipped]
    jobs = [_Job.build(case, s, length, interval) for case, s in pending]  # every case checked before any runs
    processes = _Processes()
    processes.agree("the cases to run", [job.case.name for job in jobs])
    say(
        f"campaign: {len(mine)} of {len(cases)} cases in this shard"
        + (f", {len(skipped)} finished already" if skipped else "")
        + f"; {len(jobs)} to run, in {len(_groups(jobs))} group(s) of one structure"
    )
    failed: dict[str, str] = {}
    ran: list[str] = []
    for group in _groups(jobs):
        for start in range(0, len(group), batch):
            part = group[start : start + batch]
            say(
                f"campaign: running {', '.join(j.case.name for j in part[:4])}{', ...' if len(part) > 4 else ''} "
                f"({len(part)} case(s))"
            )
            began = time.perf_counter()
            for job, outcome in zip(part, _run_batch(part, length, interval, progress, processes)):
                if outcome is None:  # another process's to write
                    continue
                if isinstance(outcome, str):
                    store.write_failure(job.case, outcome)
                    failed[job.case.name] = outcome
                    say(f"campaign: case {job.case.name} failed: {outcome}")
                else:
                    store.write(job.case, _case_dataset(outcome, job, names, statistics_from, interval))
                ran.append(job.case.name)
            say(f"campaign: {len(part)} case(s) done in {time.perf_counter() - began:.1f} s")
    processes.agree("the campaign's end", [])  # every case file written before the tables
    if processes.count > 1:  # what all of them ran, from the folder they share
        held = store.failures()
        ran = [job.case.name for job in jobs]
        failed = {name: held[name] for name in ran if name in held}
    short: tuple[str, ...] = ()
    if processes.index == 0:
        short = write_tables(store, statistics_from, [case.name for case in cases], safety_factor)
    processes.agree("the tables", [])
    groups = store.folder / "groups.csv"
    return CampaignResult(
        store.folder,
        tuple(ran),
        skipped,
        failed,
        store.folder / "summary.csv",
        groups if groups.exists() else None,
        store.folder / "report.html",
        short,
    )


def check_settings(duration: float, dt_out: float, statistics_from: float, shard: tuple[int, int], batch: int) -> None:
    """Refuse, naming the value, a duration, interval, start of the statistics, shard or
    batch that cannot run."""
    if not (np.isfinite(duration) and duration > 0):
        raise SceneError(f"campaign: duration must be a positive number of seconds, got {duration:g}")
    if not (np.isfinite(dt_out) and 0 < dt_out <= duration):
        raise SceneError(f"campaign: dt_out must be a positive interval (s) within the duration, got {dt_out:g}")
    if not (np.isfinite(statistics_from) and 0 <= statistics_from < duration):
        raise SceneError(
            f"campaign: the statistics start at {statistics_from:g} s, which leaves nothing of a {duration:g} s run"
        )
    index, count = shard
    if not (isinstance(count, int) and isinstance(index, int) and count >= 1 and 0 <= index < count):
        raise SceneError(f"campaign: shard must be i/n with 0 ≤ i < n, got {index}/{count}")
    if not (isinstance(batch, int) and batch >= 1):
        raise SceneError(f"campaign: batch must be a positive number of cases, got {batch!r}")


def identity(
    scene: Scene,
    duration: float | None = None,
    dt_out: float | None = None,
    statistics_from: float = 0.0,
    channels: Sequence[str] | None = (),
) -> dict:
    """What a campaign is, for its folder (`jaxcable._campaign.store.Store`): the
    scene's digest, the duration and output interval (s; the scene's by default), the
    start of the statistics (s) and the channels (the scene's by default, each checked:
    `SceneError` for one it does not have)."""
    from ..io._channels import default_channels, parse_channel

    duration = scene.run.duration if duration is None else float(duration)
    dt_out = (scene.run.dt_out or 0.1) if dt_out is None else float(dt_out)
    channels = tuple(channels or ()) or default_channels(scene)
    for name in channels:
        parse_channel(name, scene)
    return {
        "scene": digest(scene),
        "duration": duration,
        "dt_out": dt_out,
        "statistics_from": float(statistics_from),
        "channels": list(channels),
        "describe": f"{Path(scene.source).name}, {duration:g} s with outputs every {dt_out:g} s",
    }


def write_tables(
    store: Store, statistics_from: float, order: Sequence[str] = (), safety_factor: float = DEFAULT_SAFETY_FACTOR
) -> tuple[str, ...]:
    """Make `summary.csv` (and `groups.csv`, where cases differ only in their seed)
    from every case file in the store's folder, in the order of the case names in
    `order` (the table's), cases not named there after them, and `report.html`, which
    judges the lines' safety factors against `safety_factor`. Returns the lines whose
    safety factor falls short, in words (`store.shortfalls`)."""
    rank = {name: k for k, name in enumerate(order)}
    files = sorted(store.case_files(), key=lambda path: (rank.get(path.stem, len(rank)), path.stem))
    rows, given = summary_rows(files)
    for name, message in store.failures().items():
        rows.append({"case": name, "failed": message})
    summary = store.folder / "summary.csv"
    write_table(summary, rows, ["case", *given])  # the case table's columns first, then the results
    grouped = group_rows(files, statistics_from)
    title = f"Campaign of {store.identity.get('describe', store.folder.name)}"
    write_report(store.folder / "report.html", title, rows, given, grouped, safety_factor)
    groups = store.folder / "groups.csv"
    if grouped:
        write_table(groups, grouped, ["cases", "seeds", *given])
    else:
        groups.unlink(missing_ok=True)  # an earlier run's, of other cases
    finished = [row for row in rows if not row.get("failed")]
    return tuple(shortfalls(finished, safety_factor) + shortfalls(grouped, safety_factor, "mpm_safety_factor."))


@dataclasses.dataclass
class _Job:
    """A case ready to run: its scene built, its model and water as its run needs them,
    and the solver its own run would take, with that run's notes on it."""

    case: Case
    scene: Scene
    built: "BuiltScene"
    model: "CableNetwork"
    env: "Environment"
    solver: "SolverConfig"
    notes: tuple[str, ...]

    @classmethod
    def build(cls, case: Case, scene: Scene, duration: float, dt_out: float) -> "_Job":
        """The case built, with the solver `jaxcable run` would choose for it."""
        from .._model.reach import for_run
        from ..io._run import _feasible, check_motion_tables, output_times

        try:
            check_motion_tables(scene, duration)
            built = scene.build()
        except (SceneError, ValueError) as error:
            raise SceneError(f"{case.where}: case {case.name}: {error}") from None
        solver, notes = _feasible(scene.run.solver_config(built, duration), built, output_times(duration, dt_out))
        return cls(case, scene, built, built.model, for_run(built.model, built.environment, duration), solver, notes)


def _groups(jobs: list[_Job]) -> list[list[_Job]]:
    """The jobs grouped by structure: the same array shapes and types, the same
    everything else (topology, options) and the same solver, in table order. Each case
    takes the steps its own `jaxcable run` would, whatever its batch or shard: cases
    whose fastest modes ask for other steps run apart."""
    import equinox as eqx
    import jax

    groups: list[tuple[tuple, object, list[_Job]]] = []  # (array shapes, the rest, the jobs)
    for job in jobs:
        arrays, rest = eqx.partition((job.model, job.env), eqx.is_array)
        shape = (jax.tree.structure(arrays), [(np.shape(x), x.dtype) for x in jax.tree.leaves(arrays)])
        rest = (rest, job.solver)
        for shapes, others, members in groups:
            if shapes == shape and bool(eqx.tree_equal(others, rest)):
                members.append(job)
                break
        else:
            groups.append((shape, rest, [job]))
    return [members for _, _, members in groups]


class _Processes:
    """The processes of JAX's multi-controller runtime (`jax.distributed`) that run one
    campaign together: one global batch a sweep, split across all their devices, whose
    results process 0 writes; the cases run alone, split among them. One process
    alone: nothing to agree on."""

    def __init__(self):
        import jax

        self.index, self.count = jax.process_index(), jax.process_count()

    def agree(self, what: str, names: list[str]) -> None:
        """Wait for every process here, and check that each has the same `names`: a
        process that saw other finished cases (a folder not shared) would run other
        batches, and the shared programs would wait for each other for ever."""
        if self.count == 1:
            return
        import hashlib

        from jax.experimental import multihost_utils

        multihost_utils.sync_global_devices(f"jaxcable campaign: {what}")
        digest = np.frombuffer(hashlib.sha256("\n".join(names).encode()).digest(), np.uint8)
        multihost_utils.assert_equal(
            digest, f"campaign: the processes disagree on {what}: is the campaign's folder shared by all of them?"
        )

    def owns(self, k: int, batched: bool) -> bool:
        """Whether this process writes the `k`-th case of a batch: process 0 a sweep's,
        case k's own process (k modulo the count) a case run alone."""
        return self.index == 0 if batched else k % self.count == self.index


def _run_batch(jobs: list[_Job], duration: float, dt_out: float, progress: bool, processes: _Processes) -> list:
    """Each job's `SceneRun`, or why it failed, or `None` where another process writes
    it (`_Processes.owns`): cases whose models differ by one sweep, from each one's own
    equilibrium; a lone case (or cases whose models are equal) by `run_scene`, as
    `jaxcable run` runs it."""
    import equinox as eqx
    import jax

    from ..io._run import run_scene

    def varying(cases: list[int]) -> list[bool]:
        """Which array leaves of the models and water differ between `cases`."""
        leaves = [jax.tree.leaves(eqx.filter((jobs[k].model, jobs[k].env), eqx.is_array)) for k in cases]
        return [
            any(not np.array_equal(np.asarray(x[i]), np.asarray(leaves[0][i])) for x in leaves)
            for i in range(len(leaves[0]))
        ]

    running = list(range(len(jobs)))
    outcomes: list = [None] * len(jobs)
    batched = len(jobs) > 1 and any(varying(running))
    if batched:  # each case's equilibrium first, for the sweep to start from (run_scene solves its own)
        outcomes = [_start(job) for job in jobs]
        running = [k for k, outcome in enumerate(outcomes) if not isinstance(outcome, str)]
        batched = len(running) > 1 and any(varying(running))
    if batched:
        runs = _sweep_batch(
            [jobs[k] for k in running],
            [outcomes[k] for k in running],
            [jax.tree.leaves(eqx.filter((jobs[k].model, jobs[k].env), eqx.is_array)) for k in running],
            varying(running),
            duration,
            dt_out,
            progress,
        )
        for k, run in zip(running, runs):
            outcomes[k] = run
    else:
        for k in running:
            if not processes.owns(k, batched):
                continue
            try:
                outcomes[k] = run_scene(jobs[k].scene, duration=duration, dt_out=dt_out, progress=progress)
            except (RuntimeError, ValueError) as error:  # its statics or dynamics failed, or statics refused it
                outcomes[k] = str(error)
    return [outcome if processes.owns(k, batched) else None for k, outcome in enumerate(outcomes)]


def _start(job: _Job):
    """Where `job` starts, as `run_scene` starts it: `(statics or None, positions,
    velocities, seconds)`, the equilibrium in still water with the current (or the
    file's geometry at rest, where the scene skips statics) and the wall time (s) it
    took; or why statics failed."""
    import optimistix as optx

    from .._statics.solve import failure_message, solve_statics
    from ..io._initial_shape import initial_positions

    began = time.perf_counter()
    if not job.scene.run.statics:
        positions = initial_positions(job.built)[0]
        return None, positions, np.zeros_like(positions), time.perf_counter() - began
    try:
        static = solve_statics(job.model, job.env.without_waves(), throw=False)
    except ValueError as error:  # refused before solving: a line far too short for its ends, say
        return str(error)
    if static.result != optx.RESULTS.successful:
        return failure_message(static)
    state = static.state
    return static, np.asarray(state.positions), np.asarray(state.velocities), time.perf_counter() - began


def _sweep_batch(jobs, starts, leaves, varying, duration, dt_out, progress) -> list:
    """The jobs' runs (`SceneRun`s, or why one failed) as one sweep over the case
    index, from `starts` (`_start`'s): the leaves that differ between cases are
    stacked, and the model of case k picks row k of each."""
    import equinox as eqx
    import jax
    import jax.numpy as jnp

    from .._model.state import State
    from .._simulation.simulate import to_host
    from .._sweep.sweep import sweep
    from ..io._run import SceneRun, output_times

    arrays, rest = eqx.partition((jobs[0].model, jobs[0].env), eqx.is_array)
    tree = jax.tree.structure(arrays)
    table = [
        jax.device_put(np.stack([np.asarray(case[i]) for case in leaves])) if varying[i] else leaves[0][i]
        for i in range(len(varying))
    ]

    def build(case):
        row = jnp.asarray(case, int)
        picked = [x[row] if v else x for x, v in zip(table, varying)]
        return eqx.combine(jax.tree.unflatten(tree, picked), rest)

    initial = State(np.stack([start[1] for start in starts]), np.stack([start[2] for start in starts]))
    began = time.perf_counter()
    result = sweep(
        build,
        {"case": np.arange(len(jobs), dtype=float)},
        duration,
        ts=output_times(duration, dt_out),
        initial=initial,
        solver=jobs[0].solver,
        progress=progress,
    )
    simulation = to_host(result.simulation)  # gathered from every process where it spans several
    share = (time.perf_counter() - began) / len(jobs)
    runs: list = []
    for k, (job, start) in enumerate(zip(jobs, starts)):
        if result.status[k] != "successful":
            runs.append(result.status[k])
            continue
        runs.append(
            SceneRun(
                job.built,
                start[0],
                simulation.times[k],
                simulation.positions[k],
                simulation.velocities[k],
                simulation.tension[k],
                simulation.reactions[k],
                int(simulation.stats["num_steps"][k]),
                result.stepping,
                start[3],
                share,
                job.notes,
            )
        )
    return runs


def _case_dataset(run, job: _Job, channels: Sequence[str], statistics_from: float, dt_out: float):
    """The case's run as a dataset (`SceneRun.to_dataset`) with each channel's
    statistics and each line's fatigue damage from `statistics_from` (s)."""
    import xarray as xr

    from ..io._channels import parse_channel

    present = []
    for name in channels:
        try:
            parse_channel(name, job.scene)
            present.append(name)
        except SceneError:
            pass  # a channel of a line this case removed
    names = tuple(present)
    dataset = run.to_dataset(names, statistics_from)
    statistics = run.channel_statistics(names, statistics_from)
    dataset = dataset.assign_coords(channel=[s.name for s in statistics])
    for field, description in (
        ("maximum", "largest sample"),
        ("minimum", "smallest sample"),
        ("mean", "time-averaged mean"),
        ("std", "time-averaged standard deviation"),
    ):
        dataset[f"channel_{field}"] = xr.Variable(
            ("channel",), [getattr(s, field) for s in statistics], attrs={"long_name": f"each channel's {description}"}
        )
    dataset["channel_units"] = xr.Variable(("channel",), [s.units for s in statistics])
    fatigue = {f.line: f for f in run.line_fatigue(statistics_from)}
    lines = [line.name for line in job.scene.lines]
    for field, unit, description in (
        ("damage", "1", "Miner's sum of the most damaged segment"),
        ("annual_damage", "1/year", "that damage per year"),
        ("life", "year", "the fatigue life at that rate"),
        ("equivalent_load", "N", "that segment's damage-equivalent load, one cycle a second"),
    ):
        values = [getattr(fatigue[n], field) if n in fatigue else np.nan for n in lines]
        name = "fatigue_damage" if field == "damage" else f"fatigue_{field}"
        dataset[name] = xr.Variable(("line",), values, attrs={"units": unit, "long_name": description})
    dataset.attrs.update(
        jaxcable_version=importlib.metadata.version("jaxcable"),
        statistics_from=statistics_from,
        dt_out=dt_out,
        notes=json.dumps(list(run.notes)),
        python=sys.version.split()[0],
    )
    return dataset
