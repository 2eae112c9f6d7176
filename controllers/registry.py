"""The one registry of controller kinds, planar and spatial (:data:`CONTROLLERS`).

Each kind is a name (of reports, ``cdpr compare --controllers`` and results folders) and a
factory per dimension its physics exists in: ``CONTROLLERS[name](scene, **options)`` makes the
controller, or refuses a scene of another dimension before any run. A learning kind is handed
what runs its trials (``learner``), so the controllers import nothing that simulates.
"""

from __future__ import annotations

from dataclasses import dataclass
from typing import Callable, Mapping

from cdpr_exu.core.errors import SceneError

from .feedback import ClosedLoopController, FilteredPositionPI
from .ideal_ik import IdealIKController
from .ilc import LearnedController
from .tension_aware import ClosedLoopTensionAwareController, TensionAwareController

#: Gains of the spatial closed loops (both feed the rotation back), chosen from the loop's disk margins on the
#: CoGiRo-class and IPAnema-class robots, nominal and 10 % off, at 24 poses over each run (examples/robustness_study.py,
#: which stops if the design picks others): a disk margin >= 0.87 everywhere, so >= 8 dB and >= 47 deg in every loop
#: at once. The gains first chosen by trial (:data:`SPATIAL_LOOP_PREVIOUS`) leave the CoGiRo-class cables' first
#: transverse modes (2.4 Hz) growing in the linear model; those chosen next (k_p 0.3, k_i 5 /s, f_c 1.5 Hz, from 4 poses
#: after the ramp and each loop's margins alone) kept a disk margin of 0.14 near the workspace's centre.
SPATIAL_LOOP = {"proportional_gain": 0.1, "integral_gain": 2.5, "cutoff": 1.0, "rotation": True}
SPATIAL_LOOP_PREVIOUS = {"proportional_gain": 0.5, "integral_gain": 5.0, "cutoff": 2.0, "rotation": True}


@dataclass(frozen=True)
class ControllerKind:
    """A kind of controller: its name, its factory ``(scene, **options) -> Controller`` by dimension, and
    whether it ``learns`` over trials before its run (it then takes a ``learner``,
    :func:`cdpr_exu.studies.learning.learners`)."""

    name: str
    factories: Mapping[int, Callable[..., object]]
    learns: bool = False

    @property
    def dimensions(self) -> tuple[int, ...]:
        """The dimensions the kind runs in."""
        return tuple(sorted(self.factories))

    def supports(self, scene) -> bool:
        """Whether the kind runs on ``scene`` (its dimension)."""
        return scene.space.dimension in self.factories

    def check(self, scene) -> None:
        """Refuse (SceneError) ``scene`` if the kind has no physics in its dimension, naming both."""
        if not self.supports(scene):
            where = " and ".join(f"{d}-D" for d in self.dimensions)
            raise SceneError(f"controller {self.name!r} has no {scene.space.name} ({scene.space.dimension}-D) "
                             f"version: it runs on {where} scenes, not on scene {scene.name!r}")

    def __call__(self, scene, **options):
        """The controller for a run of ``scene`` with the factory's ``options``."""
        self.check(scene)
        if self.learns and options.get("learner") is None:
            raise SceneError(f"controller {self.name!r} learns over trials: give it a learner "
                             "(cdpr_exu.studies.learning.learners(scene, ...))")
        return self.factories[scene.space.dimension](scene, **options)


def _learned(name: str, on_model: bool, loop: bool = False, gains: Mapping | None = None) -> Callable[..., object]:
    """The factory of a learning kind: commands learned by ``learner(on_model)``, with the PI loop (``gains``)
    around them for ``loop``."""
    def make(scene, learner, **loop_options):
        learned = LearnedController("model_feed_forward" if loop else name, learner(on_model))
        if not loop:
            return learned
        feedback = loop_options.pop("feedback", None)
        return ClosedLoopController(name, learned, FilteredPositionPI(**(gains or {})) if feedback is None else feedback,
                                    **loop_options)
    return make


def _preset(cls, **preset) -> Callable[..., object]:
    """The factory of ``cls`` with ``preset`` options, which a run's options override."""
    return lambda scene, **options: cls(**{**preset, **options})


def _kinds(*kinds: ControllerKind) -> dict[str, ControllerKind]:
    return {kind.name: kind for kind in kinds}


#: Every kind of controller, by name, in the order ``cdpr compare`` runs them.
CONTROLLERS: dict[str, ControllerKind] = _kinds(
    ControllerKind("ideal_ik", dict.fromkeys((2, 3), lambda scene: IdealIKController())),
    ControllerKind("tension_aware", dict.fromkeys((2, 3), _preset(TensionAwareController))),
    ControllerKind("tension_aware_chordal", {2: _preset(TensionAwareController, chordal_correction=True)}),
    ControllerKind("tension_aware_dynamic_chordal",
                   {2: _preset(TensionAwareController, dynamic=True, chordal_correction=True)}),
    ControllerKind("tension_aware_chain",
                   dict.fromkeys((2, 3), _preset(TensionAwareController, statics="chain"))),
    ControllerKind("closed_loop_tension_aware",
                   {2: _preset(ClosedLoopTensionAwareController, dynamic=True, chordal_correction=True),
                    3: _preset(ClosedLoopTensionAwareController, **SPATIAL_LOOP)}),
    ControllerKind("model_feed_forward", dict.fromkeys((2, 3), _learned("model_feed_forward", on_model=True)),
                   learns=True),
    ControllerKind("closed_loop_model_feed_forward",
                   {2: _learned("closed_loop_model_feed_forward", on_model=True, loop=True),
                    3: _learned("closed_loop_model_feed_forward", on_model=True, loop=True, gains=SPATIAL_LOOP)},
                   learns=True),
    ControllerKind("ilc", dict.fromkeys((2, 3), _learned("ilc", on_model=False)), learns=True),
)


def controller_kind(name: str) -> ControllerKind:
    """The kind called ``name``; SceneError listing the known ones for an unknown name."""
    if name not in CONTROLLERS:
        raise SceneError(f"unknown controller {name!r}; known: {list(CONTROLLERS)}")
    return CONTROLLERS[name]


def controllers_for(scene) -> list[str]:
    """The controllers ``cdpr compare`` runs on ``scene`` by default: every kind of its dimension."""
    return [name for name, kind in CONTROLLERS.items() if kind.supports(scene)]
