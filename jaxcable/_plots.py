"""Figures of a run: tension histories and the shape of the lines (matplotlib)."""

from pathlib import Path
from typing import TYPE_CHECKING

import numpy as np

if TYPE_CHECKING:
    from ._run import SceneRun


def _pyplot():
    try:
        import matplotlib

        matplotlib.use("Agg")
        import matplotlib.pyplot as plt
    except ImportError:
        raise ImportError("plots need matplotlib: pip install matplotlib (or jaxcable[plot])") from None
    return plt


def plot_run(run: "SceneRun", path: str | Path, channels: tuple[str, ...] = (), snapshots: int = 6):
    """Save a two-panel figure of `run` to `path` (any format matplotlib writes).

    Left: the tension history of each of `channels` (MoorDyn names of tension channels,
    `FairTen<k>`, `AnchTen<k>`, `L<k>N<i>T`; every line's end tensions by default), in
    kN against time in s. For a statics-only run, the tension along each line against
    the unstretched arc length from end A instead. Right: the lines in the x–z plane at
    `snapshots` evenly spaced output times (the equilibrium for statics only).

    **Returns:**

    The matplotlib figure, already saved.
    """
    plt = _pyplot()
    figure, (left, right) = plt.subplots(1, 2, figsize=(12, 4.5), layout="constrained")
    scene, built = run.built.scene, run.built
    if run.times.size > 1:
        values = run.channels(channels)
        for name, series in values.items():
            if name != "Time" and not name.endswith(("PX", "PY", "PZ")):
                left.plot(run.times, series / 1e3, label=name, linewidth=1.0)
        left.set_xlabel("time t (s)")
        left.set_title("Tension history")
    else:
        for k, line in enumerate(scene.lines):
            segments = built.line_segments[k]
            arc = (np.arange(segments.size) + 0.5) * line.length / line.segments
            left.plot(arc, run.tension[0, segments] / 1e3, marker=".", label=f"line {line.name}")
        left.set_xlabel("unstretched arc length from end A, s (m)")
        left.set_title("Static tension along the lines")
    left.set_ylabel("tension T (kN)")
    left.grid(True, alpha=0.3)
    left.legend(fontsize="small")

    picks = np.unique(np.linspace(0, run.times.size - 1, max(1, snapshots)).round().astype(int))
    colours = plt.cm.viridis(np.linspace(0, 0.9, picks.size))
    for colour, t in zip(colours, picks):
        for k, nodes in enumerate(built.line_nodes):
            xyz = run.positions[t, nodes]
            label = f"t = {run.times[t]:.2f} s" if k == 0 else None
            right.plot(xyz[:, 0], xyz[:, 2], color=colour, linewidth=1.0, label=label)
    if scene.water.depth is not None:
        right.axhline(-scene.water.depth, color="saddlebrown", linewidth=1.0, label="seabed")
    right.axhline(0.0, color="tab:blue", linewidth=0.8, linestyle="--", label="still water level")
    right.set_xlabel("x (m)")
    right.set_ylabel("z (m)")
    right.set_aspect("equal", adjustable="datalim")
    right.set_title("Line shape, x–z plane")
    right.grid(True, alpha=0.3)
    right.legend(fontsize="small")
    figure.suptitle(f"{scene.title} ({Path(scene.source).name})" if scene.title else Path(scene.source).name)
    figure.savefig(path, dpi=120)
    plt.close(figure)
    return figure
