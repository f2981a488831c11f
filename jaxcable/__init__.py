"""jaxcable: differentiable, JIT-compiled dynamics of underwater cable systems.

jaxcable works in float64 throughout (stiff cables need it): importing it enables
`jax_enable_x64`.
"""

import jax as _jax

_jax.config.update("jax_enable_x64", True)

from ._advice import Advice as Advice, advise as advise
from ._calibrate import (
    CalibrationResult as CalibrationResult,
    calibrate as calibrate,
    synthetic_record as synthetic_record,
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
from ._network import Body as Body, Branch as Branch, CableNetwork as CableNetwork, LineType as LineType
from ._picard import PicardTrapezoid as PicardTrapezoid
from ._records import (
    COLUMNS as COLUMNS,
    UNITS as UNITS,
    RecordError as RecordError,
    TowingRecord as TowingRecord,
    to_si as to_si,
)
from .io import (
    read_moordyn as read_moordyn,
    read_motion_file as read_motion_file,
    read_record as read_record,
    read_records as read_records,
    read_scene as read_scene,
    write_output as write_output,
    write_record as write_record,
    SceneRun as SceneRun,
    load_scene as load_scene,
    run_scene as run_scene,
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
from .plot import plot_calibration as plot_calibration, plot_run as plot_run
from ._simulate import (
    SOLVERS as SOLVERS,
    SimulationResult as SimulationResult,
    default_solver as default_solver,
    simulate as simulate,
    stiff_solver as stiff_solver,
)
from ._state import State as State
from ._sweep import SweepResult as SweepResult, sweep as sweep, sweep_grid as sweep_grid
from ._statics import StaticSolution as StaticSolution, solve_statics as solve_statics
from ._towing import (
    COEFFICIENTS as COEFFICIENTS,
    RIGS as RIGS,
    AbstractTowingRig as AbstractTowingRig,
    HorizontalTow as HorizontalTow,
    SolverSettings as SolverSettings,
    TowingRun as TowingRun,
    VerticalTow as VerticalTow,
    rig_from_conditions as rig_from_conditions,
)
from ._waves import (
    AbstractWave as AbstractWave,
    Airy as Airy,
    airy_wavenumber as airy_wavenumber,
    seed003_amplitude as seed003_amplitude,
)

__version__ = "0.1.0"
