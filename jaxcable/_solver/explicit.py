"""Explicit Runge–Kutta steps with their stages written out.

diffrax's general Runge–Kutta step (`diffrax.AbstractRungeKutta.step`) runs the stages
of any tableau in one checkpointed `while_loop`, which serves every tableau, implicit
stages and reverse-mode derivatives without copies of the triangular stage sums. XLA
cannot fuse across the loop's iterations, and each stage reads and writes the stacked
stage derivatives: for a batch of small systems the loop costs more than the stages
(an RK4 step of 128 anchored lines of 20 segments takes about 2.4 times as long through
it; `python benchmarks/step_cost.py --segments 20 --batch 128`, column "RK4 step").

[`explicit_step`][] takes a step of an explicit tableau without the first-same-as-last
property (Euler's is not a tableau; midpoint, Heun, Ralston and RK4 are) stage by stage,
skipping zero coefficients, with diffrax's returns; other solvers take their own
`step`. Derivatives (forward and reverse) go through the written-out stages as through
any JAX code.
"""

import functools
import operator

import diffrax
import jax
import jax.numpy as jnp


def unrolls(solver: diffrax.AbstractSolver) -> bool:
    """Whether [`explicit_step`][] writes out `solver`'s stages: an explicit Runge–Kutta
    method with one tableau that is not first-same-as-last (whose step would carry the
    last stage's derivative as its state)."""
    tableau = getattr(solver, "tableau", None)
    return isinstance(solver, diffrax.AbstractERK) and isinstance(tableau, diffrax.ButcherTableau) and not tableau.fsal


def explicit_step(solver: diffrax.AbstractSolver, terms, t0, t1, y0, args, solver_state, made_jump):
    """`solver.step(terms, t0, t1, y0, args, solver_state, made_jump)`, with the stages
    written out where [`unrolls`][] says so: the same `(y1, y_error, dense_info,
    solver_state, result)`, equal to diffrax's to rounding (the same sums, in the
    tableau's order, without its zero terms)."""
    if not unrolls(solver):
        return solver.step(terms, t0, t1, y0, args, solver_state, made_jump)
    tableau: diffrax.ButcherTableau = solver.tableau  # pyright: ignore[reportAttributeAccessIssue]
    control = terms.contr(t0, t1)
    dt = t1 - t0

    def combine(weights, ks, base=None):
        """`base + Σ wᵢ kᵢ` over the non-zero weights, leaf by leaf (no `base`: the sum)."""
        used = [(float(w), k) for w, k in zip(weights, ks) if w != 0]

        def leaf(*leaves):
            total = functools.reduce(operator.add, [w * x for (w, _), x in zip(used, leaves[-len(used) :])])
            return total if base is None else leaves[0] + total

        return jax.tree.map(leaf, *([] if base is None else [base]), *[k for _, k in used])

    ks = [terms.vf_prod(t0, y0, args, control)]
    for c, row in zip(tableau.c, tableau.a_lower):
        t = t1 if c == 1 else t0 + float(c) * dt
        ks.append(terms.vf_prod(t, combine(row, ks, base=y0), args, control))
    y1 = combine(tableau.b_sol, ks, base=y0)
    y_error = combine(tableau.b_error, ks)
    dense_info = dict(y0=y0, y1=y1, k=jax.tree.map(lambda *k: jnp.stack(k), *ks))
    return y1, y_error, dense_info, solver_state, diffrax.RESULTS.successful
