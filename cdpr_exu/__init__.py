"""cdpr-exu: cable-driven parallel robots with lumped-mass cables, simulated with Exudyn.

The names a user needs are importable from here; they load on first use, so that
``import cdpr_exu`` stays cheap (Exudyn and numba load with the first simulation)::

    import cdpr_exu
    scene = cdpr_exu.load_scene("paper-circle")
    result = cdpr_exu.simulate(scene)                 # ideal inverse kinematics
    result = cdpr_exu.simulate(scene, cdpr_exu.TensionAwareController())
"""

from __future__ import annotations

import importlib

__version__ = "0.1.0"

#: Public name -> module that defines it.
_EXPORTS: dict[str, str] = {
    "load_scene": "cdpr_exu.scenes.scene",
    "save_scene": "cdpr_exu.scenes.scene",
    "shipped_scenes": "cdpr_exu.scenes.scene",
    "Scene": "cdpr_exu.scenes.scene",
    "Effects": "cdpr_exu.scenes.scene",
    "simulate": "cdpr_exu.run.simulate",
    "Result": "cdpr_exu.results.result",
    "CdprError": "cdpr_exu.core.errors",
    "SceneError": "cdpr_exu.core.errors",
    "UnreachableError": "cdpr_exu.core.errors",
    "SolverFailure": "cdpr_exu.core.errors",
    "RunInterrupted": "cdpr_exu.core.errors",
    "OutputError": "cdpr_exu.core.errors",
    "CdprWarning": "cdpr_exu.core.errors",
    "CoarseOutputWarning": "cdpr_exu.core.errors",
    "compare_controllers": "cdpr_exu.studies.comparison",
    "CONTROLLERS": "controllers.registry",
    "Controller": "controllers.base",
    "IdealIKController": "controllers.ideal_ik",
    "TensionAwareController": "controllers.tension_aware",
    "ClosedLoopTensionAwareController": "controllers.tension_aware",
}

__all__ = sorted(_EXPORTS)


def __getattr__(name: str):
    """Load an exported name on first use (PEP 562)."""
    module = _EXPORTS.get(name)
    if module is None:
        raise AttributeError(f"module 'cdpr_exu' has no attribute {name!r}")
    value = getattr(importlib.import_module(module), name)
    globals()[name] = value
    return value


def __dir__() -> list[str]:
    return sorted(set(globals()) | set(_EXPORTS))
