"""The shape a scene's lines start in when statics is skipped: MoorDyn's own.

With `TmaxIC = 0` MoorDyn runs no initial-condition solve, and each line starts where
`Line::initialize` put it (MoorDyn v2.7, Line.cpp): on the elastic catenary between
its end points (Jonkman's quasi-static line, FAST v7 and MAP, `QSlines.hpp`) when
they are more than 0.1 mm apart horizontally, with the seabed under the line's lower
end when either end is on the bed; straight between them otherwise, or where the
catenary has no solution (a line too long to reach its fairlead without doubling back
on the bed, a neutrally buoyant line, an iteration that does not converge). Free
points start at the file's positions, at rest.

The catenary ([`jaxcable._statics.catenary.catenary`][]) is solved in numpy by Newton's method
on the fairlead tension (H, V) as MoorDyn iterates: its first guess, its damped steps,
and its stop at a relative step of 1e-5 (before that step is taken). A stiff line's
start tension depends on that tolerance (on a chain of EA 5e8 N, 1e-4 m of stretch is
kilonewtons), so a converged catenary would not start where MoorDyn's does.
"""

import numpy as np

from .._statics.catenary import TOLERANCE, catenary
from ._scene import BuiltScene

# MoorDyn's horizontal spread below which a line starts vertical and straight (m); its
# catenary's tolerance, `TOLERANCE`, also marks an end on the bed (within 1e-5 of the
# depth).
VERTICAL_SPREAD = 1e-4


def initial_positions(built: BuiltScene) -> tuple[np.ndarray, tuple[str, ...]]:
    """Node positions (m, shape `(nodes, 3)`) with every line on MoorDyn's start shape
    (module docstring) and every point at the file's position; with a note naming
    each line started straight because its catenary had no solution."""
    scene = built.scene
    positions = np.array(built.model.node_positions, dtype=float)
    types = {t.name: t for t in scene.line_types}
    depth = scene.water.depth
    notes = []
    for line, nodes in zip(scene.lines, built.line_nodes):
        start = np.asarray(scene.points[line.start].position, dtype=float)
        end = np.asarray(scene.points[line.end].position, dtype=float)
        chord = end - start
        n = line.segments
        shape = start + chord * (np.arange(n + 1) / n)[:, None]
        spread = float(np.hypot(chord[0], chord[1]))
        if spread > VERTICAL_SPREAD:
            kind = types[line.line_type]
            area = np.pi * kind.diameter**2 / 4
            weight = float((kind.mass_per_length - scene.water.density * area) * scene.water.gravity)
            on_bed = depth is not None and bool(min(start[2], end[2]) <= -depth * (1 - TOLERANCE))
            arc = np.linspace(0.0, line.length, n + 1)
            profile = catenary(
                spread, float(chord[2]), float(line.length), float(kind.axial_stiffness), weight, on_bed, arc
            )
            if profile is None:
                notes.append(
                    f"{line.where}: line {line.name} starts straight between its ends: its catenary has no "
                    "solution (as in MoorDyn, which then starts it straight too)"
                )
            else:
                horizontal, vertical = profile
                heading = chord[:2] / spread
                shape = start + np.column_stack((horizontal * heading[0], horizontal * heading[1], vertical))
        positions[nodes[1:-1]] = shape[1:-1]
    return positions, tuple(notes)
