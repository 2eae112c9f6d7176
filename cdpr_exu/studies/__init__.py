"""Studies over many runs: parameter sweeps, the accuracy study, and the controller comparison.

Data flows scene (``cdpr_exu.scenes``) -> model (``cdpr_exu.builder``) -> run (``cdpr_exu.run``)
-> result (``cdpr_exu.results``) -> studies and plots (``cdpr_exu.studies``, ``cdpr_exu.post``).
"""
