"""Where each integration method fails: the largest stable fixed step, and how it fails.

The anchored line (lumped mass; see `jaxcable.examples.anchored_line`) is simulated
from static equilibrium over a window of `--window` seconds (6 s by default), which holds
the violent part of the first wave period: the line goes slack at about 3 s and snaps
taut again at about 5 s (at C_E = 3e7 N, N = 20). For each method, the largest fixed
step that survives the window is found by bracketing (doubling or halving from a guess)
and then bisecting in log space until the bracket is narrower than `--ratio`.

A run with step dt *fails*, in this order of precedence, when:

1. diffrax's result is not `successful` (the mode is diffrax's code, e.g.
   `nonlinear_max_steps_reached` when the Newton iteration of an implicit step does not
   converge);
2. a position, velocity or tension at an output time is not finite (`non-finite`: with
   `ConstantStepSize` diffrax reports success even then, so the check is ours);
3. the total energy K + Π strays from its initial value by more than `--energy-factor`
   (10) times the most the reference ever strays (`energy blow-up`);
4. the peak tension exceeds `--tension-factor` (3) times the reference's (`tension blow-up`).

The reference is Dopri5 with an adaptive step at rtol = atol = 1e-8 on the same
configuration. Every run also records its peak-tension error against the reference, and a
second bisection finds the largest step whose peak tension is within `--accuracy` (5 %)
of the reference's (the largest *accurate* step), so that a method's limit can be read as
stability, Newton convergence or accuracy.

Three axes of study:

- **stiffness**: C_E = EA × segment count N, i.e. ω_n = 2 √(EA / m') / l with l = L/N and
  m' = m + ρ F C_aτ the mass per length the axial mode carries (3.4 kg/m);
- **slack**: the slack switch's smoothing width, down to 0 (the sharp Heaviside), at fixed
  EA and N (`--study-segments`);
- **forcing**: the fairlead amplitude scaled 0.25–2×, and a uniform current along +x.

On the slack and forcing axes the adaptive defaults (`jaxcable.default_solver`, Dopri5,
and `jaxcable.stiff_solver`, Kvaerno5 + Newton) also run at rtol = atol = 1e-6; their step
counts, rejected steps and result are recorded.

Implicit methods take a Newton root finder with its own tolerances (rtol = atol = 1e-8,
diffrax's default of 10 iterations): a fixed step has no adaptive controller to lend them.

    python benchmarks/stability.py                 # the study (33 min on 2 cores at load average 13-17)
    python benchmarks/stability.py --quick         # a tiny run, to check the script
    python benchmarks/stability.py --report        # tables of the latest session
    python benchmarks/stability.py --summary       # compact tables, as in benchmarks/README.md
    python benchmarks/stability.py --plot          # charts of the latest session

Results are appended to benchmarks/results/stability.json; charts go to
benchmarks/results/stability_*.png.
"""

import argparse
import json
import math
import os
import time
from pathlib import Path

import diffrax
import equinox as eqx
import jax
import jax.numpy as jnp
import numpy as np
import optimistix as optx
from _results import append_session

import jaxcable as jc
from jaxcable.equations import kinetic_energy, potential_energy
from jaxcable.examples import anchored_line

jax.config.update("jax_enable_x64", True)  # jaxcable computes in float64 and leaves the switch to us

RESULTS = Path(__file__).parent / "results"


def _newton():
    # A fixed step has no adaptive controller whose tolerances the root finder could
    # borrow, so it gets its own.
    return optx.Newton(rtol=1e-8, atol=1e-8)


METHODS = {
    # name: (factory, kind)
    "heun": (diffrax.Heun, "explicit"),
    "midpoint": (diffrax.Midpoint, "explicit"),
    "tsit5": (diffrax.Tsit5, "explicit"),
    "dopri5": (diffrax.Dopri5, "explicit"),
    "picard3": (lambda: jc.PicardTrapezoid(iterations=3), "explicit"),
    "implicit-euler": (lambda: diffrax.ImplicitEuler(root_finder=_newton()), "implicit"),
    "kvaerno3": (lambda: diffrax.Kvaerno3(root_finder=_newton()), "implicit"),
    "kvaerno4": (lambda: diffrax.Kvaerno4(root_finder=_newton()), "implicit"),
    "kvaerno5": (lambda: diffrax.Kvaerno5(root_finder=_newton()), "implicit"),
}

ADAPTIVE = {"dopri5 (default)": jc.default_solver, "kvaerno5 (stiff_solver)": jc.stiff_solver}

BASE_STIFFNESS = 3.0e7  # C_E of anchored_line (N)


def result_name(result) -> str:
    """The name of a diffrax result code, e.g. `"max_steps_reached"`."""
    for name, item in diffrax.RESULTS._name_to_item.items():
        if bool(result == item):
            return name
    return str(result)


def imaginary_axis_limit(solver, tol=1e-9, hi=6.0) -> float:
    """The largest y = ω dt (–) with |R(iy)| ≤ 1 near the origin for one step of `solver`.

    `tol` is the growth per step allowed: 1e-9 for the strict limit, 0.01 for the step at
    which an undamped mode grows by 1 % a step. R is measured, not looked up: one step of the
    solver on the undamped oscillator x' = ω v, v' = −ω x (eigenvalues ±iω) gives the step's
    amplification matrix, whose spectral radius is |R(iω dt)|. 0 where the region touches the
    imaginary axis only at the origin (as for every two-stage second-order Runge–Kutta method).
    """

    @jax.jit
    def radii(ys):
        def radius(y):
            def field(t, state, args):
                x, v = state
                return (y * v, -y * x)

            term = diffrax.ODETerm(field)

            def step(state):
                init = solver.init(term, 0.0, 1.0, state, None)
                return jnp.stack(solver.step(term, 0.0, 1.0, state, None, init, False)[0])

            one = jnp.ones_like(y)
            columns = jnp.stack([step((one, 0 * one)), step((0 * one, one))], axis=1)
            return jnp.max(jnp.abs(jnp.linalg.eigvals(columns)))

        return jax.vmap(radius)(ys)

    ys = np.linspace(1e-3, hi, 3001)
    stable = np.asarray(radii(jnp.asarray(ys))) <= 1 + tol
    if not stable[0]:
        return 0.0
    # Refine the first crossing on a finer grid.
    first = int(np.argmin(stable)) if not stable.all() else len(ys) - 1
    fine = np.linspace(ys[max(first - 1, 0)], ys[first], 2001)
    ok = np.asarray(radii(jnp.asarray(fine))) <= 1 + tol
    return float(fine[int(np.argmin(ok)) - 1] if not ok.all() else fine[-1])


def build(config):
    """The anchored line for one configuration, with its statics.

    `config` holds `stiffness` (C_E, N; C_E1 stays 0.1 C_E), `segments`, `slack_width`
    (–), `amplitude_scale` (–, on the anchored-line paper's 1.573 m) and `current` (m/s along +x).
    Returns `(model, env, static, omega_n)` with ω_n (rad/s) of the lumped line.
    """
    model, env = anchored_line(config["segments"], slack_width=config["slack_width"], mass_matrix="lumped")
    law = model.line.tension_law
    # Float leaves: a new stiffness or amplitude reuses the compiled solve.
    model = eqx.tree_at(
        lambda m: (m.line.tension_law.axial_stiffness, m.line.tension_law.quadratic_coefficient),
        model,
        (
            law.axial_stiffness * config["stiffness"] / BASE_STIFFNESS,
            law.quadratic_coefficient * config["stiffness"] / BASE_STIFFNESS,
        ),
    )
    model = eqx.tree_at(lambda m: m.motions[1].amplitude, model, model.motions[1].amplitude * config["amplitude_scale"])
    if config["current"]:
        env = jc.Environment(
            water_density=env.water_density, gravity=env.gravity, current=(config["current"], 0.0, 0.0)
        )
    static = jc.solve_statics(model, env)
    line = model.line
    # Per-segment arrays; the line is uniform, so every segment has the same ω_n.
    axial_mass = np.asarray(line.mass_per_length) + float(env.water_density) * np.asarray(line.area) * np.asarray(
        line.tangential_added_mass
    )
    stiffness = np.asarray(line.tension_law.axial_stiffness)
    length = np.asarray(model.segment_length)
    omega = float(np.max(2.0 / length * np.sqrt(stiffness / axial_mass)))
    return model, env, static, omega


@eqx.filter_jit
def total_energy(model, env, positions, velocities):
    """K + Π (J) at each output time."""
    return jax.vmap(lambda p, v: kinetic_energy(model, env, p, v) + potential_energy(model, env, p))(
        positions, velocities
    )


class Case:
    """One configuration: its model, statics, reference solve and the measures a run is
    judged against."""

    def __init__(self, config, window, ts):
        self.config = config
        self.model, self.env, self.static, self.omega = build(config)
        self.window, self.ts = window, ts
        start = time.perf_counter()
        tight = jc.SolverConfig(diffrax.Dopri5(), rtol=1e-8, atol=1e-8, max_steps=2_000_000)
        ref = jc.simulate(self.model, self.env, window, ts=ts, initial=self.static.state, solver=tight, throw=False)
        tension = np.asarray(ref.tension)
        self.reference_ok = bool(ref.success) and bool(np.isfinite(tension).all())
        self.reference = {
            "result": result_name(ref.result),
            "steps": int(ref.stats["num_steps"]),
            "rejected_steps": int(ref.stats["num_rejected_steps"]),
            "wall_s": time.perf_counter() - start,
            "peak_tension_N": float(np.nanmax(tension)),
            "static_top_tension_N": float(self.static.tension[-1]),
            # When the reference goes slack and how much of it: says whether the window
            # holds a slack/snap event for this configuration.
            "slack_segment_fraction": float(np.mean(tension <= 0.0)),
            "first_slack_s": float(ts[np.argmax((tension <= 0.0).any(axis=1))]) if (tension <= 0.0).any() else None,
        }
        energy = np.asarray(total_energy(self.model, self.env, ref.positions, ref.velocities))
        self.energy_excursion = float(np.max(np.abs(energy - energy[0])))
        self.reference["energy_excursion_J"] = self.energy_excursion
        self.peak = self.reference["peak_tension_N"]

    def judge(self, r, args):
        """Classify one run: `(ok, record)`, with the failure mode and the time it was
        first seen (s). NaNs never leave here: they become the `non-finite` mode."""
        code = result_name(r.result)
        positions, velocities, tension = (np.asarray(a) for a in (r.positions, r.velocities, r.tension))
        finite = (
            np.isfinite(positions).all(axis=(1, 2))
            & np.isfinite(velocities).all(axis=(1, 2))
            & np.isfinite(tension).all(axis=1)
        )
        energy = np.full(len(self.ts), np.inf)
        if finite.any():
            e = np.asarray(total_energy(self.model, self.env, r.positions, r.velocities))
            energy = np.where(finite, e, np.inf)
        excursion = np.abs(energy - energy[0]) if finite[0] else np.full(len(self.ts), np.inf)
        peak_by_time = np.where(finite, np.max(np.where(np.isfinite(tension), tension, -np.inf), axis=1), np.inf)
        flags = {
            "non-finite": ~finite,
            "energy blow-up": excursion > args.energy_factor * self.energy_excursion,
            "tension blow-up": peak_by_time > args.tension_factor * self.peak,
        }
        if code != "successful":
            mode = code
            bad = ~finite
        else:
            mode, bad = next(((m, f) for m, f in flags.items() if f.any()), (None, None))
        record = {
            "steps": int(r.stats["num_steps"]),
            "mode": mode,
            "fail_time_s": float(self.ts[np.argmax(bad)]) if bad is not None and bad.any() else None,
            "peak_tension_N": float(np.max(tension[finite])) if finite.any() else None,
        }
        record["peak_tension_rel_error"] = (
            abs(record["peak_tension_N"] - self.peak) / self.peak if record["peak_tension_N"] is not None else None
        )
        return mode is None, record


def bracket_and_bisect(trial, guess, floor, cap, ratio):
    """Largest dt (s) in [floor, cap] for which `trial(dt)` passes, assuming one crossing.

    `trial(dt)` returns `(ok, record)`. Doubling or halving from `guess` brackets the
    crossing, then log-space bisection narrows it to `hi/lo < ratio`. Returns
    `(lo, hi, record at lo, record at hi, trials)`; `lo` is `None` if even `floor`
    fails, `hi` is `None` if `cap` passes.
    """
    trials = []

    def run(dt):
        ok, record = trial(dt)
        trials.append({"dt": dt, "ok": ok, **record})
        return ok, record

    dt = min(max(guess, floor), cap)
    ok, record = run(dt)
    lo = hi = lo_rec = hi_rec = None
    if ok:
        lo, lo_rec = dt, record
        while hi is None:
            if lo >= cap:
                return lo, None, lo_rec, None, trials
            dt = min(2 * lo, cap)
            ok, record = run(dt)
            if ok:
                lo, lo_rec = dt, record
            else:
                hi, hi_rec = dt, record
    else:
        hi, hi_rec = dt, record
        while lo is None:
            if hi <= floor:
                return None, hi, None, hi_rec, trials
            dt = max(hi / 2, floor)
            ok, record = run(dt)
            if ok:
                lo, lo_rec = dt, record
            else:
                hi, hi_rec = dt, record
    while hi / lo > ratio:
        dt = math.sqrt(lo * hi)
        ok, record = run(dt)
        if ok:
            lo, lo_rec = dt, record
        else:
            hi, hi_rec = dt, record
    return lo, hi, lo_rec, hi_rec, trials


def study_method(name, cases, args):
    """Both bisections (stable, accurate) for one method over the cases sharing one N."""
    factory, kind = METHODS[name]
    solver = factory()
    max_steps = int(math.ceil(args.window / args.dt_floor)) + 10
    records = []
    compiled = False
    for case in cases:
        if not case.reference_ok:
            records.append(
                {"method": name, "kind": kind, **case.config, "omega_n": case.omega, "skipped": "reference failed"}
            )
            continue
        wall = {"stable": 0.0, "accurate": 0.0}

        def make_trial(stage, accurate):
            def trial(dt):
                nonlocal compiled
                start = time.perf_counter()
                config = jc.SolverConfig(
                    solver, dt0=dt, stepsize_controller=diffrax.ConstantStepSize(), max_steps=max_steps
                )
                r = jc.simulate(
                    case.model,
                    case.env,
                    args.window,
                    ts=case.ts,
                    initial=case.static.state,
                    solver=config,
                    throw=False,
                )
                jax.block_until_ready(r.positions)
                elapsed = time.perf_counter() - start
                if not compiled:
                    compiled = True
                    first_call_times.append(elapsed)
                else:
                    wall[stage] += elapsed
                ok, record = case.judge(r, args)
                if accurate and ok and record["peak_tension_rel_error"] > args.accuracy:
                    ok = False
                    record["mode"] = "inaccurate"
                return ok, record

            return trial

        first_call_times = []
        floor = max(args.dt_floor, 0.02 / case.omega)
        guess = 2.0 / case.omega if kind == "explicit" else min(20.0 / case.omega, args.dt_cap)
        lo, hi, lo_rec, hi_rec, trials = bracket_and_bisect(
            make_trial("stable", False), guess, floor, args.dt_cap, args.ratio
        )
        record = {
            "method": name,
            "kind": kind,
            **case.config,
            "omega_n": case.omega,
            "dt_stable": lo,
            "dt_first_fail": hi,
            "omega_dt_stable": None if lo is None else lo * case.omega,
            "failure_mode": None if hi_rec is None else hi_rec["mode"],
            "failure_time_s": None if hi_rec is None else hi_rec["fail_time_s"],
            "peak_tension_rel_error_at_dt_stable": None if lo_rec is None else lo_rec["peak_tension_rel_error"],
            "stable_trials": trials,
        }
        if lo is not None:
            if lo_rec["peak_tension_rel_error"] <= args.accuracy:
                # The largest stable step is already accurate: nothing to search.
                record.update(dt_accurate=lo, accurate_trials=[])
            else:
                # Implicit steps are dear: do not search below a step count the budget allows.
                acc_floor = max(floor, args.window / args.implicit_step_budget) if kind == "implicit" else floor
                alo, ahi, _, _, atrials = bracket_and_bisect(
                    make_trial("accurate", True), lo / 2, acc_floor, lo, args.ratio**3
                )
                record.update(
                    dt_accurate=alo, dt_accurate_floor=acc_floor if alo is None else None, accurate_trials=atrials
                )
        # The first call compiles: its time is compile plus one run, not part of the walls below.
        record["first_call_s"] = first_call_times[0] if first_call_times else None
        record["wall_stable_s"], record["wall_accurate_s"] = wall["stable"], wall["accurate"]
        records.append(record)
        print(json.dumps({k: v for k, v in record.items() if not k.endswith("trials")}), flush=True)
    return records


def study_adaptive(cases, args):
    """The adaptive defaults at rtol = atol = `--adaptive-rtol` on the slack and forcing cases."""
    records = []
    for label, factory in ADAPTIVE.items():
        solver = factory()
        max_steps = args.adaptive_max_steps if "dopri5" in label else args.adaptive_max_steps_implicit
        for case in cases:
            if not case.reference_ok:
                continue
            start = time.perf_counter()
            config = jc.SolverConfig(solver, rtol=args.adaptive_rtol, atol=args.adaptive_rtol, max_steps=max_steps)
            r = jc.simulate(
                case.model,
                case.env,
                args.window,
                ts=case.ts,
                initial=case.static.state,
                solver=config,
                throw=False,
            )
            jax.block_until_ready(r.positions)
            wall = time.perf_counter() - start
            _, verdict = case.judge(r, args)
            record = {
                "solver": label,
                **case.config,
                "omega_n": case.omega,
                "rtol": args.adaptive_rtol,
                "max_steps": max_steps,
                "result": result_name(r.result),
                "steps": int(r.stats["num_steps"]),
                "rejected_steps": int(r.stats["num_rejected_steps"]),
                "mode": verdict["mode"],
                "fail_time_s": verdict["fail_time_s"],
                "peak_tension_rel_error": verdict["peak_tension_rel_error"],
                "wall_s_including_compile": wall,
                "load_average": os.getloadavg(),
            }
            records.append(record)
            print(json.dumps(record), flush=True)
        jax.clear_caches()
    return records


def main():
    parser = argparse.ArgumentParser(description=__doc__, formatter_class=argparse.RawDescriptionHelpFormatter)
    parser.add_argument("--stiffness", type=float, nargs="+", default=[3e5, 3e6, 3e7, 3e8], help="C_E values (N)")
    parser.add_argument("--segments", type=int, nargs="+", default=[5, 10, 20])
    parser.add_argument(
        "--implicit-segments",
        type=int,
        nargs="+",
        default=[5, 10],
        help="segment counts for implicit methods (a dense Jacobian costs O(N^3) per step)",
    )
    parser.add_argument("--study-segments", type=int, default=10, help="N of the slack and forcing studies")
    parser.add_argument("--slack-widths", type=float, nargs="+", default=[1e-3, 1e-4, 1e-5, 1e-6, 1e-7, 0.0])
    parser.add_argument("--amplitude-scales", type=float, nargs="+", default=[0.25, 0.5, 1.0, 1.5, 2.0])
    parser.add_argument("--currents", type=float, nargs="+", default=[1.0], help="uniform currents along +x (m/s)")
    parser.add_argument("--methods", nargs="+", default=list(METHODS), choices=list(METHODS))
    parser.add_argument("--window", type=float, default=6.0, help="simulated window from statics (s)")
    parser.add_argument("--output-rate", type=float, default=100.0, help="output times per second (Hz)")
    parser.add_argument("--ratio", type=float, default=1.05, help="bisect the stable step until hi/lo < ratio")
    parser.add_argument("--dt-floor", type=float, default=3e-5, help="smallest fixed step tried (s)")
    parser.add_argument("--dt-cap", type=float, default=1.0, help="largest fixed step tried (s)")
    parser.add_argument("--energy-factor", type=float, default=10.0)
    parser.add_argument("--tension-factor", type=float, default=3.0)
    parser.add_argument("--accuracy", type=float, default=0.05, help="peak-tension error of an accurate step (–)")
    parser.add_argument(
        "--implicit-step-budget", type=int, default=600, help="most fixed steps an implicit accuracy trial may take"
    )
    parser.add_argument("--adaptive-rtol", type=float, default=1e-6)
    parser.add_argument("--adaptive-max-steps", type=int, default=200_000)
    parser.add_argument("--adaptive-max-steps-implicit", type=int, default=20_000)
    parser.add_argument("--quick", action="store_true", help="a tiny run: N = 5, one case on each axis")
    parser.add_argument("--out", default=str(RESULTS / "stability.json"))
    parser.add_argument("--report", action="store_true", help="print the latest session as markdown tables")
    parser.add_argument("--plot", action="store_true", help="chart the latest session")
    parser.add_argument(
        "--summary",
        action="store_true",
        help="print the latest session as compact tables (one row per method), as in benchmarks/README.md",
    )
    args = parser.parse_args()
    if args.report:
        report(Path(args.out))
        return
    if args.plot:
        plot(Path(args.out))
        return
    if args.summary:
        summary(Path(args.out))
        return
    if args.quick:
        if args.out == str(RESULTS / "stability.json"):
            args.out = "/tmp/h2/stability_quick.json"
        args.stiffness, args.segments, args.implicit_segments, args.study_segments = [3e7], [5], [5], 5
        args.slack_widths, args.amplitude_scales, args.currents = [0.0], [2.0], [1.0]
        args.ratio = 1.1

    started = time.perf_counter()
    load_start = os.getloadavg()
    ts = np.linspace(0.0, args.window, int(round(args.window * args.output_rate)) + 1)
    base = {"stiffness": BASE_STIFFNESS, "slack_width": 1e-5, "amplitude_scale": 1.0, "current": 0.0}
    limits = {
        name: {
            "strict": imaginary_axis_limit(METHODS[name][0]()),
            "growth_1pct": imaginary_axis_limit(METHODS[name][0](), tol=0.01),
        }
        for name in args.methods
        if METHODS[name][1] == "explicit"
    }
    print("imaginary-axis limits", limits, flush=True)

    records, adaptive = [], []
    for n in sorted(set(args.segments) | {args.study_segments}):
        configs = []
        if n in args.segments:
            configs += [{**base, "axis": "stiffness", "segments": n, "stiffness": ea} for ea in args.stiffness]
        if n == args.study_segments:
            configs += [{**base, "axis": "slack", "segments": n, "slack_width": w} for w in args.slack_widths]
            configs += [{**base, "axis": "forcing", "segments": n, "amplitude_scale": a} for a in args.amplitude_scales]
            configs += [{**base, "axis": "forcing", "segments": n, "current": c} for c in args.currents]
        cases = [Case(c, args.window, ts) for c in configs]
        for case in cases:
            print(json.dumps({**case.config, "omega_n": case.omega, "reference": case.reference}), flush=True)
        jax.clear_caches()
        for name in args.methods:
            if METHODS[name][1] == "implicit" and n not in args.implicit_segments:
                chosen = [c for c in cases if c.config["axis"] != "stiffness"]
            else:
                chosen = cases
            if chosen:
                for rec in study_method(name, chosen, args):
                    rec["load_average"] = os.getloadavg()
                    records.append(rec)
                # A checkpoint, so that a long run cut short keeps what it measured.
                Path("/tmp/h2").mkdir(exist_ok=True)
                Path("/tmp/h2/stability_partial.json").write_text(json.dumps(records))
            # Each compiled program maps thousands of memory regions; free them.
            jax.clear_caches()
        if n == args.study_segments:
            adaptive += study_adaptive([c for c in cases if c.config["axis"] != "stiffness"], args)
        for case in cases:
            case.reference.update({**case.config, "omega_n": case.omega})
        references = [c.reference for c in cases]
        records.append({"references": references})
        del cases
        jax.clear_caches()

    append_session(
        args.out,
        window_s=args.window,
        output_rate_hz=args.output_rate,
        ratio=args.ratio,
        energy_factor=args.energy_factor,
        tension_factor=args.tension_factor,
        accuracy=args.accuracy,
        imaginary_axis_limits=limits,
        quick=args.quick,
        load_average_start=load_start,
        load_average_end=os.getloadavg(),
        wall_s=time.perf_counter() - started,
        records=[r for r in records if "references" not in r],
        references=[ref for r in records if "references" in r for ref in r["references"]],
        adaptive=adaptive,
    )
    plot(Path(args.out))


def _latest(path: Path) -> dict:
    return json.loads(path.read_text())[-1]


def _fmt_dt(value, bound=None):
    if value is None:
        return f"< {bound:.3g}" if bound is not None else "–"
    return f"{value:.3g}"


def report(path: Path) -> None:
    """Print the latest session as markdown tables: one per axis, and the adaptive runs."""
    s = _latest(path)
    print(
        f"Session {s['time']}, commit {s['commit']}, {s['machine']}, load average "
        f"{s['load_average_start'][0]:.1f} → {s['load_average_end'][0]:.1f}, {s['wall_s'] / 60:.0f} min"
        f"{' (quick)' if s.get('quick') else ''}.\n"
    )
    print(
        "Imaginary-axis limits y = ω dt of each explicit method, measured from one step on an undamped oscillator "
        "(strict: |R(iy)| ≤ 1; 1 %: |R(iy)| ≤ 1.01): "
        + ", ".join(f"{k} {v['strict']:.2f} / {v['growth_1pct']:.2f}" for k, v in s["imaginary_axis_limits"].items())
        + ".\n"
    )
    columns = {
        "stiffness": ("C_E (N)", lambda r: f"{r['stiffness']:.0e}"),
        "slack": ("slack width", lambda r: "0 (sharp)" if r["slack_width"] == 0 else f"{r['slack_width']:.0e}"),
        "forcing": (
            "forcing",
            lambda r: f"current {r['current']} m/s" if r["current"] else f"amplitude × {r['amplitude_scale']}",
        ),
    }
    for axis, (label, cell) in columns.items():
        rows = [r for r in s["records"] if r.get("axis") == axis and "skipped" not in r]
        if not rows:
            continue
        print(f"**{axis}**\n")
        print(
            f"| method | N | {label} | ω_n (rad/s) | dt_max (s) | ω_n·dt_max | failure above it (at t) | "
            "peak err at dt_max | dt accurate (s) |"
        )
        print("|---|---|---|---|---|---|---|---|---|")
        for r in rows:
            stable = (
                _fmt_dt(r["dt_stable"])
                if r["dt_first_fail"] is not None or r["dt_stable"] is None
                else f"≥ {r['dt_stable']:.3g}"
            )
            if r["dt_stable"] is None:
                stable = f"< {r['dt_first_fail']:.3g}"
            fail = (
                "none up to the cap"
                if r["failure_mode"] is None
                else (
                    r["failure_mode"] + (f" ({r['failure_time_s']:.2f} s)" if r["failure_time_s"] is not None else "")
                )
            )
            err = r["peak_tension_rel_error_at_dt_stable"]
            acc = _fmt_dt(r.get("dt_accurate"), r.get("dt_accurate_floor"))
            print(
                f"| {r['method']} | {r['segments']} | {cell(r)} | {r['omega_n']:.0f} | {stable} | "
                f"{'–' if r['omega_dt_stable'] is None else format(r['omega_dt_stable'], '.2f')} | {fail} | "
                f"{'–' if err is None else f'{100 * err:.1f} %'} | {acc} |"
            )
        print()
    if s["adaptive"]:
        print("**adaptive defaults**\n")
        print("| solver | N | case | result | steps (rejected) | peak err | wall incl. compile (s) |")
        print("|---|---|---|---|---|---|---|")
        for r in s["adaptive"]:
            case = (
                f"slack width {r['slack_width']:.0e}"
                if r["axis"] == "slack"
                else f"current {r['current']} m/s"
                if r["current"]
                else f"amplitude × {r['amplitude_scale']}"
            )
            err = r["peak_tension_rel_error"]
            result = r["result"] if r["mode"] is None or r["mode"] == r["result"] else f"{r['result']}, {r['mode']}"
            print(
                f"| {r['solver']} | {r['segments']} | {case} | {result} | {r['steps']} ({r['rejected_steps']}) | "
                f"{'–' if err is None else f'{100 * err:.2f} %'} | {r['wall_s_including_compile']:.1f} |"
            )
        print()
    print("**references** (Dopri5, rtol = atol = 1e-8)\n")
    print(
        "| N | C_E (N) | slack width | amplitude × | current (m/s) | steps | peak T (kN) | first slack (s) | slack "
        "fraction |"
    )
    print("|---|---|---|---|---|---|---|---|---|")
    for r in s["references"]:
        first = "none" if r["first_slack_s"] is None else f"{r['first_slack_s']:.2f}"
        print(
            f"| {r['segments']} | {r['stiffness']:.0e} | {r['slack_width']:.0e} | {r['amplitude_scale']} | "
            f"{r['current']} | "
            f"{r['steps']} | {r['peak_tension_N'] / 1e3:.1f} | {first} | {100 * r['slack_segment_fraction']:.1f} % |"
        )


SHORT = {
    "tension blow-up": "T",
    "energy blow-up": "E",
    "non-finite": "NaN",
    "nonlinear_max_steps_reached": "N",
    "nonlinear_divergence": "ND",
    None: "cap",
}


def summary(path: Path) -> None:
    """Compact tables of the latest session: one row per method, one column per case;
    each cell is dt_max (s) and a letter for what failed just above it."""
    s = _latest(path)
    records = [r for r in s["records"] if "skipped" not in r]
    methods = [m for m in METHODS if any(r["method"] == m for r in records)]
    print(
        "Cells: largest stable fixed step dt_max (s) / ω_n·dt_max, then the failure just above it: "
        "T tension blow-up, E energy blow-up, NaN non-finite state, N Newton did not converge "
        "(`nonlinear_max_steps_reached`), cap: none up to the 1 s cap.\n"
    )
    rows = [r for r in records if r["axis"] == "stiffness"]
    cases = sorted({(r["segments"], r["stiffness"]) for r in rows})
    print("| method | " + " | ".join(f"N={n}, EA={ea:.0e}" for n, ea in cases) + " |")
    print("|---|" + "---|" * len(cases))
    print(
        "| ω_n (rad/s) | "
        + " | ".join(f"{next(r['omega_n'] for r in rows if (r['segments'], r['stiffness']) == c):.0f}" for c in cases)
        + " |"
    )
    for m in methods:
        cells = []
        for c in cases:
            r = next((r for r in rows if r["method"] == m and (r["segments"], r["stiffness"]) == c), None)
            cells.append(
                "–"
                if r is None
                else f"{_fmt_dt(r['dt_stable'])} / {r['omega_dt_stable']:.2f} "
                f"{SHORT.get(r['failure_mode'], r['failure_mode'])}"
                if r["dt_stable"] is not None
                else f"< {r['dt_first_fail']:.3g}"
            )
        print(f"| {m} | " + " | ".join(cells) + " |")
    print()
    for axis, key, label in (("slack", "slack_width", "w"), ("forcing", "amplitude_scale", "A ×")):
        rows = [r for r in records if r["axis"] == axis]
        if not rows:
            continue

        def case_of(r):
            return ("current", r["current"]) if r["current"] else (key, r[key])

        cases = sorted(
            {case_of(r) for r in rows}, key=lambda c: (c[0] == "current", -c[1] if axis == "slack" else c[1])
        )
        head = [
            f"U = {v} m/s" if k == "current" else (f"{label} {v:g}" if v else f"{label} 0 (sharp)") for k, v in cases
        ]
        print(f"| method, N = {rows[0]['segments']}, EA = {rows[0]['stiffness']:.0e} | " + " | ".join(head) + " |")
        print("|---|" + "---|" * len(cases))
        for m in methods:
            cells = []
            for c in cases:
                r = next((r for r in rows if r["method"] == m and case_of(r) == c), None)
                cells.append(
                    "–"
                    if r is None or r["dt_stable"] is None
                    else f"{_fmt_dt(r['dt_stable'])} {SHORT.get(r['failure_mode'], r['failure_mode'])}"
                )
            print(f"| {m} | " + " | ".join(cells) + " |")
        accurate = [r for r in rows if r["method"] in methods]
        print(
            "| *accurate dt (5 %)* | "
            + " | ".join(
                "; ".join(
                    f"{r['method']} {_fmt_dt(r.get('dt_accurate'), r.get('dt_accurate_floor'))}"
                    for r in accurate
                    if case_of(r) == c and r["method"] in ("dopri5", "kvaerno5")
                )
                for c in cases
            )
            + " |"
        )
        print()


MARKERS = {
    "heun": "o",
    "midpoint": "s",
    "tsit5": "^",
    "dopri5": "v",
    "picard3": "D",
    "implicit-euler": "x",
    "kvaerno3": "+",
    "kvaerno4": "1",
    "kvaerno5": "*",
}


def plot(path: Path) -> None:
    """Three charts of the latest session: stability_stiffness.png, stability_slack.png,
    stability_forcing.png."""
    import matplotlib

    matplotlib.use("Agg")
    import matplotlib.pyplot as plt

    s = _latest(path)
    records = [r for r in s["records"] if "skipped" not in r]
    methods = [m for m in METHODS if any(r["method"] == m for r in records)]
    colors = {m: plt.cm.tab10(i) for i, m in enumerate(METHODS)}

    def capped(r):
        # A step that never failed is drawn at the cap, hollow.
        return r["dt_first_fail"] is None

    rows = [r for r in records if r["axis"] == "stiffness" and r["dt_stable"] is not None]
    if rows:
        fig, (ax1, ax2) = plt.subplots(1, 2, figsize=(13, 5.2))
        for m in methods:
            mine = sorted((r for r in rows if r["method"] == m), key=lambda r: r["omega_n"])
            if not mine:
                continue
            w = np.array([r["omega_n"] for r in mine])
            dt = np.array([r["dt_stable"] for r in mine])
            hollow = np.array([capped(r) for r in mine])
            kw = dict(color=colors[m], marker=MARKERS[m], linestyle="none")
            ax1.plot(w[~hollow], dt[~hollow], label=m, **kw)
            ax1.plot(w[hollow], dt[hollow], markerfacecolor="none", **kw)
            ax2.plot(w[~hollow], (w * dt)[~hollow], label=m, **kw)
            ax2.plot(w[hollow], (w * dt)[hollow], markerfacecolor="none", **kw)
        grid = np.geomspace(min(r["omega_n"] for r in rows) / 1.5, max(r["omega_n"] for r in rows) * 1.5, 50)
        for c in (1.0, 3.0):
            ax1.plot(grid, c / grid, color="0.6", linestyle=":" if c == 1 else "--", linewidth=1)
            ax1.text(grid[-1], c / grid[-1], f" dt = {c:g}/ω_n", fontsize=8, color="0.4", va="center")
        for name, y in s["imaginary_axis_limits"].items():
            ax2.axhline(y["growth_1pct"], color=colors[name], linestyle="--", linewidth=0.8)
        ax1.set(
            xscale="log",
            yscale="log",
            xlabel="ω_n = 2√(EA/m′)/l (rad/s)",
            ylabel="largest stable fixed step dt_max (s)",
            title="Largest stable step against the axial frequency",
        )
        ax2.set(
            xscale="log",
            yscale="log",
            xlabel="ω_n (rad/s)",
            ylabel="ω_n · dt_max (–)",
            title="ω_n·dt_max; dashed: ω dt where an undamped mode grows 1 %/step",
        )
        ax1.legend(fontsize=8, ncol=2)
        segments = sorted({r["segments"] for r in rows})
        stiffness = sorted({r["stiffness"] for r in rows})
        fig.text(
            0.01,
            0.01,
            "Points at dt = 1 s (hollow where the marker allows): no failure up to the 1 s cap. "
            f"The anchored line, lumped mass, {s['window_s']:g} s from statics; EA = "
            + ", ".join(f"{ea:.0e}" for ea in stiffness)
            + " N; N = "
            + ", ".join(map(str, segments))
            + ".",
            fontsize=8,
        )
        fig.tight_layout(rect=(0, 0.03, 1, 1))
        fig.savefig(path.parent / "stability_stiffness.png", dpi=120)
        plt.close(fig)

    def axis_chart(axis, key, xlabel, fname, title, xfmt):
        rows = [r for r in records if r["axis"] == axis]
        adaptive = [r for r in s["adaptive"] if r["axis"] == axis]
        if axis == "forcing":
            rows = [r for r in rows if not r["current"]]
            adaptive_rows = [r for r in adaptive if not r["current"]]
        else:
            adaptive_rows = adaptive
        if not rows:
            return
        fig, (ax1, ax2) = plt.subplots(1, 2, figsize=(13, 5.2))
        for m in methods:
            mine = sorted((r for r in rows if r["method"] == m), key=xfmt)
            if not mine:
                continue
            x = np.array([xfmt(r) for r in mine])
            dt = np.array([np.nan if r["dt_stable"] is None else r["dt_stable"] for r in mine])
            hollow = np.array([capped(r) for r in mine])
            kw = dict(color=colors[m], marker=MARKERS[m])
            ax1.plot(x, dt, label=m, **kw)
            ax1.plot(x[hollow], dt[hollow], markerfacecolor="white", linestyle="none", **kw)
        for label in ADAPTIVE:
            mine = sorted((r for r in adaptive_rows if r["solver"] == label), key=xfmt)
            if not mine:
                continue
            x = np.array([xfmt(r) for r in mine])
            steps = np.array([r["steps"] for r in mine], dtype=float)
            rejected = np.array([r["rejected_steps"] for r in mine], dtype=float)
            failed = np.array([r["mode"] is not None for r in mine])
            (line,) = ax2.plot(x, steps, marker="o", label=f"{label}: steps")
            ax2.plot(
                x,
                np.maximum(rejected, 0.5),
                marker=".",
                linestyle="--",
                color=line.get_color(),
                label=f"{label}: rejected",
            )
            ax2.plot(x[failed], steps[failed], marker="X", markersize=12, linestyle="none", color="red")
        ax1.set(xscale="log", yscale="log", xlabel=xlabel, ylabel="largest stable fixed step dt_max (s)", title=title)
        ax2.set(
            xscale="log",
            yscale="log",
            xlabel=xlabel,
            ylabel="steps over the window",
            title=f"Adaptive defaults at rtol = atol = {s['adaptive'][0]['rtol'] if s['adaptive'] else ''} "
            "(red X: failed)",
        )
        ax1.legend(fontsize=8, ncol=2)
        ax2.legend(fontsize=8)
        return fig, ax1, ax2

    out = axis_chart(
        "slack",
        "slack_width",
        "slack smoothing width w (strain)",
        "stability_slack.png",
        "Largest stable step against the slack switch's width",
        lambda r: r["slack_width"] if r["slack_width"] > 0 else 1e-8,
    )
    if out:
        fig, ax1, ax2 = out
        for ax in (ax1, ax2):
            # w = 0 is drawn at 1e-8: label it as what it is.
            ax.set_xticks([1e-8, 1e-7, 1e-6, 1e-5, 1e-4, 1e-3], ["0 (sharp)", "1e-7", "1e-6", "1e-5", "1e-4", "1e-3"])
            ax.xaxis.set_minor_locator(matplotlib.ticker.NullLocator())
        # The step counts span less than a decade: label 1, 2 and 5 times each decade.
        ax2.yaxis.set_major_locator(matplotlib.ticker.LogLocator(subs=(1.0, 2.0, 5.0)))
        ax2.yaxis.set_major_formatter(matplotlib.ticker.FormatStrFormatter("%g"))
        ax2.yaxis.set_minor_formatter(matplotlib.ticker.NullFormatter())
        fig.tight_layout()
        fig.savefig(path.parent / "stability_slack.png", dpi=120)
        plt.close(fig)
    out = axis_chart(
        "forcing",
        "amplitude_scale",
        "fairlead amplitude / the anchored-line paper's 1.573 m",
        "stability_forcing.png",
        "Largest stable step against the forcing",
        lambda r: r["amplitude_scale"],
    )
    if out:
        fig, ax1, _ = out
        currents = [r for r in records if r["axis"] == "forcing" and r["current"]]
        if currents:
            text = "Current (amplitude × 1): " + "; ".join(
                f"{r['method']} {r['current']} m/s: {_fmt_dt(r['dt_stable'])} s" for r in currents
            )
            fig.text(0.01, 0.005, text, fontsize=6, wrap=True)
        fig.tight_layout(rect=(0, 0.06, 1, 1))
        fig.savefig(path.parent / "stability_forcing.png", dpi=120)
        plt.close(fig)


if __name__ == "__main__":
    main()
