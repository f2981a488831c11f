"""Bad input fails at construction, with a message naming the field and the value."""

import math

import equinox as eqx
import jax
import numpy as np
import pytest

import jaxcable as jc


def law(**kw):
    return jc.LinearElastic(1e6, **kw)


def line(**kw):
    args = dict(mass_per_length=1.0, diameter=0.02, tension_law=law())
    args.update(kw)
    return jc.LineType(**args)


def network(**kw):
    args = dict(
        node_positions=[[0.0, 0, 0], [1, 0, 0], [2, 0, 0]],
        segment_nodes=[[0, 1], [1, 2]],
        segment_length=[1.0, 1.0],
        line=line(),
        constraints={0: jc.Fixed(), 2: jc.Fixed()},
    )
    args.update(kw)
    return jc.CableNetwork(**args)


def test_a_valid_network_builds():
    model = network(bodies={1: jc.Body(mass=2.0, volume=0.001)})
    assert model.n_nodes == 3 and model.n_segments == 2
    assert model.free_nodes.tolist() == [1]
    assert model.body.mass.tolist() == [0.0, 2.0, 0.0]


@pytest.mark.parametrize(
    "field, value, message",
    [
        ("mass_per_length", 0.0, r"LineType.mass_per_length must be positive, got 0.0"),
        ("mass_per_length", -3.0, r"LineType.mass_per_length must be positive, got -3.0"),
        ("diameter", -0.1, r"LineType.diameter must be positive, got -0.1"),
        ("area", 0.0, r"LineType.area must be positive, got 0.0"),
        ("normal_drag", -1.0, r"LineType.normal_drag must be non-negative, got -1.0"),
        ("tangential_added_mass", -1.0, r"LineType.tangential_added_mass must be non-negative"),
    ],
)
def test_non_positive_line_properties(field, value, message):
    with pytest.raises(ValueError, match=message):
        line(**{field: value})


def test_non_positive_stiffness():
    with pytest.raises(ValueError, match=r"tension_law.axial_stiffness must be positive, got -5.0"):
        line(tension_law=jc.LinearElastic(-5.0))
    with pytest.raises(ValueError, match=r"tension_law.slack_width must be non-negative, got -0.1"):
        line(tension_law=jc.LinearElastic(1e6, slack_width=-0.1))
    with pytest.raises(ValueError, match=r"tension_law.damping must be non-negative, got -1.0"):
        line(tension_law=jc.KelvinVoigt(1e6, 0.0, -1.0))


def test_non_positive_length_names_the_segment():
    with pytest.raises(ValueError, match=r"CableNetwork.segment_length must be positive, got 0.0 at index 1"):
        network(segment_length=[1.0, 0.0])


def test_non_positive_body_mass():
    with pytest.raises(ValueError, match=r"Body.mass must be non-negative, got -1.0"):
        jc.Body(mass=-1.0)


@pytest.mark.parametrize("bad", [math.nan, math.inf, -math.inf])
def test_nan_and_inf(bad):
    with pytest.raises(ValueError, match=rf"LineType.diameter must be finite, got {bad}"):
        line(diameter=bad)
    with pytest.raises(ValueError, match=r"CableNetwork.node_positions must be finite"):
        network(node_positions=[[0.0, 0, 0], [1, bad, 0], [2, 0, 0]])
    with pytest.raises(ValueError, match=r"Environment.current must be finite"):
        jc.Environment(current=(bad, 0.0, 0.0))
    with pytest.raises(ValueError, match=r"Harmonic.amplitude must be finite"):
        jc.Harmonic(bad, 5.0)
    with pytest.raises(ValueError, match=r"tension_law.axial_stiffness must be finite"):
        line(tension_law=jc.LinearElastic(bad))


def test_node_index_out_of_range():
    with pytest.raises(ValueError, match=r"segment_nodes\[1, 1\] = 3 is out of range for 3 nodes"):
        network(segment_nodes=[[0, 1], [1, 3]])
    with pytest.raises(ValueError, match=r"segment_nodes\[0, 0\] = -1 is out of range"):
        network(segment_nodes=[[-1, 1], [1, 2]])
    with pytest.raises(ValueError, match=r"constraints has node 7, out of range for 3 nodes"):
        network(constraints={0: jc.Fixed(), 7: jc.Fixed()})
    with pytest.raises(ValueError, match=r"bodies has node 5, out of range"):
        network(bodies={5: jc.Body(mass=1.0)})
    with pytest.raises(ValueError, match=r"branches\[0\].end = 4 is out of range for 2 junctions"):
        jc.CableNetwork.from_branches([[0.0, 0, 0], [1, 0, 0]], [jc.Branch(0, 4, line(), 1.0, 2)], {0: jc.Fixed()})


def test_segment_joining_a_node_to_itself():
    with pytest.raises(ValueError, match=r"segment_nodes\[1\] joins node 1 to itself"):
        network(segment_nodes=[[0, 1], [1, 1]])


def test_unheld_part_of_the_network_has_no_statics():
    # Nodes 2-3 form their own component, with no constrained node: it may move freely,
    # but it has no equilibrium.
    env = jc.Environment(water_density=1025.0)
    free_pair = network(
        node_positions=[[0.0, 0, 0], [1, 0, 0], [2, 0, 0], [3, 0, 0]],
        segment_nodes=[[0, 1], [2, 3]],
        constraints={0: jc.Fixed()},
    )
    with pytest.raises(ValueError, match=r"nodes \[2, 3\] form a part of the network with no constrained node"):
        jc.solve_statics(free_pair, env)
    with pytest.raises(ValueError, match=r"no constrained node"):
        jc.solve_statics(network(constraints={}), env)
    # The topology is static, so the check holds when the model is traced too.
    with pytest.raises(ValueError, match=r"nodes \[2, 3\] form a part of the network with no constrained node"):
        eqx.filter_jit(jc.solve_statics)(free_pair, env)
    with pytest.raises(ValueError, match=r"nodes \[2, 3\] form a part"):
        jax.vmap(lambda m: jc.solve_statics(m, env).residual)(jax.tree.map(lambda x: x[None], free_pair))


def test_mismatched_shapes():
    with pytest.raises(ValueError, match=r"CableNetwork.segment_length must have shape \(2,\).*got shape \(3,\)"):
        network(segment_length=[1.0, 1.0, 1.0])
    with pytest.raises(ValueError, match=r"CableNetwork.line.mass_per_length must have shape \(2,\).*got shape \(5,\)"):
        network(line=line(mass_per_length=np.ones(5)))
    with pytest.raises(ValueError, match=r"node_positions must have shape \(nodes, 3\), got \(3, 2\)"):
        network(node_positions=np.zeros((3, 2)))
    with pytest.raises(ValueError, match=r"segment_nodes must have shape \(segments, 2\), got \(2, 3\)"):
        network(segment_nodes=[[0, 1, 2], [1, 2, 0]])
    with pytest.raises(ValueError, match=r"Sampled.displacements must have shape \(3, 3\)"):
        jc.Sampled([0.0, 1.0, 2.0], np.zeros((2, 3)))
    with pytest.raises(ValueError, match=r"Harmonic.direction must have shape \(3,\)"):
        jc.Harmonic(1.0, 5.0, direction=(1.0, 0.0))


def test_unknown_options():
    with pytest.raises(ValueError, match=r"mass_matrix must be one of \('consistent', 'lumped'\), got 'diagonal'"):
        network(mass_matrix="diagonal")
    with pytest.raises(ValueError, match=r"drag_points must be a positive integer, got 0"):
        network(drag_points=0)
    with pytest.raises(TypeError, match=r"unexpected keyword argument 'mass_matrx'"):
        network(mass_matrx="lumped")
    with pytest.raises(ValueError, match=r"all branches must share one class of tension law"):
        other = line(tension_law=jc.NonlinearElastic(1e6, 1e5))
        jc.CableNetwork.from_branches(
            [[0.0, 0, 0], [1, 0, 0], [2, 0, 0]],
            [jc.Branch(0, 1, line(), 1.0, 1), jc.Branch(1, 2, other, 1.0, 1)],
            {0: jc.Fixed(), 2: jc.Fixed()},
        )


def test_bad_motions_and_environment():
    with pytest.raises(ValueError, match=r"Harmonic.period must be positive, got 0.0"):
        jc.Harmonic(1.0, 0.0)
    with pytest.raises(ValueError, match=r"Harmonic.direction \(its length\) must be positive, got 0.0"):
        jc.Harmonic(1.0, 5.0, direction=(0.0, 0.0, 0.0))
    with pytest.raises(ValueError, match=r"Sampled.times must be strictly increasing"):
        jc.Sampled([0.0, 2.0, 1.0], np.zeros((3, 3)))
    with pytest.raises(ValueError, match=r"Environment.water_density must be positive, got -1.0"):
        jc.Environment(water_density=-1.0)


@pytest.mark.unchecked  # a string where the hint says a motion, on purpose: the network's own error
def test_a_constraint_that_is_not_a_motion():
    with pytest.raises(ValueError, match=r"CableNetwork.constraints\[0\] must be a motion"):
        network(constraints={0: "fixed", 2: jc.Fixed()})


def test_simulate_arguments():
    model = network()
    env = jc.Environment()
    with pytest.raises(ValueError, match=r"t1 must be greater than t0, got t0=0.0, t1=0.0"):
        jc.simulate(model, env, 0.0)
    with pytest.raises(ValueError, match=r"ts must lie within \[t0, t1\]"):
        jc.simulate(model, env, 1.0, ts=[0.0, 2.0])
    with pytest.raises(ValueError, match=r"initial.positions must have shape \(3, 3\), got \(2, 3\)"):
        jc.simulate(model, env, 1.0, initial=jc.State(np.zeros((2, 3)), np.zeros((2, 3))))
