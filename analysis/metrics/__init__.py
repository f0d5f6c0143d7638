"""Numbers of a run against its ideal twin or a reference: statistics, summary, response, accuracy."""
