"""Cnoidal wave loads (Yakovlev et al.) reproduced in full: wave loads on a fixed vertical cylinder in shallow water,
cnoidal against Airy waves of the same height, period and depth.

The studies of `studies.cnoidal_loads` at the `FULL` size, in d = 35 m (the paper's shelf):

1. the held cylinder's horizontal force and overturning moment about the base over one
   period, on a pile (D = 1 m), a column (D = 8 m) and the column without drag (Morison's
   potential-flow part, the paper's Fig. 1 quantity at small ka), for H = 2 … 20 m ×
   T = 14 … 50 s (U = 2 … 580) and a λ̄-series (λ̄ = 1 … 3 at λ = 500 m): the cnoidal
   cases as one `jaxcable.sweep`, the Airy ones by the same generalised forces evaluated
   directly; every case against Morison's load integrated over depth by SciPy's quad;
2. the kinematics at crest and trough of every wave;
3. the harmonic superposition (eqs. 32–33) at λ̄ = 1 and 3: the truncated series, each
   harmonic alone, and the harmonics as free waves (`jaxcable.WaveComponents`);
4. the load integrated to the moving surface instead of the still-water level;
5. the claims table.

    python -m validation.cnoidal_loads_reproduction             # about 5 min on 2 cores
    python -m validation.cnoidal_loads_reproduction --report    # reprint the last record
    python -m validation.cnoidal_loads_reproduction --notebook  # run the notebook in full instead

Results are appended to validation/results/cnoidal_loads_reproduction.json; figures go to
validation/results/cnoidal_loads_reproduction_*.png. Compile time is reported apart from run
time.
"""

import argparse
import json
import os
import time
from pathlib import Path

import jax
import matplotlib

matplotlib.use("Agg")
import matplotlib.pyplot as plt  # noqa: E402
import numpy as np  # noqa: E402

from benchmarks._results import append_session  # noqa: E402
from studies import cnoidal_loads as s4  # noqa: E402

jax.config.update("jax_enable_x64", True)  # jaxcable computes in float64 and leaves the switch to us

RESULTS = Path(__file__).parent / "results"
NOTEBOOK = Path(__file__).parent.parent / "notebooks" / "cnoidal_loads.ipynb"
KINEMATICS = ((7.0, s4.SHELF_PERIOD), (14.0, 40.0))


def main():
    parser = argparse.ArgumentParser(description=__doc__, formatter_class=argparse.RawDescriptionHelpFormatter)
    parser.add_argument("--out", default=str(RESULTS / "cnoidal_loads_reproduction.json"))
    parser.add_argument("--report", action="store_true", help="reprint the last record")
    parser.add_argument(
        "--notebook",
        action="store_true",
        help="only execute notebooks/cnoidal_loads.ipynb with JAXCABLE_FULL=1, saving the executed copy "
        "as results/cnoidal_loads_full.ipynb",
    )
    args = parser.parse_args()
    out = Path(args.out)
    if args.report:
        report(json.loads(out.read_text())[-1])
        return
    if args.notebook:
        run_notebook(out.parent)
        return

    wall = time.perf_counter()
    study = s4.cnoidal_load_study(s4.FULL, verbose=True)
    print(f"load study and its checks: {time.perf_counter() - wall:.0f} s", flush=True)
    start = time.perf_counter()
    sup = s4.superposition_study(study, s4.FULL)
    print(f"harmonic superposition: {time.perf_counter() - start:.0f} s", flush=True)
    limit = s4.limits()
    sensitivity = {f"{h:g}": s4.surface_sensitivity(h) for h in (7.0, 14.0)}
    rows = s4.claims(study, sup, limit)
    figures = make_figures(study, sup, out.parent)
    fields = dict(
        wall_s=time.perf_counter() - wall,
        load_average=os.getloadavg(),
        settings=study.settings,
        timings={
            theory: {"compile_s": study.loads[theory].compile_s, "run_s": study.loads[theory].run_s}
            for theory in s4.THEORIES
        }
        | {"superposition": {"compile_s": sup.compile_s, "run_s": sup.run_s}},
        checks=study.checks,
        cases=study.rows(),
        underprediction=s4.underprediction_table(study),
        superposition={
            "waves": sup.waves,
            "truncations": list(sup.truncations),
            "coefficients": sup.coefficients,
            "checks": sup.checks,
            "cases": [
                {
                    "wave": wave,
                    "structure": name,
                    "truncation_error": sup.truncation_error((wave, name)).tolist(),
                    "superposition_error": sup.superposition_error((wave, name)),
                    "superposed_peak": sup.superposed_peak((wave, name)),
                    "free_error": sup.free_error((wave, name)),
                    "free_peak": sup.free_peak((wave, name)),
                }
                for wave, name in sup.closed
            ],
        },
        limits=limit,
        surface_sensitivity=sensitivity,
        claims=[dict(zip(("claim", "result", "agreement", "why"), row)) for row in rows],
        figures=figures,
    )
    append_session(out, **_finite(fields))
    report(json.loads(out.read_text())[-1])


def _finite(value):
    """`value` with numpy scalars as Python numbers and every non-finite float as None
    (JSON has no NaN or infinity)."""
    if isinstance(value, dict):
        return {str(k): _finite(v) for k, v in value.items()}
    if isinstance(value, list | tuple):
        return [_finite(v) for v in value]
    if isinstance(value, np.ndarray):
        return _finite(value.tolist())
    if isinstance(value, np.generic):
        value = value.item()
    if isinstance(value, float) and not np.isfinite(value):
        return None
    return value


def make_figures(study, sup, folder: Path) -> list[str]:
    folder.mkdir(parents=True, exist_ok=True)
    names = []
    s4.plot_kinematics(KINEMATICS)
    plt.tight_layout()
    names.append(_save(folder / "cnoidal_loads_reproduction_kinematics.png"))
    s4.plot_loads(study, 7.0, s4.SHELF_PERIOD)
    plt.tight_layout()
    names.append(_save(folder / "cnoidal_loads_reproduction_loads.png"))
    fig, axes = plt.subplots(2, 2, figsize=(13, 8))
    s4.plot_ratios(study, "force", axes[0])
    s4.plot_ratios(study, "moment", axes[1])
    fig.tight_layout()
    names.append(_save(folder / "cnoidal_loads_reproduction_ursell.png"))
    s4.plot_steepness(study)
    plt.tight_layout()
    names.append(_save(folder / "cnoidal_loads_reproduction_steepness.png"))
    s4.plot_superposition(sup)
    plt.tight_layout()
    names.append(_save(folder / "cnoidal_loads_reproduction_superposition.png"))
    return names


def _save(path: Path) -> str:
    plt.savefig(path, dpi=110)
    plt.close("all")
    return path.name


def run_notebook(folder: Path) -> None:
    """Execute the reproduction notebook in full mode; keep the executed copy."""
    import nbformat
    from nbclient import NotebookClient

    notebook = nbformat.read(NOTEBOOK, as_version=4)
    os.environ["JAXCABLE_FULL"] = "1"
    start = time.perf_counter()
    NotebookClient(
        notebook, timeout=3600, kernel_name="python3", resources={"metadata": {"path": str(NOTEBOOK.parent)}}
    ).execute()
    elapsed = time.perf_counter() - start
    target = folder / "cnoidal_loads_full.ipynb"
    nbformat.write(notebook, target)
    print(f"notebook executed in full mode in {elapsed:.0f} s: {target}", flush=True)


def report(session: dict) -> None:
    s = session["settings"]
    print(
        f"## Cnoidal wave loads (Yakovlev et al.) reproduced — {session['time']}, {session['machine']}, "
        f"commit {session.get('commit')}, "
        f"load {np.round(session['load_average'], 1).tolist()}"
    )
    print(
        f"\nd = {s['depth_m']:g} m; H = {s['heights_m']} m × T = {s['periods_s']} s and λ̄ = {s['steepness']} at "
        f"λ = {s['steepness_wavelength_m']:g} m; structures {s['structures']}; loads every {s['sample_step_s']} s "
        f"to {s['loads_to']}; {len(session['cases'])} cases per theory; wall {session['wall_s'] / 60:.1f} min."
    )
    for theory, t in session["timings"].items():
        print(f"- {theory}: {t['compile_s']:.1f} s compiling, {t['run_s']:.1f} s again")
    c = session["checks"]
    print(
        f"\nAgainst SciPy: m {c['m']:.1e} (of 1 − m); λ {c['wavelength']}; kinematics {c['kinematics']}; loads by "
        f"quad {c['loads']}; sampled peak below the reference's {c['peak_sampling']}"
    )
    print("\n### Airy's peak against cnoidal's, (Airy − cnoidal)/cnoidal, by U\n")
    print(s4.underprediction_markdown(session["underprediction"]))
    print("\n### Cases on the paper's shelf (T = 20 s) and the λ̄-series\n")
    print(
        "| structure | H (m) | T (s) | U | λ̄ | F crest/trough, cnoidal (kN) | Airy (kN) "
        "| M crest, cnoidal / Airy (MN·m) |"
    )
    print("|---|---|---|---|---|---|---|---|")
    for r in session["cases"]:
        if r["period_s"] != s4.SHELF_PERIOD and r["steepness"] is None:
            continue
        print(
            f"| {r['structure']} | {r['height_m']:.2f} | {r['period_s']:.2f} | {r['ursell_cnoidal']:.1f} | "
            f"{r['steepness'] or '–'} | {r['force_crest_cnoidal'] / 1e3:.0f} / {r['force_trough_cnoidal'] / 1e3:.0f} | "
            f"{r['force_crest_airy'] / 1e3:.0f} / {r['force_trough_airy'] / 1e3:.0f} | "
            f"{r['moment_crest_cnoidal'] / 1e6:.1f} / {r['moment_crest_airy'] / 1e6:.1f} |"
        )
    sup = session["superposition"]
    print(
        f"\n### Harmonic superposition\n\naₙ: eq. 33 vs closed form {sup['coefficients']['paper_eq33']:.1e}, FFT "
        f"{sup['coefficients']['fft']:.1e}; series loads vs quad {sup['checks']}\n"
    )
    print("| wave | structure | Σ single harmonics vs F | its peak / F's | free harmonics vs F | their peak / F's |")
    print("|---|---|---|---|---|---|")
    for r in sup["cases"]:
        print(
            f"| {r['wave']} | {r['structure']} | {r['superposition_error']:.1e} | {r['superposed_peak']:.3f} | "
            f"{r['free_error']:.3f} | {r['free_peak']:.3f} |"
        )
    print("\n### Loads to the surface η instead of z = 0 (SciPy), T = 20 s\n")
    for h, sens in session["surface_sensitivity"].items():
        print(f"H = {h} m\n")
        print(s4.sensitivity_markdown(sens))
        print()
    print("### Claims\n")
    print(s4.verdict_markdown([(r["claim"], r["result"], r["agreement"], r["why"]) for r in session["claims"]]))
    print(f"\nFigures: {', '.join(session['figures'])}")


if __name__ == "__main__":
    main()
