"""The Low & Langley (2006) jumper from its MoorDyn input file, against the published
reference and against MoorDyn on the same input.

- Statics: the force of each end's support on the line, against (11.40, 0, 45.71) kN at
  the top and (−11.40, 0, 24.04) kN at the bottom (±0.2 kN).
- Cases 1–3: the top moves along x, y or z as A sin(2πt/T), A = 10 m, T = 27 s, ramped in
  over one period by f³(6f² − 15f + 10); the reference covers 80 s after the ramp. Each
  case is run through the command line, `jaxcable run line.txt --motion TABLE`, exactly
  as a user would, and its top tension compared with the digitised reference: RMS and
  largest error at the reference times. `--without-bending` runs both engines on the
  file with its EI set to 0, to show what the jumper's bending stiffness does.
- Timing: one in-process `run_scene` per case after a first (compiling) call, beside
  MoorDyn 2 (`pip install moordyn`) stepping the same motion with its own file settings
  (dtM = 1 ms); MoorDyn's initial-condition generation is not timed.

Two top tensions are compared, because the reference is a continuum's top tension and
a discretised line has two candidates for it: `FairTen1`, the tension in the top
segment (MoorDyn's channel of that name; half a segment below the top), and |R|, the
magnitude of the top support's force on the line (what MoorDyn's own regression test
compares, as the net force on its top node).

    python benchmarks/lowe_langley.py [--cases 1 2 3] [--repeats 1] [--no-moordyn] [--without-bending]
    python benchmarks/lowe_langley.py --report
"""

import argparse
import json
import platform
import shutil
import subprocess
import sys
import tempfile
import time
from pathlib import Path

import numpy as np

DATA = Path(__file__).resolve().parents[1] / "tests" / "data" / "lowe_and_langley_2006"
RESULTS = Path(__file__).resolve().parent / "results" / "lowe_langley.json"
AMPLITUDE, PERIOD, AFTER_RAMP = 10.0, 27.0, 80.0
TOP_REFERENCE = np.array([11.40, 0.0, 45.71])  # kN
BOTTOM_REFERENCE = np.array([-11.40, 0.0, 24.04])


def _jaxcable():
    """jaxcable, with JAX switched to float64 (jaxcable computes in float64 and leaves the
    switch to us). Imported on first use, not with this module, so that a process that
    only runs MoorDyn (`speed.py` times one whole) does not import JAX."""
    import jax

    import jaxcable

    jax.config.update("jax_enable_x64", True)
    return jaxcable


def top_rest(line_file: Path) -> np.ndarray:
    """The top's (point 2's) position (m) at rest, from the MoorDyn file."""
    return np.array(_jaxcable().load_scene(line_file).points[1].position)


def top_position(t: np.ndarray, case: int, rest: np.ndarray) -> np.ndarray:
    """The top's position (m) at times `t` (s): rest + f(t) A sin(2πt/T) along axis
    case − 1, with the smoothstep ramp f over the first period."""
    f = np.clip(t / PERIOD, 0.0, 1.0)
    f = f**3 * (6 * f**2 - 15 * f + 10)
    positions = np.tile(rest, (t.size, 1))
    positions[:, case - 1] += f * AMPLITUDE * np.sin(2 * np.pi * t / PERIOD)
    return positions


def errors(times: np.ndarray, series_kn: np.ndarray, reference: np.ndarray) -> dict:
    """RMS, largest and mean error (kN) at the reference times (time 0 = end of ramp)."""
    simulated = np.interp(reference[:, 0], times - PERIOD, series_kn)
    error = simulated - reference[:, 1]
    return {"rms": float(np.sqrt(np.mean(error**2))), "max": float(np.abs(error).max()), "mean": float(error.mean())}


def difference(first: dict, second: dict, key: str) -> dict:
    """RMS, largest and mean of `first[key] − second[key]` (kN) after the ramp, at
    `first`'s times: how far two engines' top tensions are apart, beside how far
    each is from the reference."""
    after = first["times"] > PERIOD
    apart = first[key][after] - np.interp(first["times"][after], second["times"], second[key])
    return {"rms": float(np.sqrt(np.mean(apart**2))), "max": float(np.abs(apart).max()), "mean": float(apart.mean())}


def run_cli(workdir: Path, case: int, rest: np.ndarray, dt_motion: float, env: dict | None = None) -> dict:
    """`jaxcable run line.txt --motion ...` for one case; its top tensions and wall time.
    `env`: the process's environment (this one's by default)."""
    t = np.arange(0.0, PERIOD + AFTER_RAMP + dt_motion / 2, dt_motion)
    table = workdir / f"case{case}_motion.csv"
    np.savetxt(
        table,
        np.column_stack([t, top_position(t, case, rest)]),
        delimiter=",",
        header="time,x,y,z",
        comments="",
        fmt="%.9f",
    )
    out = workdir / f"case{case}.npz"
    command = [
        "jaxcable",
        "run",
        str(workdir / "line.txt"),
        "--motion",
        str(table),
        "--out",
        str(out),
        "--dt-out",
        "0.05",
        "--no-progress",
        "--channels",
        "FairTen1",
        "AnchTen1",
    ]
    start = time.perf_counter()
    completed = subprocess.run(command, capture_output=True, text=True, check=True, env=env)
    wall = time.perf_counter() - start
    data = np.load(out)
    top = int(np.flatnonzero(data["constrained_nodes"] == 1)[0])  # point 2 is node 1
    return {
        "times": data["time"],
        "fairten": data["FairTen1"] / 1e3,
        "reaction": np.linalg.norm(data["reactions"][:, top], axis=1) / 1e3,
        "wall": wall,
        "summary": completed.stdout.strip().splitlines()[-1],
    }


def time_in_process(workdir: Path, case: int, rest: np.ndarray, dt_motion: float, repeats: int) -> dict:
    """Compile and run time (s) of `run_scene` for one case, in this process."""
    jc = _jaxcable()
    t = np.arange(0.0, PERIOD + AFTER_RAMP + dt_motion / 2, dt_motion)
    scene = jc.load_scene(workdir / "line.txt")
    scene = scene.with_motion_table(t, top_position(t, case, rest)[:, None, :])
    duration = PERIOD + AFTER_RAMP
    first = jc.run_scene(scene, duration=duration, dt_out=0.05)
    runs = [jc.run_scene(scene, duration=duration, dt_out=0.05) for _ in range(repeats)]
    run = float(np.median([r.dynamics_seconds for r in runs]))
    return {"compile": first.dynamics_seconds - run, "run": run, "steps": runs[0].steps, "stepping": runs[0].stepping}


def run_moordyn(workdir: Path, case: int, dt: float = 0.005) -> dict:
    """MoorDyn on the same file and motion, stepped every `dt` (s) as its own test does."""
    import moordyn

    system = moordyn.Create(str(workdir / "line.txt"))
    line, point = moordyn.GetLine(system, 1), moordyn.GetPoint(system, 2)
    rest = np.array(moordyn.GetPointPos(point))
    moordyn.Init(system, rest.tolist(), [0.0, 0.0, 0.0])
    n = moordyn.GetLineN(line)
    t, times, fairten, node_force = 0.0, [], [], []
    position = rest.copy()
    start = time.perf_counter()
    while t < PERIOD + AFTER_RAMP - 1e-9:
        target = top_position(np.array([t + dt]), case, rest)[0]
        velocity = (target - position) / dt
        moordyn.Step(system, position.tolist(), velocity.tolist(), t, dt)
        t += dt
        position = target
        times.append(t)
        fairten.append(moordyn.GetLineFairTen(line) / 1e3)
        node_force.append(np.linalg.norm(moordyn.GetLineNodeForce(line, n)) / 1e3)
    wall = time.perf_counter() - start
    moordyn.Close(system)
    return {"times": np.array(times), "fairten": np.array(fairten), "reaction": np.array(node_force), "run": wall}


def statics(workdir: Path) -> dict:
    out = workdir / "statics.npz"
    subprocess.run(
        ["jaxcable", "run", str(workdir / "line.txt"), "--duration", "0", "--out", str(out)],
        capture_output=True,
        text=True,
        check=True,
    )
    data = np.load(out)
    reactions = data["reactions"][0] / 1e3
    order = list(data["constrained_nodes"])
    top, bottom = reactions[order.index(1)], reactions[order.index(0)]
    return {
        "top_kN": top.tolist(),
        "bottom_kN": bottom.tolist(),
        "top_error_kN": (top - TOP_REFERENCE).tolist(),
        "bottom_error_kN": (bottom - BOTTOM_REFERENCE).tolist(),
        "top_tension_kN": float(np.linalg.norm(top)),
    }


def main() -> None:
    parser = argparse.ArgumentParser(description=__doc__, formatter_class=argparse.RawDescriptionHelpFormatter)
    parser.add_argument("--cases", type=int, nargs="+", default=[1], choices=[1, 2, 3])
    parser.add_argument("--repeats", type=int, default=1, help="warm in-process runs timed per case")
    parser.add_argument("--dt-motion", type=float, default=0.01, help="motion table interval (s)")
    parser.add_argument("--no-moordyn", action="store_true")
    parser.add_argument("--without-bending", action="store_true", help="set the file's EI to 0 (both engines)")
    parser.add_argument("--plot", type=Path, default=RESULTS.parent / "lowe_langley_case1.png")
    parser.add_argument("--report", action="store_true", help="print the table from the results file")
    args = parser.parse_args()
    if args.report:
        report()
        return
    if shutil.which("jaxcable") is None:
        sys.exit("the jaxcable command is not on PATH: pip install -e . first")

    with tempfile.TemporaryDirectory() as tmp:
        workdir = Path(tmp)
        text = (DATA / "line.txt").read_text()  # copied: MoorDyn writes beside its input
        if args.without_bending:
            text = text.replace("120.8e3", "0.0")
        (workdir / "line.txt").write_text(text)
        rest = top_rest(workdir / "line.txt")
        record = {
            "statics": statics(workdir),
            "cases": {},
            "bending": not args.without_bending,
            "machine": f"{platform.machine()} ({_cores()} cores)",
            "date": time.strftime("%Y-%m-%d"),
        }
        print("statics:", json.dumps(record["statics"]))
        curves = {}
        for case in args.cases:
            reference = np.loadtxt(DATA / f"case{case}.csv", delimiter=",")
            cli = run_cli(workdir, case, rest, args.dt_motion)
            timing = time_in_process(workdir, case, rest, args.dt_motion, args.repeats)
            entry = {
                "jaxcable": {
                    "fairten_error_kN": errors(cli["times"], cli["fairten"], reference),
                    "reaction_error_kN": errors(cli["times"], cli["reaction"], reference),
                    "cli_wall_s": cli["wall"],
                    "cli_summary": cli["summary"],
                    **timing,
                },
            }
            curves[case] = {"reference": reference, "jaxcable": cli}
            if not args.no_moordyn:
                md = run_moordyn(workdir, case)
                entry["moordyn"] = {
                    "fairten_error_kN": errors(md["times"], md["fairten"], reference),
                    "reaction_error_kN": errors(md["times"], md["reaction"], reference),
                    "run": md["run"],
                }
                entry["run_time_ratio_jaxcable_to_moordyn"] = timing["run"] / md["run"]
                entry["jaxcable_minus_moordyn_kN"] = {key: difference(cli, md, key) for key in ("fairten", "reaction")}
                curves[case]["moordyn"] = md
            record["cases"][str(case)] = entry
            print(f"case {case}:", json.dumps(entry))
    RESULTS.parent.mkdir(exist_ok=True)
    history = json.loads(RESULTS.read_text()) if RESULTS.exists() else []
    history.append(record)
    RESULTS.write_text(json.dumps(history, indent=1))
    if 1 in curves and not args.without_bending:
        plot(curves[1], args.plot)
    report()


def plot(curves: dict, path: Path) -> None:
    import matplotlib

    matplotlib.use("Agg")
    import matplotlib.pyplot as plt

    figure, axis = plt.subplots(figsize=(10, 4), layout="constrained")
    reference = curves["reference"]
    axis.plot(reference[:, 0], reference[:, 1], "k.", markersize=3, label="Low & Langley (digitised)")
    cli = curves["jaxcable"]
    axis.plot(cli["times"] - PERIOD, cli["fairten"], label="jaxcable FairTen1 (top segment)")
    axis.plot(cli["times"] - PERIOD, cli["reaction"], "--", label="jaxcable |R| (top support force)")
    if "moordyn" in curves:
        md = curves["moordyn"]
        axis.plot(md["times"] - PERIOD, md["reaction"], ":", label="MoorDyn |F| at top node")
    axis.set_xlim(0, AFTER_RAMP)
    axis.set_xlabel("time after the ramp (s)")
    axis.set_ylabel("top tension (kN)")
    axis.set_title("Low & Langley jumper, case 1: top moved along x, A = 10 m, T = 27 s")
    axis.grid(True, alpha=0.3)
    axis.legend(fontsize="small")
    figure.savefig(path, dpi=120)
    print(f"wrote {path}")


def report() -> None:
    history = json.loads(RESULTS.read_text())
    # The latest record with the file's EI and the latest without it (older records,
    # from before jaxcable modelled bending, left it out too).
    for bending in (True, False):
        records = [r for r in history if r.get("bending", False) == bending]
        if records:
            print(f"### {'with' if bending else 'without'} bending (EI = {120.8 if bending else 0} kN·m²)")
            _report(records[-1])


def _report(latest: dict) -> None:
    s = latest["statics"]
    print(
        f"statics: top {np.round(s['top_kN'], 3)} kN (error {np.round(s['top_error_kN'], 3)}), "
        f"bottom {np.round(s['bottom_kN'], 3)} kN (error {np.round(s['bottom_error_kN'], 3)}); "
        f"|top| {s['top_tension_kN']:.3f} kN"
    )
    print(
        "| case | engine | top tension | RMS err (kN) | max err (kN) | mean err (kN) | steps | compile (s) | run (s) | "
        "run ratio |"
    )
    print("|---|---|---|---|---|---|---|---|---|---|")
    for case, entry in latest["cases"].items():
        j = entry["jaxcable"]
        ratio = entry.get("run_time_ratio_jaxcable_to_moordyn")
        for label, key in (("FairTen1", "fairten_error_kN"), ("abs R", "reaction_error_kN")):
            e = j[key]
            print(
                f"| {case} | jaxcable | {label} | {e['rms']:.3f} | {e['max']:.3f} | {e['mean']:+.3f} | {j['steps']} | "
                f"{j['compile']:.1f} | {j['run']:.1f} | {'' if ratio is None else f'{ratio:.2f}'} |"
            )
        if "moordyn" in entry:
            m = entry["moordyn"]
            for label, key in (("FairTen", "fairten_error_kN"), ("abs F top node", "reaction_error_kN")):
                e = m[key]
                print(
                    f"| {case} | MoorDyn 2 | {label} | {e['rms']:.3f} | {e['max']:.3f} | {e['mean']:+.3f} | "
                    f"dtM 1 ms | – | {m['run']:.1f} | 1 |"
                )
    for case, entry in latest["cases"].items():
        if "jaxcable_minus_moordyn_kN" in entry:
            apart = entry["jaxcable_minus_moordyn_kN"]
            print(
                f"case {case}, jaxcable − MoorDyn after the ramp (kN): "
                + "; ".join(
                    f"{label} RMS {apart[key]['rms']:.3f}, mean {apart[key]['mean']:+.3f}, max {apart[key]['max']:.3f}"
                    for label, key in (("FairTen1", "fairten"), ("top force", "reaction"))
                )
            )
    print(f"({latest['machine']}, {latest['date']})")


def _cores() -> int:
    import os

    return os.cpu_count() or 0


if __name__ == "__main__":
    main()
