"""jaxcable: differentiable, JIT-compiled dynamics of underwater cable systems.

jaxcable computes in float64 throughout (stiff cables need it). Importing it changes no
global setting: enable JAX's float64 once, before building a model, with
`jax.config.update("jax_enable_x64", True)` or `JAX_ENABLE_X64=1` in the environment.
A model built without it raises an error that says so.
"""

from importlib.metadata import version as _version

from ._advice import Advice as Advice, advise as advise
from ._calibrate import (
    CalibrationResult as CalibrationResult,
    calibrate as calibrate,
    calibration_solver as calibration_solver,
    default_optimizer as default_optimizer,
    synthetic_record as synthetic_record,
)
from ._checks import Float64Error as Float64Error
from ._config import (
    SOLVERS as SOLVERS,
    SolverConfig as SolverConfig,
    default_solver as default_solver,
    stiff_solver as stiff_solver,
)
from ._cnoidal import Cnoidal as Cnoidal, cnoidal_coefficients as cnoidal_coefficients
from ._jacobian import NetworkJacobian as NetworkJacobian
from ._environment import CurrentProfile as CurrentProfile, Environment as Environment, Seabed as Seabed
from ._lagrangian import (
    generalised_forces as generalised_forces,
    kinetic_energy as kinetic_energy,
    potential_energy as potential_energy,
    tension as tension,
)
from ._materials import (
    AbstractTensionLaw as AbstractTensionLaw,
    KelvinVoigt as KelvinVoigt,
    LinearElastic as LinearElastic,
    NonlinearElastic as NonlinearElastic,
    slack_switch as slack_switch,
)
from ._motion import (
    AbstractMotion as AbstractMotion,
    Fixed as Fixed,
    Harmonic as Harmonic,
    Sampled as Sampled,
    Towing as Towing,
)
from ._moordyn import read_moordyn as read_moordyn
from ._motion_file import read_motion_file as read_motion_file
from ._network import Body as Body, Branch as Branch, CableNetwork as CableNetwork, LineType as LineType
from ._output import write as write_output
from ._picard import PicardTrapezoid as PicardTrapezoid
from ._records import (
    COLUMNS as COLUMNS,
    UNITS as UNITS,
    RecordError as RecordError,
    TowingRecord as TowingRecord,
    read_record as read_record,
    read_records as read_records,
    to_si as to_si,
    write_record as write_record,
)
from ._plots import plot_calibration as plot_calibration, plot_run as plot_run
from ._run import SceneRun as SceneRun, load_scene as load_scene, run_scene as run_scene
from ._scene import (
    BuiltScene as BuiltScene,
    CurrentProfileSpec as CurrentProfileSpec,
    LineSpec as LineSpec,
    LineTypeSpec as LineTypeSpec,
    PointSpec as PointSpec,
    RunSettings as RunSettings,
    Scene as Scene,
    SceneError as SceneError,
    SeabedSpec as SeabedSpec,
    Water as Water,
    WaveSpec as WaveSpec,
)
from ._scene_file import read_scene as read_scene
from ._simulate import SimulationResult as SimulationResult, simulate as simulate
from ._state import State as State
from ._sweep import SweepResult as SweepResult, sweep as sweep, sweep_grid as sweep_grid
from ._statics import StaticSolution as StaticSolution, solve_statics as solve_statics
from ._towing import (
    COEFFICIENTS as COEFFICIENTS,
    RIGS as RIGS,
    AbstractTowingRig as AbstractTowingRig,
    HorizontalTow as HorizontalTow,
    TowingRun as TowingRun,
    VerticalTow as VerticalTow,
    rig_from_conditions as rig_from_conditions,
    rig_solver as rig_solver,
)
from ._waves import (
    AbstractWave as AbstractWave,
    Airy as Airy,
    airy_wavenumber as airy_wavenumber,
    seed003_amplitude as seed003_amplitude,
)

__version__ = _version("jaxcable")
