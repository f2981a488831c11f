"""Type hints for what the public API accepts.

jaxtyping's `ArrayLike` is what `jnp.asarray` takes without a copy through Python: JAX and
numpy arrays and numpy or Python scalars. The API converts its numeric arguments itself
(`jnp.asarray`, `np.asarray`), so it accepts lists and tuples as well, nested for matrices
(`Body(force=(0.0, 0.0, -10.0))`, `CableNetwork(segment_nodes=[[0, 1], [1, 2]])`). These
aliases say so; fields and return values stay `Array`.
"""

from collections.abc import Sequence
from typing import TypeAlias

import numpy as np
from jaxtyping import Array, ArrayLike

# A real number or a 0-d array: what diffrax calls `RealScalarLike`.
RealScalarLike: TypeAlias = bool | int | float | Array | np.ndarray | np.bool_ | np.number

# A number, an array, or a (nested) list or tuple of them: anything `jnp.asarray` takes.
RealLike: TypeAlias = ArrayLike | Sequence[ArrayLike] | Sequence[Sequence[ArrayLike]]
