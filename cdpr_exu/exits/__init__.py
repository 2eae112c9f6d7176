"""Exits: where each cable leaves the frame, one object per kind (:mod:`cdpr_exu.exits.base`).

The shipped kinds enter the registry here: a point exit (both dimensions), a planar pulley,
a swivel pulley (spatial). Another kind is one module plus one entry ``EXIT_KINDS[kind] = Class``.
"""

from cdpr_exu.exits.base import EXIT_KINDS, Exit, exit_from_dict
from cdpr_exu.exits.point import PointExit
from cdpr_exu.exits.pulley import Pulley
from cdpr_exu.exits.swivel import Swivel

EXIT_KINDS.update({PointExit.kind: PointExit, Pulley.kind: Pulley, Swivel.kind: Swivel})

__all__ = ["EXIT_KINDS", "Exit", "exit_from_dict", "PointExit", "Pulley", "Swivel"]
