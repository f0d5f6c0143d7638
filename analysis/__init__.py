"""clearance.analysis."""
