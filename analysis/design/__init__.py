"""Design for clearance: start-state ensembles, tolerance allocation, design optimisation."""
