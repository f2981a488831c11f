"""Calibration against a model it does not use: records made at finer segmentation (or a
tighter tolerance) than the fit, and what the fit, its residual checks and its
discretisation check say about them.

- `horizontal`: the depressor and the drogue tows of `benchmarks/calibration.py`
    (100 m cable, 1 -> 2 m/s step, 151 samples over 30 s), recorded at `--fine` segments
    and rtol = atol = 1e-8, fitted with 4 segments from 2x the truth (K_n = 1.2,
    K_τ = 0.01). With `--refit`, the fit is repeated at 8 segments, to set the
    discretisation check's linearised move beside a real one.
- `vertical`: three vertical tows recorded at rtol = atol = 1e-10 and fitted at the
    default 1e-6 (k₀ = 0.5 s²/m²).

Prints each coefficient's error, reported 1σ and its widening, each series' residual
check, the discretisation check and the times (records, fit, check), compile included.

    JAX_ENABLE_X64=1 python -m validation.calibration_hidden_truth horizontal --noise 0.02 --refit
"""

import argparse
import time
import warnings

import numpy as np

import jaxcable as jc
from jaxcable.calibration import HorizontalTow, VerticalTow, discretisation_check, rig_solver, synthetic_record

TRUTH = {"normal_drag": 1.2, "tangential_drag": 0.01, "specific_drag": 0.5}
TIMES = np.linspace(0.0, 30.0, 151)
STEP_UP = np.interp(TIMES, [0.0, 10.0, 13.0, 30.0], [1.0, 1.0, 2.0, 2.0])
NEUTRAL = 1025.0 * np.pi * 0.0173**2 / 4  # kg/m: the cable's displaced mass


CABLE = dict(cable_length=100.0, cable_axial_stiffness=2e6, cable_axial_damping=5e3)


def depressor(segments: int) -> HorizontalTow:
    return HorizontalTow(**CABLE, segments=segments, end_mass=100.0, end_volume=0.015, end_drag_area=0.1)


def drogue(segments: int) -> HorizontalTow:
    return HorizontalTow(
        **CABLE,
        segments=segments,
        cable_mass_per_length=1.05 * NEUTRAL,
        end_mass=2.0,
        end_volume=0.0015,
        end_drag_area=0.05,
    )


def _fit(pairs, start):
    with warnings.catch_warnings():
        warnings.simplefilter("ignore")  # printed from the result
        return jc.calibrate(pairs, start, progress=False)


def main():
    parser = argparse.ArgumentParser(description=__doc__, formatter_class=argparse.RawDescriptionHelpFormatter)
    parser.add_argument("case", choices=("horizontal", "vertical"))
    parser.add_argument("--fine", type=int, default=12, help="segments of the model that makes horizontal records")
    parser.add_argument("--noise", type=float, default=0.02, help="relative noise of the records")
    parser.add_argument("--refit", action="store_true", help="also fit at 8 segments (horizontal)")
    args = parser.parse_args()

    began = time.perf_counter()
    if args.case == "horizontal":
        reference = rig_solver(rtol=1e-8, atol=1e-8, max_steps=1_000_000)
        pairs = [
            (make(4), synthetic_record(make(args.fine), TIMES, {"speed": STEP_UP}, noise=args.noise, seed=30 + k,
                                       name=make.__name__, solver=reference))
            for k, make in enumerate((depressor, drogue))
        ]  # fmt: skip
        start = {"normal_drag": 2.4, "tangential_drag": 0.02}
    else:
        reference = rig_solver(rtol=1e-10, atol=1e-10)
        times = np.linspace(0.0, 20.0, 101)
        pairs = [
            (VerticalTow(leader_lift=lift), synthetic_record(VerticalTow(leader_lift=lift), times, noise=args.noise,
                                                             seed=40 + k, name=f"{lift:g} N", solver=reference))
            for k, lift in enumerate((160.0, 220.0, 300.0))
        ]  # fmt: skip
        start = {"specific_drag": 1.0}
    recorded = time.perf_counter()
    result = _fit(pairs, start)
    fitted = time.perf_counter()
    print(f"records {recorded - began:.1f} s, fit {fitted - recorded:.1f} s (compile included)")
    print(result.summary())
    for name, value in result.values.items():
        error = value / TRUTH[name] - 1
        print(
            f"{name}: error {100 * error:+.2f} %, 1σ {100 * result.relative_uncertainty[name]:.2f} % "
            f"(z {error / result.relative_uncertainty[name]:+.2f}), widened {result.inflation[name]:.3f}x"
        )
    for (record, observable), c in result.residual_checks.items():
        print(
            f"  {record} {observable}: ρ {c.lag1:+.3f}, offset {100 * c.mean_offset:+.2f} %, runs {c.runs} "
            f"(expected {c.expected_runs:.0f}), n_eff {c.effective_samples:.0f}, discrepancy {c.discrepancy}"
        )
    if args.case == "vertical":
        return  # the vertical rig's tether is too stiff at 2 segments for the default step limit
    checked = time.perf_counter()
    with warnings.catch_warnings():
        warnings.simplefilter("ignore")
        check = discretisation_check(result)
    print(f"discretisation check {time.perf_counter() - checked:.1f} s")
    for (record, observable), shift in check.shift.items():
        print(f"  {record} {observable}: moves {shift:.3f} σ at 8 segments")
    print(*(f"warning: {w}" for w in check.warnings), sep="\n")
    if args.refit:
        refitting = time.perf_counter()
        finer = _fit([(make(8), record) for make, (_, record) in zip((depressor, drogue), pairs)], start)
        print(f"refit at 8 segments {time.perf_counter() - refitting:.1f} s")
        for name, value in result.values.items():
            moved, error = np.log(finer.values[name] / value), finer.values[name] / TRUTH[name] - 1
            print(
                f"{name}: moves {100 * moved:+.3f} % (linearised {100 * check.moves[name]:+.3f} %); "
                f"error at 8 segments {100 * error:+.3f} %"
            )


if __name__ == "__main__":
    main()
