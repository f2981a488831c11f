"""jaxcable: differentiable, JIT-compiled dynamics of underwater cable systems.

jaxcable computes in float64 throughout (stiff cables need it). Importing it changes no
global setting: enable JAX's float64 once, before building a model, with
`jax.config.update("jax_enable_x64", True)` or `JAX_ENABLE_X64=1` in the environment.
A model built without it raises [`jaxcable.Float64Error`][], which says so.

The names here are the ones a user needs day to day: the model and the sea (regular
waves, and irregular ones realised from a spectrum), the motions of supports, the entry
points (simulate, solve_statics, stiffness, sweep, calibrate, advise, check_derivative and check_gradient, reading and
running scenes, and campaigns of load cases) with their results, the extremes of a response over realisations, its
fatigue damage, and the solvers. The rest is grouped in
public modules:

- `jaxcable.io`: scene specs, the scene runner's result, output files, motion tables and
    towing records (with their units and columns), and advice in words.
- `jaxcable.calibration`: the towing rigs and their registries, and synthetic records.
- `jaxcable.equations`: energies, forces, tension, the vector field, the stiffest mode.
- `jaxcable.plot`: figures of a scene run and of a calibration.
- `jaxcable.examples`: the source papers' scenes, as builders and bundled scene files.

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
    from ._calibration.calibrate import calibrate as calibrate
    from ._calibration.report import CalibrationResult as CalibrationResult
    from ._campaign.campaign import CampaignResult as CampaignResult
    from ._campaign.campaign import run_campaign as run_campaign
    from ._campaign.cases import Case as Case
    from ._campaign.cases import read_cases as read_cases
    from ._campaign.fatigue import TN_CURVES as TN_CURVES
    from ._campaign.fatigue import FatigueDamage as FatigueDamage
    from ._campaign.fatigue import TNCurve as TNCurve
    from ._campaign.fatigue import chain_area as chain_area
    from ._campaign.fatigue import damage_equivalent_load as damage_equivalent_load
    from ._campaign.fatigue import fatigue_damage as fatigue_damage
    from ._campaign.fatigue import rainflow_cycles as rainflow_cycles
    from ._checks import Float64Error as Float64Error
    from ._derivative_check import DerivativeCheck as DerivativeCheck
    from ._derivative_check import DerivativeWarning as DerivativeWarning
    from ._derivative_check import check_derivative as check_derivative
    from ._derivative_check import check_gradient as check_gradient
    from ._model.materials import AbstractTensionLaw as AbstractTensionLaw
    from ._model.materials import KelvinVoigt as KelvinVoigt
    from ._model.materials import LinearElastic as LinearElastic
    from ._model.materials import NonlinearElastic as NonlinearElastic
    from ._model.motion import AbstractMotion as AbstractMotion
    from ._model.motion import Fixed as Fixed
    from ._model.motion import Harmonic as Harmonic
    from ._model.motion import Sampled as Sampled
    from ._model.motion import Towing as Towing
    from ._model.network import Body as Body
    from ._model.network import Branch as Branch
    from ._model.network import CableNetwork as CableNetwork
    from ._model.network import LineType as LineType
    from ._model.state import State as State
    from ._sea.cnoidal import Cnoidal as Cnoidal
    from ._sea.cnoidal import cnoidal_coefficients as cnoidal_coefficients
    from ._sea.environment import CurrentProfile as CurrentProfile
    from ._sea.environment import Environment as Environment
    from ._sea.environment import Seabed as Seabed
    from ._sea.extremes import ExtremeStatistics as ExtremeStatistics
    from ._sea.extremes import extreme_statistics as extreme_statistics
    from ._sea.irregular import WaveComponents as WaveComponents
    from ._sea.spectrum import Jonswap as Jonswap
    from ._sea.waves import AbstractWave as AbstractWave
    from ._sea.waves import Airy as Airy
    from ._sea.waves import airy_wavenumber as airy_wavenumber
    from ._simulation.blocks import SimulationFailed as SimulationFailed
    from ._simulation.blocks import SimulationInterrupted as SimulationInterrupted
    from ._simulation.simulate import SimulationResult as SimulationResult
    from ._simulation.simulate import simulate as simulate
    from ._solver.config import SOLVERS as SOLVERS
    from ._solver.config import SolverConfig as SolverConfig
    from ._solver.config import default_solver as default_solver
    from ._solver.config import stiff_solver as stiff_solver
    from ._solver.jacobian import NetworkJacobian as NetworkJacobian
    from ._solver.picard import PicardSimpson as PicardSimpson
    from ._solver.picard import PicardTrapezoid as PicardTrapezoid
    from ._solver.rk4 import RK4 as RK4
    from ._solver.stability import fixed_steps as fixed_steps
    from ._solver.stability import stable_step as stable_step
    from ._statics.solution import StaticSolution as StaticSolution
    from ._statics.solve import solve_statics as solve_statics
    from ._statics.stiffness import body_stiffness as body_stiffness
    from ._statics.stiffness import stiffness as stiffness
    from ._sweep.cases import sweep_grid as sweep_grid
    from ._sweep.result import SweepResult as SweepResult
    from ._sweep.sweep import sweep as sweep
    from .io._moordyn import read_moordyn as read_moordyn
    from .io._run import load_scene as load_scene
    from .io._run import run_scene as run_scene
    from .io._scene_file import read_scene as read_scene

__getattr__, __dir__ = _lazy.attach(__name__, __file__, globals())

__version__ = _version("jaxcable")
