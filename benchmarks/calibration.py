"""Calibration cost: a gradient and a whole fit against one forward simulation, and how
both grow with the record's length.

Two record sets, each of synthetic records with 2 % noise (`jaxcable.calibration.synthetic_record`):

- `horizontal`: two tows on `jaxcable.calibration.HorizontalTow` (100 m of the default armoured
    cable in `--segments` segments, EA = 2e6 N, C_v = 5e3 N·s): a 100 kg depressor and a
    light cable on a drogue (the axial-flow case), each stepping 1 -> 2 m/s over 3 s a
    third of the way in. Fits K_n and K_τ.
- `vertical`: three vertical tows on `jaxcable.calibration.VerticalTow` (leader lifts 160, 220 and
    300 N). Fits k₀.

For each record length the script times, on the whole set (records vmapped):

- *forward*: the loss, i.e. one simulation of every record;
- *gradient, forward mode*: the residuals' Jacobian by `jax.jacfwd` with
    `diffrax.ForwardMode` (one tangent per coefficient), which is how `calibrate`
    takes its gradient by default and its uncertainty always;
- *gradient, reverse mode*: `jax.value_and_grad` of the loss through
    `diffrax.RecursiveCheckpointAdjoint`;
- *fit*: a whole `jaxcable.calibrate` from a start 2x off the truth (L-BFGS), with its
    iterations and the error of each recovered coefficient.

Compile time (first call less the median warm call) is reported apart from run time
(median of `--repeats` warm calls). The fit is timed once, compile included, and again
warm.

With `--monte-carlo N`, the fit is repeated on N noise draws of the same records (seeds
100, 110, ...), and the spread of the fitted values is set beside the 1σ that each fit
reports from its Gauss–Newton covariance: the uncertainty is honest if the two agree
and about 95 % of the fits fall within 2σ of the truth. `--linear-draws N` does the
same for many more draws at the cost of one simulation each: the Gauss–Newton step from
the truth, `-(JᵀJ)⁻¹Jᵀr` with the Jacobian at the truth, which is the fit's estimate to
first order (they agreed to 0.02 % on 8 draws), against the sandwich 1σ from each
draw's residuals. `diffrax.BacksolveAdjoint` is not timed: on these models (diffrax 0.7.2) it
raised `TypeError: Argument '()' of type <class 'equinox._tree._DistinctTuple'> is not
a valid JAX type`.

    python benchmarks/calibration.py                          # defaults below
    python benchmarks/calibration.py --lengths 10 20 --repeats 2 --sets vertical
    python benchmarks/calibration.py --lengths 20 --no-fit --monte-carlo 20

Results are appended to benchmarks/results/calibration.json;
`python benchmarks/calibration.py --report` prints them as a markdown table.
"""

import argparse
import json
import math
import time
import warnings
from pathlib import Path

from _results import append_session
from _timing import timed

TRUTH = {"normal_drag": 1.2, "tangential_drag": 0.01, "specific_drag": 0.5}


def parse():
    parser = argparse.ArgumentParser(description=__doc__, formatter_class=argparse.RawDescriptionHelpFormatter)
    parser.add_argument("--sets", nargs="+", choices=["horizontal", "vertical"], default=["horizontal", "vertical"])
    parser.add_argument("--lengths", type=float, nargs="+", default=[15.0, 30.0, 60.0], help="record lengths (s)")
    parser.add_argument("--sample-interval", type=float, default=0.2, help="record sampling interval (s)")
    parser.add_argument("--segments", type=int, default=4)
    parser.add_argument("--repeats", type=int, default=3)
    parser.add_argument("--no-fit", action="store_true", help="time the loss and gradients only")
    parser.add_argument("--monte-carlo", type=int, default=0, help="fits on this many noise draws (0: none)")
    parser.add_argument(
        "--linear-draws", type=int, default=0, help="linearised estimates on this many noise draws (0: none)"
    )
    parser.add_argument("--out", default=str(Path(__file__).parent / "results" / "calibration.json"))
    parser.add_argument("--report", action="store_true", help="print the recorded results as a markdown table")
    return parser.parse_args()


def records_for(name, length, interval, segments, seed=0):
    import numpy as np

    from jaxcable.calibration import HorizontalTow, VerticalTow, synthetic_record

    times = np.arange(0.0, length + interval / 2, interval)
    if name == "vertical":
        rigs = [VerticalTow(leader_lift=lift) for lift in (160.0, 220.0, 300.0)]
        records = [synthetic_record(r, times, seed=seed + k, name=f"lift {k}") for k, r in enumerate(rigs)]
        return records, ("specific_drag",)
    small = dict(cable_length=100.0, segments=segments, cable_axial_stiffness=2e6, cable_axial_damping=5e3)
    neutral = 1025.0 * math.pi * 0.0173**2 / 4
    rigs = [
        HorizontalTow(**small, end_mass=100.0, end_volume=0.015, end_drag_area=0.1),
        HorizontalTow(
            **small, cable_mass_per_length=1.05 * neutral, end_mass=2.0, end_volume=0.0015, end_drag_area=0.05
        ),
    ]
    speed = np.interp(times, [0.0, length / 3, length / 3 + 3.0, length], [1.0, 1.0, 2.0, 2.0])
    records = [synthetic_record(r, times, {"speed": speed}, seed=seed + k, name=f"tow {k}") for k, r in enumerate(rigs)]
    return records, ("normal_drag", "tangential_drag")


def main():
    args = parse()
    if args.report:
        report(Path(args.out))
        return
    import diffrax
    import equinox as eqx
    import jax
    import numpy as np

    import jaxcable as jc
    from jaxcable._calibration import problem as _problem

    jax.config.update("jax_enable_x64", True)  # jaxcable computes in float64 and leaves the switch to us

    entries = []
    for name in args.sets:
        for length in args.lengths:
            records, names = records_for(name, length, args.sample_interval, args.segments)
            problem, _ = _problem.fitting_problem(records, names, jc.calibration.calibration_solver())
            start = np.log(np.array([2 * TRUTH[n] for n in names]))
            loss = eqx.filter_jit(problem.loss)
            # The solver's adjoint is calibrate's gradient mode.
            reverse = eqx.tree_at(lambda p: p.solver.adjoint, problem, diffrax.RecursiveCheckpointAdjoint())
            _, forward_compile, forward_run = timed(lambda: loss(start), args.repeats)
            _, jac_compile, jac_run = timed(lambda: _problem.evaluate(start, problem), args.repeats)
            _, rev_compile, rev_run = timed(lambda: _problem.evaluate(start, reverse), args.repeats)
            steps = [int(np.max(s.simulation.stats["num_steps"])) for s in _steps(problem, start)]
            entry = {
                "set": name,
                "records": len(records),
                "length_s": length,
                "samples": int(sum(r.times.size for r in records)),
                "segments": args.segments if name == "horizontal" else 1,
                "coefficients": list(names),
                "max_steps_per_record": max(steps),
                "forward_compile_s": forward_compile,
                "forward_run_s": forward_run,
                "jacfwd_compile_s": jac_compile,
                "jacfwd_run_s": jac_run,
                "reverse_compile_s": rev_compile,
                "reverse_run_s": rev_run,
            }
            if not args.no_fit:
                for label in ("fit_first", "fit_warm"):
                    begin = time.perf_counter()
                    with warnings.catch_warnings():
                        warnings.simplefilter("ignore")
                        result = jc.calibrate(records, {n: 2 * TRUTH[n] for n in names}, progress=False)
                    entry[f"{label}_s"] = time.perf_counter() - begin
                entry["fit_iterations"] = result.iterations
                entry["fit_converged"] = result.converged
                entry["fitted"] = result.values
                entry["error_percent"] = {n: 100 * (result.values[n] / TRUTH[n] - 1) for n in names}
                entry["sigma_percent"] = {n: 100 * result.relative_uncertainty[n] for n in names}
            if args.monte_carlo:
                entry["monte_carlo"] = monte_carlo(name, length, args, names)
            if args.linear_draws:
                entry["linear_draws"] = linear_draws(name, length, args, names)
            entries.append(entry)
            print(json.dumps(entry), flush=True)
            # Each configuration compiles its own programs; free them, or their code's
            # memory maps pile up past the kernel's limit (65,530) within a few lengths.
            jax.clear_caches()

    history = append_session(args.out, repeats=args.repeats, entries=entries)
    print()
    print_table(history[-1:])


def monte_carlo(name, length, args, names):
    """Fit `args.monte_carlo` noise draws; per coefficient, the mean and standard
    deviation of the error (%), the mean reported 1σ (%), and the share of fits within
    2 reported σ of the truth."""
    import numpy as np

    import jaxcable as jc

    errors, sigmas = [], []
    for draw in range(args.monte_carlo):
        records, _ = records_for(name, length, args.sample_interval, args.segments, seed=100 + 10 * draw)
        with warnings.catch_warnings():
            warnings.simplefilter("ignore")
            result = jc.calibrate(records, {n: 2 * TRUTH[n] for n in names}, progress=False)
        errors.append([result.values[n] / TRUTH[n] - 1 for n in names])
        sigmas.append([result.relative_uncertainty[n] for n in names])
    errors, sigmas = 100 * np.array(errors), 100 * np.array(sigmas)
    return {
        n: {
            "draws": args.monte_carlo,
            "error_mean_percent": float(errors[:, i].mean()),
            "error_std_percent": float(errors[:, i].std(ddof=1)),
            "reported_sigma_mean_percent": float(sigmas[:, i].mean()),
            "within_2_sigma": float(np.mean(np.abs(errors[:, i]) <= 2 * sigmas[:, i])),
        }
        for i, n in enumerate(names)
    }


def linear_draws(name, length, args, names):
    """The linearised Monte Carlo of the module's docstring: per coefficient, the mean
    and standard deviation of the first-order error (%), the mean sandwich 1σ (%), and
    the share within 2σ."""
    import equinox as eqx
    import numpy as np

    import jaxcable as jc
    from jaxcable._calibration import problem as _problem

    truth = np.log(np.array([TRUTH[n] for n in names]))
    records, _ = records_for(name, length, args.sample_interval, args.segments, seed=100)
    problem, _ = _problem.fitting_problem(records, names, jc.calibration.calibration_solver())
    _, _, (jacobian, _, _) = _problem.evaluate(truth, problem)
    jacobian = np.asarray(jacobian)
    inner = np.linalg.inv(jacobian.T @ jacobian)
    blocks = problem.groups[0].times.shape[1]  # samples per series: every record is equally long here
    residuals_at = eqx.filter_jit(lambda p: p.residuals(truth)[0])
    errors, sigmas = [], []
    for draw in range(args.linear_draws):
        records, _ = records_for(name, length, args.sample_interval, args.segments, seed=100 + 10 * draw)
        problem, _ = _problem.fitting_problem(records, names, jc.calibration.calibration_solver())
        r = np.asarray(residuals_at(problem))
        noise = np.repeat(np.sqrt(np.mean(r.reshape(-1, blocks) ** 2, axis=1)), blocks)
        noisy = jacobian * noise[:, None]
        errors.append(-inner @ jacobian.T @ r)
        sigmas.append(np.sqrt(np.diag(inner @ noisy.T @ noisy @ inner)))
    errors, sigmas = 100 * np.array(errors), 100 * np.array(sigmas)
    return {
        n: {
            "draws": args.linear_draws,
            "error_mean_percent": float(errors[:, i].mean()),
            "error_std_percent": float(errors[:, i].std(ddof=1)),
            "reported_sigma_mean_percent": float(sigmas[:, i].mean()),
            "within_2_sigma": float(np.mean(np.abs(errors[:, i]) <= 2 * sigmas[:, i])),
        }
        for i, n in enumerate(names)
    }


def _steps(problem, log_values):
    """Each group's runs at `log_values`, for their step counts."""
    import jax
    import jax.numpy as jnp

    values = dict(zip(problem.names, jnp.exp(log_values)))
    return [
        jax.vmap(lambda rig, t, i: rig.with_coefficients(values).simulate(t, i, problem.solver))(
            g.rigs, g.times, g.inputs
        )
        for g in problem.groups
    ]


def report(path: Path) -> None:
    """Print every recorded session as one markdown table."""
    print_table(json.loads(path.read_text()))


def print_table(sessions) -> None:
    print(
        "| set | records × length (s) | steps | forward (s) | jacfwd (s) | ratio | reverse (s) | ratio "
        "| compile fwd / jacfwd / rev (s) | fit (s) | fit / forward | iterations | error (%) | ±1σ (%) | device |"
    )
    print("|---|---|---|---|---|---|---|---|---|---|---|---|---|---|---|")
    for session in sessions:
        device = session["devices"][0] if session["devices"] else "?"
        for e in session["entries"]:
            fit = e.get("fit_warm_s")
            errors = ", ".join(f"{k} {v:+.2f}" for k, v in e.get("error_percent", {}).items())
            sigmas = ", ".join(f"{v:.2f}" for v in e.get("sigma_percent", {}).values())
            print(
                f"| {e['set']} | {e['records']} × {e['length_s']:g} | {e['max_steps_per_record']} "
                f"| {e['forward_run_s']:.3f} | {e['jacfwd_run_s']:.3f} | {e['jacfwd_run_s'] / e['forward_run_s']:.2f}× "
                f"| {e['reverse_run_s']:.3f} | {e['reverse_run_s'] / e['forward_run_s']:.2f}× "
                f"| {e['forward_compile_s']:.1f} / {e['jacfwd_compile_s']:.1f} / {e['reverse_compile_s']:.1f} "
                + (
                    f"| {fit:.1f} | {fit / e['forward_run_s']:.0f}× | {e['fit_iterations']} | {errors} | {sigmas} "
                    if fit is not None
                    else "| – | – | – | – | – "
                )
                + f"| {device} |"
            )
    carlo = [
        (e, n, m, kind)
        for s in sessions
        for e in s["entries"]
        for kind in ("monte_carlo", "linear_draws")
        for n, m in e.get(kind, {}).items()
    ]
    if carlo:
        print()
        print(
            "| set | length (s) | coefficient | estimate | draws | mean error (%) | std of error (%) "
            "| mean reported 1σ (%) | within 2σ |"
        )
        print("|---|---|---|---|---|---|---|---|---|")
        for e, n, m, kind in carlo:
            estimate = "fit" if kind == "monte_carlo" else "linearised"
            print(
                f"| {e['set']} | {e['length_s']:g} | {n} | {estimate} | {m['draws']} | {m['error_mean_percent']:+.3f} "
                f"| {m['error_std_percent']:.3f} | {m['reported_sigma_mean_percent']:.3f} "
                f"| {100 * m['within_2_sigma']:.0f} % |"
            )


if __name__ == "__main__":
    main()
