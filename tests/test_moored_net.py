"""The moored net in still water: the static equilibrium, and its symmetry.

The reference is the discrete equilibrium written out by hand with numpy, independent of
jaxcable's Lagrangian: at every free node (the buoys, the frame's corners and hub, and
the branches' interior nodes), Hooke's-law tensions along the solved segments, half of
each adjacent segment's submerged weight, and each floating buoy's weight and the
buoyancy of its submerged part must sum to zero; at the anchors, the same sum is the
support's reaction. The geometry is symmetric under a quarter turn about the vertical
axis and under the mirror y → −y (the wave's vertical plane), so the equilibrium must be.
"""

import numpy as np
import pytest
from helpers import hand_forces, wet_fraction

import jaxcable as jc
from jaxcable.examples._moored_net import (
    BUOY,
    CORNER_DEPTH,
    HUB,
    anchor_node,
    branch_segments,
    buoy_node,
    corner_node,
    fig5_segments,
    moored_net,
)

SEGMENTS = (2, 3, 3, 2)  # few, for speed: upper, lower, row side, diagonal


@pytest.fixture(scope="module")
def net():
    model, env = moored_net(segments=SEGMENTS)
    statics = jc.solve_statics(model, env.without_waves())
    return model, env, statics


def test_net_nodes_balance_by_hand(net):
    model, env, statics = net
    positions = np.asarray(statics.state.positions)
    # Two materials: the steel vertical branches and the polyester frame.
    assert len(np.unique(np.asarray(model.line.tension_law.axial_stiffness))) == 2
    buoys = {buoy_node(b): BUOY for b in range(1, 5)}
    tension, force = hand_forces(model, env, positions, buoys)
    np.testing.assert_allclose(np.asarray(statics.tension), tension, rtol=1e-6)
    assert np.all(tension > 0)  # every segment taut
    # Each buoy floats, piercing the still surface: its buoyancy is of its part below z = 0.
    wet = wet_fraction(BUOY, positions[list(buoys), 2])
    assert np.all((0.0 < wet) & (wet < 1.0))
    free = np.asarray(model.free_nodes)
    scale = np.max(np.abs(tension))
    assert np.max(np.abs(force[free])) < 1e-7 * scale
    # The anchors' reactions balance what the network pulls them with.
    anchors = np.asarray(model.constrained_nodes)
    np.testing.assert_array_equal(anchors, [anchor_node(b) for b in range(1, 5)])
    np.testing.assert_allclose(np.asarray(statics.reactions), -force[anchors], atol=1e-7 * scale)


def _chain(model, start, end):
    """The nodes of the branch from junction `start` to `end`, in order."""
    ends = np.asarray(model.segment_nodes)
    segments = branch_segments(model, start, end)
    return np.append(ends[segments, 0], ends[segments[-1], 1]), segments


def _branches():
    """Every branch as (start, end) junctions, with the branch it becomes under a
    quarter turn (buoy k → k + 1) and under the mirror y → −y (buoys 2 ↔ 4), each with
    whether it is then traversed backwards."""

    def turn(b):
        return b % 4 + 1

    def mirror(b):
        return {1: 1, 2: 4, 3: 3, 4: 2}[b]

    out = []
    for b in range(1, 5):
        for node in (buoy_node, corner_node):
            to = {buoy_node: corner_node, corner_node: anchor_node}[node]
            out.append(((node(b), to(b)), (node(turn(b)), to(turn(b))), (node(mirror(b)), to(mirror(b)))))
        ring = (corner_node(b), corner_node(turn(b)))
        # The mirror turns the ring's sense: side b → b+1 becomes side b' − 1 → b'.
        mirrored = (corner_node(mirror(turn(b))), corner_node(mirror(b)))
        out.append((ring, (corner_node(turn(b)), corner_node(turn(turn(b)))), mirrored + ("reversed",)))
        out.append(((HUB, corner_node(b)), (HUB, corner_node(turn(b))), (HUB, corner_node(mirror(b)))))
    return out


def test_net_is_symmetric(net):
    # A quarter turn about z maps buoy k's branches onto buoy k + 1's; the mirror
    # y → −y maps buoys 2 and 4 onto each other. Nodes map onto nodes, branch by branch,
    # with the same tensions.
    model, _, statics = net
    p = np.asarray(statics.state.positions)
    tension = np.asarray(statics.tension)
    quarter = np.array([[0.0, -1.0, 0.0], [1.0, 0.0, 0.0], [0.0, 0.0, 1.0]])  # +90° about z
    mirror = np.diag([1.0, -1.0, 1.0])
    assert len(_branches()) == 16
    for branch, turned, mirrored in _branches():
        nodes, segments = _chain(model, *branch)
        for transform, image in ((quarter, turned), (mirror, mirrored)):
            backwards = image[-1] == "reversed"
            other, other_segments = _chain(model, *image[:2])
            if backwards:
                other, other_segments = other[::-1], other_segments[::-1]
            np.testing.assert_allclose(p[nodes] @ transform.T, p[other], atol=1e-6)
            np.testing.assert_allclose(tension[segments], tension[other_segments], rtol=1e-6)
    # The hub stays on the axis, and the frame hangs near its design depth, below the
    # corners, with each buoy above its corner and the upper parts plumb.
    np.testing.assert_allclose(p[HUB, :2], 0.0, atol=1e-6)
    corners = [corner_node(b) for b in range(1, 5)]
    assert np.all(np.abs(p[corners, 2] + CORNER_DEPTH) < 1.0)
    assert p[HUB, 2] < p[corners[0], 2]
    for b in range(1, 5):
        np.testing.assert_allclose(p[buoy_node(b), :2], p[corner_node(b), :2], atol=1e-6)


def test_fig5_places(net):
    # Fig. 5's four places on buoy 2's vertical branch, from the buoy down to the anchor.
    model, _, statics = net
    ends = np.asarray(model.segment_nodes)
    places = fig5_segments(model, 2)
    assert list(places) == ["under buoy", "above junction", "below junction", "near anchor"]
    s = places
    assert ends[s["under buoy"], 0] == buoy_node(2)
    assert ends[s["above junction"], 1] == corner_node(2)
    assert ends[s["below junction"], 0] == corner_node(2)
    assert ends[s["near anchor"], 1] == anchor_node(2)
    # In still water the tension falls down each part, which carries its own weight.
    tension = np.asarray(statics.tension)
    assert tension[s["under buoy"]] > tension[s["above junction"]]
    assert tension[s["below junction"]] > tension[s["near anchor"]]
