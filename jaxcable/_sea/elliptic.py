"""Complete elliptic integrals and Jacobi elliptic functions, in JAX.

`jax.scipy.special` (JAX 0.10) has none of these. All three are built on the
arithmetic-geometric mean (AGM) of 1 and √m₁, where m₁ = 1 − m is the complementary
parameter, and run a fixed number of steps, so they trace, `jit`, `vmap` and
differentiate (forward and reverse) like any elementwise function.

The parameter m may be given with its complement m₁: a near-solitary cnoidal wave has
m₁ down to 1e-12 and below, which `1 − m` would round away. The AGM needs only √m₁
and m itself (never √m), so every function is smooth, and differentiable, for
0 ≤ m < 1, including m = 0, and any m₁ > 0 down to the smallest float64. m = 1 itself
(m₁ = 0, where K is infinite) is outside the domain: the fixed number of steps gives
wrong, finite values there.

Notation as in Abramowitz & Stegun, ch. 16–17 (and SciPy): parameter m = k², where k
is the modulus.
"""

import jax
import jax.numpy as jnp
from jaxtyping import Array, ArrayLike, Float

# AGM steps: c_n/a_n falls quadratically once a_n ≈ b_n, and below 1e-17 within 13 steps
# for every m₁ ≥ 5e-324 (the smallest float64), the slowest start being b₀ = √m₁ ≪ 1.
# Steps past convergence leave every result unchanged.
_STEPS = 14


def _parameters(m, m1):
    m = jnp.asarray(m, dtype=float)
    m1 = 1 - m if m1 is None else jnp.asarray(m1, dtype=float)
    return m, m1


def _agm(m, m1):
    """The AGM of a₀ = 1 and b₀ = √m₁: aₙ, bₙ and cₙ (with cₙ² = aₙ² − bₙ²) for
    n = 1 … `_STEPS`, each stacked along a new leading axis.

    cₙ₊₁ = cₙ² / (4 aₙ₊₁), with c₀² = m, equals (aₙ − bₙ)/2 but needs neither the
    subtraction (which loses cₙ₊₁ to cancellation once aₙ ≈ bₙ) nor c₀ = √m (whose
    derivative is infinite at m = 0). A `scan`, not a Python loop, keeps the compiled
    code small (and the public functions are jitted so that eager calls reuse it).
    """

    def step(carry, _):
        a, b, c_squared = carry
        a, b, c = 0.5 * (a + b), jnp.sqrt(a * b), c_squared / (2 * (a + b))
        return (a, b, jnp.square(c)), (a, b, c)

    _, (a, b, c) = jax.lax.scan(step, (jnp.ones_like(m), jnp.sqrt(m1), m), length=_STEPS)
    return a, b, c


@jax.jit
def ellipk(m: Float[ArrayLike, "*#batch"], m1: Float[ArrayLike, "*#batch"] | None = None) -> Float[Array, "*batch"]:
    """The complete elliptic integral of the first kind, K(m) = ∫₀^{π/2} dθ / √(1 − m sin²θ).

    K = π / (2 AGM(1, √m₁)).

    **Arguments:**

    - `m`: the parameter m, 0 ≤ m < 1 (–).
    - `m1`: the complementary parameter m₁ = 1 − m > 0 (–); computed from `m` if not
        given. Give it when m is within rounding of 1.

    **Returns:**

    K (–), the shape of `m` and `m1` broadcast.
    """
    m, m1 = _parameters(m, m1)
    a, _, _ = _agm(m, m1)
    return jnp.pi / (2 * a[-1])


@jax.jit
def ellipke(
    m: Float[ArrayLike, "*#batch"], m1: Float[ArrayLike, "*#batch"] | None = None
) -> tuple[Float[Array, "*batch"], Float[Array, "*batch"]]:
    """The complete elliptic integrals K(m) and E(m) = ∫₀^{π/2} √(1 − m sin²θ) dθ, from
    one AGM.

    E = K (1 − Σₙ 2ⁿ⁻¹ cₙ²), n ≥ 0, c₀² = m (Abramowitz & Stegun 17.6.3–4). As m → 1
    the bracket tends to 1/K and loses digits to cancellation: E's relative error
    grows like K ε, to 5e-15 at 1 − m = 1e-12 (E/K keeps an absolute error of ε).

    **Arguments:** as for `ellipk`.

    **Returns:**

    `(K, E)` (–).
    """
    m, m1 = _parameters(m, m1)
    a, _, c = _agm(m, m1)
    k = jnp.pi / (2 * a[-1])
    total = 0.5 * m + jnp.tensordot(2.0 ** jnp.arange(_STEPS), jnp.square(c), axes=1)
    return k, k * (1 - total)


def ellipe(m: Float[ArrayLike, "*#batch"], m1: Float[ArrayLike, "*#batch"] | None = None) -> Float[Array, "*batch"]:
    """The complete elliptic integral of the second kind, E(m); arguments as for
    `ellipk`."""
    return ellipke(m, m1)[1]


@jax.jit
def ellipj(
    u: Float[ArrayLike, "*#batch"], m: Float[ArrayLike, "*#batch"], m1: Float[ArrayLike, "*#batch"] | None = None
) -> tuple[Float[Array, "*batch"], Float[Array, "*batch"], Float[Array, "*batch"]]:
    """The Jacobi elliptic functions sn(u|m), cn(u|m), dn(u|m).

    The descending Landen transformation (Abramowitz & Stegun 16.4): φ_N = 2^N a_N u,
    then `φₙ₋₁ = (φₙ + arcsin((cₙ/aₙ) sin φₙ)) / 2` down to the amplitude φ₀ = am(u|m),
    and sn = sin φ₀, cn = cos φ₀, dn = √(m₁ + m cn²). The rounding error of φ_N halves
    at each step down, so φ₀ is accurate to a few ulp of u; dn is written with m₁ so
    that it keeps its relative accuracy where it is small (dn(K) = √m₁, as m → 1)
    rather than losing it in 1 − m sn², as long as m₁ ≫ ε², cn's absolute error.

    **Arguments:**

    - `u`: the argument (–); best kept within a few periods of 0, as its rounding
        error is the floor on the results' error (sn and cn have period 4K, dn 2K).
    - `m`, `m1`: as for `ellipk`.

    **Returns:**

    `(sn, cn, dn)` (–), the shape of the arguments broadcast.
    """
    m, m1 = _parameters(m, m1)
    u = jnp.asarray(u, dtype=float)
    a, b, c = _agm(m, m1)
    phi = 2.0**_STEPS * a[-1] * u

    def step(phi, abc):
        an, bn, cn = abc
        # arcsin((cₙ/aₙ) sin φₙ), written as an arctan with the cosine from bₙ (as
        # aₙ² − cₙ² = bₙ²): as m → 1, c₁/a₁ → 1 and arcsin's slope at ±1 would
        # magnify the argument's rounding error.
        sin, cos = jnp.sin(phi), jnp.cos(phi)
        return 0.5 * (phi + jnp.arctan2(cn * sin, jnp.sqrt(jnp.square(an * cos) + jnp.square(bn * sin)))), None

    phi, _ = jax.lax.scan(step, phi, (a, b, c), reverse=True)
    sn, cn = jnp.sin(phi), jnp.cos(phi)
    return sn, cn, jnp.sqrt(m1 + m * jnp.square(cn))
