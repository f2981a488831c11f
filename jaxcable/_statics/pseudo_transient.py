"""Pseudo-transient continuation as an optimistix root finder: implicit Euler steps of
the overdamped motion `D ẋ = Q_f(x)`, each a linear step and Newton's corrections
towards its end, with the pseudo-time step grown or shrunk by how well the linear model
predicted the force (as a trust region)."""

import equinox as eqx
import jax
import jax.numpy as jnp
import lineax as lx
import optimistix as optx
from jaxtyping import Array, Float, Int

from .._solver.jacobian import NetworkJacobian


class _PseudoTransientState(eqx.Module):
    force: Float[Array, "free 3"]
    tolerance: Float[Array, ""]
    strain: Float[Array, " segments"]
    size: Float[Array, ""]
    step_size: Float[Array, ""]
    rejected: Int[Array, ""]
    previous: Float[Array, ""]


class PseudoTransient(optx.AbstractRootFinder):
    """Pseudo-transient continuation as an optimistix root finder for the free nodes'
    forces `fn(x) = Q_f(x)` (N), whose auxiliary output is the force tolerance (N) at
    `x`; `options["mass"]` holds the free nodes' pseudo-masses D (kg) and
    `options["shortest"]` the shortest segment (m).

    A step solves `(D/Δτ − J) δ = Q_f`, J = ∂Q_f/∂x, makes up to `corrections` of
    Newton's corrections towards implicit Euler's end point x' (each linearised at its
    iterate; they stop once the residual `Q_f(x') − D (x' − x)/Δτ` is below `resolved`
    times the force before the step), and tries x'. Δτ is steered as a trust region
    is, by how well the step's model predicted the force there, `Q_f(x') = D (x' −
    x)/Δτ`: its error, relative to the force before the step, below `good` lets Δτ
    grow by `grow`; above `poor` shrinks it by `shrink`; above `bad` (or a force that
    is not finite) refuses the step, unless the force still halved.
    A model error, not the force's change, is the test because the force need not
    fall along the way (a slack line falls freely at its weight), and because where a
    segment switches between slack and taut, Newton-like steps can cycle between the
    two states with the force rising and falling in turn (seen on a light, stiff
    riser in a current): the model's error there is large and Δτ shrinks until the
    steps follow the damped motion across the switch. The first Δτ moves the fastest
    node a tenth of the shortest segment. `give_up` steps refused in a row end the
    solve as stalled.
    """

    graph: NetworkJacobian
    rtol: float = 0.0  # unused: convergence is the force tolerance
    atol: float = 0.0
    norm: object = optx.max_norm
    good: float = 0.25
    poor: float = 0.5
    bad: float = 1.0
    grow: float = 4.0
    shrink: float = 0.25
    give_up: int = 40
    corrections: int = 10
    resolved: float = 0.01

    def init(self, fn, y, args, options, f_struct, aux_struct, tags):
        force, (tolerance, strain) = fn(y, args)
        mass = options["mass"][:, None]
        speed = jnp.max(jnp.abs(force) / mass)
        step_size = jnp.where(speed > 0, 0.1 * options["shortest"] / jnp.where(speed > 0, speed, 1.0), 1.0)
        return _PseudoTransientState(
            force, tolerance, strain, jnp.max(jnp.abs(force)), step_size, jnp.array(0), jnp.array(jnp.inf)
        )

    def step(self, fn, y, args, options, state, tags):
        mass = options["mass"][:, None]

        def newton(carry):
            k, x, residual = carry
            operator = lx.FunctionLinearOperator(
                lambda v: mass * v / state.step_size - jax.jvp(lambda z: fn(z, args)[0], (x,), (v,))[1],
                jax.eval_shape(lambda: y),
            )
            x = x + lx.linear_solve(operator, residual, self.graph, throw=False).value
            # Implicit Euler's residual `Q_f(x) − D (x − y)/Δτ`, zero at the step's end.
            return k + 1, x, fn(x, args)[0] - mass * (x - y) / state.step_size

        def unresolved(carry):
            k, _, residual = carry
            return (k <= self.corrections) & (jnp.max(jnp.abs(residual)) > self.resolved * state.size)

        # The linear step, then Newton's corrections towards implicit Euler's end
        # point, each linearised afresh, until its residual is a small part of the
        # force. A stiff segment turned by δ stretches by δ²/2L, which the linear
        # step cannot see; and a stiff line at rest inside its slack switch's band
        # (strains of 1e-7 to 1e-5, where the law is cubic) is stiffer at every
        # iterate than at the last. Corrections with the first step's factors (a
        # chord method) diverged there: every other step was refused and stiff lines of
        # `benchmarks/statics_fuzz.py` stalled at 1e-4 of their force scale. Linearised
        # afresh, they end in tens of steps, not thousands. The residual is carried
        # from one correction to the next (at y it is the force there), so that each
        # evaluates the forces once besides their JVPs: the loop's condition and a
        # `jax.linearize` evaluated them again, and tracing those was a third of the
        # tracing of the Low & Langley file's statics.
        step = jax.lax.while_loop(unresolved, newton, (0, y, state.force))[1] - y
        # Truncated where a segment would switch between slack and taut: the linear
        # model holds on one side of the switch only. A slack segment (ε ≤ 0) that the
        # step would stretch past the top of its switch's band stops there, a taut one
        # (above the band) that it would slacken stops at zero strain; one inside the
        # band moves freely (stiff lines rest there). All by the shortest such fraction α
        # of the step (the strain taken as linear along it). Without this, a slack
        # stretch of line drifting under its buoyancy or a current (a buoyant line
        # floating up, a light line on the bed in a current) moved only as far as the
        # step's model stayed good across its many switches: a few centimetres a step,
        # and thousands of steps (as on random scenes of `benchmarks/statics_fuzz.py`).
        _, (_, ahead) = fn(y + step, args)
        taut, before = options["taut"], state.strain
        tightens = (before <= 0) & (ahead > taut)
        slackens = (before >= taut) & (ahead < 0)
        change = jnp.where(tightens | slackens, ahead - before, 1.0)
        fraction = jnp.where(tightens, (taut - before) / change, jnp.where(slackens, -before / change, 1.0))
        alpha = jnp.clip(jnp.min(fraction, initial=1.0), 0.0, 1.0)
        candidate = y + alpha * step
        force, (tolerance, strain) = fn(candidate, args)
        size = jnp.max(jnp.abs(force))
        # The linear model's force at the truncated point: `(1 − α) Q_f + α D δ/Δτ`.
        predicted = (1 - alpha) * state.force + alpha * mass * step / state.step_size
        error = jnp.max(jnp.abs(force - predicted)) / state.size
        finite = jnp.isfinite(size) & jnp.isfinite(error)
        taken = finite & ((error <= self.bad) | (size <= 0.5 * state.size))
        # A truncated step took a fraction α of what Δτ allowed: Δτ follows it down,
        # so that the next step ends near the next switch, not far past it.
        factor = jnp.where(error <= self.good, self.grow, jnp.where(error <= self.poor, 1.0, self.shrink))
        factor = factor * jnp.maximum(alpha, self.shrink**2)
        new = _PseudoTransientState(
            force=jnp.where(taken, force, state.force),
            tolerance=jnp.where(taken, tolerance, state.tolerance),
            strain=jnp.where(taken, strain, state.strain),
            size=jnp.where(taken, size, state.size),
            step_size=state.step_size * jnp.where(finite, factor, self.shrink),
            rejected=jnp.where(taken, 0, state.rejected + 1),
            previous=jnp.where(taken, state.size, state.previous),
        )
        return jnp.where(taken, candidate, y), new, (tolerance, strain)

    def terminate(self, fn, y, args, options, state, tags):
        # Within the tolerance the steps go on while they still halve the force: near
        # the equilibrium they are Newton's, so a few take it from the tolerance down
        # to rounding (the supports then carry the weight to 1e-8 and better, where the
        # tolerance allowed 1e-6 of the tension). A step that no longer halves it, or
        # one refused (rounding's noise), ends the solve.
        within = state.size <= state.tolerance
        done = within & ((state.size > 0.5 * state.previous) | (state.rejected >= 1))
        stalled = state.rejected >= self.give_up
        failed = stalled & ~done
        return done | stalled, optx.RESULTS.where(failed, optx.RESULTS.nonlinear_divergence, optx.RESULTS.successful)

    def postprocess(self, fn, y, aux, args, options, state, tags, result):
        return y, aux, {}
