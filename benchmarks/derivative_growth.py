"""Derivatives through slack and snap loads: how the tangent grows, and which
statistics' derivatives can be trusted.

The line is the README's anchored line (20 segments, C_E = 3e7 N, C_E1 = 3e6 N, no
axial damping, 1.57 m top motion at 5.6 s, 0.5 m/s current), started from statics. Its
top segment goes slack at about 3.0 s. The parameter is every segment's unstretched
length at once (m), moved by `eqx.tree_at`; statics is solved once, at the nominal
length, so that the derivative is the dynamics' alone.

1. **The tangent against time** (`--part tangent`): the forward-mode tangent of the top
   tension, d T_top / d l (N/m), and the largest |d x / d l| over the nodes (m/m), beside
   central differences at h = 1e-3 ... 1e-9 m. The steps are fixed (Dopri5, dt =
   2e-4 s), so that the discrete solution is a smooth function of the length and its
   differences must converge to its derivative as h shrinks: where they do, the tangent
   is exact, whatever its size. Before the slack the two agree at every h; after it,
   only at smaller and smaller h, as the tangent grows by one to three orders of
   magnitude every quarter second (an exponential sensitivity, not a jump).
   `--part jumper` does the same on the Low & Langley jumper (`lowe_langley.py`'s file
   and case 1 motion, 10 m surge at 27 s, with its EI), whose top segment stays taut:
   fixed Dopri5 steps of 5e-4 s over its first 54 s.
2. **Statistics** (`--part statistics`): the mean, RMS and maximum of the top tension
   over windows [0, t], by `jax.grad` through `jc.simulate` with its default solver and
   adjoint, judged by `jc.check_derivative` against central differences at h = 0.2 m
   ... 2e-6 m.
3. **Axial damping** (`--part damping`): the same statistics over [0, 10] s on the same
   line given axial damping, `jc.KelvinVoigt` with C_v = ζ L √(EA m) (MoorDyn's `BA =
   −ζ`, the damping ratio of one segment's axial mode, L the segment length) at ζ = 0.1,
   0.3 and 0.8 (MoorDyn files commonly ask for 0.8), beside ζ = 0: whether the
   derivative agrees with central differences, and how far the damping moves the
   statistic itself.

    python benchmarks/derivative_growth.py                  # both parts (about 10 min on 2 cores)
    python benchmarks/derivative_growth.py --part tangent   # part 1 alone
    python benchmarks/derivative_growth.py --part jumper    # part 1 on the jumper (about 2 min)
    python benchmarks/derivative_growth.py --part damping   # part 3 (about 16 min)
    python benchmarks/derivative_growth.py --report         # the latest session's tables

Results are appended to benchmarks/results/derivative_growth.json.
"""

import argparse
import json
import time
from pathlib import Path

import diffrax
import equinox as eqx
import jax
import jax.numpy as jnp
import numpy as np

jax.config.update("jax_enable_x64", True)

from _results import append_session  # noqa: E402

import jaxcable as jc  # noqa: E402

RESULTS = Path(__file__).parent / "results" / "derivative_growth.json"
WINDOWS = (1.5, 2.5, 5.0, 10.0)
STATISTICS = {
    "mean": lambda t: jnp.mean(t),
    "rms": lambda t: jnp.sqrt(jnp.mean(t**2)),
    "max": lambda t: jnp.max(t),
}


def readme_line():
    """The README's line and water (`jaxcable.examples.anchored_line_in_current`), and
    the statics to start from."""
    model, env = jc.examples.anchored_line_in_current()
    return model, env, jc.solve_statics(model, env).state


def lengthened(model, change):
    return eqx.tree_at(lambda m: m.segment_length, model, model.segment_length + change)


def tangent_rows(model, env, start, top, t1, dt, every, steps):
    """The forward-mode tangent of segment `top`'s tension in every segment's length,
    beside central differences at `steps` (m), at output times `every` s apart to `t1`,
    with fixed Dopri5 steps of `dt` s from `start`: one row per output time."""
    ts = jnp.linspace(0.0, t1, int(round(t1 / every)) + 1)
    config = jc.SolverConfig(
        diffrax.Dopri5(),
        dt0=dt,
        stepsize_controller=diffrax.ConstantStepSize(),
        adjoint=diffrax.ForwardMode(),
        max_steps=int(t1 / dt) + 10,
    )

    def run(change):
        r = jc.simulate(lengthened(model, change), env, t1=t1, ts=ts, initial=start, solver=config)
        return r.tension[:, top], r.positions, jnp.min(r.tension, axis=1)

    (tension, _, lowest), (d_tension, d_positions, _) = jax.jvp(run, (0.0,), (1.0,))
    differences = {h: (run(h)[0] - run(-h)[0]) / (2 * h) for h in steps}
    return [
        {
            "t": t,
            "top_tension": float(tension[i]),
            "lowest_tension": float(lowest[i]),
            "max_position_tangent": float(jnp.max(jnp.abs(d_positions[i]))),
            "tension_tangent": float(d_tension[i]),
            "differences": {f"{h:g}": float(d[i]) for h, d in differences.items()},
        }
        for i, t in enumerate(ts.tolist())
    ]


def tangent_part(t1=4.0, dt=2e-4, steps=(1e-3, 1e-5, 1e-7, 1e-9)):
    model, env, start = readme_line()
    return {"t1": t1, "dt": dt, "rows": tangent_rows(model, env, start, -1, t1, dt, 0.25, steps)}


def jumper_part(t1=54.0, dt=5e-4, every=2.0, steps=(1e-3, 1e-5, 1e-7, 1e-9)):
    """`tangent_part` on the Low & Langley jumper, case 1: the top segment's tension
    and its tangent in every segment's unstretched length, against central
    differences."""
    import lowe_langley as ll

    line_file = ll.DATA / "line.txt"
    t = np.arange(0.0, t1 + ll.PERIOD / 2, 0.1)
    scene = jc.load_scene(line_file).with_motion_table(t, ll.top_position(t, 1, ll.top_rest(line_file))[:, None, :])
    built = scene.build()
    model, env = built.model, built.environment
    start = jc.solve_statics(model, env).state
    top = int(np.flatnonzero((np.asarray(model.segment_nodes) == 1).any(axis=1))[0])  # point 2 keeps node 1
    rows = tangent_rows(model, env, start, top, t1, dt, every, steps)
    return {"t1": t1, "dt": dt, "segments": model.n_segments, "rows": rows}


def damped(model, ratio):
    """`model` with axial damping of ratio `ratio` (MoorDyn's `BA = −ζ`): C_v = ζ L √(EA m)
    (N·s), L its segment length, on its own tension law's stiffnesses."""
    law, line = model.line.tension_law, model.line
    stiffness, mass = np.asarray(law.axial_stiffness), np.asarray(line.mass_per_length)
    damping = ratio * np.asarray(model.segment_length) * np.sqrt(stiffness * mass)
    viscous = jc.KelvinVoigt(law.axial_stiffness, law.quadratic_stiffness(), damping, slack_width=law.slack_width)
    return eqx.tree_at(lambda m: m.line.tension_law, model, viscous)


def damping_part(ratios=(0.0, 0.1, 0.3, 0.8), window=10.0):
    model, env, _ = readme_line()
    part = statistics_part((window,), [damped(model, ratio) for ratio in ratios])
    for record in part["records"]:
        record["damping_ratio"] = ratios[record.pop("model")]
    return part


def statistics_part(windows=WINDOWS, models=None):
    """Each statistic over each window [0, t] by `jax.grad`, judged by
    `jc.check_derivative`; on the README's line, or on each of `models` (its water)."""
    line, env, _ = readme_line()
    records = []
    for index, model in enumerate([line] if models is None else models):
        start = jc.solve_statics(model, env).state
        records += _statistics(model, env, start, windows, index)
    return {"records": records}


def _statistics(model, env, start, windows, index):
    records = []
    for window in windows:
        ts = jnp.linspace(0.0, window, int(round(window / 0.05)) + 1)
        for name, statistic in STATISTICS.items():

            def f(change, statistic=statistic, ts=ts, window=window):
                r = jc.simulate(lengthened(model, change), env, t1=window, ts=ts, initial=start)
                return statistic(r.tension[:, -1])

            began = time.perf_counter()
            check = jc.check_derivative(f, 0.0, steps=[0.2 * 10.0**-k for k in range(6)], warn=False)
            records.append(
                {
                    "window": window,
                    "statistic": name,
                    "value": check.value,
                    "derivative": check.derivative,
                    "steps": list(check.steps),
                    "differences": list(check.differences),
                    "reference": check.reference,
                    "verdict": check.verdict,
                    "seconds": time.perf_counter() - began,
                    "model": index,
                }
            )
            print(f"model {index}, [0, {window:g}] s, {name}: {check.verdict}", flush=True)
    return records


def report(session):
    for key, what in (("tangent", "the README's line"), ("jumper", "the Low & Langley jumper")):
        if key not in session:
            continue
        part = session[key]
        steps = list(part["rows"][0]["differences"])
        print(f"The tangent against time on {what} (fixed Dopri5 steps of {part['dt']:g} s), d/d(segment length):\n")
        head = ["t (s)", "top T (N)", "least T (N)", "max abs dx/dl", "dT/dl, tangent", *(f"CD h={h}" for h in steps)]
        print("| " + " | ".join(head) + " |")
        print("|---" * (5 + len(steps)) + "|")
        for r in part["rows"]:
            cells = [f"{r['t']:.2f}", f"{r['top_tension']:.4g}", f"{r['lowest_tension']:.3g}"]
            cells += [f"{r['max_position_tangent']:.3g}", f"{r['tension_tangent']:.4g}"]
            cells += [f"{r['differences'][h]:.4g}" for h in steps]
            print("| " + " | ".join(cells) + " |")
    if "damping" in session:
        records = session["damping"]["records"]
        print("\nStatistics of the top tension over [0, 10] s with axial damping of ratio ζ (MoorDyn's BA = −ζ),")
        print("jax.grad against central differences (h = 0.2 ... 2e-6 m), and the statistic against ζ = 0:\n")
        head = ["ζ", "statistic", "value (N)", "change from ζ = 0", "derivative (N/m)", "settled difference (N/m)"]
        print("| " + " | ".join([*head, "verdict"]) + " |")
        print("|---|---|---|---|---|---|---|")
        undamped = {r["statistic"]: r["value"] for r in records if r["damping_ratio"] == 0}
        for r in records:
            reference = "none" if r["reference"] is None else f"{r['reference']:.4g}"
            change = r["value"] / undamped[r["statistic"]] - 1 if r["statistic"] in undamped else float("nan")
            cells = [f"{r['damping_ratio']:g}", r["statistic"], f"{r['value']:.6g}", f"{change:+.2%}"]
            cells += [f"{r['derivative']:.4g}", reference, r["verdict"]]
            print("| " + " | ".join(cells) + " |")
    if "statistics" in session:
        print("\nStatistics of the top tension over [0, t], jax.grad against central differences", end="")
        print(" (h = 0.2 ... 2e-6 m):\n")
        print("| window | statistic | derivative (N/m) | settled difference (N/m) | verdict |")
        print("|---|---|---|---|---|")
        for r in session["statistics"]["records"]:
            reference = "none" if r["reference"] is None else f"{r['reference']:.4g}"
            cells = [f"[0, {r['window']:g}] s", r["statistic"], f"{r['derivative']:.4g}", reference, r["verdict"]]
            print("| " + " | ".join(cells) + " |")


def main():
    parser = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    parser.add_argument("--part", choices=("tangent", "jumper", "statistics", "damping", "both"), default="both")
    parser.add_argument("--report", action="store_true", help="print the latest session's tables and stop")
    args = parser.parse_args()
    if args.report:
        report(json.loads(RESULTS.read_text())[-1])
        return
    session = {}
    began = time.perf_counter()
    if args.part in ("tangent", "both"):
        session["tangent"] = tangent_part()
    if args.part == "jumper":
        session["jumper"] = jumper_part()
    if args.part in ("statistics", "both"):
        session["statistics"] = statistics_part()
    if args.part == "damping":
        session["damping"] = damping_part()
    session["seconds"] = time.perf_counter() - began
    append_session(RESULTS, **session)
    report(session)


if __name__ == "__main__":
    main()
