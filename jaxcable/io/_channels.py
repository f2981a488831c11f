"""Output channels with MoorDyn's names: which a scene asks for, their units, and their
values over a run.

Channels (names are case-insensitive on input, written as below):

- `Time` (s).
- `FairTen<k>`, `AnchTen<k>` (N): the magnitude of the tension in the segment at end B
    and at end A of line k, as MoorDyn defines them (the end segment's tension, damping
    included; a slack segment that its damping pushes reads its force's magnitude).
- `L<k>N<i>PX`, `PY`, `PZ` (m), `VX`, `VY`, `VZ` (m/s): the position and velocity of
    node i of line k, i = 0 at end A; MoorDyn's spellings `Line<k>N<i>...`,
    `L<k>NA...` (node 0) and `L<k>NB...` (the last node) too.
- `L<k>N<i>T` (or `TEN`, N): the tension at node i as MoorDyn's: the magnitude of the
    mean of the adjacent segments' force vectors (the end segment's at an end).
- `P<k>PX`, ... `P<k>VZ` (MoorDyn's `Point<k>PX`, and MoorDyn-F's and v1's `Con<k>`,
    `C<k>` and `Connect<k>`): the position (m) and velocity (m/s) of point k.
- `P<k>FX`, `FY`, `FZ` (N): the net force on point k as MoorDyn's `Point::doRHS` sums
    it: every force on the point and the line ends on it (tensions, weight and
    buoyancy, drag, seabed contact, a body's constant force) but not the inertial
    ones, so that it is the mass matrix times the acceleration on a free point, and
    the negative of the support's reaction on a fixed one. `P<k>T` is its magnitude.
    (MoorDyn computes this force only for free and coupled points; it writes zeros
    for a fixed one.)

Names are split as MoorDyn splits them (letters, number, letters, number, the rest).
A name MoorDyn reads but jaxcable does not write (accelerations, rods, bodies, `TA`/`TB`,
`SUB`) or does not know is an [`UnknownChannel`][]: a MoorDyn file's `OUTPUTS` skips it
with a note, as MoorDyn skips a name it cannot read; `--channels` refuses it.

A run ([`jaxcable.io.SceneRun`][]) reads its channels from here, and the writers in
`_output` write them: neither imports the other.
"""

import re
from collections.abc import Callable

import numpy as np

from ._scene import BuiltScene, Scene, SceneError

# MoorDyn's split of a channel name (`str::decomposeString`): letters, a number, letters,
# a number, and whatever follows.
_PARTS = re.compile(r"([A-Z]+)(\d+)([A-Z]*)(\d*)(.*)")
_LINES = ("L", "LINE")
_POINTS = ("P", "POINT", "C", "CON", "CONNECT")
# The quantities jaxcable writes, by MoorDyn's name, and their units.
_QUANTITIES = {"PX": "m", "PY": "m", "PZ": "m", "VX": "m/s", "VY": "m/s", "VZ": "m/s", "T": "N", "TEN": "N"}
_POINT_ONLY = {"FX": "N", "FY": "N", "FZ": "N"}


class UnknownChannel(SceneError):
    """An output channel that jaxcable does not write: a name MoorDyn reads for what
    jaxcable does not model (an acceleration, a rod, a body, `TA`, `SUB`), or no name
    MoorDyn reads at all."""


def default_channels(scene: "Scene") -> tuple[str, ...]:
    """The scene's own channels, or `FairTen<k>` and `AnchTen<k>` for every line."""
    return tuple(scene.channels) or end_tensions(scene)


def end_tensions(scene: "Scene") -> tuple[str, ...]:
    """`FairTen<k>` and `AnchTen<k>` for every line."""
    return tuple(f"{kind}{k}" for k in range(1, len(scene.lines) + 1) for kind in ("FairTen", "AnchTen"))


def is_tension(name: str, scene: "Scene") -> bool:
    """Whether channel `name` is a line's tension (`FairTen<k>`, `AnchTen<k>`,
    `L<k>N<i>T`), not a position, velocity or point force."""
    _, quantity, _, node = parse_channel(name, scene)
    return quantity in ("FairTen", "AnchTen") or (quantity == "T" and node >= 0)


def channel_units(name: str) -> str:
    """The unit of channel `name`: `s`, `N`, `m` or `m/s`."""
    if name == "Time":
        return "s"
    return {**_QUANTITIES, **_POINT_ONLY}.get(_quantity(name), "N")


def _quantity(name: str) -> str:
    """The quantity part of channel `name` in any of its spellings, upper case (`PX`,
    `TEN`, ...); empty for the end tensions or a name with none."""
    parts = _PARTS.fullmatch(name.upper())
    if parts is None:
        return ""
    kind, _, letters, node, rest = parts.groups()
    if node:  # L<k>N<i><quantity>
        return rest
    if kind in _LINES and letters[:2] in ("NA", "NB"):  # L<k>NA<quantity>
        return letters[2:]
    return letters


def describe_channel(name: str, scene: "Scene") -> str:
    """Channel `name` in words a user recognises, for a plot's legend: "line 1
    fairlead tension (end B, at point 2)", "point 2 z", "line 3 node 10 tension". An end
    is a fairlead where its point is coupled (moved) and an anchor where it is fixed, as a
    mooring's are; otherwise it is named by its end ("line rope_3 end B tension (at point
    b2)" for a rope between two buoys of a net)."""
    _, quantity, k, i = parse_channel(name, scene)
    if quantity in ("FairTen", "AnchTen"):
        line = scene.lines[k]
        end = "B" if quantity == "FairTen" else "A"
        point = scene.points[line.end if end == "B" else line.start]
        role = {"FairTen": "coupled", "AnchTen": "fixed"}[quantity]
        if point.kind == role:
            what = "fairlead" if quantity == "FairTen" else "anchor"
            return f"line {line.name} {what} tension (end {end}, at point {point.name})"
        return f"line {line.name} end {end} tension (at point {point.name})"
    words = {"T": "tension", "PX": "x", "PY": "y", "PZ": "z", "VX": "vx", "VY": "vy", "VZ": "vz"}
    words |= {"FX": "net force x", "FY": "net force y", "FZ": "net force z"}
    if i < 0:
        what = "net force" if quantity == "T" else words[quantity]
        return f"point {scene.points[k].name} {what}"
    return f"line {scene.lines[k].name} node {i} {words[quantity]}"


def parse_channel(name: str, scene: "Scene") -> tuple[str, str, int, int]:
    """`(canonical name, quantity, index, node index)` of channel `name`, with quantity
    one of `FairTen`, `AnchTen`, `PX`, `PY`, `PZ`, `VX`, `VY`, `VZ`, `FX`, `FY`, `FZ`,
    `T`, and indices from 0: the line and its node, or the point and node −1 (node −1
    for the end tensions too).

    **Raises:**

    [`UnknownChannel`][] (a [`jaxcable.io.SceneError`][]) for a name jaxcable does not
    write, and `SceneError` naming a channel that refers to a line, node or point that
    does not exist (MoorDyn refuses those too).
    """
    parts = _PARTS.fullmatch(name.upper())
    if parts is None:
        raise _unknown(name)
    kind, number, letters, node, rest = parts.groups()
    if kind in ("FAIRTEN", "ANCHTEN") and not (letters or node or rest):
        label = "FairTen" if kind == "FAIRTEN" else "AnchTen"
        k = _index(name, "line", int(number), len(scene.lines))
        return f"{label}{k + 1}", label, k, -1
    spelled = _quantity(name)
    quantity = "T" if spelled == "TEN" else spelled
    if kind in _LINES:
        k = _index(name, "line", int(number), len(scene.lines))
        last = scene.lines[k].segments
        if node:  # L<k>N<i><quantity>
            i = int(node)
            if i > last:
                raise SceneError(f"output channel {name!r}: line {k + 1} has nodes 0 to {last}")
        elif letters[:2] in ("NA", "NB"):  # L<k>NA<quantity>, L<k>NB<quantity>
            i = 0 if letters[:2] == "NA" else last
        else:
            raise _unknown(name)
        if spelled not in _QUANTITIES:
            raise _unknown(name)
        return f"L{k + 1}N{i}{quantity}", quantity, k, i
    if kind in _POINTS and not node:
        if spelled not in _QUANTITIES and spelled not in _POINT_ONLY:
            raise _unknown(name)
        k = _index(name, "point", int(number), len(scene.points))
        return f"Point{k + 1}{quantity}", quantity, k, -1
    raise _unknown(name)


def _unknown(name: str) -> UnknownChannel:
    return UnknownChannel(
        f"unknown output channel {name!r}; jaxcable writes FairTen<k>, AnchTen<k>, L<k>N<i>PX / PY / PZ / VX / VY / "
        "VZ / T (Line<k>, NA and NB too), and Point<k>PX / PY / PZ / VX / VY / VZ / FX / FY / FZ / T (P<k>, Con<k>, "
        "C<k> too)"
    )


def channels(
    built: BuiltScene,
    times: np.ndarray,
    tension: np.ndarray,
    positions: np.ndarray,
    velocities: np.ndarray,
    point_forces: Callable[[], np.ndarray],
    names: tuple[str, ...] = (),
) -> dict[str, np.ndarray]:
    """Channel values over `times` (s) of a run of `built` with segment tensions `tension`
    (N, shape `(times, segments)`), node positions `positions` (m) and velocities
    `velocities` (m/s, each of shape `(times, nodes, 3)`), by name, `Time` first;
    `names` defaults to [`default_channels`][]. `point_forces()` gives the net force
    on every node (N, shape `(times, nodes, 3)`), called only when a `FX`, `FY`, `FZ`
    or point `T` channel asks for it.

    **Raises:**

    [`jaxcable.io.SceneError`][], as [`parse_channel`][].
    """
    scene = built.scene
    values = {"Time": times}
    forces = None
    for name in tuple(names) or default_channels(scene):
        canonical, quantity, k, i = parse_channel(name, scene)
        if quantity in ("FairTen", "AnchTen"):
            # The end segment's force's magnitude, as MoorDyn writes it: a slack end
            # segment pushed by its damping reads positive there, not negative.
            segments = built.line_segments[k]
            values[canonical] = np.abs(tension[:, segments[-1] if quantity == "FairTen" else segments[0]])
            continue
        # Point k is node k (`Scene.build`); a line's nodes are listed from end A.
        node = k if i < 0 else built.line_nodes[k][i]
        if quantity == "T" and i >= 0:
            values[canonical] = _node_tension(built, k, i, tension, positions)
        elif quantity[0] in "FT":
            forces = point_forces() if forces is None else forces
            force = forces[:, node]
            values[canonical] = (
                np.linalg.norm(force, axis=-1) if quantity == "T" else force[:, "XYZ".index(quantity[1])]
            )
        else:
            series = positions if quantity[0] == "P" else velocities
            values[canonical] = series[:, node, "XYZ".index(quantity[1])]
    return values


def _node_tension(built: BuiltScene, k: int, i: int, tension: np.ndarray, positions: np.ndarray) -> np.ndarray:
    """MoorDyn's `L<k>N<i>T` (N), shape `(times,)`: the magnitude of the mean of the
    force vectors `T τ` of the segments beside node i of line k (of the one segment at
    an end), τ each segment's unit direction from end A."""
    segments, nodes = built.line_segments[k], built.line_nodes[k]
    adjacent = range(max(i - 1, 0), min(i, segments.size - 1) + 1)
    force = 0.0
    for j in adjacent:
        chord = positions[:, nodes[j + 1]] - positions[:, nodes[j]]
        force = force + tension[:, segments[j], None] * (chord / np.linalg.norm(chord, axis=-1, keepdims=True))
    return np.linalg.norm(force / len(adjacent), axis=-1)


def _index(name: str, kind: str, k: int, count: int) -> int:
    if not 1 <= k <= count:
        raise SceneError(f"output channel {name!r}: {kind} {k} does not exist ({count} {kind}s)")
    return k - 1
