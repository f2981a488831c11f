"""Progress over simulated time: one bar for `simulate`, `sweep` and the command line.

Every bar counts simulated seconds (`12.3/60.0 s simulated`), not percent. On a terminal
it is a tqdm bar; where stderr is not a terminal (a log file, a pipe), a redrawn bar
would write a line per update, so it writes a line at most every `LOG_INTERVAL` seconds
of wall time, and the last one.

Inside a compiled solve the time reached comes out through [`SimulatedTime`][], a diffrax
progress meter that calls back to the host every `refresh_steps` steps; the bar itself
decides when to draw.
"""

import itertools
import sys
import threading
import time
from collections.abc import Callable, Iterator
from contextlib import contextmanager

import diffrax
import equinox as eqx
import equinox.internal as eqxi
import jax
import jax.numpy as jnp
import numpy as np
from jax.experimental import io_callback
from jaxtyping import Array, Float

LOG_INTERVAL = 20.0
"""With stderr not a terminal (a log), a bar writes a line at most this often (s of wall
time), and at the end."""


@contextmanager
def progress_bar(duration: float, show: bool, what: str = "simulate") -> Iterator[Callable[[float], None] | None]:
    """A bar on stderr over `duration` (s) of simulated time, or none; yields the
    function to call with the simulated time reached (s, from 0).

    On a terminal it is a tqdm bar counting simulated seconds (`12.3/60.0 s`). Where
    stderr is not a terminal a redrawn bar would write a line per update, so it writes
    `simulate: 12.3/60.0 s simulated, 0:00:41 wall` at most once every `LOG_INTERVAL`
    seconds of wall time, and once at the end. `what` names the work (`simulate`,
    `sweep`).
    """
    if not show:
        yield None
        return
    stream = sys.stderr
    if not stream.isatty():
        yield from _log_progress(duration, stream, what)
        return
    from tqdm import tqdm

    with tqdm(
        total=duration,
        file=stream,
        desc=what,
        bar_format="{desc}: |{bar}| {n:.1f}/{total:.1f} s simulated [{elapsed}<{remaining}]",
    ) as bar:

        def reached(t: float) -> None:
            bar.update(t - bar.n)

        yield reached


def _log_progress(duration: float, stream, what: str) -> Iterator[Callable[[float], None]]:
    """[`progress_bar`][]'s lines for a log: see there."""
    start = time.monotonic()
    last = [start]  # when the last line was written
    times = {"reached": 0.0, "written": -1.0}  # simulated

    def write(t: float) -> None:
        last[0] = time.monotonic()
        times["written"] = t
        elapsed = int(last[0] - start)
        wall = f"{elapsed // 3600}:{elapsed // 60 % 60:02d}:{elapsed % 60:02d}"
        print(f"{what}: {t:.1f}/{duration:.1f} s simulated, {wall} wall", file=stream, flush=True)

    def reached(t: float) -> None:
        times["reached"] = t
        if time.monotonic() - last[0] >= LOG_INTERVAL:
            write(t)

    yield reached
    if times["written"] != times["reached"]:
        write(times["reached"])


class _Bars:
    """The host's open bars, by number: a compiled solve holds only the number."""

    def __init__(self):
        self.lock = threading.Lock()
        self.count = itertools.count(1)
        self.open: dict[int, tuple] = {}  # number → (context, reached, t0, duration)

    def start(self, t0, t1) -> np.ndarray:
        t0, duration = float(t0), float(t1) - float(t0)
        context = progress_bar(duration, True)
        reached = context.__enter__()
        with self.lock:
            number = next(self.count)
            self.open[number] = (context, reached, t0, duration)
        return np.asarray(number, dtype=np.int32)

    def reach(self, number, progress) -> np.ndarray:
        # Under `vmap` the number and progress may carry a spurious batch axis
        # (`vmap_method="expand_dims"`); there is one bar.
        key = int(np.unique(number).item())
        with self.lock:
            entry = self.open.get(key)
        if entry is not None:  # None: the bar is closed (a backward pass, say)
            _, reached, _, duration = entry
            reached(float(np.min(progress)) * duration)
        return np.asarray(number, dtype=np.int32)

    def close(self, number) -> None:
        with self.lock:
            entry = self.open.pop(int(number), None)
        if entry is not None:
            context, reached, _, duration = entry
            reached(duration)
            context.__exit__(None, None, None)


_bars = _Bars()


class _MeterState(eqx.Module):
    number: Array
    step: Array


class SimulatedTime(diffrax.AbstractProgressMeter):
    """A diffrax progress meter that shows [`progress_bar`][]'s bar in simulated
    seconds, from `t0` to `t1` (s), for a solve compiled anywhere (under `jit` too):
    `t0` and `t1` are array fields, so a new duration reuses the compiled solve. The
    host is told the time reached every `refresh_steps` steps (each a callback).

    Under `vmap` the bar follows the slowest case, as diffrax's own meters do.
    """

    t0: Float[Array, ""]
    t1: Float[Array, ""]
    refresh_steps: int = eqx.field(static=True, default=200)

    def init(self) -> _MeterState:
        number = io_callback(_bars.start, jax.ShapeDtypeStruct((), jnp.int32), self.t0, self.t1)
        return _MeterState(number=eqxi.nonbatchable(number), step=jnp.array(0))

    def step(self, state: _MeterState, progress) -> _MeterState:
        # The step counts of a batch start together and stop as each case ends: their
        # maximum is the batch's.
        due = eqxi.nonbatchable(eqxi.unvmap_max(state.step) % self.refresh_steps == 0)
        number = jax.lax.cond(
            due,
            lambda n: jax.pure_callback(
                _bars.reach, jax.ShapeDtypeStruct((), jnp.int32), n, progress, vmap_method="expand_dims"
            ),
            lambda n: n,
            state.number,
        )
        return _MeterState(number=number, step=state.step + 1)

    def close(self, state: _MeterState) -> None:
        io_callback(_bars.close, None, eqxi.unvmap_max(state.number))
