"""`jc.check_derivative`: each verdict on a function whose derivative is known, and on
the README's anchored line before and after its first slack."""

import warnings

import diffrax
import equinox as eqx
import jax
import jax.numpy as jnp
import numpy as np
import pytest

import jaxcable as jc
from jaxcable import _derivative_check as derivative_check
from jaxcable._checks import differentiated


@jax.custom_jvp
def _sine_with_double_slope(x):
    return jnp.sin(x)


# A wrong derivative on purpose: twice the slope of the sine.
_sine_with_double_slope.defjvp(lambda primals, tangents: (jnp.sin(primals[0]), 2 * jnp.cos(primals[0]) * tangents[0]))


def test_a_smooth_derivative_agrees():
    check = jc.check_derivative(lambda x: jnp.sin(x) * x**2, 1.3)
    assert check.verdict == "agrees" and check.trusted
    exact = np.cos(1.3) * 1.3**2 + 2 * 1.3 * np.sin(1.3)
    assert check.derivative == pytest.approx(exact, rel=1e-12)
    assert check.reference == pytest.approx(exact, rel=1e-6)
    assert len(check.differences) == len(check.steps) == len(jc._derivative_check.DEFAULT_STEPS)
    assert "agrees with central differences within 2 %" in str(check)


def test_a_wrong_derivative_disagrees_and_warns():
    with pytest.warns(jc.DerivativeWarning, match="disagrees with central differences, which settle on 0.921"):
        check = jc.check_derivative(_sine_with_double_slope, 0.4)
    assert check.verdict == "disagrees" and not check.trusted
    assert check.derivative == pytest.approx(2 * np.cos(0.4))
    assert check.reference == pytest.approx(np.cos(0.4), rel=1e-6)


def test_a_function_rough_below_the_steps_is_ill_conditioned():
    """A slope of 1 at scales above 1e-6, ripples of 1e-3 below: the exact derivative
    (1 + 1000 cos(1e6 x)) is the ripples', and the differences move towards it as h
    shrinks."""
    check = jc.check_derivative(lambda x: x + 1e-3 * jnp.sin(1e6 * x), 0.7, steps=[1.0, 0.5, 0.1, 1e-7], warn=False)
    assert check.verdict == "ill-conditioned" and not check.trusted
    assert check.reference == pytest.approx(1.0, rel=0.02)
    assert abs(check.derivative) > 100
    assert "settle on 0.9996" in str(check) and "move towards the derivative" in str(check)


def test_differences_that_never_settle_are_ill_conditioned():
    check = jc.check_derivative(lambda x: x + 1e-3 * jnp.sin(1e6 * x), 0.7, warn=False)
    assert check.verdict == "ill-conditioned" and check.reference is None
    assert not any(check.settled)


def test_a_directional_derivative_in_forward_mode():
    x, direction = jnp.array([1.0, 2.0, -0.5]), jnp.array([0.0, 1.0, 2.0])
    check = jc.check_derivative(lambda v: jnp.sum(v**3), x, direction=direction, mode="forward")
    assert check.trusted
    assert check.derivative == pytest.approx(float(jnp.dot(3 * x**2, direction)))
    # The default steps scale with |x| / |direction|.
    assert check.steps[0] == pytest.approx(1e-2 * float(jnp.linalg.norm(x) / jnp.linalg.norm(direction)))


@pytest.mark.parametrize(
    ("keywords", "message"),
    [
        ({"direction": jnp.ones(2)}, "direction must have the shape of x, (), got (2,)"),
        ({"direction": 0.0}, "direction must be finite and not all zero"),
        ({"steps": [0.1, -1.0]}, "steps must be positive finite numbers"),
        ({"rtol": 0.0}, "rtol must be positive, got 0.0"),
    ],
)
def test_bad_arguments_are_refused_by_name(keywords, message):
    with pytest.raises(ValueError, match=f"check_derivative: {message}".replace("(", r"\(").replace(")", r"\)")):
        jc.check_derivative(jnp.sin, 0.3, **keywords)


@pytest.mark.unchecked  # jaxtyping's checker would refuse the mode first, by annotation
def test_an_unknown_mode_is_refused_by_name():
    with pytest.raises(ValueError, match="check_derivative: mode must be 'reverse' or 'forward', got 'backward'"):
        jc.check_derivative(jnp.sin, 0.3, mode="backward")  # pyright: ignore[reportArgumentType]


def test_a_function_that_returns_no_scalar_is_refused():
    with pytest.raises(ValueError, match=r"f must return a scalar, got shape \(2,\)"):
        jc.check_derivative(lambda x: jnp.array([x, x]), 0.3)


def test_a_gradient_is_checked_component_by_component():
    """One gradient, each component against its own central differences, at steps
    scaled by the component's own size; a wrong component alone is named."""
    x = jnp.array([[1.3, 0.0], [-2.0, 0.4]])
    calls = []

    def f(v):
        calls.append(1)
        return jnp.sin(v[0, 0]) * v[0, 0] ** 2 + v[0, 1] ** 3 + 4.0 * v[1, 0] + _sine_with_double_slope(v[1, 1])

    with pytest.warns(jc.DerivativeWarning, match="component 3 of x: check_derivative: the derivative .* disagrees"):
        checks = jc.check_gradient(f, x)
    assert [c.verdict for c in checks] == ["agrees", "agrees", "agrees", "disagrees"]
    exact = [np.cos(1.3) * 1.3**2 + 2 * 1.3 * np.sin(1.3), 0.0, 4.0, 2 * np.cos(0.4)]
    assert [c.derivative for c in checks] == pytest.approx(exact, rel=1e-12, abs=1e-12)
    assert checks[3].reference == pytest.approx(np.cos(0.4), rel=1e-6)
    # Each component's steps from its own size; a zero component's from 1.
    assert [c.steps[0] for c in checks] == pytest.approx([1.3e-2, 1e-2, 2e-2, 0.4e-2])
    # One gradient (f traced once for it) and two evaluations a step and component.
    assert len(calls) == 1 + 2 * 4 * len(jc._derivative_check.DEFAULT_STEPS)


@pytest.mark.parametrize(
    ("x", "keywords", "message"),
    [
        (jnp.zeros(0), {}, "x must have at least one component, got an empty array"),
        (jnp.ones(2), {"steps": []}, r"steps must be positive finite numbers, got \[\]"),
        (jnp.ones(2), {"rtol": -1.0}, "rtol must be positive, got -1.0"),
    ],
)
def test_bad_arguments_to_check_gradient_are_refused_by_name(x, keywords, message):
    with pytest.raises(ValueError, match=f"check_gradient: {message}"):
        jc.check_gradient(lambda v: jnp.sum(v), x, **keywords)


def _readme_line():
    model, env = jc.examples.anchored_line_in_current()
    return model, env, jc.solve_statics(model, env).state


@pytest.mark.slow
def test_the_mean_top_tension_of_the_readme_line_before_and_through_its_first_slack():
    """d(mean top tension over [0, t])/d(segment length): trusted over 1.5 s, before any
    segment goes slack; ill-conditioned over 5 s, through the slack at 3 s and the snap
    after it (`benchmarks/derivative_growth.py` measures the tangent's growth)."""
    model, env, start = _readme_line()

    def mean_top_tension(window):
        def f(change):
            lengthened = eqx.tree_at(lambda m: m.segment_length, model, model.segment_length + change)
            result = jc.simulate(lengthened, env, t1=window, ts=jnp.linspace(0.0, window, 31), initial=start)
            return jnp.mean(result.tension[:, -1])

        return f

    steps = [0.2 * 10.0**-k for k in range(6)]
    smooth = jc.check_derivative(mean_top_tension(1.5), 0.0, steps=steps)
    assert smooth.trusted, smooth
    with pytest.warns(jc.DerivativeWarning, match="ill-conditioned"):
        rough = jc.check_derivative(mean_top_tension(5.0), 0.0, steps=steps)
    assert rough.verdict == "ill-conditioned"
    assert abs(rough.derivative) > 1e6 * abs(smooth.derivative)


def test_differentiated_sees_a_derivative_beneath_vmap_and_jit():
    """`_checks.differentiated`: the tracers of `jax.grad`, `jax.jvp` and `jax.jacfwd`,
    alone, beneath `vmap`'s or inside `jit`; not `jit`'s or `vmap`'s alone."""
    seen = []

    def f(x):
        seen.append(differentiated(x))
        return jnp.sin(x).sum()

    jax.grad(f)(1.0)
    jax.jvp(f, (1.0,), (1.0,))
    jax.jacfwd(f)(1.0)
    jax.jit(jax.grad(f))(2.0)
    jax.vmap(jax.grad(f))(jnp.ones(2))
    jax.grad(lambda x: jax.vmap(f)(x).sum())(jnp.ones(2))
    assert seen == [True] * 6
    jax.jit(f)(3.0)
    jax.vmap(f)(jnp.ones(3))
    f(1.0)
    assert seen[6:] == [False] * 3


@pytest.mark.slow
def test_a_derivative_through_slack_is_warned_of(monkeypatch):
    """`simulate`, differentiated through a segment going slack (the README line's top
    segment, at 3 s), warns once a process, naming the first event; over a window
    before it, or not differentiated, it says nothing."""
    model, env, start = _readme_line()
    config = jc.SolverConfig(adjoint=diffrax.ForwardMode())

    def mean_top_tension(window):
        def f(change):
            lengthened = eqx.tree_at(lambda m: m.segment_length, model, model.segment_length + change)
            ts = jnp.linspace(0.0, window, 41)
            return jc.simulate(lengthened, env, window, ts=ts, initial=start, solver=config).tension[:, -1].mean()

        return f

    monkeypatch.setattr(derivative_check, "_SLACK_WARNED", [False])
    with warnings.catch_warnings():
        warnings.simplefilter("error", jc.DerivativeWarning)
        jax.jvp(mean_top_tension(2.0), (0.0,), (1.0,))
        mean_top_tension(4.0)(0.0)
    with pytest.warns(
        jc.DerivativeWarning,
        match=r"through \d+ slack events? .*the first at t = 3(\.\d+)? s, segment 20 of 20.*no axial damping",
    ):
        jax.jvp(mean_top_tension(4.0), (0.0,), (1.0,))
    with warnings.catch_warnings():
        warnings.simplefilter("error", jc.DerivativeWarning)
        jax.jvp(mean_top_tension(4.0), (0.0,), (1.0,))


def test_the_slack_warning_names_damping_as_the_remedy_only_for_an_undamped_line(monkeypatch):
    """The README's line has no axial damping (NonlinearElastic); a KelvinVoigt law with
    zero damping has none either; with damping, or damping being differentiated, the
    warning does not suggest it."""
    from jaxcable._simulation.simulate import _undamped

    model, _, _ = _readme_line()
    law = model.line.tension_law
    assert _undamped(model)
    for damping, undamped in ((0.0, True), (6.0e4, False)):
        viscous = jc.KelvinVoigt(law.axial_stiffness, law.quadratic_stiffness(), damping)
        assert _undamped(eqx.tree_at(lambda m: m.line.tension_law, model, viscous)) is undamped
    seen = []
    jax.jit(
        lambda c: seen.append(_undamped(eqx.tree_at(lambda m: m.line.tension_law, model, jc.KelvinVoigt(1, 0, c))))
    )(0.0)
    assert seen == [False]  # traced damping: its value is unknown
    for undamped in (True, False):
        monkeypatch.setattr(derivative_check, "_SLACK_WARNED", [False])
        with pytest.warns(jc.DerivativeWarning) as caught:
            derivative_check._slack_warning(3, 2.5, 19, 20, undamped=undamped)
        assert ("no axial damping" in str(caught[0].message)) is undamped
