"""The input readers: MoorDyn v2 files, jaxcable's TOML scenes, motion tables and the
command line's handling of bad input.

Everything here reads and builds models; nothing integrates, so the file runs in
seconds. Inputs are written into `tmp_path` by the tests, and the line numbers that
errors must report are counted from that text, not from the reader. The MoorDyn reader
warns of physics it leaves out (bending, bathymetry, waves); the tests that cause such
notes check the warning too.
"""

import dataclasses
import re
import warnings
from pathlib import Path

import diffrax
import jax.numpy as jnp
import numpy as np
import pytest
from helpers import SCENE

import jaxcable as jc
from jaxcable._cli import main as cli_main
from jaxcable.io import SeabedSpec, WaveSpec

LOWE_AND_LANGLEY = Path(__file__).parent / "data" / "lowe_and_langley_2006" / "line.txt"


# --------------------------------------------------------------------------------------
# Helpers


def line_of(path: Path, fragment: str) -> int:
    """The 1-based number of the one line of `path` that contains `fragment`."""
    hits = [n for n, line in enumerate(path.read_text().splitlines(), start=1) if fragment in line]
    assert len(hits) == 1, f"{fragment!r} is on lines {hits} of {path}"
    return hits[0]


def assert_located(error: pytest.ExceptionInfo, path: Path, fragment: str, *words: str) -> str:
    """The error names `path`, the line holding `fragment` and each of `words`."""
    message = str(error.value)
    assert str(path) in message, message
    number = line_of(path, fragment)
    assert re.search(rf"\bline {number}\b", message), f"expected line {number}: {message}"
    for word in words:
        assert word in message, f"expected {word!r}: {message}"
    return message


_TYPE_COLUMNS = (
    "TypeName   Diam    Mass/m   EA       BA/-zeta  EI       Cd     Ca     CdAx   CaAx",
    "(name)     (m)     (kg/m)   (N)      (N-s/-)   (N-m^2)  (-)    (-)    (-)    (-)",
)
_POINT_COLUMNS = (
    "ID   Type      X       Y      Z       Mass    Volume   CdA    Ca",
    "(#)  (-)       (m)     (m)    (m)     (kg)    (m^3)    (m^2)  (-)",
)
_LINE_COLUMNS = (
    "ID   LineType  AttachA  AttachB  UnstrLen  NumSegs  LineOutputs",
    "(#)  (name)    (#)      (#)      (m)       (-)      (-)",
)
_ROD_COLUMNS = (
    "ID   RodType   Attachment  Xa   Ya   Za   Xb   Yb   Zb   NumSegs  RodOutputs",
    "(#)  (name)    (#/key)     (m)  (m)  (m)  (m)  (m)  (m)  (-)      (-)",
)
_BODY_COLUMNS = (
    "ID   Attachment  X0   Y0   Z0   r0   p0   y0   Mass  CG*  I*  Volume  CdA*  Ca*",
    "(#)  (word)      (m)  (m)  (m)  (deg) (deg) (deg) (kg) (m) (kg-m^2) (m^3) (m^2) (-)",
)

TYPES = ("chain   0.1     20.0     1.0e9    -0.5      0        1.2    1.0    0.05   0.0",)
POINTS = (
    "1    Fixed     0.0     0.0    -100.0  0       0        0      0",
    "2    Vessel    200.0   0.0    0.0     0       0        0      0",
)
LINES = ("1    chain     1        2        250.0     10       -",)
OPTIONS = ("1025.0   WtrDnsty   water density", "9.81     g          gravity", "150.0    WtrDpth    depth")


def moordyn_text(
    types=TYPES,
    points=POINTS,
    lines=LINES,
    options=OPTIONS,
    outputs=None,
    before=(),
    omit=(),
) -> str:
    """A MoorDyn v2 input file: a title, the given sections (`before` is a list of
    `(header, column lines, rows)` placed after LINE TYPES), and the closing header."""
    text = ["--------------------- MoorDyn Input File ------------------------", "jaxcable reader test"]
    sections = [
        ("LINE TYPES", _TYPE_COLUMNS, types),
        *before,
        ("POINTS", _POINT_COLUMNS, points),
        ("LINES", _LINE_COLUMNS, lines),
        ("OPTIONS", (), options),
    ]
    if outputs is not None:
        sections.append(("OUTPUTS", (), outputs))
    for name, columns, rows in sections:
        if name in omit:
            continue
        text += [f"---------------------- {name} ----------------------", *columns, *rows]
    text.append("--------------------- need this line ------------------------")
    return "\n".join(text) + "\n"


def write_moordyn(tmp_path: Path, name: str = "system.txt", **sections) -> Path:
    path = tmp_path / name
    path.write_text(moordyn_text(**sections))
    return path


def segment_damping(built: jc.io.BuiltScene, line: int) -> np.ndarray:
    """C_v (N·s) of each segment of line `line` (from 0) in the built model."""
    return np.asarray(built.model.line.tension_law.damping())[built.line_segments[line]]


# --------------------------------------------------------------------------------------
# MoorDyn: what maps where


def test_moordyn_line_type_coefficients_are_copied_one_to_one(tmp_path):
    path = write_moordyn(
        tmp_path,
        types=("rope  0.15  30.5  2.0e8  1500  0  1.3  0.9  0.07  0.2",),
        lines=("1    rope      1        2        250.0     10       -",),
    )
    scene = jc.read_moordyn(path)
    (spec,) = scene.line_types
    assert spec.name == "rope"
    assert spec.diameter == 0.15  # Diam
    assert spec.mass_per_length == 30.5  # Mass/m
    assert spec.axial_stiffness == 2.0e8  # EA
    assert spec.normal_drag == 1.3  # Cd
    assert spec.normal_added_mass == 0.9  # Ca
    assert spec.tangential_drag == 0.07  # CdAx
    assert spec.tangential_added_mass == 0.2  # CaAx
    assert spec.quadratic_stiffness == 0.0
    assert re.search(rf"\bline {line_of(path, 'rope  0.15')}\b", spec.where)
    # ... and they reach the engine's LineType unchanged.
    line = scene.build().model.line
    for field, value in [
        ("diameter", 0.15),
        ("mass_per_length", 30.5),
        ("normal_drag", 1.3),
        ("normal_added_mass", 0.9),
        ("tangential_drag", 0.07),
        ("tangential_added_mass", 0.2),
    ]:
        np.testing.assert_allclose(np.asarray(getattr(line, field)), value, err_msg=field)
    np.testing.assert_allclose(np.asarray(line.tension_law.axial_stiffness), 2.0e8)


def test_moordyn_points_lines_and_bodies(tmp_path):
    path = write_moordyn(
        tmp_path,
        points=(*POINTS, "3    Free      100.0   5.0    -50.0   500     0.8      1.5    0.7"),
        lines=(LINES[0], "2    chain     P1       C3       120.0     6        -"),
    )
    scene = jc.read_moordyn(path)
    assert [p.name for p in scene.points] == ["1", "2", "3"]
    assert [p.kind for p in scene.points] == ["fixed", "coupled", "free"]
    assert scene.points[2].position == (100.0, 5.0, -50.0)
    assert scene.points[0].body is None and scene.points[1].body is None
    body = scene.points[2].body
    assert (float(body.mass), float(body.volume), float(body.drag_area), float(body.added_mass)) == (500, 0.8, 1.5, 0.7)
    assert float(body.specific_drag) == 0.0
    assert re.search(rf"\bline {line_of(path, '3    Free')}\b", scene.points[2].where)
    first, second = scene.lines
    assert (first.start, first.end, first.length, first.segments, first.line_type) == (0, 1, 250.0, 10, "chain")
    assert (second.name, second.start, second.end, second.length, second.segments) == ("2", 0, 2, 120.0, 6)
    assert scene.coupled_points == (1,)
    built = scene.build()
    assert built.model.mass_matrix == "lumped"
    assert [n.size for n in built.line_nodes] == [11, 7]


@pytest.mark.parametrize(
    "word, kind",
    [
        ("Fixed", "fixed"),
        ("fixed", "fixed"),
        ("ANCHOR", "fixed"),
        ("anchor", "fixed"),
        ("Vessel", "coupled"),
        ("vessel", "coupled"),
        ("Coupled", "coupled"),
        ("FAIRLEAD", "coupled"),
        ("fairlead", "coupled"),
        ("Free", "free"),
        ("FREE", "free"),
        ("Point", "free"),
        ("connect", "free"),
        ("Connect", "free"),
    ],
)
def test_moordyn_point_types(tmp_path, word, kind):
    path = write_moordyn(
        tmp_path,
        points=(*POINTS, f"3    {word:8}  100.0   0.0    -50.0   0       0        0      0"),
        lines=(LINES[0], "2    chain     1        3        120.0     6        -"),
    )
    assert jc.read_moordyn(path).points[2].kind == kind


def test_moordyn_options_and_outputs(tmp_path):
    path = write_moordyn(
        tmp_path,
        options=("1020.0   WtrDnsty", "9.8      g", "150.0    WtrDpth", "0.25     dtOut   output interval"),
        outputs=("FairTen1 AnchTen1", "L1N5PZ", "END", "ignored after END"),
    )
    scene = jc.read_moordyn(path)
    assert scene.water.density == 1020.0
    assert scene.water.gravity == 9.8
    assert scene.water.depth == 150.0
    assert scene.water.current == (0.0, 0.0, 0.0)
    assert scene.run.dt_out == 0.25
    assert scene.run.mass_matrix == "lumped"
    assert scene.channels == ("FairTen1", "AnchTen1", "L1N5PZ")
    assert scene.source == str(path)


def test_moordyn_option_aliases_and_defaults(tmp_path):
    # Without WtrDpth, MoorDyn's depth (0) is lowered to the deepest point, the anchor
    # at z = −100 m, and its seabed is there.
    scene = jc.read_moordyn(write_moordyn(tmp_path, options=("1000  rho", "9.7  gravity")))
    assert (scene.water.density, scene.water.gravity, scene.water.depth) == (1000.0, 9.7, 100.0)
    assert scene.run.dt_out is None and scene.channels == ()
    path = write_moordyn(tmp_path, "bare.txt", options=())
    scene = jc.read_moordyn(path)
    assert (scene.water.density, scene.water.gravity, scene.water.depth) == (1025.0, 9.80665, 100.0)
    (note,) = [n for n in scene.notes if "water depth" in n]
    assert "no WtrDpth" in note and "point 1" in note and re.search(rf"\bline {line_of(path, 'Fixed')}\b", note)


def test_moordyn_bad_option_value_is_located(tmp_path):
    path = write_moordyn(tmp_path, options=("deep  WtrDpth",))
    with pytest.raises(jc.io.SceneError) as error:
        jc.read_moordyn(path)
    assert_located(error, path, "deep  WtrDpth", "WtrDpth", "'deep'")
    path = write_moordyn(tmp_path, "negative.txt", options=("-9.81  g",))
    with pytest.raises(jc.io.SceneError) as error:
        jc.read_moordyn(path)
    assert_located(error, path, "-9.81  g", "g must be positive")


# --------------------------------------------------------------------------------------
# MoorDyn: axial damping BA / -zeta


def test_moordyn_positive_ba_is_a_damping_coefficient(tmp_path):
    path = write_moordyn(tmp_path, types=("chain  0.1  20.0  1.0e9  1500  0  1.2  1.0  0.05  0.0",))
    scene = jc.read_moordyn(path)
    (spec,) = scene.line_types
    assert (spec.axial_damping, spec.axial_damping_ratio) == (1500.0, 0.0)
    np.testing.assert_allclose(segment_damping(scene.build(), 0), 1500.0)
    np.testing.assert_allclose(segment_damping(scene.with_segments(40).build(), 0), 1500.0)


def test_moordyn_negative_ba_is_a_fraction_of_critical_damping(tmp_path):
    # MoorDyn (Line.cpp): BA = -BAin * UnstrLen / N * sqrt(EA * w), per line.
    zeta, ea, mass = 0.5, 1.0e9, 20.0
    lengths, segments = (250.0, 120.0), (10, 8)
    path = write_moordyn(
        tmp_path,
        points=(*POINTS, "3    Fixed     100.0   0.0    -100.0  0       0        0      0"),
        lines=(LINES[0], "2    chain     3        2        120.0     8        -"),
    )
    scene = jc.read_moordyn(path)
    (spec,) = scene.line_types
    assert (spec.axial_damping, spec.axial_damping_ratio) == (0.0, zeta)
    built = scene.build()
    for k, (length, n) in enumerate(zip(lengths, segments)):
        expected = zeta * length / n * np.sqrt(ea * mass)
        assert expected > 1e5  # far from zero, so a wrong formula cannot pass by accident
        np.testing.assert_allclose(segment_damping(built, k), expected, rtol=1e-12)
        assert spec.damping_coefficient(length / n) == pytest.approx(expected, rel=1e-12)
    finer = scene.with_segments(25).build()
    for k, length in enumerate(lengths):
        np.testing.assert_allclose(segment_damping(finer, k), zeta * length / 25 * np.sqrt(ea * mass), rtol=1e-12)


def test_moordyn_zero_ba_is_undamped(tmp_path):
    scene = jc.read_moordyn(write_moordyn(tmp_path, types=("chain  0.1  20.0  1.0e9  0  0  1.2  1.0  0.05  0.0",)))
    assert (scene.line_types[0].axial_damping, scene.line_types[0].axial_damping_ratio) == (0.0, 0.0)
    np.testing.assert_allclose(segment_damping(scene.build(), 0), 0.0)


# --------------------------------------------------------------------------------------
# MoorDyn: notes and unsupported features


def test_moordyn_bending_stiffness_is_read(tmp_path):
    # A constant EI is the line type's bending stiffness, and nothing is left out.
    path = write_moordyn(tmp_path, types=("chain  0.1  20.0  1.0e9  -0.5  3.5e4  1.2  1.0  0.05  0.0",))
    scene = jc.read_moordyn(path)
    assert scene.line_types[0].bending_stiffness == 3.5e4 and not scene.dropped
    np.testing.assert_array_equal(scene.build().model.line.bending_stiffness, 3.5e4)
    # EI = 0 is no bending: none of its code.
    scene = jc.read_moordyn(write_moordyn(tmp_path, "no_bending.txt"))
    assert scene.build().model.line.bending_stiffness is None
    # A table of EI against curvature is not modelled: a note, and a warning.
    path = write_moordyn(tmp_path, "table.txt", types=("chain  0.1  20.0  1.0e9  -0.5  ei.dat  1.2  1.0  0.05  0.0",))
    with pytest.warns(UserWarning, match="bending stiffness table 'ei.dat' ignored"):
        scene = jc.read_moordyn(path)
    (note,) = [n for n in scene.notes if "bending" in n]
    assert re.search(rf"\bline {line_of(path, 'ei.dat')}\b", note) and "chain" in note


def test_moordyn_seabed_is_always_on_with_moordyns_defaults(tmp_path):
    # MoorDyn (MoorDyn2.cpp): kb = 3.0e6 Pa/m, cb = 3.0e5 Pa·s/m, no friction, and the
    # bed at WtrDpth whether or not any seabed option is given.
    with warnings.catch_warnings():
        warnings.simplefilter("error")
        scene = jc.read_moordyn(write_moordyn(tmp_path))
    bed = scene.water.seabed
    assert (bed.stiffness, bed.damping, bed.friction) == (3.0e6, 3.0e5, 0.0)
    assert scene.water.depth == 150.0
    assert not any("seabed" in n or "water depth" in n for n in scene.notes)
    env = scene.build().environment
    assert float(env.depth) == 150.0
    np.testing.assert_array_equal([env.seabed.stiffness, env.seabed.damping, env.seabed.friction], [3.0e6, 3.0e5, 0.0])


@pytest.mark.parametrize("stiffness, damping", [("kBot", "cBot"), ("kb", "cb"), ("KBOT", "CBot")])
def test_moordyn_seabed_options_map_to_the_seabed(tmp_path, stiffness, damping):
    options = (*OPTIONS, f"2.5e6    {stiffness}   bottom stiffness", f"4.0e4    {damping}   bottom damping")
    with warnings.catch_warnings():
        warnings.simplefilter("error")  # mapped, not left out: no warning
        scene = jc.read_moordyn(write_moordyn(tmp_path, options=options))
    bed = scene.water.seabed
    assert (bed.stiffness, bed.damping, bed.friction) == (2.5e6, 4.0e4, 0.0)
    assert not any(stiffness in n or damping in n for n in scene.notes)
    env = scene.build().environment
    assert (float(env.seabed.stiffness), float(env.seabed.damping)) == (2.5e6, 4.0e4)


def test_moordyn_friction_is_moordyns_form(tmp_path):
    """`FrictionCoefficient` and `FricDamp` select MoorDyn's friction (the seabed's
    `friction_damping`), silently; FricDamp is MoorDyn's 200 N·s/m when absent."""
    options = (*OPTIONS, "0.6   FrictionCoefficient", "150   FricDamp")
    with warnings.catch_warnings():
        warnings.simplefilter("error")
        scene = jc.read_moordyn(write_moordyn(tmp_path, options=options))
    bed = scene.water.seabed
    assert (bed.friction, bed.friction_damping) == (0.6, 150.0)
    assert not any("FricDamp" in n for n in scene.notes)
    env = scene.build().environment
    assert (float(env.seabed.friction), float(env.seabed.friction_damping)) == (0.6, 150.0)
    scene = jc.read_moordyn(write_moordyn(tmp_path, "default.txt", options=(*OPTIONS, "0.6   FrictionCoefficient")))
    assert scene.water.seabed.friction_damping == 200.0


def test_moordyn_static_to_dynamic_friction_ratio_and_bathymetry_are_notes(tmp_path):
    options = (*OPTIONS, "0.6   FrictionCoefficient", "1.5   StatDynFricScale", "bathymetry.txt   SeafloorFile")
    path = write_moordyn(tmp_path, options=options)
    with pytest.warns(UserWarning) as caught:
        scene = jc.read_moordyn(path)
    said = " ".join(str(w.message) for w in caught)
    assert "StatDynFricScale" in said and "SeafloorFile" in said
    for option in ("StatDynFricScale", "SeafloorFile"):
        (note,) = [n for n in scene.notes if option in n]
        assert "ignored" in note and re.search(rf"\bline {line_of(path, option)}\b", note)
    assert scene.water.seabed.friction == 0.6 and scene.water.depth == 150.0


def test_moordyn_point_below_wtrdpth_lowers_the_seabed(tmp_path):
    # MoorDyn sets the water depth to a point's depth when the point lies below it.
    path = write_moordyn(tmp_path, options=("1025.0   WtrDnsty", "80.0    WtrDpth    depth"))
    scene = jc.read_moordyn(path)
    assert scene.water.depth == 100.0
    (note,) = [n for n in scene.notes if "water depth" in n]
    assert "WtrDpth = 80 m" in note and "z = -100 m" in note and re.search(rf"\bline {line_of(path, 'Fixed')}\b", note)


@pytest.mark.parametrize(
    "row, expected",
    [
        ("-3.0e6   kBot", "kBot must be positive"),
        ("-1.0   cBot", "cBot must be non-negative"),
        ("-0.5   FrictionCoefficient", "must be non-negative"),
        ("0   FricDamp", "FricDamp must be positive"),
    ],
)
def test_moordyn_bad_seabed_options_are_located(tmp_path, row, expected):
    path = write_moordyn(tmp_path, options=(*OPTIONS, row))
    with pytest.raises(jc.io.SceneError) as error:
        jc.read_moordyn(path)
    assert_located(error, path, row, expected)


def test_moordyn_lying_chain_presses_into_the_bed_as_moordyn_says(tmp_path):
    # A chain much longer than its span lies on the bed at 100 m, where each interior
    # node's weight w l is carried by kBot δ d l (MoorDyn's bottom pressure on d times
    # the node's length): δ = w / (kBot d).
    points = (
        "1    Fixed     0.0     0.0    -100.0  0       0        0      0",
        "2    Fixed     60.0    0.0    -60.0   0       0        0      0",
    )
    lines = ("1    chain     1        2        150.0     10       -",)
    options = ("1025.0   WtrDnsty", "9.81   g", "100.0   WtrDpth", "1.0e6   kBot")
    scene = jc.read_moordyn(write_moordyn(tmp_path, points=points, lines=lines, options=options))
    built = scene.build()
    static = jc.solve_statics(built.model, built.environment)
    z = np.asarray(static.state.positions)[built.line_nodes[0], 2]
    w = (20.0 - 1025.0 * np.pi * 0.1**2 / 4) * 9.81
    lying = z < -100.0
    assert lying.sum() >= 3  # the line does lie on the bed
    # Nodes well inside the lying part carry their own weight only.
    inner = np.flatnonzero(lying)[1:-2]
    np.testing.assert_allclose(-100.0 - z[inner], w / (1.0e6 * 0.1), rtol=1e-3)


def test_moordyn_file_with_nothing_left_out_reads_without_warnings(tmp_path):
    options = (*OPTIONS, "0.001  dtM", "1.0  dtIC", "60  TmaxIC", "0.001  threshIC", "0  WaveKin", "1  disableOutTime")
    with warnings.catch_warnings():
        warnings.simplefilter("error")
        scene = jc.read_moordyn(write_moordyn(tmp_path, options=options))
    # The initial-condition options are noted as not needed, without a warning, in one note.
    (note,) = [n for n in scene.notes if "not needed" in n]
    assert re.search(r"options dtIC = 1.0 \(line \d+\), TmaxIC = 60 \(line \d+\), threshIC = 0.001 \(line", note)
    assert not any("WaveKin" in n or "disableOutTime" in n for n in scene.notes)


@pytest.mark.parametrize(
    "scheme, solver, honoured",
    [
        (None, "midpoint", True),
        ("RK2", "midpoint", True),
        ("heun", "heun", True),
        ("Euler", "euler", True),
        ("midpoint5", "midpoint", False),
        ("RK4", "rk4", True),
        ("RK3", "midpoint", False),
    ],
)
def test_moordyn_dtm_and_tscheme_are_fixed_steps(tmp_path, scheme, solver, honoured):
    options = (*OPTIONS, "0.002  dtM") + (() if scheme is None else (f"{scheme}  tScheme",))
    scene = jc.read_moordyn(write_moordyn(tmp_path, options=options))
    assert (scene.run.dt, scene.run.solver) == (0.002, solver)
    config = scene.run.solver_config()
    assert isinstance(config.stepsize_controller, diffrax.ConstantStepSize)
    assert float(config.dt0) == 0.002
    (note,) = [n for n in scene.notes if "dtM" in n]
    assert "fixed steps of dtM = 0.002 s" in note and "--adaptive" in note
    assert ("does not have" in note) is not honoured


def test_moordyn_without_dtm_takes_the_steps_chosen_for_the_scene(tmp_path):
    scene = jc.read_moordyn(write_moordyn(tmp_path, options=OPTIONS))
    assert scene.run.dt is None and scene.run.solver == "auto"


def test_moordyn_non_positive_dtm_is_located(tmp_path):
    with pytest.raises(jc.io.SceneError, match=r"line \d+: option dtM must be positive, got 0"):
        jc.read_moordyn(write_moordyn(tmp_path, options=(*OPTIONS, "0  dtM")))


def test_moordyn_empty_rod_and_body_sections_are_accepted(tmp_path):
    # Many MoorDyn files carry these sections with no rows.
    rod_types = ("TypeName Diam Mass/m Cd Ca CdEnd CaEnd", "(-) (m) (kg/m) (-) (-) (-) (-)")
    empty = [("ROD TYPES", rod_types, ()), ("BODIES", _BODY_COLUMNS, ()), ("RODS", _ROD_COLUMNS, ())]
    path = write_moordyn(tmp_path, before=empty)
    assert len(jc.read_moordyn(path).lines) == 1


def test_moordyn_rods_are_rejected(tmp_path):
    row = "1    pipe      Free        0    0    -10  0    0    -20  5        -"
    path = write_moordyn(tmp_path, before=[("RODS", _ROD_COLUMNS, (row,))])
    with pytest.raises(jc.io.SceneError) as error:
        jc.read_moordyn(path)
    assert_located(error, path, row, "RODS", "rods", "does not model")


def test_moordyn_bodies_are_rejected(tmp_path):
    row = "1    Free        0    0    -10  0    0    0    1000  0    0   2.0     0     0"
    path = write_moordyn(tmp_path, before=[("BODIES", _BODY_COLUMNS, (row,))])
    with pytest.raises(jc.io.SceneError) as error:
        jc.read_moordyn(path)
    assert_located(error, path, row, "BODIES", "bodies", "does not model")


def test_moordyn_point_on_a_body_is_rejected(tmp_path):
    row = "3    Body1     10.0    0.0    -5.0    0       0        0      0"
    lines = (LINES[0], "2    chain     1        3        120.0     6        -")
    path = write_moordyn(tmp_path, points=(*POINTS, row), lines=lines)
    with pytest.raises(jc.io.SceneError) as error:
        jc.read_moordyn(path)
    assert_located(error, path, row, "column Type", "'Body1'", "body")


def test_moordyn_line_on_a_rod_is_rejected(tmp_path):
    row = "1    chain     1        R1A      250.0     10       -"
    path = write_moordyn(tmp_path, lines=(row,))
    with pytest.raises(jc.io.SceneError) as error:
        jc.read_moordyn(path)
    assert_located(error, path, row, "column AttachB", "rod")


def test_moordyn_stiffness_table_is_rejected(tmp_path):
    row = "chain  0.1  20.0  ea_curve.dat  -0.5  0  1.2  1.0  0.05  0.0"
    path = write_moordyn(tmp_path, types=(row,))
    with pytest.raises(jc.io.SceneError) as error:
        jc.read_moordyn(path)
    assert_located(error, path, row, "column EA", "'ea_curve.dat'", "table")


def test_moordyn_viscoelastic_stiffness_is_rejected(tmp_path):
    row = "chain  0.1  20.0  1.0e9|2.0e9  -0.5  0  1.2  1.0  0.05  0.0"
    path = write_moordyn(tmp_path, types=(row,))
    with pytest.raises(jc.io.SceneError) as error:
        jc.read_moordyn(path)
    assert_located(error, path, row, "EA", "viscoelastic", "1.0e9|2.0e9")


def test_moordyn_viv_column_is_rejected_unless_zero(tmp_path):
    row = "chain  0.1  20.0  1.0e9  -0.5  0  1.2  1.0  0.05  0.0  0.8"
    path = write_moordyn(tmp_path, types=(row,))
    with pytest.raises(jc.io.SceneError) as error:
        jc.read_moordyn(path)
    assert_located(error, path, row, "column 11", "vortex-induced vibration")
    # A zero lift coefficient is MoorDyn's "no VIV" and reads as the plain line type.
    row = "chain  0.1  20.0  1.0e9  -0.5  0  1.2  1.0  0.05  0.0  0"
    scene = jc.read_moordyn(write_moordyn(tmp_path, "no_viv.txt", types=(row,)))
    assert scene.line_types[0].tangential_added_mass == 0.0


def test_moordyn_point_forces_on_free_points_are_body_forces(tmp_path):
    # 12 columns: ID Type X Y Z Mass Volume FX FY FZ CdA Ca; CdA and Ca come from
    # columns 11 and 12.
    row = "3    Free   100.0   0.0   -50.0   10   0.5   0   300   -2000   1.5   0.7"
    lines = (LINES[0], "2    chain     1        3        120.0     6        -")
    scene = jc.read_moordyn(write_moordyn(tmp_path, points=(*POINTS, row), lines=lines))
    body = scene.points[2].body
    assert (float(body.mass), float(body.volume), float(body.drag_area), float(body.added_mass)) == (10, 0.5, 1.5, 0.7)
    np.testing.assert_array_equal(body.force, [0.0, 300.0, -2000.0])
    # On a fixed point a force acts on nothing that moves.
    row = "3    Fixed   100.0   0.0   -50.0   10   0.5   0   0   -2000   1.5   0.7"
    path = write_moordyn(tmp_path, "fixed_force.txt", points=(*POINTS, row), lines=lines)
    with pytest.raises(jc.io.SceneError) as error:
        jc.read_moordyn(path)
    assert_located(error, path, row, "FX FY FZ", "fixed point")


# --------------------------------------------------------------------------------------
# MoorDyn: malformed input


@pytest.mark.parametrize("missing", ["LINE TYPES", "POINTS", "LINES"])
def test_moordyn_missing_section(tmp_path, missing):
    path = write_moordyn(tmp_path, omit=(missing,))
    with pytest.raises(jc.io.SceneError) as error:
        jc.read_moordyn(path)
    message = str(error.value)
    assert str(path) in message and f"missing section {missing}" in message, message


def test_moordyn_empty_sections(tmp_path):
    path = write_moordyn(tmp_path, lines=())
    with pytest.raises(jc.io.SceneError, match="section LINES has no rows"):
        jc.read_moordyn(path)
    path = write_moordyn(tmp_path, "no_points.txt", points=(), lines=())
    with pytest.raises(jc.io.SceneError, match="section POINTS has no rows"):
        jc.read_moordyn(path)


@pytest.mark.parametrize("row, what", [(1, "row of units"), (0, "row of column names")])
def test_moordyn_missing_heading_row_is_named(tmp_path, row, what):
    """A table without its row of units (or of column names) would lose its first row
    of data in MoorDyn, which skips two rows after every header: refused, naming the
    row and the data it would lose."""
    text = moordyn_text().replace(_LINE_COLUMNS[row] + "\n", "")
    path = tmp_path / "system.txt"
    path.write_text(text)
    number = text.splitlines().index(LINES[0]) + 1
    with pytest.raises(jc.io.SceneError) as error:
        jc.read_moordyn(path)
    message = str(error.value)
    assert f"{path}, line {number}: section LINES's {what}" in message, message
    assert "would skip this row of data, '1 chain 1 2 250.0 10 -'" in message, message


@pytest.mark.parametrize("encoding", ["utf-16", "utf-8-sig"])
def test_moordyn_file_with_a_byte_order_mark_is_read(tmp_path, encoding):
    """Windows editors save UTF-16 or UTF-8 with a byte-order mark: read as the plain
    file is."""
    plain_path = write_moordyn(tmp_path, "plain.txt")
    path = tmp_path / "marked.txt"
    path.write_bytes(moordyn_text().encode(encoding))
    plain, marked = jc.read_moordyn(plain_path), jc.read_moordyn(path)
    # The same points, line types and lines, located in their own file.
    for got, expected in [
        (marked.points, plain.points),
        (marked.line_types, plain.line_types),
        (marked.lines, plain.lines),
    ]:
        assert repr(got).replace(str(path), str(plain_path)) == repr(expected)


@pytest.mark.parametrize("end", ["\r\n", "\r"], ids=["windows", "classic mac"])
def test_files_with_other_line_ends_are_read(tmp_path, end):
    """Windows and classic Mac line ends read as Unix ones do: a MoorDyn file, and a
    scene file, whose TOML allows only LF and CR LF (a CR alone stopped `tomllib`)."""
    plain_path = write_moordyn(tmp_path, "plain.txt")
    path = tmp_path / "ends.txt"
    path.write_bytes(moordyn_text().replace("\n", end).encode())
    plain, other = jc.read_moordyn(plain_path), jc.read_moordyn(path)
    assert repr(other.lines).replace(str(path), str(plain_path)) == repr(plain.lines)

    source = jc.examples.scene_path("anchored_line")
    scene_path = tmp_path / "anchored_line.toml"
    scene_path.write_bytes(source.read_text(encoding="utf-8").replace("\n", end).encode())
    expected, got = jc.read_scene(source), jc.read_scene(scene_path)
    assert repr(got.lines).replace(str(scene_path), str(source)) == repr(expected.lines)


def test_moordyn_utf16_without_a_byte_order_mark_is_named(tmp_path):
    path = tmp_path / "system.txt"
    path.write_bytes(moordyn_text().encode("utf-16-le"))
    with pytest.raises(
        jc.io.SceneError, match=r"zero bytes, as UTF-16 text without a byte-order mark does; save it as UTF-8"
    ):
        jc.read_moordyn(path)


def test_moordyn_unknown_point_type(tmp_path):
    row = "2    Buoy      200.0   0.0    0.0     0       0        0      0"
    path = write_moordyn(tmp_path, points=(POINTS[0], row))
    with pytest.raises(jc.io.SceneError) as error:
        jc.read_moordyn(path)
    assert_located(error, path, row, "column Type", "unknown point type 'Buoy'", "Fixed", "Vessel", "Free")


def test_moordyn_line_attached_to_a_missing_point(tmp_path):
    row = "1    chain     1        5        250.0     10       -"
    path = write_moordyn(tmp_path, lines=(row,))
    with pytest.raises(jc.io.SceneError) as error:
        jc.read_moordyn(path)
    assert_located(error, path, row, "column AttachB", "point 5 does not exist", "2 points")


def test_moordyn_attachment_that_is_not_a_point(tmp_path):
    row = "1    chain     anchor   2        250.0     10       -"
    path = write_moordyn(tmp_path, lines=(row,))
    with pytest.raises(jc.io.SceneError) as error:
        jc.read_moordyn(path)
    assert_located(error, path, row, "column AttachA", "'anchor'")


@pytest.mark.parametrize("length", ["-250.0", "0", "0.0"])
def test_moordyn_non_positive_length(tmp_path, length):
    row = f"1    chain     1        2        {length:9} 10       -"
    path = write_moordyn(tmp_path, lines=(row,))
    with pytest.raises(jc.io.SceneError) as error:
        jc.read_moordyn(path)
    assert_located(error, path, row, "column UnstrLen", "positive")


@pytest.mark.parametrize(
    "section, row, column, token",
    [
        ("types", "chain  abc  20.0  1.0e9  -0.5  0  1.2  1.0  0.05  0.0", "column Diam", "'abc'"),
        ("types", "chain  0.1  20.0  1.0e9x  -0.5  0  1.2  1.0  0.05  0.0", "column EA", "'1.0e9x'"),
        ("types", "chain  0.1  heavy  1.0e9  -0.5  0  1.2  1.0  0.05  0.0", "column Mass/m", "'heavy'"),
        ("types", "chain  0.1  20.0  1.0e9  -0.5  0  1.2  1.0  0.05  none", "column CaAx", "'none'"),
        ("types", "chain  0.1  20.0  1.0e9  lots  0  1.2  1.0  0.05  0.0", "column BA/-zeta", "'lots'"),
        ("points", "2    Vessel    north   0.0    0.0     0       0        0      0", "column X", "'north'"),
        ("points", "2    Vessel    200.0   0.0    0.0     0       0        0      0.5x", "column Ca", "'0.5x'"),
        ("lines", "1    chain     1        2        long      10       -", "column UnstrLen", "'long'"),
    ],
)
def test_moordyn_non_numeric_field(tmp_path, section, row, column, token):
    sections = {"types": {"types": (row,)}, "points": {"points": (POINTS[0], row)}, "lines": {"lines": (row,)}}
    path = write_moordyn(tmp_path, **sections[section])
    with pytest.raises(jc.io.SceneError) as error:
        jc.read_moordyn(path)
    assert_located(error, path, row, column, token)


@pytest.mark.parametrize("segments", ["10.5", "ten", "0", "-3"])
def test_moordyn_segments_must_be_a_positive_integer(tmp_path, segments):
    row = f"1    chain     1        2        250.0     {segments:8} -"
    path = write_moordyn(tmp_path, lines=(row,))
    with pytest.raises(jc.io.SceneError) as error:
        jc.read_moordyn(path)
    assert_located(error, path, row, "column NumSegs", repr(segments))


def test_moordyn_unknown_line_type(tmp_path):
    row = "1    wire      1        2        250.0     10       -"
    path = write_moordyn(tmp_path, lines=(row,))
    with pytest.raises(jc.io.SceneError) as error:
        jc.read_moordyn(path)
    assert_located(error, path, row, "column LineType", "'wire'", "chain")


def test_moordyn_duplicate_line_type(tmp_path):
    second = "chain   0.2     40.0     2.0e9    -0.5      0        1.2    1.0    0.05   0.0"
    path = write_moordyn(tmp_path, types=(TYPES[0], second))
    with pytest.raises(jc.io.SceneError) as error:
        jc.read_moordyn(path)
    assert_located(error, path, second, "'chain'", "already defined")


def test_moordyn_point_ids_must_be_sequential(tmp_path):
    row = "3    Vessel    200.0   0.0    0.0     0       0        0      0"
    path = write_moordyn(tmp_path, points=(POINTS[0], row))
    with pytest.raises(jc.io.SceneError) as error:
        jc.read_moordyn(path)
    assert_located(error, path, row, "column ID", "expected 2", "'3'")


def test_moordyn_line_ids_must_be_sequential(tmp_path):
    row = "1    chain     1        2        120.0     6        -"
    path = write_moordyn(tmp_path, lines=(LINES[0], row))
    with pytest.raises(jc.io.SceneError) as error:
        jc.read_moordyn(path)
    assert_located(error, path, row, "column ID", "expected 2", "'1'")


@pytest.mark.parametrize(
    "section, row, needed",
    [
        ("types", "chain  0.1  20.0  1.0e9  -0.5  0  1.2  1.0  0.05", "10 fields"),
        ("points", "2    Vessel    200.0   0.0    0.0     0       0        0", "9 fields"),
        ("lines", "1    chain     1        2        250.0     10", "7 fields"),
    ],
)
def test_moordyn_short_rows(tmp_path, section, row, needed):
    sections = {"types": {"types": (row,)}, "points": {"points": (POINTS[0], row)}, "lines": {"lines": (row,)}}
    path = write_moordyn(tmp_path, **sections[section])
    with pytest.raises(jc.io.SceneError) as error:
        jc.read_moordyn(path)
    assert_located(error, path, row, needed)


def test_moordyn_missing_file(tmp_path):
    with pytest.raises(jc.io.SceneError, match="cannot read"):
        jc.read_moordyn(tmp_path / "nowhere.txt")


# --------------------------------------------------------------------------------------
# MoorDyn: a real input


def test_moordyn_lowe_and_langley_file():
    scene = jc.read_moordyn(LOWE_AND_LANGLEY)
    assert [p.kind for p in scene.points] == ["fixed", "coupled"]
    assert scene.points[0].position == (-100.0, 0.0, -55.0)
    assert scene.points[1].position == (0.0, 0.0, -5.0)
    (line,) = scene.lines
    assert (line.start, line.end, line.length, line.segments) == (0, 1, 170.0, 68)
    (spec,) = scene.line_types
    assert spec.axial_stiffness == 5e8
    assert (spec.axial_damping, spec.axial_damping_ratio) == (0.0, 0.5)
    assert (spec.diameter, spec.mass_per_length, spec.normal_drag, spec.normal_added_mass) == (0.396, 165.0, 1.0, 1.0)
    assert spec.bending_stiffness == 120.8e3 and not scene.dropped
    assert not any("kBot" in n or "cBot" in n for n in scene.notes)
    assert (scene.water.seabed.stiffness, scene.water.seabed.damping) == (3.0e6, 3.0e5)  # the file's kBot, cBot
    assert (scene.water.density, scene.water.gravity, scene.water.depth) == (1000.0, 9.807, 100.0)
    damping = segment_damping(scene.build(), 0)
    np.testing.assert_allclose(damping, 0.5 * 170.0 / 68 * np.sqrt(5e8 * 165.0), rtol=1e-12)


# --------------------------------------------------------------------------------------
# TOML scenes


def write_scene(tmp_path: Path, text: str, name: str = "scene.toml") -> Path:
    path = tmp_path / name
    path.write_text(text)
    return path


def edited(old: str, new: str, text: str = SCENE) -> str:
    assert text.count(old) == 1, old
    return text.replace(old, new)


def read_scene_error(tmp_path: Path, text: str) -> tuple[pytest.ExceptionInfo, Path]:
    path = write_scene(tmp_path, text)
    with pytest.raises(jc.io.SceneError) as error:
        jc.read_scene(path)
    return error, path


def test_toml_minimal_scene(tmp_path):
    scene = jc.read_scene(write_scene(tmp_path, SCENE))
    assert [(p.name, p.kind, p.position) for p in scene.points] == [
        ("anchor", "fixed", (0.0, 0.0, -100.0)),
        ("float", "coupled", (150.0, 0.0, 0.0)),
    ]
    (spec,) = scene.line_types
    assert (spec.name, spec.mass_per_length, spec.diameter, spec.axial_stiffness) == ("rope", 3.0, 0.02, 3.0e7)
    assert (spec.axial_damping, spec.axial_damping_ratio) == (0.0, 0.2)
    (line,) = scene.lines
    assert (line.name, line.start, line.end, line.length, line.segments) == ("1", 0, 1, 190.0, 10)
    assert (scene.water.density, scene.water.gravity, scene.water.depth) == (1025.0, 9.81, 150.0)
    assert (scene.run.duration, scene.run.dt_out, scene.run.mass_matrix) == (10.0, 0.5, "consistent")
    built = scene.build()
    np.testing.assert_allclose(segment_damping(built, 0), 0.2 * 19.0 * np.sqrt(3.0e7 * 3.0), rtol=1e-12)


def test_toml_body_height_and_force(tmp_path):
    text = edited(
        '[points.float]\ntype = "coupled"\nposition = [150.0, 0.0, 0.0]\n',
        '[points.float]\ntype = "coupled"\nposition = [150.0, 0.0, 0.0]\n\n'
        '[points.buoy]\ntype = "free"\nposition = [100.0, 0.0, -1.0]\nmass = 100.0\nvolume = 1.0\n'
        "height = 2.0\nforce = [0.0, 500.0, 0.0]\n",
    )
    scene = jc.read_scene(write_scene(tmp_path, text))
    body = scene.points[2].body
    assert (float(body.mass), float(body.volume), float(body.height)) == (100.0, 1.0, 2.0)
    np.testing.assert_array_equal(body.force, [0.0, 500.0, 0.0])
    error, path = read_scene_error(tmp_path, edited("force = [0.0, 500.0, 0.0]", "force = [0.0, 500.0]", text))
    assert "force" in str(error.value)


def test_toml_line_numbers_are_counted_from_the_text(tmp_path):
    # The first [[lines]] table is on line 25 and its `length` on line 29 of SCENE.
    error, path = read_scene_error(tmp_path, edited("length = 190.0", "length = -190.0"))
    assert f"{path}, line 29, key lines[0].length" in str(error.value)
    typo = edited("axial_stiffness = 3.0e7\n", "axial_stiffness = 3.0e7\nmass_per_lenght = 3.0\n")
    error, path = read_scene_error(tmp_path, typo)
    assert f"{path}, line 15, key line_types.rope.mass_per_lenght" in str(error.value)


def test_toml_unknown_key(tmp_path):
    error, path = read_scene_error(tmp_path, edited("mass_per_length = 3.0", "mass_per_lenght = 3.0"))
    assert_located(error, path, "mass_per_lenght", "line_types.rope.mass_per_lenght", "unknown key", "mass_per_length")


def test_toml_unknown_table(tmp_path):
    error, path = read_scene_error(tmp_path, edited("[simulation]", "[simulaton]"))
    assert_located(error, path, "[simulaton]", "key simulaton", "unknown key")


def test_toml_missing_required_key(tmp_path):
    error, path = read_scene_error(tmp_path, edited("diameter = 0.02\n", ""))
    # The key is not in the text, so the line is that of its table.
    assert_located(error, path, "[line_types.rope]", "line_types.rope.diameter", "missing required key")


def test_toml_missing_line_key(tmp_path):
    error, path = read_scene_error(tmp_path, edited('to = "float"\n', ""))
    assert_located(error, path, "[[lines]]", "lines[0].to", "missing required key")


@pytest.mark.parametrize(
    "old, new, key, expected",
    [
        ("diameter = 0.02", 'diameter = "0.02"', "line_types.rope.diameter", "expected a finite number"),
        ("length = 190.0", "length = true", "lines[0].length", "expected a finite number"),
        ("density = 1025.0", 'density = "salty"', "water.density", "expected a finite number"),
        ("position = [0.0, 0.0, -100.0]", "position = [0.0, -100.0]", "points.anchor.position", "three numbers"),
        ("position = [150.0, 0.0, 0.0]", 'position = [150.0, "0", 0.0]', "points.float.position", "three numbers"),
        ('type = "fixed"', "type = 1", "points.anchor.type", "expected a string"),
    ],
)
def test_toml_wrong_type(tmp_path, old, new, key, expected):
    error, path = read_scene_error(tmp_path, edited(old, new))
    assert_located(error, path, new, f"key {key}", expected)


def test_toml_unknown_point_type(tmp_path):
    error, path = read_scene_error(tmp_path, edited('type = "fixed"', 'type = "anchor"'))
    assert_located(error, path, 'type = "anchor"', "points.anchor.type", "unknown point type 'anchor'")


def test_toml_line_from_a_missing_point(tmp_path):
    error, path = read_scene_error(tmp_path, edited('from = "anchor"', 'from = "ancor"'))
    assert_located(error, path, 'from = "ancor"', "lines[0].from", "'ancor' does not exist", "anchor")


def test_toml_error_in_the_second_line_table(tmp_path):
    second = '\n[[lines]]\ntype = "rope"\nfrom = "anchor"\nto = "buoy"\nlength = 100.0\nsegments = 5\n'
    error, path = read_scene_error(tmp_path, SCENE + second)
    assert_located(error, path, 'to = "buoy"', "lines[1].to", "'buoy' does not exist")


def test_toml_missing_line_type(tmp_path):
    error, path = read_scene_error(tmp_path, edited('type = "rope"', 'type = "wire"'))
    assert_located(error, path, 'type = "wire"', "lines[0].type", "'wire' does not exist", "rope")


@pytest.mark.parametrize("length", ["-190.0", "0.0"])
def test_toml_non_positive_length(tmp_path, length):
    error, path = read_scene_error(tmp_path, edited("length = 190.0", f"length = {length}"))
    assert_located(error, path, f"length = {length}", "lines[0].length", "positive")


@pytest.mark.parametrize("segments", ["10.5", '"10"', "0", "-2", "true"])
def test_toml_segments_must_be_a_positive_integer(tmp_path, segments):
    error, path = read_scene_error(tmp_path, edited("segments = 10", f"segments = {segments}"))
    assert_located(error, path, f"segments = {segments}", "lines[0].segments", "positive integer")


def test_toml_both_damping_keys_fail_at_build(tmp_path):
    path = write_scene(tmp_path, edited("axial_damping_ratio = 0.2", "axial_damping_ratio = 0.2\naxial_damping = 50.0"))
    scene = jc.read_scene(path)
    with pytest.raises(jc.io.SceneError) as error:
        scene.build()
    # Located at the line type's table: the conflict is between two of its keys.
    assert_located(
        error, path, "[line_types.rope]", "line_types.rope", "axial_damping (50", "axial_damping_ratio (0.2", "not both"
    )


def test_toml_syntax_error(tmp_path):
    error, path = read_scene_error(tmp_path, edited("segments = 10", "segments = = 10"))
    assert_located(error, path, "segments = = 10")


def test_toml_only_coupled_points_move(tmp_path):
    text = edited('type = "fixed"\n', 'type = "fixed"\nmotion = { type = "harmonic", amplitude = 1.0, period = 5.0 }\n')
    error, path = read_scene_error(tmp_path, text)
    assert_located(error, path, "motion = {", "points.anchor.motion", "coupled")


def test_toml_motion_table_file(tmp_path):
    (tmp_path / "float.csv").write_text("time,x,y,z\n0,150,0,0\n1,151,0,0.5\n2,150,0,0\n")
    motion = 'motion = { type = "table", file = "float.csv" }\n'
    text = edited("position = [150.0, 0.0, 0.0]\n", "position = [150.0, 0.0, 0.0]\n" + motion)
    scene = jc.read_scene(write_scene(tmp_path, text))
    motion = scene.points[1].motion
    assert isinstance(motion, jc.Sampled)
    np.testing.assert_allclose(np.asarray(motion.displacement(1.0)), [1.0, 0.0, 0.5], atol=1e-12)


# --------------------------------------------------------------------------------------
# TOML scenes: the sea


SEA = """
[water.current_profile]
heights = [-150.0, -50.0, 0.0]
speeds = [0.1, 0.3, 0.6]
heading = 30.0

[[waves]]
theory = "airy"
height = 4.0
period = 10.0
heading = 45.0
phase = 1.5
wheeler = true

[[waves]]
theory = "cnoidal"
steepness = 0.005
period = 40.0

[seabed]
stiffness = 2.0e6
friction = 0.4
friction_speed = 0.05
"""


def test_toml_sea_is_read_and_built(tmp_path):
    text = edited("depth = 150.0\n", "depth = 150.0\nfluid_inertia = false\n") + SEA
    scene = jc.read_scene(write_scene(tmp_path, text))
    water = scene.water
    assert water.fluid_inertia is False and water.depth == 150.0
    assert (water.current_profile.heights, water.current_profile.speeds) == ((-150.0, -50.0, 0.0), (0.1, 0.3, 0.6))
    airy, cnoidal = water.waves
    assert (airy.theory, airy.height, airy.steepness, airy.period, airy.heading, airy.phase, airy.wheeler) == (
        "airy",
        4.0,
        None,
        10.0,
        45.0,
        1.5,
        True,
    )
    assert (cnoidal.theory, cnoidal.height, cnoidal.steepness, cnoidal.heading, cnoidal.wheeler) == (
        "cnoidal",
        None,
        0.005,
        0.0,
        False,
    )
    bed = water.seabed
    assert (bed.stiffness, bed.damping, bed.friction, bed.friction_speed) == (2.0e6, 3.0e5, 0.4, 0.05)

    env = scene.build().environment
    assert env.fluid_inertia is False and float(env.depth) == 150.0
    first, second = env.waves
    assert isinstance(first, jc.Airy) and first.wheeler
    np.testing.assert_allclose(
        [first.height, first.period, first.heading, first.phase, first.depth, first.gravity],
        [4.0, 10.0, 45.0, 1.5, 150.0, 9.81],
    )
    # From the steepness: H/λ as given, in the water's depth.
    assert isinstance(second, jc.Cnoidal)
    np.testing.assert_allclose(float(second.steepness), 0.005, rtol=1e-9)
    assert float(second.depth) == 150.0
    assert isinstance(env.current, jc.CurrentProfile)
    # 0.3 m/s at z = −50 m, towards 30°.
    np.testing.assert_allclose(
        np.asarray(env.current.velocity(jnp.array([0.0, 0.0, -50.0]))),
        0.3 * np.array([np.cos(np.pi / 6), np.sin(np.pi / 6), 0.0]),
        atol=1e-12,
    )
    np.testing.assert_allclose(
        [env.seabed.stiffness, env.seabed.damping, env.seabed.friction, env.seabed.friction_speed],
        [2.0e6, 3.0e5, 0.4, 0.05],
    )


def test_toml_sea_defaults(tmp_path):
    text = SCENE + '\n[[waves]]\ntheory = "airy"\nsteepness = 0.02\nperiod = 8.0\n\n[seabed]\n'
    scene = jc.read_scene(write_scene(tmp_path, text))
    (wave,) = scene.water.waves
    assert (wave.heading, wave.phase, wave.wheeler) == (0.0, 0.0, False)
    bed = scene.water.seabed
    assert (bed.stiffness, bed.damping, bed.friction, bed.friction_speed) == (3.0e6, 3.0e5, 0.0, 0.01)
    assert scene.water.fluid_inertia is True and scene.water.current_profile is None
    env = scene.build().environment
    np.testing.assert_allclose(float(env.waves[0].steepness), 0.02, rtol=1e-12)
    # Without [seabed] or [[waves]]: none.
    env = jc.read_scene(write_scene(tmp_path, SCENE, "plain.toml")).build().environment
    assert env.seabed is None and env.waves == ()
    assert scene.water.wave_ramp == 0.0 and float(env.wave_ramp) == 0.0


WAVE = '\n[[waves]]\ntheory = "airy"\nheight = 2.0\nperiod = 8.0\n'


def test_toml_wave_ramp_reaches_the_environment(tmp_path):
    text = edited("depth = 150.0\n", "depth = 150.0\nwave_ramp = 12.5\n") + WAVE
    scene = jc.read_scene(write_scene(tmp_path, text))
    assert scene.water.wave_ramp == 12.5
    assert float(scene.build().environment.wave_ramp) == 12.5


@pytest.mark.parametrize(
    "text, fragment, words",
    [
        # Schema: unknown keys, wrong types, missing keys.
        (SCENE + WAVE.replace("period", "perod"), "perod", ("waves[0].perod", "unknown key", "period")),
        (SCENE + WAVE.replace("8.0", '"8"'), 'period = "8"', ("waves[0].period", "finite number")),
        (SCENE + WAVE + "wheeler = 1\n", "wheeler = 1", ("waves[0].wheeler", "true or false")),
        (SCENE + WAVE.replace('theory = "airy"\n', ""), "[[waves]]", ("waves[0].theory", "missing required key")),
        (SCENE + WAVE.replace("period = 8.0\n", ""), "[[waves]]", ("waves[0].period", "missing required key")),
        (SCENE + '\n[waves]\ntheory = "airy"\n', "[waves]", ("key waves", "[[waves]]")),
        (SCENE + "\n[seabed]\nstifness = 1.0\n", "stifness", ("seabed.stifness", "unknown key", "stiffness")),
        (
            edited("depth = 150.0", "depth = 150.0\nfluid_inertia = 0"),
            "fluid_inertia",
            ("water.fluid_inertia", "true or false"),
        ),
        (
            edited("depth = 150.0", "depth = 150.0\nwave_ramp = -8.0"),
            "wave_ramp",
            ("water.wave_ramp", "non-negative", "-8"),
        ),
        # Values.
        (
            SCENE + WAVE.replace("airy", "stokes"),
            'theory = "stokes"',
            ("waves[0].theory", "unknown wave theory 'stokes'", "cnoidal"),
        ),
        (SCENE + WAVE + "steepness = 0.01\n", "steepness = 0.01", ("waves[0].steepness", "exactly one of height")),
        (SCENE + WAVE.replace("height = 2.0\n", ""), "[[waves]]", ("waves[0]", "exactly one of height")),
        (SCENE + WAVE.replace("8.0", "-8.0"), "period = -8.0", ("waves[0].period", "positive")),
        (SCENE + WAVE.replace("2.0", "0.0"), "height = 0.0", ("waves[0].height", "positive")),
        (
            SCENE + WAVE.replace("airy", "cnoidal").replace("period = 8.0", "period = 60.0") + "wheeler = false\n",
            "wheeler = false",
            ("waves[0].wheeler", "airy waves only"),
        ),
        (SCENE + "\n[seabed]\nstiffness = -3.0e6\n", "stiffness = -3.0e6", ("seabed.stiffness", "positive")),
        (SCENE + "\n[seabed]\nfriction = -0.1\n", "friction = -0.1", ("seabed.friction", "non-negative")),
        (SCENE + "\n[seabed]\nfriction_speed = 0\n", "friction_speed = 0", ("seabed.friction_speed", "positive")),
        (
            SCENE + "\n[seabed]\nfriction_damping = 0\n",
            "friction_damping = 0",
            ("seabed.friction_damping", "positive"),
        ),
        (
            edited("axial_stiffness = 3.0e7\n", "axial_stiffness = 3.0e7\nslack_damping = 1\n"),
            "slack_damping = 1",
            ("slack_damping", "true or false"),
        ),
        # The engine's own checks, located at the wave's table.
        (
            SCENE + WAVE.replace("airy", "cnoidal").replace("height = 2.0", "height = 120.0"),
            "[[waves]]",
            ("waves[0]", "breaking"),
        ),
        (SCENE + WAVE.replace("airy", "cnoidal"), "[[waves]]", ("waves[0]", "Cnoidal.period", "use Airy")),
        # Depth: waves and a seabed need it.
        (SCENE.replace("depth = 150.0\n", "") + WAVE, "[[waves]]", ("waves[0]", "water depth", "[water] depth")),
        (SCENE.replace("depth = 150.0\n", "") + "\n[seabed]\n", "[seabed]", ("key seabed", "water depth")),
        # Currents.
        (
            edited("depth = 150.0", "depth = 150.0\ncurrent = [0.1, 0.0, 0.0]") + SEA.split("[[waves]]")[0],
            "[water.current_profile]",
            ("water.current_profile", "not both"),
        ),
        (
            SCENE + "\n[water.current_profile]\nheights = [0.0, -10.0]\nspeeds = [0.1, 0.2]\n",
            "[water.current_profile]",
            ("water.current_profile", "strictly increasing"),
        ),
        (
            SCENE + "\n[water.current_profile]\nheights = [-10.0, 0.0]\nspeeds = 0.2\n",
            "speeds = 0.2",
            ("water.current_profile.speeds", "list of finite numbers"),
        ),
    ],
)
def test_toml_sea_errors_are_located(tmp_path, text, fragment, words):
    error, path = read_scene_error(tmp_path, text)
    assert_located(error, path, fragment, *words)


SEA_STATE = """
[[waves]]
spectrum = "jonswap"
significant_height = 2.5
peak_period = 9.0
peak_enhancement = 2.0
components = 120
frequencies = [0.4, 3.2]
seed = 7
heading = 20.0
spreading = 6.0
"""


def test_toml_sea_state_is_the_engines_realisation(tmp_path):
    scene = jc.read_scene(write_scene(tmp_path, SCENE + SEA_STATE))
    (spec,) = scene.water.waves
    assert isinstance(spec, jc.io.SeaStateSpec)
    assert (spec.spectrum, spec.significant_height, spec.peak_period, spec.peak_enhancement) == (
        "jonswap",
        2.5,
        9.0,
        2.0,
    )
    assert (spec.components, spec.frequencies, spec.seed, spec.heading, spec.spreading) == (
        120,
        (0.4, 3.2),
        7,
        20.0,
        6.0,
    )
    assert "repeating after 269.3 s" in spec.describe()  # 2π · 120 / 2.8 rad/s
    sea = spec.wave(150.0, 9.81)  # as the scene builds it
    expected = jc.WaveComponents.from_spectrum(
        jc.Jonswap(2.5, 9.0, 2.0), 150.0, seed=7, components=120, frequencies=(0.4, 3.2), heading=20.0, spreading=6.0
    )
    for field in ("amplitudes", "periods", "phases", "headings"):
        np.testing.assert_array_equal(getattr(sea, field), getattr(expected, field), err_msg=field)
    # Pierson–Moskowitz: γ = 1, long-crested without a spreading.
    text = SCENE + SEA_STATE.replace('"jonswap"', '"pierson-moskowitz"').replace("peak_enhancement = 2.0\n", "")
    (pm,) = jc.read_scene(write_scene(tmp_path, text.replace("spreading = 6.0\n", ""))).water.waves
    assert float(pm.sea_state().peak_enhancement) == 1.0 and pm.spreading is None


@pytest.mark.parametrize(
    "old, new, fragment, words",
    [
        ('"jonswap"', '"bretschneider"', "spectrum =", ("waves[0].spectrum", "unknown spectrum", "jonswap")),
        ("components = 120", "components = 12.5", "components =", ("waves[0].components", "integer")),
        ("seed = 7", "seed = -1", "seed =", ("waves[0].seed", "from 0 to")),
        ("[0.4, 3.2]", "[3.2, 0.4]", "frequencies =", ("waves[0].frequencies", "ω_min < ω_max")),
        ("spreading = 6.0", "spreading = 0.0", "spreading =", ("waves[0].spreading", "positive")),
        ('"jonswap"', '"pierson-moskowitz"', "peak_enhancement", ("waves[0].peak_enhancement", "has none")),
        ("peak_enhancement = 2.0", "peak_enhancement = 0.5", "[[waves]]", ("waves[0]", "at least 1")),
        # The band holds too little of m₀: the engine's check, located at the table.
        ("[0.4, 3.2]", "[0.6, 1.2]", "[[waves]]", ("waves[0]", "% of the spectrum's m₀", "widen frequencies")),
    ],
)
def test_toml_sea_state_errors_are_located(tmp_path, old, new, fragment, words):
    error, path = read_scene_error(tmp_path, SCENE + SEA_STATE.replace(old, new))
    assert_located(error, path, fragment, *words)


def test_toml_low_ursell_cnoidal_wave_is_a_note(tmp_path):
    # A cnoidal wave of Ursell number below 5: the engine warns that Airy fits better;
    # the reader keeps it as a note on the wave's line.
    text = SCENE + WAVE.replace("airy", "cnoidal").replace("period = 8.0", "period = 30.0")
    path = write_scene(tmp_path, text)
    with warnings.catch_warnings():
        warnings.simplefilter("error")
        scene = jc.read_scene(path)
        scene.build()
    (note,) = scene.notes
    assert "Ursell" in note and "Airy" in note and re.search(rf"\bline {line_of(path, '[[waves]]')}\b", note)


def test_water_built_from_python_checks_its_depth():
    # A Water made in Python, without a file: still a SceneError, naming what is missing.
    water = jc.io.Water(waves=(WaveSpec("airy", 8.0, height=2.0, where="wave 1"),))
    with pytest.raises(jc.io.SceneError, match="wave 1: waves need the water depth"):
        water.environment()
    with pytest.raises(jc.io.SceneError, match="give exactly one of height and steepness"):
        jc.io.Water(depth=50.0, waves=(WaveSpec("airy", 8.0),)).environment()
    with pytest.raises(jc.io.SceneError, match="Seabed.stiffness must be positive"):
        jc.io.Water(depth=50.0, seabed=SeabedSpec(stiffness=0.0)).environment()


# --------------------------------------------------------------------------------------
# Motion tables


def write_motion(tmp_path: Path, text: str, name: str = "motion.txt") -> Path:
    path = tmp_path / name
    path.write_text(text)
    return path


def test_motion_file_whitespace_and_csv_agree(tmp_path):
    expected_times = np.array([0.0, 0.5, 1.0])
    expected = np.array([[[1, 2, 3], [4, 5, 6]], [[1.5, 2, 3], [4, 5, 6.5]], [[2, 2, 3], [4, 5, 7]]], dtype=float)
    spaced = write_motion(
        tmp_path,
        "# two fairleads\n"
        "0.0   1 2 3    4 5 6\n"
        "\n"
        "0.5\t1.5 2 3\t4 5 6.5\n"
        "   # a comment between rows\n"
        "1.0   2 2 3    4 5 7\n",
    )
    csv = write_motion(
        tmp_path,
        "time,x1,y1,z1,x2,y2,z2\n0.0,1,2,3,4,5,6\n0.5, 1.5, 2, 3, 4, 5, 6.5\n# comment\n1.0,2,2,3,4,5,7\n",
        "motion.csv",
    )
    for path in (spaced, csv):
        times, positions = jc.io.read_motion_file(path, 2)
        np.testing.assert_array_equal(times, expected_times)
        np.testing.assert_array_equal(positions, expected)
        assert positions.shape == (3, 2, 3)


def test_motion_file_wrong_column_count(tmp_path):
    path = write_motion(tmp_path, "t x y z\n0 1 2 3\n1 1 2\n2 1 2 3\n")
    with pytest.raises(jc.io.SceneError) as error:
        jc.io.read_motion_file(path, 1)
    assert_located(error, path, "1 1 2", "expected 4 columns", "got 3")
    path = write_motion(tmp_path, "0 1 2 3\n1 1 2 3\n", "two_points.txt")
    with pytest.raises(jc.io.SceneError) as error:
        jc.io.read_motion_file(path, 2)
    assert_located(error, path, "0 1 2 3", "expected 7 columns", "2 coupled point")


@pytest.mark.parametrize("later", ["1.0", "0.5"])
def test_motion_file_time_must_increase(tmp_path, later):
    path = write_motion(tmp_path, f"0.0 0 0 0\n1.0 1 0 0\n{later} 2 0 0\n2.0 3 0 0\n")
    with pytest.raises(jc.io.SceneError) as error:
        jc.io.read_motion_file(path, 1)
    assert_located(error, path, f"{later} 2 0 0", "must increase")


def test_motion_file_non_numeric_field(tmp_path):
    path = write_motion(tmp_path, "time x y z\n0 0 0 0\n1 0 oops 0\n2 0 0 0\n")
    with pytest.raises(jc.io.SceneError) as error:
        jc.io.read_motion_file(path, 1)
    assert_located(error, path, "oops", "non-numeric")


def test_motion_file_non_finite_value(tmp_path):
    path = write_motion(tmp_path, "0 0 0 0\n1 nan 0 0\n2 0 0 0\n")
    with pytest.raises(jc.io.SceneError) as error:
        jc.io.read_motion_file(path, 1)
    assert_located(error, path, "nan", "non-finite")


@pytest.mark.parametrize("text", ["", "# only a comment\n", "t x y z\n", "t x y z\n0 1 2 3\n", "0 1 2 3\n"])
def test_motion_file_needs_two_rows(tmp_path, text):
    path = write_motion(tmp_path, text)
    with pytest.raises(jc.io.SceneError, match="at least 2 rows"):
        jc.io.read_motion_file(path, 1)


def test_motion_file_missing(tmp_path):
    with pytest.raises(jc.io.SceneError, match="cannot read motion file"):
        jc.io.read_motion_file(tmp_path / "nowhere.csv", 1)


def test_with_motion_table_gives_displacements_about_the_points(tmp_path):
    points = (*POINTS, "3    Coupled   -200.0  10.0   -5.0    0       0        0      0")
    lines = (LINES[0], "2    chain     1        3        250.0     10       -")
    scene = jc.read_moordyn(write_moordyn(tmp_path, points=points, lines=lines))
    assert scene.coupled_points == (1, 2)
    times = np.array([0.0, 0.5, 1.5, 3.0])
    positions = np.stack(
        [
            np.stack([200.0 + np.sin(times), 0.1 * times, np.cos(times) - 1.0], axis=1),
            np.stack([-200.0 - times, 10.0 + times**2, -5.0 + 0.3 * times], axis=1),
        ],
        axis=1,
    )
    moved = scene.with_motion_table(times, positions)
    assert moved.points[0].motion is None and scene.points[1].motion is None
    for column, k in enumerate(scene.coupled_points):
        motion = moved.points[k].motion
        assert isinstance(motion, jc.Sampled)
        origin = np.asarray(scene.points[k].position)
        for i, t in enumerate(times):
            np.testing.assert_allclose(np.asarray(motion.displacement(t)), positions[i, column] - origin, atol=1e-12)
    with pytest.raises(jc.io.SceneError, match="2 coupled point"):
        scene.with_motion_table(times, positions[:, :1])


# --------------------------------------------------------------------------------------
# The command line


def test_cli_malformed_input(tmp_path, capsys):
    row = "1    chain     1        2        250.0     ten      -"
    path = write_moordyn(tmp_path, lines=(row,))
    for argv in (["run", str(path), "--no-progress"], ["info", str(path)]):
        assert cli_main(argv) == 2
        err = capsys.readouterr().err
        assert err.startswith("jaxcable: error:"), err
        assert f"line {line_of(path, row)}" in err and "NumSegs" in err


def test_cli_malformed_scene(tmp_path, capsys):
    path = write_scene(tmp_path, edited("segments = 10", "segments = 10.5"))
    assert cli_main(["info", str(path)]) == 2
    err = capsys.readouterr().err
    assert err.startswith("jaxcable: error:") and f"line {line_of(path, 'segments = 10.5')}" in err, err


def test_cli_motion_with_wrong_column_count(tmp_path, capsys):
    path = write_moordyn(tmp_path)
    motion = write_motion(tmp_path, "0 200 0 0 1\n1 201 0 0 1\n")
    assert cli_main(["run", str(path), "--motion", str(motion), "--no-progress"]) == 2
    err = capsys.readouterr().err
    assert "jaxcable: error:" in err and "line 1" in err and "expected 4 columns" in err, err


def test_cli_motion_without_coupled_points(tmp_path, capsys):
    points = (POINTS[0], "2    Fixed     200.0   0.0    0.0     0       0        0      0")
    path = write_moordyn(tmp_path, points=points)
    motion = write_motion(tmp_path, "0 200 0 0\n1 201 0 0\n")
    assert cli_main(["run", str(path), "--motion", str(motion), "--no-progress"]) == 2
    err = capsys.readouterr().err
    assert "jaxcable: error:" in err and "no coupled points" in err, err


def test_cli_duration_past_the_motion_table(tmp_path, capsys):
    path = write_moordyn(tmp_path)
    motion = write_motion(tmp_path, "0 200 0 0\n1 201 0 0\n2 200 0 0\n")
    assert cli_main(["run", str(path), "--motion", str(motion), "--duration", "5", "--no-progress"]) == 2
    err = capsys.readouterr().err
    assert "jaxcable: error:" in err and "--duration 5" in err and "2 s" in err, err


def test_cli_motion_table_must_start_at_zero(tmp_path, capsys):
    path = write_moordyn(tmp_path)
    motion = write_motion(tmp_path, "1 200 0 0\n2 201 0 0\n")
    assert cli_main(["run", str(path), "--motion", str(motion), "--no-progress"]) == 2
    assert "t = 0" in capsys.readouterr().err


# --------------------------------------------------------------------------------------
# Regressions found by reading MoorDyn's own inputs and probing the readers


def test_cli_out_writes_the_files_own_channels(tmp_path):
    path = write_moordyn(tmp_path, outputs=("L1N5PZ FairTen1", "END"))
    out = tmp_path / "o.csv"
    assert cli_main(["run", str(path), "--duration", "0", "--out", str(out), "--no-progress"]) == 0
    assert out.read_text().splitlines()[0] == "Time,L1N5PZ,FairTen1"


def test_cli_unknown_channel_fails_before_running(tmp_path, capsys):
    path = write_moordyn(tmp_path, outputs=("FairTen1 L1N99PX", "END"))
    assert cli_main(["run", str(path), "--duration", "0", "--no-progress"]) == 2
    err = capsys.readouterr().err
    assert "L1N99PX" in err and "nodes 0 to 10" in err, err


def test_motion_file_bad_first_row_is_not_a_header(tmp_path):
    # A header has no numbers in it; a first data row with a typo is an error.
    path = write_motion(tmp_path, "0 200 0 0x\n1 201 0 0\n2 202 0 0\n")
    with pytest.raises(jc.io.SceneError, match="line 1: non-numeric"):
        jc.io.read_motion_file(path, 1)


@pytest.mark.parametrize(
    "section, row, column",
    [
        ("points", "2    Vessel    nan     0.0    0.0     0       0        0      0", "X"),
        ("lines", "1    chain     1        2        inf       10       -", "UnstrLen"),
    ],
)
def test_moordyn_non_finite_numbers_are_located(tmp_path, section, row, column):
    sections = {"points": (POINTS[0], row)} if section == "points" else {"lines": (row,)}
    path = write_moordyn(tmp_path, **sections)
    with pytest.raises(jc.io.SceneError) as error:
        jc.read_moordyn(path)
    assert_located(error, path, row, column, "not a finite number")


def test_moordyn_negative_dtout_is_located(tmp_path):
    path = write_moordyn(tmp_path, options=(*OPTIONS, "-1   dtOut   output interval"))
    with pytest.raises(jc.io.SceneError) as error:
        jc.read_moordyn(path)
    assert_located(error, path, "dtOut", "must be positive")


def test_moordyn_line_from_a_point_to_itself(tmp_path):
    row = "1    chain     2        2        250.0     10       -"
    path = write_moordyn(tmp_path, lines=(row,))
    with pytest.raises(jc.io.SceneError) as error:
        jc.read_moordyn(path)
    assert_located(error, path, row, "to itself")


def test_run_past_a_scene_motion_table_fails_before_solving(tmp_path):
    write_motion(tmp_path, "0 150 0 0\n1 151 0 0\n2 150 0 0\n", name="float.csv")
    path = write_scene(
        tmp_path,
        edited(
            "position = [150.0, 0.0, 0.0]\n",
            'position = [150.0, 0.0, 0.0]\nmotion = { type = "table", file = "float.csv" }\n',
        ),
    )
    scene = jc.read_scene(path)
    with pytest.raises(jc.io.SceneError, match="covers 0 to 2 s, but the run needs 0 to 10 s"):
        jc.run_scene(scene)


def test_titles_are_read(tmp_path):
    scene = jc.read_moordyn(LOWE_AND_LANGLEY)
    assert scene.title == "MoorDyn input file for a flexible jumper (Lowe and Langley, 2006)"
    assert jc.read_scene(write_scene(tmp_path, SCENE)).title == "reader test"


def test_cli_unknown_name_lists_the_bundled_examples(capsys):
    assert cli_main(["info", "y_brnch"]) == 2
    err = capsys.readouterr().err
    assert "no file or bundled example named 'y_brnch'" in err and "y_branch" in err, err


def test_run_notes_a_line_out_of_the_water(tmp_path):
    # The fairlead 2 m above the still-water level. MoorDyn files model the surface, as
    # MoorDyn does; without it, the run says that the emerged part is treated as
    # submerged rather than pass it over in silence.
    points = (POINTS[0], "2    Vessel    200.0   0.0    2.0     0       0        0      0")
    scene = jc.read_moordyn(write_moordyn(tmp_path, points=points))
    assert scene.water.free_surface
    assert not any("above the still-water level" in note for note in jc.run_scene(scene, duration=0).notes)
    submerged = scene.replace(water=dataclasses.replace(scene.water, free_surface=False))
    run = jc.run_scene(submerged, duration=0)
    assert any("z = 2.00 m, above the still-water level" in note for note in run.notes), run.notes


@pytest.mark.parametrize(
    "old, new, key",
    [
        ("dt_out = 0.5", 'dt_out = 0.5\nsolver = "rk5"', "simulation.solver"),
        ("dt_out = 0.5", 'dt_out = 0.5\nmass_matrix = "diagonal"', "simulation.mass_matrix"),
        ("dt_out = 0.5", "dt_out = -0.5", "simulation.dt_out"),
        ("duration = 10.0", "duration = -1.0", "simulation.duration"),
    ],
)
def test_toml_bad_simulation_settings_are_located(tmp_path, old, new, key):
    error, path = read_scene_error(tmp_path, edited(old, new))
    assert_located(error, path, new.splitlines()[-1], key)


@pytest.mark.parametrize(
    "option, kind",
    [
        ("5  WaveKin", "waves"),
        ("2  Currents", "currents"),
        ("bathymetry.txt  SeafloorFile", "bathymetry"),
        ("1.5  StatDynFricScale", "friction"),
    ],
)
def test_moordyn_physics_left_out_is_listed_by_kind(tmp_path, option, kind):
    options = (*OPTIONS, "0.5  FrictionCoefficient", option)
    with pytest.warns(UserWarning, match="ignored"):
        scene = jc.read_moordyn(write_moordyn(tmp_path, options=options))
    ((dropped_kind, note),) = scene.dropped
    assert dropped_kind == kind and note in scene.notes and option.split()[-1] in note


def test_the_command_line_refuses_physics_left_out_unless_allowed(tmp_path, capsys):
    """A file with a bending stiffness table (MoorDyn's EI against curvature) is refused,
    naming the line; with --allow-ignored EI it runs, and the summary says what was left
    out."""
    path = write_moordyn(tmp_path, types=("chain  0.1  20.0  1.0e9  -0.5  ei.dat  1.2  1.0  0.05  0.0",))
    argv = ["run", str(path), "--duration", "0", "--no-progress"]
    assert cli_main(argv) == 2
    err = capsys.readouterr().err
    assert f"line {line_of(path, 'ei.dat')}: line type chain: bending stiffness table 'ei.dat' ignored" in err
    assert err.rstrip().endswith("to run without it, add --allow-ignored EI")
    assert cli_main([*argv, "--allow-ignored", "waves"]) == 2  # not the kind left out
    capsys.readouterr()
    assert cli_main([*argv, "--allow-ignored", "EI,waves"]) == 0
    assert "left out (--allow-ignored): " in capsys.readouterr().out
    assert cli_main([*argv, "--allow-ignored", "EI,bends"]) == 2
    assert "--allow-ignored: unknown kind(s) bends" in capsys.readouterr().err


def test_toml_moordyn_forms_of_damping_and_friction(tmp_path):
    """`slack_damping` on a line type and `friction_damping` on the seabed reach the
    engine; without them, the law and friction are jaxcable's own."""
    text = edited("axial_stiffness = 3.0e7\n", "axial_stiffness = 3.0e7\nslack_damping = true\n")
    text += "\n[seabed]\nfriction = 0.5\nfriction_damping = 150.0\n"
    built = jc.read_scene(write_scene(tmp_path, text)).build()
    assert built.model.line.tension_law.slack_damping is True
    assert float(built.environment.seabed.friction_damping) == 150.0
    plain = jc.read_scene(write_scene(tmp_path, SCENE + "\n[seabed]\nfriction = 0.5\n", "plain.toml")).build()
    assert plain.model.line.tension_law.slack_damping is False
    assert plain.environment.seabed.friction_damping is None
