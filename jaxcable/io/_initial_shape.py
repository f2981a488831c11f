"""The shape a scene's lines start in when statics is skipped: MoorDyn's own.

With `TmaxIC = 0` MoorDyn runs no initial-condition solve, and each line starts where
`Line::initialize` put it (MoorDyn v2.7, Line.cpp): on the elastic catenary between
its end points (Jonkman's quasi-static line, FAST v7 and MAP, `QSlines.hpp`) when
they are more than 0.1 mm apart horizontally, with the seabed under the line's lower
end when either end is on the bed; straight between them otherwise, or where the
catenary has no solution (a line too long to reach its fairlead without doubling back
on the bed, a neutrally buoyant line, an iteration that does not converge). Free
points start at the file's positions, at rest.

The catenary here is solved in numpy by Newton's method on the fairlead tension
(H, V) as MoorDyn iterates: its first guess, its damped steps, and its stop at a
relative step of 1e-5 (before that step is taken). A stiff line's start tension
depends on that tolerance (on a chain of EA 5e8 N, 1e-4 m of stretch is kilonewtons),
so a converged catenary would not start where MoorDyn's does.
"""

import numpy as np

from ._scene import BuiltScene

# MoorDyn's tolerances: the horizontal spread below which a line starts vertical and
# straight (m), and the catenary's relative tolerance, which also marks an end on the
# bed (within 1e-5 of the depth), floors the spans, damps the steps and bounds their
# number (1/TOLERANCE).
VERTICAL_SPREAD = 1e-4
TOLERANCE = 1e-5


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


def catenary(
    spread: float, rise: float, length: float, stiffness: float, weight: float, on_bed: bool, arc: np.ndarray
) -> tuple[np.ndarray, np.ndarray] | None:
    """The elastic catenary of a line from end A to end B, `spread` (m) apart
    horizontally and B `rise` (m) above A, of unstretched `length` (m), axial stiffness
    `stiffness` (N) and wet weight `weight` (N/m), resting on a frictionless bed
    through its lower end if `on_bed`; `None` where it has no solution.

    **Returns:**

    The horizontal distance from A towards B and the height above A (m) of the points
    at unstretched arc lengths `arc` (m) from A, each of `arc`'s shape.
    """
    if rise < 0:  # solve with the ends swapped, so that the lower end is at the origin
        solved = catenary(spread, -rise, length, stiffness, weight, on_bed, length - arc)
        if solved is None:
            return None
        horizontal, vertical = solved
        return spread - horizontal, vertical - (-rise)
    if weight == 0:
        return None
    on_bed = on_bed and weight > 0
    # MoorDyn floors both spans at the tolerance, so that neither limit case (vertical,
    # horizontal) needs its own formulas.
    spread, rise = max(spread, TOLERANCE), max(rise, TOLERANCE)
    if on_bed and length >= spread - stiffness / weight + np.sqrt(
        (stiffness / weight) ** 2 + 2 * rise * stiffness / weight
    ):
        return None  # longer than the "L" along the bed and up to B: it would double back
    tensions = _fairlead_tension(spread, rise, length, stiffness, weight, on_bed)
    if tensions is None:
        return None
    horizontal_tension, vertical_tension = tensions
    w, h, ea = weight, horizontal_tension, stiffness
    anchor = vertical_tension - w * length  # the vertical tension at A (negative: on the bed)
    if not on_bed or anchor > 0:
        ratio = (anchor + w * arc) / h
        x = h / w * (np.arcsinh(ratio) - np.arcsinh(anchor / h)) + arc * h / ea
        z = h / w * (np.hypot(1, ratio) - np.hypot(1, anchor / h)) + arc / ea * (anchor + w * arc / 2)
        return x, z
    resting = length - vertical_tension / w  # the length on the bed
    ratio = np.maximum(anchor + w * arc, 0.0) / h
    hanging = h / w * np.arcsinh(ratio) + resting
    x = np.where(arc <= resting, arc, hanging) + arc * h / ea
    z = np.where(arc <= resting, 0.0, h / w * (np.hypot(1, ratio) - 1) + arc / ea * (anchor + w * arc / 2))
    z = z + np.where(arc <= resting, 0.0, anchor**2 / (2 * w * ea))
    return x, z


def _fairlead_tension(
    spread: float, rise: float, length: float, stiffness: float, weight: float, on_bed: bool
) -> tuple[float, float] | None:
    """The horizontal and vertical tension (N) at the upper end that put it `spread`,
    `rise` (m) from the lower: Newton's method on the catenary's closure equations
    from Peyrot and Goulois's first guess, with MoorDyn's damping and stopping rule
    (module docstring); `None` if it does not converge."""
    w, ea, length = weight, stiffness, length
    if length <= np.hypot(spread, rise):
        shape = 0.2  # taut
    else:
        shape = np.sqrt(3 * ((length**2 - rise**2) / spread**2 - 1))
    h = max(abs(0.5 * w * spread / shape), TOLERANCE)
    v = 0.5 * w * (rise / np.tanh(shape) + length)
    for step in range(1, int(round(1 / TOLERANCE)) + 1):
        a, b = v / h, (v - w * length) / h
        ra, rb = np.hypot(1, a), np.hypot(1, b)
        if on_bed and v - w * length <= 0:
            x = h / w * np.arcsinh(a) + length * h / ea + length - v / w - spread
            z = h / w * (ra - 1) + v**2 / (2 * w * ea) - rise
            jacobian = np.array(
                [
                    [(np.arcsinh(a) - a / ra) / w + length / ea, (1 / ra - 1) / w],
                    [(ra - 1 - a**2 / ra) / w, a / ra / w + v / (w * ea)],
                ]
            )
        else:
            x = h / w * (np.arcsinh(a) - np.arcsinh(b)) + length * h / ea - spread
            z = h / w * (ra - rb) + length / ea * (v - w * length / 2) - rise
            jacobian = np.array(
                [
                    [(np.arcsinh(a) - np.arcsinh(b) - a / ra + b / rb) / w + length / ea, (1 / ra - 1 / rb) / w],
                    [(ra - rb - a**2 / ra + b**2 / rb) / w, (a / ra - b / rb) / w + length / ea],
                ]
            )
        try:
            dh, dv = np.linalg.solve(jacobian, [-x, -z])
        except np.linalg.LinAlgError:
            return None
        dh, dv = dh * (1 - TOLERANCE * step), dv * (1 - TOLERANCE * step)
        dh = max(dh, (TOLERANCE - 1) * h)  # keeps the horizontal tension positive
        if not (np.isfinite(dh) and np.isfinite(dv)):
            return None
        if abs(dh) <= TOLERANCE * h and abs(dv) <= TOLERANCE * abs(v):
            return float(h), float(v)
        h, v = h + dh, v + dv
    return None
