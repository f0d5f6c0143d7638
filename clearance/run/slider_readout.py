"""A MuJoCo run's sliders with play, from its sensor rows (vectorised, no per-step Python).

Each slider's `clearance.translational.SliderResult` holds what the reference solver's does
(`clearance.reference.output`), in the guide's frame (u along the guide, n across):

* position: the slider site's position in the guide site's frame (``<joint>__spos``);
* velocity: d/dt (R_g' (p_s - p_g)) = R_g' (v_s - v_g) + w_g (y, -x), from the two sites' world
  velocities and the guide's angular velocity;
* tilt: the angle of the slider site's x axis in the guide site's frame (``<joint>__sxaxis``),
  tilt_rate: the two sites' angular velocities' difference;
* the corners' penetrations and normal forces: in the exact mode the compiled contact's sensor;
  in the portable form the corners' exact geometry, |s_k| - (H/2 + c) with
  s_k = across + s_u L sin(tilt) + s_n H cos(tilt), and the normal component of each corner
  sphere's contact sensor;
* the net contact force on the slider in the guide frame: along, the corners' friction; across,
  -sign(s_k) times their normal forces (the compiled contact), or the corner sensors' sum;
* the contact case: `clearance.translational.classify_contact` of the penetrations.
"""

from __future__ import annotations

from collections.abc import Callable

import numpy as np

from clearance.contact_plugin.slider_guide import slider_sensor_offsets
from clearance.run.preparation import PreparedModel, exact_contact_name
from clearance.run.reactions import frame_rate, rotate
from clearance.translational import CORNERS, SliderResult, classify_contact

__all__ = ["read_sliders"]


def read_sliders(
    prepared: PreparedModel, get: Callable[[str], np.ndarray], sens: np.ndarray
) -> tuple[dict[str, SliderResult], dict[str, np.ndarray]]:
    """Every slider with play's series, and the net contact force on each slider (world).

    Args:
        prepared: the model.
        get: sensor name -> (n, dim) rows of that sensor.
        sens: (n, nsensordata) the sensor rows (the compiled contact's block is read by index).

    Returns:
        (slider -> `SliderResult`, slider -> (n, 2) net contact force on the slider, world [N]).
    """
    sliders: dict[str, SliderResult] = {}
    world: dict[str, np.ndarray] = {}
    fu, fn = np.array(CORNERS).T
    for joint, geometry in prepared.built.guides.items():
        play = geometry.play
        pos = get(f"{joint}__spos")[:, :2].copy()
        xaxis = get(f"{joint}__sxaxis")
        tilt = np.arctan2(xaxis[:, 1], xaxis[:, 0])
        gx = get(f"{joint}__gxaxis")
        c, s = gx[:, 0], gx[:, 1]
        dv = get(f"{joint}__svel")[:, :2] - get(f"{joint}__gvel")[:, :2]
        wg = get(f"{joint}__gangvel")[:, 2]
        vel = frame_rate(gx, dv, wg, pos)
        across = (
            pos[:, 1:2]
            + fu * play.slider_length * np.sin(tilt)[:, None]
            + fn * play.slider_height * np.cos(tilt)[:, None]
        )
        side = np.where(across >= 0.0, 1.0, -1.0)
        if prepared.built.exact_contact:
            at = slider_sensor_offsets(prepared.model, exact_contact_name(joint))
            pen = np.stack([sens[:, at[f"penetration_{k}"]] for k in range(4)], axis=1)
            normal = np.stack([sens[:, at[f"normal_force_{k}"]] for k in range(4)], axis=1)
            along = np.stack([sens[:, at[f"tangential_force_{k}"]] for k in range(4)], axis=1)
            force = np.stack([along.sum(axis=1), -(side * normal).sum(axis=1)], axis=1)
        else:
            pen = np.abs(across) - (0.5 * play.slider_height + play.clearance)
            fw = np.stack([get(f"{joint}__corner{k}_force")[:, :2] for k in range(4)], axis=1)  # (n, 4, 2) world
            f_across = -s[:, None] * fw[..., 0] + c[:, None] * fw[..., 1]
            normal = -side * f_across
            force = np.stack([(c[:, None] * fw[..., 0] + s[:, None] * fw[..., 1]).sum(axis=1), f_across.sum(axis=1)], 1)
        sliders[joint] = SliderResult(
            position=pos,
            velocity=vel,
            tilt=tilt,
            tilt_rate=get(f"{joint}__sangvel")[:, 2] - wg,
            corner_penetration=pen,
            corner_force=normal,
            contact_force=force,
            contact_case=classify_contact(pen),
        )
        world[joint] = rotate(gx, force)
    return sliders, world
