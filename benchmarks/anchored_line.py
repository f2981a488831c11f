"""The anchored line: compile time, run time and peak tension against N.

The line is anchored at 200 m depth at a 30° design angle (m = 3 kg/m, F = 0.0003 m²,
C_n = 15.6, C_τ = 0.78, C_a = 0.4, C_E = 3e7 N, C_E1 = 0.1 C_E) and its top is driven at
T_w = 5.6 s with the anchored-line paper's amplitude law (see `jaxcable.examples.anchored_line`). Each
run starts from static equilibrium. Accuracy is reported against a reference solve of the
same N (Tsit5 at rtol = atol = 1e-9 by default): the relative error of the peak tension and the
largest tension error over the history, relative to the peak.

    python benchmarks/anchored_line.py                       # N = 10, 20, 50, 100; 60 s
    python benchmarks/anchored_line.py --segments 10 20 --duration 10 --solvers tsit5

Results are appended to benchmarks/results/anchored_line.json;
`python benchmarks/anchored_line.py --report` prints them as the table in benchmarks/README.md.
"""

import argparse
import json
from pathlib import Path

import diffrax
import jax
import numpy as np
from _results import append_session
from _timing import timed

import jaxcable as jc
from jaxcable.examples import anchored_line

jax.config.update("jax_enable_x64", True)  # jaxcable computes in float64 and leaves the switch to us

SOLVERS = {
    "default": jc.default_solver,
    "kvaerno5-verychord": lambda: diffrax.Kvaerno5(),
    "kvaerno5-newton": jc.stiff_solver,
    "tsit5": diffrax.Tsit5,
    "dopri5": diffrax.Dopri5,
}


def main():
    parser = argparse.ArgumentParser(description=__doc__, formatter_class=argparse.RawDescriptionHelpFormatter)
    parser.add_argument("--segments", type=int, nargs="+", default=[10, 20, 50, 100])
    parser.add_argument("--duration", type=float, default=60.0)
    parser.add_argument(
        "--solvers", nargs="+", default=["default", "dopri5", "kvaerno5-newton"], choices=sorted(SOLVERS)
    )
    parser.add_argument("--mass-matrix", default="consistent", choices=["consistent", "lumped"])
    parser.add_argument("--rtol", type=float, default=1e-6)
    parser.add_argument("--atol", type=float, default=1e-6)
    parser.add_argument("--repeats", type=int, default=3)
    parser.add_argument("--max-steps", type=int, default=2_000_000)
    parser.add_argument(
        "--reference-rtol",
        type=float,
        default=1e-9,
        help="tolerance of the Tsit5 reference solve that accuracy is measured against",
    )
    parser.add_argument("--no-reference", action="store_true", help="skip the accuracy reference solve")
    parser.add_argument("--out", default=str(Path(__file__).parent / "results" / "anchored_line.json"))
    parser.add_argument("--report", action="store_true", help="print the recorded results as a markdown table")
    args = parser.parse_args()
    if args.report:
        report(Path(args.out))
        return

    ts = np.linspace(0.0, args.duration, int(args.duration * 20) + 1)  # 20 Hz output
    records = []
    for n in args.segments:
        model, env = anchored_line(n, mass_matrix=args.mass_matrix)
        static = jc.solve_statics(model, env)
        reference = None
        if not args.no_reference:
            tight = args.reference_rtol
            config = jc.SolverConfig(diffrax.Tsit5(), rtol=tight, atol=tight, max_steps=args.max_steps)
            reference = jc.simulate(model, env, args.duration, ts=ts, initial=static.state, solver=config)
        for name in args.solvers:
            solver = SOLVERS[name]()

            def run():
                config = jc.SolverConfig(solver, rtol=args.rtol, atol=args.atol, max_steps=args.max_steps)
                return jc.simulate(
                    model,
                    env,
                    args.duration,
                    ts=ts,
                    initial=static.state,
                    solver=config,
                    throw=False,
                )

            result, compile_time, run_time = timed(run, args.repeats)
            tension = np.asarray(result.tension)
            record = {
                "segments": n,
                "solver": name if name != "default" else f"default ({type(solver).__name__})",
                "mass_matrix": args.mass_matrix,
                "rtol": args.rtol,
                "atol": args.atol,
                "duration_s": args.duration,
                "success": bool(result.success),
                "steps": int(result.stats["num_steps"]),
                "rejected_steps": int(result.stats["num_rejected_steps"]),
                "compile_s": compile_time,
                "run_s": run_time,
                "peak_tension_N": float(tension.max()),
                "static_top_tension_N": float(static.tension[-1]),
            }
            if reference is not None:
                ref = np.asarray(reference.tension)
                record["reference_rtol"] = args.reference_rtol
                record["peak_tension_rel_error"] = float(abs(tension.max() - ref.max()) / ref.max())
                record["max_tension_error_rel_peak"] = float(np.max(np.abs(tension - ref)) / ref.max())
            records.append(record)
            print(json.dumps(record), flush=True)

    append_session(args.out, records=records)


def report(path: Path) -> None:
    """Print every recorded run as one markdown table, one row per configuration."""
    print(
        "| N | mass | solver | steps (rejected) | compile (s) | run (s) | peak T (kN) | peak err | max err / peak | "
        "machine |"
    )
    print("|---|---|---|---|---|---|---|---|---|---|")
    for session in json.loads(path.read_text()):
        for r in session["records"]:
            accuracy = (
                f"{100 * r['peak_tension_rel_error']:.2f} % | {100 * r['max_tension_error_rel_peak']:.1f} %"
                if "peak_tension_rel_error" in r
                else "– | –"
            )
            print(
                f"| {r['segments']} | {r['mass_matrix']} | {r['solver']} | {r['steps']} ({r['rejected_steps']}) "
                f"| {r['compile_s']:.1f} | {r['run_s']:.2f} | {r['peak_tension_N'] / 1e3:.1f} | {accuracy} "
                f"| {session['machine'].split(' ', 1)[1]}, {r['duration_s']:.0f} s simulated |"
            )


if __name__ == "__main__":
    main()
