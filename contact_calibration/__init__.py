"""clearance.contact_calibration."""
