"""clearance.run: a mechanism through MuJoCo, from model preparation to a `SimulationResult`.

The run's floor sits on the MJCF builder and the contact calibration: `preparation` turns a
`Mechanism` and `ModelOptions` into a compiled model with its sizing and contact parameters,
`simulation` steps it with `mujoco.rollout` in chunks, `readout` turns sensor rows into a
`SimulationResult`, and `initial_state` gives start states other than the default.
"""
