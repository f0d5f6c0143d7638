"""Many runs through one executor: bifurcation diagrams, criticality ranking, batches of named runs."""
