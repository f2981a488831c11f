"""MoorDyn's wave and current input files, read into jaxcable's water.

MoorDyn-C reads its water kinematics from files beside the input file, chosen by the
options `WaveKin` and `Currents` (MoorDyn's docs, *Water Kinematics*; Waves.cpp,
WaveGrid.cpp, SpectrumKin.cpp). jaxcable honours those that a sum of linear wave
components and a steady current profile can represent:

- `Currents = 1`: `current_profile.txt`, three header lines then rows `z ux [uy [uz]]`,
    interpolated linearly in z and held beyond its ends, as MoorDyn does. It becomes a
    [`jaxcable.CurrentProfile`][] when every row's horizontal velocity lies along one
    direction and uz = 0 (a uniform current when it has one row).
- `WaveKin = 7`: `wave_frequencies.txt`, rows `ω Re(Z) Im(Z) [β]` (rad/s, m, m, rad),
    the first at ω = 0; MoorDyn sums η = Σ |Z| sin(ωt − k x_β + arg Z) with Wheeler
    stretching, and so does jaxcable.
- `WaveKin = 2`: the same file, which MoorDyn first interpolates linearly onto equal
    steps of the smallest spacing, then sums as η = Σ |Z| cos(ωt − k x_β + arg Z) by an
    inverse FFT (the last, Nyquist, component at half its real part) on a grid,
    interpolated linearly in time; jaxcable sums the same components exactly.
- `WaveKin = 3`: `wave_elevation.txt`, rows `t η`, which MoorDyn resamples linearly at
    steps of `dtWave` from t = 0 (an even number of samples), transforms by FFT, and
    cuts above 0.5 Hz; jaxcable takes the same components.

MoorDyn evaluates the grids (`WaveKin = 2, 3`) at the points of `water_grid.txt` and
interpolates between them; jaxcable evaluates the sum at each node, which is what the
grid approximates. A mean level (the component at ω = 0) carries no kinematics and is
left out with a note. Other values (dynamic or 4-D current grids, externally driven or
unimplemented wave modes) stay refused as physics left out.

MoorDyn v2 has no wave spectrum of its own: its wave inputs are complex amplitudes
(`WaveKin = 2, 7`) or an elevation record (`3`), and the modes that would take more
(`4` to `6`) are not implemented (MoorDyn's docs, *Water Kinematics*). So a sea state
reaches MoorDyn as one realisation: [`write_wave_frequencies`][] writes any
[`jaxcable.WaveComponents`][] (a JONSWAP realisation from
[`jaxcable.WaveComponents.from_spectrum`][], say) as the `wave_frequencies.txt` of
`WaveKin = 7`, which MoorDyn sums with Wheeler stretching and which this reader reads
back as the same sea.
"""

from pathlib import Path
from typing import TYPE_CHECKING

import numpy as np

from ._scene import CurrentProfileSpec, SceneError, WaveComponentsSpec

if TYPE_CHECKING:  # the readers are plain numpy: the command line reads a file before it imports JAX
    from .._sea.irregular import WaveComponents

CUTOFF = 2 * np.pi * 0.5
"""MoorDyn's cut of an elevation record's spectrum (rad/s): components above 0.5 Hz
are zeroed (WaveGrid.cpp), "to avoid FFT noise getting amplified"."""


def moordyn_phase(phase: np.ndarray, *, sine: bool) -> np.ndarray:
    """θ₀ (rad) for a MoorDyn component of complex amplitude phase φ = arg Z: MoorDyn's
    summed components (`WaveKin = 7`) write η = |Z| sin(ωt − kx + φ), its FFT grids
    (`WaveKin = 2, 3`) η = |Z| cos(ωt − kx + φ); jaxcable's θ = kx − ωt + θ₀."""
    phase = np.asarray(phase, dtype=float)
    return np.pi / 2 - phase if sine else -phase


def _table(path: Path, skip: int, columns: int, what: str) -> tuple[np.ndarray, list[int]]:
    """The numeric rows of `path` after `skip` lines, at least `columns` each (missing
    trailing columns, up to 4, are zero), with their line numbers."""
    try:
        text = path.read_text(errors="replace").splitlines()
    except OSError as error:
        raise SceneError(f"{path}: cannot read {what}: {error.strerror}") from None
    rows, numbers = [], []
    for number, line in enumerate(text[skip:], start=skip + 1):
        fields = line.split()
        if not fields:
            continue
        if len(fields) < columns:
            raise SceneError(f"{path}, line {number}: {what} needs at least {columns} numbers, got {line.strip()!r}")
        try:
            values = [float(v) for v in fields[:4]]
        except ValueError:
            raise SceneError(f"{path}, line {number}: {what} has a non-numeric field in {line.strip()!r}") from None
        if not np.all(np.isfinite(values)):
            raise SceneError(f"{path}, line {number}: {what} has a non-finite value in {line.strip()!r}")
        rows.append(values + [0.0] * (4 - len(values)))
        numbers.append(number)
    if not rows:
        raise SceneError(f"{path}: {what} has no rows")
    return np.array(rows), numbers


def current_profile(path: Path) -> tuple[tuple[float, float, float], CurrentProfileSpec | None]:
    """MoorDyn's steady current profile (`Currents = 1`): a uniform current, or a
    profile along one heading.

    **Raises:**

    [`jaxcable.io.SceneError`][] naming the file and line for a malformed row, heights
    not increasing, a vertical velocity, or horizontal velocities in more than one
    direction (a turning profile, which [`jaxcable.CurrentProfile`][] cannot hold).
    """
    rows, numbers = _table(path, 3, 2, "a current profile row (z ux [uy [uz]])")
    z, horizontal, vertical = rows[:, 0], rows[:, 1:3], rows[:, 3]
    if np.any(vertical != 0):
        k = int(np.flatnonzero(vertical)[0])
        raise SceneError(
            f"{path}, line {numbers[k]}: a vertical current uz = {vertical[k]:g} m/s, which jaxcable lacks"
        )
    if len(z) == 1:
        return (float(horizontal[0, 0]), float(horizontal[0, 1]), 0.0), None
    if np.any(np.diff(z) <= 0):
        k = int(np.flatnonzero(np.diff(z) <= 0)[0]) + 1
        raise SceneError(f"{path}, line {numbers[k]}: the heights z must increase, got {z[k]:g} after {z[k - 1]:g} m")
    speeds = np.linalg.norm(horizontal, axis=1)
    strongest = horizontal[int(np.argmax(speeds))]
    if not speeds.max() > 0:
        return (0.0, 0.0, 0.0), None
    direction = strongest / np.linalg.norm(strongest)
    along = horizontal @ direction
    across = horizontal @ np.array([-direction[1], direction[0]])
    if np.any(np.abs(across) > 1e-9 * speeds.max()):
        k = int(np.argmax(np.abs(across)))
        raise SceneError(
            f"{path}, line {numbers[k]}: the current turns ({horizontal[k, 0]:g}, {horizontal[k, 1]:g}) m/s against "
            f"({strongest[0]:g}, {strongest[1]:g}) elsewhere; jaxcable's profile has one heading"
        )
    heading = float(np.degrees(np.arctan2(direction[1], direction[0])))
    return (0.0, 0.0, 0.0), CurrentProfileSpec(tuple(z.tolist()), tuple(along.tolist()), heading, f"{path}")


def spectrum(path: Path, mode: int) -> tuple[WaveComponentsSpec, list[str]]:
    """The components of `wave_frequencies.txt` for `WaveKin = mode` (2 or 7)."""
    rows, numbers = _table(path, 0, 3, "a wave frequency row (ω Re(Z) Im(Z) [β])")
    omega, amplitude, beta = rows[:, 0], rows[:, 1] + 1j * rows[:, 2], rows[:, 3]
    if omega[0] != 0.0:
        raise SceneError(f"{path}, line {numbers[0]}: the first frequency must be 0 rad/s, as MoorDyn requires")
    if len(omega) < 2:
        raise SceneError(f"{path}: at least 2 frequency components are needed, as MoorDyn requires")
    if np.any(np.abs(beta) > 2 * np.pi):
        k = int(np.argmax(np.abs(beta)))
        raise SceneError(f"{path}, line {numbers[k]}: the direction {beta[k]:g} must be in radians, within ±2π")
    if mode == 2:
        step = np.diff(omega)
        if np.any(step <= 0):
            k = int(np.flatnonzero(step <= 0)[0]) + 1
            raise SceneError(f"{path}, line {numbers[k]}: frequencies must increase for WaveKin = 2")
        dw = step.min()
        even = np.arange(int(np.floor(omega[-1] / dw)) + 1) * dw
        amplitude = np.interp(even, omega, amplitude.real) + 1j * np.interp(even, omega, amplitude.imag)
        beta = np.interp(even, omega, beta)
        omega = even
        amplitude[-1] = 0.5 * amplitude[-1].real  # the inverse FFT's Nyquist term
    notes = []
    if amplitude[0] != 0:
        notes.append(f"{path}, line {numbers[0]}: the mean level at ω = 0 ({abs(amplitude[0]):g} m) is left out")
    keep = (omega > 0) & (np.abs(amplitude) > 0)
    if not keep.any():
        raise SceneError(f"{path}: every component at ω > 0 has zero amplitude")
    spec = WaveComponentsSpec(
        tuple(np.abs(amplitude[keep]).tolist()),
        tuple((2 * np.pi / omega[keep]).tolist()),
        tuple(np.degrees(beta[keep]).tolist()),
        tuple(moordyn_phase(np.angle(amplitude[keep]), sine=mode == 7).tolist()),
        wheeler=mode == 7,
        where=str(path),
    )
    return spec, notes


def elevation_record(path: Path, step: float) -> tuple[WaveComponentsSpec, list[str]]:
    """The components of `wave_elevation.txt` for `WaveKin = 3`, resampled at `step`
    (MoorDyn's `dtWave`, s) as MoorDyn does."""
    rows, numbers = _table(path, 0, 2, "a wave elevation row (t η)")
    t, eta = rows[:, 0], rows[:, 1]
    if np.any(np.diff(t) <= 0):
        k = int(np.flatnonzero(np.diff(t) <= 0)[0]) + 1
        raise SceneError(f"{path}, line {numbers[k]}: times must increase")
    n = int(np.floor(t[-1] / step)) + 1
    n -= n % 2
    if n < 2:
        raise SceneError(f"{path}: the record ({t[-1]:g} s) is shorter than two steps of dtWave = {step:g} s")
    samples = np.interp(np.arange(n) * step, t, eta)
    transform = np.fft.rfft(samples)
    omega = np.arange(transform.size) * 2 * np.pi / (n * step)
    transform[omega > CUTOFF] = 0.0
    amplitude = 2 * transform / n
    amplitude[-1] = transform[-1].real / n  # the Nyquist term
    notes = [f"{path}: {n} samples at dtWave = {step:g} s, components above 0.5 Hz cut, as MoorDyn does"]
    if abs(amplitude[0]) > 1e-12:
        notes.append(f"{path}: the record's mean level ({amplitude[0].real / 2:g} m) is left out")
    keep = (omega > 0) & (np.abs(amplitude) > 1e-12 * np.abs(amplitude).max())
    spec = WaveComponentsSpec(
        tuple(np.abs(amplitude[keep]).tolist()),
        tuple((2 * np.pi / omega[keep]).tolist()),
        0.0,
        tuple(moordyn_phase(np.angle(amplitude[keep]), sine=False).tolist()),
        where=str(path),
    )
    return spec, notes


def write_wave_frequencies(path: str | Path, sea: "WaveComponents") -> Path:
    """Write `sea` as MoorDyn's `wave_frequencies.txt` for its summed components
    (`WaveKin = 7`): a first row at ω = 0, then one row `ω Re(Z) Im(Z) β` (rad/s, m,
    m, rad) per component in increasing ω, with |Z| = a_i and arg Z = π/2 − θ₀_i
    (MoorDyn's η = Σ |Z| sin(ωt − k x_β + arg Z) is jaxcable's Σ a_i cos(k x_β − ωt +
    θ₀_i)), to 17 significant digits. MoorDyn applies Wheeler stretching to these
    components: the sea it computes is `sea` with `wheeler=True`, which is how
    [`jaxcable.read_moordyn`][] reads the file back. Give `path` as the file beside the
    MoorDyn input file, which is where MoorDyn looks for it.

    **Returns:**

    `path`, as a `Path`.
    """
    path = Path(path)
    omega = 2 * np.pi / np.asarray(sea.periods)
    order = np.argsort(omega, kind="stable")
    angle = np.pi / 2 - np.asarray(sea.phases)[order]
    amplitude = np.asarray(sea.amplitudes)[order]
    rows = np.column_stack(
        [
            omega[order],
            amplitude * np.cos(angle),
            amplitude * np.sin(angle),
            np.radians(np.asarray(sea.headings))[order],
        ]
    )
    lines = ["0 0 0 0"] + [" ".join(f"{v:.17g}" for v in row) for row in rows]
    path.write_text("\n".join(lines) + "\n")
    return path
