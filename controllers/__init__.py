"""Controllers: plain NumPy, no Exudyn. See :mod:`controllers.base` for the interface."""
from .base import Controller, Measurement, SmoothStart, WinchCommand
from .ideal_ik import IdealIKController

__all__ = ["Controller", "Measurement", "SmoothStart", "WinchCommand", "IdealIKController"]
