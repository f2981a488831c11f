import gc

import jax
import pytest


# jaxcable computes in float64 and leaves the switch to its caller; the suite is the
# caller here, and flips it before any test builds an array.
jax.config.update("jax_enable_x64", True)


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
