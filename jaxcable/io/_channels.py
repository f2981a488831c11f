"""Output channels with MoorDyn's names: which a scene asks for, their units, and their
values over a run.

Channels (names are case-insensitive on input, written as below):

- `Time` (s).
- `FairTen<k>`, `AnchTen<k>` (N): the tension in the segment at end B and at end A of
    line k, as MoorDyn defines them (the end segment's tension, damping included).
- `L<k>N<i>PX`, `PY`, `PZ` (m): the position of node i of line k, i = 0 at end A.
- `L<k>N<i>T` (N): the tension at node i, the mean of the adjacent segments' (the end
    segment's at an end), as MoorDyn's.

A run ([`jaxcable.io.SceneRun`][]) reads its channels from here, and the writers in
`_output` write them: neither imports the other.
"""

import re

import numpy as np

from ._scene import BuiltScene, Scene, SceneError

_END_TENSION = re.compile(r"(?i)(fairten|anchten)(\d+)")
_NODE = re.compile(r"(?i)l(\d+)n(\d+)(px|py|pz|t)")


def default_channels(scene: "Scene") -> tuple[str, ...]:
    """The scene's own channels, or `FairTen<k>` and `AnchTen<k>` for every line."""
    if scene.channels:
        return tuple(scene.channels)
    return tuple(f"{kind}{k}" for k in range(1, len(scene.lines) + 1) for kind in ("FairTen", "AnchTen"))


def channel_units(name: str) -> str:
    """The unit of channel `name`: `s`, `N` or `m`."""
    if name == "Time":
        return "s"
    match = _NODE.fullmatch(name)
    return "m" if match and match.group(3).lower() != "t" else "N"


def parse_channel(name: str, scene: "Scene") -> tuple[str, str, int, int]:
    """`(canonical name, quantity, line index, node index)` of channel `name`, with
    quantity one of `FairTen`, `AnchTen`, `PX`, `PY`, `PZ`, `T` and indices from 0
    (node −1 for the end tensions).

    **Raises:**

    [`jaxcable.io.SceneError`][] naming a channel that is unknown or refers to a line or
    node that does not exist.
    """
    count = len(scene.lines)
    if match := _END_TENSION.fullmatch(name):
        kind = "FairTen" if match.group(1).lower() == "fairten" else "AnchTen"
        k = _line_index(name, int(match.group(2)), count)
        return f"{kind}{k + 1}", kind, k, -1
    if match := _NODE.fullmatch(name):
        k = _line_index(name, int(match.group(1)), count)
        i, quantity = int(match.group(2)), match.group(3).upper()
        last = scene.lines[k].segments
        if i > last:
            raise SceneError(f"output channel {name!r}: line {k + 1} has nodes 0 to {last}")
        return f"L{k + 1}N{i}{quantity}", quantity, k, i
    raise SceneError(
        f"unknown output channel {name!r}; jaxcable writes FairTen<k>, AnchTen<k>, L<k>N<i>PX / PY / PZ and L<k>N<i>T"
    )


def channels(
    built: BuiltScene, times: np.ndarray, tension: np.ndarray, positions: np.ndarray, names: tuple[str, ...] = ()
) -> dict[str, np.ndarray]:
    """Channel values over `times` (s) of a run of `built` with segment tensions `tension`
    (N, shape `(times, segments)`) and node positions `positions` (m, shape
    `(times, nodes, 3)`), by name, `Time` first; `names` defaults to
    [`default_channels`][].

    **Raises:**

    [`jaxcable.io.SceneError`][], as [`parse_channel`][].
    """
    scene = built.scene
    values = {"Time": times}
    for name in tuple(names) or default_channels(scene):
        canonical, quantity, k, i = parse_channel(name, scene)
        nodes, segments = built.line_nodes[k], built.line_segments[k]
        if quantity in ("FairTen", "AnchTen"):
            values[canonical] = tension[:, segments[-1] if quantity == "FairTen" else segments[0]]
        elif quantity == "T":
            adjacent = segments[max(i - 1, 0) : min(i, segments.size - 1) + 1]
            values[canonical] = tension[:, adjacent].mean(axis=1)
        else:
            values[canonical] = positions[:, nodes[i], "XYZ".index(quantity[1])]
    return values


def _line_index(name: str, k: int, count: int) -> int:
    if not 1 <= k <= count:
        raise SceneError(f"output channel {name!r}: line {k} does not exist ({count} lines)")
    return k - 1
