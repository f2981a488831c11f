"""Seed 003 reproduced in full: 3 angles × 4 ratios, the C_E dependence, and convergence.

Bezverkhyy & Korniienko's anchored line (H = 200 m, m = 3 kg/m, F = 0.0003 m²,
C_n = 15.6, C_τ = 0.78, C_a = 0.4, T_w = 5.6 s, A = 1.573 m) at α = 30°, 45°, 60° with
C_E1/C_E = 0, 0.05, 0.1, 0.2, read over t = 30–48 s as in their Figs. 2–5
(`studies.seed003`). Each case starts from static equilibrium.

1. The main study at C_E = 3e7 N (`FULL`: 20 segments, lumped mass, Dopri5 at
   rtol = atol = 1e-8, tension sampled at 200 Hz in the window).
2. The key comparisons (C_E1 = 0 and 0.2 at every angle) at C_E = 1e6, 3e6 and 1e7 N.
3. Convergence at α = 30°, C_E1 = 0 and 0.2: N = 10, 20, 40 and rtol = 1e-8 … 1e-10.

    python benchmarks/seed003_reproduction.py              # everything, ~20 min on 2 cores
    python benchmarks/seed003_reproduction.py --report     # reprint the last record
    python benchmarks/seed003_reproduction.py --notebook   # run the notebook in full instead

Results are appended to benchmarks/results/seed003_reproduction.json; figures go to
benchmarks/results/seed003_reproduction_*.png. Compile time (once per shape and option
set, reused across angles and C_E) is reported apart from run time.
"""

import argparse
import json
import os
import platform
import sys
import time
from pathlib import Path

import diffrax
import jax
import matplotlib

matplotlib.use("Agg")
import matplotlib.pyplot as plt  # noqa: E402

# The paper studies live in the repository's `studies/` folder, not in the package.
sys.path.insert(0, str(Path(__file__).resolve().parent.parent))
from studies.seed003 import (  # noqa: E402
    ANGLES,
    FULL,
    RATIOS,
    plot_along,
    plot_histories,
    seed003_study,
    stiffness_table_markdown,
    verdict,
)

jax.config.update("jax_enable_x64", True)  # jaxcable computes in float64 and leaves the switch to us

RESULTS = Path(__file__).parent / "results"
NOTEBOOK = Path(__file__).parent.parent / "notebooks" / "seed003_reproduction.ipynb"
PAPER_FIGURES = {30.0: "Fig. 2 (C_E1 = 0.1, 0.2 C_E)", 45.0: "Fig. 3 (all four)", 60.0: "Fig. 4 (C_E1 = 0.1, 0.2 C_E)"}


def main():
    parser = argparse.ArgumentParser(description=__doc__, formatter_class=argparse.RawDescriptionHelpFormatter)
    parser.add_argument("--axial-stiffness", type=float, default=3e7, help="C_E (N) of the main study")
    parser.add_argument(
        "--stiffnesses", type=float, nargs="*", default=[1e6, 3e6, 1e7], help="further C_E (N) for the key comparisons"
    )
    parser.add_argument("--segments", type=int, default=FULL["n_segments"])
    parser.add_argument("--rtol", type=float, default=FULL["rtol"])
    parser.add_argument(
        "--convergence",
        nargs="*",
        default=["10:1e-8", "10:1e-9", "10:1e-10", "20:1e-9", "40:1e-8"],
        help="N:rtol pairs for the convergence check at 30° (the main study gives N = --segments)",
    )
    parser.add_argument("--out", default=str(RESULTS / "seed003_reproduction.json"))
    parser.add_argument("--report", action="store_true", help="reprint the last record")
    parser.add_argument(
        "--notebook",
        action="store_true",
        help="only execute notebooks/seed003_reproduction.ipynb with JAXCABLE_FULL=1, saving the "
        "executed copy as results/seed003_reproduction_full.ipynb",
    )
    args = parser.parse_args()
    out = Path(args.out)
    if args.report:
        report(json.loads(out.read_text())[-1])
        return
    if args.notebook:
        run_notebook(out.parent)
        return

    config = dict(FULL, n_segments=args.segments, rtol=args.rtol, atol=args.rtol)
    wall = time.perf_counter()
    print(f"main study: C_E = {args.axial_stiffness:.0e} N, {config}", flush=True)
    main_study = seed003_study(ANGLES, RATIOS, axial_stiffness=args.axial_stiffness, verbose=True, **config)
    studies = {args.axial_stiffness: main_study}
    for c_e in args.stiffnesses:
        print(f"key comparisons at C_E = {c_e:.0e} N", flush=True)
        studies[c_e] = seed003_study(ANGLES, (0.0, 0.2), axial_stiffness=c_e, verbose=True, **config)

    convergence = [_convergence_record(main_study, 30.0, config["n_segments"], config["rtol"], reused=True)]
    for item in args.convergence:
        n, tol = item.split(":")
        print(f"convergence: N = {n}, rtol = {tol}", flush=True)
        c = dict(config, n_segments=int(n), rtol=float(tol), atol=float(tol))
        study = seed003_study((30.0,), (0.0, 0.2), axial_stiffness=args.axial_stiffness, **c)
        convergence.append(_convergence_record(study, 30.0, int(n), float(tol)))

    figures = make_figures(main_study, studies, args.axial_stiffness, out.parent)
    session = {
        "time": time.strftime("%Y-%m-%dT%H:%M:%S%z"),
        "machine": f"{platform.node()} {platform.machine()} ({os.cpu_count()} cores)",
        "load_average": os.getloadavg(),
        "devices": [str(d) for d in jax.devices()],
        "jax": jax.__version__,
        "diffrax": diffrax.__version__,
        "wall_s": time.perf_counter() - wall,
        "main": main_study.to_dict(history_rate=25.0),
        "stiffness": {f"{c_e:.0e}": studies[c_e].to_dict(history_rate=0, segments=False) for c_e in sorted(studies)},
        "convergence": convergence,
        "figures": figures,
    }
    session["verdict"] = {k: v for k, v in verdict(main_study).items() if k in ("claim1", "claim2", "text")}
    out.parent.mkdir(parents=True, exist_ok=True)
    history = json.loads(out.read_text()) if out.exists() else []
    history.append(session)
    out.write_text(json.dumps(history) + "\n")
    report(session)


def _convergence_record(study, angle, n, rtol, reused=False):
    rows = {c.ratio: c for c in study.cases if c.angle == angle}
    linear, top = rows[0.0], rows[max(rows)]
    return {
        "angle_deg": angle,
        "n_segments": n,
        "rtol": rtol,
        "peak_top_N": {str(r): c.peak_top for r, c in rows.items()},
        "peak_line_N": {str(r): c.peak_line for r, c in rows.items()},
        "slack_top_s": {str(r): c.slack_seconds for r, c in rows.items()},
        "steps": {str(r): c.steps for r, c in rows.items()},
        "ratio_effect": top.peak_top / linear.peak_top - 1,
        "compile_s": study.compile_s,
        "run_s": study.run_s_by_angle[angle],
        "batch": len(study.ratios),
        "from_main_study": reused,
    }


def make_figures(main_study, studies, c_e, folder: Path) -> list[str]:
    folder.mkdir(parents=True, exist_ok=True)
    names = []

    fig, axes = plt.subplots(3, 1, figsize=(9, 9), sharex=True)
    for ax, angle in zip(axes, ANGLES):
        plot_histories(main_study, angle, ax=ax, legend=False)
        ax.set_title(f"α = {angle:g}°, top segment, C_E = {c_e:.0e} N — cf. the paper's {PAPER_FIGURES[angle]}")
    # The histories fill every panel edge to edge: one legend above them all.
    fig.legend(*axes[0].get_legend_handles_labels(), loc="upper center", ncol=len(main_study.ratios), fontsize=8)
    fig.tight_layout(rect=(0, 0, 1, 0.96))
    names.append(_save(fig, folder / "seed003_reproduction_histories.png"))

    fig, axes = plt.subplots(1, 3, figsize=(14, 3.8), sharey=True)
    for ax, angle in zip(axes, ANGLES):
        plot_along(main_study, angle, ax=ax)
    fig.tight_layout()
    names.append(_save(fig, folder / "seed003_reproduction_along.png"))

    fig, axes = plt.subplots(1, 3, figsize=(14, 3.6))
    stiff = sorted(studies)
    for angle in ANGLES:
        linear = [studies[k].case(angle, 0.0).peak_top / 1e4 for k in stiff]
        change = [
            100 * (studies[k].case(angle, 0.2).peak_top / studies[k].case(angle, 0.0).peak_top - 1) for k in stiff
        ]
        axes[0].plot(stiff, linear, "o-", label=f"{angle:g}°")
        axes[1].plot(stiff, change, "o-", label=f"{angle:g}°")
    for ratio, style in ((0.0, "o-"), (0.2, "s--")):
        for colour, (hi, lo) in (("C3", (45.0, 30.0)), ("C4", (60.0, 30.0))):
            v = [100 * (studies[k].case(hi, ratio).peak_top / studies[k].case(lo, ratio).peak_top - 1) for k in stiff]
            axes[2].plot(stiff, v, style, color=colour, label=f"{hi:g}° vs {lo:g}°, C_E1 = {ratio:g} C_E")
    axes[0].set_ylabel("peak top T, C_E1 = 0 (10⁴ N)")
    axes[1].set_ylabel("peak at C_E1 = 0.2 C_E vs linear (%)")
    axes[1].axhspan(-25, -15, color="0.85", label="paper: up to ~−20 %")
    axes[2].set_ylabel("peak change with angle (%)")
    axes[2].axhspan(-30, -20, color="0.85", label="paper: 60° ~−25 %")
    for ax in axes:
        ax.set_xscale("log")
        ax.set_xlabel("C_E (N)")
        ax.axhline(0, color="k", lw=0.5)
        ax.legend(fontsize=7)
    fig.tight_layout()
    names.append(_save(fig, folder / "seed003_reproduction_stiffness.png"))
    return names


def _save(fig, path: Path) -> str:
    fig.savefig(path, dpi=110)
    plt.close(fig)
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
    target = folder / "seed003_reproduction_full.ipynb"
    nbformat.write(notebook, target)
    print(f"notebook executed in full mode in {elapsed:.0f} s: {target}", flush=True)


def report(session: dict) -> None:
    main_ = session["main"]
    s = main_["settings"]
    print(f"## Seed 003 reproduction — {session['time']}, {session['machine']}, load {session.get('load_average')}")
    print(
        f"\nMain study: C_E = {s['axial_stiffness_N']:.0e} N, N = {s['n_segments']}, {s['mass_matrix']} mass, "
        f"{s['solver']} rtol = atol = {s['rtol']:g}, window {s['window_s']} s, {s['sample_rate_Hz']:g} Hz; "
        f"compile {main_['compile_s']:.1f} s, run {main_['run_s']:.1f} s (12 cases, 3 batches of 4).\n"
    )
    _print_table(main_["cases"])
    print("\n### Verdict (top-segment peak, t = 30–48 s)\n")
    print(verdict(main_["cases"])["text"])
    for key in ("peak_line_N", "peak_anchor_N"):
        v = verdict(main_["cases"], key)
        print(f"\n(with {key}: claim 1 {v['claim1']}, claim 2 {v['claim2']})")
    print("\n### C_E dependence (C_E1 = 0 and 0.2 C_E)\n")
    print(stiffness_table_markdown({float(k): v["cases"] for k, v in session["stiffness"].items()}))
    print()
    for k, v in session["stiffness"].items():
        print(f"- C_E = {k} N: compile {v['compile_s']:.1f} s, run {v['run_s']:.1f} s")
    print("\n### Convergence (α = 30°, top-segment peak in the window)\n")
    print(
        "| N | rtol | peak, C_E1 = 0 (kN) | peak, C_E1 = 0.2 C_E (kN) | 0.2 vs 0 | slack top, 0 / 0.2 (s) | steps "
        "(C_E1 = 0) | run (s) |"
    )
    print("|---|---|---|---|---|---|---|---|")
    for c in sorted(session["convergence"], key=lambda c: (c["n_segments"], -c["rtol"])):
        p = c["peak_top_N"]
        print(
            f"| {c['n_segments']} | {c['rtol']:g} | {p['0.0'] / 1e3:.2f} | {p['0.2'] / 1e3:.2f} | "
            f"{100 * c['ratio_effect']:+.1f} % "
            f"| {c['slack_top_s']['0.0']:.2f} / {c['slack_top_s']['0.2']:.2f} | {c['steps']['0.0']} "
            f"| {c['run_s']:.1f}{' (main study, batch of 4)' if c['from_main_study'] else ''} |"
        )
    print(f"\nFigures: {', '.join(session['figures'])}; wall time {session['wall_s'] / 60:.1f} min.")


def _print_table(rows):
    print(
        "| α | C_E1/C_E | static top (kN) | peak top (kN) | min top (kN) | peak anchor (kN) | peak on line (kN) | peak "
        "ε | slack top (s) | slack top (%) | steps | ok |"
    )
    print("|---|---|---|---|---|---|---|---|---|---|---|---|")
    for r in rows:
        print(
            f"| {r['angle_deg']:g}° | {r['ratio']:g} | {r['static_top_N'] / 1e3:.1f} | {r['peak_top_N'] / 1e3:.1f} "
            f"| {r['min_top_N'] / 1e3:.2f} | {r['peak_anchor_N'] / 1e3:.1f} | {r['peak_line_N'] / 1e3:.1f} | "
            f"{r['peak_strain']:.4f} "
            f"| {r['slack_top_s']:.2f} | {100 * r['slack_top_fraction']:.1f} | {r['steps']} | "
            f"{'yes' if r['success'] else 'NO'} |"
        )


if __name__ == "__main__":
    main()
