"""The `jaxcable` command line: run or describe a scene file or a MoorDyn input file.

    jaxcable run INPUT [--duration S] [--motion FILE] [--motion-interpolation cubic|pchip|linear]
                       [--out FILE] [--dt-out S] [--plot FILE.png] [--solver NAME]
                       [--dt S | --adaptive] [--rtol R] [--atol A] [--max-steps N]
                       [--no-statics] [--segments N] [--channels ...]
                       [--allow-ignored EI,waves,...]
    jaxcable info INPUT [--segments N] [--duration S]
    jaxcable calibrate RECORD.csv [RECORD.csv ...] --fit NAME=START [NAME=START ...]
                       [--segments N] [--check-segments]
                       [--optimizer lbfgs|adam] [--max-steps N] [--plot FILE.png]
                       [--out FILE.json]
    jaxcable campaign INPUT CASES --out FOLDER [--duration S] [--dt-out S] [--shard I/N]
                       [--batch N] [--tables-only] [--channels ...] [--distributed]
    jaxcable examples

INPUT is a jaxcable scene (`.toml`), a MoorDyn v2 input file (any other suffix), or the
name of a bundled example scene (see `jaxcable examples`). A RECORD is a towing record
(CSV, see `jaxcable.io.read_record`) whose header names its rig, or the name of a
bundled sample record.

`--help` and `examples` answer without importing JAX (seconds). `run`, `info` and
`campaign` read and check their flags and input files (and the case table) first, in plain Python and numpy, so that a
refused input is answered without JAX too; then they import the engine.
"""

import argparse
import dataclasses
import gc
import json
import math
import os
import sys
import threading
import warnings
from collections.abc import Callable
from pathlib import Path
from typing import TYPE_CHECKING, Any, NamedTuple

import numpy as np

from ._campaign import command as campaign_command
from ._interrupt import StopRequest
from ._names import (
    AUTO,
    DEFAULT_SAFETY_FACTOR,
    DROPPED_KINDS,
    INTERPOLATIONS,
    LARGEST_RTOL,
    SMALLEST_RTOL,
    SOLVER_NAMES,
)
from .examples import record_names, record_path, scene_names, scene_path, scene_title

if TYPE_CHECKING:
    from .io import RunSettings, Scene
    from .io._scene import ParsedScene

OPTIMIZERS = ("lbfgs", "adam")
"""The `calibrate` command's optimizers by name (`_optimizer`)."""


def command() -> None:
    """The `jaxcable` executable and `python -m jaxcable`: [`main`][] on the process's
    arguments, then the process ends.

    A command that succeeded ends at once (`os._exit`), once its output is flushed and
    every program compiling in the background is written: the interpreter's own shutdown
    spends about a tenth of a warm `jaxcable run` of the Low & Langley file releasing
    JAX's compiled programs and backend, for nothing the process still needs. A failure exits the usual way.

    The process collects its oldest generation of objects a hundred times less often
    than Python's default: four such collections, each walking every object that the
    imports and JAX's traces made (nearly all of which live to the end), took 0.27 s of
    a cold `jaxcable run` of the Low & Langley file. The young generations, where
    short-lived garbage is, are collected as usual."""
    young, middle, _ = gc.get_threshold()
    gc.set_threshold(young, middle, 1000)
    stop = StopRequest()
    try:
        code = _interruptible(lambda: main(stop=stop), stop)
    except BrokenPipeError:  # `jaxcable examples | head`: stop quietly, as `main` does for the others
        os.dup2(os.open(os.devnull, os.O_WRONLY), sys.stdout.fileno())
        sys.exit(1)
    if code != 0:
        sys.exit(code)
    if "jax" in sys.modules:  # --help and `examples` never imported it
        from . import _programs

        _programs.finish()
    try:
        sys.stdout.flush()
        sys.stderr.flush()
    except BrokenPipeError:  # output piped into `head` and the like
        os._exit(1)
    os._exit(0)


INTERRUPTED = 130
"""The exit status after Ctrl-C: 128 + SIGINT, as a shell reports it."""


def _interruptible(work: Callable[[], int], stop: StopRequest | None = None) -> int:
    """`work()` on a thread of its own while this, the main thread, waits for it, so
    that Ctrl-C ends the command at once, or, in a run's blocks, keeps what it computed.

    Python raises `KeyboardInterrupt` in the main thread only, between bytecodes: while
    the main thread is inside a compiled program or XLA's compiler (a statics solve, a
    long compile), Ctrl-C would wait for it to end, minutes on a hard scene. The
    waiting thread wakes five times a second. On Ctrl-C, where `stop` says a run has
    results to keep (it has finished a block of output intervals), the run is asked to
    stop at the end of its block and `work` to write and report what it has, its exit
    status then 130; a second Ctrl-C, or one before there is anything to keep, says so
    and ends the process at once (a running program cannot be stopped, only left), exit
    status 130. Exceptions of `work` are raised here."""
    done, outcome = _on_thread(work, "jaxcable command")
    try:
        try:
            while not done.wait(0.2):
                pass
        except KeyboardInterrupt:
            if stop is None or not stop.ask():
                raise
            print(
                "\njaxcable: interrupted: stopping at the end of this block of the run to keep what it computed "
                "(Ctrl-C again to quit at once)",
                file=sys.stderr,
                flush=True,
            )
            while not done.wait(0.2):
                pass
    except KeyboardInterrupt:
        print("\njaxcable: interrupted", file=sys.stderr, flush=True)
        os._exit(INTERRUPTED)
    return _outcome(outcome)


def _on_thread(work: Callable[[], object], name: str) -> tuple[threading.Event, dict[str, object]]:
    """`work()` started on a daemon thread; the event set when it ends, and the dict its
    result (`"value"`) or exception (`"error"`) lands in, which [`_outcome`][] reads.

    Wait on the event, not with `Thread.join`: Python 3.11's `join`, interrupted by
    Ctrl-C, releases the running thread's own lock and takes the thread for ended."""
    outcome: dict[str, object] = {}
    done = threading.Event()

    def run() -> None:
        try:
            outcome["value"] = work()
        except BaseException as error:  # raised again by `_outcome`, in the waiting thread
            outcome["error"] = error
        finally:
            done.set()

    threading.Thread(target=run, name=name, daemon=True).start()
    return done, outcome


def _outcome(outcome: dict[str, object]) -> Any:
    """The result that [`_on_thread`][]'s work returned, or its exception raised here."""
    if "error" in outcome:
        raise outcome["error"]  # pyright: ignore[reportGeneralTypeIssues]
    return outcome["value"]


def main(argv: list[str] | None = None, stop: StopRequest | None = None) -> int:
    """Entry point of the `jaxcable` command; returns the exit status. `stop`, asked
    from another thread, stops `run` at the end of a block of its output intervals,
    which then writes and reports what it computed (exit status 130)."""
    parser = _parser()
    args = parser.parse_args(argv)
    args.stop = stop
    if args.command is None:
        parser.print_help()
        return 2
    if args.command == "examples":
        return _examples(args)
    from .io import SceneError  # plain Python, as the scene readers are (`jaxcable.io`)

    # What the flags and the input files alone decide is checked before JAX is imported
    # (1.3 s, most of a refusal's time otherwise): a number out of range, a malformed
    # or missing scene file or motion table.
    try:
        _check_numbers(args)
        _check_no_overwrite(args)
        if args.command in ("run", "info"):
            given = _read_input(args)
        elif args.command == "campaign":
            given = _read_campaign(args)
        else:
            given = None
    except SceneError as error:
        print(f"jaxcable: error: {error}", file=sys.stderr)
        return 2
    # Only now the engine, and JAX with it: --help, `examples` and a refused input
    # need neither.
    import jax

    from . import _programs

    # The command owns its process, so it may set JAX's global configuration, which
    # the library itself never does.
    jax.config.update("jax_enable_x64", True)
    if args.command == "campaign":
        campaign_command.initialize(args)  # before the backend starts
    kept = _programs.folder()
    _use_compilation_cache()
    _one_kernel_thread()  # every command runs one scene or calibration at a time
    try:
        with warnings.catch_warnings():  # restores the display below when the command ends
            warnings.showwarning = _show_warning
            _check_output_files(args)
            if given is None:  # calibrate: its records are read with the engine's rigs
                return args.handler(args)
            return args.handler(args, given)
    except SceneError as error:
        print(f"jaxcable: error: {error}", file=sys.stderr)
        return 2
    except RuntimeError as error:  # a failed statics or dynamics solve
        print(f"jaxcable: solver failed: {error}", file=sys.stderr)
        return 1
    except BrokenPipeError:  # output piped into `head` and the like: stop quietly
        os.dup2(os.open(os.devnull, os.O_WRONLY), sys.stdout.fileno())
        return 1
    finally:
        _programs.use_folder(kept)  # for a caller that runs the command in its own process


def _show_warning(message, category, filename, lineno, file=None, line=None) -> None:
    """Print a warning as one line, `warning: ...`, as the command's notes are, without
    the source line Python's display adds."""
    del category, filename, lineno, file, line
    print(f"warning: {message}", file=sys.stderr)


def _one_kernel_thread() -> None:
    """Have XLA's CPU backend run a single run's kernels on the calling thread alone.

    By default the backend sizes its thread pool to the cores and hands a program's
    independent kernels between those threads. A step of a single run is a few hundred
    kernels of a microsecond or so each, and handing them between threads costs more
    than running them together gains. With one thread (`PJRT_NPROC=1`, read when the
    backend starts, which is after this: nothing has run yet) the Low & Langley file's
    107,000 fixed midpoint steps take 20–45 % less time than with the default pool, and a
    Dopri5 step of the anchored-line paper's lumped line 8 % less at N = 20 and 14 % less
    at N = 100 than with XLA's in-order scheduler
    (`--xla_cpu_enable_concurrency_optimized_scheduler=false`), which this replaces
    (`benchmarks/step_cost.py` times the steps). A sweep is the opposite case: its chunks run on threads
    of their own (`jaxcable.sweep`), and one thread made it 1.7 times slower, so this
    suits the single-scene commands only. A `PJRT_NPROC` the caller set comes first and wins.
    """
    os.environ.setdefault("PJRT_NPROC", "1")


def _use_compilation_cache() -> None:
    """Keep compiled programs on disk between runs, so that a second `jaxcable run` of a
    scene with the same structure (the same file, or another of the same topology and
    options) loads its programs instead of compiling them.

    The folder is `$JAXCABLE_CACHE_DIR`, or `jaxcable/xla` under `$XDG_CACHE_HOME`
    (`~/.cache` by default); `JAXCABLE_CACHE_DIR=""` turns the cache off. A folder set
    for JAX itself (`JAX_COMPILATION_CACHE_DIR`) is used instead. JAX keeps its programs
    there, keyed by their lowered code; jaxcable keeps its main programs (statics', the
    run's) in its `jaxcable-programs` folder, keyed by the scene's structure, so that
    they load without being traced first (`jaxcable._programs`).
    """
    import jax

    from . import _programs

    root = _programs.cache_root()
    if root is not None and "JAX_COMPILATION_CACHE_DIR" not in os.environ:  # JAX reads its own
        jax.config.update("jax_compilation_cache_dir", str(root))
        # Every program of a run is worth keeping: the small ones (an eager operation
        # compiles in 15-30 ms, and loads in 5) add up to seconds.
        jax.config.update("jax_persistent_cache_min_compile_time_secs", 0.0)
    _programs.use_folder(_programs.default_folder())


def _parser() -> argparse.ArgumentParser:
    parser = argparse.ArgumentParser(
        prog="jaxcable", description=__doc__, formatter_class=argparse.RawDescriptionHelpFormatter
    )
    commands = parser.add_subparsers(dest="command")

    run = commands.add_parser("run", help="solve statics, then simulate; write and plot the results")
    run.add_argument("input", help="scene (.toml), MoorDyn input file, or bundled example name")
    run.add_argument("--duration", type=float, help="simulated time (s); 0 solves statics only")
    run.add_argument("--motion", type=Path, help="table of time x y z for each coupled point, in order")
    run.add_argument(
        "--motion-interpolation",
        choices=INTERPOLATIONS,
        default="cubic",
        help="between the motion table's rows: natural cubic spline (default; may overshoot a step), "
        "pchip (monotone) or linear",
    )
    run.add_argument(
        "--ramp", type=float, help="switch --motion's table on smoothly over this time (s), from rest at t = 0"
    )
    run.add_argument("--out", type=Path, help="output file: .csv, .out (MoorDyn layout), .npz or .nc")
    run.add_argument("--dt-out", type=float, help="output interval (s); default: the file's dtOut, or 0.1 s")
    run.add_argument("--plot", type=Path, help="save tension histories and line shapes to this image")
    run.add_argument(
        "--solver",
        choices=[AUTO, *sorted(SOLVER_NAMES)],
        help="ODE solver (default: the scene's; auto, fixed RK4 steps chosen for the scene's fastest modes, or "
        "the file's tScheme with its dtM for a MoorDyn file); auto chooses its step in place of the file's dtM "
        "unless --dt is given",
    )
    run.add_argument("--dt", type=float, help="fixed step (s), as MoorDyn's dtM (default: the file's dtM, if any)")
    run.add_argument("--adaptive", action="store_true", help="step adaptively, even where the file gives dtM")
    run.add_argument("--rtol", type=float, help="relative tolerance of adaptive steps (default 1e-6)")
    run.add_argument("--atol", type=float, help="absolute tolerance of adaptive steps, m and m/s (default 1e-6)")
    run.add_argument("--max-steps", type=int, help="most solver steps before the run fails (default 1000000)")
    run.add_argument(
        "--no-statics",
        action="store_true",
        help="start from the file's geometry at rest, lines as MoorDyn lays them with TmaxIC = 0 (its catenary, "
        "or straight), for drop and swing tests; a MoorDyn file's TmaxIC = 0 asks for this too",
    )
    run.add_argument("--channels", nargs="+", help="output channels, e.g. FairTen1 AnchTen1 L1N10PZ Point2PZ Point2FZ")
    _scene_flags(run)
    run.add_argument("--no-progress", action="store_true", help="do not show the progress bar")
    run.set_defaults(handler=_run)

    info = commands.add_parser("info", help="print the parsed model, what is ignored, and advice")
    info.add_argument("input", help="scene (.toml), MoorDyn input file, or bundled example name")
    info.add_argument("--segments", type=int, help="divide every line into this many segments")
    info.add_argument("--duration", type=float, help="simulated time (s) the advice assumes")
    info.add_argument(
        "--stiffness",
        action="store_true",
        help="also report the coupled points' stiffness at rest (jaxcable.stiffness; compiles a program of its own)",
    )
    info.add_argument(
        "--advice-time",
        type=float,
        default=ADVICE_TIME,
        metavar="S",
        help=f"seconds to wait for the statics the advice checks segments, slack and stiffness at (default "
        f"{ADVICE_TIME:g}); past them, or with 0, the advice is what the model alone gives",
    )
    info.set_defaults(handler=_info)

    calibrate = commands.add_parser("calibrate", help="fit drag coefficients to towing records")
    calibrate.add_argument(
        "records",
        nargs="+",
        type=Path,
        help="towing records (CSV) whose headers name their rigs, or bundled records by name (jaxcable examples)",
    )
    calibrate.add_argument(
        "--fit",
        nargs="+",
        required=True,
        metavar="NAME=START",
        help="coefficients to fit, with starting values: normal_drag (K_n), tangential_drag "
        "(K_τ), specific_drag (k₀, s²/m²)",
    )
    calibrate.add_argument("--optimizer", choices=OPTIMIZERS, default="lbfgs", help="optax optimizer")
    calibrate.add_argument("--max-steps", type=int, default=50, help="most optimizer iterations (default 50)")
    calibrate.add_argument("--learning-rate", type=float, default=0.05, help="Adam's step in log coefficients")
    calibrate.add_argument("--rtol", type=float, default=1e-6, help="solver relative tolerance")
    calibrate.add_argument("--atol", type=float, default=1e-6, help="solver absolute tolerance")
    calibrate.add_argument("--plot", type=Path, help="save the data against the fit, and the loss, to this image")
    calibrate.add_argument("--out", type=Path, help="write the fitted values and uncertainties to this JSON file")
    calibrate.add_argument("--no-progress", action="store_true", help="do not show the progress bar")
    calibrate.add_argument(
        "--segments", type=int, help="divide every rig's cable into this many segments (overrides the records' headers)"
    )
    calibrate.add_argument(
        "--check-segments",
        action="store_true",
        help="after the fit, re-predict at twice the segments and report how far the predictions move",
    )
    calibrate.set_defaults(handler=_calibrate)

    campaign_command.add_parser(commands, _scene_flags)
    commands.choices["campaign"].set_defaults(handler=_campaign)

    examples = commands.add_parser("examples", help="list the bundled example scenes")
    examples.set_defaults(handler=_examples)
    return parser


def _scene_flags(parser: argparse.ArgumentParser) -> None:
    """The flags `run` and `campaign` share: what to do to the input file's scene
    (`--segments`, `--allow-ignored`, `--breaking-load`, `--fatigue`) and how to judge
    its results (`--safety-factor`, `--statistics-from`)."""
    parser.add_argument("--segments", type=int, help="divide every line into this many segments")
    parser.add_argument(
        "--allow-ignored",
        metavar="KINDS",
        help="run a MoorDyn file without the physics it asks for and jaxcable leaves out, named by kind "
        f"({', '.join(DROPPED_KINDS)}; comma-separated, e.g. EI,waves); without it such a file is refused",
    )
    parser.add_argument(
        "--breaking-load",
        nargs="+",
        metavar="[TYPE=]N",
        help="minimum breaking load (N) of a line type, e.g. chain=2.2e7 rope=8e6, or one value for every type: "
        "each line's utilisation is reported, and a line past --safety-factor warned of (a scene file may give "
        "minimum_breaking_load instead)",
    )
    parser.add_argument(
        "--safety-factor",
        type=float,
        default=DEFAULT_SAFETY_FACTOR,
        help="warn of a line whose largest tension passes its breaking load over this (default "
        f"{DEFAULT_SAFETY_FACTOR:g}, API RP 2SK's for an intact mooring, dynamic analysis)",
    )
    parser.add_argument(
        "--fatigue",
        nargs="+",
        metavar="[TYPE=]CURVE[:AREA]",
        help="a T-N curve for a line type's fatigue damage, e.g. chain=dnv_studless_chain:0.00907 "
        "rope=api_polyester, or one for every type: a DNV curve with the nominal area in m² (2 π d²/4 for "
        "chain), an API curve with the type's breaking load (a scene file may give fatigue_curve instead)",
    )
    parser.add_argument(
        "--statistics-from",
        type=float,
        default=0.0,
        metavar="S",
        help="leave the first S seconds (a start-up transient) out of each line's extremes and utilisation, each "
        "output channel's statistics and the fatigue damage (default 0)",
    )


def _input_path(args) -> Path:
    """The input file: a path, or a bundled example's by name."""
    from .io import SceneError

    path = Path(args.input)
    if not path.exists():
        if args.input in scene_names():
            return scene_path(args.input)
        if not path.suffix:
            raise SceneError(f"no file or bundled example named {args.input!r}; bundled: {', '.join(scene_names())}")
    return path


class _Input(NamedTuple):
    """What `run` and `info` read and check before JAX is imported (`_read_input`).

    - `parsed`: the input file, read and checked, with `--segments` applied.
    - `motion`: `--motion`'s table, times (s) of shape `(samples,)` and positions (m)
        of shape `(samples, coupled, 3)`; `None` without one.
    - `duration`: the simulated time (s): `--duration`, or the motion table's last
        time, or the file's.
    - `settings`: the file's run settings, with `run`'s stepping flags.
    """

    parsed: "ParsedScene"
    motion: tuple[np.ndarray, np.ndarray] | None
    duration: float
    settings: "RunSettings"


def _read_input(args) -> _Input:
    """Read and check the input file of `run` or `info`, and `run`'s motion table, in
    plain Python and numpy, as [`jaxcable.load_scene`][] reads it: a jaxcable scene
    if it ends in `.toml`, otherwise a MoorDyn file. `SceneError` for anything the
    files and flags alone refuse: a malformed file, physics left out that
    `--allow-ignored` does not allow, a motion table that does not fit the scene or
    the duration, stepping flags that contradict each other or the file."""
    from .io import SceneError

    parsed = _read_scene(args)
    scene = parsed.scene
    duration = scene.run.duration if args.duration is None else args.duration
    if args.command == "info":
        return _Input(parsed, None, duration, scene.run)
    motion = None
    if args.ramp is not None and args.motion is None:
        raise SceneError("--ramp switches a --motion table on smoothly: give the table with --motion")
    if args.motion is not None:
        from .io import read_motion_file

        coupled = scene.coupled_points
        if not coupled:
            raise SceneError(f"--motion {args.motion}: the scene has no coupled points to move")
        times, positions = read_motion_file(args.motion, len(coupled))
        if times[0] > 0:
            raise SceneError(f"--motion {args.motion}: the table starts at {times[0]:g} s; it must cover t = 0")
        if args.duration is None:
            duration = times[-1]
        if duration > times[-1]:
            raise SceneError(f"--duration {duration:g} s runs past the motion table's last time, {times[-1]:g} s")
        motion = (times, positions)
    if args.statistics_from > 0 and args.statistics_from >= duration:
        raise SceneError(
            f"--statistics-from {args.statistics_from:g} s leaves nothing of a {duration:g} s run: give a time "
            "before its end"
        )
    return _Input(parsed, motion, duration, _run_settings(scene, args))


def _read_scene(args) -> "ParsedScene":
    """The input file, read in plain Python as [`jaxcable.load_scene`][] reads it (a
    jaxcable scene if it ends in `.toml`, otherwise a MoorDyn file), with the shared
    flags (`_scene_flags`) applied; `SceneError` for a malformed file or flag, and, but
    for `info`, physics left out that `--allow-ignored` does not allow."""
    from .io import SceneError

    path = _input_path(args)
    if path.suffix.lower() == ".toml":
        from .io._scene_file import parse_scene as parse
    else:
        from .io._moordyn import parse_moordyn as parse
    parsed = parse(path)
    if args.segments is not None:
        parsed = dataclasses.replace(parsed, scene=parsed.scene.with_segments(args.segments))
    if getattr(args, "breaking_load", None):
        loads = parsed.scene.with_breaking_loads(_breaking_loads(args.breaking_load), "--breaking-load")
        parsed = dataclasses.replace(parsed, scene=loads)
    if getattr(args, "fatigue", None):
        curves = parsed.scene.with_fatigue_curves(_fatigue_curves(args.fatigue), "--fatigue")
        parsed = dataclasses.replace(parsed, scene=curves)
    for line_type in parsed.scene.line_types:  # an API curve's breaking load, from the file or a flag
        if problem := line_type.fatigue_problem():
            raise SceneError(problem)
    if args.command != "info":
        _refuse_dropped(parsed.scene, _allowed(args))
    return parsed


def _read_campaign(args) -> tuple["ParsedScene", "campaign_command.Given"]:
    """The input file and the case table of `campaign`, checked before JAX is imported."""
    parsed = _read_scene(args)
    return parsed, campaign_command.read(args, parsed.scene)


def _campaign(args, given) -> int:
    parsed, read = given
    scene = _finish(parsed)
    for note in scene.notes:
        print(f"note: {note}", file=sys.stderr)
    return campaign_command.run(args, read._replace(scene=scene))


def _fatigue_curves(items: list[str]) -> dict[str | None, tuple[str, float | None]]:
    """`--fatigue`'s items, `TYPE=CURVE[:AREA]` or a lone `CURVE[:AREA]` for every line
    type, as `Scene.with_fatigue_curves` takes them."""

    def curve(given: str) -> tuple[str, float | None]:
        name, _, area = given.partition(":")
        return name.strip(), float(area) if area else None

    return _by_line_type(items, "--fatigue", "CURVE", "[TYPE=]CURVE[:AREA], an area in m² after the colon", curve)


def _breaking_loads(items: list[str]) -> dict[str | None, float]:
    """`--breaking-load`'s items, `TYPE=N` or a lone `N` for every line type, as
    `Scene.with_breaking_loads` takes them."""
    return _by_line_type(items, "--breaking-load", "N", "TYPE=N or N, a load in newtons", float)


def _by_line_type(items: list[str], flag: str, value: str, form: str, parse: Callable[[str], Any]) -> dict:
    """A flag's items, `TYPE=VALUE` or one lone `VALUE` for every line type (the key
    `None`), each value read by `parse`; `SceneError` naming the flag and item for a
    value `parse` refuses (`ValueError`), a lone value among several, or a type named
    twice."""
    from .io import SceneError

    values: dict = {}
    for item in items:
        name, _, given = item.rpartition("=")
        key = name.strip() or None
        if key is None and len(items) > 1:
            raise SceneError(f"{flag} {item}: name the line type (TYPE={value}) where more than one is given")
        try:
            parsed = parse(given)
        except ValueError:
            raise SceneError(f"{flag} {item}: expected {form}") from None
        if key in values:
            raise SceneError(f"{flag} names line type {key} twice")
        values[key] = parsed
    return values


def _finish(parsed: "ParsedScene") -> "Scene":
    """The scene `parsed` with the engine's parts made (`ParsedScene.finish`)."""
    with warnings.catch_warnings():
        warnings.simplefilter("ignore")  # the command prints the scene's notes itself
        return parsed.finish()


def _allowed(args) -> set[str]:
    """The kinds of left-out physics `--allow-ignored` names; `SceneError` for one that
    is not a kind."""
    from .io import SceneError

    kinds = {kind.strip() for kind in (args.allow_ignored or "").split(",") if kind.strip()}
    unknown = sorted(kinds - set(DROPPED_KINDS))
    if unknown:
        raise SceneError(
            f"--allow-ignored: unknown kind(s) {', '.join(unknown)}; the kinds: {', '.join(DROPPED_KINDS)}"
        )
    return kinds


def _refuse_dropped(scene: "Scene", allowed: set[str]) -> None:
    """`SceneError` naming each option and line of the physics the file asks for and
    jaxcable leaves out, unless `--allow-ignored` allows its kind."""
    from .io import SceneError

    refused = [(kind, note) for kind, note in scene.dropped if kind not in allowed]
    if refused:
        kinds = ",".join(dict.fromkeys(kind for kind, _ in refused))
        raise SceneError(
            "the file asks for physics jaxcable leaves out, which would change the answer:\n  "
            + "\n  ".join(note for _, note in refused)
            + f"\nto run without it, add --allow-ignored {kinds}"
        )


def _check_numbers(args) -> None:
    """Refuse a flag's number out of range, before any work (and before JAX is
    imported)."""
    from .io import SceneError

    for flag, value, allow_zero in (
        ("--duration", "duration", True),
        ("--dt-out", "dt_out", False),
        ("--ramp", "ramp", True),
        ("--advice-time", "advice_time", True),
        ("--statistics-from", "statistics_from", True),
    ):
        number = getattr(args, value, None)
        if number is not None and not (np.isfinite(number) and (number >= 0 if allow_zero else number > 0)):
            kind = "non-negative" if allow_zero else "positive"
            raise SceneError(f"{flag} must be a {kind} number of seconds, got {number:g}")
    factor = getattr(args, "safety_factor", None)
    if factor is not None and not (np.isfinite(factor) and factor >= 1):
        raise SceneError(f"--safety-factor must be a number of at least 1 (1: up to the breaking load), got {factor:g}")
    for flag, value in (("--segments", "segments"), ("--max-steps", "max_steps")):
        number = getattr(args, value, None)
        if number is not None and number < 1:
            raise SceneError(f"{flag} must be a positive integer, got {number}")
    for flag, value in (("--learning-rate", "learning_rate"), ("--rtol", "rtol"), ("--atol", "atol"), ("--dt", "dt")):
        number = getattr(args, value, None)
        if number is not None and not (np.isfinite(number) and number > 0):
            raise SceneError(f"{flag} must be a positive number, got {number:g}")
    rtol = getattr(args, "rtol", None)
    if rtol is not None and rtol < SMALLEST_RTOL:  # SolverConfig's own check, by the flag's name
        raise SceneError(
            f"--rtol must be at least {SMALLEST_RTOL:g}, below which float64 rounding (ε = 2.2e-16) exceeds the "
            f"error the step controller allows and the step shrinks without end, got {rtol:g}"
        )
    if rtol is not None and rtol > LARGEST_RTOL:
        raise SceneError(
            f"--rtol must be at most {LARGEST_RTOL:g}: a looser step's error is as large as the solution, got {rtol:g}"
        )


def _check_no_overwrite(args) -> None:
    """Refuse an output (`--out`, `--plot`) that is one of the command's inputs (the
    scene or MoorDyn file, `--motion`'s table, a towing record) or the other output:
    a run would overwrite what the user gave it."""
    from .io import SceneError

    given = []
    if getattr(args, "input", None) is not None:
        given.append(("the input file", Path(args.input)))
    if getattr(args, "motion", None) is not None:
        given.append(("--motion", Path(args.motion)))
    given += [("a towing record", Path(record)) for record in getattr(args, "records", None) or ()]
    written = [
        (flag, Path(path)) for flag in ("--out", "--plot") if (path := getattr(args, flag[2:], None)) is not None
    ]
    for k, (flag, path) in enumerate(written):
        for what, other in given + written[:k]:
            if _same_file(path, other):
                raise SceneError(f"{flag} {path} is {what} ({other}): the run would overwrite it; write elsewhere")


def _same_file(a: Path, b: Path) -> bool:
    """Whether paths `a` and `b` name one file (the same link target, or the same path
    where neither exists yet)."""
    if a.exists() and b.exists():
        return os.path.samefile(a, b)
    return a.resolve() == b.resolve()


def _check_output_files(args) -> None:
    """Refuse an output or plot file that could not be written at the end of a run,
    before the run."""
    from .io._output import check_output, check_writable

    out = getattr(args, "out", None)
    if out is not None:
        if args.command == "run":
            check_output(out, "--out")
        else:
            check_writable(out, "--out")
    if getattr(args, "plot", None) is not None:
        from .plot import check_plot_path

        check_plot_path(args.plot, "--plot")


def _run(args, given: _Input) -> int:
    from ._simulation.blocks import SimulationFailed, SimulationInterrupted
    from .io import write_output
    from .io._channels import default_channels, parse_channel
    from .io._extremes import overloads, table
    from .io._line_fatigue import table as fatigue_table
    from .io._run import run_scene
    from .io._statistics import table as statistics_table

    scene = _finish(given.parsed)
    if given.motion is not None:
        times, positions = given.motion
        with warnings.catch_warnings(record=True) as caught:
            warnings.simplefilter("always", UserWarning)
            scene = scene.with_motion_table(
                times, positions, f"--motion {args.motion}", args.motion_interpolation, args.ramp or 0.0
            )
        for warning in caught:  # a spline that overshoots the table, a table that starts moving
            message = str(warning.message)
            prefix = f"--motion {args.motion}"
            print(f"warning: {message if message.startswith(prefix) else f'{prefix}: {message}'}", file=sys.stderr)
    for note in scene.notes:
        print(f"note: {note}", file=sys.stderr)
    held = [scene.points[k].name for k in scene.coupled_points if scene.points[k].motion is None]
    if held:
        print(
            f"note: coupled point(s) {', '.join(held)} have no motion and are held where they are; give a "
            "motion table with --motion",
            file=sys.stderr,
        )
    print(f"{Path(scene.source).name}" + (f": {scene.title}" if scene.title else ""))
    channels = tuple(args.channels or ())
    for name in channels or default_channels(scene):
        parse_channel(name, scene)  # fail now, not after the simulation
    settings = given.settings
    try:
        run = run_scene(
            dataclasses.replace(scene, run=settings),  # its solver chosen for the scene where "auto"
            duration=given.duration,
            dt_out=args.dt_out,
            progress=not args.no_progress,
            statics=settings.statics,
            stop=args.stop,
        )
        failure = None
    except SimulationFailed as error:  # what ran before the failure is reported and written
        if error.partial is None:
            raise
        run, failure = error.partial, error
    static = run.static
    # The equilibrium's own tensions: the first output's would carry the damping of a
    # table that starts moving at t = 0.
    start = np.asarray(run.tension[0] if static is None else static.tension)
    if static is None:
        source = "--no-statics" if args.no_statics else "the file's TmaxIC = 0"
        print(f"statics skipped ({source}): the run starts from the file's geometry at rest; ", end="")
    else:
        print(f"equilibrium: {int(static.steps)} iterations, {run.statics_seconds:.1f} s; ", end="")
    print(f"largest tension {float(np.max(start)) / 1e3:.3f} kN, smallest {float(np.min(start)) / 1e3 + 0.0:.3f} kN")
    sys.stdout.flush()  # keep stdout and stderr lines in the order they were written
    for note in run.notes:
        print(f"warning: {note}", file=sys.stderr)
    interrupted = isinstance(failure, SimulationInterrupted)
    ended = "it was interrupted" if interrupted else "it failed"
    so_far = "" if failure is None else f" (the run up to t = {failure.time:g} s, where {ended})"
    if args.out is not None:
        write_output(args.out, run, channels)
        print(f"wrote {args.out}{so_far}")
    if args.plot is not None:
        from .plot import plot_run

        plot_run(run, args.plot, channels)
        print(f"wrote {args.plot}{so_far}")
    # A run that failed before `--statistics-from` keeps its extremes over what it ran.
    windowed = bool(run.steps) and run.times[-1] > args.statistics_from
    start = args.statistics_from if windowed else 0.0
    extremes = run.line_extremes(start)
    if start > 0:
        print(f"line tensions over t = {start:g} to {run.times[-1]:g} s:")
    print(table(extremes))
    if windowed:
        print(statistics_table(run.channel_statistics(channels, start)))
        if fatigue := run.line_fatigue(start):
            print(fatigue_table(fatigue))
    sys.stdout.flush()
    for warning in overloads(extremes, args.safety_factor):
        print(f"warning: {warning}", file=sys.stderr)
    print(run.summary())
    for _, note in scene.dropped:
        print(f"left out (--allow-ignored): {note}")
    if failure is not None:
        sys.stdout.flush()
        written = " and the files written" if args.out or args.plot else ""
        what = "" if interrupted else "solver failed: "
        print(
            f"jaxcable: {what}{str(failure).rstrip('.')}; the results above{written} are the run before it",
            file=sys.stderr,
        )
        return INTERRUPTED if interrupted else 1
    return 0


def _run_settings(scene: "Scene", args) -> "RunSettings":
    """The scene's run settings with the command line's `--solver`, `--dt`,
    `--adaptive`, `--rtol`, `--atol`, `--max-steps` and `--no-statics` (their values
    checked by `_check_numbers`); `SceneError` naming the flags that contradict each
    other."""
    from .io import SceneError

    if args.dt is not None and args.adaptive:
        raise SceneError("--dt asks for fixed steps and --adaptive for adaptive ones: give one of them")
    changes: dict = {"solver": args.solver, "dt": args.dt, "rtol": args.rtol, "atol": args.atol}
    changes = {key: value for key, value in changes.items() if value is not None}
    if args.max_steps is not None:
        changes["max_steps"] = args.max_steps
    if args.solver == AUTO and args.dt is None:
        changes["dt"] = None  # auto chooses its step, in place of a file's dtM
    if args.adaptive:
        changes["dt"] = None
        if changes.get("solver", scene.run.solver) == AUTO:  # auto's steps are fixed
            changes["solver"] = "dopri5"
    if args.no_statics:
        changes["statics"] = False
    settings = dataclasses.replace(scene.run, **changes)
    if args.rtol is not None or args.atol is not None:
        if settings.dt is not None:
            raise SceneError(
                f"--rtol and --atol set adaptive steps, but this run takes fixed steps of {settings.dt:g} s "
                f"({'--dt' if args.dt is not None else 'the file'}): add --adaptive, or leave them out"
            )
        if settings.solver == AUTO:
            raise SceneError(
                "--rtol and --atol set adaptive steps, but solver auto takes fixed steps chosen for the scene: "
                "add --adaptive (Dopri5), or name an adaptive solver with --solver"
            )
    return settings


def _info(args, given: _Input) -> int:
    from ._solver.config import describe_stepping
    from ._solver.stability import STABLE_GROWTH, STEP_FRACTION, fixed_step_growth
    from .io import advice_lines
    from .io._run import DEFAULT_DT_OUT, check_size

    scene = _finish(given.parsed)
    built = scene.build()
    model = built.model
    water = scene.water
    duration = given.duration
    # The advice solves statics: refuse a model too large for memory first.
    for warning in check_size(built, duration, scene.run.dt_out or DEFAULT_DT_OUT, scene.run.solver_config()):
        print(f"warning: {warning}", file=sys.stderr)
    print(f"{scene.source}" + (f": {scene.title}" if scene.title else ""))
    depth = "unbounded" if water.depth is None else f"{water.depth:g} m"
    profile = water.current_profile
    current = (
        f"{water.current} m/s"
        if profile is None
        else f"profile {profile.speeds} m/s at z = {profile.heights} m, towards {profile.heading:g}°"
    )
    print(
        f"water: density {water.density:g} kg/m³, g = {water.gravity:g} m/s², depth {depth}, current {current}, "
        f"free surface {'on' if water.free_surface else 'off (lines wholly submerged)'}, "
        f"fluid inertia {'on' if water.fluid_inertia else 'off (waves load by drag only)'}"
    )
    for k, wave in enumerate(water.waves, start=1):
        print(f"wave {k}: {wave.describe()}")
    if water.waves and water.wave_ramp > 0:
        print(f"waves switched on smoothly over the first {water.wave_ramp:g} s")
    # build() refused a seabed without a depth.
    if water.seabed is not None and water.depth is not None:
        bed = water.seabed
        if not bed.friction:
            form = " (none)"
        elif bed.friction_damping is not None:
            form = f" (MoorDyn's: μ·{bed.friction_damping:g} N·s/m·|v| up to μN)"
        else:
            form = f" (viscous below {bed.friction_speed:.4g} m/s)"
        friction = f"friction μ = {bed.friction:g}{form}"
        print(
            f"seabed: at z = {-water.depth:g} m, stiffness {bed.stiffness:g} Pa/m, damping {bed.damping:g} Pa·s/m, "
            f"{friction}"
        )
    print(
        f"model: {model.n_nodes} nodes ({model.free_nodes.size} free), {model.n_segments} segments, "
        f"{model.mass_matrix} mass matrix, hydrodynamics at the {model.hydrodynamics}"
    )
    print("line types:")
    for t in scene.line_types:
        damping = (
            f"C_v = {t.axial_damping:g} N·s"
            if not t.axial_damping_ratio
            else f"ζ = {t.axial_damping_ratio:g} of critical per segment"
        )
        print(
            f"  {t.name}: m = {t.mass_per_length:g} kg/m, d = {t.diameter:g} m, EA = {t.axial_stiffness:g} N, "
            f"C_E1 = {t.quadratic_stiffness:g} N, {damping}, K_n = {t.normal_drag:g}, K_τ = {t.tangential_drag:g}, "
            f"C_a = {t.normal_added_mass:g}, C_aτ = {t.tangential_added_mass:g}"
        )
    print("points:")
    for p in scene.points:
        extra = ""
        if p.kind == "coupled":
            extra = ", " + _describe_motion(p.motion)
        if p.body is not None:
            extra += (
                f", body: mass {float(p.body.mass):g} kg, volume {float(p.body.volume):g} m³, "
                f"CdA {float(p.body.drag_area):g} m²"
            )
        print(f"  {p.name} ({p.kind}) at {p.position}{extra}")
    print("lines:")
    for k, line in enumerate(scene.lines):
        segments = built.line_segments[k]
        damping = float(np.asarray(model.line.tension_law.damping())[segments[0]])
        a, b = scene.points[line.start].name, scene.points[line.end].name
        print(
            f"  {line.name}: {line.line_type} from {a} to {b}, {line.length:g} m in {line.segments} segments "
            f"of {line.length / line.segments:.4g} m, C_v = {damping:.4g} N·s"
        )
    run = scene.run
    if run.dt is not None:
        stepping = f"(fixed steps of {run.dt:g} s)"
    elif run.solver == AUTO:
        chosen = run.solver_config(built, duration)
        stepping = f"({describe_stepping(chosen)}: {STEP_FRACTION:g} of its stability limit at the fastest modes)"
    else:
        stepping = f"(rtol {run.rtol:g}, atol {run.atol:g})"
    print(
        f"run: {duration:g} s, solver {run.solver} {stepping}"
        + f", output every {run.dt_out or DEFAULT_DT_OUT:g} s"
        + ("" if run.statics else "; no statics: starts from the file's geometry at rest")
    )
    if run.dt is not None:
        solver = run.solver_config().solver
        growth = fixed_step_growth(solver, run.dt, built, steps=math.ceil(duration / run.dt))
        if growth is not None:
            verdict = "stable" if growth <= STABLE_GROWTH else "unstable: the run takes RK4 at a stable step instead"
            print(
                f"fixed step: {type(solver).__name__} at {run.dt:g} s, largest growth of a fast mode a step "
                f"|R(λΔt)| = {growth:.3g}: {verdict}"
            )
    print("channels: " + " ".join(scene.channels or ["FairTen<k> AnchTen<k> for every line"]))
    print("ignored or assumed:" if scene.notes else "ignored or assumed: nothing")
    for note in scene.notes:
        print(f"  {note}")
    advice, late = _advice_within(built, duration, args.stiffness, args.advice_time)
    print("advice:" if late is None else f"advice ({late}):")
    for line in advice_lines(advice):
        print(f"  {line}")
    return 0


ADVICE_TIME = 20.0
"""Seconds `jaxcable info` waits for its advice's statics by default."""


def _advice_within(built, duration: float, stiffness: bool, seconds: float):
    """`info`'s advice, and why it leaves out what needs the mean equilibrium (or
    `None`): the statics solve on a thread of its own for at most `seconds` (s), after
    which the advice is what the model alone gives.

    A hard scene's statics (MoorDyn's tripod: 82 short segments with EI, which
    diverge after 80 s) would otherwise hold `info` for minutes after everything else
    was printed. The solve cannot be stopped: it is left to run while the command ends
    (the process ends with it)."""
    from ._advice import advise

    if seconds > 0:
        done, outcome = _on_thread(lambda: advise(built, duration=duration, stiffness=stiffness), "jaxcable advice")
        if done.wait(seconds):
            return _outcome(outcome), None
        late = f"statics did not finish within {seconds:g} s; --advice-time S waits longer"
    else:
        late = "statics left out by --advice-time 0"
    return advise(built, duration=duration, statics=False), late


def _describe_motion(motion) -> str:
    from ._model.motion import Harmonic, Sampled

    if motion is None:
        return "held (no motion given)"
    if isinstance(motion, Harmonic):
        direction = tuple(round(float(x), 4) for x in motion.direction)
        return (
            f"harmonic: amplitude {float(motion.amplitude):g} m, period {float(motion.period):g} s, "
            f"direction {direction}, phase {float(motion.phase):g} rad, ramp {float(motion.ramp):g} s"
        )
    if isinstance(motion, Sampled):
        return f"table of {motion.times.size} samples from {float(motion.times[0]):g} to {float(motion.times[-1]):g} s"
    return type(motion).__name__


def _optimizer(name: str, learning_rate: float):
    """The `calibrate` command's optimizer `name` (one of `OPTIMIZERS`), made from
    `--learning-rate` (which L-BFGS, with its line search, does not use)."""
    import optax

    from ._calibration.calibrate import default_optimizer

    return default_optimizer() if name == "lbfgs" else optax.adam(learning_rate)


def _calibrate(args) -> int:
    from ._calibration.calibrate import calibrate, calibration_solver
    from ._calibration.discretisation import discretisation_check
    from ._calibration.towing import rig_from_conditions
    from .io import SceneError, read_records

    start = {}
    for item in args.fit:
        name, _, value = item.partition("=")
        try:
            start[name.strip()] = float(value)
        except ValueError:
            raise SceneError(f"--fit {item!r}: give NAME=START, e.g. normal_drag=1.2") from None
    if args.segments is not None and args.segments < 1:
        raise SceneError(f"--segments must be a positive integer, got {args.segments}")
    try:
        records = read_records([_record_path(path) for path in args.records])
        tests = records
        if args.segments is not None:
            tests = [(rig_from_conditions({**r.conditions, "segments": args.segments}, r.name), r) for r in records]
        with warnings.catch_warnings():
            warnings.simplefilter("ignore")  # the summary prints the warnings itself
            result = calibrate(
                tests,
                start,
                optimizer=_optimizer(args.optimizer, args.learning_rate),
                max_steps=args.max_steps,
                solver=calibration_solver(rtol=args.rtol, atol=args.atol),
                progress=not args.no_progress,
            )
    except ValueError as error:  # a malformed record, an unknown rig or coefficient
        raise SceneError(str(error)) from None
    except OSError as error:  # a record that is missing, or a folder
        raise SceneError(f"cannot read {error.filename}: {error.strerror}") from None
    print(result.summary())
    check = None
    if args.check_segments:
        try:
            with warnings.catch_warnings():
                warnings.simplefilter("ignore")  # printed below
                check = discretisation_check(result, solver=calibration_solver(rtol=args.rtol, atol=args.atol))
        except RuntimeError as error:  # the fit stands; only its check could not be made
            print(f"warning: cannot check the segmentation: {error}")
        else:
            for (name, observable), moved in check.shift.items():
                coarse, fine = check.segments[name]
                print(f"{name}: {observable} moves {moved:.3g} σ from {coarse} to {fine} segments")
            for name, move in check.moves.items():
                print(f"{name} would move {100 * move:+.3g} % refitted at twice the segments (linearised)")
            for message in check.warnings:
                print(f"warning: {message}")
    if args.out is not None:
        summary = {
            "values": result.values,
            "uncertainty": result.uncertainty,
            "relative_uncertainty": result.relative_uncertainty,
            "correlation": result.correlation.tolist(),
            "sensitivity": result.sensitivity,
            "start": result.start,
            "loss": result.loss.tolist(),
            "iterations": result.iterations,
            "converged": result.converged,
            "stalled": result.stalled,
            "tangent_error": result.tangent_error,
            "tolerances": result.tolerances,
            "noise": [{"record": r, "observable": o, "sigma": s} for (r, o), s in result.noise.items()],
            "records": [r.name for r in result.records],
            "success": result.success,
            "warnings": result.warnings + (check.warnings if check is not None else []),
            "inflation": result.inflation,
            "residual_checks": [
                {"record": r, "observable": o, **dataclasses.asdict(c)} for (r, o), c in result.residual_checks.items()
            ],
        }
        if check is not None:
            summary["discretisation"] = [
                {"record": r, "observable": o, "segments": check.segments[r], "shift_sigma": m}
                for (r, o), m in check.shift.items()
            ]
            summary["discretisation_moves"] = check.moves
        args.out.write_text(json.dumps(summary, indent=2) + "\n")
        print(f"wrote {args.out}")
    if args.plot is not None:
        from .plot import plot_calibration

        plot_calibration(result, args.plot)
        print(f"wrote {args.plot}")
    return 0


def _record_path(path: Path) -> Path:
    """A towing record's file: a path, or a bundled record's by name."""
    from .io import SceneError

    if not path.exists():
        if str(path) in record_names():
            return record_path(str(path))
        if not path.suffix:
            raise SceneError(
                f"no file or bundled towing record named {str(path)!r}; bundled: {', '.join(record_names())}"
            )
    return path


def _examples(args) -> int:
    del args
    for name in scene_names():
        print(f"{name:14s} {scene_title(name)}")
    print(f"(scene files in {scene_path(scene_names()[0]).parent}; run one with `jaxcable run NAME`)")
    records = record_names()
    print(
        f"\nsample towing records: {', '.join(records)} (in {record_path(records[0]).parent}), synthetic tows "
        "of known drag (see README); fit them with\n"
        f"  jaxcable calibrate {' '.join(records)} --fit normal_drag=1.2 tangential_drag=0.01"
    )
    return 0


if __name__ == "__main__":
    sys.exit(main())
