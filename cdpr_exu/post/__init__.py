"""Looking at results (the last layer, beside ``cdpr_exu.studies``): figures, Exudyn's SolutionViewer and
headless animations."""
