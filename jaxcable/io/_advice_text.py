"""Advice in words: the text `jaxcable info` prints for an [`Advice`][jaxcable.Advice],
whose numbers the engine computes ([`jaxcable.advise`][])."""

import numpy as np

from .._advice import RESONANT_AMPLIFICATION, STABLE_STEP, Advice, resonant_amplification


def advice_lines(advice: Advice) -> list[str]:
    """An [`Advice`][jaxcable.Advice] in words, one item per line: what `jaxcable info`
    prints."""
    text = []
    for fit in advice.waves:
        uses = "which it uses" if fit.uses_fitting_theory else f"but the model uses {fit.theory}"
        fits = {
            "airy": "Airy fits",
            "cnoidal": "cnoidal fits",
            "none": "neither theory fits well",
        }[fit.fits]
        size = (
            f"irregular, H_s = {fit.height:.3g} m, its largest component at T = {fit.period:.3g} s"
            if fit.irregular
            else f"{fit.theory}, H = {fit.height:.3g} m, T = {fit.period:.3g} s"
        )
        text.append(
            f"wave {fit.index + 1} ({size}): "
            f"λ = {fit.wavelength:.4g} m, d/λ = {fit.relative_depth:.3g} ({fit.regime} water), "
            f"U = Hλ²/d³ = {fit.ursell:.3g}, H/d = {fit.height_ratio:.3g}: {fits}"
            + ("" if fit.fits == "none" else f", {uses}")
            + f" — {fit.reason}"
        )
    for check in advice.inertia:
        regime = {"drag": "drag dominates", "inertia": "inertia dominates", "both": "drag and inertia both matter"}
        text.append(
            f"{check.element} in wave {check.wave + 1}: u = {check.speed:.3g} m/s at z = {check.depth:.3g} m, "
            f"KC = uT/D = {check.keulegan_carpenter:.3g} (D = {check.diameter:.3g} m), peak inertia/drag "
            f"= {check.inertia_ratio:.3g}: {regime[check.regime]}"
        )
    if advice.drag_dominates is True and advice.fluid_inertia:
        text.append(
            "drag dominates everywhere: fluid_inertia = false would lose less than 6 % of the peak wave load "
            "and save evaluating the water's acceleration"
        )
    elif advice.drag_dominates is False and not advice.fluid_inertia:
        text.append("fluid inertia matters on some element: set fluid_inertia = true")
    text += _sea_lines(advice)
    if advice.statics_error is not None:
        text.append(f"no mean equilibrium, so no check of the segments or of slack: {advice.statics_error}")
    for d in advice.discretisation:
        verdict = "enough" if d.needed <= d.segments else f"more needed: about {d.needed}"
        text.append(
            f"line {d.line}: {d.segments} segments of {d.length / d.segments:.4g} m, largest curvature "
            f"{d.curvature:.3g} 1/m, polyline error ≤ √2/8·h²·κ = {d.deviation:.3g} m against {d.tolerance:.3g} m"
            f" allowed: {d.segments} segments {verdict}"
            + (" (a lower bound: the curvature is taken from the coarse shape)" if d.needed > d.segments else "")
        )
    if advice.rest_min_tension is not None and advice.rest_max_tension is not None and advice.slack:
        text.append(
            f"at rest the tension is {advice.rest_min_tension / 1e3:.4g} to {advice.rest_max_tension / 1e3:.4g} kN"
        )
    for c in advice.slack:
        shift = ", ".join(f"{x:.3g}" for x in c.displacement)
        if not c.converged:
            state = "no taut equilibrium: slack"
        else:
            state = f"smallest tension {c.min_tension / 1e3:.4g} kN (line {c.line})" + (": slack" if c.slack else "")
        text.append(f"point {c.point} moved by ({shift}) m: {state}")
    if advice.slack:
        if advice.slack_expected:
            text.append("slack expected, quasi-statically; dynamics (drag, inertia) make it more likely still")
        else:
            text.append("no slack quasi-statically; dynamics (drag, inertia) can still slacken a line that this misses")
        for c in advice.slack:
            if np.isfinite(c.terminal_speed) and c.speed > c.terminal_speed:
                text.append(
                    f"point {c.point} moves at up to {c.speed:.3g} m/s, faster than its lines fall sideways "
                    f"({c.terminal_speed:.3g} m/s, their terminal speed): expect slack and snap loads"
                )
                break
    for k in advice.stiffness:
        diagonal = ", ".join(f"{x / 1e3:.4g}" for x in k.diagonal)
        text.append(
            f"point {k.point}: stiffness at rest K_xx, K_yy, K_zz = {diagonal} kN/m (the lines' restoring force "
            "per metre it moves, K = −∂F/∂x; jaxcable.stiffness gives the whole matrix)"
        )
    if advice.stiffness_points and not advice.stiffness and advice.statics_error is None:
        text.append(
            f"coupled point(s) {', '.join(advice.stiffness_points)}: jaxcable info --stiffness adds their stiffness "
            "at rest (K = −∂F/∂x, MoorPy's), from jaxcable.stiffness"
        )
    text.append(
        f"stiffest axial mode: ω_n = {advice.omega:.4g} rad/s (period {2 * np.pi / advice.omega:.3g} s) at segment "
        f"{advice.segment}; with damping |λ| = {advice.eigenvalue:.4g} 1/s"
    )
    if advice.bending is not None:
        b = advice.bending
        if not np.isfinite(b.bending_length):
            reach = "a slack segment at rest: bending carries its shape there"
        elif np.isnan(b.bending_length):
            reach = "no equilibrium to measure the bending length at"
        else:
            verdict = (
                "bending shapes the line near its supports and loads, keep EI"
                if b.matters
                else "under a tenth of a segment, so EI changes the forces little and leaving it out saves its cost"
            )
            reach = (
                f"bending length √(EI/T) = {b.bending_length:.3g} m at rest against segments of "
                f"{b.segment_length:.3g} m: {verdict}"
            )
        text.append(
            f"bending stiffness EI = {b.bending_stiffness:.4g} N·m²: {reach}; its fastest mode "
            f"ω_b = 4√(EI/μ)/ℓ² = {b.omega:.4g} rad/s"
            + (", faster than the axial mode" if b.omega > advice.eigenvalue else ", slower than the axial mode")
        )
    if advice.seabed_eigenvalue > 0:
        what = {"damping": "its damping", "stiffness": "its stiffness", "friction": "friction below friction_speed"}
        text.append(
            f"seabed contact: |λ| = {advice.seabed_eigenvalue:.4g} 1/s from {what[advice.seabed_limit]}"
            + (", faster than the axial mode" if advice.seabed_eigenvalue > advice.eigenvalue else "")
        )
    steps = f", so {advice.duration:g} s needs at least ~{advice.steps:,} steps" if advice.duration is not None else ""
    text.append(
        f"an explicit solver (dopri5, tsit5) is stable for steps up to about {STABLE_STEP:g}/|λ| = "
        f"{advice.explicit_step:.3g} s" + steps
    )
    if advice.explicit_step < 1e-3:
        text.append(
            "that step is short: if the run is slow, fewer segments (--segments) lengthen it in proportion, "
            "or an implicit solver (--solver kvaerno5) removes the limit at a higher cost per step"
        )
    return text


def _sea_lines(advice: Advice) -> list[str]:
    """When the waves call for an irregular sea, and whether an irregular sea's record
    repeats within the run."""
    text = []
    periods = advice.natural_periods
    if periods:
        text.append(
            "natural periods of the mooring about its mean equilibrium (undamped, supports held): "
            + ", ".join(f"{p:.3g}" for p in periods)
            + " s"
        )
    regular = [fit for fit in advice.waves if not fit.irregular]
    for fit in regular:
        if not periods:
            break
        nearest = max(periods, key=lambda p: resonant_amplification(p, fit.period))
        gain = resonant_amplification(nearest, fit.period)
        if gain >= RESONANT_AMPLIFICATION:
            text.append(
                f"wave {fit.index + 1} (T = {fit.period:.3g} s) is near the natural period {nearest:.3g} s: an "
                f"undamped oscillator amplifies it 1/|1 − (T_n/T)²| = {gain:.3g} times, so the response hinges "
                "on damping, and a regular wave at one period can over- or understate what a sea of the same "
                'energy does: check it in an irregular sea ([[waves]] spectrum = "jonswap" at the design H_s and T_p)'
            )
    if regular:
        text.append(
            "regular waves repeat one response: a design check's most probable maximum tension needs an irregular "
            "sea over several seeds (a [[waves]] spectrum; in Python, jaxcable.sweep over the seed and "
            "SweepResult.tension_extremes)"
        )
    for fit in advice.waves:
        if not (fit.irregular and np.isfinite(fit.repeat_period)):
            continue
        repeat = f"wave {fit.index + 1} repeats after {fit.repeat_period:.4g} s (2π/Δω)"
        if advice.duration is not None and advice.duration > fit.repeat_period:
            more = advice.duration / fit.repeat_period
            text.append(
                f"{repeat}, within the run's {advice.duration:g} s: the rest repeats its statistics; for a "
                f"record of D s give at least (ω_max − ω_min) D/2π components, {more:.3g} times as many here"
            )
        elif advice.duration is not None:
            text.append(f"{repeat}, beyond the run's {advice.duration:g} s: the record does not repeat")
    return text
