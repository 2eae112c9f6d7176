"""The project's foundations, used by every layer: errors and exit codes, argument validation, the geometry of poses, rotations, anchors and pulleys (one home for both dimensions), and strict output files.

Data flows scene (``cdpr_exu.scenes``) -> model (``cdpr_exu.builder``) -> run (``cdpr_exu.run``)
-> result (``cdpr_exu.results``) -> studies and plots (``cdpr_exu.studies``, ``cdpr_exu.post``).
"""
