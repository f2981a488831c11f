"""jaxcable.calibration: the towing rigs that calibration fits, and test records made
from them.

[`jaxcable.calibrate`][] fits a rig's drag coefficients to towing records
([`jaxcable.io.read_records`][]); each record's header names its rig, which
[`rig_from_conditions`][jaxcable.calibration.rig_from_conditions] builds from the
registry `RIGS`. `COEFFICIENTS` names the coefficients a fit may free, and
[`synthetic_record`][jaxcable.calibration.synthetic_record] simulates a record to test a
fit against known values.
"""

from ._calibrate import (
    calibration_solver as calibration_solver,
    default_optimizer as default_optimizer,
    synthetic_record as synthetic_record,
)
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
