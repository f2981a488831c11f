"""What an implicit step costs against the node count, with the structured Jacobian
(`jaxcable.NetworkJacobian`: coloured JVPs and a block-tridiagonal factorisation) and
without it (diffrax's dense Jacobian and LU).

The anchored line with lumped mass, from static equilibrium (interpolated from 300
segments' above that), for each N:

- *solve*: one linear solve of an implicit stage, `(h γ J − I) Δ = r` with the
  Jacobian built afresh (what each Newton iteration does), at h γ = dt;
- *step*: the cost per step of `steps` fixed steps of Kvaerno5 with a Newton root
  finder (a new Jacobian every iteration), dt = 1 ms by default, and of Kvaerno5 with
  diffrax's VeryChord (one Jacobian per step), at root tolerances `--root-tolerance`
  (1e-6 by default). A run whose root finder fails stops
  early; its time per step is reported as a failure.

Times are medians of warm repeats, compile time apart.

    python benchmarks/implicit_scaling.py                          # N = 10 … 1000
    python benchmarks/implicit_scaling.py --segments 10 100 --dense-up-to 100
    python benchmarks/implicit_scaling.py --report

Results are appended to benchmarks/results/implicit_scaling.json; the chart is
benchmarks/results/implicit_scaling.png.
"""

import argparse
import json
from pathlib import Path

import diffrax
import jax
import jax.numpy as jnp
import lineax as lx
import numpy as np
import optimistix as optx
from _results import append_session
from _timing import timed

import jaxcable as jc
from jaxcable.equations import vector_field
from jaxcable.examples import anchored_line

jax.config.update("jax_enable_x64", True)  # jaxcable computes in float64 and leaves the switch to us

RESULTS = Path(__file__).parent / "results"


def stage_solve(model, env, state, linear_solver, h=1e-3):
    """A jitted function solving one implicit stage's linear system from scratch."""
    free = model.free_nodes
    y = (state.positions[free], state.velocities[free])
    rhs = jax.tree.map(jnp.ones_like, y)

    @jax.jit
    def solve(y, rhs):
        def fn(k, args):
            moved = jax.tree.map(lambda a, b: a + h * b, y, k)
            return jax.tree.map(lambda f, b: h * f - b, vector_field(0.0, moved, (model, env)), k)

        operator = lx.JacobianLinearOperator(fn, jax.tree.map(jnp.zeros_like, y), None)
        return lx.linear_solve(operator, rhs, linear_solver).value

    return lambda: solve(y, rhs)


def equilibrium(n: int, statics_up_to: int) -> jc.State:
    """The anchored line of `n` segments at rest in (or near) equilibrium. Above
    `statics_up_to` segments the statics' dense solve costs minutes, so the shape of
    the `statics_up_to`-segment equilibrium is interpolated along the line instead:
    a state within the coarse line's discretisation error of equilibrium, which is
    all a step's cost needs."""
    coarse = min(n, statics_up_to)
    model, env = anchored_line(coarse, mass_matrix="lumped")
    positions = np.asarray(jc.solve_statics(model, env).state.positions)
    if coarse == n:
        return jc.State(positions, np.zeros_like(positions))
    # Nodes 0 and 1 are the anchor and the fairlead; 2, 3, ... run between them.
    chain = positions[[0, *range(2, coarse + 1), 1]]
    along = np.linspace(0.0, 1.0, n + 1)
    fine = np.stack([np.interp(along, np.linspace(0.0, 1.0, coarse + 1), chain[:, k]) for k in range(3)], axis=1)
    fine = fine[[0, n, *range(1, n)]]
    return jc.State(fine, np.zeros_like(fine))


def root_finder(name, tolerance, linear_solver):
    # Too tight a tolerance and the iterations stall on rounding (the stiff springs
    # scale the stage residual: at N = 100 below 1e-6, at N = 1000 below 1e-4) until
    # diffrax's cap of 10 root-find steps.
    options = dict(rtol=tolerance, atol=tolerance, linear_solver=linear_solver)
    return optx.Newton(**options) if name == "newton" else diffrax.VeryChord(**options)


def main():
    parser = argparse.ArgumentParser(description=__doc__, formatter_class=argparse.RawDescriptionHelpFormatter)
    parser.add_argument("--segments", type=int, nargs="+", default=[10, 30, 100, 300, 1000])
    parser.add_argument("--dense-up-to", type=int, default=300, help="largest N run with the dense Jacobian")
    parser.add_argument("--steps", type=int, default=20, help="fixed implicit steps per timed run")
    parser.add_argument("--dt", type=float, default=1e-3, help="the fixed step (s), and h γ of the linear solve")
    parser.add_argument("--root-tolerance", type=float, default=1e-6, help="the root finder's rtol and atol")
    parser.add_argument(
        "--statics-up-to", type=int, default=300, help="larger N start from this N's equilibrium, interpolated"
    )
    parser.add_argument("--repeats", type=int, default=3)
    parser.add_argument("--out", default=str(RESULTS / "implicit_scaling.json"))
    parser.add_argument("--report", action="store_true")
    args = parser.parse_args()
    if args.report:
        report(Path(args.out))
        return

    rows = []
    for n in args.segments:
        model, env = anchored_line(n, mass_matrix="lumped")
        state = equilibrium(n, args.statics_up_to)
        for jacobian in ("structured", "dense"):
            if jacobian == "dense" and n > args.dense_up_to:
                continue
            linear = jc.NetworkJacobian(model) if jacobian == "structured" else lx.LU()
            _, compile_solve, solve = timed(stage_solve(model, env, state, linear, args.dt), args.repeats)
            row = {"segments": n, "jacobian": jacobian, "solve_s": solve, "solve_compile_s": compile_solve}
            for name in ("newton", "verychord"):
                solver = diffrax.Kvaerno5(root_finder=root_finder(name, args.root_tolerance, linear))
                config = jc.SolverConfig(solver, dt0=args.dt, stepsize_controller=diffrax.ConstantStepSize())

                def run():
                    return jc.simulate(
                        model,
                        env,
                        args.steps * args.dt,
                        ts=[args.steps * args.dt],
                        initial=state,
                        solver=config,
                        throw=False,
                    )

                result, compile_step, run_time = timed(run, args.repeats)
                row[f"{name}_step_s"] = run_time / args.steps
                row[f"{name}_compile_s"] = compile_step
                row[f"{name}_success"] = bool(result.success)
            print(json.dumps(row), flush=True)
            rows.append(row)
            jax.clear_caches()
    append_session(
        args.out, steps=args.steps, dt=args.dt, root_tolerance=args.root_tolerance, repeats=args.repeats, rows=rows
    )
    report(Path(args.out))


def report(path: Path):
    sessions = json.loads(path.read_text())
    print(
        "| N | Jacobian | linear solve (ms) | Kvaerno5 + Newton step (ms) | Kvaerno5 + VeryChord step (ms) | compile "
        "solve / Newton / VeryChord (s) | session, step, root tolerance |"
    )
    print("|---|---|---|---|---|---|---|")
    for session in sessions:
        for r in session["rows"]:
            print(
                f"| {r['segments']} | {r['jacobian']} | {1e3 * r['solve_s']:.2f} | {_step(r, 'newton')} | "
                f"{_step(r, 'verychord')} | {r['solve_compile_s']:.1f} / {r['newton_compile_s']:.1f} / "
                f"{r['verychord_compile_s']:.1f} | {session['time'][11:16]}, dt {session.get('dt', 1e-3):g} s, "
                f"tol {session.get('root_tolerance', 1e-6):g} |"
            )
    latest = sessions[-1]["rows"]
    print(
        f"latest session: dt = {sessions[-1].get('dt', 1e-3)} s, root tolerance "
        f"{sessions[-1].get('root_tolerance', 1e-6)}"
    )
    for jacobian in ("structured", "dense"):
        by_n = {r["segments"]: r for r in latest if r["jacobian"] == jacobian}
        if 100 in by_n and 1000 in by_n:
            for key in ("solve", "newton", "verychord"):
                if all(_ok(by_n[n], key) for n in (100, 1000)):
                    print(
                        f"{jacobian}: {key} at N = 1000 / N = 100 = "
                        f"{_time(by_n[1000], key) / _time(by_n[100], key):.1f}"
                    )
    # The chart shows the broadest session (the most N, both Jacobians) and the latest.
    broadest = max(sessions, key=lambda session: len(session["rows"]))
    plot([broadest] if broadest is sessions[-1] else [broadest, sessions[-1]])


def _ok(row, key):
    return key == "solve" or row[f"{key}_success"]


def _time(row, key):
    return row["solve_s"] if key == "solve" else row[f"{key}_step_s"]


def _step(row, key):
    """A step's cost (ms), or the failure: a fixed-step run whose root finder failed
    stopped early, so its time per step means nothing."""
    return f"{1e3 * row[f'{key}_step_s']:.2f}" if row[f"{key}_success"] else "failed (root finder)"


def plot(sessions):
    import matplotlib

    matplotlib.use("Agg")
    import matplotlib.pyplot as plt

    fig, ax = plt.subplots(figsize=(7.5, 5.5))
    styles = {"structured": "-", "dense": "--"}
    keys = (("solve", "o", "linear solve"), ("newton", "s", "Newton step"), ("verychord", "^", "VeryChord step"))
    for index, session in enumerate(sessions):
        setting = f"dt {session.get('dt', 1e-3):g} s, tol {session.get('root_tolerance', 1e-6):g}"
        for jacobian, style in styles.items():
            chosen = sorted((r for r in session["rows"] if r["jacobian"] == jacobian), key=lambda r: r["segments"])
            for (key, marker, label), colour in zip(keys, ("C0", "C1", "C2") if index == 0 else ("C3", "C4", "C5")):
                ok = [r for r in chosen if _ok(r, key)]
                if ok:
                    ax.loglog(
                        [r["segments"] for r in ok],
                        [1e3 * _time(r, key) for r in ok],
                        style,
                        color=colour,
                        marker=marker,
                        label=f"{label}, {jacobian} ({setting})",
                    )
    n = np.array([10, 1000])
    ax.loglog(n, 0.05 * n, ":", color="grey", label="∝ N")
    ax.loglog(n, 0.05 * (n / 10) ** 3, "-.", color="grey", label="∝ N³")
    ax.set_xlabel("segments N")
    ax.set_ylabel("wall time (ms)")
    ax.set_title("Implicit steps on the anchored line (lumped mass)")
    ax.legend(fontsize=7)
    fig.tight_layout()
    fig.savefig(RESULTS / "implicit_scaling.png", dpi=120)


if __name__ == "__main__":
    main()
