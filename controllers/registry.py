"""The one registry of controller kinds, planar and spatial (:data:`CONTROLLERS`).

Each kind is a name (the one reports, ``cdpr compare --controllers``, robustness studies and the
results folders use) and a factory per dimension its physics exists in: ``CONTROLLERS[name](scene,
**options)`` makes the controller for a run of ``scene``, or refuses, naming the controller and the
scene's dimension, a kind that has no physics there (the chordal correction of the planar pulley's
polygon, on a spatial scene), before any run. :func:`controllers_for` is
the list ``cdpr compare`` runs on a scene by default: every kind its dimension has, in the
registry's order.

The registry asks the scene for its space (``scene.space.dimension``, ``.name``); a learning kind is
handed what runs its trials (``learner``, :func:`cdpr_exu.studies.learning.learners`), so that the
controllers import nothing that runs a simulation. Units SI.
"""

from __future__ import annotations

from dataclasses import dataclass
from typing import Callable, Mapping

from cdpr_exu.core.errors import SceneError

from .feedback import ClosedLoopController, FilteredPositionPI
from .ideal_ik import IdealIKController
from .ilc import LearnedController
from .tension_aware import ClosedLoopTensionAwareController, TensionAwareController

#: Gains of the spatial closed loop (:class:`~controllers.feedback.FilteredPositionPI`), lower than the planar
#: defaults: the shipped spatial scenes step at 10 ms and the loop acts one step late; with the planar gains
#: the IPAnema circle oscillated from 1 s and the run failed at 2 s (217 mm). It feeds the rotation back too.
SPATIAL_LOOP = {"proportional_gain": 0.5, "integral_gain": 5.0, "cutoff": 2.0, "rotation": True}


@dataclass(frozen=True)
class ControllerKind:
    """A kind of controller: its name and its factory ``(scene, **options) -> Controller`` per dimension.

    Attributes
    ----------
    name : str
    factories : mapping of int to callable
        By dimension (2, 3): where the kind's physics exists.
    learns : bool
        Whether the controller learns its commands over trials before its run: it then takes a ``learner``,
        ``learner(on_model) -> learner`` of :class:`controllers.ilc.LearnedController`
        (:func:`cdpr_exu.studies.learning.learners`, which runs the trials).
    """

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
        """Refuse ``scene`` if the kind has no physics in its dimension (naming both).

        Raises
        ------
        SceneError
        """
        if not self.supports(scene):
            where = " and ".join(f"{d}-D" for d in self.dimensions)
            raise SceneError(f"controller {self.name!r} has no {scene.space.name} ({scene.space.dimension}-D) "
                             f"version: it runs on {where} scenes, not on scene {scene.name!r}")

    def __call__(self, scene, **options):
        """The controller for a run of ``scene`` with ``options`` (the factory's keyword options)."""
        self.check(scene)
        if self.learns and options.get("learner") is None:
            raise SceneError(f"controller {self.name!r} learns over trials: give it a learner "
                             "(cdpr_exu.studies.learning.learners(scene, ...))")
        return self.factories[scene.space.dimension](scene, **options)


def _learned(name: str, on_model: bool, loop: bool = False, gains: Mapping | None = None) -> Callable[..., object]:
    """The factory of a learning kind: its commands learned by ``learner(on_model)`` (on the controllers'
    model, or on the robot itself for ILC), with the filtered PI loop (``gains``: its options) around them
    for ``loop``."""
    def make(scene, learner, **loop_options):
        learned = LearnedController("model_feed_forward" if loop else name, learner(on_model))
        if not loop:
            return learned
        feedback = loop_options.pop("feedback", None)
        return ClosedLoopController(name, learned, FilteredPositionPI(**(gains or {})) if feedback is None else feedback,
                                    **loop_options)
    return make


def _kinds(*kinds: ControllerKind) -> dict[str, ControllerKind]:
    return {kind.name: kind for kind in kinds}


#: Every kind of controller, by name, in the order ``cdpr compare`` runs them.
CONTROLLERS: dict[str, ControllerKind] = _kinds(
    ControllerKind("ideal_ik", {2: lambda scene: IdealIKController(), 3: lambda scene: IdealIKController()}),
    ControllerKind("tension_aware", {2: lambda scene, **o: TensionAwareController(**o),
                                     3: lambda scene, **o: TensionAwareController(**o)}),
    ControllerKind("tension_aware_chordal",
                   {2: lambda scene, **o: TensionAwareController(**{"chordal_correction": True, **o})}),
    ControllerKind("tension_aware_dynamic_chordal",
                   {2: lambda scene, **o: TensionAwareController(**{"dynamic": True, "chordal_correction": True, **o})}),
    ControllerKind("tension_aware_chain", {2: lambda scene, **o: TensionAwareController(**{"statics": "chain", **o}),
                                           3: lambda scene, **o: TensionAwareController(**{"statics": "chain", **o})}),
    ControllerKind("closed_loop_tension_aware",
                   {2: lambda scene, **o: ClosedLoopTensionAwareController(**{"dynamic": True,
                                                                             "chordal_correction": True, **o}),
                    3: lambda scene, **o: ClosedLoopTensionAwareController(**{**SPATIAL_LOOP, **o})}),
    ControllerKind("model_feed_forward", dict.fromkeys((2, 3), _learned("model_feed_forward", on_model=True)),
                   learns=True),
    ControllerKind("closed_loop_model_feed_forward",
                   {2: _learned("closed_loop_model_feed_forward", on_model=True, loop=True),
                    3: _learned("closed_loop_model_feed_forward", on_model=True, loop=True,
                                gains={**SPATIAL_LOOP, "rotation": False})},  # the learned path is positions
                   learns=True),
    ControllerKind("ilc", dict.fromkeys((2, 3), _learned("ilc", on_model=False)), learns=True),
)


def controller_kind(name: str) -> ControllerKind:
    """The kind called ``name``.

    Raises
    ------
    SceneError
        For an unknown name, listing the known ones.
    """
    if name not in CONTROLLERS:
        raise SceneError(f"unknown controller {name!r}; known: {list(CONTROLLERS)}")
    return CONTROLLERS[name]


def controllers_for(scene) -> list[str]:
    """The controllers ``cdpr compare`` runs on ``scene`` by default: every kind its dimension has, in order."""
    return [name for name, kind in CONTROLLERS.items() if kind.supports(scene)]
