"""jaxcable.calibration: the towing rigs that calibration fits, and test records made
from them.

[`jaxcable.calibrate`][] fits a rig's drag coefficients to towing records
([`jaxcable.io.read_records`][]); each record's header names its rig, which
[`rig_from_conditions`][jaxcable.calibration.rig_from_conditions] builds from the
registry `RIGS`. `COEFFICIENTS` names the coefficients a fit may free, and
[`synthetic_record`][jaxcable.calibration.synthetic_record] simulates a record to test a
fit against known values.
"""

from ._calibration.calibrate import calibration_solver as calibration_solver
from ._calibration.calibrate import default_optimizer as default_optimizer
from ._calibration.discretisation import COMPARABLE as COMPARABLE
from ._calibration.discretisation import DiscretisationCheck as DiscretisationCheck
from ._calibration.discretisation import discretisation_check as discretisation_check
from ._calibration.report import ResidualCheck as ResidualCheck
from ._calibration.report import residual_check as residual_check
from ._calibration.synthetic import synthetic_record as synthetic_record
from ._calibration.towing import COEFFICIENTS as COEFFICIENTS
from ._calibration.towing import RIGS as RIGS
from ._calibration.towing import AbstractTowingRig as AbstractTowingRig
from ._calibration.towing import HorizontalTow as HorizontalTow
from ._calibration.towing import TowingRun as TowingRun
from ._calibration.towing import VerticalTow as VerticalTow
from ._calibration.towing import rig_from_conditions as rig_from_conditions
from ._calibration.towing import rig_solver as rig_solver
