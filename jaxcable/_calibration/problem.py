"""Towing records as one fitting problem: each record paired with its rig, rigs of one
structure padded to one length and simulated as one `vmap`ped batch, and the scaled
residuals, their Jacobian and gradient in the fitted coefficients' logs."""

from typing import NamedTuple

import diffrax
import equinox as eqx
import jax
import jax.numpy as jnp
import numpy as np

from .._solver.config import SolverConfig
from .records import TowingRecord
from .towing import AbstractTowingRig, rig_from_conditions

# Padded samples sit this far (s) apart past a record's end, so that padded times stay
# strictly increasing (a tow speed's knots must) while simulating no further, to
# within microseconds.
_PAD_STEP = 1e-6


class _Group(NamedTuple):
    """Records on rigs of one structure, padded to one length and stacked."""

    indices: tuple[int, ...]  # into the list of records
    lengths: tuple[int, ...]  # unpadded samples per record
    names: tuple[str, ...]  # observables measured by at least one record
    rigs: AbstractTowingRig  # leaves stacked over records
    times: jax.Array  # (records, samples)
    inputs: dict  # name -> (records, samples)
    observed: dict  # name -> (records, samples)
    mask: dict  # name -> (records, samples), 1 where measured
    scale: dict  # name -> (records,): each record's RMS of its measured values (SI)


@eqx.filter_jit
def simulate_one(rig, times, inputs, solver):
    return rig.simulate(times, inputs, solver)


def _pair(test, index) -> tuple[AbstractTowingRig, TowingRecord]:
    if isinstance(test, TowingRecord):
        rig, record = rig_from_conditions(test.conditions, test.name or f"record {index}"), test
    else:
        rig, record = test
    if not isinstance(rig, AbstractTowingRig):
        raise ValueError(f"calibrate: tests[{index}] must pair a towing rig with a record, got {rig!r}")
    if not isinstance(record, TowingRecord):
        raise ValueError(f"calibrate: tests[{index}] must pair a rig with a TowingRecord, got {record!r}")
    label = record.name or f"tests[{index}]"
    missing = [k for k in rig.inputs if k not in record.columns]
    if missing:
        raise ValueError(f"calibrate: {label} has no {missing[0]!r} column, which {type(rig).__name__} needs as input")
    if not any(k in record.columns for k in rig.observables):
        raise ValueError(f"calibrate: {label} measures none of {type(rig).__name__}'s observables {rig.observables}")
    return rig, record


def group_records(pairs) -> list[_Group]:
    """Stack the records rig structure by rig structure, padding each group to its
    longest record: repeated final values, at times `_PAD_STEP` apart."""
    by_structure: dict = {}
    for i, (rig, _) in enumerate(pairs):
        by_structure.setdefault(jax.tree.structure(rig), []).append(i)
    groups = []
    for indices in by_structure.values():
        rigs = [pairs[i][0] for i in indices]
        records = [pairs[i][1] for i in indices]
        lengths = tuple(len(r.times) for r in records)
        size = max(lengths)
        names = tuple(k for k in rigs[0].observables if any(k in r.columns for r in records))

        def pad(values, n):
            return np.concatenate([values, np.full(size - n, values[-1])])  # noqa: B023 (called within this iteration)

        times = np.stack(
            [
                np.concatenate([r.times, r.times[-1] + _PAD_STEP * np.arange(1, size - len(r.times) + 1)])
                for r in records
            ]
        )
        inputs = {k: np.stack([pad(r.columns[k], len(r.times)) for r in records]) for k in rigs[0].inputs}
        observed, mask, scale = {}, {}, {}
        for k in names:
            observed[k] = np.stack(
                [pad(r.columns[k], len(r.times)) if k in r.columns else np.zeros(size) for r in records]
            )
            mask[k] = np.stack([(np.arange(size) < len(r.times)) & (k in r.columns) for r in records]).astype(float)
            scale[k] = jnp.asarray(
                [max(float(np.sqrt(np.mean(r.columns[k] ** 2))), 1e-12) if k in r.columns else 1.0 for r in records]
            )
        stacked = jax.tree.map(lambda *leaves: jnp.stack(leaves), *rigs)
        groups.append(
            _Group(
                tuple(indices),
                lengths,
                names,
                stacked,
                jnp.asarray(times),
                {k: jnp.asarray(v) for k, v in inputs.items()},
                {k: jnp.asarray(v) for k, v in observed.items()},
                {k: jnp.asarray(v) for k, v in mask.items()},
                scale,
            )
        )
    return groups


class FittingProblem(eqx.Module):
    """A calibration's data and settings, as one argument for the compiled steps, so
    that fits of the same structure reuse their compilation."""

    names: tuple[str, ...] = eqx.field(static=True)
    groups: tuple[_Group, ...]
    samples: jax.Array  # measured samples in all, for the mean
    solver: SolverConfig
    forward: SolverConfig  # `solver` with diffrax.ForwardMode, for the Jacobian

    @property
    def gradient(self) -> str:
        """`"forward"` or `"reverse"`: the gradient mode that `solver`'s adjoint asks for."""
        return "forward" if isinstance(self.solver.adjoint, diffrax.ForwardMode) else "reverse"

    def residuals(self, log_values, solver=None):
        """All scaled residuals, predicted minus measured over the RMS, masked, flat;
        and each group's per-record success. A failed simulation's residuals are
        zeroed, not NaN, so that gradients stay finite; `loss` reports the failure as
        infinite instead."""
        parts, successes = [], []
        predicted = _predict(log_values, self.names, self.groups, self.solver if solver is None else solver)
        for group, (observables, success) in zip(self.groups, predicted):
            successes.append(success)
            for k in group.names:
                scaled = (observables[k] - group.observed[k]) / group.scale[k][:, None]
                parts.append(jnp.where(success[:, None] & (group.mask[k] > 0), scaled, 0.0).reshape(-1))
        return jnp.concatenate(parts), tuple(successes)

    def loss_of(self, r, successes):
        """Half the mean squared scaled residual; infinite if a simulation failed."""
        ok = jnp.all(jnp.concatenate(successes))
        return jnp.where(ok, 0.5 * jnp.sum(r**2) / self.samples, jnp.inf)

    def loss(self, log_values, solver=None):
        return self.loss_of(*self.residuals(log_values, solver))


def fitting_problem(tests, names, solver) -> tuple[FittingProblem, list]:
    """Check the records against their rigs, and group, pad and stack them."""
    pairs = [_pair(test, i) for i, test in enumerate(tests)]
    if not pairs:
        raise ValueError("calibrate: no records to fit")
    for name in names:
        if not any(name in rig.coefficients for rig, _ in pairs):
            raise ValueError(f"calibrate: no record's rig depends on {name!r}, so no record can fit it")
    groups = group_records(pairs)
    problem = FittingProblem(
        names=names,
        groups=tuple(groups),
        samples=jnp.asarray(sum(float(np.sum(m)) for g in groups for m in g.mask.values())),
        solver=solver,
        # The Jacobian needs forward mode whichever way the fit's gradient goes.
        forward=eqx.tree_at(lambda s: s.adjoint, solver, diffrax.ForwardMode()),
    )
    return problem, pairs


def _predict(log_values, names, groups, solver):
    """Each group's observables, name -> (records, samples), and per-record success."""
    values = dict(zip(names, jnp.exp(log_values)))
    out = []
    for group in groups:

        def one(rig, times, inputs):
            run = rig.with_coefficients(values).simulate(times, inputs, solver)
            return run.observables, run.success

        out.append(jax.vmap(one)(group.rigs, group.times, group.inputs))
    return out


@eqx.filter_jit
def residual_jacobian(log_values, problem: FittingProblem):
    """The residuals' Jacobian in the log coefficients, shape `(residuals, p)`, in
    forward mode; and (residuals, successes)."""

    def residuals(p):
        r, successes = problem.residuals(p, problem.forward)
        return r, (r, successes)

    return jax.jacfwd(residuals, has_aux=True)(log_values)


@eqx.filter_jit
def _reverse(log_values, problem: FittingProblem):
    return jax.value_and_grad(problem.loss)(log_values)


def evaluate(log_values, problem: FittingProblem):
    """The loss and its gradient at `log_values`, and, in forward mode, what the
    report needs there: the Jacobian, residuals and successes. Each mode runs one
    compiled program, which the report reuses rather than compiling its own (every
    compiled program maps thousands of memory regions, about 3,500 for a vertical-tow
    fit, and a process may hold only about 65,000, Linux's default `vm.max_map_count`)."""
    if problem.gradient == "reverse":
        value, grad = _reverse(log_values, problem)
        return value, grad, None
    jacobian, (r, successes) = residual_jacobian(log_values, problem)
    return problem.loss_of(r, successes), jacobian.T @ r / problem.samples, (jacobian, r, successes)


def solver_tolerances(problem: FittingProblem) -> tuple[float, float] | None:
    """The fit's step-size controller's `(rtol, atol)`; `None` if it has none (fixed
    steps)."""
    controller = problem.forward.stepsize_controller
    if not isinstance(controller, diffrax.PIDController):
        return None
    return float(controller.rtol), float(controller.atol)
