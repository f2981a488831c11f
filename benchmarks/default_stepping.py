"""How accurate the default fixed steps are: `jc.fixed_steps` (RK4 at 0.7 of its
stability limit, the default of `jc.sweep` and of a scene that names no solver) against a
converged run, beside MoorDyn's own scheme at its usual step and adaptive Dopri5.

Each scene is run over its first `--duration` seconds (3 s: the first snap, before the
first slack event, after which no run's history converges pointwise; see
`benchmarks/README.md`, *Work-precision diagrams*) from statics, saving the top segment's
tension at 100 Hz. The reference is Dopri8 at rtol = atol = 1e-11. Each run's error is
the largest and the RMS difference of that history from the reference's, and the
difference of its peak, all relative to the reference's peak.

Scenes:

- `sweep`: the anchored line as `first_contact.py`'s sweeps run it (20 segments, linear
  EA, lumped mass, MoorDyn's nodal hydrodynamics), the top's amplitude 0.5 m and 3 m
  (the sweep's ends), with 100 Hz output: the default steps end at the output times.
- `scene`: the bundled `anchored_line` scene (20 segments, C_E1 = 0.1 C_E, consistent
  mass), as `jaxcable run anchored_line` runs it with 20 Hz output.

    python benchmarks/default_stepping.py                 # both scenes
    python benchmarks/default_stepping.py --report        # the latest session's table

Sessions are appended to `benchmarks/results/default_stepping.json`.
"""

import argparse
import math
import sys
from pathlib import Path

import numpy as np

sys.path.insert(0, str(Path(__file__).resolve().parent))
from _results import append_session  # noqa: E402

RESULTS = Path(__file__).resolve().parent / "results" / "default_stepping.json"


def scenes(duration: float):
    """`(name, model, env, output interval)` of each scene (module docstring)."""
    import equinox as eqx

    import jaxcable as jc

    for amplitude in (0.5, 3.0):
        model, env = jc.examples.anchored_line(
            n_segments=20, quadratic_ratio=0.0, mass_matrix="lumped", hydrodynamics="nodes"
        )
        top = list(np.asarray(model.constrained_nodes)).index(1)
        model = eqx.tree_at(lambda m: m.motions[top].amplitude, model, amplitude)
        yield f"sweep, amplitude {amplitude:g} m", model, env, 0.01
    built = jc.load_scene(jc.examples.scene_path("anchored_line")).build()
    yield "scene anchored_line", built.model, built.environment, 0.05


def runs(model, env, duration: float, interval: float):
    """`(label, SolverConfig, steps)` of the settings compared (module docstring); the
    default's step is what a run with this output interval takes."""
    import diffrax

    import jaxcable as jc

    default = jc.fixed_steps([(model, env)], duration)
    limit = float(np.asarray(default.dt0))
    substeps = math.ceil(interval / limit * (1 - 1e-9))
    step = interval / substeps

    def fixed(solver, dt):
        return jc.SolverConfig(solver, dt0=dt, stepsize_controller=diffrax.ConstantStepSize())

    yield f"default: RK4 at {step * 1e3:.3g} ms (0.7 of the limit, or less)", fixed(jc.RK4(), step)
    yield "RK4 at half the default's step", fixed(jc.RK4(), step / 2)
    yield "midpoint at 1 ms (MoorDyn's RK2 at its usual dtM)", fixed(diffrax.Midpoint(), 1e-3)
    yield "Dopri5, adaptive, rtol = atol = 1e-6", jc.SolverConfig()


def measure(duration: float) -> list[dict]:
    import diffrax

    import jaxcable as jc

    rows = []
    for name, model, env, interval in scenes(duration):
        ts = np.linspace(0.0, duration, round(duration / interval) + 1)
        static = jc.solve_statics(model, env).state

        def top(config):
            result = jc.simulate(model, env, duration, ts=ts, initial=static, solver=config)
            return np.asarray(result.tension[:, -1]), int(result.stats["num_steps"])

        reference, _ = top(jc.SolverConfig(diffrax.Dopri8(), rtol=1e-11, atol=1e-11))
        peak = float(np.max(reference))
        for label, config in runs(model, env, duration, interval):
            tension, steps = top(config)
            difference = tension - reference
            rows.append(
                {
                    "scene": name,
                    "run": label,
                    "steps": steps,
                    "largest": float(np.max(np.abs(difference)) / peak),
                    "rms": float(np.sqrt(np.mean(difference**2)) / peak),
                    "peak": float(np.max(tension) / peak - 1),
                    "reference_peak_n": peak,
                }
            )
            print(
                f"{name}: {label}: {steps} steps, largest {100 * rows[-1]['largest']:.3f} %, "
                f"RMS {100 * rows[-1]['rms']:.3f} %, peak {100 * rows[-1]['peak']:+.3f} %",
                flush=True,
            )
    return rows


def report(path: Path) -> None:
    import json

    session = json.loads(path.read_text())[-1]
    print(f"Session {session['time']}, commit {session['commit']}, first {session['duration']:g} s")
    print()
    print("| scene | run | steps | largest | RMS | peak |")
    print("|---|---|---|---|---|---|")
    for r in session["rows"]:
        print(
            f"| {r['scene']} | {r['run']} | {r['steps']:,} | {100 * r['largest']:.2f} % | {100 * r['rms']:.2f} % "
            f"| {100 * r['peak']:+.2f} % |"
        )


def main(argv=None) -> None:
    parser = argparse.ArgumentParser(description=__doc__, formatter_class=argparse.RawDescriptionHelpFormatter)
    parser.add_argument("--duration", type=float, default=3.0, help="simulated time (s) compared")
    parser.add_argument("--out", type=Path, default=RESULTS)
    parser.add_argument("--report", action="store_true", help="print the latest session's table")
    args = parser.parse_args(argv)
    if args.report:
        report(args.out)
        return
    import jax

    jax.config.update("jax_enable_x64", True)
    rows = measure(args.duration)
    append_session(args.out, command=" ".join(["python", *sys.argv]), duration=args.duration, rows=rows)
    print()
    report(args.out)


if __name__ == "__main__":
    main()
