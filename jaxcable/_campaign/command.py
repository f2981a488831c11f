"""`jaxcable campaign SCENE CASES --out FOLDER`: the command line of
`jaxcable._campaign.campaign`. The scene, its flags and the case table are read and
every case's scene checked before JAX is imported (`read`); `run` does the work."""

import re
import sys
from pathlib import Path
from typing import NamedTuple

from ..io._scene import Scene, SceneError
from .cases import COLUMNS

HELP = "run a scene over a table of load cases; keep each case's results and tables of them"


def add_parser(commands, scene_flags) -> None:
    """Add the `campaign` command to `commands` (argparse's subparsers); `scene_flags`
    adds the flags it shares with `run` (`--breaking-load`, `--fatigue`, ...)."""
    campaign = commands.add_parser(
        "campaign",
        help=HELP,
        description=f"{HELP}. The case table's columns (an empty cell keeps the scene's value; .NAME names a line): "
        f"{', '.join(COLUMNS)}. See the docs' command-line page, jaxcable campaign.",
    )
    campaign.add_argument("input", help="scene (.toml), MoorDyn input file, or bundled example name")
    campaign.add_argument("cases", type=Path, help="case table: CSV (a header of columns, a row a case) or TOML")
    campaign.add_argument(
        "--out",
        dest="folder",
        type=Path,
        required=True,
        help="the campaign's folder: a file a case, summary.csv, groups.csv and report.html; a folder of this "
        "campaign is continued (finished cases skipped), one of another refused",
    )
    campaign.add_argument("--duration", type=float, help="simulated time of each case (s); default: the scene's")
    campaign.add_argument("--dt-out", type=float, help="output interval (s); default: the scene's, or 0.1 s")
    campaign.add_argument("--channels", nargs="+", help="output channels kept with each case (default: the scene's)")
    campaign.add_argument(
        "--shard",
        metavar="I/N",
        help="run only the cases whose row (from 0) is I modulo N, for job arrays (Slurm: "
        "--shard $SLURM_ARRAY_TASK_ID/$SLURM_ARRAY_TASK_COUNT); every shard may write into one folder",
    )
    campaign.add_argument("--batch", type=int, help="the most cases run together in one sweep (default 32)")
    campaign.add_argument(
        "--tables-only",
        action="store_true",
        help="run nothing: make summary.csv, groups.csv and report.html from the cases in the folder",
    )
    campaign.add_argument(
        "--distributed",
        action="store_true",
        help="run as one of several processes (on one host or many) sharing each batch through JAX's "
        "multi-controller runtime, set up from the environment of Slurm or Open MPI; start the same command in "
        "each, with one --out folder that they all see",
    )
    campaign.add_argument(
        "--coordinator", metavar="HOST:PORT", help="as --distributed, with process 0's address given here"
    )
    campaign.add_argument("--processes", type=int, metavar="N", help="with --coordinator: how many processes")
    campaign.add_argument("--process-id", type=int, metavar="I", help="with --coordinator: this one, from 0")
    scene_flags(campaign)
    campaign.add_argument("--no-progress", action="store_true", help="do not show the progress bars")
    campaign.set_defaults(handler=run, reader=read)


class Given(NamedTuple):
    """What `read` checked: the scene, the cases, and the shard."""

    scene: Scene
    cases: tuple
    shard: tuple[int, int]


def read(args, scene: Scene) -> Given:
    """Check the case table against `scene` (the input file with its flags applied),
    and the flags, in plain Python: `SceneError` for anything they refuse."""
    from .campaign import DEFAULT_BATCH, case_scenes, check_settings
    from .cases import read_cases

    cases = read_cases(args.cases)
    shard = (0, 1)
    if args.shard is not None:
        match = re.fullmatch(r"\s*(\d+)\s*/\s*(\d+)\s*", args.shard)
        if not match:
            raise SceneError(f"--shard must be I/N, such as 0/4, got {args.shard!r}")
        shard = (int(match[1]), int(match[2]))
    explicit = (args.coordinator, args.processes, args.process_id)
    if any(v is not None for v in explicit):
        if any(v is None for v in explicit) or args.distributed:
            raise SceneError("--coordinator, --processes and --process-id go together, without --distributed")
        if not re.fullmatch(r"[^\s:]+:\d+", args.coordinator):
            raise SceneError(f"--coordinator must be HOST:PORT, such as localhost:12345, got {args.coordinator!r}")
        if not (args.processes >= 1 and 0 <= args.process_id < args.processes):
            raise SceneError(
                f"--process-id must be from 0 to --processes − 1, got {args.process_id} of {args.processes}"
            )
    duration = scene.run.duration if args.duration is None else args.duration
    dt_out = (scene.run.dt_out or 0.1) if args.dt_out is None else args.dt_out
    check_settings(duration, dt_out, args.statistics_from, shard, DEFAULT_BATCH if args.batch is None else args.batch)
    case_scenes(scene, cases, args.cases.parent, motion=False)  # every row checked against the scene, before JAX
    return Given(scene, cases, shard)


def initialize(args) -> None:
    """Join JAX's multi-controller runtime where the flags ask for it, before JAX starts
    its backend: from the environment (`--distributed`) or from `--coordinator`,
    `--processes` and `--process-id`; with Gloo for the CPU's collectives across
    processes."""
    if not (args.distributed or args.coordinator):
        return
    import jax

    jax.config.update("jax_cpu_collectives_implementation", "gloo")
    jax.distributed.initialize(args.coordinator, args.processes, args.process_id)


def run(args, given: Given) -> int:
    """Run the campaign (or with `--tables-only` make its tables) and print where its
    results are."""
    import jax

    from .campaign import DEFAULT_BATCH, run_campaign, write_tables

    first = jax.process_index() == 0  # of the processes of one campaign, the one that reports

    def say(line: str) -> None:
        if first:
            print(line, file=sys.stderr, flush=True)

    scene = given.scene
    if args.tables_only:
        from .campaign import identity
        from .store import Store

        settings = identity(scene, args.duration, args.dt_out, args.statistics_from, args.channels)
        store = Store(args.folder, settings, create=False)
        short = write_tables(store, args.statistics_from, [c.name for c in given.cases], args.safety_factor)
        _report(args.folder, short)
        return 0
    result = run_campaign(
        scene,
        given.cases,
        args.folder,
        table_folder=args.cases.parent,
        duration=args.duration,
        dt_out=args.dt_out,
        statistics_from=args.statistics_from,
        channels=tuple(args.channels or ()),
        shard=given.shard,
        batch=DEFAULT_BATCH if args.batch is None else args.batch,
        safety_factor=args.safety_factor,
        progress=first and not args.no_progress,
        log=say,
    )
    if not first:  # process 0 reports for all
        return 1 if result.failed else 0
    ran, failed = len(result.ran), len(result.failed)
    print(f"campaign {args.folder}: {ran - failed} case(s) run, {failed} failed, {len(result.skipped)} finished before")
    for name, message in result.failed.items():
        print(f"  failed: {name}: {message}")
    _report(args.folder, result.shortfalls)
    return 1 if failed else 0


def _report(folder: Path, short: tuple[str, ...]) -> None:
    """Name the tables written in `folder`, and warn of each safety factor short of
    the required one."""
    tables = [folder / name for name in ("summary.csv", "groups.csv", "report.html") if (folder / name).exists()]
    print("wrote " + ", ".join(map(str, tables)))
    sys.stdout.flush()
    for text in short:
        print(f"warning: {text}", file=sys.stderr)
