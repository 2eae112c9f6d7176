"""A point exit: the cable leaves the frame at a fixed point, in the plane or in space.

No pulley: the cable runs straight from the point to its anchor, nothing wraps, and there is
no contact. In a planar scene the cable's winch end is held at the point (fixed winches); in
a spatial scene the winch pays the cable out through it. Its ideal cable is its space's pulley
kernel at radius 0 (:mod:`cdpr_exu.core.geometry`).
"""

from __future__ import annotations

from dataclasses import dataclass
from typing import Any, ClassVar, Mapping

import numpy as np

from cdpr_exu.core.errors import SceneError
from cdpr_exu.core.geometry import PulleyExit, planar_exit, swivel_pulley_exit
from cdpr_exu.core.validation import from_table, vector
from cdpr_exu.exits.base import Exit

__all__ = ["PointExit"]

_LABELS = {2: "x, z", 3: "x, y, z"}

#: The ideal cable's kernel of a point exit, by the size of its point: the planar pulley's at radius 0, hung
#: on its left (side -1), and the swivel pulley's at radius 0.
_KERNELS = {2: lambda point, anchor_points, azimuth_hint: planar_exit(point, 0.0, -1, anchor_points),
            3: lambda point, anchor_points, azimuth_hint: swivel_pulley_exit(point, 0.0, anchor_points, azimuth_hint)}


@dataclass(frozen=True)
class PointExit(Exit):
    """A fixed exit point: the cable leaves the frame at ``point`` (x, z) or (x, y, z) [m], world frame
    (its size is its scene's dimension); anything but two or three finite numbers is refused."""

    kind: ClassVar[str] = "point"
    dimensions: ClassVar[tuple[int, ...]] = (2, 3)
    required_fields: ClassVar[dict[str, str]] = {"point": "m"}
    path_head: ClassVar[str] = "point_exit"

    point: tuple = (0.0, 0.0)

    def __post_init__(self) -> None:
        size = 2 if isinstance(self.point, (tuple, list, np.ndarray)) and len(self.point) == 2 else 3
        value = vector(f"{self.path_head}.point", self.point, size, f" ({_LABELS[size]}) [m]")
        object.__setattr__(self, "point", tuple(float(v) for v in value))

    @property
    def radius(self) -> float:
        """0: nothing wraps."""
        return 0.0

    def exit(self, anchor_points, azimuth_hint=None) -> PulleyExit:
        """The straight cable from the point to ``anchor_points`` (d,) or (N, d) [m] (``azimuth_hint``: in
        space, the direction reported for an anchor straight below the point)."""
        return _KERNELS[len(self.point)](self.point, anchor_points, azimuth_hint)

    @classmethod
    def from_dict(cls, data: Mapping[str, Any], path: str, space) -> "PointExit":
        if set(data) != {"point"}:
            raise SceneError(f"{path}: a point exit has one field 'point' = [{', '.join(space.position_labels)}] "
                             f"(and kind = 'point'), got {sorted(data)}")
        point = vector(f"{path}.point", data["point"], space.position_size,
                       f" ({', '.join(space.position_labels)}) [m]")
        return from_table(cls, {"point": tuple(float(v) for v in point)}, path, cls.path_head)
