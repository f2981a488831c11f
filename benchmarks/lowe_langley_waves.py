"""The Low & Langley (2006) jumper in Airy waves (cases 4–6), against the published
reference and against MoorDyn fed the same wave kinematics.

The line is read from its MoorDyn input file (`tests/data/lowe_and_langley_2006/line.txt`)
and held fixed at both ends. Waves of amplitude 5 m and period 10 s travel at headings
0°, 45° and 90° with phases 230°, 165° and 0° (cases 4, 5, 6), as MoorDyn's regression
test sets them. Time 0 of the reference is t = 20 s (two periods) into the run.

- jaxcable: `Environment(waves=Airy(...))`, the finite-depth dispersion relation, from
  still-water equilibrium, with the waves ramped in over one period.
- MoorDyn 2 (`pip install moordyn`), stepped at 5 ms through its external-wave API with
  the kinematics its regression test uses (deep-water k; the same profile to 0.06 % at
  kd = 4.0), switched on at once, as there.

The compared quantity is |R|, the magnitude of the top support's force on the line: what
MoorDyn's regression test compares, within 1 kN, as the net force on its top node.

    python benchmarks/lowe_langley_waves.py [--cases 4 5 6] [--no-moordyn] [--repeats 1]
    python benchmarks/lowe_langley_waves.py --report
"""

import argparse
import json
import platform
import shutil
import tempfile
import time
from pathlib import Path

import jax
import numpy as np
from _timing import timed

import jaxcable as jc

jax.config.update("jax_enable_x64", True)  # jaxcable computes in float64 and leaves the switch to us

DATA = Path(__file__).resolve().parents[1] / "tests" / "data" / "lowe_and_langley_2006"
RESULTS = Path(__file__).resolve().parent / "results" / "lowe_langley_waves.json"
AMPLITUDE, PERIOD, SETTLE, AFTER = 5.0, 10.0, 20.0, 30.0
PHASES = {4: 230.0, 5: 165.0, 6: 0.0}  # degrees


def heading(case: int) -> float:
    return 45.0 * (case - 4)


def errors(times, series_kn, reference) -> dict:
    """RMS, largest and mean error (kN) at the reference times."""
    error = np.interp(reference[:, 0], times - SETTLE, series_kn) - reference[:, 1]
    return {"rms": float(np.sqrt(np.mean(error**2))), "max": float(np.abs(error).max()), "mean": float(error.mean())}


def run_jaxcable(case: int, repeats: int) -> dict:
    built = jc.load_scene(DATA / "line.txt").build()
    still = built.environment
    depth = float(still.depth) if still.depth is not None else 100.0
    wave = jc.Airy(
        2 * AMPLITUDE, PERIOD, depth, gravity=still.gravity, heading=heading(case), phase=np.radians(PHASES[case])
    )
    env = jc.Environment(
        still.water_density,
        still.gravity,
        still.current,
        still.free_surface,
        depth=depth,
        waves=wave,
        wave_ramp=PERIOD,
        seabed=still.seabed,
    )
    model = built.model
    static = jc.solve_statics(
        model, jc.Environment(still.water_density, still.gravity, free_surface=still.free_surface)
    )
    ts = np.arange(0.0, SETTLE + AFTER + 1e-9, 0.05)
    top = int(np.flatnonzero(np.asarray(model.constrained_nodes) == 1)[0])

    def run():
        return jc.simulate(model, env, SETTLE + AFTER, ts=ts, initial=static.state)

    result, compile_time, wall = timed(run, repeats)
    reaction = np.linalg.norm(np.asarray(result.reactions[:, top]), axis=1) / 1e3
    return {
        "times": ts,
        "reaction": reaction,
        "compile": compile_time,
        "run": wall,
        "steps": int(result.stats["num_steps"]),
        "success": bool(result.success),
    }


def run_moordyn(case: int, dt: float = 0.005) -> dict:
    """MoorDyn through its external-wave API, as its regression test drives it."""
    import moordyn

    omega, phase, beta = 2 * np.pi / PERIOD, np.radians(PHASES[case]), np.radians(heading(case))
    k, depth = omega**2 / 9.81, 100.0

    def kinematics(points, t):
        x = points[:, 0] * np.cos(beta) + points[:, 1] * np.sin(beta)
        cs, ss = np.cos(k * x - omega * t + phase), np.sin(k * x - omega * t + phase)
        ch = np.cosh(k * (points[:, 2] + depth)) / np.cosh(k * depth)
        sh = np.sinh(k * (points[:, 2] + depth)) / np.cosh(k * depth)
        u = omega * AMPLITUDE * np.column_stack([cs * ch * np.cos(beta), cs * ch * np.sin(beta), ss * sh])
        a = omega**2 * AMPLITUDE * np.column_stack([ss * ch * np.cos(beta), ss * ch * np.sin(beta), -cs * sh])
        return u, a

    # MoorDyn writes its output files beside its input: give it a copy.
    workdir = Path(tempfile.mkdtemp())
    shutil.copy(DATA / "line.txt", workdir)
    system = moordyn.Create(str(workdir / "line.txt"))
    line, point = moordyn.GetLine(system, 1), moordyn.GetPoint(system, 2)
    rest = list(moordyn.GetPointPos(point))
    moordyn.Init(system, rest, [0.0, 0.0, 0.0])
    moordyn.ExternalWaveKinInit(system)
    n = moordyn.GetLineN(line)
    t, times, reaction = 0.0, [], []
    start = time.perf_counter()
    while t < SETTLE + AFTER - 1e-9:
        points = np.asarray(moordyn.ExternalWaveKinGetCoordinates(system)).reshape(-1, 3)
        u, a = kinematics(points, t + 0.5 * dt)
        moordyn.ExternalWaveKinSet(system, u.tolist(), a.tolist(), t + 0.5 * dt)
        moordyn.Step(system, rest, [0.0, 0.0, 0.0], t, dt)
        t += dt
        times.append(t)
        reaction.append(np.linalg.norm(moordyn.GetLineNodeForce(line, n)) / 1e3)
    wall = time.perf_counter() - start
    moordyn.Close(system)
    shutil.rmtree(workdir)
    return {"times": np.array(times), "reaction": np.array(reaction), "run": wall}


def report(entries) -> None:
    print(
        "| case | heading | jaxcable |R| RMS / max error (kN) | MoorDyn |R| RMS / max error (kN) | jaxcable run (s) | "
        "MoorDyn run (s) | ratio |"
    )
    print("|---|---|---|---|---|---|---|")
    for e in entries:
        md = e.get("moordyn")
        md_err = f"{md['error']['rms']:.2f} / {md['error']['max']:.2f}" if md else "–"
        md_run = f"{md['run']:.2f}" if md else "–"
        ratio = f"{e['jaxcable']['run'] / md['run']:.2f}" if md else "–"
        print(
            f"| {e['case']} | {heading(e['case']):.0f}° | {e['jaxcable']['error']['rms']:.2f} / "
            f"{e['jaxcable']['error']['max']:.2f} "
            f"| {md_err} | {e['jaxcable']['run']:.2f} (compile {e['jaxcable']['compile']:.1f}) | {md_run} | {ratio} |"
        )


def main() -> None:
    parser = argparse.ArgumentParser(description=__doc__, formatter_class=argparse.RawDescriptionHelpFormatter)
    parser.add_argument("--cases", type=int, nargs="+", default=[4, 5, 6], choices=[4, 5, 6])
    parser.add_argument("--repeats", type=int, default=1)
    parser.add_argument("--no-moordyn", action="store_true")
    parser.add_argument("--plot", type=Path, default=RESULTS.parent / "lowe_langley_waves.png")
    parser.add_argument("--report", action="store_true")
    args = parser.parse_args()
    if args.report:
        report(json.loads(RESULTS.read_text())[-1]["cases"])
        return

    entries, curves = [], {}
    for case in args.cases:
        reference = np.loadtxt(DATA / f"case{case}.csv", delimiter=",")
        ours = run_jaxcable(case, args.repeats)
        entry = {"case": case, "jaxcable": {k: ours[k] for k in ("compile", "run", "steps", "success")}}
        entry["jaxcable"]["error"] = errors(ours["times"], ours["reaction"], reference)
        curves[case] = {"reference": reference, "jaxcable": ours}
        if not args.no_moordyn:
            theirs = run_moordyn(case)
            entry["moordyn"] = {"run": theirs["run"], "error": errors(theirs["times"], theirs["reaction"], reference)}
            curves[case]["moordyn"] = theirs
        entries.append(entry)
        print(json.dumps(entry), flush=True)

    record = {
        "date": time.strftime("%Y-%m-%d %H:%M"),
        "machine": {
            "platform": platform.platform(),
            "processor": platform.processor(),
            "devices": [str(d) for d in jax.devices()],
        },
        "cases": entries,
    }
    history = json.loads(RESULTS.read_text()) if RESULTS.exists() else []
    RESULTS.parent.mkdir(exist_ok=True)
    RESULTS.write_text(json.dumps(history + [record], indent=1))
    report(entries)

    import matplotlib

    matplotlib.use("Agg")
    import matplotlib.pyplot as plt

    fig, axes = plt.subplots(len(curves), 1, figsize=(8, 2.6 * len(curves)), sharex=True, squeeze=False)
    for ax, (case, c) in zip(axes[:, 0], curves.items()):
        ax.plot(c["reference"][:, 0], c["reference"][:, 1], "k.", ms=3, label="Low & Langley (digitised)")
        ax.plot(c["jaxcable"]["times"] - SETTLE, c["jaxcable"]["reaction"], label="jaxcable")
        if "moordyn" in c:
            ax.plot(c["moordyn"]["times"] - SETTLE, c["moordyn"]["reaction"], "--", label="MoorDyn")
        ax.set_xlim(0, AFTER)
        ax.set_ylabel(f"case {case}: |R| top (kN)")
    axes[-1, 0].set_xlabel("t − 20 s (s)")
    axes[0, 0].legend(fontsize=8)
    fig.tight_layout()
    fig.savefig(args.plot, dpi=120)
    print(f"figure: {args.plot}")


if __name__ == "__main__":
    main()
