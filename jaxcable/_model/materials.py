"""Tension laws: how a segment's axial force depends on its strain and strain rate.

Every law here is tension-only. The switch between slack and taut is a Heaviside
function `H(ε)`, either sharp or smoothed over a strain band `[0, w]` by the cubic
smoothstep `3s² − 2s³`, `s = ε / w`. Putting the band on the taut side keeps the laws
strictly tension-only (no force at all in compression) and exact once `ε ≥ w`.

Bezverkhyy & Korniienko write the law as `T = (C_E ε + C_E1 ε²) H(ε)` but differentiate
an energy
whose derivative carries `3/2 C_E1`, which does not match the law. jaxcable defines
the tension directly and takes the elastic energy as its integral,
`Π_e = L ∫₀^ε T(e) de`, so that `∂Π_e/∂ε = L T(ε)` holds exactly.
"""

import abc
from typing import ClassVar

import equinox as eqx
import jax
import jax.numpy as jnp
import numpy as np
from jax.custom_derivatives import SymbolicZero
from jaxtyping import Array, ArrayLike, Float

from .. import _checks as checks
from .._typing import RealLike

CHECKED_STRAIN = 1.0
"""The strain ε (–) up to which a tension law must rise: a segment stretched to twice
its length. Steel wire ropes break at strains of about 0.01–0.02 and fibre ropes below
about 0.3, so a cable reaches no further; a law sound to here is sound wherever a run
can go, and a law that is not fails where a snap load or a mistaken length can take
it (a C_E1 = −10 C_E law peaks at ε = 0.05 and is compressive from ε = 0.1)."""

# Three-point Gauss–Legendre on [0, 1]. The smoothed elastic tension is a polynomial of
# degree 5 inside the smoothing band, which three points integrate exactly.
_GL3_NODES = 0.5 * (1.0 + np.array([-np.sqrt(3.0 / 5.0), 0.0, np.sqrt(3.0 / 5.0)]))
_GL3_WEIGHTS = 0.5 * np.array([5.0 / 9.0, 8.0 / 9.0, 5.0 / 9.0])


def slack_switch(strain: RealLike, width: RealLike) -> Array:
    """The Heaviside factor `H(ε)` that makes a law tension-only.

    **Arguments:**

    - `strain`: ε (–), any shape.
    - `width`: w (–), the smoothing band; broadcasts against `strain`. `0` selects the
        sharp switch `H = 1[ε > 0]`.

    **Returns:**

    `H(ε)` in `[0, 1]`, the shape of `strain` broadcast with `width`.
    """
    strain = jnp.asarray(strain)
    width = jnp.asarray(width)
    smooth = width > 0
    # Double `where` so that the sharp branch never divides by zero, not even in the
    # derivative.
    s = jnp.clip(strain / jnp.where(smooth, width, 1.0), 0.0, 1.0)
    return jnp.where(smooth, s * s * (3.0 - 2.0 * s), (strain > 0).astype(strain.dtype))


class AbstractTensionLaw(eqx.Module):
    """A tension-only constitutive law, `T(ε, ε̇) = (C_E ε + C_E1 ε² + C_v ε̇) H(ε)`.

    Each parameter is a float array with one entry per segment (or a scalar that
    broadcasts), so that a single law instance describes a whole network and any
    parameter can be differentiated or swept.

    Subclasses fix which of the three terms exist. The damping term, when present, does
    no conservative work: it enters through virtual work, not through the energy. It
    can make `T` briefly negative while a taut segment shortens quickly, as in MoorDyn.
    """

    axial_stiffness: eqx.AbstractVar[Float[Array, "*segments"]]
    slack_width: eqx.AbstractVar[Float[Array, "*segments"]]
    # Whether the law has a damping term at all: a class's structure, known when
    # tracing, so that the equations skip the viscous force of a law that has none.
    damped: ClassVar[bool] = True

    @abc.abstractmethod
    def quadratic_stiffness(self) -> Float[Array, "*segments"]:
        """C_E1 (N), the coefficient of ε² in the elastic tension."""

    @abc.abstractmethod
    def damping(self) -> Float[Array, "*segments"]:
        """C_v (N·s), the coefficient of ε̇ in the tension."""

    def rising(self, name: str) -> checks.Condition:
        """The elastic tension rises with strain over `0 ≤ ε ≤ CHECKED_STRAIN`: its slope
        `C_E + 2 C_E1 ε`, linear in ε, is non-negative at both ends. At ε = 0 that is
        C_E ≥ 0, checked on its own; at the far end `C_E1 ≥ −C_E / (2 ε_max)`. A law
        that fell would make a stretched segment soften and then push (a negative
        tension), which a rope cannot. `name` prefixes the message ("LineType.tension_law")."""
        c_e, c_e1 = checks.on_host(self.axial_stiffness), checks.on_host(self.quadratic_stiffness())
        slope = c_e + 2 * c_e1 * CHECKED_STRAIN

        def detail() -> str:
            bad = np.broadcast_to(np.asarray(slope) < 0, np.broadcast_shapes(np.shape(c_e), np.shape(c_e1)))
            index = tuple(np.argwhere(bad)[0])
            stiff = float(np.broadcast_to(np.asarray(c_e), bad.shape)[index])
            quadratic = float(np.broadcast_to(np.asarray(c_e1), bad.shape)[index])
            where = f" at index {', '.join(map(str, index))}" if index else ""
            return (
                f"{name}.quadratic_stiffness C_E1 = {quadratic:g} N with C_E = {stiff:g} N{where} makes the "
                f"tension fall beyond ε = {-stiff / (2 * quadratic):.3g} and turn negative beyond ε = "
                f"{-stiff / quadratic:.3g}: a tension law must rise up to ε = {CHECKED_STRAIN:g}, so C_E1 must be "
                f"at least −C_E/{2 * CHECKED_STRAIN:g} = {-stiff / (2 * CHECKED_STRAIN):g} N"
            )

        return checks.Condition(
            f"{name}.quadratic_stiffness",
            slope < 0,
            c_e1,
            f"must be at least −C_E/{2 * CHECKED_STRAIN:g}, so that the tension rises up to ε = {CHECKED_STRAIN:g}",
            detail,
        )

    def elastic_tension(self, strain: Float[ArrayLike, "*segments"]) -> Array:
        """The elastic part `(C_E ε + C_E1 ε²) H(ε)` (N)."""
        return _switched_polynomial(
            jnp.asarray(strain), self.axial_stiffness, self.quadratic_stiffness(), self.slack_width
        )

    def viscous_tension(
        self, strain: Float[ArrayLike, "*segments"], strain_rate: Float[ArrayLike, "*segments"]
    ) -> Array:
        """The damping part `C_v ε̇ H(ε)` (N); zero for a law that is not `damped`."""
        if not self.damped:
            return jnp.zeros(jnp.broadcast_shapes(jnp.shape(strain), jnp.shape(strain_rate)))
        return self.damping() * strain_rate * slack_switch(strain, self.slack_width)

    def tension(self, strain: Float[ArrayLike, "*segments"], strain_rate: Float[ArrayLike, "*segments"]) -> Array:
        """The full tension `T(ε, ε̇)` (N), including damping."""
        return self.elastic_tension(strain) + self.viscous_tension(strain, strain_rate)

    def elastic_energy_density(self, strain: Float[ArrayLike, "*segments"]) -> Array:
        """`∫₀^ε T_e(e) de` (N, i.e. J per metre of unstretched length).

        Exact for both the sharp and the smoothed switch: Gauss–Legendre inside the
        smoothing band, where the integrand is a quintic, and the closed form above it.
        """
        strain = jnp.asarray(strain)
        shape = jnp.shape(strain)
        return _energy_density(
            strain,
            jnp.broadcast_to(self.axial_stiffness, shape),
            jnp.broadcast_to(self.quadratic_stiffness(), shape),
            jnp.broadcast_to(self.slack_width, shape),
        )


def _integrated_energy_density(strain, c_e, c_e1, width):
    """`∫₀^ε (C_E e + C_E1 e²) H(e) de`, arrays of one shape."""
    # `where`, not `clip`/`maximum`: at the tie ε = w those split the derivative in
    # half, and the force there must be the whole T(w).
    inside = jnp.where(strain < width, jnp.maximum(strain, 0.0), width)
    # One term per quadrature point, not a trailing axis of three (see `_hydro.dot`).
    band = inside * sum(
        weight * _switched_polynomial(inside * node, c_e, c_e1, width)
        for node, weight in zip(_GL3_NODES.tolist(), _GL3_WEIGHTS.tolist())
    )

    def antiderivative(e):
        return c_e * e**2 / 2 + c_e1 * e**3 / 3

    above = jnp.where(strain >= width, strain, width)
    return band + jnp.where(strain >= width, antiderivative(above) - antiderivative(width), 0.0)


@jax.custom_jvp
def _energy_density(strain, c_e, c_e1, width):
    return _integrated_energy_density(strain, c_e, c_e1, width)


def _energy_density_jvp(primals, tangents):
    """The derivative in ε is the tension law itself, `T_e(ε)`, by the fundamental
    theorem of calculus: the forces `−∂Π/∂x` then cost one evaluation of the law, not
    the reverse pass through the quadrature. Exact, since the quadrature is. The
    parameters' derivatives (a fit of C_E, say) go through the quadrature as before,
    and only when asked for."""
    strain, *parameters = primals
    d_strain, *d_parameters = tangents
    value = _energy_density(*primals)
    tangent = jnp.zeros_like(value)
    if not isinstance(d_strain, SymbolicZero):
        tangent = tangent + _switched_polynomial(*primals) * d_strain
    if not all(isinstance(d, SymbolicZero) for d in d_parameters):
        d_parameters = [
            jnp.zeros_like(p) if isinstance(d, SymbolicZero) else d for p, d in zip(parameters, d_parameters)
        ]
        _, by_parameters = jax.jvp(
            lambda *p: _integrated_energy_density(strain, *p), tuple(parameters), tuple(d_parameters)
        )
        tangent = tangent + by_parameters
    return value, tangent


_energy_density.defjvp(_energy_density_jvp, symbolic_zeros=True)


def _switched_polynomial(strain, c_e, c_e1, width):
    return strain * (c_e + c_e1 * strain) * slack_switch(strain, width)


class LinearElastic(AbstractTensionLaw):
    """Hooke's law, tension only: `T = C_E ε H(ε)`.

    **Arguments:**

    - `axial_stiffness`: C_E = EA (N), per segment or scalar.
    - `slack_width`: w (–), the strain band over which the slack switch is smoothed;
        `0` for the sharp switch.
    """

    axial_stiffness: Float[Array, "*segments"]
    slack_width: Float[Array, "*segments"]
    damped: ClassVar[bool] = False

    def __init__(self, axial_stiffness: RealLike, slack_width: RealLike = 1e-5):
        self.axial_stiffness = checks.on_device(axial_stiffness)
        self.slack_width = checks.on_device(slack_width)

    def quadratic_stiffness(self):
        return jnp.zeros_like(self.axial_stiffness)

    def damping(self):
        return jnp.zeros_like(self.axial_stiffness)


class NonlinearElastic(AbstractTensionLaw):
    """The anchored-line paper's law: `T = (C_E ε + C_E1 ε²) H(ε)`.

    **Arguments:**

    - `axial_stiffness`: C_E (N).
    - `quadratic_stiffness`: C_E1 (N); Bezverkhyy & Korniienko use 0.05–0.2 × C_E. A negative C_E1
        must keep the tension rising up to ε = 1 (`C_E1 ≥ −C_E/2`), which
        [`jaxcable.LineType`][] checks.
    - `slack_width`: w (–), as for [`jaxcable.LinearElastic`][].
    """

    axial_stiffness: Float[Array, "*segments"]
    quadratic_coefficient: Float[Array, "*segments"]
    slack_width: Float[Array, "*segments"]
    damped: ClassVar[bool] = False

    def __init__(self, axial_stiffness: RealLike, quadratic_stiffness: RealLike, slack_width: RealLike = 1e-5):
        self.axial_stiffness = checks.on_device(axial_stiffness)
        self.quadratic_coefficient = checks.on_device(quadratic_stiffness)
        self.slack_width = checks.on_device(slack_width)

    def quadratic_stiffness(self):
        return self.quadratic_coefficient

    def damping(self):
        # numpy's zeros where concrete: a model's checks ask for it eagerly.
        stiffness = checks.on_host(self.axial_stiffness)
        return (jnp if checks.traced(stiffness) else np).zeros_like(stiffness)


class KelvinVoigt(AbstractTensionLaw):
    """The branched-systems paper's viscoelastic law: `T = (C_E ε + C_E1 ε² + C_v ε̇) H(ε)`.

    **Arguments:**

    - `axial_stiffness`: C_E (N).
    - `quadratic_stiffness`: C_E1 (N).
    - `axial_damping`: C_v (N·s); Bezverkhyy & Korniienko's branched-systems paper takes 0.02 × C_E (in seconds × N).
    - `slack_width`: w (–), as for [`jaxcable.LinearElastic`][].
    - `slack_damping`: whether the damping acts on a slack segment too, `T = (C_E ε +
        C_E1 ε²) H(ε) + C_v ε̇`, as MoorDyn's `BA` does (its `Line::getStateDeriv`
        switches off only the elastic part in compression); `False` (default) for seed
        002's law, where a slack segment carries nothing. It matters where a segment
        starts compressed, as the touchdown segments of MoorDyn's initial shape of a
        chain resting on the seabed do.
    """

    axial_stiffness: Float[Array, "*segments"]
    quadratic_coefficient: Float[Array, "*segments"]
    axial_damping: Float[Array, "*segments"]
    slack_width: Float[Array, "*segments"]
    slack_damping: bool = eqx.field(static=True)

    def __init__(
        self,
        axial_stiffness: RealLike,
        quadratic_stiffness: RealLike,
        axial_damping: RealLike,
        slack_width: RealLike = 1e-5,
        slack_damping: bool = False,
    ):
        self.axial_stiffness = checks.on_device(axial_stiffness)
        self.quadratic_coefficient = checks.on_device(quadratic_stiffness)
        self.axial_damping = checks.on_device(axial_damping)
        self.slack_width = checks.on_device(slack_width)
        self.slack_damping = bool(slack_damping)

    def viscous_tension(
        self, strain: Float[ArrayLike, "*segments"], strain_rate: Float[ArrayLike, "*segments"]
    ) -> Array:
        """The damping part `C_v ε̇ H(ε)` (N), or `C_v ε̇` with `slack_damping`."""
        if not self.slack_damping:
            return super().viscous_tension(strain, strain_rate)
        shape = jnp.broadcast_shapes(jnp.shape(strain), jnp.shape(strain_rate))
        return jnp.broadcast_to(self.damping() * jnp.asarray(strain_rate), shape)

    def quadratic_stiffness(self):
        return self.quadratic_coefficient

    def damping(self):
        return self.axial_damping
