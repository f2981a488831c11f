"""jaxcable.io: scenes in and results out.

Everything between a file and the engine: the scene as data ([`jaxcable.io.Scene`][] and
its parts), the readers of jaxcable's TOML scenes, MoorDyn input files, motion tables and
towing records, the scene runner and the writers of its output channels. The engine never
imports from here: data flows scene → model → equations → solver → result → outputs.

The scene entry points, [`jaxcable.read_scene`][], [`jaxcable.read_moordyn`][],
[`jaxcable.load_scene`][] and [`jaxcable.run_scene`][], are in `jaxcable` itself; this
module holds what they take and give, and the rest of the file formats.
"""

from .._records import (
    COLUMNS as COLUMNS,
    UNITS as UNITS,
    RecordError as RecordError,
    TowingRecord as TowingRecord,
    to_si as to_si,
)
from ._advice_text import advice_lines as advice_lines
from ._motion_file import read_motion_file as read_motion_file
from ._output import write as write_output
from ._records import read_record as read_record, read_records as read_records, write_record as write_record
from ._run import SceneRun as SceneRun
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
