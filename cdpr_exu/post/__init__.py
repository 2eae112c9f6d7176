"""Looking at results: figures, Exudyn's SolutionViewer and headless animations.

Data flows scene (``cdpr_exu.scenes``) -> model (``cdpr_exu.builder``) -> run (``cdpr_exu.run``)
-> result (``cdpr_exu.results``) -> studies and plots (``cdpr_exu.studies``, ``cdpr_exu.post``).
"""
