"""Complete elliptic integrals and Jacobi elliptic functions against independent values.

References:

- SciPy's `ellipk`, `ellipkm1`, `ellipe` and `ellipj` (Cephes), where they are accurate:
  `ellipj` switches, for 1 − m < 1e-9, to an approximation valid only for small u, and
  its dn = √(1 − m sn²) loses digits where dn is small, so it is compared only for
  1 − m ≥ 1e-9, and dn only for 1 − m ≥ 1e-3.
- Abramowitz & Stegun 16.15: sn, cn, dn to first order in m₁ = 1 − m, for the
  near-solitary range 1 − m ≤ 1e-12 (the neglected terms are O(m₁² e^{2|u|})).
- Closed forms: cn(K) = 0 and dn(K) = √m₁; K(m) ≈ ln(4/√m₁) + O(m₁ ln m₁) as m → 1;
  dK/dm = (E − m₁K)/(2 m m₁), dE/dm = (E − K)/(2m), d sn/du = cn dn,
  d cn/du = −sn dn, d dn/du = −m sn cn.
"""

import jax
import jax.numpy as jnp
import numpy as np
import pytest
from scipy import special

from jaxcable._sea.elliptic import ellipe, ellipj, ellipk, ellipke


def test_complete_integrals_match_scipy():
    # m over [0, 1) and, with the complement given, m₁ down to 1e-300.
    m = np.linspace(0.0, 0.999, 400)
    np.testing.assert_allclose(ellipk(m), special.ellipk(m), rtol=1e-15)
    np.testing.assert_allclose(ellipe(m), special.ellipe(m), rtol=1e-15)
    m1 = np.geomspace(1e-300, 1e-3, 300)
    k, e = ellipke(1 - m1, m1)
    np.testing.assert_allclose(k, special.ellipkm1(m1), rtol=1e-15)
    # E to SciPy's where 1 − m₁ keeps m₁'s digits; beyond, against A&S 17.3.36,
    # E(1 − m₁) = 1 + (m₁/2)(L − 1/2) + (3m₁²/16)(L − 13/12) + O(m₁³ L), L = ln(4/√m₁).
    # E's relative error grows like K ε (K = 350 at m₁ = 1e-300).
    kept = m1 > 1e-6
    np.testing.assert_allclose(e[kept], special.ellipe(1 - m1[kept]), rtol=2e-15)
    tiny = m1[~kept]
    log = np.log(4 / np.sqrt(tiny))
    series = 1 + tiny / 2 * (log - 0.5) + 3 * tiny**2 / 16 * (log - 13 / 12)
    np.testing.assert_array_less(np.abs(e[~kept] / series - 1), 1e-15 * k[~kept])


def test_integrals_at_the_ends():
    # K = E = π/2 at m = 0; at m₁ = 1e-12, K = ln(4/√m₁) to O(m₁ ln m₁).
    k, e = ellipke(0.0)
    np.testing.assert_allclose([k, e], [np.pi / 2, np.pi / 2], rtol=1e-16)
    np.testing.assert_allclose(ellipk(1 - 1e-12, 1e-12), np.log(4 / np.sqrt(1e-12)), rtol=1e-12)


@pytest.mark.parametrize("m", [0.0, 1e-8, 0.3, 0.9, 1 - 1e-3, 1 - 1e-6, 1 - 1e-9])
def test_jacobi_functions_match_scipy(m):
    # Three quarter-periods either side of 0; m exactly representable, m₁ = 1 − m exact.
    m1 = 1 - m
    quarter = special.ellipk(m)
    u = np.linspace(-3 * quarter, 3 * quarter, 601)
    sn, cn, dn = ellipj(u, m, m1)
    reference = special.ellipj(u, m)
    np.testing.assert_allclose(sn, reference[0], rtol=0, atol=5e-15)
    np.testing.assert_allclose(cn, reference[1], rtol=0, atol=1e-14)
    if m1 >= 1e-3:
        np.testing.assert_allclose(dn, reference[2], rtol=0, atol=1e-14)


@pytest.mark.parametrize("m1", [1e-12, 1e-20, 1e-60])
def test_jacobi_functions_near_the_solitary_limit(m1):
    # A&S 16.15.1–3: sn = tanh u + ¼ m₁ (sinh u cosh u − u) sech² u, and so on.
    u = np.linspace(-5.0, 5.0, 401)
    sn, cn, dn = ellipj(u, 1 - m1, m1)
    sh, ch, th = np.sinh(u), np.cosh(u), np.tanh(u)
    np.testing.assert_allclose(sn, th + m1 / 4 * (sh * ch - u) / ch**2, rtol=0, atol=2e-15)
    np.testing.assert_allclose(cn, 1 / ch - m1 / 4 * (sh * ch - u) * th / ch, rtol=0, atol=2e-15)
    np.testing.assert_allclose(dn, 1 / ch + m1 / 4 * (sh * ch + u) * th / ch, rtol=0, atol=2e-15)


@pytest.mark.parametrize("m1", [0.5, 1e-6, 1e-12, 1e-18])
def test_quarter_period(m1):
    # cn(K) = 0, sn(K) = 1, and dn(K) = √m₁ to its own relative precision.
    k = ellipk(1 - m1, m1)
    sn, cn, dn = ellipj(k, 1 - m1, m1)
    assert abs(float(cn)) < 1e-15 and abs(float(sn) - 1) < 1e-15
    np.testing.assert_allclose(dn, np.sqrt(m1), rtol=1e-12)


def test_derivatives_in_m():
    # Legendre's derivatives, at m = 0 too, where K' = −E' = π/8.
    m = jnp.array([0.0, 0.2, 0.7, 0.99, 1 - 1e-8])
    dk = jax.vmap(jax.grad(lambda m: ellipk(m)))(m)
    de = jax.vmap(jax.grad(lambda m: ellipe(m)))(m)
    k, e, m1 = special.ellipk(m), special.ellipe(m), 1 - np.asarray(m)
    with np.errstate(invalid="ignore", divide="ignore"):
        expected_k = np.where(m > 0, (e - m1 * k) / (2 * m * m1), np.pi / 8)
        expected_e = np.where(m > 0, (e - k) / (2 * m), -np.pi / 8)
    np.testing.assert_allclose(dk, expected_k, rtol=1e-8)
    np.testing.assert_allclose(de, expected_e, rtol=1e-8)


def test_derivatives_in_u_and_m():
    # d/du of (sn, cn, dn) by autodiff against the closed forms; d/dm against central
    # differences (step 1e-6, error O(1e-12)), through jit and vmap.
    m = 0.8
    u = jnp.linspace(-2.0, 2.0, 9)
    jac = jax.jit(jax.vmap(jax.jacfwd(lambda u, m: jnp.stack(ellipj(u, m)), argnums=(0, 1)), (0, None)))
    du, dm = jac(u, m)
    sn, cn, dn = special.ellipj(np.asarray(u), m)[:3]
    np.testing.assert_allclose(du, np.stack([cn * dn, -sn * dn, -m * sn * cn], -1), rtol=0, atol=1e-14)
    step = 1e-6
    central = (
        np.stack(special.ellipj(np.asarray(u), m + step)[:3], -1)
        - np.stack(special.ellipj(np.asarray(u), m - step)[:3], -1)
    ) / (2 * step)
    np.testing.assert_allclose(dm, central, rtol=0, atol=1e-9)
