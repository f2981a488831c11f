"""jaxcable.io: scenes in and results out.

Everything between a file and the engine: the scene as data ([`jaxcable.io.Scene`][] and
its parts), the readers of jaxcable's TOML scenes, MoorDyn input files, motion tables and
towing records, the scene runner and the writers of its output channels. The engine never
imports from here: data flows scene → model → equations → solver → result → outputs.

The scene entry points, [`jaxcable.read_scene`][], [`jaxcable.read_moordyn`][],
[`jaxcable.load_scene`][] and [`jaxcable.run_scene`][], are in `jaxcable` itself; this
module holds what they take and give, and the rest of the file formats.

The names are imported when first used (PEP 562), as `jaxcable`'s are: the scene
readers are plain Python and numpy, and the command line reads and refuses an input
file through them before it imports JAX (1.3 s); the runner and the writers import it.
They are listed once, as the imports under `TYPE_CHECKING` below (`jaxcable._lazy`).
"""

from typing import TYPE_CHECKING

from .. import _lazy

if TYPE_CHECKING:
    from .._calibration.records import COLUMNS as COLUMNS
    from .._calibration.records import CONDITIONS as CONDITIONS
    from .._calibration.records import UNITS as UNITS
    from .._calibration.records import RecordError as RecordError
    from .._calibration.records import TowingRecord as TowingRecord
    from .._calibration.records import to_si as to_si
    from ._advice_text import advice_lines as advice_lines
    from ._extremes import DEFAULT_SAFETY_FACTOR as DEFAULT_SAFETY_FACTOR
    from ._extremes import LineExtremes as LineExtremes
    from ._line_fatigue import LineFatigue as LineFatigue
    from ._moordyn_water import write_wave_frequencies as write_wave_frequencies
    from ._motion_file import read_motion_file as read_motion_file
    from ._output import write as write_output  # noqa: F401 (re-exported under a new name)
    from ._records import read_record as read_record
    from ._records import read_records as read_records
    from ._records import write_record as write_record
    from ._run import SceneRun as SceneRun
    from ._scene import BuiltScene as BuiltScene
    from ._scene import CurrentProfileSpec as CurrentProfileSpec
    from ._scene import LineSpec as LineSpec
    from ._scene import LineTypeSpec as LineTypeSpec
    from ._scene import PointSpec as PointSpec
    from ._scene import RunSettings as RunSettings
    from ._scene import Scene as Scene
    from ._scene import SceneError as SceneError
    from ._scene import SeabedSpec as SeabedSpec
    from ._scene import SeaStateSpec as SeaStateSpec
    from ._scene import Water as Water
    from ._scene import WaveComponentsSpec as WaveComponentsSpec
    from ._scene import WaveSpec as WaveSpec
    from ._statistics import ChannelStatistics as ChannelStatistics

__getattr__, __dir__ = _lazy.attach(__name__, __file__, globals())
