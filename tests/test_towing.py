"""The towing rigs against closed forms: a neutrally buoyant cable towed along the flow
(tangential drag alone), and Zhukov's leader and element rising at the speed where
lift balances drag."""

import math

import jax
import numpy as np
import pytest

import jaxcable as jc
from jaxcable.calibration import HorizontalTow, VerticalTow, rig_from_conditions

RHO, G = 1025.0, 9.81


def test_cable_towed_along_the_flow_carries_its_tangential_drag():
    # A neutrally buoyant cable with nothing at its end streams straight aft at the tow
    # depth, and its tow-point tension is the tangential drag C_τ u² on everything aft
    # of the first segment's middle: the segment's tension is what holds the nodes
    # behind it, and the drag of each segment goes half to each end node.
    diameter, n = 0.0173, 5
    area = math.pi * diameter**2 / 4
    rig = HorizontalTow(
        cable_length=100.0,
        cable_diameter=diameter,
        cable_mass_per_length=RHO * area,
        cable_axial_stiffness=2e6,
        cable_axial_damping=5e3,
        normal_drag=1.2,
        tangential_drag=0.01,
        end_mass=0.0,
        end_volume=0.0,
        end_drag_area=0.0,
        end_added_mass=0.0,
        tow_depth=5.0,
        segments=n,
        water_density=RHO,
        gravity=G,
    )
    times = np.linspace(0.0, 30.0, 61)
    speed = np.interp(times, [0.0, 10.0, 12.0, 30.0], [1.0, 1.0, 2.0, 2.0])
    towed = rig.simulate(times, {"speed": speed}, jc.calibration.rig_solver(rtol=1e-9, atol=1e-9))
    observables, result = towed.observables, towed.simulation
    assert bool(towed.success)
    c_tau = 0.5 * RHO * 0.01 * math.pi * diameter
    stretched = np.linalg.norm(np.diff(np.asarray(result.positions), axis=1), axis=-1)  # (times, segments)
    aft_of_middle = stretched[:, 1:].sum(axis=1) + 0.5 * stretched[:, 0]
    for k in (0, 19, 60):  # steady at 1 m/s from the start, and 18 s after the step to 2 m/s
        expected = c_tau * speed[k] ** 2 * aft_of_middle[k]
        np.testing.assert_allclose(float(observables["tension"][k]), expected, rtol=1e-6)
    np.testing.assert_allclose(np.asarray(observables["depth"]), 5.0, atol=1e-9)
    np.testing.assert_allclose(np.asarray(observables["layback"]), stretched.sum(axis=1), rtol=1e-12)


def test_steady_tow_starts_in_equilibrium():
    # The start is statics in a current against the tow; simulated as motion through
    # still water at that speed, nothing should change (Galilean invariance of the
    # drag, through two different code paths).
    rig = HorizontalTow(
        cable_length=100.0,
        segments=4,
        cable_axial_stiffness=2e6,
        cable_axial_damping=5e3,
        end_mass=100.0,
        end_volume=0.015,
        end_drag_area=0.1,
    )
    times = np.linspace(0.0, 10.0, 11)
    observables = rig.predict(times, {"speed": np.full(11, 1.5)}, jc.calibration.rig_solver(rtol=1e-9, atol=1e-9))
    for name in rig.observables:
        values = np.asarray(observables[name])
        np.testing.assert_allclose(values, values[0], rtol=1e-7, err_msg=name)
    assert 30.0 < float(observables["depth"][0]) < 100.0  # streamed aft, not hanging straight down


def test_tow_load_is_the_support_reaction_and_exceeds_the_first_segment_tension():
    # In steady tow the tow node is in equilibrium: the support holds the first
    # segment's pull T t̂ plus the tow node's half segment, its wet weight and its drag.
    # So the load cell reads more than T by about that half segment's load along the
    # cable.
    diameter, mass, n, length, speed = 0.0173, 1.21, 4, 100.0, 1.5
    rig = HorizontalTow(
        cable_length=length,
        cable_diameter=diameter,
        cable_mass_per_length=mass,
        cable_axial_stiffness=2e6,
        cable_axial_damping=5e3,
        normal_drag=1.2,
        tangential_drag=0.01,
        end_mass=100.0,
        end_volume=0.015,
        end_drag_area=0.1,
        segments=n,
        water_density=RHO,
        gravity=G,
    )
    times = np.linspace(0.0, 4.0, 5)
    speeds = np.full(5, speed)
    solver = jc.calibration.rig_solver(rtol=1e-9, atol=1e-9)
    towed = rig.simulate(times, {"speed": speeds}, solver)
    observables, run = towed.observables, towed.simulation
    assert bool(towed.success)
    # The same rig simulated plainly, from the rig's own starting state.
    initial = jc.State(run.positions[0], run.velocities[0])
    plain = jc.simulate(
        rig.network(times, speeds), jc.Environment(RHO, G), times[-1], ts=times, initial=initial, solver=solver
    )
    reaction = np.asarray(plain.reactions[:, 0, :])
    np.testing.assert_allclose(np.asarray(observables["tow_load"]), np.linalg.norm(reaction, axis=1), rtol=1e-9)

    positions = np.asarray(run.positions[-1])
    chord = positions[1] - positions[0]
    stretched = float(np.linalg.norm(chord))
    along = chord / stretched
    tension = float(observables["tension"][-1])
    area = math.pi * diameter**2 / 4
    weight = np.array([0.0, 0.0, -(mass - RHO * area) * G * length / n / 2])
    flow = np.array([-speed, 0.0, 0.0])  # the water past the cable
    flow_along = (flow @ along) * along
    flow_across = flow - flow_along
    drag_per_length = 0.5 * RHO * 1.2 * diameter * np.linalg.norm(flow_across) * flow_across + (
        0.5 * RHO * 0.01 * math.pi * diameter * np.linalg.norm(flow_along) * flow_along
    )
    half_segment = weight + drag_per_length * stretched / 2
    np.testing.assert_allclose(
        reaction[-1] + tension * along, -half_segment, atol=0.01 * float(np.linalg.norm(half_segment))
    )
    gap = float(observables["tow_load"][-1]) - tension
    expected_gap = float(half_segment @ along)  # |T t̂ + H| ≈ T + H·t̂, to first order in |H| / T
    assert 0.005 * tension < gap, "the load cell must read visibly more than the segment tension"
    np.testing.assert_allclose(gap, expected_gap, rtol=0.03)


@pytest.mark.parametrize("lift", [150.0, 300.0])
def test_vertical_tow_rises_at_the_speed_where_lift_balances_drag(lift):
    rig = VerticalTow(leader_lift=lift, element_drag_area=0.01)
    times = np.linspace(0.0, 20.0, 41)
    observables = rig.predict(times, solver=jc.calibration.rig_solver(rtol=1e-9, atol=1e-9))
    # Closed form, written out here from the rig's defaults (scallop cage, 8 mm rope):
    element_wet = (25.0 - RHO * 0.012) * G
    tether_area = math.pi * 0.008**2 / 4
    tether_wet = (0.05 - RHO * tether_area) * G * 3.0
    tether_drag = 0.5 * RHO * 0.01 * math.pi * 0.008 * 3.0
    quadratic = 0.5 * RHO * (0.02 + 0.01) + 0.5 * 20.0 * G + tether_drag
    speed = math.sqrt((lift - element_wet - tether_wet) / quadratic)
    np.testing.assert_allclose(float(rig.steady_speed()), speed, rtol=1e-12)
    np.testing.assert_allclose(np.asarray(observables["speed"][-5:]), speed, rtol=1e-5)
    # The tether at the element holds the element's weight and drag, and half of the
    # tether's own (one segment, lumped).
    tension = element_wet + (0.5 * 20.0 * G + 0.5 * RHO * 0.01) * speed**2 + 0.5 * (tether_wet + tether_drag * speed**2)
    np.testing.assert_allclose(np.asarray(observables["tension"][-5:]), tension, rtol=1e-5)
    assert float(observables["speed"][0]) == 0.0  # released from rest


def test_rig_conditions_round_trip_through_a_record_file(tmp_path):
    for rig in (HorizontalTow(cable_length=150.0, end_mass=250.0, segments=6), VerticalTow(leader_lift=180.0)):
        record = jc.io.TowingRecord(times=[0.0, 1.0], columns={"tension": [1.0, 2.0]}, conditions=rig.conditions())
        jc.io.write_record(tmp_path / "r.csv", record)
        rebuilt = rig_from_conditions(jc.io.read_record(tmp_path / "r.csv").conditions)
        assert type(rebuilt) is type(rig) and rebuilt.segments == rig.segments
        for a, b in zip(jax.tree.leaves(rig), jax.tree.leaves(rebuilt)):
            np.testing.assert_allclose(np.asarray(a), np.asarray(b), rtol=1e-15)


def test_bad_rigs_fail_at_construction():
    with pytest.raises(ValueError, match=r"VerticalTow.leader_lift = 100.0 N must exceed the weight in water"):
        VerticalTow(leader_lift=100.0)
    with pytest.raises(ValueError, match=r"HorizontalTow.cable_length must be positive, got -1.0"):
        HorizontalTow(cable_length=-1.0)
    with pytest.raises(ValueError, match=r"HorizontalTow.segments must be a positive integer, got 0"):
        HorizontalTow(segments=0)
    with pytest.raises(ValueError, match=r"Body.mass must be non-negative, got -5.0"):
        HorizontalTow(end_mass=-5.0)
    with pytest.raises(ValueError, match=r"LineType.normal_drag must be finite, got nan"):
        HorizontalTow(normal_drag=float("nan"))


@pytest.mark.parametrize(
    "conditions, message",
    [
        ({"end_mass": 1.0}, r"tow.csv: no 'rig' in the header"),
        ({"rig": "sideways_tow"}, r"tow.csv: unknown rig 'sideways_tow'; known rigs: horizontal_tow, vertical_tow"),
        ({"rig": "horizontal_tow", "end_mas": 1.0}, r"tow.csv: unknown condition 'end_mas' for rig horizontal_tow"),
        ({"rig": "vertical_tow", "leader_lift": "high"}, r"tow.csv: condition 'leader_lift' must be a number"),
        ({"rig": "vertical_tow", "leader_lift": 50.0}, r"tow.csv: VerticalTow.leader_lift = 50.0 N must exceed"),
    ],
)
def test_rig_from_conditions_errors(conditions, message):
    with pytest.raises(ValueError, match=message):
        rig_from_conditions(conditions, "tow.csv")
