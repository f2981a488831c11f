"""The advice against values computed here: the stiffest axial mode against the
eigenvalues of the linearised model; the Ursell number against the dispersion relation
solved by bisection; the Keulegan–Carpenter number against Airy's speed amplitude;
curvature and segment counts on a circle and a catenary; quasi-static tensions against
the catenary; slack on a line with nothing to hold it taut."""

import math

import diffrax
import jax
import jax.numpy as jnp
import numpy as np
import pytest
import scipy.special
from helpers import catenary_parameter
from scipy.optimize import brentq

import jaxcable as jc
from jaxcable._advice import STABLE_STEP, advise, polyline_curvature, segments_needed, wave_fit
from jaxcable._equations import lagrangian as lag
from jaxcable._equations.modes import _axial_modes, bending_modes, fastest_eigenvalues, seabed_mode, stiffest_axial_mode
from jaxcable._solver.stability import (
    BENDING_RUN_GROWTH,
    STEP_FRACTION,
    fixed_step_growth,
    fixed_steps,
    stability_function,
    stable_step,
)
from jaxcable.io import advice_lines


def taut_line(
    mass_matrix: str, damping_ratio: float = 0.0, bending_stiffness: float = 0.0, slack_width: float = 1e-5
) -> jc.io.BuiltScene:
    # A straight, stretched line between two anchors: its fastest mode is axial.
    rope = jc.io.LineTypeSpec(
        "rope",
        mass_per_length=2.0,
        diameter=0.02,
        axial_stiffness=4e6,
        axial_damping_ratio=damping_ratio,
        tangential_added_mass=0.5,
        bending_stiffness=bending_stiffness,
        slack_width=slack_width,
    )
    points = (jc.io.PointSpec("a", "fixed", (0.0, 0.0, -50.0)), jc.io.PointSpec("b", "fixed", (101.0, 0.0, -50.0)))
    lines = (jc.io.LineSpec("1", "rope", 0, 1, 100.0, 20),)
    scene = jc.io.Scene(points, (rope,), lines, run=jc.io.RunSettings(mass_matrix=mass_matrix))
    return scene.build()


def largest_eigenvalue(built: jc.io.BuiltScene) -> float:
    """|λ|max of the first-order system linearised about the equilibrium at rest."""
    return float(np.abs(linearised_eigenvalues(built)).max())


def linearised_eigenvalues(built: jc.io.BuiltScene) -> np.ndarray:
    """The eigenvalues (1/s, complex) of the first-order system linearised about the
    equilibrium at rest."""
    model, env = built.model, built.environment
    static = jc.solve_statics(model, env)
    free = model.free_nodes
    x0 = static.state.positions[free]
    n = x0.size

    def field(y):
        x, v = y[:n].reshape(x0.shape), y[n:].reshape(x0.shape)
        a, *_ = lag.free_accelerations(model, env, 0.0, x, v)
        return jnp.concatenate([v.ravel(), a.ravel()])

    jacobian = jax.jacfwd(field)(jnp.concatenate([x0.ravel(), jnp.zeros(n)]))
    return np.linalg.eigvals(np.asarray(jacobian))


@pytest.mark.parametrize("mass_matrix", ["lumped", "consistent"])
@pytest.mark.parametrize("damping_ratio", [0.0, 2.0])
def test_stiffest_mode_bounds_the_linearised_spectrum(mass_matrix, damping_ratio):
    # The alternating mode of a chain is the highest: a 20-segment line's largest
    # eigenvalue lies just below the two-node bound the advice quotes (sin(20π/42)
    # of it, undamped), never above it.
    built = taut_line(mass_matrix, damping_ratio)
    _, bound, _ = stiffest_axial_mode(built)
    measured = largest_eigenvalue(built)
    assert 0.97 * bound < measured <= bound * (1 + 1e-6)


@pytest.mark.parametrize("damping_ratio", [0.5, 2.0])
def test_a_fixed_step_stable_by_the_bound_is_stable_for_the_linearised_line(damping_ratio):
    """Midpoint's longest step that `fixed_step_growth` calls stable (|R| = 1 at the
    bound's eigenvalues, found by bisection) keeps the fast eigenvalues of the
    linearised line within |R(λ Δt)| ≤ 1, and is not far short of the true limit: 1.5
    times it is unstable for the line itself. (The slow transverse modes, undamped when
    linearised at rest, grow by 1e-4 a step at this step: quadratic drag, not a linear
    term, holds them, as it does in MoorDyn.)"""
    built = taut_line("lumped", damping_ratio)
    solver = diffrax.Midpoint()
    low, high = 1e-6, 1.0
    for _ in range(60):
        middle = 0.5 * (low + high)
        low, high = (middle, high) if fixed_step_growth(solver, middle, built) <= 1 else (low, middle)
    eigenvalues = linearised_eigenvalues(built)
    fast = eigenvalues[np.abs(eigenvalues) > 0.5 * stiffest_axial_mode(built)[1]]
    assert fast.size >= 9
    assert np.abs(stability_function(solver, fast * low)).max() <= 1 + 1e-9
    assert np.abs(stability_function(solver, eigenvalues * 1.5 * low)).max() > 1


def test_an_undamped_line_has_no_stable_two_stage_fixed_step():
    # |R(iy)|² = 1 + y⁴/4 for the two-stage methods: an undamped axial mode grows a
    # little with any step.
    built = taut_line("lumped", 0.0)
    for dt in (1e-5, 1e-4, 1e-3):
        assert fixed_step_growth(diffrax.Midpoint(), dt, built) > 1


def test_a_bending_mode_counts_against_a_fixed_step_where_the_run_would_grow_it():
    # Undamped, a bending mode grows a little at any two-stage step; it counts only where
    # the run's steps would grow it by more than 1 %: not for a few steps, and for
    # many. The damped axial mode alone is stable at this step.
    built = taut_line("lumped", 0.5, bending_stiffness=2e5)
    solver, dt = diffrax.Midpoint(), 2e-3
    axial = fixed_step_growth(solver, dt, taut_line("lumped", 0.5))
    assert axial is not None and axial <= 1
    bending = np.abs(stability_function(solver, 1j * bending_modes(built.model, built.environment) * dt)).max()
    assert 1 < bending and bending**10 < BENDING_RUN_GROWTH < bending**100_000
    assert fixed_step_growth(solver, dt, built, steps=10) == axial
    assert fixed_step_growth(solver, dt, built, steps=100_000) == bending


def test_the_stable_step_is_the_edge_of_the_stability_region():
    """Undamped, the fastest axial mode λ = iω is stable under RK4 up to ω Δt = 2√2
    (|R(iy)|² = 1 − y⁶/72 + y⁸/576). With a sharp slack switch ω is the taut
    segment's ω_n; with a smoothed one, a segment inside the switch's band is stiffer,
    27/16 C_E at most (the tangent of C_E ε s²(3 − 2s), s = ε/w, at s = 3/4), so
    ω = √(27/16) ω_n. Damped, the step ends where |R(λ Δt)| first reaches 1 on a mode's
    ray, which the closed form of R confirms from both sides; and a two-stage method
    keeps no undamped mode from growing at any step."""
    undamped = taut_line("lumped", 0.0)
    _, omega, _ = stiffest_axial_mode(undamped)
    sharp = taut_line("lumped", 0.0, slack_width=0.0)
    assert stable_step(jc.RK4(), sharp) * omega == pytest.approx(2 * math.sqrt(2), rel=1e-9)
    assert stable_step(jc.RK4(), undamped) * omega * math.sqrt(27 / 16) == pytest.approx(2 * math.sqrt(2), rel=1e-9)
    assert stable_step(diffrax.Midpoint(), undamped) * omega < 1e-2
    damped = taut_line("lumped", 0.5)
    dt = stable_step(jc.RK4(), damped)
    eigenvalues = fastest_eigenvalues(damped, slack_band=True)
    assert np.abs(stability_function(jc.RK4(), eigenvalues * dt)).max() <= 1 + 1e-9
    assert np.abs(stability_function(jc.RK4(), eigenvalues * dt * 1.001)).max() > 1


# A damped 40-segment steel rope whose top's motion slackens it from t ≈ 3 s (as in
# `benchmarks/first_contact.py`'s line40): its segments pass through the slack
# switch's band, where they are stiffer and less damped than taut.
SNAPPING_ROPE = """snapping rope
----------------------- LINE TYPES ------------------------------------------
TypeName   Diam     Mass/m     EA         BA/-zeta    EI         Cd     Ca     CdAx    CaAx
(name)     (m)      (kg/m)     (N)        (N-s/-)     (N-m^2)    (-)    (-)    (-)     (-)
rope  0.0195441  3.0  3.0e7  -0.8  0.0  1.557  1.301  0.0248  1.301
---------------------- POINTS --------------------------------
ID    Type      X       Y       Z       Mass    Volume      CdA    Ca
(#)   (-)       (m)     (m)     (m)     (kg)    (m^3)       (m^2)  (-)
1     Fixed     0.0     0.0     -200.0  0       0           0      0
2     Coupled   346.4101615137755  0.0  0.0  0       0           0      0
---------------------- LINES ----------------------------------------
ID   LineType   AttachA  AttachB  UnstrLen  NumSegs  LineOutputs
(#)   (name)     (#)      (#)       (m)       (-)     (-)
1    rope       1        2        400.0     40       pt
---------------------- OPTIONS -----------------------------------------
250           WtrDpth       water depth (m)
0.1           dtOut         output interval (s)
------------------------- need this line --------------------------------------
"""


def test_a_segment_inside_the_slack_band_bounds_the_step(tmp_path):
    """The slack band's modes are real: on a damped rope through its first slack and
    snap, RK4 at 1.1 times the step they allow, at which the taut modes alone are
    stable, goes non-finite; at `fixed_steps`' 0.7 of it, the top tension is that of
    steps a quarter as long to 0.1 % of the peak."""
    path = tmp_path / "rope.txt"
    path.write_text(SNAPPING_ROPE)
    t = np.arange(0.0, 8.05, 0.1)
    top = np.column_stack([346.4101615137755 + 1.5733 * np.sin(2 * np.pi * t / 5.6), 0 * t, 0 * t])
    built = jc.read_moordyn(path).with_motion_table(t, top[:, None, :], "the top's motion").build()
    model, env = built.model, built.environment
    limit = stable_step(jc.RK4(), built, duration=8.0)
    assert limit is not None
    assert np.abs(stability_function(jc.RK4(), _axial_modes(model, env)[1] * 1.1 * limit)).max() < 1

    def top_tension(dt):
        config = jc.SolverConfig(jc.RK4(), dt0=dt, stepsize_controller=diffrax.ConstantStepSize())
        return np.asarray(jc.simulate(model, env, 8.0, ts=t, solver=config).tension[:, -1])

    with pytest.raises(RuntimeError, match="non-finite"):
        top_tension(1.1 * limit)
    fine = top_tension(0.7 * limit / 4)
    assert np.max(np.abs(top_tension(0.7 * limit) - fine)) < 1e-3 * np.max(fine)
    assert np.max(fine) > 100e3  # N: the snap at t ≈ 6.8 s


def test_fixed_steps_are_stable_for_the_linearised_line_of_every_scene():
    """[`fixed_steps`][]: RK4 at 0.7 of the stability limit of the stiffest of the
    scenes, and within RK4's region for every eigenvalue of each scene's linearised
    system (an independent check of the modes that bound the step)."""
    soft, stiff = taut_line("lumped", 0.0), taut_line("consistent", 0.5)
    config = fixed_steps([(soft.model, soft.environment), (stiff.model, stiff.environment)])
    assert isinstance(config.solver, jc.RK4)
    assert isinstance(config.stepsize_controller, diffrax.ConstantStepSize)
    dt = float(config.dt0)  # pyright: ignore[reportArgumentType]
    limits = [stable_step(jc.RK4(), built) for built in (soft, stiff)]
    assert dt == pytest.approx(STEP_FRACTION * min(limits), rel=1e-12)  # pyright: ignore[reportArgumentType]
    for built in (soft, stiff):
        growth = np.abs(stability_function(jc.RK4(), linearised_eigenvalues(built) * dt))
        assert growth.max() <= 1 + 1e-9


def test_stability_functions_are_the_closed_forms():
    z = np.array([-1.0, 0.5j, -2.0, -0.3 + 1j, -2.5 + 0.5j])
    polynomial = lambda z, n: sum(z**k / math.factorial(k) for k in range(n + 1))  # noqa: E731
    np.testing.assert_allclose(stability_function(diffrax.Euler(), z), polynomial(z, 1), atol=1e-15)
    for two_stage in (diffrax.Midpoint(), diffrax.Heun()):
        np.testing.assert_allclose(stability_function(two_stage, z), polynomial(z, 2), atol=1e-15)
    # Dopri5's: Taylor's to z⁵/5! and z⁶/600 (Hairer, Nørsett & Wanner I, §IV.2).
    np.testing.assert_allclose(stability_function(diffrax.Dopri5(), z), polynomial(z, 5) + z**6 / 600, atol=1e-14)
    assert stability_function(diffrax.Kvaerno5(), z) is None


def test_advice_counts_steps_from_the_bound():
    built = taut_line("lumped")
    omega, magnitude, _ = stiffest_axial_mode(built)
    # Undamped, lumped: ω_n = 2 √(EA / m) / l with m including tangential added mass.
    m = 2.0 + 1025.0 * np.pi * 0.01**2 * 0.5
    np.testing.assert_allclose(omega, 2 * np.sqrt(4e6 / m) / 5.0, rtol=1e-12)
    assert magnitude == omega
    text = " ".join(advice_lines(advise(built, duration=10.0)))
    assert f"~{int(np.ceil(10.0 / (STABLE_STEP / magnitude))):,} steps" in text


# --------------------------------------------------------------------------------------
# Wave theory: the Ursell number and d/λ, against the dispersion relation solved here.


def linear_wavelength(period: float, depth: float, g: float = 9.81) -> float:
    """λ (m) from ω² = g k tanh(k d), by bisection (independent of jaxcable's solver)."""
    omega = 2 * np.pi / period
    k = brentq(lambda k: g * k * np.tanh(k * depth) - omega**2, 1e-8, 10.0, xtol=1e-15)
    return 2 * np.pi / k


@pytest.mark.parametrize(
    "height, period, depth, fits",
    [
        (2.0, 8.0, 30.0, "airy"),  # intermediate depth, U ≈ 0.8
        (3.0, 14.0, 10.0, "cnoidal"),  # shallow and long: U ≈ 57, λ ≈ 13.7 d
        (5.5, 8.0, 10.0, "none"),  # U ≈ 28 > 26 but λ ≈ 7 d
    ],
)
def test_wave_fit_from_the_ursell_number(height, period, depth, fits):
    wave = jc.Airy(height, period, depth)
    fit = wave_fit(wave)
    length = linear_wavelength(period, depth)
    ursell = height * length**2 / depth**3
    np.testing.assert_allclose(
        [fit.wavelength, fit.ursell, fit.relative_depth, fit.height_ratio],
        [length, ursell, depth / length, height / depth],
        rtol=1e-9,
    )
    # The cases are where the docstring's rule puts them: U against 8π²/3, λ against 8d.
    if fits == "airy":
        assert ursell < 8 * np.pi**2 / 3
    elif fits == "cnoidal":
        assert ursell > 8 * np.pi**2 / 3 and length > 8 * depth
    elif fits == "none":
        assert ursell > 8 * np.pi**2 / 3 and length < 8 * depth and height / depth < 0.78
        assert height / length < 0.142 * np.tanh(2 * np.pi * depth / length)  # not breaking (Miche)
    assert fit.fits == fits and fit.theory == "airy"
    assert fit.uses_fitting_theory == (fits == "airy")


def test_cnoidal_wave_fit_uses_its_own_wavelength():
    # For a cnoidal wave U = 16 m K(m)² / 3 exactly (first-order theory).
    wave = jc.Cnoidal(3.0, 14.0, 10.0)
    fit = wave_fit(wave)
    np.testing.assert_allclose(fit.ursell, 16 * float(wave.m) * scipy.special.ellipk(float(wave.m)) ** 2 / 3, rtol=1e-9)
    assert fit.theory == "cnoidal" and fit.fits == "cnoidal" and fit.uses_fitting_theory


# --------------------------------------------------------------------------------------
# Drag against fluid inertia: the Keulegan–Carpenter number by hand.


def line_in_waves(diameter: float, area: float, wave: jc.Airy, body: jc.Body | None = None):
    """A taut horizontal line 5 m below the still-water level, between two anchors,
    with an optional body at its middle node."""
    law = jc.LinearElastic(1e8)
    line = jc.LineType(
        mass_per_length=2.0 * 1025 * area,
        diameter=diameter,
        tension_law=law,
        area=area,
        normal_drag=1.2,
        normal_added_mass=1.0,
    )
    model = jc.CableNetwork.from_branches(
        junctions=[[0.0, 0.0, -5.0], [40.0, 0.0, -5.0], [20.0, 0.0, -5.0]],
        branches=[jc.Branch(0, 2, line, 19.99, 4), jc.Branch(2, 1, line, 19.99, 4)],
        constraints={0: jc.Fixed(), 1: jc.Fixed()},
        bodies={2: body} if body is not None else None,
    )
    return model, jc.Environment(depth=float(wave.depth), waves=(wave,))


def test_keulegan_carpenter_number_and_inertia_ratio_by_hand():
    height, period, depth, z = 3.0, 9.0, 40.0, -5.0
    wave = jc.Airy(height, period, depth)
    k = 2 * np.pi / linear_wavelength(period, depth)
    # The horizontal speed amplitude at the shallowest point, the anchors at z = −5 m.
    u = np.pi * height / period * np.cosh(k * (z + depth)) / np.sinh(k * depth)

    # A thin rope: KC in the hundreds, drag dominates.
    d = 0.02
    thin = advise(*line_in_waves(d, np.pi * d**2 / 4, wave))
    (check,) = thin.inertia
    np.testing.assert_allclose([check.speed, check.depth], [u, z], rtol=1e-6)
    np.testing.assert_allclose(check.keulegan_carpenter, u * period / d, rtol=1e-6)
    # r = π² C_M / (K_n KC) for a solid round section, C_M = 1 + C_a = 2.
    np.testing.assert_allclose(check.inertia_ratio, np.pi**2 * 2 / (1.2 * u * period / d), rtol=1e-6)
    assert check.regime == "drag" and thin.drag_dominates is True
    assert any("fluid_inertia = false" in line for line in advice_lines(thin))

    # A 1 m pipe with a 0.5 m³ buoy on it: KC ≈ 10, inertia matters.
    d, volume = 1.0, 0.5
    body = jc.Body(mass=400.0, volume=volume, drag_area=0.3, added_mass=0.5)
    thick = advise(*line_in_waves(d, np.pi * d**2 / 4, wave, body))
    pipe, buoy = thick.inertia
    np.testing.assert_allclose(pipe.keulegan_carpenter, u * period / d, rtol=1e-6)
    assert pipe.regime in ("both", "inertia") and thick.drag_dominates is False
    # The body: D = (6V/π)^⅓ and r = 4π V (1 + C_a) / (C_D A u T), at its own depth.
    np.testing.assert_allclose(buoy.diameter, (6 * volume / np.pi) ** (1 / 3), rtol=1e-12)
    z_body = buoy.depth
    u_body = np.pi * height / period * np.cosh(k * (z_body + depth)) / np.sinh(k * depth)
    np.testing.assert_allclose(buoy.speed, u_body, rtol=1e-6)
    np.testing.assert_allclose(buoy.inertia_ratio, 4 * np.pi * volume * 1.5 / (0.3 * u_body * period), rtol=1e-6)
    assert not any("fluid_inertia = false" in line for line in advice_lines(thick))
    # The body splits the line into two chains of the graph.
    assert [d.segments for d in thick.discretisation] == [4, 4]


# --------------------------------------------------------------------------------------
# Segments: the polyline error bound on shapes whose curvature is known.


def test_polyline_curvature_of_a_circle_and_the_segments_it_needs():
    radius, n = 10.0, 8
    angles = np.linspace(0.0, np.pi, n + 1)
    points = radius * np.c_[np.cos(angles), np.sin(angles), np.zeros(n + 1)]
    step = np.pi / n
    chord = 2 * radius * np.sin(step / 2)
    # Each interior node turns by the angle the chord subtends; over the chord length.
    np.testing.assert_allclose(polyline_curvature(points), step / chord, rtol=1e-12)
    assert abs(step / chord * radius - 1) < step**2 / 20
    # A semicircle, L = πR, κ = 1/R, allowed 1 % of L = 0.314 m: √2/8 (L/N)² / R falls
    # below it at N = 8 (0.278 m), not at 7 (0.356 m). The 8-gon's true sagitta, 0.192 m,
    # is within the bound.
    length, tolerance = np.pi * radius, 0.01 * np.pi * radius
    assert np.sqrt(2) / 8 * (length / 7) ** 2 / radius > tolerance > np.sqrt(2) / 8 * (length / 8) ** 2 / radius
    assert segments_needed(length, 1 / radius, tolerance) == 8
    assert radius * (1 - np.cos(step / 2)) < np.sqrt(2) / 8 * chord**2 / radius
    assert segments_needed(length, 0.0, tolerance) == 1


@pytest.fixture(scope="module")
def hanging():
    """A heavy line hanging between an anchor and a support at the same height that
    moves 4 m along x, in water; its advice. It stretches by 1e-4 at most: a catenary."""
    law = jc.LinearElastic(1e8)
    line = jc.LineType(mass_per_length=20.0, diameter=0.05, tension_law=law, normal_drag=1.2)
    motion = jc.Harmonic(amplitude=4.0, period=10.0, direction=(1.0, 0.0, 0.0))
    model = jc.CableNetwork.from_branches(
        junctions=[[0.0, 0.0, -20.0], [80.0, 0.0, -20.0]],
        branches=[jc.Branch(0, 1, line, 100.0, 40)],
        constraints={0: jc.Fixed(), 1: motion},
        mass_matrix="lumped",
    )
    env = jc.Environment()
    return model, env, advise(model, env, tolerance=0.01)


def test_catenary_curvature_gives_the_segment_count(hanging):
    model, env, result = hanging
    (d,) = result.discretisation
    # The curvature of a catenary is largest at its lowest point, 1/a.
    a = catenary_parameter(80.0, 100.0)
    np.testing.assert_allclose(d.curvature, 1 / a, rtol=0.01)  # O((l/a)²), l = 2.5 m, a ≈ 25 m
    assert d.node == int(np.asarray(model.free_nodes)[19])  # the middle node of 41
    np.testing.assert_allclose(d.deviation, np.sqrt(2) / 8 * 2.5**2 * d.curvature, rtol=1e-12)
    assert d.tolerance == pytest.approx(1.0) and d.needed == segments_needed(100.0, d.curvature, 1.0)
    assert d.needed < 40 < segments_needed(100.0, d.curvature, 0.01)
    assert advise(model, env, absolute_tolerance=0.01).discretisation[0].needed > 40


def test_catenary_quasi_static_tension_at_the_extremes_of_the_motion(hanging):
    model, env, result = hanging
    w = (20.0 - 1025.0 * np.pi * 0.05**2 / 4) * 9.81
    # Each extreme is a catenary of span 80 ± 4 m: its smallest tension, at the lowest
    # point, is H = w a; the segment there is within (l/2a)²/2 of it.
    for check, span in zip(result.slack, (84.0, 76.0)):
        assert check.converged and not check.slack
        np.testing.assert_allclose(check.displacement, [span - 80.0, 0.0, 0.0], atol=1e-12)
        np.testing.assert_allclose(check.min_tension, w * catenary_parameter(span, 100.0), rtol=2e-3)
    assert result.slack_expected is False
    # The support's top speed A ω against the line's terminal sideways speed.
    terminal = np.sqrt(2 * w / (1025.0 * 1.2 * 0.05))
    np.testing.assert_allclose(
        [result.slack[0].speed, result.slack[0].terminal_speed], [4.0 * 2 * np.pi / 10.0, terminal], rtol=1e-12
    )
    assert 4.0 * 2 * np.pi / 10.0 > terminal and result.snap_possible is True  # 2.51 against 2.40 m/s


def taut_weightless_line(amplitude: float):
    """A neutrally buoyant line 100 m long between supports 101 m apart: straight, at
    1 % strain; its far end moves by `amplitude` along the line."""
    area = 3e-4
    line = jc.LineType(mass_per_length=1025.0 * area, diameter=0.02, tension_law=jc.LinearElastic(4e6), area=area)
    model = jc.CableNetwork.from_branches(
        junctions=[[0.0, 0.0, -30.0], [101.0, 0.0, -30.0]],
        branches=[jc.Branch(0, 1, line, 100.0, 10)],
        constraints={0: jc.Fixed(), 1: jc.Harmonic(amplitude=amplitude, period=8.0)},
        mass_matrix="lumped",
    )
    return model, jc.Environment()


def test_slack_when_the_support_moves_past_the_stretch():
    # Towards the anchor by 2 m, more than the 1 m stretch: nothing holds the line taut.
    result = advise(*taut_weightless_line(2.0))
    towards = [c for c in result.slack if c.displacement[0] < 0]
    assert len(towards) == 1 and towards[0].slack and result.slack_expected is True
    assert any("slack expected" in line for line in advice_lines(result))


def test_no_slack_when_the_support_moves_less_than_the_stretch():
    # 0.5 m either way: strain 0.5 % and 1.5 %, tension EA ε exactly (no weight).
    result = advise(*taut_weightless_line(0.5))
    assert result.slack_expected is False
    np.testing.assert_allclose([c.min_tension for c in result.slack], [4e6 * 0.015, 4e6 * 0.005], rtol=1e-8)
    np.testing.assert_allclose([result.rest_min_tension, result.rest_max_tension], 4e6 * 0.01, rtol=1e-8)
    assert np.isnan(result.slack[0].terminal_speed) and result.snap_possible is None


# --------------------------------------------------------------------------------------
# The seabed's contact modes.


def test_seabed_mode_by_hand():
    m, d, area, ca, cat = 50.0, 0.09, 6.4e-3, 1.0, 0.5
    line = jc.LineType(
        mass_per_length=m,
        diameter=d,
        tension_law=jc.LinearElastic(2e8),
        area=area,
        normal_added_mass=ca,
        tangential_added_mass=cat,
    )
    model = jc.CableNetwork.from_branches(
        [[0.0, 0.0, -60.0], [100.0, 0.0, -60.0]],
        [jc.Branch(0, 1, line, 99.0, 10)],
        {0: jc.Fixed(), 1: jc.Fixed()},
        mass_matrix="lumped",
    )
    rho, g = 1025.0, 9.81
    normal, along = m + rho * area * ca, m + rho * area * cat
    # Overdamped contact: |λ| = (c' + √(c'² − 4k'))/2.
    env = jc.Environment(depth=60.0, seabed=jc.Seabed(3e6, 3e5))
    c, k = 3e5 * d / normal, 3e6 * d / normal
    rate, kind = seabed_mode(model, env)
    np.testing.assert_allclose(rate, (c + np.sqrt(c**2 - 4 * k)) / 2, rtol=1e-12)
    assert kind == "damping"
    # Friction with a small friction speed: μ w / (v_s M).
    env = jc.Environment(depth=60.0, seabed=jc.Seabed(3e6, 3e5, friction=0.8, friction_speed=0.005))
    rate, kind = seabed_mode(model, env)
    np.testing.assert_allclose(rate, 0.8 * (m - rho * area) * g / (0.005 * along), rtol=1e-12)
    assert kind == "friction"
    # MoorDyn's friction, μ c_f per node of length l = 9.9 m: μ c_f / (M l).
    env = jc.Environment(depth=60.0, seabed=jc.Seabed(3e6, 3e5, friction=0.8, friction_damping=5e6))
    rate, kind = seabed_mode(model, env)
    np.testing.assert_allclose(rate, 0.8 * 5e6 / (along * 9.9), rtol=1e-12)
    assert kind == "friction"
    # Underdamped: √k'.
    env = jc.Environment(depth=60.0, seabed=jc.Seabed(3e6, 1e3))
    np.testing.assert_allclose(seabed_mode(model, env)[0], np.sqrt(k), rtol=1e-12)
    assert seabed_mode(model, jc.Environment()) == (0.0, "")
