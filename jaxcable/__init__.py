"""jaxcable: differentiable, JIT-compiled dynamics of underwater cable systems.

jaxcable computes in float64 throughout (stiff cables need it). Importing it changes no
global setting: enable JAX's float64 once, before building a model, with
`jax.config.update("jax_enable_x64", True)` or `JAX_ENABLE_X64=1` in the environment.
A model built without it raises [`jaxcable.Float64Error`][], which says so.

The names here are the ones a user needs day to day: the model and the sea, the motions
of supports, the entry points (simulate, solve_statics, sweep, calibrate, advise, and
reading and running scenes) with their results, and the solvers. The rest is grouped in
public modules:

- `jaxcable.io`: scene specs, the scene runner's result, output files, motion tables and
    towing records (with their units and columns), and advice in words.
- `jaxcable.calibration`: the towing rigs and their registries, and synthetic records.
- `jaxcable.equations`: energies, forces, tension, the vector field, the stiffest mode.
- `jaxcable.plot`: figures of a scene run and of a calibration.
- `jaxcable.examples`: the seed papers' scenes, as builders and bundled scene files.
"""

from importlib.metadata import version as _version

from ._advice import Advice as Advice, advise as advise
from ._calibrate import CalibrationResult as CalibrationResult, calibrate as calibrate
from ._checks import Float64Error as Float64Error
from ._cnoidal import Cnoidal as Cnoidal, cnoidal_coefficients as cnoidal_coefficients
from ._jacobian import NetworkJacobian as NetworkJacobian
from ._environment import CurrentProfile as CurrentProfile, Environment as Environment, Seabed as Seabed
from ._materials import (
    AbstractTensionLaw as AbstractTensionLaw,
    KelvinVoigt as KelvinVoigt,
    LinearElastic as LinearElastic,
    NonlinearElastic as NonlinearElastic,
)
from ._motion import (
    AbstractMotion as AbstractMotion,
    Fixed as Fixed,
    Harmonic as Harmonic,
    Sampled as Sampled,
    Towing as Towing,
)
from ._network import Body as Body, Branch as Branch, CableNetwork as CableNetwork, LineType as LineType
from ._picard import PicardTrapezoid as PicardTrapezoid
from ._config import (
    SOLVERS as SOLVERS,
    SolverConfig as SolverConfig,
    default_solver as default_solver,
    stiff_solver as stiff_solver,
)
from ._simulate import SimulationResult as SimulationResult, simulate as simulate
from ._state import State as State
from ._sweep import SweepResult as SweepResult, sweep as sweep, sweep_grid as sweep_grid
from ._statics import StaticSolution as StaticSolution, solve_statics as solve_statics
from ._waves import AbstractWave as AbstractWave, Airy as Airy, airy_wavenumber as airy_wavenumber
from .io._moordyn import read_moordyn as read_moordyn
from .io._run import load_scene as load_scene, run_scene as run_scene
from .io._scene_file import read_scene as read_scene

from . import calibration as calibration, equations as equations, examples as examples, io as io, plot as plot

__version__ = _version("jaxcable")
