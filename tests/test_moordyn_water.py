"""MoorDyn's wave and current files (`WaveKin`, `Currents`) read into jaxcable's water:
each against the closed form MoorDyn's own sources give for it (a component's
elevation, the profile's values), and each refusal named with its file and line; and a
sea state's realisation written for MoorDyn, against MoorDyn's own kinematics."""

import jax.numpy as jnp
import numpy as np
import pytest
from test_readers import OPTIONS, write_moordyn

import jaxcable as jc
from jaxcable.io import SceneError


def options(*extra):
    return (*OPTIONS, *extra)


def test_a_steady_profile_becomes_a_current_profile(tmp_path):
    # Along 30°: ux = s cos 30°, uy = s sin 30°.
    rows = "".join(
        f"{z} {s * np.cos(np.pi / 6)} {s * np.sin(np.pi / 6)} 0\n" for z, s in ((-150, 0.0), (-50, 0.6), (0, 0.8))
    )
    (tmp_path / "current_profile.txt").write_text("h\nh\nh\n" + rows)
    scene = jc.read_moordyn(write_moordyn(tmp_path, options=options("1 Currents")))
    assert scene.dropped == ()
    env = scene.build().environment
    u = np.asarray(env.water_velocity(np.array([[0.0, 0.0, -100.0], [5.0, 0.0, -25.0]]), 0.0))
    expected = np.array([0.3, 0.7])[:, None] * np.array([np.cos(np.pi / 6), np.sin(np.pi / 6), 0.0])
    np.testing.assert_allclose(u, expected, atol=1e-12)


def test_wave_frequencies_summed_as_moordyn_does(tmp_path):
    (tmp_path / "wave_frequencies.txt").write_text("0 0 0\n0.5 0.3 0.4\n0.9 0 -0.2 0.5\n")
    scene = jc.read_moordyn(write_moordyn(tmp_path, options=options("7 WaveKin")))
    wave = scene.build().environment.waves[0]
    assert wave.wheeler
    # MoorDyn (SpectrumKin.cpp): η = Σ |Z| sin(ωt − k(x cos β + y sin β) + arg Z).
    k = np.asarray(jc.airy_wavenumber(2 * np.pi / np.array([0.5, 0.9]), 150.0, 9.81))
    x, y, t = 12.0, -3.0, 4.2
    phase = 0.9 * t - k[1] * (x * np.cos(0.5) + y * np.sin(0.5)) + np.angle(-0.2j)
    eta = 0.5 * np.sin(0.5 * t - k[0] * x + np.angle(0.3 + 0.4j)) + 0.2 * np.sin(phase)
    assert float(wave.elevation(x, y, t)) == pytest.approx(eta, abs=1e-12)


def test_wave_frequencies_on_moordyns_even_grid(tmp_path):
    (tmp_path / "wave_frequencies.txt").write_text("0 0 0\n0.2 0.5 0\n0.4 0 1.0\n0.5 0 0\n")
    scene = jc.read_moordyn(write_moordyn(tmp_path, options=options("2 WaveKin")))
    wave = scene.build().environment.waves[0]
    # Interpolated onto steps of 0.1 rad/s: 0.1 → 0.25, 0.2 → 0.5, 0.3 → 0.25 + 0.5i, 0.4 → i;
    # η = Σ |Z| cos(ωt − kx + arg Z) (WaveGrid.cpp's inverse FFT), the last at half its real part.
    omega = np.array([0.1, 0.2, 0.3, 0.4])
    z = np.array([0.25, 0.5, 0.25 + 0.5j, 1j])
    t = np.linspace(0.0, 60.0, 7)
    eta = np.sum(np.abs(z)[:, None] * np.cos(omega[:, None] * t + np.angle(z)[:, None]), axis=0)
    np.testing.assert_allclose([float(wave.elevation(0.0, 0.0, s)) for s in t], eta, atol=1e-12)


def test_an_elevation_record_is_resampled_and_transformed(tmp_path):
    t = np.arange(0.0, 30.0001, 0.05)
    record = 0.7 * np.sin(2 * np.pi * t / 10.0) + 0.2 * np.cos(2 * np.pi * t / 6.0)
    (tmp_path / "wave_elevation.txt").write_text("".join(f"{a} {b}\n" for a, b in zip(t, record, strict=True)))
    scene = jc.read_moordyn(write_moordyn(tmp_path, options=options("3 WaveKin", "0.1 dtWave")))
    wave = scene.build().environment.waves[0]
    samples = np.arange(0.0, 30.0, 0.1)  # 300 samples: 30 s holds whole periods of both
    eta = [float(wave.elevation(0.0, 0.0, s)) for s in samples[::17]]
    expected = 0.7 * np.sin(2 * np.pi * samples[::17] / 10.0) + 0.2 * np.cos(2 * np.pi * samples[::17] / 6.0)
    np.testing.assert_allclose(eta, expected, atol=1e-9)


@pytest.mark.parametrize(
    "option, message", [("2 Currents", "Currents = 2 ignored"), ("5 WaveKin", "WaveKin = 5 ignored")]
)
def test_modes_jaxcable_cannot_read_stay_dropped(tmp_path, option, message):
    with pytest.warns(UserWarning):
        scene = jc.read_moordyn(write_moordyn(tmp_path, options=options(option)))
    assert any(message.split(" ignored")[0] in note for _, note in scene.dropped)


@pytest.mark.parametrize(
    "option, name, text, message",
    [
        ("1 Currents", "current_profile.txt", "h\nh\nh\n-10 0.5 0 0.1\n0 0.5 0 0\n", "line 4: a vertical current"),
        ("1 Currents", "current_profile.txt", "h\nh\nh\n-10 0.5 0 0\n0 0 0.5 0\n", "line 5: the current turns"),
        ("1 Currents", "current_profile.txt", "h\nh\nh\n0 0.5 0 0\n-10 0.5 0 0\n", "line 5: the heights z must"),
        ("7 WaveKin", "wave_frequencies.txt", "0.1 0 0\n0.5 1 0\n", "line 1: the first frequency must be 0"),
        ("7 WaveKin", "wave_frequencies.txt", "0 0 0\n0.5 x 0\n", "line 2: a wave frequency row"),
        ("7 WaveKin", "missing.txt", "", "cannot read"),
    ],
)
def test_bad_water_files_are_located(tmp_path, option, name, text, message):
    if text:
        (tmp_path / name).write_text(text)
    with pytest.raises(SceneError, match=message) as error:
        jc.read_moordyn(write_moordyn(tmp_path, options=options(option)))
    assert "system.txt, line" in str(error.value)


def test_a_realised_sea_state_reaches_moordyn(tmp_path):
    """MoorDyn has no spectrum: a JONSWAP realisation reaches it as the components of
    `WaveKin = 7`. Written by jaxcable, read back by jaxcable, and computed by MoorDyn
    itself (its elevation and velocity at a point, at its own times), it is one sea:
    jaxcable's with Wheeler stretching, as MoorDyn sums it."""
    moordyn = pytest.importorskip("moordyn")
    sea = jc.WaveComponents.from_spectrum(
        jc.Jonswap(2.0, 9.0), 150.0, seed=4, components=60, frequencies=(0.4, 3.0), heading=15.0, spreading=4.0
    )
    jc.io.write_wave_frequencies(tmp_path / "wave_frequencies.txt", sea)
    path = write_moordyn(tmp_path, options=options("7 WaveKin", "0.002 dtM"))
    read = jc.read_moordyn(path).water.waves[0].wave(150.0, 9.81)
    assert read.wheeler
    omega = 2 * np.pi / np.asarray(sea.periods)
    np.testing.assert_allclose(2 * np.pi / np.asarray(read.periods), omega, rtol=1e-15)
    np.testing.assert_allclose(read.amplitudes, sea.amplitudes, rtol=1e-15)
    np.testing.assert_allclose(np.cos(np.asarray(read.phases) - np.asarray(sea.phases)), 1.0, rtol=1e-14)
    np.testing.assert_allclose(read.headings, sea.headings, rtol=1e-14)

    stretched = jc.WaveComponents(
        sea.amplitudes, sea.periods, 150.0, headings=sea.headings, phases=sea.phases, wheeler=True
    )
    point = (12.0, -30.0, -8.0)
    system = moordyn.Create(str(path))
    try:
        moordyn.Init(system, [200.0, 0.0, 0.0], [0.0, 0.0, 0.0])
        waves, floor = moordyn.GetWaves(system), moordyn.GetSeafloor(system)
        # MoorDyn solves the dispersion relation to its own tolerance, and its time is
        # a sum of steps: agreement to 1e-8 m and m/s (of H_s = 2 m).
        t = 0.0
        for _ in range(3):
            moordyn.Step(system, [200.0, 0.0, 0.0], [0.0, 0.0, 0.0], t, 0.6)
            t += 0.6
            velocity, _, elevation, _ = moordyn.GetWavesKin(waves, *point, floor)
            assert float(stretched.elevation(point[0], point[1], t)) == pytest.approx(elevation, abs=1e-8)
            np.testing.assert_allclose(stretched.velocity(jnp.array(point), t), velocity, rtol=0, atol=1e-8)
    finally:
        moordyn.Close(system)
