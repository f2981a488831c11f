"""A campaign's short report, `report.html`: what ran, the cases and lines whose safety
factor falls short, the table of cases and of groups of seeds, and a figure of each
line's largest tension by case against its allowed load. One self-contained file (the
figure embedded), to open in a browser or print to PDF; the figure needs matplotlib
(the `plot` extra), and without it the report has the tables alone."""

import base64
import html
import io
import math
from pathlib import Path
from typing import Any

from .store import cell, shortfalls


def write_report(
    path: Path,
    title: str,
    rows: list[dict[str, Any]],
    given: list[str],
    groups: list[dict[str, Any]],
    required: float,
) -> Path:
    """Write the report of `rows` (a case each, `summary_rows`, whose case table's
    columns are `given`) and `groups` (`group_rows`) to `path`, judging safety factors
    against `required`."""
    lines = sorted({c.split(".", 1)[1] for row in rows for c in row if c.startswith("largest_tension.")})
    failed = [row for row in rows if row.get("failed")]
    finished = [row for row in rows if not row.get("failed")]
    short = shortfalls(finished, required) + shortfalls(groups, required, "mpm_safety_factor.")
    parts = [
        f"<h1>{html.escape(title)}</h1>",
        f"<p>{len(finished)} case(s) finished, {len(failed)} failed. Safety factors are each line's minimum "
        f"breaking load over its largest tension (over a group's seeds, its most probable maximum), judged "
        f"against {required:g}.</p>",
    ]
    if short:
        parts.append("<h2>Below the required safety factor</h2><ul>")
        parts += [f"<li>{html.escape(text)}</li>" for text in short]
        parts.append("</ul>")
    figure = _figure(finished, lines, required)
    if figure:
        parts.append(f'<h2>Largest tension by case</h2><img alt="largest tension by case" src="{figure}">')
    columns = ["case", *given, *(f"{kind}.{line}" for line in lines for kind in _PER_LINE)]
    parts += ["<h2>Cases</h2>", _table(finished, columns)]
    if groups:
        kinds = ("mpm_tension", "mpm_standard_error", "mpm_safety_factor", "mean_fatigue_damage")
        group_columns = ["cases", "seeds", *(f"{kind}.{line}" for line in lines for kind in kinds)]
        parts += ["<h2>Sea states over seeds</h2>", _table(groups, group_columns)]
    if failed:
        parts += ["<h2>Failed cases</h2>", _table(failed, ["case", "failed"])]
    style = (
        "body{font-family:sans-serif;margin:2em}table{border-collapse:collapse;font-size:0.85em}"
        "td,th{border:1px solid #ccc;padding:2px 6px;text-align:right}th{background:#eee}img{max-width:100%}"
    )
    text = f'<!DOCTYPE html><html><head><meta charset="utf-8"><title>{html.escape(title)}</title>'
    text += f"<style>{style}</style></head><body>{''.join(parts)}</body></html>\n"
    path.write_text(text, encoding="utf-8")
    return path


# Each line's columns in the report's table of cases.
_PER_LINE = ("largest_tension", "safety_factor", "fatigue_damage", "fatigue_equivalent_load")

# The columns shown in kN, which the tables hold in N.
_KILONEWTONS = ("largest_tension", "mpm_tension", "mpm_standard_error", "fatigue_equivalent_load")


def _table(rows: list[dict[str, Any]], columns: list[str]) -> str:
    present = [c for c in columns if any(c in row for row in rows)]
    head = "".join(f"<th>{html.escape(_heading(c))}</th>" for c in present)
    body = "".join(
        "<tr>" + "".join(f"<td>{html.escape(cell(_shown(row.get(c), c), 4))}</td>" for c in present) + "</tr>"
        for row in rows
    )
    return f"<table><tr>{head}</tr>{body}</table>"


def _shown(value: Any, column: str) -> Any:
    """A table's value as the report shows it: tensions in kN."""
    if column.partition(".")[0] in _KILONEWTONS and isinstance(value, float):
        return value / 1e3
    return value


def _heading(column: str) -> str:
    kind, _, line = column.partition(".")
    units = " (kN)" if kind in _KILONEWTONS else ""
    return f"{kind.replace('_', ' ')}{units}" + (f", {line}" if line else "")


def _figure(rows: list[dict[str, Any]], lines: list[str], required: float) -> str:
    """Each line's largest tension (kN) by case, with its allowed load (MBL over the
    required factor) where it has one, as a PNG data URL; empty without matplotlib or
    cases."""
    try:
        import matplotlib

        matplotlib.use("Agg")
        import matplotlib.pyplot as plt
    except ImportError:
        return ""
    if not rows or not lines:
        return ""
    names = [str(row["case"]) for row in rows]
    figure, axes = plt.subplots(figsize=(max(6.0, 0.25 * len(rows) + 2), 4), layout="constrained")
    for line in lines:
        values = [row.get(f"largest_tension.{line}", math.nan) / 1e3 for row in rows]
        (drawn,) = axes.plot(names, values, "o", label=f"line {line}")
        # The allowed load, MBL / required, each case's (a case may change the line's type).
        factors = [row.get(f"safety_factor.{line}", math.nan) for row in rows]
        allowed = [v * f / required for v, f in zip(values, factors)]
        if any(math.isfinite(a) for a in allowed):
            axes.plot(
                names, allowed, "_", markersize=14, color=drawn.get_color(), label=f"line {line}: MBL / {required:g}"
            )
    axes.set_ylabel("largest tension (kN)")
    axes.tick_params(axis="x", labelrotation=90)
    axes.legend(loc="upper center", bbox_to_anchor=(0.5, -0.35), ncol=min(4, 2 * len(lines)), fontsize="small")
    buffer = io.BytesIO()
    figure.savefig(buffer, format="png", dpi=100)
    plt.close(figure)
    return "data:image/png;base64," + base64.b64encode(buffer.getvalue()).decode()
