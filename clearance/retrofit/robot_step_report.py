"""The report section of backlash at the robot's step (appended to ``retrofit.md``).

What the step-limited stop is (`clearance.retrofit.step_stop`), its fit against the exact stop,
and per band the fastest closing and deepest penetration under the sizing motion at the step,
the smallest band the stop represents there and the largest step for the band.
"""

from __future__ import annotations

import math

from clearance.retrofit.robot_step import RobotStepBacklash
from clearance.retrofit.step_stop import MAX_PENETRATION, PHASES, STEP_IMPEDANCE, STEP_SPAN

__all__ = ["robot_step_report"]


def _arcmin(rad: float) -> str:
    return f"{math.degrees(rad) * 60:.4g}"


def robot_step_report(result: RobotStepBacklash) -> str:
    """Markdown section on ``result``'s stops and bands at its robot step."""
    s, h = result.stop, result.robot_step
    lines = [
        f"## At the robot's step ({h * 1e3:g} ms)",
        "",
        f"Every band is closed by the step-limited stop: MuJoCo's soft limit on the band's tendon with its spring "
        f"time constant 1/omega = {STEP_SPAN:g} steps (omega = {s.omega:.4g} rad/s; MuJoCo's own rule for solref, "
        f"timeconst >= 2 h) and a constant impedance {STEP_IMPEDANCE:g} (solimplimit), so its relative "
        "acceleration, and with it its rebound and penetration, do not depend on the pose. Its damping ratio is "
        "fitted to the exact stop (the gear mesh's law in the compiled plugin at a fine step): rebound and impulse "
        f"per impact, over {len(PHASES)} onset phases within a step. The band, `ref`, the limits and the sensors "
        "are copied from the request and the model, never fitted. The model and `original.xml` are written at "
        "this step; stock MuJoCo opens them (no plugin).",
        "",
        "| solreflimit (timeconst, dampratio) | exact rebound | stop rebound (worst phase) | error | exact impulse "
        "/ J v | stop impulse / J v (worst phase) | error | deepest penetration / closing speed [ms] |",
        "|---|---:|---:|---:|---:|---:|---:|---:|",
        f"| ({s.solref[0]:.6g}, {s.solref[1]:.6g}) | {s.exact.rebound:.4f} | "
        f"{s.exact.rebound * (1 + s.rebound_error):.4f} | {100 * s.rebound_error:+.2f} % | {s.exact.impulse:.4f} | "
        f"{s.exact.impulse * (1 + s.impulse_error):.4f} | {100 * s.impulse_error:+.2f} % | "
        f"{s.penetration * 1e3:.4g} |",
        "",
        f"A band is represented where the stop's deepest penetration at its fastest closing under the sizing motion "
        f"(run on this model at this step) is at most {MAX_PENETRATION:g} b; the penetration per closing speed "
        "grows with the step, so the smallest band grows with the step and the closing speed.",
        "",
        "| hinge | b [arcmin] | fastest closing [rad/s] | deepest penetration in the sizing run [b] | smallest "
        "band at this step and closing [arcmin] | largest step for this band [ms] |",
        "|---|---:|---:|---:|---:|---:|",
    ]
    for b in result.bands.values():
        lines.append(
            f"| {b.hinge} | {_arcmin(b.half_width)} | {b.closing_speed:.3g} | {b.penetration / b.half_width:.3f} | "
            f"{_arcmin(b.smallest_band)} | {b.largest_step * 1e3:.3g} |"
        )
    return "\n".join(lines) + "\n"
