"""The speed issue's target table, jaxcable beside MoorDyn, measured in one run.

Every speed figure is a ratio to MoorDyn 2 (`pip install moordyn`) measured in the same
run on the same machine: the machine this was written for is a shared 2-core CPU on
which other jobs run, so absolute times drift, and timings are medians over repeats
(interleaved with MoorDyn's where both are timed), compile time apart. The load average
is recorded at the start and end of every row.

Rows (`--only` takes these names):

- `ll`: Low & Langley (2006) case 1 from its MoorDyn file (`lowe_langley.py`), three rows.
  *run*: the median warm in-process `run_scene` (compile apart) over MoorDyn's stepping
  time at the file's dtM = 1 ms (its IC generation not timed), with the RMS error of the
  top tension (|R| and `FairTen1`) against the digitised reference beside each engine's;
  met when the ratio is ≤ 0.5 and jaxcable's RMS error of |R| is no larger than
  MoorDyn's. |R| is what the reference gives, the top tension at the support: the
  support's force on the line (MoorDyn's own regression test compares its top node's
  net force). `FairTen1` is the top segment's tension, half a segment below the
  support, and both engines' sit about 0.4 kN under the reference for that reason
  alone (`benchmarks/README.md`, *Which top tension*); it is reported, not judged.
  *process, cold* and *warm*: the whole `jaxcable run line.txt --motion ...` process
  over a whole Python process that runs MoorDyn on the same case (start-up, input, IC
  generation, stepping, saving its results). Cold: `JAX_COMPILATION_CACHE_DIR` pointed
  at a new, empty folder, with `JAX_PERSISTENT_CACHE_MIN_COMPILE_TIME_SECS=0` so that
  every program is cached; warm: a second process with the same folder.
- `anchored_line`: the anchored line (`moordyn_side_by_side.scene`: lumped, nodal
  hydrodynamics as MoorDyn's, linear EA, slack band 1e-6) at each `--segments`,
  `--duration` (60 s) simulated, at matched error. The error is the RMS top-tension
  difference from a Dopri8 reference at rtol = atol = 1e-12, relative to its peak,
  over t ≤ 3 s: the line's tension can be converged
  pointwise only up to its first slack event (see `moordyn_side_by_side.py`). Short
  runs (4 s) of MoorDyn at several dtM and of jaxcable's settings find, for each engine,
  the cheapest setting within `--level` (1e-3) and the next cheaper one; those are timed
  over the whole duration and each engine's time at the level interpolated in log-log
  between them (`moordyn_side_by_side.wall_at`). jaxcable's settings come in families,
  each bracketed and interpolated on its own, and the fastest family's time is the
  row's: Dopri5 at `--tols`, and each of `--fixed` (Bosh3, RK4, Tsit5) at fixed steps
  `--fixed-dt` (scaled by 20/N as MoorDyn's dtM is), the way a MoorDyn user picks dtM.
  A step beyond a method's stability limit shows as an infinite error and is not picked.
- `sweep`: `moordyn_side_by_side.part_sweep`: 256 wave steepnesses as one
  `jaxcable.sweep` (`--sweep-steps`, shared steps by default; the default chunks, one
  per core), against 256 sequential MoorDyn runs (stepping time, IC generation
  apart). MoorDyn runs at dtM = 1 ms; jaxcable at each family's cheapest setting whose
  error, in the N = 20 `anchored_line` row of the same run, is no larger than MoorDyn's there
  (Dopri5 at the tolerance of equal error, interpolated; each fixed-step family at its
  largest step within that error; `sweep_settings`). Each is timed, and the fastest is
  the row's.
- `field`: the cost per node of one force evaluation, `jaxcable.equations.vector_field`
  on the anchored line (N = 20, 21 nodes, lumped), vmapped over a batch of 256 cases (the
  sweep's fairlead amplitudes) inside one compiled `fori_loop` (`step_cost.field_seconds`),
  in ns per node per case-evaluation; the single run's beside it. MoorDyn's: its
  seconds per RK2 step at dtM = 1 ms on the same line (10 s), less its Python stepping
  loop's share (`moordyn_side_by_side.python_overhead`), over 2 evaluations a step and
  21 nodes (an upper bound: a step also updates the state).
- `compile`: the first `jaxcable.simulate` call less the median warm call, on
  `anchored_line(20, mass_matrix="lumped")` from its statics, 10 s at 20 Hz, with JAX's
  in-memory caches cleared first and its persistent cache off (as it is for this whole
  process: only the `ll` processes use one).

Threads. The rows that time one run at a time (`compile`, `ll`, `anchored_line`) run as
`jaxcable run` does, with XLA's CPU backend on one kernel thread (`PJRT_NPROC=1`; see
`jaxcable._cli._one_kernel_thread`): when other rows are asked for too, they run in a
child process of this script. The batched rows (`field`, `sweep`) keep the backend's
default thread pool, which the sweep's chunks run on. A `PJRT_NPROC` set by the caller
applies to every row.

`--quick` is a smoke run, NOT the target measurement: one repeat, N = 20 only over 10 s,
a 16-case 4 s sweep, one process pair.

    python benchmarks/speed.py                       # the whole table (25 min here, quiet-ish)
    python benchmarks/speed.py --quick               # smoke run
    python benchmarks/speed.py --only anchored_line --segments 20
    python benchmarks/speed.py --report              # the latest table as markdown

Results are appended to benchmarks/results/speed.json.
"""

import argparse
import json
import os
import shutil
import statistics
import subprocess
import sys
import tempfile
import time
from pathlib import Path

import numpy as np

BENCHMARKS = Path(__file__).resolve().parent
RESULTS = BENCHMARKS / "results" / "speed.json"
ROWS = ("compile", "field", "ll", "anchored_line", "sweep")
SINGLE_RUN_ROWS = ("compile", "ll", "anchored_line")  # timed on one kernel thread, as `jaxcable run` runs
OUTPUT_DT = 0.05  # s: 20 Hz, moordyn_side_by_side's output interval


def parse(argv=None):
    parser = argparse.ArgumentParser(description=__doc__, formatter_class=argparse.RawDescriptionHelpFormatter)
    parser.add_argument("--only", nargs="+", choices=ROWS, default=list(ROWS), help="run only these rows")
    parser.add_argument("--quick", action="store_true", help="smoke run (not the target measurement)")
    parser.add_argument("--repeats", type=int, default=3, help="warm runs timed per configuration")
    parser.add_argument(
        "--slow",
        type=float,
        default=20.0,
        help="a configuration whose warm run takes longer than this (s) is timed once",
    )
    parser.add_argument("--process-repeats", type=int, default=2, help="cold / warm / MoorDyn process triples")
    parser.add_argument("--segments", type=int, nargs="+", default=[20, 100], help="anchored_line rows' N")
    parser.add_argument("--duration", type=float, default=60.0, help="anchored_line rows' simulated time (s)")
    parser.add_argument("--level", type=float, default=1e-3, help="anchored_line rows' matched RMS error / peak")
    parser.add_argument("--window", type=float, default=3.0, help="errors are taken over t ≤ window (s)")
    parser.add_argument("--reference-tol", type=float, default=1e-12)
    parser.add_argument("--tols", type=float, nargs="+", default=[1e-3, 3e-4, 1e-4, 3e-5, 1e-5, 3e-6, 1e-6])
    parser.add_argument(
        "--fixed",
        nargs="*",
        default=["Bosh3", "RK4", "Tsit5"],
        help="explicit solvers (diffrax's, or jaxcable's RK4) also tried at fixed steps (`--fixed-dt`), beside "
        "Dopri5's tolerances",
    )
    parser.add_argument(
        "--fixed-dt",
        type=float,
        nargs="+",
        default=[9e-3, 8e-3, 7e-3, 6e-3, 5e-3, 4.5e-3, 4e-3, 3e-3, 2e-3, 1e-3],
        help="jaxcable's fixed steps (s) at N = 20, scaled by 20/N for other N (and rounded to divide 0.05 s)",
    )
    parser.add_argument(
        "--dtm",
        type=float,
        nargs="+",
        default=[2e-3, 1e-3, 5e-4, 2.5e-4, 1e-4, 5e-5],
        help="MoorDyn steps (s) at N = 20, scaled by 20/N for other N (and rounded to divide 0.05 s)",
    )
    parser.add_argument("--cases", type=int, default=256, help="sweep cases")
    parser.add_argument("--sweep-duration", type=float, default=10.0)
    parser.add_argument("--sweep-repeats", type=int, default=2)
    parser.add_argument(
        "--sweep-steps", choices=["per_case", "shared"], default="shared", help="jaxcable.sweep's steps"
    )
    parser.add_argument("--batch", type=int, default=256, help="field row's batch")
    parser.add_argument("--slack-width", type=float, default=1e-6)
    parser.add_argument("--out", type=Path, default=RESULTS)
    parser.add_argument("--report", action="store_true", help="print the latest recorded table")
    args = parser.parse_args(argv)
    if args.quick:
        args.repeats, args.process_repeats, args.sweep_repeats = 1, 1, 1
        args.duration, args.cases, args.sweep_duration = 10.0, 16, 4.0
        args.segments = [20]
        args.tols = [1e-3, 1e-4, 1e-5, 1e-6]
        args.dtm = [1e-3, 5e-4, 2.5e-4, 1e-4]
        args.fixed_dt = [5e-3, 4e-3, 2e-3]
    return args


# Another job on a shared machine may stop this process (SIGSTOP) for a while, as a
# script that wants a quiet machine for its own timing does; the time it was stopped is
# not the engine's. A watcher process notes every such interval: when this process is in
# the stopped state (`/proc`), or when the watcher, stopped with it, wakes up late.
WATCHER = r"""
import os, sys, time
main, path = int(sys.argv[1]), sys.argv[2]
last, stopped = time.monotonic(), None
with open(path, "a", buffering=1) as out:
    while os.getppid() == main:
        time.sleep(0.05)
        now = time.monotonic()
        try:
            with open(f"/proc/{main}/stat") as f:
                state = f.read().rsplit(")", 1)[1].split()[0]
        except OSError:
            break
        if now - last > 1.0:
            out.write(f"{last} {now}\n")
        if state in "Tt" and stopped is None:
            stopped = now
        elif state not in "Tt" and stopped is not None:
            out.write(f"{stopped} {now}\n")
            stopped = None
        last = now
"""


class Pauses:
    """When this process was stopped by another job: `paused(start, end)` is the time
    (s, `time.monotonic`) it spent stopped between `start` and `end`."""

    def __init__(self):
        self.log = Path(tempfile.mkstemp(prefix="speed_pauses_")[1])
        self.watcher = subprocess.Popen([sys.executable, "-c", WATCHER, str(os.getpid()), str(self.log)])
        self.events = []  # (what, seconds stopped): measurements that were taken again

    def paused(self, start: float, end: float) -> float:
        intervals = sorted(tuple(map(float, line.split())) for line in self.log.read_text().splitlines() if line)
        total, reach = 0.0, start
        for a, b in intervals:  # the union's overlap with [start, end]
            a, b = max(a, reach), min(b, end)
            if b > a:
                total += b - a
                reach = b
        return total

    def close(self):
        self.watcher.terminate()
        self.log.unlink(missing_ok=True)


PAUSES: Pauses | None = None


def guarded(what: str, measure, tries: int = 3):
    """`measure()`, taken again (up to `tries` times in all) while this process was
    stopped by another job during it; each such stop is kept in `PAUSES.events` as
    (what, seconds, whether the stopped measurement was kept)."""
    for attempt in range(tries):
        start = time.monotonic()
        result = measure()
        lost = PAUSES.paused(start, time.monotonic()) if PAUSES else 0.0
        if not lost:
            return result
        kept = attempt == tries - 1
        PAUSES.events.append((what, round(lost, 1), kept))
        print(f"  {what}: this process was stopped for {lost:.1f} s by another job", flush=True)
    print(f"  {what}: kept after {tries} stopped tries", flush=True)
    return result


def pauses_since(count: int) -> list:
    """The stops noted since `PAUSES.events` held `count` entries."""
    return [] if PAUSES is None else [list(e) for e in PAUSES.events[count:]]


def load() -> list[float]:
    return [round(x, 2) for x in os.getloadavg()]


def row(
    measure, *, jaxcable, moordyn=None, unit="s", target, quantity="ratio", accuracy="", accuracy_met=None, **extra
):
    """One table row. `target` is the bound on `quantity`: the ratio jaxcable ÷ MoorDyn
    (≤), or jaxcable's own figure (≤); met when that holds and `accuracy_met` is not
    False."""
    ratio = None if jaxcable is None or moordyn is None else jaxcable / moordyn
    value = ratio if quantity == "ratio" else jaxcable
    speed_met = None if value is None else bool(value <= target)
    met = None if speed_met is None else bool(speed_met and accuracy_met is not False)
    return {
        "measure": measure,
        "jaxcable": jaxcable,
        "moordyn": moordyn,
        "unit": unit,
        "ratio": ratio,
        "quantity": quantity,
        "target": target,
        "speed_met": speed_met,
        "accuracy": accuracy,
        "accuracy_met": accuracy_met,
        "met": met,
        **extra,
    }


def interleaved(runs: dict, repeats: int, slow: float) -> dict:
    """Time each of `runs` (name → function returning seconds) `repeats` times, taking
    turns so that every configuration sees the same load; a configuration whose first
    run took over `slow` seconds is run only once. Returns name → list of seconds."""
    times = {name: [] for name in runs}
    for k in range(repeats):
        for name, run in runs.items():
            if k and times[name][0] > slow:
                continue
            times[name].append(guarded(name, run))
    return times


# ---------------------------------------------------------------------------------------
# Rows


def rows_compile(args) -> list[dict]:
    import jax

    import jaxcable as jc
    from jaxcable.examples import anchored_line

    before, count = load(), len(PAUSES.events) if PAUSES else 0
    model, env = anchored_line(20, mass_matrix="lumped")
    duration = 10.0
    ts = np.linspace(0.0, duration, round(duration / OUTPUT_DT) + 1)

    def measure():
        jax.clear_caches()
        start = time.perf_counter()
        static = jc.solve_statics(model, env)
        statics_first = time.perf_counter() - start
        walls = []
        for _ in range(1 + max(args.repeats, 1)):
            start = time.perf_counter()
            result = jax.block_until_ready(jc.simulate(model, env, duration, ts=ts, initial=static.state))
            walls.append(time.perf_counter() - start)
        return statics_first, walls, result

    statics_first, walls, result = guarded("compile", measure)
    warm = statistics.median(walls[1:])
    compile_time = max(walls[0] - warm, 0.0)
    print(f"compile: first call {walls[0]:.2f} s, warm {warm:.2f} s, statics first call {statics_first:.2f} s")
    return [
        row(
            "compile time, standard scene (anchored_line(20, lumped), first simulate − warm)",
            jaxcable=compile_time,
            target=10.0,
            quantity="jaxcable",
            accuracy="–",
            notes=f"first call {walls[0]:.1f} s, warm {warm:.2f} s ({int(result.stats['num_steps'])} steps, 10 s); "
            f"statics' first call {statics_first:.1f} s, not counted",
            first_call_s=walls[0],
            warm_s=walls[1:],
            statics_first_call_s=statics_first,
            stops=pauses_since(count),
            load=[before, load()],
        )
    ]


def rows_field(args) -> list[dict]:
    import jax
    import jax.numpy as jnp
    import moordyn_side_by_side as mss
    from step_cost import field_seconds

    import jaxcable as jc

    before, count = load(), len(PAUSES.events) if PAUSES else 0
    model, env = mss.scene(args.slack_width, 20)
    nodes = int(model.node_positions.shape[0])
    state = jc.solve_statics(model, env).state
    y = (jnp.asarray(state.positions)[model.free_nodes], jnp.asarray(state.velocities)[model.free_nodes])
    amplitude = float(jc.examples.floater_amplitude(mss.PERIOD))
    amplitudes = amplitude * np.linspace(0.5, 1.5, args.batch)
    batch_y = jax.tree.map(lambda a: jnp.broadcast_to(a, (args.batch, *a.shape)), y)

    def build(a):
        return mss.with_amplitude(model, a), env

    repeats = max(args.repeats, 5)
    single, single_compile = guarded("field, single", lambda: field_seconds(build, amplitude, y, repeats))
    batch, batch_compile = guarded(
        "field, batch", lambda: field_seconds(build, amplitudes, batch_y, repeats, batched=True)
    )
    jaxcable_ns = batch / (args.batch * nodes) * 1e9
    single_ns = single / nodes * 1e9

    duration, dtm = 10.0, 1e-3
    with tempfile.TemporaryDirectory() as tmp:
        path = Path(tmp) / "anchored_line.txt"
        path.write_text(mss.moordyn_input(model, env, dtm))
        fairlead = np.asarray(model.node_positions[1])
        runs = [
            guarded("MoorDyn", lambda: mss.run_moordyn(path, fairlead, amplitude, duration, dtm))
            for _ in range(repeats)
        ]
        overhead = guarded("MoorDyn's loop", lambda: mss.python_overhead(path, fairlead))
    step = statistics.median(r["run_s"] for r in runs) / runs[0]["steps"]
    moordyn_ns = (step - overhead) / 2 / nodes * 1e9
    print(f"field: batched {jaxcable_ns:.1f} ns, single {single_ns:.1f} ns, MoorDyn {moordyn_ns:.1f} ns per node")
    return [
        row(
            f"batched cost per node per force evaluation ({args.batch} cases, N = 20, {nodes} nodes)",
            jaxcable=jaxcable_ns,
            moordyn=moordyn_ns,
            unit="ns",
            target=30.0,
            quantity="jaxcable",
            accuracy="–",
            notes=f"single run {single_ns:.0f} ns/node ({single * 1e6:.2f} µs an evaluation); MoorDyn: RK2 step "
            f"{step * 1e6:.2f} µs at dtM 1 ms less its Python loop's {overhead * 1e6:.2f} µs, / 2 evaluations / "
            f"{nodes} nodes",
            single_ns=single_ns,
            batch_s_per_evaluation=batch,
            single_s_per_evaluation=single,
            compile_s={"single": single_compile, "batch": batch_compile},
            moordyn_step_s=step,
            moordyn_python_loop_s=overhead,
            stops=pauses_since(count),
            load=[before, load()],
        )
    ]


def rows_ll(args) -> list[dict]:
    import jax
    import lowe_langley as ll
    import moordyn_side_by_side as mss

    before, count = load(), len(PAUSES.events) if PAUSES else 0
    case, dt_motion = 1, 0.01
    reference = np.loadtxt(ll.DATA / f"case{case}.csv", delimiter=",")
    bin_dir = str(Path(sys.executable).parent)  # the `jaxcable` command beside this Python
    env = {**os.environ, "PATH": bin_dir + os.pathsep + os.environ.get("PATH", "")}
    with tempfile.TemporaryDirectory() as tmp:
        workdir = Path(tmp)
        shutil.copy(ll.DATA / "line.txt", workdir / "line.txt")  # MoorDyn writes beside its input
        rest = ll.top_rest(workdir / "line.txt")

        # In process: jaxcable's warm runs and MoorDyn's stepping, at the file's dtM.
        def in_process():
            jax.clear_caches()  # so that a second try compiles too
            return ll.time_in_process(workdir, case, rest, dt_motion, args.repeats)

        timing = guarded("run_scene", in_process, 2)
        with mss.quiet():  # MoorDyn prints its input
            md_runs = [guarded("MoorDyn", lambda: ll.run_moordyn(workdir, case)) for _ in range(args.repeats)]
        count_run = len(PAUSES.events) if PAUSES else 0
        md_run = statistics.median(r["run"] for r in md_runs)
        md_errors = {
            "reaction": ll.errors(md_runs[0]["times"], md_runs[0]["reaction"], reference),
            "fairten": ll.errors(md_runs[0]["times"], md_runs[0]["fairten"], reference),
        }
        mid = load()

        # Whole processes: jaxcable cold and warm, MoorDyn, in turns.
        moordyn_code = (
            "import sys; from pathlib import Path; import numpy as np; "
            f"sys.path.insert(0, {str(BENCHMARKS)!r}); from lowe_langley import run_moordyn; "
            f"np.savez(sys.argv[2], **run_moordyn(Path(sys.argv[1]), {case}))"
        )
        cold, warm, md_process, cache_files = [], [], [], []
        cli = None
        out = workdir / "moordyn_process.npz"
        folders = iter(range(1000))

        def cold_process():
            cache = workdir / f"jax_cache_{next(folders)}"  # a new, empty one each time
            cache.mkdir()
            cache_env = {
                **env,
                "JAX_COMPILATION_CACHE_DIR": str(cache),
                "JAX_PERSISTENT_CACHE_MIN_COMPILE_TIME_SECS": "0",
            }
            return ll.run_cli(workdir, case, rest, dt_motion, env=cache_env), cache_env

        def moordyn_process():
            start = time.perf_counter()
            subprocess.run(
                [sys.executable, "-c", moordyn_code, str(workdir), str(out)], check=True, capture_output=True, env=env
            )
            return time.perf_counter() - start

        for _ in range(args.process_repeats):
            first, cache_env = guarded("jaxcable process, cold", cold_process)
            cold.append(first["wall"])
            cache_files.append(cached_programs(Path(cache_env["JAX_COMPILATION_CACHE_DIR"])))
            cli = cli or first
            warm.append(
                guarded("jaxcable process, warm", lambda: ll.run_cli(workdir, case, rest, dt_motion, env=cache_env))[
                    "wall"
                ]
            )
            md_process.append(guarded("MoorDyn process", moordyn_process))
            print(f"ll processes: cold {cold[-1]:.1f} s, warm {warm[-1]:.1f} s, MoorDyn {md_process[-1]:.1f} s")
        md_saved = np.load(out)
        md_process_error = ll.errors(md_saved["times"], md_saved["reaction"], reference)
    jx_errors = {
        "reaction": ll.errors(cli["times"], cli["reaction"], reference),
        "fairten": ll.errors(cli["times"], cli["fairten"], reference),
    }
    accurate = jx_errors["reaction"]["rms"] <= md_errors["reaction"]["rms"]  # see the module's notes
    accuracy = (
        f"RMS err vs published (kN): abs R {jx_errors['reaction']['rms']:.3f} vs {md_errors['reaction']['rms']:.3f}, "
        f"FairTen1 {jx_errors['fairten']['rms']:.3f} vs {md_errors['fairten']['rms']:.3f} (max "
        f"{jx_errors['reaction']['max']:.3f} vs {md_errors['reaction']['max']:.3f})"
    )
    details = {
        "jaxcable_errors_kN": jx_errors,
        "moordyn_errors_kN": md_errors,
        "jaxcable_steps": timing["steps"],
        "cli_summary": cli["summary"],
    }
    process_accuracy = (
        f"the processes' abs R RMS err {jx_errors['reaction']['rms']:.3f} vs {md_process_error['rms']:.3f} kN"
    )
    median = statistics.median
    print(f"ll: run {timing['run']:.2f} s (compile {timing['compile']:.1f} s), MoorDyn {md_run:.2f} s")
    return [
        row(
            "Low & Langley case 1, run time ÷ MoorDyn at dtM 1 ms",
            jaxcable=timing["run"],
            moordyn=md_run,
            target=0.5,
            accuracy=accuracy,
            accuracy_met=accurate,
            notes=f"compile {timing['compile']:.1f} s apart; {timing['steps']} steps ({timing['stepping']}); median of "
            f"{args.repeats}; MoorDyn with the file's tScheme (midpoint5); jaxcable's errors from its `jaxcable run` "
            "process (the same solver and settings)",
            compile_s=timing["compile"],
            moordyn_runs_s=[r["run"] for r in md_runs],
            stops=pauses_since(count)[: count_run - count],
            load=[before, mid],
            **details,
        ),
        row(
            "the same, whole `jaxcable run` process, cold cache ÷ MoorDyn's whole process",
            jaxcable=median(cold),
            moordyn=median(md_process),
            target=2.0,
            accuracy=process_accuracy,
            accuracy_met=accurate,
            notes=f"median of {len(cold)}; the cold run cached {len(cache_files[0])} programs, the largest "
            + ", ".join(f"{name} ({size / 1e3:.0f} kB)" for name, size in cache_files[0][:3]),
            jaxcable_runs_s=cold,
            moordyn_runs_s=md_process,
            cache_files=cache_files,
            stops=pauses_since(count_run),
            load=[mid, load()],
        ),
        row(
            "the same, whole `jaxcable run` process, warm cache ÷ MoorDyn's whole process",
            jaxcable=median(warm),
            moordyn=median(md_process),
            target=1.0,
            accuracy=process_accuracy,
            accuracy_met=accurate,
            notes=f"median of {len(warm)}; the second process with the cold run's cache folder",
            jaxcable_runs_s=warm,
            moordyn_runs_s=md_process,
            stops=pauses_since(count_run),
            load=[mid, load()],
        ),
    ]


def cached_programs(folder: Path) -> list[tuple[str, int]]:
    """The programs in JAX's persistent cache `folder` and in jaxcable's own beside it
    (`jaxcable-programs`, keyed by the scene's structure, named `jaxcable:...`),
    (name, bytes), largest first."""
    entries = [(p.name.rsplit("-", 2)[0], p.stat().st_size) for p in folder.iterdir() if p.name.endswith("-cache")]
    kept = folder / "jaxcable-programs"
    if kept.is_dir():
        entries += [("jaxcable:" + p.name.rsplit("-", 1)[0], p.stat().st_size) for p in kept.glob("*.program")]
    return sorted(entries, key=lambda e: -e[1])


def steps_for(n: int, dtms: list[float]) -> list[float]:
    """Fixed steps for N segments, largest first: `dtms` (for N = 20) scaled by 20/N (the
    fastest axial mode grows as N), each rounded down to a divisor of the 0.05 s output
    interval."""
    # Python floats: MoorDyn cannot read a numpy scalar's repr.
    return sorted({OUTPUT_DT / int(np.ceil(OUTPUT_DT / (d * 20 / n) - 1e-9)) for d in dtms}, reverse=True)


def bracket(settings: list[dict], level: float) -> list[dict]:
    """From `settings` ordered cheapest first, the cheapest whose RMS error is within
    `level` and the one just cheaper (if any): the two the matched time is
    interpolated between (not one whose run failed or diverged). Empty where none is
    within the level."""
    for i, s in enumerate(settings):
        if s["rms"] <= level:
            cheaper = settings[i - 1 : i] if i and np.isfinite(settings[i - 1]["rms"]) else []
            return [*cheaper, s]
    return []


def rows_anchored_line(args, n: int) -> tuple[list[dict], dict | None]:
    import jax
    import moordyn_side_by_side as mss

    import jaxcable as jc

    jax.clear_caches()
    before, count = load(), len(PAUSES.events) if PAUSES else 0
    model, env = mss.scene(args.slack_width, n)
    static = jc.solve_statics(model, env)
    fairlead = np.asarray(model.node_positions[1])
    amplitude = float(jc.examples.floater_amplitude(mss.PERIOD))
    short = args.window + 1.0

    def run(setting, duration, max_steps=10_000_000):
        return mss.run_jaxcable(
            model, env, static.state, duration, solver=mss.solver_setting(setting, max_steps), repeats=0
        )

    ref = run({"solver": "Dopri8", "tol": args.reference_tol}, short)
    reference = ref["tension"]
    inside = np.linspace(0.0, short, reference.size) <= args.window + 1e-9
    check = run({"solver": "Dopri8", "tol": 10 * args.reference_tol}, short)
    reference_error = mss.errors(check["tension"][inside], reference[inside])
    print(
        f"anchored_line N = {n}: reference {ref['steps']} steps, its 10× tolerance within {reference_error}", flush=True
    )

    def window_error(tension):
        return mss.errors(tension[: inside.sum()], reference[inside])

    # jaxcable's settings by family, cheapest first: Dopri5's tolerances, and each fixed
    # step solver's steps (MoorDyn's dtM is the same kind of choice).
    families = {"Dopri5": [{"solver": "Dopri5", "tol": tol} for tol in sorted(args.tols, reverse=True)]}
    for name in args.fixed:
        families[f"{name} fixed"] = [{"solver": name, "dt": dt} for dt in steps_for(n, args.fixed_dt)]

    # Short runs: each setting's error.
    rows, moordyn_settings, jaxcable_settings = [], [], {family: [] for family in families}
    with tempfile.TemporaryDirectory() as tmp:
        folder = Path(tmp)
        for dtm in steps_for(n, args.dtm):
            path = folder / f"anchored_line_{dtm:g}.txt"
            path.write_text(mss.moordyn_input(model, env, dtm))
            r = mss.run_moordyn(path, fairlead, amplitude, short, dtm)
            e = window_error(r["tension"])
            rows.append({"engine": "MoorDyn RK2", "setting": f"dtM {dtm:g}", "dt": dtm, **e, "run_s": r["run_s"]})
            moordyn_settings.append({"dtm": dtm, "path": path, **e})
            print(f"  MoorDyn dtM {dtm:g}: RMS err {e['rms']:.2e}", flush=True)
        for family, settings in families.items():
            for setting in settings:
                r = run(setting, short)
                e = window_error(r["tension"])
                rows.append(
                    {
                        "engine": f"jaxcable {family}",
                        "setting": mss.setting_name(setting),
                        **setting,
                        **e,
                        "steps": r["steps"],
                        "run_s": r["run_s"],
                    }
                )
                jaxcable_settings[family].append({**setting, **e})
                print(f"  {mss.setting_name(setting)}: RMS err {e['rms']:.2e}, {r['steps']} steps", flush=True)
        pair = sweep_settings(rows) if n == 20 else None

        # Long runs at the settings that bracket the level, in turns. Each jaxcable
        # setting is called once first: that call compiles (a fixed step's solver and
        # step are part of the program).
        md_pick = bracket(moordyn_settings, args.level)
        long, runs, first_calls = {}, {}, {}
        for family, settings in jaxcable_settings.items():
            for s in bracket(settings, args.level):
                setting = {k: s[k] for k in ("solver", "tol", "dt") if k in s}
                name = f"jaxcable {mss.setting_name(setting)}"

                def run_jx(setting=setting, name=name, family=family):
                    r = run(setting, args.duration)
                    long[name] = {**r, "family": family}
                    return r["run_s"]

                start = time.perf_counter()
                run_jx()
                first_calls[name] = time.perf_counter() - start
                print(f"  {name}: first call {first_calls[name]:.1f} s", flush=True)
                runs[name] = run_jx
        for s in md_pick:
            name = f"MoorDyn dtM {s['dtm']:g}"

            def run_md(s=s, name=name):
                r = mss.run_moordyn(s["path"], fairlead, amplitude, args.duration, s["dtm"])
                long[name] = r
                return r["run_s"]

            runs[name] = run_md
        walls = interleaved(runs, args.repeats, args.slow)
    long_rows = []
    for name, w in walls.items():
        r = long[name]
        e = window_error(r["tension"]) if np.all(np.isfinite(r["tension"])) else {"rms": np.inf, "max": np.inf}
        long_rows.append(
            {
                "name": name,
                "engine": name.split()[0],
                "family": r.get("family"),
                "runs_s": w,
                "run_s": statistics.median(w),
                "steps": int(r["steps"]),
                **e,
                "peak_N": float(np.max(r["tension"])),
                "mean_N": float(np.mean(r["tension"])),
            }
        )
        print(
            f"  {name}: {statistics.median(w):.2f} s over {args.duration:g} s ({len(w)} runs), RMS err {e['rms']:.2e}"
        )
    # jaxcable's time at the level: each family's, interpolated between its two runs; the
    # fastest family's is the row's.
    by_family = {}
    for family in families:
        points = [(r["rms"], r["run_s"]) for r in long_rows if r["family"] == family]
        wall, bound = mss.wall_at(points, args.level)
        if wall is not None:
            by_family[family] = (wall, bound)
    best = min(by_family, key=lambda f: by_family[f][0]) if by_family else None
    jx_s, jx_bound = by_family[best] if best else (None, False)
    md_s, md_bound = mss.wall_at([(r["rms"], r["run_s"]) for r in long_rows if r["engine"] == "MoorDyn"], args.level)

    def describe(engine):
        return ", ".join(f"{r['name'].split(' ', 1)[1]} {r['rms']:.1e}" for r in long_rows if r["engine"] == engine)

    accuracy = f"RMS err / peak, t ≤ {args.window:g} s: jaxcable {describe('jaxcable') or 'none ≤ level'}; MoorDyn " + (
        describe("MoorDyn") or "none ≤ level"
    )
    stats = "; ".join(
        f"{r['name']}: peak {r['peak_N'] / 1e3:.1f} kN, mean {r['mean_N'] / 1e3:.1f} kN" for r in long_rows
    )
    families_at_level = ", ".join(
        f"{family} {wall:.3g} s" + (" (bound)" if bound else "") for family, (wall, bound) in by_family.items()
    )
    notes = (
        f"times interpolated to {args.level:g} in log-log"
        + (f"; jaxcable's from {best} (each family: {families_at_level})" if best else "")
        + (" (jaxcable's an upper bound)" if jx_bound else "")
        + (" (MoorDyn's an upper bound: no ratio)" if md_bound else "")
        + f"; over {args.duration:g} s: {stats}"
    )
    return [
        row(
            f"the anchored line, N = {n}, {args.duration:g} s, at matched error ({args.level:g} of the peak)",
            jaxcable=jx_s,
            moordyn=None if md_bound else md_s,
            target=0.3,
            accuracy=accuracy,
            notes=notes,
            short_runs=rows,
            long_runs=long_rows,
            jaxcable_by_family={f: {"run_s": w, "upper_bound": b} for f, (w, b) in by_family.items()},
            jaxcable_family=best,
            reference={
                "steps": ref["steps"],
                "peak_N": float(reference.max()),
                "error_of_10x_tolerance": reference_error,
            },
            jaxcable_first_long_calls_s=first_calls,
            jaxcable_upper_bound=jx_bound,
            moordyn_upper_bound=md_bound,
            sweep_pair=pair,
            stops=pauses_since(count),
            load=[before, load()],
        )
    ], pair


def sweep_settings(rows) -> dict | None:
    """The sweep's settings of matched error, from the N = 20 short runs: MoorDyn's dtM
    and its error (`moordyn_side_by_side.sweep_pair`), Dopri5's tolerance of that error,
    and for each fixed-step family its largest step whose error is no larger."""
    import moordyn_side_by_side as mss

    pair = mss.sweep_pair(rows)
    if pair is None:
        return None
    settings = [{"solver": "Dopri5", "tol": pair["tol"]}]
    fixed = [r for r in rows if "dt" in r and r["engine"].startswith("jaxcable")]
    for family in dict.fromkeys(r["engine"] for r in fixed):
        within = [r for r in fixed if r["engine"] == family and r["rms"] <= pair["moordyn_rms"]]
        if within:
            best = max(within, key=lambda r: r["dt"])
            settings.append({"solver": best["solver"], "dt": best["dt"]})
    return {**pair, "jaxcable": settings}


def rows_sweep(args, pair) -> list[dict]:
    import jax
    import moordyn_side_by_side as mss

    before, count = load(), len(PAUSES.events) if PAUSES else 0
    options = argparse.Namespace(
        slack_width=args.slack_width,
        cases=args.cases,
        span=[0.5, 1.5],
        sweep_duration=args.sweep_duration,
        sweep_tol=pair["tol"] if pair else None,
        sweep_dtm=pair["dtm"] if pair else None,
        sweep_settings=pair.get("jaxcable") if pair else None,
        sweep_repeats=args.sweep_repeats,
        sweep_steps=args.sweep_steps,
        moordyn_cases=None,
        max_steps=200_000,
        out=mss.RESULTS,  # where the pair comes from when this run has none
    )

    def measure():
        jax.clear_caches()  # so that every try compiles
        return mss.part_sweep(options)

    record = guarded("sweep", measure, 2)
    s, j, m, p = record["settings"], record["jaxcable"], record["moordyn"], record["peaks"]
    return [
        row(
            f"{s['cases']}-case wave-steepness sweep of the anchored line ({s['duration_s']:g} s each, "
            f"steps {s.get('steps', 'per_case')}, chunks on {s.get('cores', 1)} cores) ÷ "
            f"{s['cases']} sequential MoorDyn runs",
            jaxcable=j["run_s"],
            moordyn=m["run_s"],
            target=0.1,
            accuracy=f"jaxcable {mss.setting_name(j['setting'])} against dtM {s['dtm']:g}"
            + (
                f" (RMS err ≤ MoorDyn's {pair['moordyn_rms']:.1e}, from the N = 20 row)"
                if pair
                else " (pair from moordyn_side_by_side.json)"
            )
            + f"; peaks, t ≤ {p['early_s']:g} s: largest diff {p['early_max_rel_diff']:.2%}, median "
            f"{p['early_median_rel_diff']:.2%}; over {s['duration_s']:g} s {p['max_rel_diff']:.1%}, "
            f"{p['median_rel_diff']:.1%}",
            notes=f"compile {j['compile_s']:.1f} s apart; steps max {j['steps_max']} (mean {j['steps_mean']:.0f}); "
            + "settings tried: "
            + ", ".join(f"{mss.setting_name(t['setting'])} {t['run_s']:.2f} s" for t in record["jaxcable_tried"])
            + f"; MoorDyn with IC generation {m['total_s']:.1f} s",
            sweep={k: v for k, v in record.items() if k != "peaks"},
            stops=pauses_since(count),
            load=[before, load()],
        )
    ]


# ---------------------------------------------------------------------------------------
# Report


def fmt(value, unit):
    if value is None:
        return "–"
    if unit == "ns":
        return f"{value:.1f} ns"
    return f"{value:.3g} s" if value < 10 else f"{value:.1f} s"


def report(path: Path) -> None:
    import json

    sessions = json.loads(path.read_text())
    s = sessions[-1]
    print(
        f"Session {s['time']}, commit {s['commit']}, {s['machine']}, jax {s['jax']}, MoorDyn {s['moordyn']}"
        + (" — QUICK smoke run, not the target measurement" if s.get("quick") else "")
        + f"; load average {s['load_average_start']} at the start, {s['load_average_end']} at the end."
    )
    print()
    print("| measure | jaxcable | MoorDyn | ratio | target | met? | accuracy | notes |")
    print("|---|---|---|---|---|---|---|---|")
    for r in s["rows"]:
        ratio = "–" if r["ratio"] is None else f"{r['ratio']:.2f}×"
        unit = {"ns": " ns", "s": " s"}[r["unit"]]
        target = f"≤ {r['target']:g}×" if r["quantity"] == "ratio" else f"≤ {r['target']:g}{unit}"
        met = {None: "–", True: "yes", False: "no"}[r["met"]]
        if r["met"] is False and r["speed_met"]:
            met = "no (accuracy)"
        notes = f"{r.get('notes', '')}; load {r['load'][0][0]}–{r['load'][1][0]}"
        stops = r.get("stops", [])
        if stops:
            notes += (
                f"; stopped {len(stops)}× ({sum(e[1] for e in stops):.0f} s) by another job, those measurements "
                "taken again" + ("; ONE STOPPED MEASUREMENT KEPT, suspect" if any(e[2] for e in stops) else "")
            )
        print(
            f"| {r['measure']} | {fmt(r['jaxcable'], r['unit'])} | {fmt(r['moordyn'], r['unit'])} | {ratio} | {target} "
            f"| {met} | {r['accuracy']} | {notes} |"
        )


def main(argv=None) -> None:
    args = parse(argv)
    args.argv = sys.argv[1:] if argv is None else list(argv)
    if args.report:
        report(args.out)
        return
    if all(r in SINGLE_RUN_ROWS for r in args.only):
        os.environ.setdefault("PJRT_NPROC", "1")  # before JAX's CPU backend starts, below
    import importlib.metadata

    import jax

    jax.config.update("jax_enable_x64", True)  # jaxcable computes in float64 and leaves the switch to us
    # Compile times are reported apart: no persistent cache in this process (the `ll`
    # processes get their own).
    jax.config.update("jax_enable_compilation_cache", False)
    from _results import append_session

    os.environ["PATH"] = str(Path(sys.executable).parent) + os.pathsep + os.environ.get("PATH", "")
    global PAUSES
    PAUSES = Pauses()
    start_load = load()
    try:
        rows = run_rows(args)
    finally:
        PAUSES.close()
    append_session(
        args.out,
        quick=args.quick,
        command=" ".join(["python", "benchmarks/speed.py", *(sys.argv[1:] if argv is None else argv)]),
        settings={k: (str(v) if isinstance(v, Path) else v) for k, v in vars(args).items()},
        moordyn=importlib.metadata.version("moordyn"),
        load_average_start=start_load,
        load_average_end=load(),
        rows=rows,
    )
    print()
    report(args.out)


def run_rows(args) -> list[dict]:
    rows, pair = [], None
    single = [r for r in args.only if r in SINGLE_RUN_ROWS]
    if single and len(single) < len(args.only) and "PJRT_NPROC" not in os.environ:
        rows = single_run_rows(args.argv, single)
        pair = next((r["sweep_pair"] for r in rows if r.get("sweep_pair")), None)
        args.only = [r for r in args.only if r not in single]
    if "compile" in args.only:
        rows += rows_compile(args)
    if "field" in args.only:
        rows += rows_field(args)
    if "ll" in args.only:
        rows += rows_ll(args)
    if "anchored_line" in args.only:
        for n in args.segments:
            new, found = rows_anchored_line(args, n)
            rows += new
            pair = pair or found
    if "sweep" in args.only:
        rows += rows_sweep(args, pair)
    return rows


def single_run_rows(given: list[str], only: list[str]) -> list[dict]:
    """`only`'s rows measured by this script in a child process on one kernel thread
    (`PJRT_NPROC=1`, read when XLA's CPU backend starts, so it cannot change in this
    process), with the other settings `given` on this run's command line."""
    argv, skip = [], False
    for arg in given:
        skip = arg in ("--only", "--out") or (skip and not arg.startswith("--"))
        if not skip:
            argv.append(arg)
    with tempfile.TemporaryDirectory() as tmp:
        out = Path(tmp) / "rows.json"
        command = [sys.executable, __file__, *argv, "--only", *only, "--out", str(out)]
        subprocess.run(command, check=True, env={**os.environ, "PJRT_NPROC": "1"})
        return json.loads(out.read_text())[-1]["rows"]


if __name__ == "__main__":
    main()
