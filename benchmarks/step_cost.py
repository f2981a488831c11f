"""Where a step's time goes: the force evaluation against diffrax's step loop.

On the anchored line (lumped mass, from statics), per segment count N:

- *field*: one evaluation of the vector field (forces, mass solve), timed as 200
  evaluations inside one compiled `fori_loop`, so no dispatch is counted;
- *Euler step*: a fixed-step `diffrax.Euler` run (one evaluation a step), per step:
  the field plus diffrax's loop;
- *Dopri5 step*: the default solver at rtol = atol = 1e-6 (six evaluations a
  step, FSAL), per step, with 1 output time and with 20 Hz output;
- *RK4 step*: one fixed step of `jaxcable.RK4` (four evaluations) on the state layout
  the simulation integrates, timed as 200 steps inside one compiled `fori_loop`,
  through diffrax's general stage loop (`diffrax.AbstractRungeKutta.step`) and with the
  stages written out as jaxcable steps (`jaxcable._solver.explicit.explicit_step`).

The differences say what diffrax's bookkeeping costs against the physics. Times are
medians of warm repeats.

With `--batch B`, the same for a batch of B cases (the anchored line with its top's
amplitude spread over ±10 %), per batch: the field `vmap`ped, Euler and Dopri5 as
`jaxcable.sweep` with `steps="shared"` in one chunk (one core), so a step is the
batch's step.

    python benchmarks/step_cost.py --segments 20 100
    python benchmarks/step_cost.py --segments 20 --batch 128
    python benchmarks/step_cost.py --report

Results are appended to benchmarks/results/step_cost.json.
"""

import argparse
import json
from pathlib import Path

import diffrax
import equinox as eqx
import jax
import numpy as np
from _results import append_session
from _timing import timed

import jaxcable as jc
from jaxcable._simulation.simulate import component_major_field
from jaxcable._solver.explicit import explicit_step
from jaxcable.equations import vector_field
from jaxcable.examples import anchored_line

jax.config.update("jax_enable_x64", True)  # jaxcable computes in float64 and leaves the switch to us

RESULTS = Path(__file__).parent / "results"
EVALUATIONS = 200


def field_seconds(build, parameter, y, repeats, evaluations=EVALUATIONS, batched=False):
    """Seconds for one evaluation of `vector_field(t, y, build(parameter))`, timed as
    `evaluations` of them inside one compiled `fori_loop` (so no dispatch is counted),
    median of `repeats` warm calls; and the compile time (s).

    `y` is the free nodes' (positions, velocities). With `batched`, `parameter` and `y`
    carry a leading case axis and the evaluation is `vmap`ped over it (a batch's time is
    returned); `build` is traced under the `vmap`, so what does not depend on the
    parameter stays unbatched, as in `jaxcable.sweep`.
    """

    def field(t, y, parameter):
        return vector_field(t, y, build(parameter))

    if batched:
        field = jax.vmap(field, in_axes=(None, 0, 0))

    @jax.jit
    def fields(y, parameter):
        def body(i, y):
            velocity, acceleration = field(1e-3 * i, y, parameter)
            # A negligible update keeps each evaluation dependent on the last.
            return (y[0] + 1e-12 * velocity, y[1] + 1e-12 * acceleration)

        return jax.lax.fori_loop(0, evaluations, body, y)

    _, compile_time, run = timed(lambda: fields(y, parameter), repeats)
    return run / evaluations, compile_time


def rk4_step_seconds(build, parameter, y, repeats, batched=False):
    """Seconds for one RK4 step of `dt` = 1 ms on `build(parameter)`, through diffrax's
    stage loop and written out: `(loop, written_out)`, each timed as `EVALUATIONS` steps
    inside one compiled `fori_loop`, median of `repeats` warm calls. `y` is the free
    nodes' `(positions, velocities)`, each `(free, 3)` (with a leading case axis if
    `batched`)."""
    solver, term, dt = jc.RK4(), diffrax.ODETerm(component_major_field), 1e-3
    y = jax.tree.map(lambda a: np.swapaxes(a, -1, -2), y)  # the component-major layout

    def seconds(step):
        def one(y, parameter, i):
            y1, *_ = step(solver, term, i * dt, (i + 1) * dt, y, build(parameter), None, False)
            return y1

        advance = jax.vmap(one, in_axes=(0, 0, None)) if batched else one

        @jax.jit
        def steps(y, parameter):
            return jax.lax.fori_loop(0, EVALUATIONS, lambda i, y: advance(y, parameter, i), y)

        return timed(lambda: steps(y, parameter), repeats)[2] / EVALUATIONS

    return seconds(diffrax.AbstractRungeKutta.step), seconds(explicit_step)


def main():
    parser = argparse.ArgumentParser(description=__doc__, formatter_class=argparse.RawDescriptionHelpFormatter)
    parser.add_argument("--segments", type=int, nargs="+", default=[20, 100])
    parser.add_argument("--duration", type=float, default=3.0, help="simulated time (s) of the Dopri5 runs")
    parser.add_argument("--repeats", type=int, default=5)
    parser.add_argument("--batch", type=int, default=0, help="cases in a batch (0: single runs)")
    parser.add_argument("--out", default=str(RESULTS / "step_cost.json"))
    parser.add_argument("--report", action="store_true")
    args = parser.parse_args()
    if args.report:
        report(Path(args.out))
        return
    rows = []
    for n in args.segments:
        model, env = anchored_line(n, mass_matrix="lumped")
        state = jc.solve_statics(model, env).state
        y = (state.positions[model.free_nodes], state.velocities[model.free_nodes])
        if args.batch:
            top = model.motions[-1]
            scales = np.linspace(0.9, 1.1, args.batch)

            def build(scale):
                return eqx.tree_at(lambda m: m.motions[-1].amplitude, model, top.amplitude * scale), env

            batch_y = tuple(np.broadcast_to(a, (args.batch, *a.shape)) for a in y)
            field, _ = field_seconds(build, scales, batch_y, args.repeats, batched=True)
            rk4_loop, rk4_written = rk4_step_seconds(build, scales, batch_y, args.repeats, batched=True)

            def run(solver, t1, ts, **options):
                config = jc.SolverConfig(solver, **options)
                swept = {"scale": scales}

                def batch():
                    return jc.sweep(build, swept, t1, ts=ts, initial=state, solver=config, steps="shared", chunks=1)

                return lambda: batch().simulation
        else:
            field, _ = field_seconds(lambda _: (model, env), 0.0, y, args.repeats)
            rk4_loop, rk4_written = rk4_step_seconds(lambda _: (model, env), 0.0, y, args.repeats)

            def run(solver, t1, ts, **options):
                config = jc.SolverConfig(solver, **options)
                return lambda: jc.simulate(model, env, t1, ts=ts, initial=state, solver=config, throw=False)

        euler_t1 = 2000 * 1e-5
        euler, _, euler_time = timed(
            run(diffrax.Euler(), euler_t1, [euler_t1], stepsize_controller=diffrax.ConstantStepSize(), dt0=1e-5),
            args.repeats,
        )
        one, _, one_time = timed(run(diffrax.Dopri5(), args.duration, [args.duration]), args.repeats)
        many_ts = np.linspace(0.0, args.duration, int(args.duration * 20) + 1)
        many, _, many_time = timed(run(diffrax.Dopri5(), args.duration, many_ts), args.repeats)
        row = {
            "segments": n,
            "batch": args.batch,
            "field_us": 1e6 * field,
            "euler_step_us": 1e6 * euler_time / int(np.max(euler.stats["num_steps"])),
            "dopri5_step_us_1_output": 1e6 * one_time / int(np.max(one.stats["num_steps"])),
            "dopri5_step_us_20hz": 1e6 * many_time / int(np.max(many.stats["num_steps"])),
            "dopri5_steps": int(np.max(one.stats["num_steps"])),
            "rk4_step_us_stage_loop": 1e6 * rk4_loop,
            "rk4_step_us_written_out": 1e6 * rk4_written,
        }
        print(json.dumps(row), flush=True)
        rows.append(row)
        jax.clear_caches()
    append_session(args.out, repeats=args.repeats, duration=args.duration, rows=rows)
    report(Path(args.out))


def report(path: Path):
    sessions = json.loads(path.read_text())
    print(
        "| N | batch | field (µs) | Euler step (µs) | Euler step − field | Dopri5 step, 1 output (µs) | Dopri5 step, "
        "20 Hz (µs) | Dopri5 step − 6 fields | RK4 step, stage loop / written out (µs) | session |"
    )
    print("|---|---|---|---|---|---|---|---|---|---|")
    for session in sessions:
        for r in session["rows"]:
            print(
                f"| {r['segments']} | {r.get('batch') or 1} | {r['field_us']:.1f} | {r['euler_step_us']:.1f} | "
                f"{r['euler_step_us'] - r['field_us']:.1f} | "
                f"{r['dopri5_step_us_1_output']:.1f} | {r['dopri5_step_us_20hz']:.1f} | "
                f"{r['dopri5_step_us_1_output'] - 6 * r['field_us']:.1f} | {_rk4(r)} | {session['time'][:16]} |"
            )


def _rk4(row: dict) -> str:
    if "rk4_step_us_stage_loop" not in row:  # entries from before the RK4 columns
        return "–"
    return f"{row['rk4_step_us_stage_loop']:.1f} / {row['rk4_step_us_written_out']:.1f}"


if __name__ == "__main__":
    main()
