"""What a user meets: whole processes, first and second run, beside MoorDyn's whole process.

A user does not call a warm, compiled function: they start `jaxcable run FILE`, or a
Python script of their own, and wait for the process to end. This benchmark times those
whole processes, start to exit: start-up and imports, reading the input, statics,
compiling (or loading compiled programs), running, writing the output. Each is timed
*cold*, the first run, with empty caches (`JAXCABLE_CACHE_DIR` pointed at a new, empty
folder; `JAX_COMPILATION_CACHE_DIR` taken out of the environment, since it would win),
and *warm*, a second process with the same cache folder. Where MoorDyn 2 (`pip install
moordyn`) can run the same input, its whole Python process is timed beside them. The
three take turns, cold, warm, MoorDyn, `--repeats` times, so that each triple sees the
same load; ratios are taken within each triple and summarised by their median.

Recorded per process: wall time, exit status, the load average before and after, the
first line of stderr (and its tail when the process failed), and for `jaxcable run` the
closing summary, `wall time ... statics ... compile ... run ...`, parsed into its parts.
A process that fails is recorded and the benchmark goes on. Every process runs with
`OPENBLAS_NUM_THREADS=1` (a value the caller set is kept; see `benchmarks/README.md`,
*Shared machines*).

Rows (`--rows` takes these names):

- `line40`: a 40-segment anchored steel rope (the anchored-line paper's rope, with internal damping
  BA = -0.8 and a seabed 50 m below the anchor) from a MoorDyn v2 file, its top moved
  along x by a 600 s motion table (`time,x,y,z` every 0.1 s):
  `jaxcable run line40.txt --motion motion.csv --out run.csv`, against a Python process
  that drives MoorDyn with the same table as MoorDyn's own driver does (`Init` at the
  table's first row, then `Step` at dtM = 2 ms with the table interpolated linearly at
  each step's start and the secant velocity to the next; MoorDyn writes its .out files).
  Accuracy: the RMS difference of `FairTen1` at 0.1 s, relative to MoorDyn's peak, over
  the whole run and after its first 10 s (each engine starts from its own equilibrium:
  jaxcable's statics, MoorDyn's IC generation), and both engines' tension at t = 0.
  Targets: first run ÷ MoorDyn ≤ 1.5, second run ÷ MoorDyn ≤ 0.7.
- `line40_auto`: the same with `--solver auto`: RK4 at fixed steps chosen for the
  line's fastest modes (`jaxcable.fixed_steps`) in place of the file's dtM and tScheme,
  against the same MoorDyn process, with the same targets.
- `sweep32`, `sweep256`: a user's script, `jc.sweep(build, {"amplitude":
  np.linspace(0.5, 3.0, N)}, 60.0, ts=...)` over the anchored line (N = 20, linear EA,
  lumped, nodal hydrodynamics: the model MoorDyn has) at jaxcable's default options,
  against a Python process that runs MoorDyn on the same N cases in a loop (dtM = 1 ms,
  the top's position and secant velocity each step, output at 100 Hz). The figure is
  the speed-up, MoorDyn ÷ jaxcable; accuracy, the top segment's peak tension of each
  case over the first 3 s (the first snap, before slack events make this undamped line's
  histories diverge), relative difference between the engines. The script gets the same new
  `JAXCABLE_CACHE_DIR` as `jaxcable run` does: its second run gains whatever the
  library keeps there. Targets: sweep32 first run ≥ 3× faster, second ≥ 10×; sweep256 first run ≥ 10×.
- `campaign`: a design campaign of `--campaign-cases` (32) load cases of line40, each its
  own surge table (amplitudes 0.5 to 3 m, periods 5.6 to 12 s), 120 s each: `jaxcable
  campaign line40.txt cases.csv --out FOLDER`, first and second run, against MoorDyn's
  driver in 2 processes at once (half the cases each, in turn). The figure is the
  speed-up, MoorDyn ÷ jaxcable, with cases per hour; accuracy, each case's `FairTen1`
  against MoorDyn's after the first 10 s. No target (issue 39 asks for the figure).
- `lowe_langley`: the Low & Langley (2006) file's case 1, `jaxcable run line.txt
  --motion ...` (`lowe_langley.run_cli`) against MoorDyn's whole process
  (`lowe_langley.run_moordyn`), as `speed.py`'s `ll` rows; the statics' share of the
  first run from its summary. Targets: statics ≤ 3 s in the first run (the speed
  table's own ratio targets, ≤ 2× cold and ≤ 1× warm, are shown beside it).
- `examples`: every bundled example scene (`jaxcable examples`), `jaxcable run NAME
  --out x.npz`, first and second run. Target: statics ≤ 3 s in the first run.
- `refusal`: a MoorDyn file whose LINE TYPES row has a non-numeric EA, and a TOML scene
  whose `axial_stiffness` is a string, through `jaxcable run`: the exit status, the
  first line of stderr, and the whole process's time. Target: ≤ 1 s, refused (exit
  status not 0, no traceback).

    python benchmarks/first_contact.py                      # every row: the measurement
    python benchmarks/first_contact.py --rows line40 sweep32
    python benchmarks/first_contact.py --repeats 5
    python benchmarks/first_contact.py --report             # the latest session's table
    # quick checks, NOT the measurement:
    python benchmarks/first_contact.py --rows refusal line40 --repeats 1 --duration 20
    python benchmarks/first_contact.py --rows sweep32 --cases 4 --repeats 1
    python benchmarks/first_contact.py --rows campaign --campaign-cases 4 --repeats 1
    python benchmarks/first_contact.py --rows examples --examples y_branch --repeats 1

Sessions are appended to `benchmarks/results/first_contact.json` (`--out`).
"""

import argparse
import json
import os
import re
import statistics
import subprocess
import sys
import tempfile
import time
import traceback
from pathlib import Path

import lowe_langley as ll
import moordyn_side_by_side as mss
import numpy as np
from _results import append_session
from speed import cached_programs, load

BENCHMARKS = Path(__file__).resolve().parent
RESULTS = BENCHMARKS / "results" / "first_contact.json"
ROWS = ("line40", "line40_auto", "sweep32", "sweep256", "campaign", "lowe_langley", "examples", "refusal")
DEFAULTS = {"repeats": 3, "duration": 600.0, "cases": None, "examples": None, "campaign_cases": 32}

# line40: the anchored-line paper's rope, 40 segments, with internal damping and a seabed.
LINE40_TOP = 346.4101615137755  # m: the top's x at rest, H cot 30°
LINE40_AMPLITUDE, LINE40_PERIOD = 1.5733227425801541, 5.6  # m, s: the anchored-line paper's top motion
LINE40_DTM, LINE40_DT_OUT = 0.002, 0.1  # s
LINE40_SETTLED = 10.0  # s: the tensions are also compared after this, past the start's transient
CAMPAIGN_DURATION = 120.0  # s: each case of the campaign row
CAMPAIGN_PERIODS = (5.6, 8.0, 10.0, 12.0)  # s: its cases' surge periods, in turn
LINE40 = f"""line40: a 40-segment anchored steel rope (benchmarks/first_contact.py)
----------------------- LINE TYPES ------------------------------------------
TypeName   Diam     Mass/m     EA         BA/-zeta    EI         Cd     Ca     CdAx    CaAx
(name)     (m)      (kg/m)     (N)        (N-s/-)     (N-m^2)    (-)    (-)    (-)     (-)
rope  0.019544100476116797  3.0  3.0e7  -0.8  0.0  1.5574533311185579  1.3008130081300815  0.024787639628245695  \
1.3008130081300815
---------------------- POINTS --------------------------------
ID    Type      X       Y       Z       Mass    Volume      CdA    Ca
(#)   (-)       (m)     (m)     (m)     (kg)    (m^3)       (m^2)  (-)
1     Fixed     0.0     0.0     -200.0  0       0           0      0
2     Coupled   {LINE40_TOP!r}  0.0  0.0  0       0           0      0
---------------------- LINES ----------------------------------------
ID   LineType   AttachA  AttachB  UnstrLen  NumSegs  LineOutputs
(#)   (name)     (#)      (#)       (m)       (-)     (-)
1    rope       1        2        400.0     40       pt
---------------------- OPTIONS -----------------------------------------
0             writeLog      no log file
{LINE40_DTM!r}         dtM           time step (s)
250           WtrDpth       water depth (m): the seabed 50 m below the anchor
1025          WtrDnsty      water density (kg/m^3)
9.81          g             gravity (m/s^2)
RK2           tScheme       explicit midpoint
{LINE40_DT_OUT!r}           dtOut         output interval (s)
120           TmaxIC        IC generation maximum time (s)
0.001         threshIC      IC convergence threshold (converges; 1e-7 left this line at 270 kN)
1             disableOutTime  do not print the time every step
------------------------- need this line --------------------------------------
"""

# What MoorDyn's own driver does with a motion table, as a Python process, for one table
# or several in turn: `python moordyn_table.py INPUT DTM DT_OUT TABLE TENSION.npy [TABLE
# TENSION.npy ...]`.
MOORDYN_TABLE = """\
import sys

import moordyn
import numpy as np

path, dtm, dt_out, pairs = sys.argv[1], float(sys.argv[2]), float(sys.argv[3]), sys.argv[4:]
for table, out in zip(pairs[::2], pairs[1::2]):
    data = np.loadtxt(table, delimiter=",", skiprows=1)
    steps = round((data[-1, 0] - data[0, 0]) / dtm)
    times = data[0, 0] + dtm * np.arange(steps + 1)
    x = np.column_stack([np.interp(times, data[:, 0], data[:, i]) for i in (1, 2, 3)])
    v = (x[1:] - x[:-1]) / dtm  # the secant velocity over each step
    positions, velocities, starts = x.tolist(), v.tolist(), times.tolist()
    every = round(dt_out / dtm)
    system = moordyn.Create(path)
    moordyn.Init(system, positions[0], velocities[0])
    line = moordyn.GetLine(system, 1)
    tension = [moordyn.GetLineFairTen(line)]
    for k in range(steps):
        moordyn.Step(system, positions[k], velocities[k], starts[k], dtm)
        if (k + 1) % every == 0:
            tension.append(moordyn.GetLineFairTen(line))
    moordyn.Close(system)
    np.save(out, np.array(tension))
"""

# The sweeps' line: the anchored-line paper's, with the equations MoorDyn has (as moordyn_side_by_side's).
SWEEP_LINE = {"n_segments": 20, "quadratic_ratio": 0.0, "mass_matrix": "lumped", "hydrodynamics": "nodes"}
SWEEP_DURATION, SWEEP_SAMPLES, SWEEP_DTM = 60.0, 6001, 1e-3  # s, output times (100 Hz), s
SWEEP_AMPLITUDES = (0.5, 3.0)  # m: np.linspace's ends
# The peaks are compared over the first 3 s (300 output intervals): the first snap, before
# slack events, each of which amplifies small differences about 30-fold on this undamped
# line (moordyn_side_by_side's notes); over 60 s the histories no longer compare.
SWEEP_COMPARED = 300

# A user's sweep script: `python sweep.py PEAKS.npy`.
JAXCABLE_SWEEP = """\
import sys

import jax

jax.config.update("jax_enable_x64", True)
import equinox as eqx
import jaxcable as jc
import numpy as np


def build(amplitude):
    \"\"\"The anchored line with the top's harmonic amplitude set.\"\"\"
    model, env = jc.examples.anchored_line({line})
    top = list(np.asarray(model.constrained_nodes)).index(1)  # the motion of node 1, the fairlead
    return eqx.tree_at(lambda m: m.motions[top].amplitude, model, amplitude), env


amplitudes = np.linspace({low!r}, {high!r}, {cases})
result = jc.sweep(build, {{"amplitude": amplitudes}}, {duration!r}, ts=np.linspace(0.0, {duration!r}, {samples}))
print("failed cases:", result.failed.tolist())
print("peak tensions (kN):", np.round(np.asarray(result.peak_tension) / 1e3, 3).tolist())
# The top segment's peak over the first snap (see SWEEP_COMPARED).
np.save(sys.argv[1], np.asarray(result.simulation.tension[:, : {compared} + 1, -1]).max(axis=1))
"""

# The same cases through MoorDyn, one after another: `python moordyn_sweep.py INPUT PEAKS.npy`.
MOORDYN_SWEEP = """\
import sys

import numpy as np

sys.path.insert(0, {benchmarks!r})
import moordyn_side_by_side as mss

mss.OUTPUT_DT = {dt_out!r}  # run_moordyn samples the top tension every OUTPUT_DT: 100 Hz, as the jaxcable script
peaks = [
    mss.run_moordyn(sys.argv[1], {top!r}, amplitude, {duration!r}, {dtm!r})["tension"][: {compared} + 1].max()
    for amplitude in np.linspace({low!r}, {high!r}, {cases})
]
print("peak tensions (kN):", np.round(np.array(peaks) / 1e3, 3).tolist())
np.save(sys.argv[2], np.array(peaks))
"""

# Lowe & Langley's MoorDyn process, as speed.py's `ll` rows run it.
MOORDYN_LL = (
    "import sys; from pathlib import Path; import numpy as np; "
    f"sys.path.insert(0, {str(BENCHMARKS)!r}); from lowe_langley import run_moordyn; "
    "np.savez(sys.argv[2], **run_moordyn(Path(sys.argv[1]), 1))"
)


def parse(argv=None) -> argparse.Namespace:
    parser = argparse.ArgumentParser(description=__doc__, formatter_class=argparse.RawDescriptionHelpFormatter)
    parser.add_argument("--rows", nargs="+", choices=ROWS, default=list(ROWS), help="run only these rows")
    parser.add_argument("--repeats", type=int, default=DEFAULTS["repeats"], help="cold / warm / MoorDyn triples")
    parser.add_argument(
        "--duration", type=float, default=DEFAULTS["duration"], help="line40's motion table length (s), for checks"
    )
    parser.add_argument("--cases", type=int, help="the sweeps' case count instead of 32 and 256, for checks")
    parser.add_argument("--examples", nargs="+", help="the examples row's scenes (default: every bundled one)")
    parser.add_argument(
        "--campaign-cases", type=int, default=DEFAULTS["campaign_cases"], help="the campaign row's case count"
    )
    parser.add_argument("--out", type=Path, default=RESULTS, help="the results file")
    parser.add_argument("--report", action="store_true", help="print the latest session's table")
    return parser.parse_args(argv)


# ---------------------------------------------------------------------------------------
# Processes


def environment(cache: Path | None = None) -> dict:
    """A child process's environment: this one's, with the `jaxcable` beside this Python
    first on PATH (as `speed.py` sets it), `OPENBLAS_NUM_THREADS=1` unless the caller
    set it, no `JAX_COMPILATION_CACHE_DIR` (it would take the place of jaxcable's
    folder), and `JAXCABLE_CACHE_DIR` set to `cache` if given."""
    env = {**os.environ, "PATH": str(Path(sys.executable).parent) + os.pathsep + os.environ.get("PATH", "")}
    env.setdefault("OPENBLAS_NUM_THREADS", "1")
    env.pop("JAX_COMPILATION_CACHE_DIR", None)
    if cache is not None:
        env["JAXCABLE_CACHE_DIR"] = str(cache)
    return env


def process(command: list[str], cwd: Path, cache: Path | None = None) -> dict:
    """Run `command` as a whole process in `cwd` (with `environment(cache)`), output
    captured: its wall time (s), exit status, load average before and after, first
    line of stderr, stderr's tail if it failed, stdout's last lines, and `jaxcable
    run`'s closing summary (`summary`) and its parts (`split`)."""
    before = load()
    start = time.perf_counter()
    done = subprocess.run(command, cwd=cwd, env=environment(cache), capture_output=True, text=True)
    wall = time.perf_counter() - start
    errors = [line for line in done.stderr.splitlines() if line.strip()]
    return {
        "command": " ".join("python" if c == sys.executable else c for c in command),
        "wall_s": wall,
        "status": done.returncode,
        "load": [before, load()],
        "stderr_first": errors[0] if errors else "",
        "stderr_tail": errors[-8:] if done.returncode else [],
        "traceback": "Traceback (most recent call last)" in done.stderr,
        "stdout_tail": [line for line in done.stdout.splitlines() if line.strip()][-3:],
        "summary": [line for line in done.stdout.splitlines() if line.startswith(("simulated", "statics only"))],
        "split": split(done.stdout),
    }


def split(stdout: str) -> dict:
    """The parts of `jaxcable run`'s closing line, `wall time T s: statics S s (I
    iterations; compile C s of it), compile C s, run R s; ...cache...`, as numbers
    (s), with the line itself; empty where there is none."""
    lines = [line for line in stdout.splitlines() if line.startswith("wall time")]
    if not lines:
        return {}
    line = lines[-1]
    parts = {"line": line}
    patterns = {
        "wall_s": r"wall time ([\d.]+) s",
        "statics_s": r"statics ([\d.]+) s",
        "statics_iterations": r"\((\d+) iterations",
        "statics_compile_s": r"compile ([\d.]+) s of it",
        "compile_s": r"compile ([\d.]+) s, run",
        "run_s": r", run ([\d.]+) s",
    }
    for key, pattern in patterns.items():
        found = re.search(pattern, line)
        if found:
            parts[key] = float(found.group(1))
    cache = re.search(r"; ([^;]*cache[^;]*)$", line)  # after the statics' own "(I iterations; ...)"
    parts["cache"] = cache.group(1) if cache else ""
    return parts


def failed(record: dict) -> str:
    """What to print and keep of a process that failed."""
    return f"exit {record['status']}: " + " / ".join(record["stderr_tail"][-3:])


def interleaved(jaxcable, moordyn, repeats: int, folder: Path, what: str) -> dict[str, list[dict]]:
    """`repeats` turns of a cold `jaxcable(cache)` process on a new, empty cache folder,
    a warm one on the same folder, then `moordyn()` (if given); each returns `process`'s
    record. The cold run's cache contents (`speed.cached_programs`) are kept with it."""
    runs = {"cold": [], "warm": [], "moordyn": []}
    for k in range(repeats):
        cache = folder / f"cache_{k}"
        cache.mkdir()
        runs["cold"].append(jaxcable(cache))
        programs = cached_programs(cache)
        runs["cold"][-1]["cached"] = {"programs": len(programs), "bytes": sum(size for _, size in programs)}
        runs["warm"].append(jaxcable(cache))
        if moordyn is not None:
            runs["moordyn"].append(moordyn())
        print(
            f"{what} {k + 1}/{repeats}: " + ", ".join(f"{kind} {describe(r[-1])}" for kind, r in runs.items() if r),
            flush=True,
        )
    return runs


def describe(record: dict) -> str:
    """A run's wall time, or its failure, for the progress lines."""
    return f"{record['wall_s']:.2f} s" if record["status"] == 0 else f"FAILED ({failed(record)})"


# ---------------------------------------------------------------------------------------
# Rows


def row(measure, *, jaxcable, moordyn=(), figure, target=None, accuracy="", notes="", **details) -> dict:
    """One table row from the run records of each engine, in turn order.

    `figure`: `"ratio"`, jaxcable ÷ MoorDyn per turn, median, met when ≤ `target`;
    `"speed-up"`, MoorDyn ÷ jaxcable per turn, median, met when ≥ `target`; `"statics"`,
    jaxcable's statics time (s) from its summary, median, ≤ `target`; `"wall"`,
    jaxcable's wall time (s), median, ≤ `target`. Only turns whose processes succeeded
    count (for `"wall"` of a refusal, every turn: its failure is the point). No target:
    the figure is shown, not judged."""
    ok = [r["status"] == 0 for r in jaxcable]
    pairs = [(j, m) for j, m in zip(jaxcable, moordyn) if j["status"] == 0 and m["status"] == 0]
    values = {
        "ratio": [j["wall_s"] / m["wall_s"] for j, m in pairs],
        "speed-up": [m["wall_s"] / j["wall_s"] for j, m in pairs],
        "statics": [r["split"]["statics_s"] for r, good in zip(jaxcable, ok) if good and "statics_s" in r["split"]],
        "wall": [r["wall_s"] for r in jaxcable],
    }[figure]
    value = statistics.median(values) if values else None
    met = None
    if value is not None and target is not None:
        met = bool(value >= target if figure == "speed-up" else value <= target)
    everything = [*jaxcable, *moordyn]
    return {
        "measure": measure,
        "figure": figure,
        "value": value,
        "values": values,
        "target": target,
        "met": met,
        "jaxcable_s": [r["wall_s"] for r in jaxcable],
        "moordyn_s": [r["wall_s"] for r in moordyn],
        "failures": [failed(r) for r in everything if r["status"] != 0 and figure != "wall"],
        "accuracy": accuracy,
        "notes": notes,
        "load": [everything[0]["load"][0], everything[-1]["load"][1]] if everything else None,
        "jaxcable_runs": list(jaxcable),
        "moordyn_runs": list(moordyn),
        **details,
    }


def typical(runs: list[dict]) -> dict:
    """The successful run of median wall time (the lower middle one), or the first run."""
    good = sorted((r for r in runs if r["status"] == 0), key=lambda r: r["wall_s"])
    return good[(len(good) - 1) // 2] if good else runs[0]


def row_line40(args, solver: str | None = None) -> list[dict]:
    """The 40-segment rope from its MoorDyn file and a motion table, `jaxcable run`
    against MoorDyn's driver, cold and warm; with `--solver solver` where given (the
    `line40_auto` row: the file's dtM and tScheme replaced by `auto`)."""
    with tempfile.TemporaryDirectory() as tmp:
        folder = Path(tmp)
        (folder / "line40.txt").write_text(LINE40)
        (folder / "moordyn_table.py").write_text(MOORDYN_TABLE)
        surge_table(folder / "motion.csv", args.duration, LINE40_AMPLITUDE, LINE40_PERIOD)
        jaxcable = ["jaxcable", "run", "line40.txt", "--motion", "motion.csv", "--out", "run.csv"]
        if solver is not None:
            jaxcable += ["--solver", solver]
        moordyn = [sys.executable, "moordyn_table.py", "line40.txt", repr(LINE40_DTM), repr(LINE40_DT_OUT)]
        moordyn += ["motion.csv", "moordyn_tension.npy"]
        runs = interleaved(
            lambda cache: process(jaxcable, folder, cache),
            lambda: process(moordyn, folder),
            args.repeats,
            folder,
            "line40",
        )
        accuracy, difference = line40_accuracy(folder)
    name = "line40" if solver is None else f"line40 with --solver {solver}"
    return [
        row(
            f"{name}: first `jaxcable run` ÷ MoorDyn's process ({args.duration:g} s motion table, 40 segments)",
            jaxcable=runs["cold"],
            moordyn=runs["moordyn"],
            figure="ratio",
            target=1.5,
            accuracy=accuracy,
            fairten_difference=difference,
        ),
        row(
            f"{name}: second `jaxcable run` (warm cache) ÷ MoorDyn's process",
            jaxcable=runs["warm"],
            moordyn=runs["moordyn"],
            figure="ratio",
            target=0.7,
            accuracy=accuracy,
        ),
    ]


def surge_table(path: Path, duration: float, amplitude: float, period: float) -> None:
    """A motion table (`time,x,y,z` every `LINE40_DT_OUT`) of line40's top surging
    harmonically about its rest by `amplitude` (m) at `period` (s), for `duration` (s)."""
    t = np.arange(round(duration / LINE40_DT_OUT) + 1) * LINE40_DT_OUT
    x = LINE40_TOP + amplitude * np.sin(2 * np.pi * t / period)
    zeros = np.zeros_like(t)
    table = np.column_stack([t, x, zeros, zeros])
    np.savetxt(path, table, delimiter=",", header="time,x,y,z", comments="", fmt="%.10g")


def line40_accuracy(folder: Path) -> tuple[str, dict | None]:
    """jaxcable's `FairTen1` (run.csv) against MoorDyn's (sampled every dtOut), at
    MoorDyn's times: RMS and largest difference relative to MoorDyn's peak, over the
    whole run and after its first `LINE40_SETTLED` seconds (each engine starts from its
    own initial condition: jaxcable's statics, MoorDyn's IC generation), and both
    engines' tension at t = 0."""
    try:
        ours = np.genfromtxt(folder / "run.csv", delimiter=",", names=True)
        theirs = np.load(folder / "moordyn_tension.npy")
    except OSError as error:
        return f"not compared: {error}", None
    times = np.arange(theirs.size) * LINE40_DT_OUT
    apart = np.interp(times, ours["Time"], ours["FairTen1"]) - theirs
    peak = float(np.max(np.abs(theirs)))
    later = times >= LINE40_SETTLED
    later_peak = float(np.max(np.abs(theirs[later]))) if later.any() else float("nan")
    difference = {
        "rms_over_peak": float(np.sqrt(np.mean(apart**2)) / peak),
        "max_over_peak": float(np.max(np.abs(apart)) / peak),
        "moordyn_peak_N": peak,
        "jaxcable_peak_N": float(np.max(ours["FairTen1"])),
        "settled_s": LINE40_SETTLED,
        "settled_rms_over_peak": float(np.sqrt(np.mean(apart[later] ** 2)) / later_peak) if later.any() else None,
        "settled_moordyn_peak_N": later_peak,
        "start_N": {"jaxcable": float(ours["FairTen1"][0]), "moordyn": float(theirs[0])},
        "samples": int(times.size),
    }
    text = (
        f"FairTen1 RMS diff {difference['rms_over_peak']:.2%} of MoorDyn's peak {peak / 1e3:.1f} kN (largest "
        f"{difference['max_over_peak']:.0%}; jaxcable's peak {difference['jaxcable_peak_N'] / 1e3:.1f} kN); "
        f"after {LINE40_SETTLED:g} s {difference['settled_rms_over_peak'] or float('nan'):.2%} of "
        f"{later_peak / 1e3:.1f} kN; at t = 0 jaxcable {difference['start_N']['jaxcable'] / 1e3:.1f} kN, MoorDyn "
        f"{difference['start_N']['moordyn'] / 1e3:.1f} kN"
    )
    return text, difference


def row_campaign(args) -> list[dict]:
    """A design campaign: line40 under `--campaign-cases` surge motions (amplitudes from
    0.5 to 3 m, periods 5.6, 8, 10 and 12 s in turn), `CAMPAIGN_DURATION` s each, one
    motion table a case. `jaxcable campaign line40.txt cases.csv --out FOLDER`, cold and
    warm (a new folder each, so that nothing is skipped), against MoorDyn's driver in two
    processes at once, each running half the cases in turn. The figure is the speed-up,
    MoorDyn ÷ jaxcable, with both as cases per hour; accuracy, each case's `FairTen1`
    against MoorDyn's (its RMS difference after `LINE40_SETTLED` s relative to MoorDyn's
    peak there, and its peak)."""
    count = args.campaign_cases
    amplitudes = np.linspace(0.5, 3.0, count)
    periods = [CAMPAIGN_PERIODS[k % len(CAMPAIGN_PERIODS)] for k in range(count)]
    with tempfile.TemporaryDirectory() as tmp:
        folder = Path(tmp)
        (folder / "line40.txt").write_text(LINE40)
        (folder / "moordyn_table.py").write_text(MOORDYN_TABLE)
        rows = ["case,motion"]
        for k, (amplitude, period) in enumerate(zip(amplitudes, periods)):
            surge_table(folder / f"surge{k:03d}.csv", CAMPAIGN_DURATION, amplitude, period)
            rows.append(f"surge{k:03d},surge{k:03d}.csv")
        (folder / "cases.csv").write_text("\n".join(rows) + "\n")
        outs = iter(range(10**6))

        def jaxcable(cache):
            command = ["jaxcable", "campaign", "line40.txt", "cases.csv", "--out", f"out{next(outs)}", "--no-progress"]
            command += ["--duration", repr(CAMPAIGN_DURATION)]  # a MoorDyn file gives none (60 s by default)
            return process(command, folder, cache)

        moordyn = []
        for half in (0, 1):
            command = [sys.executable, "moordyn_table.py", "line40.txt", repr(LINE40_DTM), repr(LINE40_DT_OUT)]
            for k in range(half, count, 2):
                command += [f"surge{k:03d}.csv", f"moordyn{k:03d}.npy"]
            moordyn.append(command)
        runs = interleaved(jaxcable, lambda: together(moordyn, folder), args.repeats, folder, "campaign")
        accuracy, difference = campaign_accuracy(folder, count)
    hourly = {
        kind: statistics.median(3600 * count / r["wall_s"] for r in records if r["status"] == 0)
        for kind, records in runs.items()
        if any(r["status"] == 0 for r in records)
    }
    notes = "cases per hour: " + ", ".join(f"{kind} {value:.0f}" for kind, value in hourly.items())
    measure = f"campaign: {count} cases of line40, {CAMPAIGN_DURATION:g} s each, against MoorDyn in 2 processes"
    return [
        row(
            f"{measure}, first `jaxcable campaign`",
            jaxcable=runs["cold"],
            moordyn=runs["moordyn"],
            figure="speed-up",
            accuracy=accuracy,
            notes=notes,
            difference=difference,
        ),
        row(
            f"{measure}, second `jaxcable campaign` (warm cache, a new folder)",
            jaxcable=runs["warm"],
            moordyn=runs["moordyn"],
            figure="speed-up",
            accuracy=accuracy,
            notes=notes,
        ),
    ]


def together(commands: list[list[str]], cwd: Path) -> dict:
    """`commands` as processes started at once, as `process` records one: the wall time
    until the last ends, the worst exit status, the first process's stderr."""
    before = load()
    start = time.perf_counter()
    started = [
        subprocess.Popen(c, cwd=cwd, env=environment(), stdout=subprocess.PIPE, stderr=subprocess.PIPE, text=True)
        for c in commands
    ]
    outputs = [p.communicate() for p in started]
    wall = time.perf_counter() - start
    status = max(abs(p.returncode) for p in started)
    errors = [line for _, err in outputs for line in err.splitlines() if line.strip()]
    return {
        "command": f"{len(commands)} processes at once: " + " & ".join(" ".join(c[:3]) for c in commands),
        "wall_s": wall,
        "status": status,
        "load": [before, load()],
        "stderr_first": errors[0] if errors else "",
        "stderr_tail": errors[-8:] if status else [],
        "traceback": any("Traceback" in err for _, err in outputs),
        "stdout_tail": [],
        "summary": [],
        "split": {},
    }


def campaign_accuracy(folder: Path, count: int) -> tuple[str, dict | None]:
    """Each case's `FairTen1` in the first campaign's files against MoorDyn's: the RMS
    difference after `LINE40_SETTLED` s over MoorDyn's peak there, and the peaks'
    difference over MoorDyn's peak; the median and the worst over the cases."""
    import xarray as xr

    rms, peaks = [], []
    try:
        for k in range(count):
            theirs = np.load(folder / f"moordyn{k:03d}.npy")
            with xr.open_dataset(folder / "out0" / "cases" / f"surge{k:03d}.nc") as case:
                ours = np.interp(np.arange(theirs.size) * LINE40_DT_OUT, case["time"].values, case["FairTen1"].values)
            later = np.arange(theirs.size) * LINE40_DT_OUT >= LINE40_SETTLED
            peak = float(np.max(np.abs(theirs[later])))
            rms.append(float(np.sqrt(np.mean((ours - theirs)[later] ** 2)) / peak))
            peaks.append(float(np.max(ours[later]) / peak - 1))
    except OSError as error:
        return f"not compared: {error}", None
    difference = {"settled_rms_over_peak": rms, "peak_difference": peaks, "settled_s": LINE40_SETTLED}
    text = (
        f"FairTen1 after {LINE40_SETTLED:g} s: RMS diff median {np.median(rms):.2%}, worst {np.max(rms):.2%} of "
        f"MoorDyn's peak; peaks differ by median {np.median(np.abs(peaks)):.2%}, worst {np.max(np.abs(peaks)):.2%}"
    )
    return text, difference


def keywords(options: dict) -> str:
    """`options` as a call's keyword arguments, `a=1, b='x'`."""
    return ", ".join(f"{k}={v!r}" for k, v in options.items())


def sweep_moordyn_input() -> tuple[str, list[float]]:
    """MoorDyn's input for the sweeps' line (`moordyn_side_by_side.moordyn_input` at
    dtM = 1 ms) and its fairlead's rest position."""
    import jax

    jax.config.update("jax_enable_x64", True)  # jaxcable's float64 model, whose values the file copies
    import jaxcable as jc

    model, env = jc.examples.anchored_line(**SWEEP_LINE)
    return mss.moordyn_input(model, env, SWEEP_DTM), [float(v) for v in np.asarray(model.node_positions[1])]


def row_sweep(args, cases: int, targets: tuple[float, float | None]) -> list[dict]:
    """The user's sweep script against MoorDyn's loop over the same cases, cold and warm."""
    cases = args.cases or cases
    text, top = sweep_moordyn_input()
    settings = {
        "cases": cases,
        "low": SWEEP_AMPLITUDES[0],
        "high": SWEEP_AMPLITUDES[1],
        "duration": SWEEP_DURATION,
        "compared": SWEEP_COMPARED,
    }
    with tempfile.TemporaryDirectory() as tmp:
        folder = Path(tmp)
        (folder / "anchored_line.txt").write_text(text)
        (folder / "sweep.py").write_text(
            JAXCABLE_SWEEP.format(line=keywords(SWEEP_LINE), samples=SWEEP_SAMPLES, **settings)
        )
        (folder / "moordyn_sweep.py").write_text(
            MOORDYN_SWEEP.format(
                benchmarks=str(BENCHMARKS),
                dt_out=SWEEP_DURATION / (SWEEP_SAMPLES - 1),
                top=top,
                dtm=SWEEP_DTM,
                **settings,
            )
        )
        runs = interleaved(
            lambda cache: process([sys.executable, "sweep.py", "peaks.npy"], folder, cache),
            lambda: process([sys.executable, "moordyn_sweep.py", "anchored_line.txt", "moordyn_peaks.npy"], folder),
            args.repeats,
            folder,
            f"sweep of {cases}",
        )
        accuracy, peaks = sweep_accuracy(folder)
    name = f"{cases}-case sweep script (60 s each) against MoorDyn's loop"
    return [
        row(
            f"{name}: first run, MoorDyn ÷ jaxcable",
            jaxcable=runs["cold"],
            moordyn=runs["moordyn"],
            figure="speed-up",
            target=targets[0],
            accuracy=accuracy,
            peaks=peaks,
        ),
        row(
            f"{name}: second run, MoorDyn ÷ jaxcable",
            jaxcable=runs["warm"],
            moordyn=runs["moordyn"],
            figure="speed-up",
            target=targets[1],
            accuracy=accuracy,
        ),
    ]


def sweep_accuracy(folder: Path) -> tuple[str, dict | None]:
    """The top segment's peak tension of each case over the first snap (`SWEEP_COMPARED`),
    jaxcable's against MoorDyn's."""
    try:
        ours, theirs = np.load(folder / "peaks.npy"), np.load(folder / "moordyn_peaks.npy")
    except OSError as error:
        return f"not compared: {error}", None
    apart = np.abs(ours - theirs) / theirs
    peaks = {
        "jaxcable_N": ours.tolist(),
        "moordyn_N": theirs.tolist(),
        "max_rel_diff": float(np.nanmax(apart)),
        "median_rel_diff": float(np.nanmedian(apart)),
    }
    text = (
        f"top segment's peak tensions: largest diff {peaks['max_rel_diff']:.1%}, median {peaks['median_rel_diff']:.1%}"
    )
    return text, peaks


def row_lowe_langley(args) -> list[dict]:
    """Low & Langley case 1's whole `jaxcable run` (`lowe_langley.run_cli`), cold and
    warm, against MoorDyn's whole process (`lowe_langley.run_moordyn`)."""
    import shutil

    with tempfile.TemporaryDirectory() as tmp:
        folder = Path(tmp)
        shutil.copy(ll.DATA / "line.txt", folder / "line.txt")  # MoorDyn writes beside its input
        rest = ll.top_rest(folder / "line.txt")
        last = {}

        def jaxcable(cache):
            """`lowe_langley.run_cli`'s process, recorded as `process` records one."""
            before, start = load(), time.perf_counter()
            record = {"command": "jaxcable run line.txt --motion case1_motion.csv ... (lowe_langley.run_cli)"}
            try:
                last["cli"] = ll.run_cli(folder, 1, rest, 0.01, env=environment(cache))
                record.update(wall_s=last["cli"]["wall"], status=0, split=split(last["cli"]["summary"]))
            except subprocess.CalledProcessError as error:
                errors = [line for line in error.stderr.splitlines() if line.strip()]
                record.update(wall_s=time.perf_counter() - start, status=error.returncode, split={})
                record.update(stderr_first=errors[0] if errors else "", stderr_tail=errors[-8:])
            return {**record, "load": [before, load()]}

        moordyn = [sys.executable, "-c", MOORDYN_LL, str(folder), str(folder / "moordyn.npz")]
        runs = interleaved(jaxcable, lambda: process(moordyn, folder), args.repeats, folder, "lowe_langley")
        reference = np.loadtxt(ll.DATA / "case1.csv", delimiter=",")
        accuracy = "not compared: a process failed"
        if "cli" in last and (folder / "moordyn.npz").exists():
            theirs = np.load(folder / "moordyn.npz")
            ours_error = ll.errors(last["cli"]["times"], last["cli"]["reaction"], reference)["rms"]
            theirs_error = ll.errors(theirs["times"], theirs["reaction"], reference)["rms"]
            accuracy = f"abs R RMS err vs published {ours_error:.3f} kN, MoorDyn {theirs_error:.3f} kN"
    return [
        row(
            "Low & Langley case 1: statics in the first `jaxcable run`",
            jaxcable=runs["cold"],
            figure="statics",
            target=3.0,
            notes="second run's statics "
            + ", ".join(f"{r['split'].get('statics_s', float('nan')):g}" for r in runs["warm"])
            + " s",
        ),
    ] + [
        row(
            f"Low & Langley case 1: {which} ÷ MoorDyn's process",
            jaxcable=runs[key],
            moordyn=runs["moordyn"],
            figure="ratio",
            target=target,
            accuracy=accuracy,
            notes="target: the speed table's",
        )
        for which, key, target in (
            ("first `jaxcable run`", "cold", 2.0),
            ("second `jaxcable run` (warm cache)", "warm", 1.0),
        )
    ]


def row_examples(args) -> list[dict]:
    """Every bundled example scene (or `--examples`) by `jaxcable run NAME --out x.npz`,
    first and second run: the statics' share of the first."""
    from jaxcable.examples import scene_names

    rows = []
    for name in args.examples or scene_names():
        with tempfile.TemporaryDirectory() as tmp:
            folder = Path(tmp)
            command = ["jaxcable", "run", name, "--out", "x.npz"]
            runs = interleaved(lambda cache: process(command, folder, cache), None, args.repeats, folder, name)
        warm = typical(runs["warm"])
        rows.append(
            row(
                f"`jaxcable run {name}`: statics in the first run",
                jaxcable=runs["cold"],
                figure="statics",
                target=3.0,
                notes=f"second run {describe(warm)}, its statics {warm['split'].get('statics_s', '–')} s",
                second_runs=runs["warm"],
            )
        )
    return rows


def row_refusal(args) -> list[dict]:
    """A MoorDyn file and a TOML scene that are malformed, through `jaxcable run`: how
    long the refusal takes, its exit status and first line of stderr."""
    from jaxcable.examples import scene_path

    inputs = {
        "MoorDyn file with a non-numeric EA": (
            "bad_ea.txt",
            replaced(LINE40, "3.0  3.0e7  -0.8", "3.0  stiff  -0.8"),
        ),
        "TOML scene whose axial_stiffness is a string": (
            "bad_ea.toml",
            replaced(scene_path("anchored_line").read_text(), "axial_stiffness = 3.0e7", 'axial_stiffness = "3.0e7 N"'),
        ),
    }
    rows = []
    for what, (name, text) in inputs.items():
        with tempfile.TemporaryDirectory() as tmp:
            folder = Path(tmp)
            (folder / name).write_text(text)
            runs = []
            for k in range(args.repeats):
                cache = folder / f"cache_{k}"  # jaxcable's cache folder, new and empty
                runs.append(process(["jaxcable", "run", name], folder, cache))
                print(f"refusal, {what} {k + 1}/{args.repeats}: {runs[-1]['wall_s']:.2f} s, exit {runs[-1]['status']}")
        refused = all(r["status"] != 0 and not r["traceback"] and r["stderr_first"] for r in runs)
        result = row(
            f"refusal: {what}",
            jaxcable=runs,
            figure="wall",
            target=1.0,
            notes=f"exit {runs[0]['status']}: {runs[0]['stderr_first']}"
            + ("" if refused else " — NOT A CLEAN REFUSAL (exit 0, no message, or a traceback)"),
            refused=refused,
        )
        result["met"] = None if result["met"] is None else result["met"] and refused
        rows.append(result)
    return rows


def replaced(text: str, old: str, new: str) -> str:
    """`text` with `old` replaced by `new`; an error if `old` is not in it (the input
    it was written for has changed)."""
    if old not in text:
        raise ValueError(f"{old!r} is not in the input to break")
    return text.replace(old, new)


RUNNERS = {
    "line40": row_line40,
    "line40_auto": lambda args: row_line40(args, "auto"),
    "sweep32": lambda args: row_sweep(args, 32, (3.0, 10.0)),
    "sweep256": lambda args: row_sweep(args, 256, (10.0, None)),
    "campaign": row_campaign,
    "lowe_langley": row_lowe_langley,
    "examples": row_examples,
    "refusal": row_refusal,
}


# ---------------------------------------------------------------------------------------
# Report


def cell(runs: list[dict]) -> str:
    """Each run's wall time (s), in turn order, with its exit status where it is not 0."""
    return ", ".join(f"{r['wall_s']:.3g}" + ("" if r["status"] == 0 else f" (exit {r['status']})") for r in runs) or "–"


def parts(r: dict) -> str:
    """The typical jaxcable run's summary split, in short."""
    s = typical(r["jaxcable_runs"])["split"] if r["jaxcable_runs"] else {}
    if not s:
        return "–"
    text = []
    if "statics_s" in s:
        text.append(f"statics {s['statics_s']:g} (compile {s.get('statics_compile_s', 0):g})")
    if "compile_s" in s:
        text.append(f"compile {s['compile_s']:g}, run {s['run_s']:g}")
    return ", ".join(text) + (f"; {s['cache']}" if s.get("cache") else "")


def report(path: Path) -> None:
    s = json.loads(path.read_text())[-1]
    # Fewer repeats, a shorter table, fewer cases or scenes than the measurement's: a check.
    # More repeats measure the same thing better.
    changed = {
        k: v
        for k, v in s["settings"].items()
        if k in DEFAULTS and v != DEFAULTS[k] and not (k == "repeats" and v > DEFAULTS[k])
    }
    print(
        f"Session {s['time']}, commit {s['commit']}, {s['machine']}, jax {s['jax']}, MoorDyn {s['moordyn']}, "
        f"OPENBLAS_NUM_THREADS={s['openblas_num_threads']}; load average {s['load_average_start']} at the start, "
        f"{s['load_average_end']} at the end."
        + (f" Settings {changed}: a CHECK, NOT the measurement." if changed else "")
    )
    print()
    columns = (
        "measure, jaxcable (s), MoorDyn (s), figure, target, met?, jaxcable's summary (s), accuracy and notes, load"
    )
    print("| " + " | ".join(columns.split(", ")) + " |")
    print("|---|---|---|---|---|---|---|---|---|")
    for r in s["rows"]:
        if "error" in r:
            print(f"| {r['measure']} | – | – | – | – | – | – | ROW FAILED: {r['error'][-1]} | – |")
            continue
        unit, sign = {"ratio": ("×", "≤"), "speed-up": ("×", "≥"), "statics": (" s", "≤"), "wall": (" s", "≤")}[
            r["figure"]
        ]
        name = {"ratio": "", "speed-up": "speed-up ", "statics": "statics ", "wall": ""}[r["figure"]]
        value = "–" if r["value"] is None else f"{name}{r['value']:#.3g}{unit}"
        target = "–" if r["target"] is None else f"{sign} {r['target']:g}{unit}"
        met = {None: "–", True: "yes", False: "no"}[r["met"]]
        notes = "; ".join(x for x in (r["accuracy"], r["notes"], *(f"FAILED {f}" for f in r["failures"])) if x)
        notes = notes.replace("|", "\\|")  # stderr may hold the table's separator
        load_range = "–" if not r["load"] else f"{r['load'][0][0]}–{r['load'][1][0]}"
        print(
            f"| {r['measure']} | {cell(r['jaxcable_runs'])} | {cell(r['moordyn_runs'])} | {value} | {target} | {met} | "
            f"{parts(r)} | {notes or '–'} | {load_range} |"
        )


def main(argv=None) -> None:
    args = parse(argv)
    if args.report:
        report(args.out)
        return
    import importlib.metadata

    start_load = load()
    rows = []
    for name in args.rows:
        print(f"--- {name}", flush=True)
        try:
            rows += RUNNERS[name](args)
        except Exception:  # a row that cannot run is recorded; the others go on
            error = traceback.format_exc().strip().splitlines()
            print("\n".join(error), flush=True)
            rows.append({"measure": name, "error": error[-12:]})
    append_session(
        args.out,
        command=" ".join(["python", "benchmarks/first_contact.py", *(sys.argv[1:] if argv is None else argv)]),
        settings={k: (str(v) if isinstance(v, Path) else v) for k, v in vars(args).items()},
        moordyn=importlib.metadata.version("moordyn"),
        openblas_num_threads=environment()["OPENBLAS_NUM_THREADS"],
        load_average_start=start_load,
        load_average_end=load(),
        rows=rows,
    )
    print()
    report(args.out)


if __name__ == "__main__":
    main()
