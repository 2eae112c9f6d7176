"""A swivel pulley: a grooved disc that turns about the vertical axis through its inlet (spatial).

The cable comes up that axis from its winch, leaves it at the inlet, wraps over the disc and
leaves it towards the anchor; the disc turns so that it lies in the vertical plane through the
axis and the anchor (:mod:`cdpr_exu.core.geometry`, "Swivel pulley"). The cable's
``unstrained_length`` counts from the inlet to the anchor, the wrap included: the paid-out
length of the ideal kinematics. Its contact (the groove pushes the cable's nodes out, the
bearing turns the disc) is :class:`cdpr_exu.physics.swivel_pulley.SwivelPulley`
(:meth:`Swivel.pulley`).
"""

from __future__ import annotations

import math
from dataclasses import dataclass
from typing import ClassVar

import numpy as np

from cdpr_exu.core.errors import SceneError
from cdpr_exu.core.geometry import SwivelExit, swivel_pulley_exit
from cdpr_exu.core.validation import positive, shown
from cdpr_exu.exits.base import Exit
from cdpr_exu.physics.swivel_pulley import SAFE_ELEMENT_FRACTION, SwivelPulley

__all__ = ["Swivel"]


@dataclass(frozen=True)
class Swivel(Exit):
    """A swivel-pulley exit of a spatial scene (``[[exits]]`` with ``kind = "swivel"``).

    Parameters
    ----------
    inlet : (x, y, z) [m]
        Where the cable leaves the swivel axis onto the disc (the disc's centre is
        ``radius`` from the axis, at the inlet's height).
    radius : float [m]
        Groove-bottom radius r_p of the disc.
    contact_stiffness, contact_damping, swivel_inertia, bearing_damping, groove_radius, flange_height
        As :class:`cdpr_exu.physics.swivel_pulley.SwivelPulley`'s.
    winch_line : float [m]
        Unstrained cable between the winch end (held on the axis below the inlet) and
        the inlet at the start; the winch can pay out at most this much less a
        margin of two elements during a run.
    """

    kind: ClassVar[str] = "swivel"
    dimensions: ClassVar[tuple[int, ...]] = (3,)
    required_fields: ClassVar[dict[str, str]] = {"inlet": "m", "radius": "m"}
    path_head: ClassVar[str] = "swivel"

    inlet: tuple = (0.0, 0.0, 0.0)
    radius: float = 0.1
    contact_stiffness: float = 1.0e6
    contact_damping: float = 0.0
    swivel_inertia: float = 1.0e-2
    bearing_damping: float = 1.0e-3
    groove_radius: float = 0.01
    flange_height: float = 0.01
    winch_line: float = 0.3

    def __post_init__(self) -> None:
        object.__setattr__(self, "winch_line", positive("swivel.winch_line", self.winch_line, "m"))
        pulley = self.pulley()  # refuses bad fields, naming them swivel.<field>
        for name in ("inlet", "radius", "contact_stiffness", "contact_damping", "swivel_inertia", "bearing_damping",
                     "groove_radius", "flange_height"):
            object.__setattr__(self, name, getattr(pulley, name))

    @property
    def point(self) -> tuple:
        """The inlet [m]."""
        return self.inlet

    def pulley(self) -> SwivelPulley:
        """The contact physics of this exit (:class:`cdpr_exu.physics.swivel_pulley.SwivelPulley`)."""
        return SwivelPulley(inlet=self.inlet, radius=self.radius, groove_radius=self.groove_radius,
                            flange_height=self.flange_height, contact_stiffness=self.contact_stiffness,
                            contact_damping=self.contact_damping, swivel_inertia=self.swivel_inertia,
                            bearing_damping=self.bearing_damping)

    def exit(self, anchor_points, azimuth_hint=None) -> SwivelExit:
        """The cable's exit towards ``anchor_points`` (3,) or (N, 3) [m], with the disc's azimuth
        (:func:`cdpr_exu.core.geometry.swivel_pulley_exit`; ``azimuth_hint`` for an anchor on the axis)."""
        return swivel_pulley_exit(self.inlet, self.radius, anchor_points, azimuth_hint)

    def paid_out_refusal(self, cable, index: int, lengths, lumped: bool, path: str):
        """Refuse a reference that pays out more than the winch line, less two elements (the winch end's margin
        below the inlet), beyond the start."""
        margin = 2.0 * cable.element_length
        room = self.winch_line - margin
        gain = np.asarray(lengths) - lengths[0]
        if gain.max() <= room:
            return None
        k = int(np.argmax(gain))
        return k, (f"cable {index + 1} paid out by {1000 * gain[k]:.3g} mm over its swivel pulley, more than its winch "
                   f"line holds: {path}.winch_line = {1000 * self.winch_line:.3g} mm less two elements (2 x "
                   f"{1000 * margin / 2:.3g} mm, the winch end's margin below the inlet) leaves {1000 * room:.3g} mm; "
                   f"give {path}.winch_line = {1000 * (margin + max(gain[k], 0.0)):.3g} mm or more")

    def fewest_elements(self, cable) -> int:
        """Elements no longer than ``SAFE_ELEMENT_FRACTION`` of the disc's radius (:meth:`check`)."""
        return math.ceil(cable.unstrained_length / (SAFE_ELEMENT_FRACTION * self.radius) - 1e-9)

    def check(self, cable, index: int, path: str) -> None:
        """Refuse a cable too short to reach past the disc, or whose elements are too long for it (they
        would lose the wrap: measured, coarser chains gain energy and Exudyn's static solver fails)."""
        if self.radius >= cable.unstrained_length:
            raise SceneError(f"{path}.radius = {shown(self.radius)} m: the cable (cables[{index}].unstrained_length = "
                             f"{shown(cable.unstrained_length)} m) would not reach past the disc")
        if cable.element_length > SAFE_ELEMENT_FRACTION * self.radius * (1.0 + 1e-9):
            needed = cable.unstrained_length / (SAFE_ELEMENT_FRACTION * self.radius)
            most = cable.max_elements
            give = (f"give at least {math.ceil(needed)}" if needed <= most else
                    f"it would take {needed:.3g}, more than the {most} allowed: give a larger radius")
            raise SceneError(
                f"cables[{index}].n_elements = {cable.n_elements}: its elements ({cable.element_length:.4g} m) are "
                f"longer than {SAFE_ELEMENT_FRACTION:g} of the swivel pulley's radius ({path}.radius = "
                f"{shown(self.radius)} m); {give} (measured: coarser chains lose the wrap and gain energy, and "
                "Exudyn's static solver fails)")

    def describe(self, path: str) -> str:
        return f"{path}.inlet {list(self.inlet)} m, {path}.radius {self.radius} m"
