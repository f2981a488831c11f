"""Tension laws and drag loads against closed forms and independent quadrature.

References used here, none of them jaxcable's own output:

- the tension laws' formulas, `T = (C_E ε + C_E1 ε² + C_v ε̇) H(ε)` with the smoothstep
  `H = 3s² − 2s³`, `s = ε / w`, written out in numpy;
- the elastic energy's closed form: above the band `C_E ε²/2 + C_E1 ε³/3` (sharp switch),
  and with the band `C_E w² · 7/20 + C_E1 w³ · 4/15` for the band itself (∫₀¹ s(3s² − 2s³) ds
  = 7/20 and ∫₀¹ s²(3s² − 2s³) ds = 4/15), cross-checked by `scipy.integrate.quad`;
- the drag's normal/tangential split done by hand, and its virtual work on a segment,
  `Q_a = ∫₀¹ f(ξ) N_a(ξ) S dξ`, by adaptive `scipy.integrate.quad`.
"""

import jax
import jax.numpy as jnp
import numpy as np
import pytest
from scipy import integrate

import jaxcable as jc
from jaxcable._equations import hydro as _hydro
from jaxcable._equations import lagrangian as _lagrangian

C_E = 3.0e7  # N
C_E1 = 4.5e6  # N
C_V = 6.0e5  # N·s
WIDTH = 1e-3  # a wide band, so that many strains fall inside it

# Strains that cover every regime: compression, exactly 0, inside the band, at its edge,
# above it.
STRAINS = np.array(
    [-0.3, -1e-3, -1e-12, 0.0, 1e-9, 1e-5, 2.5e-4, 5e-4, 7.5e-4, 9.99e-4, 1e-3, 1.0001e-3, 2e-3, 0.05, 0.4]
)
RATES = np.linspace(-2.0, 3.0, STRAINS.size)  # ε̇ (1/s), both signs


def smoothstep(strain, width):
    """The reference switch, written independently: 0 / 3s² − 2s³ / 1."""
    strain = np.asarray(strain, dtype=float)
    if width == 0:
        return (strain > 0).astype(float)
    s = np.clip(strain / width, 0.0, 1.0)
    return 3 * s**2 - 2 * s**3


def reference_tension(strain, rate, c_e, c_e1, c_v, width):
    return (c_e * strain + c_e1 * strain**2 + c_v * rate) * smoothstep(strain, width)


def laws(width):
    """Each law with the coefficients it carries (the others are zero)."""
    return [
        (jc.LinearElastic(C_E, width), C_E, 0.0, 0.0),
        (jc.NonlinearElastic(C_E, C_E1, width), C_E, C_E1, 0.0),
        (jc.KelvinVoigt(C_E, C_E1, C_V, width), C_E, C_E1, C_V),
    ]


LAW_CASES = [
    pytest.param(width, index, id=f"{name}-{'sharp' if width == 0 else 'smooth'}")
    for width in (0.0, WIDTH)
    for index, name in enumerate(("linear", "nonlinear", "kelvin_voigt"))
]


# --------------------------------------------------------------------------------------
# The slack switch.


def test_slack_switch_is_smoothstep_inside_band():
    strain = np.linspace(-0.5 * WIDTH, 1.5 * WIDTH, 401)
    s = np.clip(strain / WIDTH, 0, 1)
    expected = np.where(strain <= 0, 0.0, np.where(strain >= WIDTH, 1.0, 3 * s**2 - 2 * s**3))
    np.testing.assert_allclose(np.asarray(jc.equations.slack_switch(strain, WIDTH)), expected, rtol=1e-14, atol=0)
    # Exactly 0 at and below zero strain, exactly 1 from the band's top edge upward.
    assert np.all(np.asarray(jc.equations.slack_switch(strain[strain <= 0], WIDTH)) == 0.0)
    assert np.all(np.asarray(jc.equations.slack_switch(strain[strain >= WIDTH], WIDTH)) == 1.0)


def test_slack_switch_sharp_is_heaviside():
    strain = np.array([-1.0, -1e-300, 0.0, 1e-300, 1e-12, 1.0])
    np.testing.assert_array_equal(np.asarray(jc.equations.slack_switch(strain, 0.0)), [0, 0, 0, 1, 1, 1])


def test_slack_switch_per_segment_width():
    strain = np.array([5e-4, 5e-4, 5e-4, -1.0])
    width = np.array([0.0, 1e-3, 2e-3, 1e-3])
    expected = [1.0, 0.5, 3 * 0.25**2 - 2 * 0.25**3, 0.0]
    np.testing.assert_allclose(np.asarray(jc.equations.slack_switch(strain, width)), expected, rtol=1e-14)


@pytest.mark.parametrize("width", [0.0, WIDTH])
def test_slack_switch_derivative(width):
    """d H/dε = 6 s (1 − s) / w inside the band, 0 outside, finite (no NaN) everywhere,
    including the sharp switch at ε = 0 where the code divides by a masked width."""
    grad = jax.vmap(jax.grad(jc.equations.slack_switch), in_axes=(0, None))(jnp.asarray(STRAINS), width)
    if width == 0:
        expected = np.zeros_like(STRAINS)
    else:
        s = STRAINS / width
        expected = np.where((s > 0) & (s < 1), 6 * s * (1 - s) / width, 0.0)
    assert np.all(np.isfinite(np.asarray(grad)))
    np.testing.assert_allclose(np.asarray(grad), expected, rtol=1e-12, atol=1e-12 / WIDTH)


# --------------------------------------------------------------------------------------
# Tension.


@pytest.mark.parametrize("width, index", LAW_CASES)
def test_tension_matches_formula(width, index):
    law, c_e, c_e1, c_v = laws(width)[index]
    got = np.asarray(law.tension(jnp.asarray(STRAINS), jnp.asarray(RATES)))
    expected = reference_tension(STRAINS, RATES, c_e, c_e1, c_v, width)
    np.testing.assert_allclose(got, expected, rtol=1e-13, atol=1e-20)
    # Tension-only: exactly zero (not just small) at and below zero strain, whatever ε̇.
    assert np.all(got[STRAINS <= 0] == 0.0)
    # Exact law once ε ≥ w (the band sits on the taut side).
    above = STRAINS >= max(width, 1e-300)
    np.testing.assert_allclose(
        got[above], c_e * STRAINS[above] + c_e1 * STRAINS[above] ** 2 + c_v * RATES[above], rtol=1e-14
    )
    # The elastic part alone.
    np.testing.assert_allclose(
        np.asarray(law.elastic_tension(jnp.asarray(STRAINS))),
        reference_tension(STRAINS, 0.0, c_e, c_e1, 0.0, width),
        rtol=1e-13,
        atol=1e-20,
    )


def test_tension_per_segment_coefficients():
    """Per-segment parameter arrays apply element by element."""
    c_e = np.array([1e5, 2e6, 3e7])
    c_e1 = np.array([0.0, 1e5, 6e6])
    c_v = np.array([1e3, 0.0, 5e4])
    width = np.array([0.0, 1e-4, 1e-2])
    strain = np.array([0.02, 5e-5, 5e-3])
    rate = np.array([-0.1, 0.2, 0.3])
    law = jc.KelvinVoigt(c_e, c_e1, c_v, width)
    expected = [reference_tension(strain[k], rate[k], c_e[k], c_e1[k], c_v[k], width[k]) for k in range(3)]
    np.testing.assert_allclose(np.asarray(law.tension(strain, rate)), expected, rtol=1e-13)


# --------------------------------------------------------------------------------------
# Elastic energy.


def band_energy(c_e, c_e1, width):
    """∫₀^w (C_E e + C_E1 e²)(3s² − 2s³) de, s = e / w, in closed form."""
    return c_e * width**2 * 7 / 20 + c_e1 * width**3 * 4 / 15


def reference_energy(strain, c_e, c_e1, width):
    """The elastic energy density `∫₀^ε T_e(e) de`, by closed form above the band and by
    adaptive quadrature of the reference tension inside it."""
    if strain <= 0:
        return 0.0
    if strain <= width:
        value, _ = integrate.quad(
            lambda e: reference_tension(e, 0.0, c_e, c_e1, 0.0, width), 0.0, strain, epsabs=0, epsrel=1e-13
        )
        return value

    def antiderivative(e):
        return c_e * e**2 / 2 + c_e1 * e**3 / 3

    return band_energy(c_e, c_e1, width) + antiderivative(strain) - antiderivative(width)


def test_band_energy_closed_form_agrees_with_quad():
    """The test's own closed form for the band, checked by quad (a check on the test)."""
    value, _ = integrate.quad(
        lambda e: reference_tension(e, 0.0, C_E, C_E1, 0.0, WIDTH), 0.0, WIDTH, epsabs=0, epsrel=1e-13
    )
    np.testing.assert_allclose(band_energy(C_E, C_E1, WIDTH), value, rtol=1e-13)


@pytest.mark.parametrize("width, index", LAW_CASES)
def test_energy_matches_integral_of_tension(width, index):
    law, c_e, c_e1, _ = laws(width)[index]
    got = np.asarray(law.elastic_energy_density(jnp.asarray(STRAINS)))
    expected = np.array([reference_energy(e, c_e, c_e1, width) for e in STRAINS])
    np.testing.assert_allclose(got, expected, rtol=1e-12, atol=1e-30)
    assert np.all(got[STRAINS <= 0] == 0.0)
    if width == 0:  # the sharp law: exactly the textbook strain energy
        pos = STRAINS > 0
        e = STRAINS[pos]
        np.testing.assert_allclose(got[pos], c_e * e**2 / 2 + c_e1 * e**3 / 3, rtol=1e-13)


@pytest.mark.parametrize("width, index", LAW_CASES)
def test_energy_derivative_is_elastic_tension(width, index):
    """∂Π_e/∂ε = T_e(ε) exactly (the law is the energy's derivative, not 3/2 C_E1 as in
    the anchored-line paper's misprint), checked against the reference formula, not the code's tension."""
    law, c_e, c_e1, _ = laws(width)[index]
    strains = np.concatenate([STRAINS, np.linspace(0, 3 * max(width, 1e-3), 301)])
    # ε = w exactly is a separate (failing) case: test_energy_derivative_at_band_edge.
    strains = strains[(strains != width) | (width == 0)]
    grad = np.asarray(jax.vmap(jax.grad(law.elastic_energy_density))(jnp.asarray(strains)))
    expected = reference_tension(strains, 0.0, c_e, c_e1, 0.0, width)
    assert np.all(np.isfinite(grad))
    np.testing.assert_allclose(grad, expected, rtol=1e-12, atol=1e-12 * c_e * 1e-3)


@pytest.mark.parametrize("index", [0, 1, 2], ids=["linear", "nonlinear", "kelvin_voigt"])
def test_energy_derivative_at_band_edge(index):
    """∂Π_e/∂ε at the band's top edge, ε = w exactly, must be T_e(w) = C_E w + C_E1 w²."""
    law, c_e, c_e1, _ = laws(WIDTH)[index]
    grad = float(jax.grad(law.elastic_energy_density)(WIDTH))
    assert grad == pytest.approx(c_e * WIDTH + c_e1 * WIDTH**2, rel=1e-12)


def test_energy_derivative_is_not_the_papers_misprint():
    """A law whose energy carried `C_E1 ε³/2` (the anchored-line paper's energy) would give 3/2 C_E1 ε²
    here; this pins the documented choice."""
    law = jc.NonlinearElastic(C_E, C_E1, 0.0)
    e = 0.1
    grad = float(jax.grad(law.elastic_energy_density)(e))
    assert grad == pytest.approx(C_E * e + C_E1 * e**2, rel=1e-14)
    assert abs(grad - (C_E * e + 1.5 * C_E1 * e**2)) > 1e3


# --------------------------------------------------------------------------------------
# Drag.

RHO = 1025.0
DIAMETER = 0.03
K_N, K_T = 1.2, 0.01
C_N = 0.5 * RHO * K_N * DIAMETER  # kg/m²
C_T = 0.5 * RHO * K_T * np.pi * DIAMETER  # kg/m²


def reference_line_drag(u, tangent, c_n, c_t):
    """Hand-written decomposition: u_τ = (u·τ)τ, u_n = u − u_τ."""
    tangent = np.asarray(tangent, float) / np.linalg.norm(tangent)
    u_t = np.dot(u, tangent) * tangent
    u_n = u - u_t
    return c_n * np.linalg.norm(u_n) * u_n + c_t * np.linalg.norm(u_t) * u_t


def test_line_drag_simple_decomposition():
    """τ = x̂, u = (3, 4, 0): u_τ = (3, 0, 0), u_n = (0, 4, 0), so f = (9 C_τ, 16 C_n, 0)."""
    f = _hydro.line_drag(jnp.array([3.0, 4.0, 0.0]), jnp.array([1.0, 0.0, 0.0]), jnp.array(C_N), jnp.array(C_T))
    np.testing.assert_allclose(np.asarray(f), [9 * C_T, 16 * C_N, 0.0], rtol=1e-14, atol=1e-20)


def test_line_drag_random_batch():
    rng = np.random.default_rng(0)
    u = rng.normal(size=(50, 3))
    tangent = rng.normal(size=(50, 3))
    tangent /= np.linalg.norm(tangent, axis=1, keepdims=True)
    c_n = rng.uniform(1, 20, size=50)
    c_t = rng.uniform(0.1, 2, size=50)
    # `_hydro` works component-major: vectors as shape (3, ...).
    got = np.asarray(_hydro.line_drag(u.T, tangent.T, c_n, c_t)).T
    expected = np.stack([reference_line_drag(u[k], tangent[k], c_n[k], c_t[k]) for k in range(50)])
    np.testing.assert_allclose(got, expected, rtol=1e-12, atol=1e-14)
    # Purely normal and purely tangential flows.
    three, five = jnp.array(3.0), jnp.array(5.0)
    normal_only = np.asarray(_hydro.line_drag(jnp.array([0.0, 2.0, 0.0]), jnp.array([1.0, 0, 0]), three, five))
    tangential_only = np.asarray(_hydro.line_drag(jnp.array([-2.0, 0.0, 0.0]), jnp.array([1.0, 0, 0]), three, five))
    np.testing.assert_allclose(normal_only, [0.0, 12.0, 0.0], atol=1e-20)
    np.testing.assert_allclose(tangential_only, [-20.0, 0.0, 0.0], atol=1e-20)


def test_drag_gradient_finite_at_zero_velocity():
    """|u| u has a zero derivative at u = 0; the safe norm must not give NaN there."""
    g = jax.jacfwd(_hydro.line_drag)(jnp.zeros(3), jnp.array([0.0, 0.0, 1.0]), jnp.array(C_N), jnp.array(C_T))
    np.testing.assert_allclose(np.asarray(g), 0.0, atol=1e-9)
    g = jax.grad(lambda u: _hydro.body_drag(u, jnp.array(2.0))[0])(jnp.zeros(3))
    np.testing.assert_allclose(np.asarray(g), 0.0, atol=1e-9)


def test_gauss_legendre_on_unit_interval():
    for points in (1, 3, 7):
        xi, w = _hydro.gauss_legendre(points)
        assert np.all((xi > 0) & (xi < 1))
        for k in range(2 * points):  # exact up to degree 2n − 1
            assert np.dot(w, xi**k) == pytest.approx(1 / (k + 1), rel=1e-13)


def one_segment(drag_points=3, law=None, body=None, normal_drag=K_N, tangential_drag=K_T, length=10.0):
    line = jc.LineType(
        mass_per_length=2.0,
        diameter=DIAMETER,
        tension_law=law if law is not None else jc.LinearElastic(1e6),
        normal_drag=normal_drag,
        tangential_drag=tangential_drag,
    )
    return jc.CableNetwork(
        node_positions=[[0.0, 0.0, 0.0], [length, 0.0, 0.0]],
        segment_nodes=[[0, 1]],
        segment_length=[length],
        line=line,
        constraints={0: jc.Fixed()},
        bodies=None if body is None else {1: body},
        drag_points=drag_points,
    )


CURRENT = np.array([0.8, -0.3, 0.2])
# A stretched, skewed segment, S = |x1 − x0| ≈ 10.34 m against L = 10 m.
POSITIONS = np.array([[0.5, -1.0, -20.0], [8.0, 2.0, -14.0]])


def reference_segment_forces(positions, velocities, current):
    """Q_a = ∫₀¹ f(ξ) N_a(ξ) S dξ with N = (1 − ξ, ξ), by adaptive quad, per component."""
    chord = positions[1] - positions[0]
    stretched = np.linalg.norm(chord)
    tangent = chord / stretched

    def f(xi):
        u = current - (velocities[0] * (1 - xi) + velocities[1] * xi)
        return reference_line_drag(u, tangent, C_N, C_T)

    # Where u·τ or a component of u_n changes sign the integrand has a kink in its second
    # derivative: tell quad.
    du = velocities[1] - velocities[0]
    u0 = current - velocities[0]
    breaks = []
    if abs(np.dot(du, tangent)) > 0:
        breaks.append(np.dot(u0, tangent) / np.dot(du, tangent))
    breaks = [b for b in breaks if 0 < b < 1]

    out = np.zeros((2, 3))
    for a, shape in enumerate((lambda xi: 1 - xi, lambda xi: xi)):
        for k in range(3):
            out[a, k], _ = integrate.quad(
                lambda xi: f(xi)[k] * shape(xi) * stretched,  # noqa: B023 (called within this iteration)
                0.0,
                1.0,
                points=breaks or None,
                epsabs=1e-13,
                epsrel=1e-13,
                limit=500,
            )
    return out


# Node velocities: a smooth field (u·τ and u_n never vanish along the segment), and one
# where the tangential relative velocity changes sign mid-segment and the normal part
# nearly vanishes, so |u|u is only C¹ there.
SMOOTH_VELOCITIES = np.array([[0.1, 0.2, -0.4], [-0.5, 0.9, 0.6]])
KINKED_VELOCITIES = np.array([[-0.6, 0.1, 0.0], [2.4, -0.5, 1.5]])


def relative_error(got, expected):
    return np.max(np.abs(got - expected)) / np.max(np.abs(expected))


@pytest.fixture(scope="module")
def drag_errors():
    """Relative error of the nodal drag forces against quad, by drag_points and field."""
    env = jc.Environment(water_density=RHO, current=CURRENT)
    errors = {}
    for name, velocities in (("smooth", SMOOTH_VELOCITIES), ("kinked", KINKED_VELOCITIES)):
        expected = reference_segment_forces(POSITIONS, velocities, CURRENT)
        for points in (3, 8, 64):
            model = one_segment(drag_points=points)
            got = np.asarray(_lagrangian.nonconservative_forces(model, env, 0.0, POSITIONS, velocities))
            errors[name, points] = relative_error(got, expected)
    return errors


def test_kinked_field_really_changes_sign():
    """Guard on the test itself: the 'kinked' field has u·τ changing sign on (0, 1)."""
    tangent = (POSITIONS[1] - POSITIONS[0]) / np.linalg.norm(POSITIONS[1] - POSITIONS[0])
    u_t = [np.dot(CURRENT - v, tangent) for v in KINKED_VELOCITIES]
    assert u_t[0] * u_t[1] < 0
    u_t = [np.dot(CURRENT - v, tangent) for v in SMOOTH_VELOCITIES]
    assert u_t[0] * u_t[1] > 0


def test_segment_drag_virtual_work_converges(drag_errors):
    """With enough Gauss points the drag's generalised forces are the exact virtual work.

    Measured (max nodal-force error / max nodal force): smooth field, 3 points 7e-5,
    8 points 2e-11, 16 or more ~1e-15; kinked field, 3 points 2.0e-2, 8 points 1.5e-4,
    64 points 1.8e-7, 128 points 3e-8 (the integrand is only C¹ where u·τ changes sign,
    so Gauss–Legendre converges algebraically, about as n^-3, there).
    """
    assert drag_errors["smooth", 8] < 1e-6
    assert drag_errors["smooth", 64] < 1e-12
    assert drag_errors["kinked", 64] < 1e-6


def test_segment_drag_default_points_error(drag_errors):
    """jaxcable's default (3 points) error, quantified: at most a few per cent on a segment
    whose relative flow reverses along it, far less on a smooth one."""
    assert drag_errors["smooth", 3] < 1e-3
    assert drag_errors["kinked", 3] < 5e-2
    # Not exact: if these were ~0 the reference and the code would share a mistake.
    assert drag_errors["smooth", 3] > 1e-9
    assert drag_errors["kinked", 3] > drag_errors["kinked", 64]


def test_segment_drag_total_force_and_moment_form():
    """Σ_a Q_a = ∫ f dl: the nodal forces carry the whole line load (64 points)."""
    env = jc.Environment(water_density=RHO, current=CURRENT)
    model = one_segment(drag_points=64)
    got = np.asarray(_lagrangian.nonconservative_forces(model, env, 0.0, POSITIONS, SMOOTH_VELOCITIES))
    stretched = np.linalg.norm(POSITIONS[1] - POSITIONS[0])
    tangent = (POSITIONS[1] - POSITIONS[0]) / stretched
    total = np.array(
        [
            integrate.quad(
                lambda xi: (
                    reference_line_drag(
                        CURRENT - SMOOTH_VELOCITIES[0] * (1 - xi) - SMOOTH_VELOCITIES[1] * xi, tangent, C_N, C_T
                    )[k]  # noqa: B023 (called within this iteration)
                    * stretched
                ),
                0,
                1,
                epsabs=0,
                epsrel=1e-13,
            )[0]
            for k in range(3)
        ]
    )
    np.testing.assert_allclose(got.sum(axis=0), total, rtol=1e-12)


def test_uniform_flow_on_still_segment():
    """A still segment in a uniform current: f is constant, so Q_a = f S / 2 at each end,
    with f from the hand decomposition. Exact for any number of Gauss points."""
    env = jc.Environment(water_density=RHO, current=CURRENT)
    stretched = np.linalg.norm(POSITIONS[1] - POSITIONS[0])
    tangent = (POSITIONS[1] - POSITIONS[0]) / stretched
    f = reference_line_drag(CURRENT, tangent, C_N, C_T)
    for points in (1, 3):
        got = np.asarray(_lagrangian.nonconservative_forces(one_segment(points), env, 0.0, POSITIONS, np.zeros((2, 3))))
        np.testing.assert_allclose(got, [f * stretched / 2, f * stretched / 2], rtol=1e-13)


def test_body_drag_coefficients():
    """Body drag (½ ρ C_D A + k₀ m_o g)|u|u, Zhukov's R = k₀ u² m g for the second term."""
    mass, cda, k0, organism = 40.0, 0.3, 0.05, 25.0
    gravity = 9.81
    env = jc.Environment(water_density=RHO, gravity=gravity, current=CURRENT)
    velocities = np.array([[0.0, 0.0, 0.0], [0.4, -1.1, 0.25]])
    u = CURRENT - velocities[1]
    for body, m_o in (
        (jc.Body(mass=mass, drag_area=cda, specific_drag=k0), mass),
        (jc.Body(mass=mass, drag_area=cda, specific_drag=k0, organism_mass=organism), organism),
    ):
        model = one_segment(body=body, normal_drag=0.0, tangential_drag=0.0)
        got = np.asarray(_lagrangian.nonconservative_forces(model, env, 0.0, POSITIONS, velocities))
        coefficient = 0.5 * RHO * cda + k0 * m_o * gravity
        np.testing.assert_allclose(got[1], coefficient * np.linalg.norm(u) * u, rtol=1e-13)
        np.testing.assert_allclose(got[0], 0.0, atol=1e-20)
    # Zhukov's law alone, magnitude R = k₀ u² m g.
    model = one_segment(body=jc.Body(mass=mass, specific_drag=k0), normal_drag=0.0, tangential_drag=0.0)
    got = np.asarray(_lagrangian.nonconservative_forces(model, env, 0.0, POSITIONS, velocities))
    assert np.linalg.norm(got[1]) == pytest.approx(k0 * np.dot(u, u) * mass * gravity, rel=1e-13)


@pytest.mark.parametrize("strain_target", [0.01, 2e-4, -0.01])
def test_viscous_pull_on_nodes(strain_target):
    """Kelvin–Voigt damping enters as ±C_v ε̇ H(ε) τ on the two ends, ε̇ = τ·(v₁ − v₀)/L;
    nothing in compression."""
    length, width = 10.0, 1e-3
    law = jc.KelvinVoigt(C_E, C_E1, C_V, width)
    model = one_segment(law=law, normal_drag=0.0, tangential_drag=0.0, length=length)
    direction = np.array([2.0, -1.0, 2.0]) / 3.0
    positions = np.array([[1.0, 2.0, -3.0], [1.0, 2.0, -3.0]])
    positions[1] += direction * length * (1 + strain_target)
    velocities = np.array([[0.3, -0.2, 0.1], [0.9, 0.4, -0.7]])
    env = jc.Environment(water_density=RHO)
    got = np.asarray(_lagrangian.nonconservative_forces(model, env, 0.0, positions, velocities))
    rate = np.dot(direction, velocities[1] - velocities[0]) / length
    pull = C_V * rate * smoothstep(strain_target, width) * direction
    np.testing.assert_allclose(got, [pull, -pull], rtol=1e-10, atol=1e-9)
    if strain_target < 0:
        assert np.all(got == 0.0)


@pytest.mark.parametrize("strain_target", [0.01, 2e-4, -0.01])
def test_slack_damping_pulls_in_compression_too(strain_target):
    """With `slack_damping` (MoorDyn's `BA`), the damping is ±C_v ε̇ τ whatever the
    strain: a compressed segment resists its strain rate though it carries no elastic
    tension. The elastic part keeps its switch."""
    length, width = 10.0, 1e-3
    law = jc.KelvinVoigt(C_E, C_E1, C_V, width, slack_damping=True)
    np.testing.assert_allclose(
        np.asarray(law.tension(jnp.asarray(STRAINS), jnp.asarray(RATES))),
        reference_tension(STRAINS, 0.0, C_E, C_E1, 0.0, width) + C_V * RATES,
        rtol=1e-13,
        atol=1e-20,
    )
    model = one_segment(law=law, normal_drag=0.0, tangential_drag=0.0, length=length)
    direction = np.array([2.0, -1.0, 2.0]) / 3.0
    positions = np.array([[1.0, 2.0, -3.0], [1.0, 2.0, -3.0]])
    positions[1] += direction * length * (1 + strain_target)
    velocities = np.array([[0.3, -0.2, 0.1], [0.9, 0.4, -0.7]])
    got = np.asarray(
        _lagrangian.nonconservative_forces(model, jc.Environment(water_density=RHO), 0.0, positions, velocities)
    )
    pull = C_V * np.dot(direction, velocities[1] - velocities[0]) / length * direction
    np.testing.assert_allclose(got, [pull, -pull], rtol=1e-10, atol=1e-9)
    assert np.linalg.norm(pull) > 1.0
