"""Branched systems (Bezverkhyy & Korniienko) reproduced in full: Bezverkhyy & Korniienko's towed trawl and moored net.

The studies of `studies.towed_trawl` and `studies.moored_net` at the `FULL` size:

1. the towed trawl (20 segments on the tow cable, 10 on each branch) through seven speed
   steps at t = 300 s, run to t = 400 s (the falls and the elastic rise to 330 s): the
   tensions at the tow point, the branch point, the diverter and the buoy, the buoy's
   depth, the diverters' sweep, slack spells and jerks;
2. the moored net in 6.4 s waves along its diagonal: the buoys' heave and drift, and the
   tension along the vertical branch under buoy 2;
3. `studies.snap_loads`: the net's snap near buoy 2's anchor resolved at 1 µs, its
   peaks as the output interval and the tolerances halve, with C_E1 = 0.2 C_E too; the
   trawl's 3 → 1 m/s fall with and without C_E1; its steady tow in waves with and without
   the viscous term.

    python -m validation.branched_systems_reproduction                # trawl and net, about 25 min on 2 cores
    python -m validation.branched_systems_reproduction --part trawl   # or net, or snap: one study
    python -m validation.branched_systems_reproduction --part snap --small   # the snap study at its small size
    python -m validation.branched_systems_reproduction --report       # reprint the last verdicts

Results are appended to validation/results/branched_systems_reproduction.json; figures go to
validation/results/branched_systems_reproduction_*.png. Each run's time includes its compile.
"""

import argparse
import json
import time
from pathlib import Path

import jax
import matplotlib

matplotlib.use("Agg")
import matplotlib.pyplot as plt  # noqa: E402

from benchmarks._results import append_session  # noqa: E402
from studies import moored_net as s2n  # noqa: E402
from studies import snap_loads as s2s  # noqa: E402
from studies import towed_trawl as s2  # noqa: E402

jax.config.update("jax_enable_x64", True)  # jaxcable computes in float64 and leaves the switch to us

RESULTS = Path(__file__).parent / "results"


def trawl_record(run: s2.TrawlRun) -> dict:
    peak, level = s2.jerk(run)
    found = s2.snaps(run)
    return {
        "speeds_m_s": run.speeds,
        "viscous": run.viscous,
        "waves": run.waves,
        "steps": run.steps,
        "wall_s": run.wall_time,
        "front_jump_N": dict(zip(("measured", "predicted"), s2.front_jump(run))),
        "levels_N": {p: vars(s2.levels(run, run.at(p))) for p in s2.POINTS},
        "buoy_z_m": vars(s2.depth(run)),
        "branch_point_z_m": vars(s2.depth(run, "branch")),
        "sweep_width_m": s2.sweep_width(run),
        "jerk_N": {"peak": peak, "level": level},
        "slack_spells": len(found),
        "slack_segments": sorted({x.segment for x in found}),
        "first_slack_s": min((x.slack_from for x in found), default=None),
        "ringing_N": s2.ringing(run, "tow point", s2.STEP_TIME + 1, min(s2.STEP_TIME + 5, run.times[-1])),
        "settling_time_s": s2.settling_time(run),
    }


def main():
    parser = argparse.ArgumentParser(description=__doc__, formatter_class=argparse.RawDescriptionHelpFormatter)
    parser.add_argument("--out", default=str(RESULTS / "branched_systems_reproduction.json"))
    parser.add_argument("--part", choices=("trawl", "net", "snap", "both"), default="both")
    parser.add_argument("--small", action="store_true", help="the snap study at its SMALL size")
    parser.add_argument("--report", action="store_true")
    args = parser.parse_args()
    if args.report:
        history = json.loads(Path(args.out).read_text())
        for part in ("trawl", "net", "snap"):
            last = [session for session in history if session["part"] == part]
            if last:
                print(f"{part} ({last[-1]['time']}):\n{last[-1].get('convergence_table', '')}\n{last[-1]['verdict']}")
        return
    if args.part in ("trawl", "both"):
        trawl(args.out)
    if args.part in ("net", "both"):
        net(args.out)
    if args.part == "snap":
        snap(args.out, s2s.SMALL if args.small else s2s.FULL)


def snap(out: str, config: dict) -> None:
    clock = time.perf_counter()
    study = s2s.run_study(config)
    wall = time.perf_counter() - clock
    print(f"snap study: {wall:.0f} s; the snap at t = {study.at:.4f} s", flush=True)
    table = s2s.convergence_markdown(study)
    verdict = "\n".join(
        ["| paper's claim | jaxcable's result | agreement | why |", "|---|---|---|---|"]
        + ["| " + " | ".join(cell.replace("|", "/") for cell in row) + " |" for row in s2s.verdict_rows(study)]
    )
    print(table)
    print(verdict)
    append_session(
        out,
        part="snap",
        size="small" if config is s2s.SMALL else "full",
        config={k: v for k, v in config.items() if k not in ("net", "trawl")},
        net_config=config["net"],
        trawl_config=config["trawl"],
        study_s=wall,
        **s2s.record(study),
        convergence_table=table,
        verdict=verdict,
    )
    suffix = "_small" if config is s2s.SMALL else ""
    s2s.plot_convergence(study)
    plt.tight_layout()
    plt.savefig(Path(out).parent / f"branched_systems_reproduction_snap{suffix}.png", dpi=110)


def net(out: str) -> None:
    run = s2n.run_net(s2n.FULL)
    print(f"net: {run.steps} steps, {run.wall_time:.1f} s", flush=True)
    verdict = s2n.verdict_markdown(run)
    print(verdict)
    append_session(
        out,
        part="net",
        config=s2n.FULL,
        steps=run.steps,
        wall_s=run.wall_time,
        heave={b: vars(h) for b, h in s2n.heave(run).items()},
        drift={b: vars(d) for b, d in s2n.drift(run).items()},
        places={
            name: {
                "still_N": p.still,
                "min_N": p.min,
                "max_N": p.max,
                "max_20ms_N": p.max_smoothed,
                "mean_N": p.mean,
                "slack_spells": len(p.spells),
                "slack_fraction": p.slack_fraction,
                "snap_peaks_N": [x.peak for x in p.spells],
            }
            for name, p in s2n.places(run).items()
        },
        verdict=verdict,
    )
    _, axes = plt.subplots(1, 2, figsize=(13, 4))
    s2n.plot_heave(run, ax=axes[0])
    s2n.plot_paths(run, ax=axes[1])
    plt.tight_layout()
    plt.savefig(RESULTS / "branched_systems_reproduction_net_buoys.png", dpi=110)
    s2n.plot_fig5(run)
    plt.tight_layout()
    plt.savefig(RESULTS / "branched_systems_reproduction_net_fig5.png", dpi=110)


def trawl(out: str) -> None:
    clock = time.perf_counter()
    runs = s2.run_study(s2.FULL)
    for name, run in runs.items():
        print(f"{name}: {run.steps} steps, {run.wall_time:.1f} s", flush=True)
    trawl_s = time.perf_counter() - clock
    verdict = s2.verdict_markdown(runs)
    print(verdict)
    append_session(
        out,
        part="trawl",
        config=s2.FULL,
        trawl_s=trawl_s,
        trawl={name: trawl_record(run) for name, run in runs.items()},
        verdict=verdict,
    )

    rise, elastic = runs["rise 1→3"], runs["rise 1→3, elastic"]
    _, axes = plt.subplots(4, 2, figsize=(12, 9), sharex="col")
    s2.plot_tensions(rise, axes=axes[:, 0])
    for run in (elastic, rise):
        s2.plot_tensions(run, window=(s2.STEP_TIME - 0.2, s2.STEP_TIME + 3), axes=axes[:, 1])
    axes[0, 1].legend()
    plt.tight_layout()
    plt.savefig(RESULTS / "branched_systems_reproduction_fig7.png", dpi=110)
    s2.plot_tensions(runs["rise 1→4, waves"])
    plt.tight_layout()
    plt.savefig(RESULTS / "branched_systems_reproduction_fig8.png", dpi=110)
    s2.plot_buoy_depth([runs["rise 1→2"], runs["rise 1→2, waves"], runs["rise 1→4, waves"]])
    plt.tight_layout()
    plt.savefig(RESULTS / "branched_systems_reproduction_fig9.png", dpi=110)
    s2.plot_diverter_paths(runs["rise 1→4, waves"])
    plt.tight_layout()
    plt.savefig(RESULTS / "branched_systems_reproduction_fig10.png", dpi=110)
    _, axes = plt.subplots(2, 1, figsize=(10, 5), sharex=True)
    for run in (runs["fall 3→1, elastic"], runs["fall 3→1"]):
        s2.plot_tensions(run, points=("tow point", "buoy"), window=(s2.STEP_TIME - 0.2, s2.STEP_TIME + 3), axes=axes)
    axes[0].legend()
    plt.tight_layout()
    plt.savefig(RESULTS / "branched_systems_reproduction_fall.png", dpi=110)


if __name__ == "__main__":
    main()
