"""Running a scene, the layer between the model (``cdpr_exu.builder``) and its result (``cdpr_exu.results``):
the dynamic runs of both dimensions, the static mode and the per-run error estimate."""
