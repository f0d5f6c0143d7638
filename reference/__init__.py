"""clearance.reference."""
