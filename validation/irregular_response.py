"""A linear system in an irregular sea: jaxcable's sweep over seeds against the closed
form (`studies/linear_buoy.py`), and where the linear theory stops holding.

A submerged buoy heaves on a drag-free Kelvin–Voigt tether in JONSWAP seas (T_p = 6 s,
γ = 3.3) of each given H_s, one compiled `jc.sweep` over the seeds per H_s, over one
repeat period (256 s) after a 60 s start. For each seed: the tension's variance over
that period against ∫ |H_T|² S dω (scipy), the RMS and largest pointwise difference from
the closed form's record of the same components, in units of its σ; over the seeds:
the most probable maximum (Gumbel fit) of the simulated and the closed-form records,
the short-term (Rayleigh) MPM against Rice's σ √(2 ln ν₀ D), and the buoy's largest
heave and sway. Wall times include
compilation; the machine's load average is recorded with them.

    python -m validation.irregular_response [--heights 0.5 2.0] [--seeds 8]

Results are appended to validation/results/irregular_response.json.
"""

import argparse
import os
import time
from pathlib import Path

import jax
import numpy as np

import jaxcable as jc
from benchmarks._results import append_session

jax.config.update("jax_enable_x64", True)  # jaxcable computes in float64 and leaves the switch to us

from studies import linear_buoy as lb  # noqa: E402

RESULTS = Path(__file__).resolve().parent / "results" / "irregular_response.json"


def main() -> None:
    parser = argparse.ArgumentParser(description=__doc__, formatter_class=argparse.RawDescriptionHelpFormatter)
    parser.add_argument("--heights", type=float, nargs="+", default=[0.5, 2.0], help="H_s (m) of each sweep")
    parser.add_argument("--seeds", type=int, default=8)
    parser.add_argument("--out", type=Path, default=RESULTS)
    args = parser.parse_args()

    load = os.getloadavg()
    static = jc.solve_statics(lb.tethered_buoy(), lb.still_water())
    cases = []
    for height in args.heights:
        start = time.perf_counter()
        result, ts = lb.sweep_seeds(height, args.seeds, static)
        seconds = time.perf_counter() - start
        numbers = lb.compare(result, ts, static, height) | {"sweep_seconds": seconds, "status": list(result.status)}
        cases.append(numbers)
        rows = numbers["per_seed"]
        ratio = [r["variance_over_integral"] for r in rows]
        rms = [r["rms_error_over_sigma"] for r in rows]
        worst = max(r["max_error_over_sigma"] for r in rows)
        maxima = np.abs(np.subtract(numbers["maxima"], numbers["linear_maxima"])).max() / numbers["sigma"]
        print(
            f"H_s = {height:g} m, {args.seeds} seeds, σ = {numbers['sigma'] / 1e3:.4g} kN ({seconds:.0f} s): "
            f"variance/∫|H|²S {min(ratio):.4f} to {max(ratio):.4f}; pointwise RMS {min(rms):.4f} to {max(rms):.4f} σ, "
            f"largest {worst:.3f} σ; maxima within {maxima:.3f} σ; MPM {numbers['mpm'] / 1e3:.4f} kN against "
            f"{numbers['linear_mpm'] / 1e3:.4f} kN linear (standard error {numbers['standard_error'] / 1e3:.3f} kN); "
            f"Rayleigh MPM {numbers['rayleigh_mpm'] / 1e3:.4f} kN against Rice's {numbers['rice_mpm'] / 1e3:.4f} kN; "
            f"heave up to {numbers['largest_heave']:.2f} m, sway {numbers['largest_sway']:.2f} m"
        )
    append_session(args.out, cases=cases, load_average_start=load, load_average_end=os.getloadavg())
    print(f"appended to {args.out}")


if __name__ == "__main__":
    main()
