"""Make the bundled sample towing records, `records/*.csv`, for `jaxcable calibrate`.

    python -m jaxcable.examples.make_records        # rewrites jaxcable/examples/records/

Two synthetic tows on [`jaxcable.calibration.HorizontalTow`][], simulated with known
drag coefficients (`TRUTH`) and 2 % Gaussian noise on every observable
([`jaxcable.calibration.synthetic_record`][]), so that a fit can be seen to recover them:

- `depressor`: 100 m of the default armoured tow cable (17.3 mm, EA = 2e6 N here) in 4
  segments, a 100 kg depressor at its end. The cable hangs steeply and its tow-point
  load is mostly the depressor's weight and the cable's normal drag: it pins K_n.
- `streamer`: the same length of a nearly neutral cable (5 % heavier than the water it
  displaces) on a small drogue. It streams almost along the flow, so its tow-point load
  is mostly tangential drag: it pins K_τ.

Both start in steady tow at 1 m/s and are stepped to 2 m/s over 3 s from t = 6 s, as
the branched-systems paper's towing tests were; each is 20 s long, sampled every 0.2 s (101 samples),
and written in the units a towing tank would log (speed in knots, the load cell's
`tow_load` in kN). Each records what instruments read: the tow-point load, the body's
depth and layback, all at nodes, so a fit at another segment count measures the same
things (not `tension`, the first segment's at its middle, which moves with the
segments).

The headers give each rig as `rig_from_conditions` reads it, but not the two drag
coefficients: those are what the records are for. A fit that leaves one of them out
takes the rig's default for it (K_n = 1.2, K_τ = 0.01), not the truth. A free-text
header line says the record is synthetic and where it came from.

The records are package data, so this script's output is committed; rerun it only if
the rig's physics or defaults change, and update the truth in README.md if `TRUTH`
does.
"""

import math
from pathlib import Path

import numpy as np

TRUTH = {"normal_drag": 1.5, "tangential_drag": 0.015}
"""The drag coefficients the records were simulated with: K_n and K_τ (–)."""
NOISE = 0.02  # each observable's noise, relative to its RMS over the record
TIMES = np.round(np.linspace(0.0, 20.0, 101), 9)  # s, rounded so that the file reads 0.6, not 0.6000000000000001
SPEED = np.interp(TIMES, [0.0, 6.0, 9.0, 20.0], [1.0, 1.0, 2.0, 2.0])  # m/s
CABLE = dict(cable_length=100.0, cable_axial_stiffness=2e6, cable_axial_damping=5e3)  # m, N, N·s
SEGMENTS = 4
UNITS = {"speed": "kn", "tow_load": "kN"}
FOLDER = Path(__file__).parent / "records"


def rigs() -> dict:
    """The two rigs by record name, with the true coefficients."""
    from jaxcable.calibration import HorizontalTow

    neutral = 1025.0 * math.pi * 0.0173**2 / 4  # kg/m: the default cable's displaced mass
    return {
        "depressor": HorizontalTow(
            **CABLE, segments=SEGMENTS, end_mass=100.0, end_volume=0.015, end_drag_area=0.1, **TRUTH
        ),
        "streamer": HorizontalTow(
            **CABLE,
            segments=SEGMENTS,
            cable_mass_per_length=1.05 * neutral,
            end_mass=2.0,
            end_volume=0.0015,
            end_drag_area=0.05,
            **TRUTH,
        ),
    }


def main() -> None:
    import jax

    jax.config.update("jax_enable_x64", True)  # a script owns its process; the library never sets this

    from jaxcable.calibration import synthetic_record
    from jaxcable.io import TowingRecord, write_record

    FOLDER.mkdir(exist_ok=True)
    for seed, (name, rig) in enumerate(rigs().items()):
        record = synthetic_record(rig, TIMES, {"speed": SPEED}, noise=NOISE, seed=seed, name=name)
        conditions = {k: v for k, v in record.conditions.items() if k not in TRUTH}
        path = FOLDER / f"{name}.csv"
        write_record(path, TowingRecord(record.times, record.columns, conditions, name), UNITS)
        lines = path.read_text(encoding="utf-8").splitlines()
        note = (
            f"# synthetic: simulated by jaxcable.examples.make_records (HorizontalTow, K_n {TRUTH['normal_drag']:g}, "
            f"K_tau {TRUTH['tangential_drag']:g}, {100 * NOISE:g} % noise, seed {seed})"
        )
        path.write_text("\n".join([lines[0], note, *lines[1:]]) + "\n", encoding="utf-8")
        print(f"wrote {path}")


if __name__ == "__main__":
    main()
