"""Figures of runs, sweeps and comparisons, and the Markdown report of a run."""
