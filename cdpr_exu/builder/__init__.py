"""The Exudyn builder, the layer that speaks Exudyn: cables, pulleys, platform and winches of the planar model, and the spatial chains and robot, assembled into a model.

Data flows scene (``cdpr_exu.scenes``) -> model (``cdpr_exu.builder``) -> run (``cdpr_exu.run``)
-> result (``cdpr_exu.results``) -> studies and plots (``cdpr_exu.studies``, ``cdpr_exu.post``).
"""
