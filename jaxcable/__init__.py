"""jaxcable: differentiable, JIT-compiled dynamics of underwater cable systems.

jaxcable computes in float64 throughout (stiff cables need it). Importing it changes no
global setting: enable JAX's float64 once, before building a model, with
`jax.config.update("jax_enable_x64", True)` or `JAX_ENABLE_X64=1` in the environment.
A model built without it raises [`jaxcable.Float64Error`][], which says so.

The names here are the ones a user needs day to day: the model and the sea (regular
waves, and irregular ones realised from a spectrum), the motions of supports, the entry
points (simulate, solve_statics, stiffness, sweep, calibrate, advise, check_derivative, and reading and
running scenes) with their results, the extremes of a response over realisations, and
the solvers. The rest is grouped in
public modules:

- `jaxcable.io`: scene specs, the scene runner's result, output files, motion tables and
    towing records (with their units and columns), and advice in words.
- `jaxcable.calibration`: the towing rigs and their registries, and synthetic records.
- `jaxcable.equations`: energies, forces, tension, the vector field, the stiffest mode.
- `jaxcable.plot`: figures of a scene run and of a calibration.
- `jaxcable.examples`: the seed papers' scenes, as builders and bundled scene files.

The names are imported when first used (PEP 562), so that `import jaxcable` and the
command line's `--help` do not import JAX; `from jaxcable import X` and `jaxcable.X`
work as usual. They are listed once, as the imports under `TYPE_CHECKING` below
(`jaxcable._lazy`).
"""

from importlib.metadata import version as _version
from typing import TYPE_CHECKING

from . import _lazy

if TYPE_CHECKING:
    from . import calibration as calibration
    from . import equations as equations
    from . import examples as examples
    from . import io as io
    from . import plot as plot
    from ._advice import Advice as Advice
    from ._advice import advise as advise
    from ._calibrate import CalibrationResult as CalibrationResult
    from ._calibrate import calibrate as calibrate
    from ._checks import Float64Error as Float64Error
    from ._cnoidal import Cnoidal as Cnoidal
    from ._cnoidal import cnoidal_coefficients as cnoidal_coefficients
    from ._config import SOLVERS as SOLVERS
    from ._config import SolverConfig as SolverConfig
    from ._config import default_solver as default_solver
    from ._config import stiff_solver as stiff_solver
    from ._derivative_check import DerivativeCheck as DerivativeCheck
    from ._derivative_check import DerivativeWarning as DerivativeWarning
    from ._derivative_check import check_derivative as check_derivative
    from ._environment import CurrentProfile as CurrentProfile
    from ._environment import Environment as Environment
    from ._environment import Seabed as Seabed
    from ._extremes import ExtremeStatistics as ExtremeStatistics
    from ._extremes import extreme_statistics as extreme_statistics
    from ._irregular import WaveComponents as WaveComponents
    from ._jacobian import NetworkJacobian as NetworkJacobian
    from ._materials import AbstractTensionLaw as AbstractTensionLaw
    from ._materials import KelvinVoigt as KelvinVoigt
    from ._materials import LinearElastic as LinearElastic
    from ._materials import NonlinearElastic as NonlinearElastic
    from ._motion import AbstractMotion as AbstractMotion
    from ._motion import Fixed as Fixed
    from ._motion import Harmonic as Harmonic
    from ._motion import Sampled as Sampled
    from ._motion import Towing as Towing
    from ._network import Body as Body
    from ._network import Branch as Branch
    from ._network import CableNetwork as CableNetwork
    from ._network import LineType as LineType
    from ._picard import PicardSimpson as PicardSimpson
    from ._picard import PicardTrapezoid as PicardTrapezoid
    from ._rk4 import RK4 as RK4
    from ._simulate import SimulationResult as SimulationResult
    from ._simulate import simulate as simulate
    from ._spectrum import Jonswap as Jonswap
    from ._stability import fixed_steps as fixed_steps
    from ._stability import stable_step as stable_step
    from ._state import State as State
    from ._statics import StaticSolution as StaticSolution
    from ._statics import solve_statics as solve_statics
    from ._stiffness import body_stiffness as body_stiffness
    from ._stiffness import stiffness as stiffness
    from ._sweep import SweepResult as SweepResult
    from ._sweep import sweep as sweep
    from ._sweep import sweep_grid as sweep_grid
    from ._waves import AbstractWave as AbstractWave
    from ._waves import Airy as Airy
    from ._waves import airy_wavenumber as airy_wavenumber
    from .io._moordyn import read_moordyn as read_moordyn
    from .io._run import load_scene as load_scene
    from .io._run import run_scene as run_scene
    from .io._scene_file import read_scene as read_scene

__getattr__, __dir__ = _lazy.attach(__name__, __file__, globals())

__version__ = _version("jaxcable")
