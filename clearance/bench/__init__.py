"""clearance.bench: speed against error of MuJoCo settings, measured against the reference solver.

`scenarios` names the benchmark's scenarios and grid of settings, `speed_error` runs them
(resumable, in parallel for accuracy and one at a time for timing), `speed_error_report`
compares them with the reference and picks the Pareto front, `speed_error_plot` draws it.
The command is ``clearance bench`` (`clearance.cli.bench`).
"""
