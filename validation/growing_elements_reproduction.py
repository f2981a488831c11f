"""Growing elements (Zhukov) reproduced in full: Zhukov's growing element free and tethered in a wave.

The studies of `studies.growing_elements` at the `FULL` size (60 wave periods of
4 s, 20 of them settling, output at 144 samples a period):

1. the free element over k₀ = 0.5 … 5000 s²/m² (St = 1.2 … 1.2e-4): its drift against
   the Stokes drift at its mean depth;
2. the tethered element over the weight characteristic ρ = 0.05 … 2 at k₀ = 5 s²/m²,
   and the scallop cage (k₀ = 0.5 s²/m²) at ρ = 0.5 … 10: slack time, the share of the
   impulse on the back slope, peak tension, the height above the tether's arc, the
   shadow map over the wave's phase, and the impulses' fits by part of a sine and a
   parabola;
3. the thesis's integrators: Simpson's rule at step h against the trapezoid rule at
   h/5, both by 3 Picard iterations, on problem 1 (a mass on a taut string, against its
   closed form) and on the tethered element (ρ = 0.5 and 2, against Dopri5 at 1e-12);
4. eq. 7's similarity: the tethered element (ρ = 0.2) at Froude scale 4 and in
   arbitrary units, with α doubled, and with St ten times smaller at the same α, ξ, ρ.

    python -m validation.growing_elements_reproduction            # about 4 min on 2 cores
    python -m validation.growing_elements_reproduction --report   # reprint the last record

Results are appended to validation/results/growing_elements_reproduction.json; figures go to
validation/results/growing_elements_reproduction_*.png. Each study's time includes its compile.
"""

import argparse
import json
import time
from pathlib import Path

import jax
import matplotlib

matplotlib.use("Agg")
import matplotlib.pyplot as plt  # noqa: E402
import numpy as np  # noqa: E402

from benchmarks._results import append_session  # noqa: E402
from jaxcable.examples._growing_element import SPECIFIC_DRAG  # noqa: E402
from studies import growing_elements as s1  # noqa: E402

jax.config.update("jax_enable_x64", True)  # jaxcable computes in float64 and leaves the switch to us

RESULTS = Path(__file__).parent / "results"
# Fine enough near ρ = 1 to pin where the cage stops going slack.
CAGE_WEIGHTS = (0.5, 0.75, 1.0, 1.25, 1.5, 2.0, 10.0)


def main():
    parser = argparse.ArgumentParser(description=__doc__, formatter_class=argparse.RawDescriptionHelpFormatter)
    parser.add_argument("--out", default=str(RESULTS / "growing_elements_reproduction.json"))
    parser.add_argument("--report", action="store_true")
    args = parser.parse_args()
    if args.report:
        print(json.loads(Path(args.out).read_text())[-1]["verdict"])
        return

    free = s1.free_study(**s1.FULL)
    print(
        f"free: {free.run_s:.1f} s; drift / Stokes {np.round(free.drift_ratio, 4)} at St "
        f"{np.round(free.inertia_number, 5)}",
        flush=True,
    )
    tethered = s1.tethered_study(**s1.FULL)
    cage = s1.tethered_study(CAGE_WEIGHTS, specific_drag=SPECIFIC_DRAG, **s1.FULL)
    print(f"tethered: {tethered.run_s:.1f} s, the cage: {cage.run_s:.1f} s", flush=True)
    start = time.perf_counter()
    thread = s1.thread_quadrature_study()
    wave = s1.wave_quadrature_study()
    quadrature_s = time.perf_counter() - start
    print(f"integrators: {quadrature_s:.1f} s", flush=True)
    start = time.perf_counter()
    scenes = s1.similarity_study()
    similarity_s = time.perf_counter() - start
    print(f"similarity: {similarity_s:.1f} s", flush=True)
    verdict = s1.verdict_markdown(
        free, tethered, cage, extra_rows=(s1.quadrature_row(thread, wave), s1.similarity_row(scenes))
    )
    print(verdict)

    def tethered_record(study):
        fits = s1.impulse_fits(study)
        return {
            "specific_drag": study.specific_drag,
            "inertia_number": float(s1.inertia_number(study.specific_drag)),
            "run_s": study.run_s,
            "success": study.success.tolist(),
            "weight_characteristic": study.weight_characteristic.tolist(),
            "weight_N": study.weight.tolist(),
            "slack_fraction": study.slack_fraction().tolist(),
            "back_slope_share": s1.back_slope_share(study).tolist(),
            "peak_tension_N": study.tension.max(axis=1).tolist(),
            "peak_eta": study.eta.max(axis=1).tolist(),
            "lift_m": (study.positions[:, :, 2].mean(axis=1) - study.static_depth).tolist(),
            "rise_above_arc_m": s1.rise_above_arc(study).tolist(),
            "never_slack_from": s1.never_slack_from(study),
            "threshold_bracket": s1.threshold_bracket(study),
            "impulse_fits": {
                str(rho): {
                    "duration_s": float(f.times[-1] - f.times[0]),
                    "sine": f.sine,
                    "sine_rms": f.sine_rms,
                    "parabola": f.parabola,
                    "parabola_rms": f.parabola_rms,
                    "rectangle_rms": f.rectangle_rms,
                }
                for rho, f in fits.items()
            },
        }

    append_session(
        args.out,
        config=s1.FULL,
        free={
            "specific_drag": free.specific_drag.tolist(),
            "inertia_number": free.inertia_number.tolist(),
            "drift_m_s": free.drift.tolist(),
            "mean_depth_m": free.mean_depth.tolist(),
            "stokes_drift_m_s": free.stokes_drift.tolist(),
            "drift_ratio": free.drift_ratio.tolist(),
            "success": free.success.tolist(),
            "run_s": free.run_s,
        },
        tethered=tethered_record(tethered),
        cage=tethered_record(cage),
        quasi_static_threshold=s1.quasi_static_threshold(),
        orbit_radius_m=s1.orbit_radius(),
        quadrature={
            "run_s": quadrature_s,
            "step_ratio": s1.STEP_RATIO,
            "similar_factor": s1.SIMILAR_FACTOR,
            "iterations": 3,
            **{
                name: {
                    "problem": q.problem,
                    "case": q.case,
                    "simpson_step_s": q.simpson_step.tolist(),
                    "simpson_error": q.simpson_error.tolist(),
                    "trapezoid_error": q.trapezoid_error.tolist(),
                    "simpson_evaluations": q.simpson_evaluations.tolist(),
                    "trapezoid_evaluations": q.trapezoid_evaluations.tolist(),
                }
                for name, q in (("thread", thread), ("wave", wave))
            },
        },
        similarity={
            "run_s": similarity_s,
            "scenes": [
                {
                    "label": c.label,
                    "units_L_T_M": list(c.units),
                    "tether_stiffness_N": c.tether_stiffness,
                    "specific_drag": c.specific_drag,
                    "alpha": c.alpha,
                    "xi": c.xi,
                    "rho": c.rho,
                    "inertia_number": c.inertia,
                    "difference_from_first": s1.response_difference(scenes[0], c),
                    "success": c.success,
                }
                for c in scenes
            ],
        },
        verdict=verdict,
    )

    s1.plot_free(free)
    plt.tight_layout()
    plt.savefig(RESULTS / "growing_elements_reproduction_free.png", dpi=110)
    cases = [int(np.argmin(np.abs(tethered.weight_characteristic - r))) for r in (0.2, 0.5, 1.0, 2.0)]
    s1.plot_tethered(tethered, cases)
    plt.tight_layout()
    plt.savefig(RESULTS / "growing_elements_reproduction_tethered.png", dpi=110)
    s1.plot_shadow_map(tethered)
    plt.tight_layout()
    plt.savefig(RESULTS / "growing_elements_reproduction_shadow.png", dpi=110)
    fits = s1.impulse_fits(tethered)
    s1.plot_impulse(fits[max(fits)], max(fits))
    plt.tight_layout()
    plt.savefig(RESULTS / "growing_elements_reproduction_impulse.png", dpi=110)
    s1.plot_quadrature(thread, wave)
    plt.tight_layout()
    plt.savefig(RESULTS / "growing_elements_reproduction_quadrature.png", dpi=110)
    s1.plot_similarity(scenes)
    plt.tight_layout()
    plt.savefig(RESULTS / "growing_elements_reproduction_similarity.png", dpi=110)


if __name__ == "__main__":
    main()
