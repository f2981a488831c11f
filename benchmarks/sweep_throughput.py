"""Sweep throughput: cases per second of one vmapped, compiled sweep against batch size,
and against a Python loop of single `simulate` runs.

The model is the anchored line (`jaxcable.examples.anchored_line`; 200 m depth,
30°, C_E = 3e7 N, C_E1 = 0.1 C_E, top driven at T_w = 5.6 s), swept over one float
parameter:

- `amplitude`: the fairlead amplitude A, from 0.5 to 1.5 times the anchored-line paper's 1.573 m,
    replaced in a prebuilt model with `eqx.tree_at`. Larger motions snap harder and
    take more steps, so the cases of a batch differ in cost, as real sweeps do.
- `quadratic_ratio`: C_E1 / C_E from 0 to 0.2, rebuilding the line with
    `anchored_line(quadratic_ratio=...)` inside the sweep. The cases take nearly equal
    step counts.

Each case starts from its static equilibrium (`--initial statics`, solved inside the
batch; the loop calls `solve_statics` then `simulate`) or from rest. The loop is
compiled once, so it measures each run's dispatch and solve. Times: *compile* is the
first call's time less the median warm call; *run* is the median of `--repeats` warm
calls, each ended by `jax.block_until_ready`.

    python benchmarks/sweep_throughput.py                        # defaults below
    python benchmarks/sweep_throughput.py --batch-sizes 1 4 16 --duration 2 --repeats 2
    python benchmarks/sweep_throughput.py --host-devices 2 --batch-sizes 2 8   # 2 CPU devices

Results are appended to benchmarks/results/sweep_throughput.json;
`python benchmarks/sweep_throughput.py --report` prints them as a markdown table.
"""

import argparse
import json
import os
from pathlib import Path

from _results import append_session
from _timing import timed

PARAMETERS = ("amplitude", "quadratic_ratio")


def parse():
    parser = argparse.ArgumentParser(description=__doc__, formatter_class=argparse.RawDescriptionHelpFormatter)
    parser.add_argument("--segments", type=int, default=10)
    parser.add_argument("--duration", type=float, default=4.0, help="simulated time per case (s)")
    parser.add_argument("--batch-sizes", type=int, nargs="+", default=[1, 2, 4, 8, 16, 32])
    parser.add_argument("--loop-cases", type=int, default=8, help="single runs timed in the Python loop (0: none)")
    parser.add_argument("--parameter", choices=PARAMETERS, default="amplitude")
    parser.add_argument("--initial", choices=["statics", "rest"], default="statics")
    parser.add_argument("--steps", choices=["per_case", "shared"], default="per_case", help="the sweep's steps")
    parser.add_argument("--chunks", type=int, default=None, help="the sweep's chunks (default: one per core on a CPU)")
    parser.add_argument("--mass-matrix", choices=["consistent", "lumped"], default="consistent")
    parser.add_argument("--rtol", type=float, default=1e-6)
    parser.add_argument("--atol", type=float, default=1e-6)
    parser.add_argument("--max-steps", type=int, default=200_000)
    parser.add_argument("--repeats", type=int, default=3)
    parser.add_argument(
        "--host-devices",
        type=int,
        default=None,
        help="on CPU, split the host into this many JAX devices (sets XLA_FLAGS). With as "
        "many devices as cores, large batches deadlocked in jaxlib's batched LU, since replaced "
        "by a closed-form 3x3 inverse: on 2 cores, 32 cases over 2 devices hung",
    )
    parser.add_argument("--out", default=str(Path(__file__).parent / "results" / "sweep_throughput.json"))
    parser.add_argument("--report", action="store_true", help="print the recorded results as a markdown table")
    return parser.parse_args()


def main():
    args = parse()
    if args.report:
        report(Path(args.out))
        return
    if args.host_devices:
        # Read when jax initialises its backends: set before jax is imported.
        os.environ["XLA_FLAGS"] = (
            os.environ.get("XLA_FLAGS", "") + f" --xla_force_host_platform_device_count={args.host_devices}"
        )

    import equinox as eqx
    import jax
    import numpy as np

    import jaxcable as jc
    from jaxcable import sweep
    from jaxcable.examples import anchored_line, floater_amplitude

    jax.config.update("jax_enable_x64", True)  # jaxcable computes in float64 and leaves the switch to us

    base_model, env = anchored_line(args.segments, mass_matrix=args.mass_matrix)
    fairlead = int(np.flatnonzero(np.asarray(base_model.constrained_nodes) == 1)[0])

    if args.parameter == "amplitude":

        def build(amplitude):
            model = eqx.tree_at(lambda m: m.motions[fairlead].amplitude, base_model, amplitude)
            return model, env

        def values(n):
            return floater_amplitude() * np.linspace(0.5, 1.5, n)
    else:

        def build(quadratic_ratio):
            return anchored_line(args.segments, quadratic_ratio=quadratic_ratio, mass_matrix=args.mass_matrix)

        def values(n):
            return np.linspace(0.0, 0.2, n)

    ts = np.linspace(0.0, args.duration, int(args.duration * 20) + 1)  # 20 Hz output
    options = dict(ts=ts, solver=jc.SolverConfig(rtol=args.rtol, atol=args.atol, max_steps=args.max_steps))
    settings = {
        "segments": args.segments,
        "mass_matrix": args.mass_matrix,
        "parameter": args.parameter,
        "initial": args.initial,
        "duration_s": args.duration,
        "rtol": args.rtol,
        "atol": args.atol,
        "solver": type(jc.default_solver()).__name__,
        "n_devices": len(jax.devices()),
        "steps": args.steps,
        "chunks": args.chunks,
    }
    records = []

    def record(mode, batch, compile_time, run_time, steps, success):
        entry = {
            **settings,
            "mode": mode,
            "batch": batch,
            "compile_s": compile_time,
            "run_s": run_time,
            "cases_per_s": batch / run_time,
            "steps_max": int(np.max(steps)),
            "steps_mean": float(np.mean(steps)),
            "all_successful": bool(np.all(success)),
        }
        records.append(entry)
        print(json.dumps(entry), flush=True)

    for batch in args.batch_sizes:
        parameters = {args.parameter: values(batch)}

        def run():
            return sweep(
                build, parameters, args.duration, initial=args.initial, steps=args.steps, chunks=args.chunks, **options
            )

        result, compile_time, run_time = timed(run, args.repeats)
        record("sweep", batch, compile_time, run_time, result.simulation.stats["num_steps"], result.success)

    if args.loop_cases:
        # The same cases as a sweep of `--loop-cases`, one `simulate` (and `solve_statics`)
        # call each; every call after the first reuses the compiled solve.
        cases = [build(v) for v in values(args.loop_cases)]

        def loop():
            results = []
            for model, case_env in cases:
                start = jc.solve_statics(model, case_env).state if args.initial == "statics" else None
                results.append(jc.simulate(model, case_env, args.duration, initial=start, throw=False, **options))
            return results

        results, compile_time, run_time = timed(loop, args.repeats)
        steps = [int(r.stats["num_steps"]) for r in results]
        record("loop", args.loop_cases, compile_time, run_time, steps, [bool(r.success) for r in results])

    history = append_session(args.out, records=records)
    print()
    print_table(history[-1:])


def report(path: Path) -> None:
    """Print every recorded session as one markdown table."""
    print_table(json.loads(path.read_text()))


def print_table(sessions) -> None:
    print(
        "| mode | cases | devices | N | mass | parameter | initial | simulated (s) | steps max (mean) "
        "| compile (s) | run (s) | cases/s | vs loop | machine |"
    )
    print("|---|---|---|---|---|---|---|---|---|---|---|---|---|---|")
    for session in sessions:
        loops = {
            (r["segments"], r["mass_matrix"], r["parameter"], r["initial"], r["duration_s"]): r["cases_per_s"]
            for r in session["records"]
            if r["mode"] == "loop"
        }
        for r in session["records"]:
            key = (r["segments"], r["mass_matrix"], r["parameter"], r["initial"], r["duration_s"])
            speedup = f"{r['cases_per_s'] / loops[key]:.2f}×" if key in loops else "–"
            failed = "" if r["all_successful"] else " (failures)"
            shared = ", shared steps" if r.get("steps") == "shared" and r["mode"] == "sweep" else ""
            if r["mode"] == "sweep" and "chunks" in r:
                shared += f", {r['chunks'] or 'default'} chunk{'' if r['chunks'] == 1 else 's'}"
            print(
                f"| {r['mode']}{shared}{failed} | {r['batch']} | {r['n_devices']} | {r['segments']} "
                f"| {r['mass_matrix']} "
                f"| {r['parameter']} | {r['initial']} | {r['duration_s']:g} "
                f"| {r['steps_max']} ({r['steps_mean']:.0f}) | {r['compile_s']:.1f} | {r['run_s']:.3f} "
                f"| {r['cases_per_s']:.2f} | {speedup} | {session['machine'].split(' ', 1)[1]} |"
            )


if __name__ == "__main__":
    main()
