"""Rerun recordings of runs: journal orbits, contact forces, outputs, the moving mechanism."""
