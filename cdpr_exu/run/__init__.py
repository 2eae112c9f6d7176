"""Running a scene: the implicit dynamic runs (planar and spatial) with their per-step state, the static mode, and the per-run error estimate.

Data flows scene (``cdpr_exu.scenes``) -> model (``cdpr_exu.builder``) -> run (``cdpr_exu.run``)
-> result (``cdpr_exu.results``) -> studies and plots (``cdpr_exu.studies``, ``cdpr_exu.post``).
"""
