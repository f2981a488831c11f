"""Figures: a run's tension histories and line shapes, and a calibration's fit
(matplotlib)."""

from pathlib import Path
from typing import TYPE_CHECKING

import numpy as np

if TYPE_CHECKING:
    from ._calibration.report import CalibrationResult
    from .io._run import SceneRun


def _pyplot():
    try:
        import matplotlib

        matplotlib.use("Agg")
        import matplotlib.pyplot as plt
    except ImportError:
        raise ImportError("plots need matplotlib: pip install matplotlib (or jaxcable[plot])") from None
    return plt


def check_plot_path(path: str | Path, what: str = "plot") -> Path:
    """`path`, once it is known that matplotlib can write a figure there in the format
    its suffix names: before a run, so that `--plot x.foo` fails at once.

    **Raises:**

    [`jaxcable.io.SceneError`][] naming `what` and the path for a format matplotlib does
    not write, or a folder that does not exist (`jaxcable.io.check_writable`);
    `ImportError` without matplotlib.
    """
    from .io._output import check_writable

    _pyplot()  # matplotlib present, with its Agg backend
    from matplotlib.backend_bases import FigureCanvasBase

    formats = FigureCanvasBase.get_supported_filetypes()
    return check_writable(path, what, tuple(f".{suffix}" for suffix in sorted(formats)))


def plot_run(run: "SceneRun", path: str | Path, channels: tuple[str, ...] = (), snapshots: int = 6):
    """Save a two-panel figure of `run` to `path` (any format matplotlib writes).

    Left: the tension history of each tension channel among `channels` (MoorDyn names,
    `FairTen<k>`, `AnchTen<k>`, `L<k>N<i>T`; every line's end tensions by default), in
    kN against time in s, named in words ("line 1 fairlead tension (end B, at point
    2)"). For a statics-only run, the tension along each line against
    the unstretched arc length from end A instead. Right: the lines in the x–z plane at
    `snapshots` evenly spaced output times (the equilibrium for statics only).

    **Returns:**

    The matplotlib figure, already saved.
    """
    plt = _pyplot()
    figure, (left, right) = plt.subplots(1, 2, figsize=(12, 4.5), layout="constrained")
    scene, built = run.built.scene, run.built
    if run.times.size > 1:
        from .io._channels import default_channels, describe_channel, end_tensions, is_tension

        # Tensions only: positions, velocities and point forces are not this panel's.
        names = channels or default_channels(scene)
        tensions = tuple(name for name in names if is_tension(name, scene)) or end_tensions(scene)
        for name, series in run.channels(tensions).items():
            if name != "Time":
                left.plot(run.times, series / 1e3, label=describe_channel(name, scene), linewidth=1.0)
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


# Axis labels of the towing observables, with the unit each is plotted in and its
# factor from SI.
_OBSERVABLES = {
    "speed": ("speed (m/s)", 1.0),
    "tow_load": ("tow-point load (kN)", 1e-3),
    "tension": ("tension (kN)", 1e-3),
    "depth": ("depth (m)", 1.0),
    "layback": ("layback (m)", 1.0),
}


def plot_calibration(result: "CalibrationResult", path: str | Path | None = None):
    """A figure of a calibration: for each record (a row) and observable (a column),
    the measured samples against the fitted model, and the inputs (a horizontal tow's
    speed) that drove it; and, in the last row, the loss at each iteration and the
    fitted coefficients with their one-standard-deviation uncertainty relative to the
    start.

    **Arguments:**

    - `result`: a [`jaxcable.CalibrationResult`][].
    - `path`: where to save it (any format matplotlib writes); not saved if `None`.

    **Returns:**

    The matplotlib figure.
    """
    plt = _pyplot()
    names = [k for k in _OBSERVABLES if any(k in p for p in result.predictions)]
    rows, columns = len(result.records) + 1, max(len(names), 2)
    figure, axes = plt.subplots(rows, columns, figsize=(4.2 * columns, 2.6 * rows), layout="constrained", squeeze=False)
    for row, (record, predicted) in enumerate(zip(result.records, result.predictions)):
        for column in range(columns):
            ax = axes[row, column]
            if column < len(names) and names[column] in record.columns and names[column] not in predicted:
                # An input, such as a horizontal tow's speed: what drove the test.
                label, factor = _OBSERVABLES[names[column]]
                ax.plot(record.times, record.columns[names[column]] * factor, color="0.3", linewidth=1.2, label="input")
                ax.set_ylabel(f"tow {label}")
                ax.set_title(record.name or f"record {row}", fontsize="small")
                ax.grid(True, alpha=0.3)
                continue
            if column >= len(names) or names[column] not in predicted:
                ax.axis("off")
                continue
            label, factor = _OBSERVABLES[names[column]]
            ax.plot(
                record.times,
                record.columns[names[column]] * factor,
                ".",
                markersize=2.5,
                color="0.55",
                label="measured",
            )
            ax.plot(record.times, predicted[names[column]] * factor, color="tab:red", linewidth=1.2, label="fitted")
            ax.set_ylabel(label)
            ax.set_title(record.name or f"record {row}", fontsize="small")
            ax.grid(True, alpha=0.3)
            if row == rows - 2:
                ax.set_xlabel("time t (s)")
    next(ax for ax in axes.flat if len(ax.lines) > 1).legend(fontsize="small")
    loss, coefficients = axes[-1, 0], axes[-1, 1]
    loss.semilogy(np.arange(result.loss.size), result.loss, marker="o", markersize=3)
    loss.set_xlabel("iteration")
    loss.set_ylabel("loss")
    loss.set_title("Loss", fontsize="small")
    loss.grid(True, alpha=0.3)
    fitted = list(result.values)
    ratio = [result.values[n] / result.start[n] for n in fitted]
    spread = [result.uncertainty[n] / result.start[n] for n in fitted]
    coefficients.errorbar(np.arange(len(fitted)), ratio, yerr=spread, fmt="o", capsize=4)
    coefficients.set_xticks(np.arange(len(fitted)), fitted, fontsize="small")
    coefficients.set_ylabel("fitted / start (±1σ)")
    coefficients.set_title("Coefficients", fontsize="small")
    coefficients.grid(True, alpha=0.3)
    for ax in axes[-1, 2:]:
        ax.axis("off")
    if path is not None:
        figure.savefig(path, dpi=120)
        plt.close(figure)
    return figure
