import gc
import os

# The suite is compile-bound: most tests compile a program or two and run it briefly.
# XLA's CPU fusion emitters (its default) make kernels that run faster but compile
# slower; without them test_statics and test_dynamics took 60 s instead of 78 s (quiet,
# 2 cores), and their answers agree to rounding. Set before JAX starts its backend;
# `DEFAULT_XLA_FLAGS` keeps the caller's flags for tests that run the default code path
# (the command line's process test): kept in the environment by the first process, so
# that xdist's workers, which inherit the suite's flags, know the caller's too.
DEFAULT_XLA_FLAGS = os.environ.setdefault("JAXCABLE_TESTS_CALLER_XLA_FLAGS", os.environ.get("XLA_FLAGS", ""))
if "xla_cpu_use_fusion_emitters" not in DEFAULT_XLA_FLAGS:
    os.environ["XLA_FLAGS"] = f"{DEFAULT_XLA_FLAGS} --xla_cpu_use_fusion_emitters=false".strip()

import jax  # noqa: E402 (after XLA's flags)
import pytest  # noqa: E402

import jaxcable as jc  # noqa: E402

# jaxcable computes in float64 and leaves the switch to its caller; the suite is the
# caller here, and flips it before any test builds an array.
jax.config.update("jax_enable_x64", True)


def pytest_configure(config):
    """Keep compiled programs on disk, in pytest's cache folder, for the whole run (JAX's,
    and jaxcable's own kept by structure, `jaxcable._programs`).

    Modules free their compiled programs when they end (below), and the workers of
    `pytest -n` share nothing in memory, so without a disk cache a program that two
    modules or two workers need is compiled twice. JAX's persistent cache keeps every
    program that took over a second to compile; a second run of the suite on the same
    checkout skips those compilations altogether. A cache folder the caller chose
    (`JAX_COMPILATION_CACHE_DIR`) is left alone.
    """
    cache = getattr(config, "cache", None)
    if cache is not None and "JAX_COMPILATION_CACHE_DIR" not in os.environ:
        jax.config.update("jax_compilation_cache_dir", str(cache.mkdir("jax-compilation-cache")))
    # jaxcable's own programs (statics', the scene runs'), which the library keeps in the
    # user's cache folder by default: here in pytest's, beside JAX's, for this process and
    # the processes the tests start (which read the environment).
    if cache is not None and not {"JAXCABLE_CACHE_DIR", "JAX_COMPILATION_CACHE_DIR"} & set(os.environ):
        os.environ["JAXCABLE_CACHE_DIR"] = str(cache.mkdir("jaxcable"))
    # In the slow suite, one thread for each worker's XLA kernels, as `jaxcable run` has
    # (`_cli._one_kernel_thread`): a worker a core, and a backend's default pool of a thread
    # a core handed a run's microsecond kernels between threads the other worker needed.
    # Ten slow tests on 2 workers took 131 s with it against 173 s without (cold caches),
    # and the slow suite 55:17 CPU-minutes against about 57. The default suite, mostly
    # compiling, gained nothing (27:41 CPU-minutes with it, 27:59 without). Set here,
    # before xdist starts the workers, which inherit it, as the notebooks' kernels do;
    # the caller's wins.
    if _slow_suite(config):
        os.environ.setdefault("PJRT_NPROC", "1")
    # In the default suite, whose runs are short, XLA's backend without LLVM's
    # optimisation passes: test_sweep.py took 96 s instead of 112 s and
    # test_specialisation.py 137 s instead of 166 s (fresh caches, 2 cores), the same
    # tests passing. Set before any test starts JAX's backend (importing JAX does not),
    # and inherited by xdist's workers and the processes the tests start; the slow suite,
    # whose runs are long, keeps the optimised kernels.
    elif "xla_backend_optimization_level" not in os.environ["XLA_FLAGS"]:
        os.environ["XLA_FLAGS"] = f"{os.environ['XLA_FLAGS']} --xla_backend_optimization_level=0"


def _slow_suite(config) -> bool:
    return config.getoption("markexpr", "") == "slow"


# Files whose tests are each a unit of work of their own under `--dist loadfile`, which
# otherwise hands a whole file to one worker: the notebooks take 1-5 minutes each, and on
# one worker they were the slow suite's long pole (30 min of it, 2 cores).
SPLIT_FILES = ("tests/test_notebooks.py",)


def pytest_xdist_make_scheduler(config, log):
    """`--dist loadfile`, but with the tests of `SPLIT_FILES` spread across workers."""
    if config.getoption("dist") != "loadfile":
        return None
    from xdist.scheduler import LoadFileScheduling

    class SplitFileScheduling(LoadFileScheduling):
        def _split_scope(self, nodeid: str) -> str:
            path = nodeid.split("::", 1)[0]
            return nodeid if path in SPLIT_FILES else path

    return SplitFileScheduling(config, log)


@pytest.fixture(autouse=True, scope="module")
def _release_compiled_programs():
    """Drop each module's compiled programs when it ends.

    Every compiled program maps memory regions for its code (about 2,000 for one
    calibration fit, measured), and Linux lets a process hold 65,530 maps
    (`vm.max_map_count`); past that, XLA fails with "LLVM compilation error: Cannot
    allocate memory". Modules share no compiled programs worth keeping, so the suite
    frees them module by module instead of accumulating them all.
    """
    yield
    jax.clear_caches()
    gc.collect()


@pytest.fixture(autouse=True)
def _unchecked(request):
    """Turn jaxtyping's runtime checker (`--jaxtyping-packages`) off for a test marked
    `unchecked`: one that passes an argument of the wrong type on purpose, to test the
    error jaxcable itself gives a caller who runs no type checker."""
    if request.node.get_closest_marker("unchecked") is None:
        yield
        return
    import jaxtyping

    before = jaxtyping.config.jaxtyping_disable
    jaxtyping.config.update("jaxtyping_disable", True)
    try:
        yield
    finally:
        jaxtyping.config.update("jaxtyping_disable", before)


@pytest.fixture(scope="module")
def driven_line():
    """A four-segment line from an anchor to a body driven at its top, in a 0.3 m/s
    current: `(model, env, its statics)`, small enough to compile and run quickly."""
    line = jc.LineType(mass_per_length=2.0, diameter=0.03, tension_law=jc.LinearElastic(2e6))
    model = jc.CableNetwork.from_branches(
        [[0.0, 0.0, -30.0], [30.0, 0.0, 0.0]],
        [jc.Branch(0, 1, line, 43.0, 4)],
        {0: jc.Fixed(), 1: jc.Harmonic(0.5, 4.0)},
        bodies={1: jc.Body(mass=5.0)},
    )
    env = jc.Environment(current=(0.3, 0.0, 0.0))
    return model, env, jc.solve_statics(model, env)
