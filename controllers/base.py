"""The narrow interface between the simulated robot and its controllers.

A controller never sees Exudyn: it receives a :class:`Measurement` (time, winch
state and, where it declares that it uses them, the platform pose and the cable
tensions) and returns a :class:`WinchCommand`. The simulation asks for a command
once per time step, not once per Newton iteration.

The winch variable is the *paid-out length* lambda_i [m]: the unstrained cable length
between the point where cable i leaves its winch-side vertical line on the pulley
(the hang point) and the platform anchor. Hauling in decreases it. The simulation
tells each controller what was paid out at t = 0 (``reset``).
"""

from __future__ import annotations

from dataclasses import dataclass
from typing import Protocol, runtime_checkable

import numpy as np


@dataclass(frozen=True)
class Measurement:
    """What a controller may read at one time step.

    Attributes
    ----------
    time : float [s]
        The time the command is for (the end of the step being solved).
    paid_out : ndarray, shape (m,) [m]
        Current paid-out length of each winch.
    paid_out_rate : ndarray, shape (m,) [m/s]
    platform_pose : ndarray, shape (3,) or None [m, m, rad]
        Measured (x, z, rotation), only for controllers with ``uses_pose``.
    platform_velocity : ndarray, shape (3,) or None [m/s, m/s, rad/s]
    cable_tensions : ndarray, shape (m,) or None [N]
        Tension at the platform end of each cable, only for ``uses_tension``.
    """

    time: float
    paid_out: np.ndarray
    paid_out_rate: np.ndarray
    platform_pose: np.ndarray | None = None
    platform_velocity: np.ndarray | None = None
    cable_tensions: np.ndarray | None = None


@dataclass(frozen=True)
class WinchCommand:
    """Winch set-points for one time step.

    Attributes
    ----------
    paid_out : ndarray, shape (m,) [m]
        Commanded paid-out length of each winch.
    paid_out_rate : ndarray, shape (m,) [m/s]
        Its time derivative (feed-forward velocity).
    """

    paid_out: np.ndarray
    paid_out_rate: np.ndarray


@runtime_checkable
class Controller(Protocol):
    """Maps measurements to winch commands.

    Attributes
    ----------
    name : str
        Short name used in reports and tables.
    uses_pose, uses_tension : bool
        Whether :meth:`command` reads the platform pose or the cable tensions.
    """

    name: str
    uses_pose: bool
    uses_tension: bool

    def reset(self, scene, initial_paid_out) -> None:
        """Prepare for a run of ``scene`` (precompute command tables).

        ``initial_paid_out`` (shape (m,) [m]) is what the winches have paid out at t = 0.
        """

    def command(self, measurement: Measurement) -> WinchCommand:
        """The winch command for ``measurement.time``."""
