"""Progress bars count simulated seconds, for `simulate`, `sweep` and the command line,
and change no answer."""

import io

import equinox as eqx
import jax
import numpy as np

import jaxcable as jc
from jaxcable import _progress
from jaxcable.examples import anchored_line


def test_a_bar_for_a_log_writes_a_few_lines(monkeypatch):
    """Where stderr is not a terminal the bar writes a line per `LOG_INTERVAL` of wall
    time and the last one, counting simulated seconds: 1,000 updates over 100 s of
    (faked) wall time make 5 lines and the final one."""
    clock = [0.0]
    monkeypatch.setattr(_progress.time, "monotonic", lambda: clock[0])
    stream = io.StringIO()  # not a terminal
    monkeypatch.setattr(_progress.sys, "stderr", stream)
    with _progress.progress_bar(60.0, True) as reached:
        assert reached is not None
        for k in range(1, 1001):
            clock[0] = k * 0.1
            reached(k * 0.06)
    lines = stream.getvalue().splitlines()
    assert len(lines) == 5
    assert lines[0] == "simulate: 12.0/60.0 s simulated, 0:00:20 wall"
    assert lines[-1] == "simulate: 60.0/60.0 s simulated, 0:01:40 wall"
    stream = io.StringIO()
    monkeypatch.setattr(_progress.sys, "stderr", stream)
    with _progress.progress_bar(60.0, True) as reached:
        assert reached is not None
        reached(30.0)
    assert stream.getvalue().splitlines() == ["simulate: 30.0/60.0 s simulated, 0:00:00 wall"]


def _lines(text: str, what: str) -> list[str]:
    return [line for line in text.splitlines() if line.startswith(f"{what}: ")]


def test_simulate_shows_simulated_seconds_and_the_same_answer(capsys):
    """`simulate(progress=True)` writes its bar in simulated seconds (to a log here:
    capsys is not a terminal), ending at the whole duration, and returns what the run
    without a bar returns: the same steps, and the same tensions to rounding. (The bar's
    callback makes it another program, which XLA without its optimisation passes, as
    the default suite compiles, rounds differently, by about 1e-11 of the tension here;
    with them the two agree bitwise.)"""
    model, env = anchored_line(n_segments=4)
    quiet = jc.simulate(model, env, 0.5, initial="rest")
    capsys.readouterr()
    shown = jc.simulate(model, env, 0.5, initial="rest", progress=True)
    lines = _lines(capsys.readouterr().err, "simulate")
    assert lines and lines[-1].startswith("simulate: 0.5/0.5 s simulated, ")
    for count in ("num_steps", "num_accepted_steps", "num_rejected_steps"):
        assert int(shown.stats[count]) == int(quiet.stats[count]), count
    np.testing.assert_allclose(shown.tension, quiet.tension, rtol=1e-10)


def test_simulate_under_jit_shows_the_traced_duration(capsys):
    """With `t1` traced the bar still knows the duration: it is read when the solve
    starts, so a new `t1` reuses the compiled solve and shows its own."""
    model, env = anchored_line(n_segments=4)

    @jax.jit
    def last_tension(t1):
        return jc.simulate(model, env, t1, initial="rest", progress=True).tension[-1, -1]

    for t1 in (0.25, 0.4):
        jax.block_until_ready(last_tension(t1))
        lines = _lines(capsys.readouterr().err, "simulate")
        assert lines[-1].startswith(f"simulate: {t1:.1f}/{t1:.1f} s simulated, ")
    assert last_tension._cache_size() == 1


def test_sweep_shows_the_cases_simulated_seconds(capsys):
    """`sweep(progress=True)` counts the simulated seconds of every case: three cases of
    0.5 s end at 1.5 s, and the results are those of the sweep without a bar."""

    def build(amplitude):
        model, env = anchored_line(n_segments=4)
        top = list(np.asarray(model.constrained_nodes)).index(1)
        return eqx.tree_at(lambda m: m.motions[top].amplitude, model, amplitude), env

    cases = {"amplitude": np.array([0.5, 1.0, 1.5])}
    quiet = jc.sweep(build, cases, 0.5)
    capsys.readouterr()
    shown = jc.sweep(build, cases, 0.5, progress=True)
    lines = _lines(capsys.readouterr().err, "sweep")
    assert lines and lines[-1].startswith("sweep: 1.5/1.5 s simulated, ")
    np.testing.assert_array_equal(shown.tension, quiet.tension)
