"""clearance.analysis: what a run means, in rooms a reader can name.

  * `metrics`: numbers of a run against its ideal twin or a reference (statistics,
    per-joint summary, response, accuracy, comparisons between runs);
  * `chaos`: phase portraits, Poincaré sections, regimes;
  * `sweeps`: many runs through one executor (bifurcation, criticality, batches of named runs);
  * `figures`: figures and the Markdown report;
  * `recording`: rerun recordings.

Analysis reads results and calls the run; it never builds a mechanism or a model itself
(sweeps take a factory) and never imports the command line.
"""
