"""What a gradient costs against a forward simulation, and what compiles, on the anchored line.

The anchored line (`jaxcable.examples.anchored_line`: 200 m depth, 30°, C_E = 3e7 N,
top driven at T_w = 5.6 s), each run from the static equilibrium at the nominal
parameters, Dopri5 unless said otherwise. Four studies, one command (and one table) each:

- `gradient`: a scalar loss, the mean square of the top segment's tension history
    (20 Hz output) in units of 100 kN, L = mean_t (T_top(t) / 1e5 N)² (–), as a function
    of multiplicative factors θ on EA (C_E, N), K_n and K_τ (–), all 1 at the nominal
    line: EA = θ_EA · 3e7 N, and so on (C_E1 and the initial state stay fixed). Timed at
    rtol = atol = 1e-6: the loss alone (*forward*), its gradient with respect to one
    factor (θ_EA) or three by `jax.jacfwd` through `diffrax.ForwardMode()`, and by
    `jax.value_and_grad` through `diffrax.RecursiveCheckpointAdjoint` (default
    checkpoints, or `--checkpoints`). Then the gradient is checked: at
    rtol = atol = `--check-rtol` (1e-8) both modes' gradients are set against a central
    finite difference of the loss with relative step `--fd-step` (1e-5) in each factor.
    The tolerances enter the compiled programs as data, so the check compiles nothing.
- `segments`: `jaxcable.simulate` (lumped, Dopri5) at N = 5 ... 200 segments: compile
    time, and the number of equations in the vector field's jaxpr (flat in N if no
    Python loop runs over segments).
- `reuse`: what recompiles: `jaxcable.simulate` with new rtol, atol, t1 and EA, and
    `jaxcable.sweep` with new values of the same batch size, and of another batch size.
- `solvers`: what compiles for Dopri5, Tsit5, Kvaerno5 (`jaxcable.stiff_solver`) and
    `jaxcable.PicardTrapezoid` at N = 20.

In `gradient`, each program is called once (compile time = that call less its median
warm call), then the warm calls are interleaved, one of each program per round, and a
gradient's *ratio* is the median over rounds of its time over the forward run's in the
same round: on a shared machine the load drifts, and this keeps both under about the
same. Compile time is measured two ways: as `_timing.timed` does (first call less the median
warm call, s), and from JAX's own monitoring events during the first call: tracing
(jaxpr), lowering to MLIR, and XLA's backend compile, summed over every program compiled,
with the count of programs. A call that compiles nothing records no backend-compile event.

    python benchmarks/gradient_compile.py gradient --segments 10 20 --mass-matrix lumped
    python benchmarks/gradient_compile.py segments
    python benchmarks/gradient_compile.py reuse
    python benchmarks/gradient_compile.py solvers
    python benchmarks/gradient_compile.py --report

Results are appended to benchmarks/results/gradient_compile.json, each entry tagged with
its study; `--report` prints one markdown table per study.
"""

import argparse
import json
import os
import statistics
import time
from pathlib import Path

from _results import append_session
from _timing import timed

OUT = Path(__file__).parent / "results" / "gradient_compile.json"
# The loss's tension unit (N): 100 kN, the order of the line's peak tension.
TENSION_SCALE = 1e5
PARAMETERS = ("EA", "K_n", "K_tau")
# A segment below this tension (N) counts as slack (C_E · 1e-5, the slack switch's width, is 300 N).
SLACK_TENSION = 1.0


def parse():
    parser = argparse.ArgumentParser(description=__doc__, formatter_class=argparse.RawDescriptionHelpFormatter)
    parser.add_argument("study", nargs="?", choices=["gradient", "segments", "reuse", "solvers"])
    parser.add_argument("--segments", type=int, nargs="+", help="segment counts (default per study)")
    parser.add_argument("--mass-matrix", nargs="+", default=["lumped"], choices=["lumped", "consistent"])
    parser.add_argument("--duration", type=float, help="simulated time (s); default per study")
    parser.add_argument(
        "--parameters",
        type=int,
        nargs="+",
        default=[1, 3],
        help="gradient: differentiate w.r.t. the first 1 and/or 3 of EA, K_n, K_tau",
    )
    parser.add_argument(
        "--checkpoints",
        type=int,
        nargs="*",
        default=[],
        help="gradient: also time reverse mode with these RecursiveCheckpointAdjoint checkpoints",
    )
    parser.add_argument("--no-check", action="store_true", help="gradient: skip the finite-difference check")
    parser.add_argument("--check-rtol", type=float, default=1e-8)
    parser.add_argument(
        "--fd-steps", type=float, nargs="+", default=[1e-5, 1e-6], help="relative steps of the central differences"
    )
    parser.add_argument(
        "--check-duration",
        type=float,
        default=3.0,
        help="gradient: also check over this shorter horizon (s), before the line first goes slack",
    )
    parser.add_argument("--rtol", type=float, default=1e-6)
    parser.add_argument("--max-steps", type=int, default=200_000)
    parser.add_argument("--repeats", type=int, default=3)
    parser.add_argument("--out", default=str(OUT))
    parser.add_argument("--report", action="store_true", help="print the recorded results as markdown tables")
    args = parser.parse_args()
    if not args.report and args.study is None:
        parser.error("give a study (gradient, segments, reuse, solvers) or --report")
    return args


# --- JAX's compile events -------------------------------------------------------------

_EVENTS = []


def _listen():
    """Record every duration event JAX reports (tracing, lowering, backend compile)."""
    import jax

    def listener(event, duration, **kwargs):
        _EVENTS.append((event, duration))

    jax.monitoring.register_event_duration_secs_listener(listener)


def compile_events(since: int, until: int | None = None) -> dict:
    """Sum the compile events recorded from index `since` to `until`: seconds spent
    tracing to jaxprs, lowering to MLIR and in XLA's backend compile, the number of
    backend compiles and the longest one (s)."""
    from jax._src import dispatch

    events = _EVENTS[since:until]

    def total(name):
        return sum(d for e, d in events if e == name)

    backend = [d for e, d in events if e == dispatch.BACKEND_COMPILE_EVENT]
    return {
        "trace_s": total(dispatch.JAXPR_TRACE_EVENT),
        "lower_s": total(dispatch.JAXPR_TO_MLIR_MODULE_EVENT),
        "backend_s": sum(backend),
        "backend_compiles": len(backend),
        "longest_backend_s": max(backend, default=0.0),
    }


def timed_with_events(run, repeats):
    """`_timing.timed(run, repeats)`, plus the compile events of the first call, and
    the number of backend compiles during the warm calls (which should be none)."""
    start = len(_EVENTS)
    calls, second = [0], []

    def counted():
        if calls[0] == 1:
            second.append(len(_EVENTS))  # the first call is done (and blocked on)
        calls[0] += 1
        return run()

    result, compile_time, run_time = timed(counted, repeats)
    split = second[0] if second else len(_EVENTS)
    events = compile_events(start, split)
    events["warm_backend_compiles"] = compile_events(split)["backend_compiles"]
    return result, compile_time, run_time, events


def count_equations(jaxpr) -> int:
    """Equations in a closed jaxpr, counting those inside sub-jaxprs (jit, cond,
    while, custom derivatives) too."""
    import jax
    import jax.extend.core  # noqa: F401  (jaxprs_in_params)

    def walk(j):
        n = 0
        for eqn in j.eqns:
            n += 1
            for sub in jax.extend.core.jaxprs_in_params(eqn.params):
                n += walk(sub)
        return n

    return walk(jaxpr.jaxpr)


def load_average() -> list[float]:
    """The 1, 5 and 15 minute load averages, beside every timing."""
    return [round(x, 2) for x in os.getloadavg()]


# --- studies ----------------------------------------------------------------------------


def scaled(model, theta, names):
    """`model` with EA, K_n and K_τ (those in `names`) multiplied by the factors `theta`."""
    import equinox as eqx

    getters = {
        "EA": lambda m: m.line.tension_law.axial_stiffness,
        "K_n": lambda m: m.line.normal_drag,
        "K_tau": lambda m: m.line.tangential_drag,
    }
    where = lambda m: [getters[n](m) for n in names]  # noqa: E731
    return eqx.tree_at(where, model, [theta[i] * getters[n](model) for i, n in enumerate(names)])


def gradient_study(args):
    import diffrax
    import jax
    import jax.numpy as jnp
    import numpy as np

    import jaxcable as jc
    from jaxcable.examples import anchored_line

    duration = args.duration or 5.6
    n_out = int(round(duration * 20)) + 1
    entries = []
    for mass in args.mass_matrix:
        for n in args.segments or [10, 20]:
            model, env = anchored_line(n, mass_matrix=mass)
            static = jc.solve_statics(model, env)
            for k in args.parameters:
                names = PARAMETERS[:k]

                def make_loss(adjoint, names=names):
                    def loss(theta, tol, t1):
                        # t1 and the output times are data: the check at a shorter
                        # horizon reuses the compiled programs.
                        config = jc.SolverConfig(rtol=tol, atol=tol, max_steps=args.max_steps, adjoint=adjoint)
                        result = jc.simulate(
                            scaled(model, theta, names),
                            env,
                            t1,
                            ts=jnp.linspace(0.0, t1, n_out),
                            initial=static.state,
                            solver=config,
                            throw=False,
                        )
                        top = result.tension[:, -1] / TENSION_SCALE
                        slack = jnp.min(result.tension, axis=1) < SLACK_TENSION
                        first_slack = jnp.where(jnp.any(slack), result.times[jnp.argmax(slack)], jnp.inf)
                        return jnp.mean(top**2), (result.stats["num_steps"], result.success, first_slack)

                    return loss

                theta = jnp.ones(k)
                tol = jnp.asarray(args.rtol)
                t1 = jnp.asarray(duration)
                forward = jax.jit(make_loss(None))
                jacfwd = jax.jit(jax.jacfwd(make_loss(diffrax.ForwardMode()), has_aux=True))
                reverses = {"default": jax.jit(jax.value_and_grad(make_loss(None), has_aux=True))}
                for c in args.checkpoints:
                    reverses[str(c)] = jax.jit(
                        jax.value_and_grad(make_loss(diffrax.RecursiveCheckpointAdjoint(checkpoints=c)), has_aux=True)
                    )

                entry = {
                    "study": "gradient",
                    "segments": n,
                    "mass_matrix": mass,
                    "duration_s": duration,
                    "rtol": args.rtol,
                    "parameters": list(names),
                    "max_steps": args.max_steps,
                }
                programs = {
                    "forward": forward,
                    "jacfwd": jacfwd,
                    **{f"reverse {label}": r for label, r in reverses.items()},
                }
                results, first, events = {}, {}, {}
                for name, program in programs.items():
                    mark = len(_EVENTS)
                    begin = time.perf_counter()
                    results[name] = jax.block_until_ready(program(theta, tol, t1))
                    first[name] = time.perf_counter() - begin
                    events[name] = compile_events(mark)
                # Warm calls interleaved, one of each program per round: on a shared
                # machine the load drifts, and each round's programs see about the same.
                warm = {name: [] for name in programs}
                for _ in range(args.repeats):
                    for name, program in programs.items():
                        begin = time.perf_counter()
                        jax.block_until_ready(program(theta, tol, t1))
                        warm[name].append(time.perf_counter() - begin)
                run = {name: statistics.median(w) for name, w in warm.items()}
                ratio = {name: statistics.median(np.array(w) / np.array(warm["forward"])) for name, w in warm.items()}
                value, (steps, ok, slack) = results["forward"]
                g_fwd, _ = results["jacfwd"]
                entry.update(
                    loss=float(value),
                    steps=int(steps),
                    success=bool(ok),
                    first_slack_s=float(slack),
                    timing="interleaved",
                    warm_s=warm,
                    forward_run_s=run["forward"],
                    forward_compile_s=max(first["forward"] - run["forward"], 0.0),
                    forward_events=events["forward"],
                    load_forward=load_average(),
                    jacfwd_run_s=run["jacfwd"],
                    jacfwd_compile_s=max(first["jacfwd"] - run["jacfwd"], 0.0),
                    jacfwd_events=events["jacfwd"],
                    jacfwd_ratio=ratio["jacfwd"],
                    jacfwd_gradient=np.asarray(g_fwd).tolist(),
                    load_jacfwd=load_average(),
                )
                entry["reverse"] = {}
                for label in reverses:
                    name = f"reverse {label}"
                    (v_r, _), g_rev = results[name]
                    entry["reverse"][label] = {
                        "run_s": run[name],
                        "compile_s": max(first[name] - run[name], 0.0),
                        "events": events[name],
                        "ratio": ratio[name],
                        "gradient": np.asarray(g_rev).tolist(),
                        "value_matches_forward": bool(np.isclose(v_r, value, rtol=1e-12)),
                        "load": load_average(),
                    }
                print(json.dumps({k_: v for k_, v in entry.items() if "events" not in k_}), flush=True)
                if not args.no_check:
                    entry["checks"] = []
                    for horizon in sorted({min(args.check_duration, duration), duration}):
                        # At the full horizon only EA is checked: past the first slack the
                        # check says more about the loss than about the gradient (README).
                        count = k if horizon < duration or k == 1 or args.check_duration >= duration else 1
                        entry["checks"].append(
                            check_gradient(args, theta, forward, jacfwd, reverses["default"], k, horizon, count)
                        )
                        print(json.dumps(entry["checks"][-1]), flush=True)
                entries.append(entry)
                # Free the compiled programs: their memory maps add up past Linux's 65,530.
                jax.clear_caches()
    return entries


def check_gradient(args, theta, forward, jacfwd, reverse, k, horizon, count):
    """Both modes' gradients at rtol = atol = `args.check_rtol` over `horizon` (s)
    against central differences of the loss at the same tolerance, with each relative
    step in `args.fd_steps`, for the first `count` factors; relative errors against the
    first step's difference."""
    import jax.numpy as jnp
    import numpy as np

    tol, t1 = jnp.asarray(args.check_rtol), jnp.asarray(horizon)
    start = time.perf_counter()
    g_fwd, (steps, ok, slack) = jacfwd(theta, tol, t1)
    _, g_rev = reverse(theta, tol, t1)
    fd = np.zeros((len(args.fd_steps), count))
    for j, h in enumerate(args.fd_steps):
        for i in range(count):
            e = jnp.zeros(k).at[i].set(h)
            plus, _ = forward(theta + e, tol, t1)
            minus, _ = forward(theta - e, tol, t1)
            fd[j, i] = (float(plus) - float(minus)) / (2 * h)
    g_fwd, g_rev = np.asarray(g_fwd)[:count], np.asarray(g_rev)[:count]
    return {
        "horizon_s": horizon,
        "check_rtol": args.check_rtol,
        "fd_steps": args.fd_steps,
        "check_steps": int(steps),
        "check_success": bool(ok),
        "first_slack_s": float(slack),
        "parameters_checked": count,
        "finite_difference": fd.tolist(),
        "jacfwd": g_fwd.tolist(),
        "reverse": g_rev.tolist(),
        "jacfwd_rel_error": (np.abs(g_fwd - fd[0]) / np.abs(fd[0])).tolist(),
        "reverse_rel_error": (np.abs(g_rev - fd[0]) / np.abs(fd[0])).tolist(),
        "check_wall_s": time.perf_counter() - start,
        "load": load_average(),
    }


def segments_study(args):
    import jax
    import numpy as np

    import jaxcable as jc
    from jaxcable.equations import vector_field
    from jaxcable.examples import anchored_line

    duration = args.duration or 0.2
    ts = np.linspace(0.0, duration, 5)
    entries = []
    for n in args.segments or [5, 10, 20, 50, 100, 200]:
        model, env = anchored_line(n, mass_matrix="lumped")
        static = jc.solve_statics(model, env)
        jax.clear_caches()  # statics' programs are not what is measured
        y = (static.state.positions[model.free_nodes], static.state.velocities[model.free_nodes])
        equations = count_equations(jax.make_jaxpr(lambda y: vector_field(0.0, y, (model, env)))(y))

        def run():
            config = jc.SolverConfig(rtol=args.rtol, atol=args.rtol, max_steps=args.max_steps)
            return jc.simulate(model, env, duration, ts=ts, initial=static.state, solver=config, throw=False)

        result, c, r, ev = timed_with_events(run, args.repeats)
        entry = {
            "study": "segments",
            "segments": n,
            "mass_matrix": "lumped",
            "solver": "Dopri5",
            "duration_s": duration,
            "rtol": args.rtol,
            "steps": int(result.stats["num_steps"]),
            "success": bool(result.success),
            "vector_field_equations": equations,
            "compile_s": c,
            "run_s": r,
            "events": ev,
            "load": load_average(),
        }
        print(json.dumps(entry), flush=True)
        entries.append(entry)
        jax.clear_caches()
    return entries


def solvers_study(args):
    import diffrax
    import jax
    import numpy as np

    import jaxcable as jc
    from jaxcable.examples import anchored_line

    duration = args.duration or 0.5
    n = (args.segments or [20])[0]
    ts = np.linspace(0.0, duration, 5)
    model, env = anchored_line(n, mass_matrix="lumped")
    static = jc.solve_statics(model, env)
    solvers = {
        "Dopri5": diffrax.Dopri5,
        "Tsit5": diffrax.Tsit5,
        "Kvaerno5 + Newton (stiff_solver)": jc.stiff_solver,
        "PicardTrapezoid (3 iterations)": jc.PicardTrapezoid,
    }
    entries = []
    for name, make in solvers.items():
        jax.clear_caches()
        solver = make()

        def run():
            config = jc.SolverConfig(solver, rtol=args.rtol, atol=args.rtol, max_steps=args.max_steps)
            return jc.simulate(model, env, duration, ts=ts, initial=static.state, solver=config, throw=False)

        equations = count_equations(jax.make_jaxpr(run)())
        result, c, r, ev = timed_with_events(run, args.repeats)
        entry = {
            "study": "solvers",
            "solver": name,
            "segments": n,
            "mass_matrix": "lumped",
            "duration_s": duration,
            "rtol": args.rtol,
            "steps": int(result.stats["num_steps"]),
            "success": bool(result.success),
            "program_equations": equations,
            "compile_s": c,
            "run_s": r,
            "events": ev,
            "load": load_average(),
        }
        print(json.dumps(entry), flush=True)
        entries.append(entry)
    jax.clear_caches()
    return entries


def reuse_study(args):
    """Each row is one call after the first: did it compile, and what did it cost."""
    import equinox as eqx
    import jax
    import numpy as np

    import jaxcable as jc
    from jaxcable.examples import anchored_line

    duration = args.duration or 2.0
    n = (args.segments or [10])[0]
    ts = np.linspace(0.0, duration, int(round(duration * 20)) + 1)
    model, env = anchored_line(n, mass_matrix="lumped")
    static = jc.solve_statics(model, env)
    entries = []

    def call(label, what, fn):
        start = len(_EVENTS)
        begin = time.perf_counter()
        out = jax.block_until_ready(fn())
        wall = time.perf_counter() - begin
        entry = {
            "study": "reuse",
            "call": label,
            "changed": what,
            "segments": n,
            "duration_s": duration,
            "wall_s": wall,
            "events": compile_events(start),
            "load": load_average(),
        }
        print(json.dumps(entry), flush=True)
        entries.append(entry)
        return out

    def sim(m=model, rtol=1e-6, atol=1e-6, t1=duration):
        config = jc.SolverConfig(rtol=rtol, atol=atol, max_steps=args.max_steps)
        result = jc.simulate(m, env, t1, ts=ts * (t1 / duration), initial=static.state, solver=config, throw=False)
        return result.tension

    jax.clear_caches()
    call("simulate #1", "first call", sim)
    call("simulate #2", "nothing (warm)", sim)
    call("simulate #3", "rtol 1e-6 → 1e-7", lambda: sim(rtol=1e-7))
    call("simulate #4", "atol 1e-6 → 1e-8", lambda: sim(atol=1e-8))
    call("simulate #5", f"t1 {duration:g} → {duration / 2:g} s (same number of outputs)", lambda: sim(t1=duration / 2))
    stiffer = eqx.tree_at(
        lambda m: m.line.tension_law.axial_stiffness, model, 2 * model.line.tension_law.axial_stiffness
    )
    call("simulate #6", "new model: EA × 2 (same N)", lambda: sim(m=stiffer))

    def build(ea_scale):
        return eqx.tree_at(
            lambda m: m.line.tension_law.axial_stiffness, model, ea_scale * model.line.tension_law.axial_stiffness
        ), env

    batch = 8
    jax.clear_caches()

    def sweep(values):
        return jc.sweep(
            build,
            {"ea_scale": values},
            duration,
            ts=ts,
            initial=static.state,
            solver=jc.SolverConfig(max_steps=args.max_steps),
        ).simulation.tension

    call("sweep #1", f"first call, {batch} cases", lambda: sweep(np.linspace(0.8, 1.2, batch)))
    call("sweep #2", f"new values, {batch} cases", lambda: sweep(np.linspace(0.7, 1.3, batch)))
    call("sweep #3", f"new values again, {batch} cases", lambda: sweep(np.linspace(0.9, 1.1, batch)))
    call("sweep #4", f"{batch // 2} cases (new batch size)", lambda: sweep(np.linspace(0.8, 1.2, batch // 2)))
    call(
        "sweep #5",
        f"rtol 1e-6 → 1e-7, {batch // 2} cases",
        lambda: (
            jc.sweep(
                build,
                {"ea_scale": np.linspace(0.8, 1.2, batch // 2)},
                duration,
                ts=ts,
                initial=static.state,
                solver=jc.SolverConfig(rtol=1e-7, max_steps=args.max_steps),
            ).simulation.tension
        ),
    )
    jax.clear_caches()
    return entries


# --- report -----------------------------------------------------------------------------


def report(path: Path) -> None:
    sessions = json.loads(path.read_text())
    rows = [(s, e) for s in sessions for e in s["entries"]]
    by = lambda study: [(s, e) for s, e in rows if e["study"] == study]  # noqa: E731
    if by("gradient"):
        gradient_tables(by("gradient"))
    if by("segments"):
        print(
            "| N | vector-field equations | steps | compile (s) | trace / lower / XLA (s) | programs "
            "| run (s) | load (1 min) |"
        )
        print("|---|---|---|---|---|---|---|---|")
        for _s, e in by("segments"):
            ev = e["events"]
            print(
                f"| {e['segments']} | {e['vector_field_equations']} | {e['steps']} | {e['compile_s']:.1f} "
                f"| {ev['trace_s']:.1f} / {ev['lower_s']:.1f} / {ev['backend_s']:.1f} | {ev['backend_compiles']} "
                f"| {e['run_s']:.3f} | {e['load'][0]:.1f} |"
            )
        print()
    if by("solvers"):
        print(
            "| solver (N = 20, lumped) | program equations | steps | compile (s) | trace / lower / XLA (s) "
            "| programs | run (s) | load (1 min) |"
        )
        print("|---|---|---|---|---|---|---|---|")
        for _s, e in by("solvers"):
            ev = e["events"]
            print(
                f"| {e['solver']} | {e['program_equations']} | {e['steps']} | {e['compile_s']:.1f} "
                f"| {ev['trace_s']:.1f} / {ev['lower_s']:.1f} / {ev['backend_s']:.1f} | {ev['backend_compiles']} "
                f"| {e['run_s']:.2f} | {e['load'][0]:.1f} |"
            )
        print()
    if by("reuse"):
        print("| call | what changed | XLA compiles | XLA compile (s) | trace (s) | wall (s) | load (1 min) |")
        print("|---|---|---|---|---|---|---|")
        for _s, e in by("reuse"):
            ev = e["events"]
            print(
                f"| {e['call']} | {e['changed']} | {ev['backend_compiles']} | {ev['backend_s']:.2f} "
                f"| {ev['trace_s']:.2f} | {e['wall_s']:.3f} | {e['load'][0]:.1f} |"
            )
        print()


def gradient_tables(rows) -> None:
    print(
        "| mass | N | params | steps | first slack (s) | forward (s) | jacfwd (s) | ratio | reverse (s) | ratio "
        "| compile fwd / jacfwd / rev (s) | load (1 min) | timing |"
    )
    print("|---|---|---|---|---|---|---|---|---|---|---|---|---|")
    for _s, e in rows:
        rev = e["reverse"]["default"]
        loads = [e["load_forward"][0], e["load_jacfwd"][0], rev["load"][0]]
        print(
            f"| {e['mass_matrix']} | {e['segments']} | {len(e['parameters'])} | {e['steps']} "
            f"| {e['first_slack_s']:.2f} | {e['forward_run_s']:.3f} | {e['jacfwd_run_s']:.3f} "
            f"| {e.get('jacfwd_ratio', e['jacfwd_run_s'] / e['forward_run_s']):.2f}× "
            f"| {rev['run_s']:.3f} | {rev.get('ratio', rev['run_s'] / e['forward_run_s']):.2f}× "
            f"| {e['forward_compile_s']:.1f} / {e['jacfwd_compile_s']:.1f} / {rev['compile_s']:.1f} "
            f"| {min(loads):.1f}–{max(loads):.1f} | {e.get('timing', 'blocked')} |"
        )
    print()
    others = [(s, e, label) for s, e in rows for label in e["reverse"] if label != "default"]
    if others:
        print("| mass | N | params | checkpoints | reverse (s) | ratio to forward | compile (s) | load (1 min) |")
        print("|---|---|---|---|---|---|---|---|")
        for _s, e, label in [(s, e, "default") for s, e in rows if len(e["reverse"]) > 1] + others:
            rev = e["reverse"][label]
            shown = f"default (√(2·max_steps) ≈ {int((2 * e['max_steps']) ** 0.5)})" if label == "default" else label
            print(
                f"| {e['mass_matrix']} | {e['segments']} | {len(e['parameters'])} | {shown} | {rev['run_s']:.3f} "
                f"| {rev.get('ratio', rev['run_s'] / e['forward_run_s']):.2f}× | {rev['compile_s']:.1f} | "
                f"{rev['load'][0]:.1f} |"
            )
        print()
    checks = [(s, e, c) for s, e in rows for c in e.get("checks", [])]
    if checks:
        print(
            "| mass | N | params | horizon (s) | parameter | dL/dθ, FD at each step | jacfwd | reverse "
            "| rel. error jacfwd / reverse (vs first FD) | steps |"
        )
        print("|---|---|---|---|---|---|---|---|---|---|")
        for _s, e, c in checks:
            for i in range(c["parameters_checked"]):
                fds = " / ".join(f"{row[i]:.6g} (h={h:g})" for h, row in zip(c["fd_steps"], c["finite_difference"]))
                print(
                    f"| {e['mass_matrix']} | {e['segments']} | {len(e['parameters'])} | {c['horizon_s']:g} "
                    f"| {e['parameters'][i]} | {fds} | {c['jacfwd'][i]:.6g} | {c['reverse'][i]:.6g} "
                    f"| {c['jacfwd_rel_error'][i]:.1e} / {c['reverse_rel_error'][i]:.1e} | {c['check_steps']} |"
                )
        print()


def main():
    args = parse()
    if args.report:
        report(Path(args.out))
        return
    _listen()
    import jax

    jax.config.update("jax_enable_x64", True)  # jaxcable computes in float64 and leaves the switch to us

    study = {"gradient": gradient_study, "segments": segments_study, "reuse": reuse_study, "solvers": solvers_study}[
        args.study
    ]
    load_before = load_average()
    entries = study(args)
    history = append_session(
        args.out,
        study=args.study,
        argv=os.sys.argv[1:],
        load_before=load_before,
        load_after=load_average(),
        repeats=args.repeats,
        compilation_cache_dir=jax.config.jax_compilation_cache_dir,
        entries=entries,
    )
    print()
    _print_session(history[-1])


def _print_session(session) -> None:
    import tempfile

    with tempfile.NamedTemporaryFile("w", suffix=".json", delete=False) as f:
        json.dump([session], f)
    report(Path(f.name))
    os.unlink(f.name)


if __name__ == "__main__":
    main()
