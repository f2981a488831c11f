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


def plot_run(run: "SceneRun", path: str | Path, channels: tuple[str, ...] = (), snapshots: int = 0):
    """Save a three-panel figure of `run` to `path` (any format matplotlib writes).

    Left: the tension history of each tension channel among `channels` (MoorDyn names,
    `FairTen<k>`, `AnchTen<k>`, `L<k>N<i>T`; every line's end tensions by default), in
    kN against time in s, named in words ("line 1 fairlead tension (end B, at point
    2)"). For a statics-only run, the tension along each line against the unstretched
    arc length from end A instead. Middle and right: the lines in plan (x–y) and in
    elevation (x–z), at the start (the equilibrium), at the time of the run's largest
    segment tension and at that of its smallest, and at `snapshots` more evenly spaced
    output times (grey), with the points marked by kind (fixed, coupled, free), the
    still-water level and the seabed. Legends sit below the panels, off the data.

    **Returns:**

    The matplotlib figure, already saved.
    """
    plt = _pyplot()
    figure, (history, plan, elevation) = plt.subplots(
        1, 3, figsize=(16, 5.2), layout="constrained", gridspec_kw={"width_ratios": [1.2, 1.0, 1.0]}
    )
    scene, built = run.built.scene, run.built
    if run.times.size > 1:
        from .io._channels import default_channels, describe_channel, end_tensions, is_tension

        # Tensions only: positions, velocities and point forces are not this panel's.
        names = channels or default_channels(scene)
        tensions = tuple(name for name in names if is_tension(name, scene)) or end_tensions(scene)
        for name, series in run.channels(tensions).items():
            if name != "Time":
                history.plot(run.times, series / 1e3, label=describe_channel(name, scene), linewidth=1.0)
        history.set_xlabel("time t (s)")
        history.set_title("Tension history")
    else:
        for k, line in enumerate(scene.lines):
            segments = built.line_segments[k]
            arc = (np.arange(segments.size) + 0.5) * line.length / line.segments
            history.plot(arc, run.tension[0, segments] / 1e3, marker=".", label=f"line {line.name}")
        history.set_xlabel("unstretched arc length from end A, s (m)")
        history.set_title("Static tension along the lines")
    history.set_ylabel("tension T (kN)")
    history.grid(True, alpha=0.3)
    _legend_below(history)

    for when, (colour, label, width) in _shapes(run, snapshots).items():
        for k, nodes in enumerate(built.line_nodes):
            xyz = run.positions[when, nodes]
            for axes, (a, b) in ((plan, (0, 1)), (elevation, (0, 2))):
                axes.plot(xyz[:, a], xyz[:, b], color=colour, linewidth=width, label=label if k == 0 else None)
    start = run.positions[0]
    for kind, marker in (("fixed", "^"), ("coupled", "s"), ("free", "o")):
        held = [k for k, point in enumerate(scene.points) if point.kind == kind]
        for axes, (a, b) in ((plan, (0, 1)), (elevation, (0, 2))):
            if held:
                axes.plot(
                    start[held, a], start[held, b], marker, color="black", markerfacecolor="none", label=f"{kind} point"
                )
    if scene.water.depth is not None:
        elevation.axhline(-scene.water.depth, color="saddlebrown", linewidth=1.0, label="seabed")
    elevation.axhline(0.0, color="tab:blue", linewidth=0.8, linestyle="--", label="still water level")
    for axes, (a, b), title in ((plan, "xy", "Plan, x–y"), (elevation, "xz", "Elevation, x–z")):
        axes.set_xlabel(f"{a} (m)")
        axes.set_ylabel(f"{b} (m)")
        axes.set_aspect("equal", adjustable="datalim")
        axes.set_title(title)
        axes.grid(True, alpha=0.3)
        _legend_below(axes)
    figure.suptitle(f"{scene.title} ({Path(scene.source).name})" if scene.title else Path(scene.source).name)
    figure.savefig(path, dpi=120)
    plt.close(figure)
    return figure


def _shapes(run: "SceneRun", snapshots: int) -> dict[int, tuple[str, str, float]]:
    """The output times (indices) whose shapes a run's figure draws, in drawing order,
    each with its colour, legend label and line width: `snapshots` evenly spaced times
    (grey, under the rest), then the start and the times of the largest and the
    smallest segment tension."""
    start = "equilibrium" if run.static is not None else "start"
    marked = {0: ("black", start if run.times.size > 1 else f"{start} (statics only)", 1.4)}
    if run.times.size > 1:
        largest, k, _, _ = run.peak_tension()
        most = int(np.argmax(np.max(run.tension, axis=1)))
        least = int(np.argmin(np.min(run.tension, axis=1)))
        name = run.built.scene.lines[k].name
        marked[most] = (
            "tab:red",
            f"largest tension, {largest / 1e3:.4g} kN in line {name} (t = {run.times[most]:.2f} s)",
            1.4,
        )
        smallest = float(np.min(run.tension[least])) + 0.0
        marked.setdefault(
            least, ("tab:blue", f"smallest tension, {smallest / 1e3:.4g} kN (t = {run.times[least]:.2f} s)", 1.4)
        )
    evenly = np.unique(np.linspace(0, run.times.size - 1, snapshots).round().astype(int)) if snapshots else ()
    grey = [int(t) for t in evenly if int(t) not in marked]
    shapes = {t: ("0.75", "evenly spaced times" if n == 0 else "_nolegend_", 0.8) for n, t in enumerate(grey)}
    return shapes | marked


def _legend_below(axes) -> None:
    """`axes`' legend under it, outside the data."""
    axes.legend(fontsize="small", loc="upper center", bbox_to_anchor=(0.5, -0.14), frameon=False, ncols=1)


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
