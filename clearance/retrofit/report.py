"""retrofit.md: every change a retrofit made, how it sized each bearing, and what it costs."""

from __future__ import annotations

import math

import mujoco
import numpy as np

from clearance.contact_calibration.fit import GOALS
from clearance.options import ContactMode
from clearance.retrofit.insertion import bearing_frame_name
from clearance.retrofit.manifest import ROBOT_STEP_BOUND
from clearance.retrofit.masses import PIN_INERTIA, body_label
from clearance.retrofit.pipeline import Retrofit, RetrofittedHinge
from clearance.retrofit.play import DEFAULT_CLASS, SineControl
from clearance.retrofit.sizing import STEP_OMEGA_H
from clearance.retrofit.softness import MAX_IMPEDANCE

__all__ = ["retrofit_report"]


def _g(x: float, digits: int = 4) -> str:
    return f"{x:.{digits}g}"


def _vec(v: np.ndarray) -> str:
    return "(" + ", ".join(f"{float(x):.4g}" for x in v) + ")"


def _control_text(r: Retrofit) -> str:
    control = r.options.control
    if isinstance(control, SineControl):
        return (
            f"a sinusoid on every actuator (amplitude {_g(control.amplitude)} of each control range's half-width, "
            f"{_g(control.frequency)} Hz)"
        )
    return f"the control table {control.source or ''} ({len(control.times)} rows, linear in between, held beyond)"


def _hinge_rows(r: Retrofit) -> list[str]:
    rows = [
        "| hinge | journal body (child) | bearing body (parent) | axis (child frame) | c [mm] | R_B [mm] "
        "| bearing E [GPa], ν | journal E [GPa], ν | restitution | friction | law | initial eccentricity [mm] |",
        "|---|---|---|---|---|---|---|---|---|---|---|---|",
    ]
    for h in r.hinges.values():
        c = h.play.clearance
        e = h.play.initial_eccentricity
        rows.append(
            f"| {h.name} | {h.elements.journal_body} | {h.elements.bearing_body} | {_vec(h.frame.axes[:, 2])} "
            f"| {_g(c.radial_clearance * 1e3)} | {_g(c.bearing_radius * 1e3)} "
            f"| {_g(c.bearing_material.youngs_modulus / 1e9)}, {_g(c.bearing_material.poisson_ratio)} "
            f"| {_g(c.journal_material.youngs_modulus / 1e9)}, {_g(c.journal_material.poisson_ratio)} "
            f"| {_g(c.restitution)} | {_g(c.friction)} | {c.law.value} | ({_g(e[0] * 1e3)}, {_g(e[1] * 1e3)}) |"
        )
    return rows


def _pin(h: RetrofittedHinge, r: Retrofit) -> list[str]:
    """The pin and the moved connect of a loop closure."""
    el, axes, pin = h.elements, h.frame.axes, h.pin
    assert pin is not None  # a loop closure always has its pin
    share, soft = pin.share, pin.softness
    donor = body_label(r.twin, share.donor)
    kept = (
        "the twin's regularisation R = (1 - d)/d Â and its K and B kept"
        if soft.softer <= 1 + 1e-9
        else f"{soft.softer:.3g}x the twin's regularisation: the impedance stopped at MuJoCo's largest, "
        f"{MAX_IMPEDANCE:g}"
    )
    return [
        f"- body: the pin `{el.journal_body}`, a child of {el.bearing_body} at the connect's anchor "
        f"{_vec(np.asarray(h.frame.bearing.origin))} ({el.bearing_body} frame): a point mass of "
        f"{_g(share.pin_mass)} kg "
        f"({_g(share.share * 100)} % of body {donor}'s mass, cut from it at the anchor: {donor} now weighs "
        f"{_g(share.remainder.mass)} kg, and {donor} + pin is the original body in mass, centre of mass and inertia, "
        f"checked) with an isotropic inertia of {_g(PIN_INERTIA)} kg m² (MuJoCo needs one; cut from {donor} too)",
        f"- joints: slides `{el.slides[0]}` (axis {_vec(axes[:, 0])}) and `{el.slides[1]}` (axis {_vec(axes[:, 1])}) "
        "in the pin, no armature",
        f"- equality: the connect `{h.name}` ties body1's anchor to the pin instead of {el.bearing_body}; solimp "
        f"({', '.join(_g(v) for v in soft.solimp)}) and solref ({', '.join(_g(v) for v in soft.solref)}): the pin "
        "raises "
        f"the rows' inverse weight Â from {_g(soft.inverse_weight[0])} to {_g(soft.inverse_weight[1])} 1/kg, so the "
        f"impedance is raised with it ({kept}); every other attribute kept",
    ]


def _added(h: RetrofittedHinge, r: Retrofit) -> list[str]:
    el = h.elements
    n = len(el.segments)
    axes = h.frame.axes
    joints = (
        _pin(h, r)
        if h.hinge.is_connect
        else [
            f"- joints: slides `{el.slides[0]}` (axis {_vec(axes[:, 0])}) and `{el.slides[1]}` (axis "
            f"{_vec(axes[:, 1])}) in body {el.journal_body}, before the hinge, at the hinge position "
            f"{_vec(np.asarray(h.frame.journal.origin))} (child frame); the hinge `{h.name}` keeps every attribute "
            "and its default class",
        ]
    )
    head = [
        f"### {h.name}",
        "",
        *joints,
        f"- sites: `{el.journal_site}` (body {el.journal_body}), `{el.bearing_site}` (body {el.bearing_body}, at "
        f"{_vec(np.asarray(h.frame.bearing.origin))} in its frame), both with the bearing frame's axes; the bearing "
        f"site{' and the ring' if h.ring is not None else ''} in the frame `{bearing_frame_name(h.name)}` centred on "
        "the bearing (MuJoCo writes 6 digits: the ring's offsets from its centre keep them to 5e-8 m; checked after "
        "writing, within 1 % of c)",
    ]
    if h.stop is not None:
        return [
            *head,
            f"- stop: the spatial tendon `{el.sensors[1].removesuffix('_force')}` from `{el.bearing_site}` to "
            f"`{el.journal_site}` (length |e|), limited to [0, {_g(h.stop.clearance)}] m: a circle-in-circle stop in "
            f"MuJoCo's solver, solref {_vec(np.asarray(h.stop.stop.solref))}, solimp "
            f"{_vec(np.asarray(h.stop.stop.solimp))}; no geoms, no pairs, no friction",
            f"- sensors: `{el.sensors[0]}` (journal centre in the bearing frame), `{el.sensors[1]}` (the stop's force)",
            "",
        ]
    if h.ring is None:
        return [
            *head,
            f"- contact: the compiled plugin instance `{el.sensors[1]}` (clearance.journal_bearing) between the two "
            "sites: the exact circle geometry and the contact law, no geoms and no pairs",
            f"- sensors: `{el.sensors[0]}` (journal centre in the bearing frame), `{el.sensors[1]}` (the plugin's "
            "normal and tangential force, penetration, approach speed, work)",
            "",
        ]
    return [
        *head,
        f"- geoms: journal `{el.journal_geom}` (body {el.journal_body}); {n} ring segments `{el.segments[0]}` … "
        f"`{el.segments[-1]}` (body {el.bearing_body}); all massless, contype = conaffinity = 0",
        f"- pairs: {n}, `{el.pairs[0]}` … `{el.pairs[-1]}`, journal against each segment only",
        f"- sensors: `{el.sensors[0]}` (journal centre in the bearing frame), `{el.sensors[1]}` (net contact force "
        "on the journal)",
        "",
    ]


def _sizing_rows(r: Retrofit) -> list[str]:
    rows = [
        "| hinge | median load [N] | peak load [N] | effective mass [kg] (min–max) | impact speed [m/s] "
        "| typical penetration [µm] | divergence bound [µm] | segments | force ripple | ω [rad/s] | ω h |",
        "|---|---|---|---|---|---|---|---|---|---|---|",
    ]
    for h in r.hinges.values():
        s = h.sizing
        lo, hi = s.effective_mass_range
        # a robot-step stop: its own frequency and divergence bound (the bearing's are for the exact contact)
        omega = s.omega if h.stop is None else h.stop.stop.omega
        bound = s.penetration_limit if h.stop is None else ROBOT_STEP_BOUND * h.stop.penetration
        rows.append(
            f"| {h.name} | {_g(s.median_load)} | {_g(s.peak_load)} | {_g(s.effective_mass)} ({_g(lo)}–{_g(hi)}) "
            f"| {_g(s.impact_speed)} | {_g(s.typical_penetration * 1e6)} | {_g(bound * 1e6)} "
            f"| {s.segments} | {'–' if math.isnan(s.ripple) else f'{s.ripple:.1%}'} | {_g(omega)} "
            f"| {_g(omega * r.timestep, 3)} |"
        )
    return rows


def _contact_rows(r: Retrofit) -> list[str]:
    rows = [
        "| hinge | row stiffness k [N/m] | row damping b [N s/m] | impedance rise ε | worst peak-force error "
        "| worst restitution error | source |",
        "|---|---|---|---|---|---|---|",
    ]
    for h in r.hinges.values():
        p = h.contact.parameters
        cal = h.contact.calibration
        if cal is not None and cal.rows:
            fpk = max((row.peak_force_worst for row in cal.rows), key=abs)
            rest = max((row.restitution_worst for row in cal.rows), key=abs)
            errs = f"{fpk:+.1%} | {rest:+.3f}"
        else:
            errs = "– | –"
        rows.append(
            f"| {h.name} | {_g(p.stiffness)} | {_g(p.damping)} | {_g(p.impedance_rise, 3)} | {errs} | {p.source} |"
        )
    return rows


def _speed_rows(r: Retrofit) -> list[str]:
    if r.speed is None:
        return ["Not measured."]
    u, m = r.speed.unmodified, r.speed.retrofitted
    return [
        "| model | time step [s] | steps/s | simulated s per wall s |",
        "|---|---|---|---|",
        f"| unmodified | {_g(u.timestep)} | {u.steps_per_second:,.0f} | {_g(u.realtime)} |",
        f"| retrofitted | {_g(m.timestep)} | {m.steps_per_second:,.0f} | {_g(m.realtime)} |",
        "",
        f"One step of the retrofitted model takes {_g(r.speed.per_step, 3)}x as long as one of the unmodified "
        f"model; one simulated second takes {_g(r.speed.per_simulated_second, 3)}x as long (its step is "
        f"{_g(u.timestep / m.timestep, 3)}x smaller).",
    ]


def _kept(r: Retrofit, asset_changes: list[str]) -> list[str]:
    t, m = r.twin, r.model
    nh = len(r.hinges)
    n_geoms = sum(1 + len(h.elements.segments) for h in r.hinges.values() if h.ring is not None)
    assets = "; ".join(asset_changes) if asset_changes else "no asset folder needed rewriting"
    return [
        f"- bodies: {t.nbody} → {m.nbody}; every body's mass, inertia and inertial frame compiled equal "
        "(checked: new geoms and sites add no mass)"
        + ("; the pins of loop closures are the bodies added, each cut from its donor" if m.nbody > t.nbody else ""),
        f"- joints: {t.njnt} → {m.njnt} (+2 slides per hinge or pin); nq {t.nq} → {m.nq}, nv {t.nv} → {m.nv}",
        f"- geoms: {t.ngeom} → {m.ngeom} (+{n_geoms}); sites: {t.nsite} → {m.nsite} (+{2 * nh}); "
        f"pairs: {t.npair} → {m.npair}",
        f"- actuators: {t.nu} → {m.nu}; sensors: {t.nsensor} → {m.nsensor} (+{2 * nh}, after the model's own); "
        f"tendons: {t.ntendon} → {m.ntendon}; equality constraints: {t.neq} → {m.neq}",
        f"- keyframes: {r.keyframes}, each extended: the slides' qpos at the initial eccentricity, their qvel 0",
        f"- default classes: the model's own, plus `{DEFAULT_CLASS}` (MuJoCo's built-in values) for everything added",
        f"- assets: {assets}; `<include>`d files are written inline",
        f"- integrator: {r.integrator} (kept); time step {_g(float(t.opt.timestep))} s → "
        f"{_g(r.timestep)} s; every other option kept",
    ]


def _accuracy(r: Retrofit) -> list[str]:
    """What each ring states, and the rings kept although they miss it (a robot-step stop: its fit and share of c)."""
    stops = [h.stop for h in r.hinges.values() if h.stop is not None]
    if stops:
        return [
            "Each stop's damping is fitted to the law's rebound at its effective mass and closing speed; its "
            "deepest penetration is at most 20 % of c at that speed (else refused):",
            "",
            "| hinge | closing speed [m/s] | ζ | rebound error | impulse error | penetration / c | smallest c [µm] "
            "| largest step [ms] |",
            "|---|---|---|---|---|---|---|---|",
            *[
                f"| {s.hinge} | {_g(s.closing_speed, 3)} | {_g(s.stop.dampratio, 3)} | {s.stop.rebound_error:+.1%} "
                f"| {s.stop.impulse_error:+.1%} | {s.penetration / s.clearance:.1%} | {_g(s.smallest_clearance * 1e6)} "
                f"| {_g(s.largest_step * 1e3, 3)} |"
                for s in stops
            ],
            "",
        ]
    if r.options.contact_mode is ContactMode.EXACT:
        return []
    stated = (
        f"Each ring states its accuracy: a force ripple with journal direction below {r.options.ripple_limit:.1%} over "
        "half to twice its typical penetration"
        + (
            f", and a calibration within {GOALS['peak_force']:.0%} in peak force, {GOALS['max_penetration']:.0%} in "
            f"penetration, {GOALS['duration']:.0%} in duration and {GOALS['restitution']:g} in restitution at every "
            "fitted impact speed"
            if r.options.contact_mode is ContactMode.CALIBRATED
            else ""
        )
        + "; a ring that misses is refused unless --accept-inaccurate keeps it."
    )
    if not r.warnings:
        return [stated, ""]
    return [stated, "", "**Accuracy not met:**", "", *[f"- {w}" for w in r.warnings], ""]


def retrofit_report(r: Retrofit, *, source: str = "", command: str = "", asset_changes: list[str] | None = None) -> str:
    """The Markdown report of a retrofit.

    Args:
        r: the retrofit.
        source: the model file it was read from.
        command: the command line that made it.
        asset_changes: the asset folders rewritten for the output folder.
    """
    name = r.twin_spec.modelname or "model"
    h0 = float(r.twin.opt.timestep)
    lines = [f"# Retrofit of {name}" + (f" ({source})" if source else ""), ""]
    if command:
        lines += ["```", command, "```", ""]
    lines += [
        "**Planar play only: no tilt.** Each journal moves in the plane normal to its hinge axis; it cannot tilt "
        "in its bearing or move along the axis, which the hinge still holds (a loop closure's pin moves in the plane "
        "normal to the axis of a hinge of its bodies; the connect holds it along that axis).",
        "",
        (
            "Robot-step mode (stock MuJoCo): each journal held within c by a tendon-limit stop at the robot's step "
            "(clearance.retrofit.radial_stop): no ring, no friction, a linear stop far softer than the bearing."
            if r.options.robot_step is not None
            else f"Ring mode (portable MJCF, stock MuJoCo), contact {r.options.contact_mode.value}; "
            f"{r.options.journal_geom.value} journal, {r.options.segment_geom.value} segments."
        ),
        "",
        *_accuracy(r),
        "## Hinges given radial play",
        "",
        *_hinge_rows(r),
        "",
        "## Added",
        "",
        *[line for h in r.hinges.values() for line in _added(h, r)],
        "## Sizing",
        "",
        f"From {len(r.motion.times)} steps ({_g(len(r.motion.times) * h0, 3)} s) of the unmodified model at its own "
        f"step under {_control_text(r)}: the in-plane hinge load (MuJoCo's cfrc_int), "
        "and the effective mass along it in the retrofitted model with its equality constraints held.",
        "",
        *_sizing_rows(r),
        "",
        "## Contact",
        "",
        *_contact_rows(r),
        "",
        "## Time step",
        "",
        f"{_g(r.timestep)} s (the model's own: {_g(h0)} s): "
        + (
            "given"
            if r.options.timestep is not None or r.options.robot_step is not None
            else f"the largest 1, 2 or 5 x 10^k s with ω h <= {STEP_OMEGA_H} at every bearing, at most the "
            "model's own step"
        )
        + "; the run's stability limit is ω h < 2.",
        "",
        "## Speed cost",
        "",
        *_speed_rows(r),
        "",
        "## Kept",
        "",
        *_kept(r, asset_changes or []),
        "",
    ]
    if r.notes:
        lines += ["## Notes", "", *[f"- {n}" for n in r.notes], ""]
    phases = ", ".join(f"{phase} {t:.2f} s" for phase, t in r.timings.items())
    lines += [f"MuJoCo {mujoco.__version__}. Wall time: {phases}."]
    return "\n".join(lines) + "\n"
