"""The report of a backlash retrofit (``retrofit.md``): what was added, and each stop against its law.

For every hinge: the motor side that took its actuators, the band, and the stop at its ends;
for a calibrated stop the mesh law (K, cₑ, n), the effective inertia along the band, the
closing speeds fitted over (a decade around the stated estimate), the emitted solreflimit and
solimplimit, and a table of the stop's peak torque and restitution against the law's at each
speed; for an exact stop, the mesh law and that the compiled plugin computes it; for the
recipe, that the stop is MuJoCo's default limit. The time step, where the calibrated or exact
stops lowered it, is stated with the twin's.
"""

from __future__ import annotations

import math
from collections.abc import Sequence

from clearance.contact_calibration.torsional_stop import GOAL, OMEGA_H, STOP_IMPEDANCE
from clearance.retrofit.backlash import BacklashHinge, BacklashRetrofit
from clearance.retrofit.backlash_stop import POSE_SAMPLES
from clearance.retrofit.play import DEFAULT_MESH_RESTITUTION, DEFAULT_MESH_STIFFNESS
from clearance.retrofit.robot_step import ROBOT_STEP_STOP
from clearance.retrofit.step_stop import STEP_SPAN

__all__ = ["backlash_report"]

_LAW = (
    "T = K d^n [1 + 3(1 - e^2)/4 * d'/d'0], d = |q_load - q_motor| - b (Lankarani-Nikravesh in angular form, "
    "`clearance.contact_calibration.laws.mesh_torque`; n = 1 for a gear mesh)"
)


def _hinge_rows(hinges: Sequence[BacklashHinge]) -> list[str]:
    lines = [
        "| hinge | b [arcmin] | motor hinge | motor body | dead-band tendon | actuators moved | motor armature "
        "[kg m^2] | sensors moved to the motor side |",
        "|---|---|---|---|---|---|---|---|",
    ]
    for h in hinges:
        lines.append(
            f"| {h.name} | {math.degrees(h.backlash.half_width) * 60:.4g} | {h.motor_joint} | {h.motor_body} | "
            f"{h.tendon} | {', '.join(h.actuators)} | {h.motor_armature:.4g} ({h.armature_source}) | "
            f"{', '.join(h.moved_sensors) or 'none'} |"
        )
    return lines


def _stop_rows(hinges: Sequence[BacklashHinge]) -> list[str]:
    lines = [
        "| hinge | stop | K [N m/rad] | e | n | J along the band [kg m^2] | impact speed [rad/s] | fitted spring "
        "[N m/rad] | fitted damper [N m s/rad] | solreflimit | omega h |",
        "|---|---|---|---|---|---|---|---|---|---|---|",
    ]
    for h in hinges:
        s, fit = h.stop, h.stop.fit
        speed = f"{s.impact_speed:.3g} ({s.speed_source})"
        if s.kind == "exact":
            law = h.backlash
            lines.append(
                f"| {h.name} | exact (the law, compiled plugin) | {law.mesh_stiffness:.6g} | {law.restitution:g} | "
                f"{law.mesh_exponent:g} | {s.inertia:.4g} | {speed} | - | - | none (tendon unlimited) | - |"
            )
            continue
        if s.kind == ROBOT_STEP_STOP and s.solref is not None:
            law = h.backlash
            lines.append(
                f"| {h.name} | robot step (the step-limited limit, below) | {law.mesh_stiffness:.6g} | "
                f"{law.restitution:g} | {law.mesh_exponent:g} | {s.inertia:.4g} | {speed} | - | - | "
                f"({s.solref[0]:.6g}, {s.solref[1]:.6g}) | {1 / STEP_SPAN:g} |"
            )
            continue
        if fit is None or s.solref is None:
            lines.append(
                f"| {h.name} | recipe (MuJoCo's default limit) | - | - | - | {s.inertia:.4g} | {speed} | - | - | "
                "MuJoCo's default | - |"
            )
            continue
        lines.append(
            f"| {h.name} | calibrated | {fit.law.stiffness:.6g} | {fit.law.restitution:g} | {fit.law.exponent:g} | "
            f"{s.inertia:.4g} | {speed} | {fit.stiffness:.5g} | {fit.damping:.5g} | "
            f"({s.solref[0]:.6g}, {s.solref[1]:.6g}) | {fit.omega_h:.3f} |"
        )
    return lines


def _accuracy(h: BacklashHinge) -> list[str]:
    fit = h.stop.fit
    if fit is None:
        return []
    lines = [
        "",
        f"Stop of '{h.name}' against the law over the closing speeds ({len(fit.rows)}, log-spaced over the decade "
        f"around {h.stop.impact_speed:.3g} rad/s; the worse of two onset phases within a step; goal "
        f"{100 * GOAL:g} %; {'met' if fit.meets_goal() else 'NOT met'}):",
        "",
        "| closing speed [rad/s] | law peak torque [N m] | stop peak torque [N m] | error | law restitution | "
        "stop restitution | error |",
        "|---|---|---|---|---|---|---|",
    ]
    for r in fit.rows:
        lines.append(
            f"| {r.speed:.4g} | {r.law_peak_torque:.5g} | {r.peak_torque:.5g} | {100 * r.peak_torque_err:+.2f} % | "
            f"{r.law_restitution:.4f} | {r.restitution:.4f} | {100 * r.restitution_err:+.2f} % |"
        )
    if len(h.stop.pose_rows) == 2:
        (light, heavy), (lo, hi) = h.stop.pose_rows, h.stop.inertia_range
        lines += [
            "",
            f"Over {POSE_SAMPLES} poses drawn in the joints' ranges the inertia along the band runs from {lo:.4g} to "
            f"{hi:.4g} kg m^2. The stop is the same spring and damper at every pose, and a linear damper's rebound "
            f"changes with the inertia where the law's does not: at {light.speed:.3g} rad/s, peak torque "
            f"{100 * light.peak_torque_err:+.1f} % and restitution {100 * light.restitution_err:+.1f} % at the "
            f"lightest pose, {100 * heavy.peak_torque_err:+.1f} % and {100 * heavy.restitution_err:+.1f} % at the "
            "heaviest.",
        ]
    return lines


def backlash_report(
    result: BacklashRetrofit, *, source: str = "", command: str = "", changes: Sequence[str] = ()
) -> str:
    """The Markdown text of ``retrofit.md`` for a backlash retrofit.

    Args:
        result: the retrofit.
        source: the model file's name as given.
        command: the command line that made it.
        changes: asset paths rewritten when the models were written.
    """
    hinges = list(result.hinges.values())
    lines = ["# Backlash retrofit", ""]
    if source:
        lines += [f"Model: `{source}`" + (f"; command: `{command}`" if command else ""), ""]
    lines += [
        "Each hinge keeps its name, body, sensors, limits and keyframe values (the load side, the link). A motor "
        "body beside it on the same axis takes its actuators, its armature (the rotor's reflected inertia) and its "
        "damping, and a copy of its limit; the load may turn within +-b of the motor, by the limit of a fixed tendon "
        "q_load - q_motor. Keyframes start each band centred. The hinge's jointactuatorfrc sensors follow its "
        "actuators to the motor side (on the link they would read 0); its jointpos and jointvel sensors read the "
        "link unless `--backlash-sensors motor` puts them on the motor side, as an encoder on the motor reads.",
        "",
        *_hinge_rows(hinges),
        "",
        "## The stops at the ends of the bands",
        "",
        f"A calibrated stop follows the gear mesh's impact law {_LAW}, with the mesh stiffness K and restitution e "
        f"given (defaults K = {DEFAULT_MESH_STIFFNESS:g} N m/rad, the order of a small robot gearbox's torsional "
        f"stiffness in strain-wave gear catalogues, and e = {DEFAULT_MESH_RESTITUTION:g}, lubricated steel teeth as "
        "gear-rattle models take them: both recalled, not checked). The tendon limit is fitted to it as the ring "
        "bearings are: the same impact in a one-hinge MuJoCo scene at the effective inertia J along the band "
        "(1/(J_t M^-1 J_t^T) from the model's mass matrix at qpos0: the link and the rotor in series) and in the "
        "law's 1-DOF reference, over a decade of closing speeds; a spring and a damper in direct-mode solreflimit "
        f"(-spring A, -damper A with A the tendon's inverse weight) at a constant impedance {STOP_IMPEDANCE:g} "
        "(solimplimit), so the limit is a penalty spring-damper whatever the pose. The impact speed is estimated "
        "as the speed at which the motor, pushed from rest by its actuators' largest torque, takes up the whole "
        f"band. The time step keeps omega h <= {OMEGA_H:g} with omega = sqrt(K/J) at the lightest pose sampled. "
        "An exact stop is the law itself: the compiled plugin `clearance.backlash_stop` (one instance "
        "`clr_<hinge>__stop` per band, with a sensor of the torque, d and d') computes T from the two hinges' angles "
        "and speeds, keeps the closing speed of each impact, and applies T to both hinges as passive torques; the "
        "band's tendon stays, unlimited, as its angle. It holds at every pose, and the model needs the plugin "
        "wherever it is loaded; its time step follows the same omega h rule. A recipe stop is MuJoCo's "
        "default limit (solref 0.02 1, solimp 0.9 0.95 0.001) at the model's own step: the two hinges and a limit "
        "as users write them, not calibrated.",
        "",
        *_stop_rows(hinges),
    ]
    for h in hinges:
        lines += _accuracy(h)
    step, twin_step = float(result.model.opt.timestep), float(result.twin.opt.timestep)
    lines.append("")
    if step < twin_step:
        lines.append(
            f"Time step: {step:g} s, lowered from the model's {twin_step:g} s for the calibrated or exact stops "
            "(`original.xml` keeps the model's own; run the twin at this step to compare)."
        )
    else:
        lines.append(f"Time step: the model's own, {twin_step:g} s.")
    lines += ["", f"Keyframes extended: {result.keyframes}. Each motor body's mass: {result.motor_mass:g} kg."]
    lines += [f"- asset path: {c}" for c in changes]
    return "\n".join(lines) + "\n"
