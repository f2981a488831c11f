"""The Low & Langley (2006) jumper, read from its MoorDyn input file, against the
published statics and the digitised top tension of case 1 (tests/data, see its README).

The jumper's bending stiffness (EI = 120.8 kN·m²) is read from the file and modelled;
benchmarks/lowe_langley.py reports the errors in full, with and without it.
"""

from pathlib import Path

import numpy as np
import pytest

import jaxcable as jc
from jaxcable._cli import main

DATA = Path(__file__).parent / "data" / "lowe_and_langley_2006"
AMPLITUDE, PERIOD, AFTER_RAMP = 10.0, 27.0, 80.0


@pytest.fixture(scope="module")
def statics():
    scene = jc.read_moordyn(DATA / "line.txt")
    # Bending is read (EI), not left out. WaveKin = 1 (kinematics from a coupled
    # program) leaves a standalone run in still water, MoorDyn's too: a note. The
    # seabed is kept.
    assert scene.line_types[0].bending_stiffness == 120.8e3
    assert not scene.dropped
    assert any("WaveKin = 1: wave kinematics come from a coupled program" in note for note in scene.notes)
    return jc.run_scene(scene, duration=0)


def test_static_support_forces_match_the_reference(statics):
    # The force of each support on the line: (11.40, 0, 45.71) kN at the top (point 2,
    # node 1) and (−11.40, 0, 24.04) kN at the bottom, within ±0.2 kN.
    order = np.asarray(statics.built.model.constrained_nodes).tolist()
    reactions = statics.reactions[0] / 1e3
    np.testing.assert_allclose(reactions[order.index(1)], [11.40, 0.0, 45.71], atol=0.2)
    np.testing.assert_allclose(reactions[order.index(0)], [-11.40, 0.0, 24.04], atol=0.2)


def test_static_support_forces_with_bending_match_the_reference_closely(statics):
    # With EI the top force is the reference's to 0.02 kN in each component, and its
    # magnitude OrcaFlex's 47.11 kN (with bending); without it jaxcable's is the analytic
    # (inextensible, bending-free) catenary's 47.14 kN (benchmarks/README.md).
    order = np.asarray(statics.built.model.constrained_nodes).tolist()
    top = statics.reactions[0, order.index(1)] / 1e3
    np.testing.assert_allclose(top, [11.40, 0.0, 45.71], atol=0.02)
    assert abs(np.linalg.norm(top) - 47.11) < 0.01


@pytest.mark.slow
def test_case_1_through_the_command_line(tmp_path, capsys):
    # The top moves along x by f(t) A sin(2πt/T), f the smoothstep ramp over one period;
    # the reference starts at the end of the ramp. MoorDyn's own regression test allows
    # 1 kN at every reference point.
    t = np.arange(0.0, PERIOD + AFTER_RAMP + 0.005, 0.01)
    f = np.clip(t / PERIOD, 0, 1)
    f = f**3 * (6 * f**2 - 15 * f + 10)
    x = f * AMPLITUDE * np.sin(2 * np.pi * t / PERIOD)
    table = tmp_path / "case1.txt"
    np.savetxt(table, np.column_stack([t, x, 0 * t, -5.0 + 0 * t]))
    out = tmp_path / "case1.csv"
    argv = ["run", str(DATA / "line.txt"), "--motion", str(table), "--out", str(out), "--dt-out", "0.05"]
    assert main([*argv, "--no-progress"]) == 0  # with bending: nothing left out
    printed = capsys.readouterr().out
    assert "peak tension" in printed and "left out" not in printed
    columns = np.genfromtxt(out, delimiter=",", names=True)
    reference = np.loadtxt(DATA / "case1.csv", delimiter=",")
    simulated = np.interp(reference[:, 0], columns["Time"] - PERIOD, columns["FairTen1"] / 1e3)
    error = simulated - reference[:, 1]
    assert np.abs(error).max() < 1.0
    assert np.sqrt(np.mean(error**2)) < 0.6
