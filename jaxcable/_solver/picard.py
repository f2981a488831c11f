"""Zhukov's integrators (Zhukov's growing-element thesis) as diffrax solvers: the trapezoid rule and Simpson's
rule, each solved by a fixed number of Picard iterations. They are the historical
baseline that the speed-against-accuracy studies set the modern methods beside."""

from collections.abc import Callable
from typing import ClassVar

import diffrax
import equinox as eqx
import jax
import jax.numpy as jnp
from diffrax._local_interpolation import ThirdOrderHermitePolynomialInterpolation


class PicardTrapezoid(diffrax.AbstractAdaptiveSolver):
    """The trapezoid rule `y₁ = y₀ + h/2 (f(t₀, y₀) + f(t₁, y₁))`, solved for y₁ by
    `iterations` Picard iterations from an Euler predictor, as Zhukov's growing-element thesis integrates its
    thread: `y_{i+1} = y_i + ∫ f(x, y_i) dx` with the integral by the trapezoid rule.

    One iteration is Heun's method. More iterations approach the implicit trapezoid
    rule, but only while the iteration contracts, `h ‖∂f/∂y‖ / 2 < 1`: its stability,
    unlike the trapezoid rule's, is that of an explicit method, which is what Zhukov's growing-element thesis
    meant by the number of iterations trading against the step size. Second order; the
    difference from the Euler predictor is the error estimate for adaptive steps (as
    for diffrax's `Heun`); dense output is cubic Hermite.

    **Arguments:**

    - `iterations`: Picard iterations per step, at least 1; 3 by default.
    """

    iterations: int = eqx.field(static=True, default=3)

    term_structure: ClassVar = diffrax.AbstractTerm
    interpolation_cls: ClassVar[Callable[..., ThirdOrderHermitePolynomialInterpolation]] = (
        ThirdOrderHermitePolynomialInterpolation.from_k
    )

    def __check_init__(self):
        if not (isinstance(self.iterations, int) and self.iterations >= 1):
            raise ValueError(f"PicardTrapezoid.iterations must be a positive integer, got {self.iterations!r}")

    def order(self, terms):
        return 2

    def init(self, terms, t0, t1, y0, args):
        return None

    def step(self, terms, t0, t1, y0, args, solver_state, made_jump):
        del solver_state, made_jump
        control = terms.contr(t0, t1)
        k0 = terms.vf_prod(t0, y0, args, control)
        predictor = jax.tree.map(jnp.add, y0, k0)
        y1, k1 = predictor, k0
        for _ in range(self.iterations):
            k1 = terms.vf_prod(t1, y1, args, control)
            y1 = jax.tree.map(lambda y, a, b: y + 0.5 * (a + b), y0, k0, k1)
        error = jax.tree.map(jnp.subtract, y1, predictor)
        # k1 is the slope at the last iterate but one: close enough for dense output,
        # and free, where the slope at y1 itself would cost another evaluation.
        dense_info = dict(y0=y0, y1=y1, k=jax.tree.map(lambda a, b: jnp.stack([a, b]), k0, k1))
        return y1, error, dense_info, None, diffrax.RESULTS.successful

    def func(self, terms, t0, y0, args):
        return terms.vf(t0, y0, args)


class PicardSimpson(diffrax.AbstractAdaptiveSolver):
    """Simpson's rule `y₁ = y₀ + h/6 (f₀ + 4 f_m + f₁)` over the step, solved by
    `iterations` Picard iterations from an Euler predictor: Zhukov's other quadrature
    for `y_{i+1} = y_i + ∫ f(x, y_i) dx`.

    Simpson's rule needs the iterate at the step's midpoint too; it is updated by the
    quadrature through the same three nodes, `y_m = y₀ + h/24 (5 f₀ + 8 f_m − f₁)`. The
    fixed point is the three-stage Lobatto IIIA collocation method, fourth order; each
    iteration raises the order by one, so 3 iterations (the default) reach it. An
    iteration costs two evaluations of the vector field, the trapezoid's one. As for
    [`jaxcable.PicardTrapezoid`][], the iteration converges only while
    `h ‖∂f/∂y‖` is small: its stability is an explicit method's. The difference from the
    trapezoid rule through the same end points is the error estimate for adaptive steps;
    dense output is cubic Hermite.

    **Arguments:**

    - `iterations`: Picard iterations per step, at least 1; 3 by default.
    """

    iterations: int = eqx.field(static=True, default=3)

    term_structure: ClassVar = diffrax.AbstractTerm
    interpolation_cls: ClassVar[Callable[..., ThirdOrderHermitePolynomialInterpolation]] = (
        ThirdOrderHermitePolynomialInterpolation.from_k
    )

    def __check_init__(self):
        if not (isinstance(self.iterations, int) and self.iterations >= 1):
            raise ValueError(f"PicardSimpson.iterations must be a positive integer, got {self.iterations!r}")

    def order(self, terms):
        return 4

    def init(self, terms, t0, t1, y0, args):
        return None

    def step(self, terms, t0, t1, y0, args, solver_state, made_jump):
        del solver_state, made_jump
        control = terms.contr(t0, t1)
        tm = t0 + 0.5 * (t1 - t0)
        # k = h f: the vector field times the whole step, at each of the three nodes.
        k0 = terms.vf_prod(t0, y0, args, control)
        ym = jax.tree.map(lambda y, a: y + 0.5 * a, y0, k0)
        y1 = jax.tree.map(jnp.add, y0, k0)
        k1 = k0
        for _ in range(self.iterations):
            km = terms.vf_prod(tm, ym, args, control)
            k1 = terms.vf_prod(t1, y1, args, control)
            ym = jax.tree.map(lambda y, a, b, c: y + (5 * a + 8 * b - c) / 24, y0, k0, km, k1)
            y1 = jax.tree.map(lambda y, a, b, c: y + (a + 4 * b + c) / 6, y0, k0, km, k1)
        trapezoid = jax.tree.map(lambda y, a, b: y + 0.5 * (a + b), y0, k0, k1)
        error = jax.tree.map(jnp.subtract, y1, trapezoid)
        # As in PicardTrapezoid, k1 is the slope at the last iterate but one.
        dense_info = dict(y0=y0, y1=y1, k=jax.tree.map(lambda a, b: jnp.stack([a, b]), k0, k1))
        return y1, error, dense_info, None, diffrax.RESULTS.successful

    def func(self, terms, t0, y0, args):
        return terms.vf(t0, y0, args)
