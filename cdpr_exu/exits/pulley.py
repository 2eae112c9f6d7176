"""A planar pulley: the cable wraps over the top of a disc in the x-z plane and hangs to its winch.

The cable comes up from the winch along the vertical line ``x = c_x + s r_p`` (``s = -1``: it
hangs on the pulley's left, ``+1``: on its right), leaves that line at the *hang point*
``(c_x + s r_p, c_z)``, wraps over the top of the pulley and leaves the rim towards its anchor
(:mod:`cdpr_exu.core.geometry`, "Pulley convention"). The rim pushes the cable's nodes out
with a penalty (``contact_stiffness``, ``contact_damping``; :mod:`cdpr_exu.physics.node_contact`,
:mod:`cdpr_exu.physics.segment_contact`).
"""

from __future__ import annotations

import math
from dataclasses import dataclass
from typing import ClassVar

import numpy as np

from cdpr_exu.core.errors import SceneError
from cdpr_exu.core.geometry import PulleyExit, planar_exit
from cdpr_exu.core.validation import entries, non_negative, positive, shown
from cdpr_exu.exits.base import Exit

__all__ = ["Pulley"]


@dataclass(frozen=True)
class Pulley(Exit):
    """A pulley the cable runs over, and on which side the cable hangs to its winch.

    Parameters
    ----------
    center : (x, z) [m]
        Pulley centre ``c``.
    radius : float [m]
        Rim radius r_p (positive).
    side : {-1, +1}
        -1: the cable hangs on the pulley's left (x < x_c) and wraps clockwise over the top,
        +1: on its right (counter-clockwise).
    contact_stiffness, contact_damping : float [N/m, N s/m]
        Penalty stiffness k_p of the rim contact and damping c_p on a node's normal velocity.
    """

    kind: ClassVar[str] = "pulley"
    dimensions: ClassVar[tuple[int, ...]] = (2,)
    required_fields: ClassVar[dict[str, str]] = {"center": "m", "radius": "m", "side": "-1 or +1"}
    path_head: ClassVar[str] = "pulley"

    center: tuple[float, float] = (0.0, 0.0)
    radius: float = 0.25
    side: int = -1
    contact_stiffness: float = 1.0e7
    contact_damping: float = 10.0

    def __post_init__(self) -> None:
        set_ = object.__setattr__
        set_(self, "center", entries("pulley.center", self.center, 2, "m"))
        set_(self, "radius", positive("pulley.radius", self.radius, "m"))
        if self.side not in (-1, 1) or isinstance(self.side, bool):
            raise SceneError(f"pulley.side must be -1 (left) or +1 (right), got {shown(self.side)}")
        set_(self, "side", int(self.side))
        set_(self, "contact_stiffness", positive("pulley.contact_stiffness", self.contact_stiffness, "N/m"))
        set_(self, "contact_damping", non_negative("pulley.contact_damping", self.contact_damping, "N s/m"))

    @property
    def point(self) -> tuple[float, float]:
        """The pulley's centre [m]."""
        return self.center

    @property
    def hang_point(self) -> np.ndarray:
        """Where the cable leaves its vertical winch line, ``(c_x + s r_p, c_z)``, shape (2,) [m]."""
        return np.array([self.center[0] + self.side * self.radius, self.center[1]])

    def exit(self, anchor_points) -> PulleyExit:
        """Tangent point, wrap and free length of the ideal cable to ``anchor_points`` (2,) or (N, 2) [m]
        (:func:`cdpr_exu.core.geometry.pulley_exit`)."""
        return planar_exit(self.center, self.radius, self.side, anchor_points)

    def paid_out_refusal(self, cable, index: int, lengths, lumped: bool, path: str):
        """Refuse ideal lengths beyond the cable: a lumped cable keeps one element on the winch side of the
        pulley, a massless rope (no elements) may pay out its whole length."""
        spare = cable.element_length if lumped else 0.0
        too_long = np.flatnonzero(np.asarray(lengths) > cable.unstrained_length - spare + 1e-12)
        if not too_long.size:
            return None
        k = int(too_long[0])
        kept = (f"one element, {cable.element_length:.4f} m, must stay on the winch side"
                if lumped else "a massless rope can pay out at most its whole length")
        return k, (f"{lengths[k]:.4f} m of cable {index + 1} between {path} and platform.anchors[{index}], but "
                   f"cables[{index}].unstrained_length is {cable.unstrained_length} m ({kept})")

    def rim_point(self, angle: float) -> np.ndarray:
        """Point of the rim at polar angle ``angle`` [rad], shape (2,) [m]."""
        return np.array(self.center) + self.radius * np.array([math.cos(angle), math.sin(angle)])

    def wrap_to(self, angle: float) -> float:
        """Angle [rad] wrapped from the hang point over the top to the rim angle ``angle``, in [0, 2 pi)."""
        if self.side < 0:
            return (math.pi - angle) % (2.0 * math.pi)
        return angle % (2.0 * math.pi)

    def describe(self, path: str) -> str:
        return f"{path}.center {list(self.center)} m, {path}.radius {self.radius} m, {path}.side {self.side}"
