"""Nonlinear-dynamics tools: phase portraits, Poincaré sections, regime classification."""
