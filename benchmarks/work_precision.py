"""Work-precision diagrams: tension error against a tight reference, over run time
after compilation, for many integrators on four scenes; and error against segment count.

Scenes (each run starts from static equilibrium; output at 20 Hz):

- `anchored_line_taut`: the anchored line (`jaxcable.examples.anchored_line`), N = 20,
  lumped mass, its top motion's amplitude scaled to a quarter (1.573 → 0.393 m at
  5.6 s), so the line stays taut; 6 s.
- `anchored_line_slack`: the same line at the anchored-line paper's amplitude (1.573 m): it goes slack and
  snaps; 6 s. Also consistent against lumped mass, for Dopri5 and Kvaerno5 (Newton).
- `y_branch`: the bundled branched scene `jaxcable/examples/scenes/y_branch.toml`
  (26 segments, lumped); 7 s, one heave period.
- `jumper`: the Low & Langley (2006) jumper from its MoorDyn file (68 segments,
  EA = 5e8 N, lumped), its top driven along x as in `lowe_langley.py` case 1
  (A = 10 m, T = 27 s, smoothstep ramp over the first period); the first 10 s.
- `segments`: the anchored line with slack, N = 5 ... 80, Dopri5 at one tight tolerance; the top
  segment's tension history against the finest N's.

Error: every segment's tension at the 20 Hz output times against a reference of the
same model and mass matrix (Dopri8 at rtol = atol = 1e-11 by default), as the largest
and the RMS difference, both relative to the reference's peak tension; the same for the
top (driven) segment alone. The reference is checked against a second one at 10×
tighter tolerance: that difference is the reference's own error floor.

Methods: adaptive ones over rtol = atol (1e-3 ... 1e-8), fixed-step ones (diffrax's
Heun and Midpoint, the RK2 MoorDyn uses, and Zhukov's Picard iteration) over steps
dt = c / |λ|, c = 2 ... 1/16, |λ| the fastest axial eigenvalue (ω_n = 2 √(EA/m) / l, or
larger where the axial damping is over critical; `jaxcable.equations.stiffest_axial_mode`).
A method's sweep stops when a run took more than a third of `--time-cap` (the next,
tighter one would likely exceed it); skipped points are recorded as such. Runs that fail
(more steps than `--max-steps`, or `--implicit-max-steps` for implicit methods; step
size collapse; a fixed step that diverges to non-finite states) are recorded with
`success = false`. Implicit methods use whatever Jacobian `jc.simulate` picks by default.

    python benchmarks/work_precision.py --scene anchored_line_taut      # one scene at a time
    python benchmarks/work_precision.py --scene jumper --duration 5 --tolerances 1e-4 1e-6 \\
        --methods dopri5 kvaerno5-newton
    python benchmarks/work_precision.py --plot anchored_line_slack      # a chart from the results file
    python benchmarks/work_precision.py --report                  # the tables in benchmarks/README.md

Results are appended to benchmarks/results/work_precision.json, one session per scene;
charts go to benchmarks/results/work_precision_<scene>.png.
"""

import argparse
import dataclasses
import inspect
import json
import os
import statistics
import time
from pathlib import Path

import diffrax
import equinox as eqx
import jax
import numpy as np
from _results import append_session
from _timing import timed

import jaxcable as jc
from jaxcable.equations import stiffest_axial_mode
from jaxcable.examples import anchored_line

jax.config.update("jax_enable_x64", True)  # jaxcable computes in float64 and leaves the switch to us

ROOT = Path(__file__).resolve().parents[1]
RESULTS = Path(__file__).resolve().parent / "results"
OUT = RESULTS / "work_precision.json"
JUMPER = ROOT / "tests" / "data" / "lowe_and_langley_2006" / "line.txt"
Y_BRANCH = ROOT / "jaxcable" / "examples" / "scenes" / "y_branch.toml"

SCENES = ("anchored_line_taut", "anchored_line_slack", "y_branch", "jumper")
DURATIONS = {"anchored_line_taut": 6.0, "anchored_line_slack": 6.0, "y_branch": 7.0, "jumper": 10.0, "segments": 6.0}
TAUT_AMPLITUDE_SCALE = 0.25


def kencarp(kind):
    """A KenCarp solver; whether `jc.simulate` can run it (an IMEX split) is tried, not assumed."""
    return lambda: kind()


# name: (solver factory, "adaptive" or "fixed", order). Orders decide nothing here; they
# are recorded for the reader.
METHODS = {
    "dopri5": (diffrax.Dopri5, "adaptive", 5),
    "tsit5": (diffrax.Tsit5, "adaptive", 5),
    "kvaerno3": (diffrax.Kvaerno3, "adaptive", 3),
    "kvaerno4": (diffrax.Kvaerno4, "adaptive", 4),
    "kvaerno5-verychord": (diffrax.Kvaerno5, "adaptive", 5),
    "kvaerno5-newton": (jc.stiff_solver, "adaptive", 5),
    "implicit-euler": (diffrax.ImplicitEuler, "adaptive", 1),
    "kencarp3": (kencarp(diffrax.KenCarp3), "adaptive", 3),
    "kencarp4": (kencarp(diffrax.KenCarp4), "adaptive", 4),
    "kencarp5": (kencarp(diffrax.KenCarp5), "adaptive", 5),
    "picard3": (lambda: jc.PicardTrapezoid(iterations=3), "adaptive", 2),
    "heun-fixed": (diffrax.Heun, "fixed", 2),
    "midpoint-fixed": (diffrax.Midpoint, "fixed", 2),
    "picard3-fixed": (lambda: jc.PicardTrapezoid(iterations=3), "fixed", 2),
}
DEFAULT_METHODS = [m for m in METHODS if m != "picard3-fixed"]  # to fit the study's time
# Consistent mass against lumped, on the anchored line with slack: one explicit, one implicit.
CONSISTENT_METHODS = ("dopri5", "kvaerno5-newton")
TOLERANCES = (1e-3, 1e-4, 1e-5, 1e-6, 1e-7, 1e-8)
STEP_FACTORS = (2.0, 1.0, 0.5, 0.25, 0.125, 0.0625)  # |λ| dt, |λ| the fastest axial eigenvalue


def build(scene: str, segments: int = 20, mass_matrix: str = "lumped"):
    """`(model, env, top)` for a scene: the network, the water, and the index of the
    driven (top) segment."""
    if scene.startswith("anchored_line") or scene == "segments":
        model, env = anchored_line(segments, mass_matrix=mass_matrix)
        if scene == "anchored_line_taut":
            model = eqx.tree_at(
                lambda m: m.motions[1].amplitude, model, model.motions[1].amplitude * TAUT_AMPLITUDE_SCALE
            )
        return model, env, segments - 1  # the fairlead is the branch's end B
    if scene == "y_branch":
        built = jc.load_scene(Y_BRANCH).build()
        return built.model, built.environment, int(built.line_segments[2][-1])  # riser at the surface buoy
    if scene == "jumper":
        source = jc.load_scene(JUMPER)
        points = list(source.points)
        top = next(k for k, p in enumerate(points) if p.kind == "coupled")
        # lowe_langley.py case 1: A sin(2πt/T) along x with the smoothstep ramp over one period.
        points[top] = dataclasses.replace(
            points[top], motion=jc.Harmonic(10.0, 27.0, direction=(1.0, 0.0, 0.0), ramp=27.0)
        )
        built = source.replace(points=tuple(points)).build()
        return built.model, built.environment, int(built.line_segments[0][-1])
    raise ValueError(scene)


def simulate_kwargs() -> dict:
    """Options of `jc.simulate` this library version has, recorded with the results."""
    return {"jacobian": "auto"} if "jacobian" in inspect.signature(jc.simulate).parameters else {}


def errors(tension: np.ndarray, reference: np.ndarray, top: int) -> dict:
    """Largest and RMS tension difference (all segments; top segment) relative to the
    reference's peak tension (–)."""
    peak = float(np.max(reference))
    diff = tension - reference
    top_diff = diff[:, top]
    return {
        "max_err": float(np.max(np.abs(diff)) / peak),
        "rms_err": float(np.sqrt(np.mean(diff**2)) / peak),
        "top_max_err": float(np.max(np.abs(top_diff)) / peak),
        "top_rms_err": float(np.sqrt(np.mean(top_diff**2)) / peak),
    }


def warm_time(run, repeats: int, slow: float = 1.0) -> float:
    """Median wall time (s) of up to `repeats` warm calls; one if the first took over
    `slow` s (on a shared machine a second long run adds little)."""
    import jax

    times = []
    for _ in range(repeats):
        start = time.perf_counter()
        jax.block_until_ready(run())
        times.append(time.perf_counter() - start)
        if times[-1] > slow:
            break
    return statistics.median(times)


def reference(model, env, initial, duration, ts, tol, max_steps):
    """A Dopri8 solve at rtol = atol = `tol`, with its wall time (s), compilation included."""
    start = time.perf_counter()
    config = jc.SolverConfig(diffrax.Dopri8(), rtol=tol, atol=tol, max_steps=max_steps)
    r = jc.simulate(model, env, duration, ts=ts, initial=initial, solver=config, throw=False)
    tension = np.asarray(r.tension)
    return r, tension, time.perf_counter() - start


def run_scene(scene: str, args) -> dict:
    """Every method's sweep on one scene; the session written to the results file."""
    import jax

    duration = args.duration or DURATIONS[scene]
    ts = np.linspace(0.0, duration, int(round(duration * 20)) + 1)  # 20 Hz output
    masses = ["lumped"] + (["consistent"] if scene == "anchored_line_slack" and not args.no_consistent else [])
    extra = simulate_kwargs()
    session = {
        "scene": scene,
        "duration_s": duration,
        "output_hz": 20,
        "simulate_options": extra,
        "structured_jacobian_module": (ROOT / "jaxcable" / "_jacobian.py").exists(),
        "load_before": os.getloadavg(),
        "references": {},
        "records": [],
    }
    for mass in masses:
        model, env, top = build(scene, mass_matrix=mass)
        # The fixed steps scale with the fastest axial eigenvalue |λ| (damping included;
        # = ω_n where the axial damping is under critical), which bounds an explicit step.
        omega, fastest, _ = stiffest_axial_mode(model, env)
        static = jc.solve_statics(model, env.without_waves())
        initial = static.state
        ref, ref_t, ref_s = reference(model, env, initial, duration, ts, args.reference_tol, args.max_steps)
        check, check_t, check_s = reference(model, env, initial, duration, ts, args.reference_tol / 10, args.max_steps)
        floor = errors(ref_t, check_t, top)
        session["references"][mass] = {
            "solver": "dopri8",
            "tol": args.reference_tol,
            "steps": int(ref.stats["num_steps"]),
            "success": bool(ref.success),
            "wall_s": ref_s,
            "check_tol": args.reference_tol / 10,
            "check_steps": int(check.stats["num_steps"]),
            "check_success": bool(check.success),
            "check_wall_s": check_s,
            "floor": floor,
            "omega_n_rad_s": omega,
            "fastest_rad_s": fastest,
            "peak_tension_N": float(ref_t.max()),
            "min_tension_N": float(ref_t.min()),
            "top_min_tension_N": float(ref_t[:, top].min()),
            "top_peak_tension_N": float(ref_t[:, top].max()),
            "segments": int(model.segment_length.shape[0]),
        }
        print(f"[{scene}/{mass}] reference:", json.dumps(session["references"][mass]), flush=True)
        jax.clear_caches()
        names = args.methods if mass == "lumped" else [m for m in CONSISTENT_METHODS if m in args.methods]
        for name in names:
            factory, kind, order = METHODS[name]
            solver = factory()
            if kind == "adaptive":
                points = [("tol", tol) for tol in args.tolerances]
            else:
                points = [("dt", c / fastest) for c in args.step_factors]
            # An implicit step costs tens of ms here: fewer steps allowed, so a run that would
            # take minutes fails instead.
            implicit = isinstance(solver, diffrax.AbstractImplicitSolver)
            max_steps = args.implicit_max_steps if implicit else args.max_steps
            stop = None
            for i, (what, value) in enumerate(points):
                record = {
                    "method": name,
                    "mass": mass,
                    "kind": kind,
                    "order": order,
                    "implicit": implicit,
                    "max_steps": max_steps,
                    what: value,
                }
                if kind == "fixed":
                    record["lambda_dt"] = value * fastest
                if stop:
                    record.update(skipped=stop)
                    session["records"].append(record)
                    print(json.dumps(record), flush=True)
                    continue

                def run(value=value):
                    if kind == "adaptive":
                        config = jc.SolverConfig(solver, rtol=value, atol=value, max_steps=max_steps)
                    else:
                        config = jc.SolverConfig(
                            solver, dt0=value, stepsize_controller=diffrax.ConstantStepSize(), max_steps=args.max_steps
                        )
                    return jc.simulate(
                        model, env, duration, ts=ts, initial=initial, solver=config, throw=False, **extra
                    )

                try:
                    if i == 0:
                        # The first point compiles; later ones reuse the program (tolerances and dt are data).
                        result, compile_s, run_s = timed(run, 1)
                        if run_s < 1.0 and args.repeats > 1:
                            run_s = warm_time(run, args.repeats)
                        record["compile_s"] = compile_s
                    else:
                        result = run()
                        run_s = warm_time(run, args.repeats)
                except Exception as error:  # noqa: BLE001 - an unsupported method is a finding, not a crash
                    record.update(error=f"{type(error).__name__}: {str(error).splitlines()[0][:300]}")
                    stop = "method raised on the first point" if i == 0 else "method raised"
                    session["records"].append(record)
                    print(json.dumps(record), flush=True)
                    continue
                tension = np.asarray(result.tension)
                # An unstable fixed step ends in inf/NaN states without a diffrax failure.
                diverged = bool(result.success) and not np.all(np.isfinite(tension))
                record.update(
                    success=bool(result.success) and not diverged,
                    diverged=diverged,
                    steps=int(result.stats["num_steps"]),
                    rejected=int(result.stats["num_rejected_steps"]),
                    run_s=run_s,
                    load=os.getloadavg()[0],
                )
                if record["success"]:
                    record.update(errors(tension, ref_t, top))
                else:
                    record["result"] = str(result.result)
                session["records"].append(record)
                print(json.dumps(record), flush=True)
                if run_s > args.time_cap / 3:
                    stop = f"previous run took {run_s:.1f} s, over a third of the {args.time_cap:.0f} s cap"
                elif not result.success and result.result == diffrax.RESULTS.max_steps_reached:
                    stop = "previous run reached max_steps"
            jax.clear_caches()
    session["load_after"] = os.getloadavg()
    append_session(args.out, **session)
    plot_scene(scene, args.out)
    return session


def run_segments(args) -> dict:
    """The anchored line with slack at N segments, Dopri5 at one tolerance, against the finest N."""
    import jax

    duration = args.duration or DURATIONS["segments"]
    ts = np.linspace(0.0, duration, int(round(duration * 20)) + 1)
    records = []
    histories = {}
    load_before = os.getloadavg()
    for n in sorted(args.segment_counts):
        model, env, top = build("segments", n)
        static = jc.solve_statics(model, env)

        def run():
            tol = args.segments_tol
            config = jc.SolverConfig(diffrax.Dopri5(), rtol=tol, atol=tol, max_steps=args.max_steps)
            return jc.simulate(model, env, duration, ts=ts, initial=static.state, solver=config, throw=False)

        result, compile_s, run_s = timed(run, 1)
        tension = np.asarray(result.tension)
        histories[n] = tension[:, top]
        records.append(
            {
                "segments": n,
                "success": bool(result.success),
                "steps": int(result.stats["num_steps"]),
                "rejected": int(result.stats["num_rejected_steps"]),
                "compile_s": compile_s,
                "run_s": run_s,
                "omega_n_rad_s": stiffest_axial_mode(model, env)[0],
                "load": os.getloadavg()[0],
                "top_peak_tension_N": float(histories[n].max()),
                "static_top_tension_N": float(static.tension[top]),
            }
        )
        print(json.dumps(records[-1]), flush=True)
        jax.clear_caches()
    finest = max(histories)
    fine = histories[finest]
    for r in records:
        h = histories[r["segments"]]
        r["top_peak_rel_err"] = float(abs(h.max() - fine.max()) / fine.max())
        r["top_rms_rel_err"] = float(np.sqrt(np.mean((h - fine) ** 2)) / fine.max())
        r["top_max_rel_err"] = float(np.max(np.abs(h - fine)) / fine.max())
    session = {
        "scene": "segments",
        "duration_s": duration,
        "output_hz": 20,
        "solver": "dopri5",
        "tol": args.segments_tol,
        "finest_segments": finest,
        "load_before": load_before,
        "load_after": os.getloadavg(),
        "records": records,
    }
    append_session(args.out, **session)
    plot_segments(args.out)
    return session


def latest(path: Path, scene: str) -> dict | None:
    """A scene's newest session, with the methods of later sessions that ran only some
    methods (`--methods ...`) merged in: theirs replace its records of the same method and
    mass. Each record's error is against its own session's reference."""
    sessions = [s for s in json.loads(Path(path).read_text()) if s.get("scene") == scene]
    if not sessions:
        return None
    if scene == "segments":
        return sessions[-1]
    full = [i for i, s in enumerate(sessions) if any(r["method"] == "dopri5" for r in s["records"])]
    base = full[-1] if full else len(sessions) - 1
    merged = dict(sessions[base], supplements=[])
    records = list(merged["records"])
    for later in sessions[base + 1 :]:
        keys = {(r["method"], r["mass"]) for r in later["records"]}
        records = [r for r in records if (r["method"], r["mass"]) not in keys] + later["records"]
        merged["supplements"].append(
            {
                "commit": later["commit"],
                "time": later["time"],
                "methods": sorted({k[0] for k in keys}),
                "load_before": later["load_before"],
                "load_after": later["load_after"],
                "references": later["references"],
            }
        )
    merged["records"] = records
    return merged


def colour(method: str):
    """One colour per method, the same on every chart."""
    import matplotlib

    return matplotlib.colormaps["tab20"](list(METHODS).index(method) % 20)


def plot_scene(scene: str, path: Path) -> None:
    """Error over run time, log-log: largest (left) and RMS (right) error relative to
    the peak tension, one line per method (dashed: consistent mass)."""
    import matplotlib

    matplotlib.use("Agg")
    import matplotlib.pyplot as plt

    session = latest(path, scene)
    figure, axes = plt.subplots(1, 2, figsize=(13, 5.2), layout="constrained")
    markers = "os^vD<>pPX*hH8d"
    keys = list(dict.fromkeys((r["method"], r["mass"]) for r in session["records"]))
    for k, (method, mass) in enumerate(keys):
        points = [
            r
            for r in session["records"]
            if r["method"] == method and r["mass"] == mass and r.get("success") and r.get("max_err") is not None
        ]
        if not points:
            continue
        for axis, field in zip(axes, ("max_err", "rms_err")):
            axis.loglog(
                [r["run_s"] for r in points],
                [max(r[field], 1e-16) for r in points],
                marker=markers[k % len(markers)],
                linestyle="--" if mass == "consistent" else "-",
                label=method + (" (consistent)" if mass == "consistent" else ""),
                color=colour(method),
            )
    for mass, ref in session["references"].items():
        for axis, field in zip(axes, ("max_err", "rms_err")):
            axis.axhline(
                max(ref["floor"][field], 1e-16),
                color="grey",
                linewidth=0.8,
                linestyle="--" if mass == "consistent" else ":",
            )
    titles = ("largest tension error / peak tension", "RMS tension error / peak tension")
    for axis, title in zip(axes, titles):
        axis.set_xlabel("run time after compilation (s)")
        axis.set_ylabel(title)
        axis.grid(True, which="major", alpha=0.3)
    axes[1].legend(fontsize=8, ncol=2)
    load = session["load_before"][0]
    figure.suptitle(
        f"{scene}: {session['duration_s']:g} s simulated, all segments at 20 Hz, against Dopri8 at "
        f"{session['references']['lumped']['tol']:g} (grey: reference's own error); "
        f"shared 2-core CPU, load {load:.1f}",
        fontsize=10,
    )
    figure.savefig(RESULTS / f"work_precision_{scene}.png", dpi=110)
    plt.close(figure)


def plot_segments(path: Path) -> None:
    """Top-tension error against the finest N (left) and wall time (right) against N."""
    import matplotlib

    matplotlib.use("Agg")
    import matplotlib.pyplot as plt

    session = latest(path, "segments")
    records = [r for r in session["records"] if r["segments"] != session["finest_segments"]]
    n = [r["segments"] for r in records]
    figure, (left, right) = plt.subplots(1, 2, figsize=(11, 4.2), layout="constrained")
    left.loglog(n, [r["top_peak_rel_err"] for r in records], "o-", label="peak top tension")
    left.loglog(n, [r["top_rms_rel_err"] for r in records], "s-", label="RMS of the top tension history")
    left.set_xlabel("segments N")
    left.set_ylabel(f"difference from N = {session['finest_segments']}, / its peak")
    left.legend()
    everything = session["records"]
    right.loglog([r["segments"] for r in everything], [r["run_s"] for r in everything], "o-", label="run")
    right.loglog(
        [r["segments"] for r in everything], [max(r["compile_s"], 1e-3) for r in everything], "s--", label="compile"
    )
    right.set_xlabel("segments N")
    right.set_ylabel("wall time (s)")
    right.legend()
    for axis in (left, right):
        axis.grid(True, which="major", alpha=0.3)
        axis.set_xticks([r["segments"] for r in everything], [str(r["segments"]) for r in everything])
        axis.minorticks_off()
    figure.suptitle(
        f"the anchored line with slack, Dopri5 at rtol = atol = {session['tol']:g}, "
        f"{session['duration_s']:g} s simulated; load {session['load_before'][0]:.1f}",
        fontsize=10,
    )
    figure.savefig(RESULTS / "work_precision_segments.png", dpi=110)
    plt.close(figure)


LEVELS = (1e-1, 1e-2, 1e-3, 1e-4)


def short(result: str) -> str:
    """diffrax's failure message in a few words."""
    if "maximum number of solver steps" in result:
        return "max_steps reached"
    if "nonlinear solver" in result:
        return "root finder did not converge"
    return result


def report(path: Path, everything: bool) -> None:
    """Per scene: the reference, then per method the least run time (s) among runs whose
    largest error is within each level; with `everything`, every point."""
    for scene in SCENES:
        session = latest(path, scene)
        if session is None:
            continue
        print(
            f"\n#### {scene}: {session['duration_s']:g} s simulated (load average {session['load_before'][0]:.2f} "
            f"before, {session['load_after'][0]:.2f} after; {session['commit']})\n"
        )
        for extra in session.get("supplements", []):
            ref = extra["references"].get("lumped", {})
            print(
                f"- {', '.join(extra['methods'])}: run later ({extra['commit']}, {extra['time']}; load average "
                f"{extra['load_before'][0]:.2f} before, {extra['load_after'][0]:.2f} after) against their own "
                f"reference, {ref.get('steps')} steps, largest difference from the 1e-12 check "
                f"{ref.get('floor', {}).get('max_err', float('nan')):.1e}"
            )
        for mass, ref in session["references"].items():
            print(
                f"- reference ({mass}, N = {ref['segments']}, ω_n = {ref['omega_n_rad_s']:.0f} rad/s): Dopri8 at "
                f"{ref['tol']:g}, {ref['steps']} steps, {ref['wall_s']:.1f} s; against {ref['check_tol']:g}: largest "
                f"{ref['floor']['max_err']:.1e}, RMS {ref['floor']['rms_err']:.1e} of the peak "
                f"{ref['peak_tension_N'] / 1e3:.1f} kN; least tension {ref['min_tension_N'] / 1e3:.2f} kN "
                f"(top segment {ref['top_min_tension_N'] / 1e3:.2f} kN)"
            )
        print()
        header = " | ".join(f"≤ {level:g}" for level in LEVELS)
        print(
            f"| method | mass | compile (s) | {header} | tightest run: tol or &#124;λ&#124; dt, steps (rejected), run "
            "(s), "
            "largest / RMS err |"
        )
        print("|---|---|---|" + "---|" * len(LEVELS) + "---|")
        keys = list(dict.fromkeys((r["method"], r["mass"]) for r in session["records"]))
        for method, mass in keys:
            rows = [r for r in session["records"] if r["method"] == method and r["mass"] == mass]
            ok = [r for r in rows if r.get("success") and "max_err" in r]
            errs = [r for r in rows if "error" in r]
            compile_s = next((f"{r['compile_s']:.1f}" for r in rows if "compile_s" in r), "–")
            if errs and not ok:
                print(f"| {method} | {mass} | – | " + "– | " * len(LEVELS) + f"not run: {errs[0]['error'][:120]} |")
                continue
            cells = []
            for level in LEVELS:
                within = [r["run_s"] for r in ok if r["max_err"] <= level]
                cells.append(f"{min(within):.2f}" if within else "–")
            ran = [r for r in rows if "run_s" in r]
            last = ran[-1] if ran else None
            if last is None:
                tail = "–"
            else:
                where = f"{last['tol']:g}" if "tol" in last else f"{last.get('lambda_dt', last.get('omega_dt')):.3g}"
                err = (
                    f"{last['max_err']:.1e} / {last['rms_err']:.1e}"
                    if "max_err" in last
                    else "diverged"
                    if last.get("diverged")
                    else f"failed: {short(last.get('result', ''))}"
                )
                tail = f"{where}, {last['steps']} ({last['rejected']}), {last['run_s']:.2f}, {err}"
            failed = sum(1 for r in rows if r.get("success") is False and not r.get("diverged"))
            diverged = sum(1 for r in rows if r.get("diverged"))
            skipped = sum(1 for r in rows if "skipped" in r)
            notes = (
                (f"; {failed} failed" if failed else "")
                + (f"; {diverged} diverged" if diverged else "")
                + (f"; {skipped} skipped (time cap)" if skipped else "")
            )
            print(f"| {method} | {mass} | {compile_s} | " + " | ".join(cells) + f" | {tail}{notes} |")
        if everything:
            print(
                "\n| method | mass | tol or &#124;λ&#124; dt | steps (rejected) | run (s) | largest err | RMS err | "
                "top largest "
                "| top RMS | note |"
            )
            print("|---|---|---|---|---|---|---|---|---|---|")
            for r in session["records"]:
                where = f"{r['tol']:g}" if "tol" in r else f"{r.get('lambda_dt', r.get('omega_dt')):.3g}"
                if "run_s" not in r:
                    print(
                        f"| {r['method']} | {r['mass']} | {where} | – | – | – | – | – | – | "
                        f"{r.get('skipped') or r.get('error', '')[:80]} |"
                    )
                    continue
                e = [f"{r[k]:.2e}" if k in r else "–" for k in ("max_err", "rms_err", "top_max_err", "top_rms_err")]
                note = (
                    ""
                    if r["success"]
                    else "diverged (non-finite tension)"
                    if r.get("diverged")
                    else f"failed: {short(r.get('result', ''))}"
                )
                print(
                    f"| {r['method']} | {r['mass']} | {where} | {r['steps']} ({r['rejected']}) | {r['run_s']:.2f} | "
                    + " | ".join(e)
                    + f" | {note} |"
                )
    session = latest(path, "segments")
    if session is not None:
        print(
            f"\n#### segments: the anchored line with slack, Dopri5 at {session['tol']:g}, {session['duration_s']:g} s "
            f"(load average {session['load_before'][0]:.2f} before, {session['load_after'][0]:.2f} after; "
            f"{session['commit']})\n"
        )
        print(
            f"| N | ω_n (rad/s) | steps (rejected) | compile (s) | run (s) | peak top T (kN) | peak err vs "
            f"N = {session['finest_segments']} | RMS err | largest err |"
        )
        print("|---|---|---|---|---|---|---|---|---|")
        for r in session["records"]:
            print(
                f"| {r['segments']} | {r['omega_n_rad_s']:.0f} | {r['steps']} ({r['rejected']}) | "
                f"{r['compile_s']:.1f} | {r['run_s']:.2f} | {r['top_peak_tension_N'] / 1e3:.1f} | "
                f"{100 * r['top_peak_rel_err']:.2f} % | {100 * r['top_rms_rel_err']:.2f} % | "
                f"{100 * r['top_max_rel_err']:.1f} % |"
            )


def main() -> None:
    parser = argparse.ArgumentParser(description=__doc__, formatter_class=argparse.RawDescriptionHelpFormatter)
    parser.add_argument("--scene", nargs="+", default=[], choices=[*SCENES, "segments"])
    parser.add_argument("--duration", type=float, default=None, help="simulated time (s); per scene by default")
    parser.add_argument("--methods", nargs="+", default=DEFAULT_METHODS, choices=list(METHODS))
    parser.add_argument("--tolerances", type=float, nargs="+", default=list(TOLERANCES))
    parser.add_argument(
        "--step-factors",
        type=float,
        nargs="+",
        default=list(STEP_FACTORS),
        help="fixed steps as |λ| dt, |λ| the fastest axial eigenvalue",
    )
    parser.add_argument("--reference-tol", type=float, default=1e-11)
    parser.add_argument("--repeats", type=int, default=3, help="warm runs timed (one if a run takes over 2 s)")
    parser.add_argument("--time-cap", type=float, default=30.0, help="a run's time (s) that ends its method's sweep")
    parser.add_argument("--max-steps", type=int, default=300_000)
    parser.add_argument("--implicit-max-steps", type=int, default=5_000)
    parser.add_argument("--no-consistent", action="store_true", help="skip consistent mass on anchored_line_slack")
    parser.add_argument("--segment-counts", type=int, nargs="+", default=[5, 10, 20, 40, 80])
    parser.add_argument("--segments-tol", type=float, default=1e-8)
    parser.add_argument("--out", type=Path, default=OUT)
    parser.add_argument(
        "--plot", nargs="+", default=[], choices=[*SCENES, "segments"], help="redraw charts from the results file"
    )
    parser.add_argument("--report", action="store_true", help="print the markdown tables from the results file")
    parser.add_argument("--all", action="store_true", help="with --report: every point too")
    args = parser.parse_args()
    if args.report:
        report(args.out, args.all)
        return
    for scene in args.plot:
        plot_segments(args.out) if scene == "segments" else plot_scene(scene, args.out)
    for scene in args.scene:
        run_segments(args) if scene == "segments" else run_scene(scene, args)


if __name__ == "__main__":
    main()
