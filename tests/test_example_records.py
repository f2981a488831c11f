"""The bundled sample towing records (`jaxcable/examples/records/`, made by
`jaxcable/examples/make_records.py`): they load, their headers describe their rigs but
not the coefficients to fit, the command line finds them by name, and they are what
the rig predicts at the truth that the README states, to within their 2 % noise.
"""

import re
from pathlib import Path

import numpy as np
import pytest

from jaxcable import examples
from jaxcable._cli import main
from jaxcable.calibration import rig_from_conditions
from jaxcable.examples import make_records
from jaxcable.io import read_records

NAMES = examples.record_names()
README = Path(__file__).parents[1] / "README.md"


def test_bundled_records_load_with_their_rigs():
    assert NAMES == ["depressor", "streamer"]
    records = read_records([examples.record_path(name) for name in NAMES])
    for name, record in zip(NAMES, records):
        assert record.name == f"{name}.csv"
        assert record.conditions["rig"] == "horizontal_tow"
        assert set(record.columns) == {"speed", "tow_load", "depth", "layback"}
        np.testing.assert_allclose(record.times, np.linspace(0.0, 20.0, 101), rtol=0, atol=1e-12)
        # Written in knots and kN, read back in SI: 1 kn = 1852/3600 m/s.
        np.testing.assert_allclose(record.columns["speed"][[0, -1]], [1.0, 2.0], rtol=1e-12)
        # The coefficients to fit are not in the header: a fit must find them.
        assert not {"normal_drag", "tangential_drag"} & set(record.conditions)
        rig = rig_from_conditions(record.conditions, record.name)
        assert rig.segments == 4 and float(rig.cable_length) == 100.0
    with pytest.raises(ValueError, match=r"no bundled towing record 'tow'; bundled: \['depressor', 'streamer'\]"):
        examples.record_path("tow")


def test_readme_states_the_records_truth():
    text = README.read_text(encoding="utf-8")
    truth = make_records.TRUTH
    assert re.search(rf"K_n = {truth['normal_drag']:g}\b", text) and re.search(
        rf"K_τ = {truth['tangential_drag']:g}\b", text
    )


def test_examples_lists_the_records_with_a_command(capsys):
    assert main(["examples"]) == 0
    out = capsys.readouterr().out
    assert "jaxcable calibrate depressor streamer --fit normal_drag=1.2 tangential_drag=0.01" in out
    assert str(examples.record_path("depressor").parent) in out


def test_calibrate_refuses_an_unknown_record_name(capsys):
    assert main(["calibrate", "no_such_record", "--fit", "normal_drag=1.2", "--no-progress"]) == 2
    err = capsys.readouterr().err
    assert "no file or bundled towing record named 'no_such_record'; bundled: depressor, streamer" in err


@pytest.mark.slow
def test_records_are_the_rigs_at_the_truth_with_two_percent_noise():
    """Each observable, less the rig's prediction at the truth, is noise of 2 % of its
    RMS (the sample standard deviation of 101 draws is within ±30 % of σ with
    overwhelming probability); at the rig's default coefficients (K_n = 1.2,
    K_τ = 0.01) some observable of each record misses by several σ."""
    records = read_records([examples.record_path(name) for name in NAMES])
    for record in records:
        rig = rig_from_conditions(record.conditions, record.name)
        inputs = {"speed": record.columns["speed"]}
        truth = rig.with_coefficients(make_records.TRUTH).predict(record.times, inputs)
        default = rig.predict(record.times, inputs)
        misses = []
        for key in ("tow_load", "depth", "layback"):
            measured, expected = record.columns[key], np.asarray(truth[key])
            sigma = make_records.NOISE * np.sqrt(np.mean(expected**2))
            spread = np.std(measured - expected)
            assert 0.7 * sigma < spread < 1.3 * sigma, (record.name, key, spread / sigma)
            misses.append(np.sqrt(np.mean((measured - np.asarray(default[key])) ** 2)) / sigma)
        assert max(misses) > 4, (record.name, misses)
