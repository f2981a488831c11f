"""Dynamics against closed forms.

References, all computed here and independently of jaxcable:

- A taut string's transverse and axial natural frequencies, continuum
  f_n = n/(2ℓ) √(T/μ) (and n/(2L₀) √(EA/m) along it), and the exact eigenvalues of the
  discrete chain with lumped or consistent (1/3, 1/6) mass.
- Conservation of E = K + Π without dissipation; its monotone decay with drag.
- A body sinking on a slack tether: m_eff v̇ = F − c v², whose solution is
  v = v_t tanh(g′ t / v_t), with v_t = √(F/c), g′ = F/m_eff, for form drag
  c = ½ ρ C_D A and for Zhukov's specific-weight law c = k₀ m_o g.
- The tension laws themselves, T = (C_E ε + C_E1 ε²) H(ε), H the sharp switch or the
  smoothstep 3s² − 2s³ on s = ε/w.

`diffrax.Tsit5()` is passed explicitly throughout (these lines are soft enough for an
explicit method), and each scene is compiled once: the string simulations share one
model structure, output grid and tolerances.
"""

import diffrax
import equinox as eqx
import jax
import jax.numpy as jnp
import numpy as np
import pytest
from helpers import chain_nodes

import jaxcable as jc
from jaxcable._equations import lagrangian

RHO, G = 1025.0, 9.81
ENV = jc.Environment(water_density=RHO, gravity=G)


def energy(model, env, result):
    """E = K + Π at every output time, from jaxcable's public energy functions."""
    kinetic = jax.vmap(lambda x, v: jc.equations.kinetic_energy(model, env, x, v))(result.positions, result.velocities)
    potential = jax.vmap(lambda x: jc.equations.potential_energy(model, env, x))(result.positions)
    return np.asarray(kinetic + potential), np.asarray(kinetic)


# ---------------------------------------------------------------------------------------
# 1. Natural frequencies of a taut string.
# ---------------------------------------------------------------------------------------

SPAN, STRING_MASS, STRING_EA, PRESTRAIN, STRING_SEGMENTS = 10.0, 1.0, 1.0e4, 0.01, 30
REST_LENGTH = SPAN / (1 + PRESTRAIN)
STRING_TENSION = STRING_EA * PRESTRAIN  # 100 N
MASS_PER_SPAN = STRING_MASS * REST_LENGTH / SPAN  # μ, per stretched length
ENERGY_SEGMENTS, ENERGY_TIME = 12, 3.0  # the simulated strings


def string_model(
    n_segments,
    mass_matrix="consistent",
    slack_width=1e-5,
    area_fraction=1.0,
    rest_length=REST_LENGTH,
    diameter=0.02,
    **drag,
):
    """A horizontal string between two fixed ends. With `area_fraction = 1` it is
    neutrally buoyant (ρF = m), so it does not sag and T = EA ε₀ exactly."""
    options = dict(normal_drag=0.0, tangential_drag=0.0, normal_added_mass=0.0, tangential_added_mass=0.0)
    options.update(drag)
    line = jc.LineType(
        STRING_MASS,
        diameter,
        jc.LinearElastic(STRING_EA, slack_width=slack_width),
        area=area_fraction * STRING_MASS / RHO,
        **options,
    )
    return jc.CableNetwork.from_branches(
        np.array([[0.0, 0.0, 0.0], [SPAN, 0.0, 0.0]]),
        [jc.Branch(0, 1, line, rest_length, n_segments)],
        constraints={0: jc.Fixed(), 1: jc.Fixed()},
        mass_matrix=mass_matrix,
    )


def discrete_omegas(k, n, stiffness, element_mass, mass_matrix):
    """Exact ω of mode k of a uniform fixed–fixed chain of n elements, each of spring
    constant `stiffness` and mass `element_mass`."""
    theta = k * np.pi / n
    if mass_matrix == "lumped":
        return 2 * np.sqrt(stiffness / element_mass) * np.sin(theta / 2)
    return np.sqrt(6 * stiffness / element_mass * (1 - np.cos(theta)) / (2 + np.cos(theta)))


@pytest.fixture(scope="module", params=["consistent", "lumped"])
def string_spectrum(request):
    """Eigenvalues of ∂a_f/∂x_f at the straight equilibrium, split by direction."""
    model = string_model(STRING_SEGMENTS, request.param)
    free = model.free_nodes
    equilibrium = model.node_positions[free]
    still = jnp.zeros_like(equilibrium)

    def accelerations(x):
        return lagrangian.free_accelerations(model, ENV, 0.0, x, still)[0]

    assert np.max(np.abs(accelerations(equilibrium))) < 1e-8  # it is an equilibrium
    jacobian = np.asarray(jax.jit(jax.jacfwd(accelerations))(equilibrium))  # (free, 3, free, 3)
    blocks = {}
    for axis, name in enumerate("xyz"):
        block = jacobian[:, axis, :, axis]
        omega = np.sqrt(np.sort(-np.linalg.eigvals(block).real))
        blocks[name] = omega
    coupling = max(np.max(np.abs(jacobian[:, a, :, b])) for a in range(3) for b in range(3) if a != b)
    return request.param, blocks, coupling


def test_string_transverse_frequencies(string_spectrum):
    mass_matrix, omega, coupling = string_spectrum
    assert coupling < 1e-9  # x, y and z decouple about a straight line
    modes = np.arange(1, 4)
    continuum = modes / (2 * SPAN) * np.sqrt(STRING_TENSION / MASS_PER_SPAN)
    h = SPAN / STRING_SEGMENTS
    exact = discrete_omegas(modes, STRING_SEGMENTS, STRING_TENSION / h, MASS_PER_SPAN * h, mass_matrix)
    for name in "yz":  # both transverse planes
        frequency = omega[name][:3] / (2 * np.pi)
        np.testing.assert_allclose(frequency, continuum, rtol=0.01)
        np.testing.assert_allclose(omega[name][:3], exact, rtol=1e-8)
        # Consistent mass errs high, lumped low, each by about (nπ/N)²/24.
        sign = 1 if mass_matrix == "consistent" else -1
        assert np.all(sign * (frequency - continuum) > 0)


def test_string_axial_frequencies(string_spectrum):
    """Along the string the stiffness is dT/dS = EA/ℓ per segment, on m ℓ of mass (ℓ the
    unstretched segment length): f_n = n/(2L₀) √(EA/m) in the continuum."""
    mass_matrix, omega, _ = string_spectrum
    modes = np.arange(1, 4)
    continuum = modes / (2 * REST_LENGTH) * np.sqrt(STRING_EA / STRING_MASS)
    piece = REST_LENGTH / STRING_SEGMENTS
    exact = discrete_omegas(modes, STRING_SEGMENTS, STRING_EA / piece, STRING_MASS * piece, mass_matrix)
    np.testing.assert_allclose(omega["x"][:3] / (2 * np.pi), continuum, rtol=0.01)
    np.testing.assert_allclose(omega["x"][:3], exact, rtol=1e-8)


def test_string_mode_one_period_by_simulation():
    """Released from rest in its first mode shape, the midpoint crosses zero every half
    period. (12 segments, the energy tests' model, so that it compiles once: the
    discrete period is then 0.3 % off the continuum's.)"""
    n = ENERGY_SEGMENTS
    model = string_model(n)
    positions = np.asarray(model.node_positions).copy()
    amplitude = 0.01  # m: linear, 1e-3 of the span
    positions[:, 1] = amplitude * np.sin(np.pi * positions[:, 0] / SPAN)
    h = SPAN / n
    period_discrete = 2 * np.pi / discrete_omegas(1, n, STRING_TENSION / h, MASS_PER_SPAN * h, "consistent")
    period_continuum = 2 * SPAN / np.sqrt(STRING_TENSION / MASS_PER_SPAN)
    t1 = 2.05 * period_continuum
    result = simulate_string(model, jc.State(positions, np.zeros_like(positions)), t1)
    ts = np.asarray(result.times)
    y = np.asarray(result.positions)[:, chain_nodes(n)[n // 2], 1]
    crossing = np.flatnonzero(np.sign(y[:-1]) * np.sign(y[1:]) < 0)
    # Linear interpolation is exact to O(Δt³) at a zero crossing, where y'' = 0.
    times = ts[crossing] - y[crossing] * (ts[crossing + 1] - ts[crossing]) / (y[crossing + 1] - y[crossing])
    assert len(times) == 4
    period = 2 * np.mean(np.diff(times))
    np.testing.assert_allclose(period, period_continuum, rtol=0.01)
    np.testing.assert_allclose(period, period_discrete, rtol=5e-4)
    # The first crossing is a quarter period in.
    np.testing.assert_allclose(times[0], period_discrete / 4, rtol=1e-3)


# ---------------------------------------------------------------------------------------
# 2. Energy: conserved without dissipation, decaying with drag.
# ---------------------------------------------------------------------------------------


def perturbed(model):
    """A large, asymmetric perturbation of the straight string, at rest."""
    positions = np.asarray(model.node_positions).copy()
    x = positions[:, 0] / SPAN
    positions[:, 1] = 0.5 * np.sin(np.pi * x) + 0.2 * np.sin(2 * np.pi * x)
    positions[:, 2] = 0.15 * np.sin(3 * np.pi * x)
    return jc.State(positions, np.zeros_like(positions))


def simulate_string(model, initial, t1=ENERGY_TIME):
    """Every string simulation shares these options (and so one compilation per mass
    matrix): 61 outputs, Tsit5 at rtol = atol = 1e-8."""
    ts = np.linspace(0.0, t1, 61)
    config = jc.SolverConfig(diffrax.Tsit5(), rtol=1e-8, atol=1e-8)
    return jc.simulate(model, ENV, t1, ts=ts, initial=initial, solver=config)


def run_energy(model):
    result = simulate_string(model, perturbed(model))
    return result, *energy(model, ENV, result)


@pytest.mark.parametrize(
    "slack_width, added_mass",
    [(0.0, 0.0), (1e-5, 0.0), (1e-5, 1.0)],
    ids=["sharp", "smoothed", "isotropic-added-mass"],
)
def test_energy_conserved_without_dissipation(slack_width, added_mass):
    """A sinking (half-buoyant) pre-tensioned string, perturbed and released, with no
    drag and no damping: K + Π is constant. Isotropic added mass (C_a = C_aτ) keeps the
    mass matrix independent of the shape, so it conserves the same energy."""
    model = string_model(
        ENERGY_SEGMENTS,
        slack_width=slack_width,
        area_fraction=0.5,
        normal_added_mass=added_mass,
        tangential_added_mass=added_mass,
    )
    result, total, kinetic = run_energy(model)
    assert kinetic.max() > 5.0  # J: a large motion, comparable to E itself
    drift = np.max(np.abs(total - total[0]))
    assert drift < 1e-5 * kinetic.max(), drift


def test_energy_balance_with_anisotropic_added_mass():
    """Added mass normal to the line only (C_a = 1, C_aτ = 0, MoorDyn's convention) acts as
    Morison's inertia force, −m_a R̈_n, through its virtual work: the equations are
    M(x) a = −∇Π with M depending on the segments' directions. Then
    d(½ vᵀMv + Π)/dt = ½ vᵀ Ṁ v exactly, so K + Π is not conserved; its change must equal
    the time integral of ½ vᵀ Ṁ v, with Ṁ v computed here as a directional derivative."""
    model = string_model(ENERGY_SEGMENTS, area_fraction=0.5, normal_added_mass=1.0, tangential_added_mass=0.0)
    # The power oscillates with the string's axial modes: integrate it on dense outputs.
    ts = np.linspace(0.0, ENERGY_TIME, 6001)
    config = jc.SolverConfig(diffrax.Tsit5(), rtol=1e-8, atol=1e-8)
    result = jc.simulate(model, ENV, ENERGY_TIME, ts=ts, initial=perturbed(model), solver=config)
    total, kinetic = energy(model, ENV, result)

    def power(positions, velocities):
        _, m_dot_v = jax.jvp(
            lambda x: lagrangian.inertial_forces(model, ENV, x, velocities), (positions,), (velocities,)
        )
        return 0.5 * jnp.sum(velocities * m_dot_v)

    p = np.asarray(jax.vmap(power)(result.positions, result.velocities))
    t = np.asarray(result.times)
    work = np.concatenate([[0.0], np.cumsum(0.5 * (p[1:] + p[:-1]) * np.diff(t))])
    change = total - total[0]
    assert np.max(np.abs(change)) > 1e-4 * kinetic.max()  # the effect is real and measurable
    np.testing.assert_allclose(change, work, atol=0.02 * np.max(np.abs(work)))


@pytest.mark.parametrize("mass_matrix", ["consistent", "lumped"])
def test_energy_conserved_through_slack_and_snap(mass_matrix):
    """A string 2 % longer than its span, released straight (every segment compressed):
    it falls slack, snaps taut and rebounds, with the sharp switch. The tension-only law
    is still conservative, so E stays constant."""
    model = string_model(
        ENERGY_SEGMENTS, mass_matrix=mass_matrix, slack_width=0.0, area_fraction=0.5, rest_length=1.02 * SPAN
    )
    positions = np.asarray(model.node_positions).copy()
    positions[:, 0] = np.concatenate([[0.0, SPAN], np.linspace(0.0, SPAN, ENERGY_SEGMENTS + 1)[1:-1]])
    positions[:, 1] = 0.5 * np.sin(np.pi * positions[:, 0] / SPAN)
    positions[:, 2] = 0.0
    result = simulate_string(model, jc.State(positions, np.zeros_like(positions)))
    total, kinetic = energy(model, ENV, result)
    strain = np.asarray(result.strain)
    assert np.all(strain[0] < 0) and strain.max() > 0.01  # slack at first, then snapped taut
    assert np.max(np.abs(total - total[0])) < 1e-5 * kinetic.max()


def test_energy_decays_with_drag():
    """The same string with normal and tangential drag in still water: E never rises
    between outputs, and drag removes most of the perturbation's energy."""
    model = string_model(ENERGY_SEGMENTS, area_fraction=0.5, diameter=0.05, normal_drag=1.2, tangential_drag=0.008)
    result, total, kinetic = run_energy(model)
    step = np.diff(total)
    assert np.all(step <= 1e-7 * np.abs(total).max()), step.max()
    assert np.all(step[:10] < 0)  # strictly, while it is moving fast
    assert total[-1] < total[0] - 0.2 * kinetic.max()


# ---------------------------------------------------------------------------------------
# 3. Terminal sinking velocity of a body on a slack tether.
# ---------------------------------------------------------------------------------------

BODY_MASS, BODY_VOLUME, ADDED_MASS = 100.0, 0.02, 1.0
NET_WEIGHT = (BODY_MASS - RHO * BODY_VOLUME) * G
EFFECTIVE_MASS = BODY_MASS + ADDED_MASS * RHO * BODY_VOLUME
TETHER = 1000.0  # m: slack throughout the few metres the body sinks


def sinking_model(body):
    """One free node 1 m below a fixed one, tied by a 1000 m, neutrally buoyant,
    drag-free thread of 1 g/km: the thread never tightens and its mass is negligible."""
    mass = 1e-6
    line = jc.LineType(
        mass,
        1e-4,
        jc.LinearElastic(1.0),
        area=mass / RHO,
        normal_drag=0.0,
        tangential_drag=0.0,
        normal_added_mass=0.0,
        tangential_added_mass=0.0,
    )
    return jc.CableNetwork(
        np.array([[0.0, 0.0, 0.0], [0.0, 0.0, -1.0]]),
        np.array([[0, 1]]),
        [TETHER],
        line,
        constraints={0: jc.Fixed()},
        bodies={1: body},
    )


@pytest.fixture(scope="module")
def sinking():
    drag_area = 0.5
    specific_drag, organism_mass = 0.5, 30.0
    cases = {
        "form drag": (
            jc.Body(mass=BODY_MASS, volume=BODY_VOLUME, drag_area=drag_area, added_mass=ADDED_MASS),
            0.5 * RHO * drag_area,
        ),
        "Zhukov": (
            jc.Body(
                mass=BODY_MASS,
                volume=BODY_VOLUME,
                specific_drag=specific_drag,
                organism_mass=organism_mass,
                added_mass=ADDED_MASS,
            ),
            specific_drag * organism_mass * G,
        ),
    }
    ts = np.linspace(0.0, 3.0, 61)
    out = {}
    for name, (body, coefficient) in cases.items():
        model = sinking_model(body)
        result = jc.simulate(
            model, ENV, 3.0, ts=ts, initial="rest", solver=jc.SolverConfig(diffrax.Tsit5(), rtol=1e-10, atol=1e-10)
        )
        out[name] = (result, coefficient)
    return ts, out


@pytest.mark.parametrize("law", ["form drag", "Zhukov"])
def test_terminal_velocity(sinking, law):
    ts, cases = sinking
    result, coefficient = cases[law]
    terminal = np.sqrt(NET_WEIGHT / coefficient)  # √(2(M − ρV)g/(ρ C_D A)), √((M − ρV)/(k₀ m_o))
    reduced = NET_WEIGHT / EFFECTIVE_MASS
    assert np.all(np.asarray(result.strain) < -0.99)  # the tether stayed slack
    assert np.all(np.asarray(result.tension) == 0.0)
    velocity = np.asarray(result.velocities)[:, 1]
    depth = np.asarray(result.positions)[:, 1, 2]
    np.testing.assert_allclose(velocity[:, :2], 0.0, atol=1e-12)
    np.testing.assert_allclose(-velocity[:, 2], terminal * np.tanh(reduced * ts / terminal), rtol=1e-5, atol=1e-9)
    sunk = terminal**2 / reduced * np.log(np.cosh(reduced * ts / terminal))
    np.testing.assert_allclose(-1.0 - depth, sunk, rtol=1e-5, atol=1e-9)
    assert -velocity[-1, 2] > 0.99 * terminal  # it reached terminal velocity


# ---------------------------------------------------------------------------------------
# 4. Slack and snap under a hard-driven top.
# ---------------------------------------------------------------------------------------

C_E, C_E1 = 1.0e6, 1.0e5  # N
SNAP_ANCHOR, SNAP_FAIRLEAD = np.array([0.0, 0.0, -50.0]), np.array([30.0, 0.0, 0.0])
SNAP_TIME = 4.0


@pytest.fixture(scope="module")
def snap_runs():
    chord = SNAP_FAIRLEAD - SNAP_ANCHOR
    length = np.linalg.norm(chord)
    runs = {}
    solve = eqx.filter_jit(jc.solve_statics)
    for width in (0.0, 1e-3):
        line = jc.LineType(3.0, 0.05, jc.NonlinearElastic(C_E, C_E1, slack_width=width))
        model = jc.CableNetwork.from_branches(
            np.stack([SNAP_ANCHOR, SNAP_FAIRLEAD]),
            [jc.Branch(0, 1, line, 0.995 * length, 10)],
            # 1 m along the chord towards the anchor: twice the static stretch.
            constraints={0: jc.Fixed(), 1: jc.Harmonic(1.0, 4.0, direction=-chord)},
        )
        static = solve(model, ENV)
        ts = np.linspace(0.0, SNAP_TIME, 401)
        config = jc.SolverConfig(diffrax.Tsit5(), rtol=1e-7, atol=1e-7)
        result = jc.simulate(model, ENV, SNAP_TIME, ts=ts, initial=static.state, solver=config)
        runs[width] = (static, result)
    return runs


@pytest.mark.parametrize("width", [0.0, 1e-3], ids=["sharp", "smoothed"])
def test_tension_law_through_slack(snap_runs, width):
    static, result = snap_runs[width]
    strain, tension = np.asarray(result.strain), np.asarray(result.tension)
    slack = strain <= 0
    assert slack.mean() > 0.05  # the line really goes slack
    assert np.all(tension[slack] == 0.0)  # tension-only, exactly
    taut = strain >= width if width > 0 else strain > 0
    # The run's strain is `stretched / length - 1`, and the law is applied to that
    # difference as computed inside the run's program, which may round it differently from
    # the strain it outputs by a few ε: the laws below agree to that, the law's slope
    # (at most 2 C_E in the smoothing band) times 4ε.
    atol = 2 * C_E * 4 * np.finfo(float).eps
    np.testing.assert_allclose(tension[taut], C_E * strain[taut] + C_E1 * strain[taut] ** 2, rtol=1e-12, atol=atol)
    if width > 0:
        band = (strain > 0) & (strain < width)
        assert band.sum() > 10  # the smoothing band is visited
        assert np.all((tension[band] >= 0) & (tension[band] <= C_E * width + C_E1 * width**2))
        s = strain[band] / width
        law = (C_E * strain[band] + C_E1 * strain[band] ** 2) * s * s * (3 - 2 * s)
        np.testing.assert_allclose(tension[band], law, rtol=1e-12, atol=atol)


@pytest.mark.parametrize("width", [0.0, 1e-3], ids=["sharp", "smoothed"])
def test_snap_after_slack(snap_runs, width):
    """After its first slack interval the top segment re-tensions, snapping well above
    its static tension."""
    static, result = snap_runs[width]
    top_static = float(static.tension[-1])
    assert top_static > 0
    top = np.asarray(result.tension)[:, -1]
    slack = np.flatnonzero(top == 0.0)
    assert slack.size > 0
    after = np.flatnonzero(np.arange(top.size) > slack[0])
    retensioned = after[top[after] > 0]
    assert retensioned.size > 0 and top[retensioned[0] :].max() > 1.5 * top_static
