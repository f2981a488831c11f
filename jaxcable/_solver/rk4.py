"""The classical fourth-order Runge–Kutta method, MoorDyn's `tScheme RK4`, as a diffrax
solver (diffrax has none)."""

from typing import ClassVar

import diffrax
import numpy as np

from .explicit import explicit_step

_TABLEAU = diffrax.ButcherTableau(
    c=np.array([0.5, 0.5, 1.0]),
    b_sol=np.array([1 / 6, 1 / 3, 1 / 3, 1 / 6]),
    # The midpoint rule on the same stages (its solution is y₀ + h k₂) is the embedded
    # second-order method: b_sol − (0, 1, 0, 0).
    b_error=np.array([1 / 6, 1 / 3 - 1, 1 / 3, 1 / 6]),
    a_lower=(np.array([0.5]), np.array([0.0, 0.5]), np.array([0.0, 0.0, 1.0])),
)


class RK4(diffrax.AbstractERK):
    """The classical Runge–Kutta method: four stages, fourth order, MoorDyn's `RK4`.

    Meant for fixed steps (`stepsize_controller=diffrax.ConstantStepSize()`) where an
    explicit step is limited by stability: its stability interval on the imaginary
    axis, 2√2 ≈ 2.83 step·frequency, is 1.63 times a three-stage third-order method's
    (√3, `diffrax.Bosh3`), for 4/3 the evaluations a step. On the anchored line a
    256-case sweep at MoorDyn's error, in steps of 8.3 ms, ran in three quarters of the
    time Bosh3 took at its limit, 5.6 ms (`benchmarks/speed.py`). Adaptive steps work too, controlled
    by the difference from the embedded midpoint rule (second order; a conservative
    estimate for a fourth-order step). Dense output is cubic Hermite from the first and
    last stages, as for diffrax's `Heun` and `Midpoint`.
    """

    tableau: ClassVar[diffrax.ButcherTableau] = _TABLEAU
    interpolation_cls: ClassVar = diffrax.ThirdOrderHermitePolynomialInterpolation.from_k

    def order(self, terms) -> int:
        return 4

    def error_order(self, terms) -> int:
        # The error estimate is the local error of the embedded second-order method.
        return 3

    def step(self, terms, t0, t1, y0, args, solver_state, made_jump):
        # The four stages written out (`jaxcable._solver.explicit`), not through diffrax's
        # stage loop: the same step, faster.
        return explicit_step(self, terms, t0, t1, y0, args, solver_state, made_jump)
