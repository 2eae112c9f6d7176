"""Statics and ideal kinematics, pure NumPy/SciPy (no Exudyn): the kineto-statics on elastic catenaries (planar and spatial, :mod:`cdpr_exu.statics.statics`), the chain statics of the lumped cables, inverse kinematics and the structure matrix, and the workspace check of a reference.

Data flows scene (``cdpr_exu.scenes``) -> model (``cdpr_exu.builder``) -> run (``cdpr_exu.run``)
-> result (``cdpr_exu.results``) -> studies and plots (``cdpr_exu.studies``, ``cdpr_exu.post``).
"""
