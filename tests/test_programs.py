"""Programs kept on disk by their arguments' structure (`jaxcable._programs`): loaded
without tracing, told apart by everything their trace depends on, and never in the way
of a traced call."""

import os
import subprocess
import sys
import textwrap
import threading
from pathlib import Path

import jax
import jax.numpy as jnp
import numpy as np
import pytest
from jax._src import compilation_cache

import jaxcable as jc
from jaxcable import _programs
from jaxcable.io._run import load_scene

TRACES: list[str] = []


def _kernel(x, count, options):
    """A program with an array, a static integer and static options, recording each trace."""
    TRACES.append("traced")
    return {"y": x * count + options["offset"], "sum": (jnp.sum(x),)}


@pytest.fixture
def folder(tmp_path):
    """Keep programs in a fresh folder for the test, beside a fresh JAX cache (as the
    command line keeps them): a program another test compiled comes from JAX's cache
    and is not kept (`Program._compile`). None afterwards."""
    kept, kept_cache = _programs.folder(), jax.config.jax_compilation_cache_dir
    _programs.use_folder(tmp_path / "programs")
    _use_jax_cache(tmp_path / "jax")
    TRACES.clear()
    yield tmp_path / "programs"
    _programs.use_folder(kept)
    _use_jax_cache(kept_cache)


def _use_jax_cache(path):
    jax.config.update("jax_compilation_cache_dir", None if path is None else str(path))
    compilation_cache.reset_cache()  # JAX opens its cache folder once, at its first use


def _files(folder):
    return sorted(p.name for p in folder.glob("*.program")) if folder.exists() else []


def test_a_kept_program_loads_without_tracing(folder):
    x = jnp.arange(4.0)
    first = _programs.Program(_kernel)(x, 2, {"offset": 1.5})
    assert len(TRACES) == 1 and len(_files(folder)) == 1
    # A new Program over the same function stands for a new process: nothing in memory.
    again = _programs.Program(_kernel)(x, 2, {"offset": 1.5})
    assert len(TRACES) == 1
    assert jax.tree.structure(again) == jax.tree.structure(first)
    for a, b in zip(jax.tree.leaves(again), jax.tree.leaves(first)):
        np.testing.assert_array_equal(a, b)
    np.testing.assert_array_equal(again["y"], np.arange(4.0) * 2 + 1.5)


def test_a_program_from_jax_cache_is_not_kept_and_runs(folder):
    """A program that JAX's cache supplied is not written: jaxlib's CPU client
    serialises a deserialised executable without some kernels, and the file loaded and
    failed when run (CI, 2026-11-27). Programs kept here are not written to JAX's cache
    either, but an older jaxcable's may be there. Every process's answer is right."""
    x = jnp.arange(4.0)
    args = (x, 2, {"offset": 1.5})
    with _programs.persistent_cache_threshold(0):  # JAX keeps every program, as for the command line
        lowered, _ = _programs.Program(_kernel)._lower(args, {})
        lowered.compile()  # into JAX's cache, as an older jaxcable left it
        for _ in range(2):  # a new process each time: compiled again, from JAX's cache
            again = _programs.Program(_kernel)(*args)
            np.testing.assert_array_equal(again["y"], np.arange(4.0) * 2 + 1.5)
            assert _files(folder) == []


def test_a_kept_program_is_not_in_jax_cache_too(folder):
    """The folder holds the program; JAX's cache does not hold a second copy (writing
    it was on a cold run's critical path)."""
    with _programs.persistent_cache_threshold(0):
        _programs.Program(_kernel)(jnp.arange(4.0), 2, {"offset": 1.5})
        jax.jit(lambda x: jnp.sin(x) * 3.0).lower(jnp.arange(4.0)).compile()  # a program JAX does keep
    assert len(_files(folder)) == 1
    names = [p.name for p in (folder.parent / "jax").iterdir()]
    assert any("lambda" in n for n in names) and not any("_kernel" in n for n in names)


def test_each_program_counts_once_as_compiled_or_loaded(folder):
    """A first `jaxcable run` said "0 of 2 programs loaded" having compiled seven: JAX
    records no cache miss for a program compiled past its cache, as the folder's are.
    Each is now recorded once: compiled (a miss), or loaded (a hit)."""
    from jax import monitoring

    events: list[str] = []

    def listen(event: str, **_) -> None:
        if event in (_programs.COMPILED_EVENT, _programs.LOADED_EVENT, "/jax/compilation_cache/cache_misses"):
            events.append(event)

    monitoring.register_event_listener(listen)
    try:
        args = (jnp.arange(4.0), 2, {"offset": 1.5})
        _programs.Program(_kernel)(*args)
        assert events == [_programs.COMPILED_EVENT]
        events.clear()
        _programs.Program(_kernel)(*args)  # a second process's
        assert events == [_programs.LOADED_EVENT]
    finally:
        monitoring.unregister_event_listener(listen)


@pytest.mark.parametrize(
    "args",
    [
        (jnp.arange(5.0), 2, {"offset": 1.5}),  # another shape
        (jnp.arange(4, dtype=jnp.int32), 2, {"offset": 1.5}),  # another dtype
        (jnp.arange(4.0), 3, {"offset": 1.5}),  # another static integer
        (jnp.arange(4.0), 2, {"offset": 1.5 + 2**-40}),  # a static float, to the last bit
        (jnp.arange(4.0), 2, {"offset": 1.5, "more": None}),  # another structure
        (np.arange(4.0), 2.0, {"offset": 1.5}),  # a float where an integer was
    ],
)
def test_the_key_tells_apart_what_changes_the_trace(folder, args):
    program = _programs.Program(_kernel)
    program(jnp.arange(4.0), 2, {"offset": 1.5})
    assert len(TRACES) == 1
    out = _programs.Program(_kernel)(*args)
    assert len(TRACES) == 2 and len(_files(folder)) == 2
    np.testing.assert_array_equal(out["y"], np.asarray(args[0]) * args[1] + args[2]["offset"])


def test_a_numpy_array_and_a_jax_array_of_one_type_share_a_program(folder):
    program = _programs.Program(_kernel)
    program(jnp.arange(4.0), 2, {"offset": 1.5})
    program(np.arange(4.0) + 1, 2, {"offset": 1.5})
    assert len(TRACES) == 1


def test_without_a_folder_it_is_filter_jit(folder, tmp_path):
    _programs.use_folder(None)
    program = _programs.Program(_kernel)
    out = program(jnp.arange(4.0), 2, {"offset": 1.5})
    program(jnp.arange(4.0), 2, {"offset": 1.5})
    assert len(TRACES) == 1  # equinox's own cache
    assert not folder.exists()
    np.testing.assert_array_equal(out["y"], np.arange(4.0) * 2 + 1.5)


def test_traced_calls_and_closures_take_filter_jit(folder):
    program = _programs.Program(_kernel)
    under_jit = jax.jit(lambda x: program(x, 2, {"offset": 1.5})["y"])(jnp.arange(4.0))
    batched = jax.vmap(lambda x: program(x, 2, {"offset": 1.5})["y"])(jnp.ones((3, 4)))
    np.testing.assert_array_equal(under_jit, np.arange(4.0) * 2 + 1.5)
    np.testing.assert_array_equal(batched, np.full((3, 4), 3.5))
    assert not _files(folder)

    def scaled(x, f):
        return f(x)

    offset = 2.0
    closure = _programs.Program(scaled)(jnp.arange(3.0), lambda x: x + offset)  # a captured value
    np.testing.assert_array_equal(closure, np.arange(3.0) + 2.0)
    assert not _files(folder)


def test_compiler_options_are_part_of_the_key_and_left_out_under_jit(folder):
    """A program's own XLA options (`compiler_options`) key it apart from the same function
    without them, and a call traced into another program, which JAX refuses options
    for, still runs."""
    options = {"xla_cpu_use_fusion_emitters": False}
    plain, tuned = _programs.Program(_kernel), _programs.Program(_kernel, compiler_options=options)
    args = (jnp.arange(4.0), 2, {"offset": 1.5})
    keys = [program._program(args, {}) for program in (plain, tuned)]
    assert keys[0] is not None and keys[1] is not None and keys[0][0] != keys[1][0]
    np.testing.assert_array_equal(tuned(*args)["y"], plain(*args)["y"])
    assert len(_files(folder)) == 2
    under_jit = jax.jit(lambda x: tuned(x, 2, {"offset": 1.5})["y"])(jnp.arange(4.0))
    np.testing.assert_array_equal(under_jit, np.arange(4.0) * 2 + 1.5)
    _programs.use_folder(None)
    np.testing.assert_array_equal(tuned(*args)["y"], np.arange(4.0) * 2 + 1.5)  # `filter_jit` with the options


def test_an_unreadable_file_is_compiled_again(folder):
    _programs.Program(_kernel)(jnp.arange(4.0), 2, {"offset": 1.5})
    (path,) = folder.glob("*.program")
    path.write_bytes(b"not a program")
    out = _programs.Program(_kernel)(jnp.arange(4.0), 2, {"offset": 1.5})
    assert len(TRACES) == 2
    np.testing.assert_array_equal(out["y"], np.arange(4.0) * 2 + 1.5)
    assert path.read_bytes() != b"not a program"  # written again


def test_prepare_compiles_in_the_background_for_the_call(folder):
    program = _programs.Program(_kernel)
    spec = jax.ShapeDtypeStruct((4,), jnp.float64)
    program.prepare(spec, 2, {"offset": 1.5})
    assert len(TRACES) == 1
    shapes = program.output_shapes(spec, 2, {"offset": 1.5})
    assert shapes["y"].shape == (4,) and shapes["sum"][0].shape == ()
    out = program(jnp.arange(4.0), 2, {"offset": 1.5})
    assert len(TRACES) == 1
    np.testing.assert_array_equal(out["y"], np.arange(4.0) * 2 + 1.5)
    assert len(_files(folder)) == 1


def test_compilation_in_the_background_leaves_python_running(folder):
    """XLA compiles without Python's lock, which is what lets statics go on meanwhile."""

    def heavy(x):
        # Each step uses x once: XLA's loop fusion (the tests turn its newer emitters
        # off, `conftest.py`) inlines a value into every use, so two uses a step would
        # grow the fused expression as 2^200 and exhaust the memory.
        for _ in range(200):
            x = jnp.sin(x[::-1]) * 1.0001 + 0.5
        return x

    program = _programs.Program(heavy)
    done = threading.Event()
    program.prepare(jax.ShapeDtypeStruct((64,), jnp.float64))
    future = next(iter(program._programs.values()))
    future.add_done_callback(lambda _: done.set())
    ticks = 0
    while not done.is_set():
        ticks += 1
    assert ticks > 1000
    np.testing.assert_allclose(program(jnp.zeros(64)), heavy(jnp.zeros(64)))


_KEY_SCRIPT = textwrap.dedent(
    """
    import jax
    jax.config.update("jax_enable_x64", True)
    from jaxcable import _programs
    from jaxcable._statics import solve as _statics
    from jaxcable.examples import anchored_line
    model, env = anchored_line(6)
    _programs.use_folder("unused")
    key, _ = _statics._equilibrium._program((model, env, model.node_positions, 0.0, 100, 1e-6, True, True, False), {})
    print(key)
    """
)


def test_keys_are_the_same_in_every_process():
    """Python salts the hash of strings and bytes per process (`PYTHONHASHSEED`): a key
    must not depend on it (the network's topology hashes its arrays' bytes)."""
    keys = set()
    for seed in ("1", "2"):
        env = {**os.environ, "PYTHONHASHSEED": seed, "JAX_PLATFORMS": "cpu"}
        out = subprocess.run([sys.executable, "-c", _KEY_SCRIPT], capture_output=True, text=True, env=env, check=True)
        keys.add(out.stdout.strip())
    assert len(keys) == 1 and len(keys.pop()) == 64


_LIBRARY_SCRIPT = textwrap.dedent(
    """
    import equinox as eqx
    import jax
    import numpy as np
    jax.config.update("jax_enable_x64", True)
    from jax import monitoring
    import jaxcable as jc
    from jaxcable import _programs
    from jaxcable.examples import anchored_line
    loaded = []
    def listen(event, **_):
        if event == _programs.LOADED_EVENT:
            loaded.append(event)
    monitoring.register_event_listener(listen)
    model, env = anchored_line(6)
    # In a current: a single line in still water is solved in closed form, with no
    # statics program (`jaxcable._statics.catenary`).
    env = eqx.tree_at(lambda e: e.current, env, np.array([0.2, 0.0, 0.0]))
    static = jc.solve_statics(model, env)
    print(len(loaded), float(static.state.positions[2, 2]).hex())
    """
)


def test_a_scripts_second_process_loads_its_statics_program(tmp_path):
    """The library keeps its programs by default, as the command line does: a script that
    solves statics compiles their program in its first process and loads it in its
    second, with the same answer."""
    env = {**os.environ, "JAXCABLE_CACHE_DIR": str(tmp_path), "JAX_PLATFORMS": "cpu"}
    env.pop("JAX_COMPILATION_CACHE_DIR", None)
    runs = [
        subprocess.run([sys.executable, "-c", _LIBRARY_SCRIPT], capture_output=True, text=True, env=env, check=True)
        for _ in range(2)
    ]
    (first, z1), (second, z2) = (run.stdout.split() for run in runs)
    assert (first, second) == ("0", "2") and z1 == z2  # statics' two programs, bitwise
    assert any(p.name.startswith("_equilibrium-") for p in (tmp_path / "jaxcable-programs").iterdir())
    # Off where the environment says so: nothing kept, nothing loaded.
    off = subprocess.run(
        [sys.executable, "-c", _LIBRARY_SCRIPT],
        capture_output=True,
        text=True,
        env={**env, "JAXCABLE_CACHE_DIR": ""},
        check=True,
    )
    assert off.stdout.split()[0] == "0"


_DEVICES_SCRIPT = textwrap.dedent(
    """
    import jax
    import jax.numpy as jnp
    from jax import monitoring
    from jaxcable import _programs
    assert len(jax.devices()) == 2, jax.devices()
    loaded = []
    monitoring.register_event_listener(lambda event, **_: loaded.append(event == _programs.LOADED_EVENT))
    def double(x):
        return 2.0 * x
    y = _programs.Program(double)(jnp.arange(3.0))
    print(sum(loaded), float(y[2]))
    """
)


def test_a_kept_program_runs_in_a_process_with_several_devices(tmp_path):
    """A sweep's process has several devices; a program kept from one such process
    loads in the next on the default device alone, as it was compiled (loaded onto
    every device, it asked each argument for a shard per device and failed)."""
    env = {
        **os.environ,
        "JAXCABLE_CACHE_DIR": str(tmp_path),
        "JAX_PLATFORMS": "cpu",
        "XLA_FLAGS": "--xla_force_host_platform_device_count=2",
    }
    env.pop("JAX_COMPILATION_CACHE_DIR", None)
    runs = [
        subprocess.run([sys.executable, "-c", _DEVICES_SCRIPT], capture_output=True, text=True, env=env)
        for _ in range(2)
    ]
    assert all(run.returncode == 0 for run in runs), runs[-1].stderr[-3000:]
    assert [run.stdout.split() for run in runs] == [["0", "4.0"], ["1", "4.0"]]


def test_statics_and_a_run_load_their_programs_bitwise(folder):
    """The engine's own programs, through `run_scene`: a second run in a new "process"
    (programs forgotten in memory) loads all of them and gives the same bits."""
    from jaxcable._simulation import blocks as _blocks
    from jaxcable._statics import catenary as _catenary

    # Statics' program: the fairlead's position at t = 0 (the line's equilibrium is the
    # discrete catenary, in numpy).
    programs = (_catenary._displacements,)
    run = (_blocks._start, _blocks._block, _blocks._fixed_start, _blocks._fixed_block, _blocks._outputs)

    def new_process():  # what another test in this worker kept in memory is forgotten too
        for program in programs + run:
            program._programs.clear()
            program._shapes.clear()

    scene = load_scene(Path(jc.examples.__file__).parent / "scenes" / "anchored_line.toml")
    new_process()
    first = jc.run_scene(scene, duration=0.5, dt_out=0.1)
    names = {p.split("-")[0] for p in _files(folder)}
    assert "_displacements" in names and names & {"_start", "_fixed_start"}
    new_process()
    loaded = []

    def listen(event, **_):
        loaded.append(event)

    jax.monitoring.register_event_listener(listen)
    try:
        second = jc.run_scene(scene, duration=0.5, dt_out=0.1)
    finally:
        jax.monitoring.unregister_event_listener(listen)
    assert loaded.count(_programs.LOADED_EVENT) == len(names)
    np.testing.assert_array_equal(second.positions, first.positions)
    np.testing.assert_array_equal(second.tension, first.tension)


def test_the_persistent_cache_threshold_is_where_jax_keeps_it():
    """jaxcable's one reach into JAX's private modules: inside the `with`, JAX's public
    setting reads the threshold, and after it the one before. Fails if a JAX release
    moves or renames it."""
    before = jax.config.jax_persistent_cache_min_compile_time_secs
    with _programs.persistent_cache_threshold(123.0):
        assert jax.config.jax_persistent_cache_min_compile_time_secs == 123.0
    assert jax.config.jax_persistent_cache_min_compile_time_secs == before
