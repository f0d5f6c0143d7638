"""clearance.mjcf."""
