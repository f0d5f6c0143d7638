"""Small hand-written MJCF models, one per convention a retrofit must get right.

Each is the project's own (dimensions chosen for fast runs, not taken from a paper): a two-link
arm in degrees, the same arm with a reference angle and a spring reference, with the compiler's
``settotalmass``, a crank-rocker four-bar closed by a `connect`, and a pendulum whose bearing
sits far from its body's origin. Every model has motors on its hinges (backlash needs them) and
a site ``tip`` at its end effector.
"""

from __future__ import annotations

import math


def _arm(name: str, compiler: str, hip: str, elbow: str, *, lower: str = "", link: str = "", extra: str = "") -> str:
    """A two-link arm hanging in the x-z plane (hinges about y), motors on both, a site at its tip.

    Args:
        name: the model's name. compiler: the compiler's attributes. hip, elbow: each hinge's own
        attributes. lower: the lower body's extra attributes. link: how the geoms weigh (default:
        1 kg and 0.5 kg). extra: elements after the actuators.
    """
    masses = [link or 'mass="1"', link or 'mass="0.5"']
    return f"""<mujoco model="{name}">
  <compiler {compiler}/>
  <option timestep="0.002"/>
  <worldbody>
    <body name="upper" pos="0 0 1">
      <joint name="hip" axis="0 1 0" {hip} damping="0.05"/>
      <geom type="capsule" fromto="0 0 0 0.3 0 0" size="0.02" {masses[0]}/>
      <body name="lower" pos="0.3 0 0"{lower}>
        <joint name="elbow" axis="0 1 0" {elbow} damping="0.05"/>
        <geom type="capsule" fromto="0 0 0 0.25 0 0" size="0.02" {masses[1]}/>
        <site name="tip" pos="0.25 0 0"/>
      </body>
    </body>
  </worldbody>
  <actuator>
    <motor name="hip_motor" joint="hip" ctrlrange="-4 4"/>
    <motor name="elbow_motor" joint="elbow" ctrlrange="-2 2"/>
  </actuator>
{extra}</mujoco>
"""


DEGREE_ARM = _arm(
    "degree_arm",
    'angle="degree"',
    'range="-20 100"',
    'range="-160 160"',
    lower=' euler="0 30 0"',
    extra='  <sensor><jointpos name="hip_angle" joint="hip"/><jointvel name="elbow_speed" joint="elbow"/></sensor>\n'
    '  <keyframe><key name="start" qpos="0.3 -0.5" qvel="0.2 0"/></keyframe>\n',
)
"""Degrees (MJCF's default unit, said here explicitly; most published models): the hip limited to
-20...100 degrees, the elbow to +-160 degrees, the lower link tilted by an Euler angle in degrees
(the keyframe's qpos is in radians: MuJoCo does not convert it)."""

REF = -math.pi / 2
"""The hip's reference angle in `REF_ARM` [rad]."""

REF_ARM = _arm(
    "ref_arm",
    'angle="radian"',
    f'ref="{REF!r}" range="-2.6 -0.5"',
    'ref="0.4" springref="1.0" stiffness="3" range="-2 2"',
)
"""Reference angles: the hip reads -90 degrees (in radians) at the pose as written, its range
around it; the elbow has a reference angle and a spring pulling it towards another (springref)."""

TOTAL_MASS = 2.5
"""The total mass `TOTALMASS_ARM`'s compiler scales its links to [kg]."""

TOTALMASS_ARM = _arm(
    "totalmass_arm",
    f'angle="radian" settotalmass="{TOTAL_MASS}"',
    'range="-0.4 1.7"',
    'range="-2.8 2.8"',
    link='density="2000"',
)
"""``settotalmass``: the compiler scales the geoms' masses so the links weigh `TOTAL_MASS` together."""

ANCHOR = (-0.02, -0.22, 0.0)
"""The connect's anchor in the rocker's frame [m]: the rocker's ground pivot, at (0.3, 0, 0)."""

FOUR_BAR = f"""<mujoco model="four_bar">
  <option timestep="1e-4" gravity="0 -9.81 0"/>
  <default><geom type="capsule" size="0.005" contype="0" conaffinity="0"/></default>
  <worldbody>
    <body name="crank">
      <joint name="crank_pivot" axis="0 0 1" damping="0.002"/>
      <geom fromto="0 0 0 0 0.1 0" mass="0.1"/>
      <body name="coupler" pos="0 0.1 0">
        <joint name="crank_coupler" axis="0 0 1"/>
        <geom fromto="0 0 0 0.32 0.12 0" mass="0.2"/>
        <body name="rocker" pos="0.32 0.12 0">
          <joint name="coupler_rocker" axis="0 0 1"/>
          <geom fromto="0 0 0 {ANCHOR[0]} {ANCHOR[1]} 0" mass="0.15"/>
          <site name="tip" pos="0.02 0.22 0"/>
        </body>
      </body>
    </body>
  </worldbody>
  <equality>
    <connect name="loop" body1="rocker" body2="world" anchor="{ANCHOR[0]} {ANCHOR[1]} {ANCHOR[2]}" solref="0.0002 1"/>
  </equality>
  <actuator><motor name="drive" joint="crank_pivot" ctrlrange="-0.5 0.5"/></actuator>
</mujoco>
"""
"""A loop closure as MJCF writes a four-bar: the chain crank-coupler-rocker closed to the ground at the
rocker's pivot by a `connect` (a Grashof crank-rocker: ground 0.3 m, crank 0.1 m, coupler 0.342 m,
rocker 0.221 m; its tip as far beyond the coupler joint), stiff enough (0.2 ms) that the loop closes
to 0.1 um, driven at its crank."""

PIVOT = (1.2345678, 0.8765432, 0.1)
"""The far bearing's hinge position in its bodies' frames [m]."""

FAR_BEARING = f"""<mujoco model="far_bearing">
  <option timestep="0.001"/>
  <worldbody>
    <body name="base" pos="0.1 0.2 0.3">
      <geom type="box" size="0.05 0.05 0.05" mass="1"/>
      <body name="arm">
        <joint name="pivot" pos="{PIVOT[0]} {PIVOT[1]} {PIVOT[2]}" axis="0 1 0" damping="0.02"/>
        <geom type="capsule" fromto="{PIVOT[0]} {PIVOT[1]} {PIVOT[2]} {PIVOT[0] + 0.3} {PIVOT[1]} {PIVOT[2]}"
              size="0.01" mass="0.3"/>
        <site name="tip" pos="{PIVOT[0] + 0.3} {PIVOT[1]} {PIVOT[2]}"/>
      </body>
    </body>
  </worldbody>
  <actuator><motor joint="pivot" ctrlrange="-1 1"/></actuator>
</mujoco>
"""
"""A bearing far from its body's origin: the pivot 1.5 m from the origins of the fixed base and of
the arm, so MuJoCo's 6 written digits hold a body-frame coordinate only to 5 um."""

MODELS = {
    "degree_arm": DEGREE_ARM,
    "ref_arm": REF_ARM,
    "totalmass_arm": TOTALMASS_ARM,
    "four_bar": FOUR_BAR,
    "far_bearing": FAR_BEARING,
}
"""Name -> MJCF of every hand-written model."""

HINGES = {
    "degree_arm": ("hip", "elbow"),
    "ref_arm": ("hip", "elbow"),
    "totalmass_arm": ("hip", "elbow"),
    "four_bar": ("loop",),
    "far_bearing": ("pivot",),
}
"""Name -> what takes radial play (a loop closure's connect for the four-bar)."""

MOTORS = {
    "degree_arm": ("hip", "elbow"),
    "ref_arm": ("hip", "elbow"),
    "totalmass_arm": ("hip", "elbow"),
    "four_bar": ("crank_pivot",),
    "far_bearing": ("pivot",),
}
"""Name -> the actuated hinges (what takes backlash)."""
