"""Statics and ideal kinematics, pure NumPy/SciPy (no Exudyn), planar and spatial, one each: the ideal kinematics and structure matrix, the tension distribution, the workspace check of a reference, the kineto-statics on elastic catenaries (:mod:`cdpr_exu.statics.statics`) and the chain statics of the lumped cables.

Data flows scene (``cdpr_exu.scenes``) -> model (``cdpr_exu.builder``) -> run (``cdpr_exu.run``)
-> result (``cdpr_exu.results``) -> studies and plots (``cdpr_exu.studies``, ``cdpr_exu.post``).
"""
