"""A toy exit kind added from outside the library: one class here plus one registry entry (issue 24).

An :class:`Eyelet` is a fixed ring the cable runs through: a point with a guide radius, which
refuses a cable that leaves it more than ``max_angle`` away from its guide's axis (straight
down). Nothing in cdpr_exu knows it: the registry entry ``EXIT_KINDS["eyelet"] = Eyelet``
is all it takes for planar and spatial scene files to use it (``[[exits]]`` with
``kind = "eyelet"``), for the scene to validate and save it, and for the ideal kinematics to
compute its cables' lengths, and for :func:`cdpr_exu.simulate` to run its scenes in Exudyn
(the builders, the rest and the run sides ask each exit, never its kind).
"""

from __future__ import annotations

import dataclasses
import math
from dataclasses import dataclass
from typing import Any, ClassVar, Mapping

import numpy as np
import pytest

import cdpr_exu
from cdpr_exu.statics.kinematics import ideal_paid_out
from cdpr_exu.core.errors import SceneError, UnreachableError
from cdpr_exu.core.geometry import PulleyExit, finite_array
from cdpr_exu.core.validation import from_table, non_negative, positive, vector
from cdpr_exu.exits import EXIT_KINDS, Exit
from cdpr_exu.scenes.scene import load_scene, save_scene, scene_from_dict

# Straight cables: their lengths are distances, exact to a few ulp of metre-sized lengths.
ROUNDING = 1e-12
# A run over eyelets against the same run over point exits: the eyelet's straight cable (a difference and a
# norm) and the point exit's kernel (the swivel pulley's at radius 0 in space) agree to a few ulp; the
# implicit integrator carries that round-off without amplifying it. Bounds: 1e-12 m (the bound on
# moved numbers) on poses, nodes and paid-out lengths (measured: 0 in the plane, where both kernels are the
# same arithmetic, 4.4e-15 m in space), and 1e-9 of the run's largest tension on tensions (stiff cables:
# EA ~ 1e7 N turns 4e-15 m over a 0.3 m element into ~1e-7 N; measured 1.4e-8 N of 449 N, 3e-11).
RUN_ROUNDING_M = 1e-12
RUN_ROUNDING_TENSION = 1e-9


@dataclass(frozen=True)
class Eyelet(Exit):
    """A ring at ``point`` that guides the cable: it leaves at most ``max_angle`` from the vertical below.

    Parameters
    ----------
    point : (x, z) or (x, y, z) [m]
    guide_radius : float [m]
        The ring's radius (for drawing; the cable leaves from its centre: nothing wraps).
    max_angle : float [rad]
        The largest angle between the cable and the downward vertical the ring lets through.
    """

    kind: ClassVar[str] = "eyelet"
    dimensions: ClassVar[tuple[int, ...]] = (2, 3)
    required_fields: ClassVar[dict[str, str]] = {"point": "m", "guide_radius": "m"}
    path_head: ClassVar[str] = "eyelet"

    point: tuple = (0.0, 0.0)
    guide_radius: float = 0.01
    max_angle: float = math.radians(80.0)

    def __post_init__(self) -> None:
        object.__setattr__(self, "point", tuple(float(v) for v in vector("eyelet.point", self.point, len(self.point))))
        object.__setattr__(self, "guide_radius", positive("eyelet.guide_radius", self.guide_radius, "m"))
        object.__setattr__(self, "max_angle", non_negative("eyelet.max_angle", self.max_angle, "rad"))

    @property
    def radius(self) -> float:
        return 0.0  # the cable leaves from the ring's centre

    def exit(self, anchor_points) -> PulleyExit:
        anchors = finite_array("anchor", anchor_points, (len(self.point),))
        offset = anchors - np.asarray(self.point)
        length = np.linalg.norm(offset, axis=-1)
        if np.any(length == 0.0):
            raise UnreachableError(f"anchor coincides with the eyelet {list(self.point)}")
        angle = np.arccos(np.clip(-offset[..., -1] / length, -1.0, 1.0))
        if np.any(angle > self.max_angle):
            raise UnreachableError(f"the cable leaves the eyelet at {list(self.point)} m at "
                                   f"{np.degrees(np.max(angle)):.1f} deg from its guide's axis, more than its "
                                   f"max_angle {np.degrees(self.max_angle):.1f} deg")
        scalar = anchors.ndim == 1
        return PulleyExit(tangent_point=np.broadcast_to(np.asarray(self.point), anchors.shape).copy(),
                          wrap_angle=0.0 if scalar else np.zeros(len(anchors)),
                          free_length=float(length) if scalar else length, unit_vector=offset / length[..., None],
                          arc_length=0.0 if scalar else np.zeros(len(anchors)))

    @classmethod
    def from_dict(cls, data: Mapping[str, Any], path: str, space) -> "Eyelet":
        data = dict(data)
        if "point" in data:
            data["point"] = tuple(vector(f"{path}.point", data["point"], space.position_size))
        return from_table(cls, data, path, cls.path_head)


@pytest.fixture
def eyelets(monkeypatch):
    """The one registry entry (undone after the test)."""
    monkeypatch.setitem(EXIT_KINDS, "eyelet", Eyelet)


PLANAR = """
name = "planar-eyelets"
[cable]
unstrained_length = 2.6
n_elements = 10
[[cables]]
[[cables]]
[[exits]]
kind = "eyelet"
point = [-1.75, 0.0]
guide_radius = 0.02
[[exits]]
kind = "eyelet"
point = [1.75, 0.0]
guide_radius = 0.02
[platform]
mass = 1.0
anchors = [[0.0, 0.0], [0.0, 0.0]]
initial_pose = [0.0, -1.75, 0.0]
[winch]
kind = "fixed"
[trajectory]
kind = "hold"
pose = [0.0, -1.75, 0.0]
"""

SPATIAL = """
name = "spatial-eyelets"
dimension = 3
[cable]
n_elements = 10
[[cables]]
unstrained_length = 2.5
[[cables]]
unstrained_length = 2.5
[[cables]]
unstrained_length = 2.5
[[exits]]
kind = "eyelet"
point = [1.5, 0.0, 0.0]
guide_radius = 0.02
[[exits]]
kind = "eyelet"
point = [-0.75, 1.3, 0.0]
guide_radius = 0.02
[[exits]]
kind = "eyelet"
point = [-0.75, -1.3, 0.0]
guide_radius = 0.02
[platform]
mass = 5.0
anchors = [[0.0, 0.0, 0.0], [0.0, 0.0, 0.0], [0.0, 0.0, 0.0]]
"""


def _scene(text: str):
    import tomllib

    return scene_from_dict(tomllib.loads(text))


def test_a_planar_and_a_spatial_scene_load_with_eyelets_and_give_their_ideal_cable_lengths(eyelets):
    for text, poses in ((PLANAR, np.array([[0.0, -1.75, 0.0], [0.3, -1.5, 0.0]])),
                        (SPATIAL, np.array([[0.0, 0.0, -1.8, 0.0, 0.0, 0.0], [0.2, -0.1, -1.6, 0.0, 0.0, 0.0]]))):
        scene = _scene(text)
        assert all(isinstance(e, Eyelet) for e in scene.exits) and not scene.pulley_contact
        anchors = scene.space.anchor_points(poses, np.asarray(scene.platform.anchors))  # (N, m, d)
        lengths = np.column_stack([e.cable_length(anchors[:, i]) for i, e in enumerate(scene.exits)])
        straight = np.linalg.norm(anchors - scene.exit_points, axis=-1)
        assert lengths == pytest.approx(straight, abs=ROUNDING)
        # the ideal kinematics the controllers use ask the eyelets
        assert np.array_equal(ideal_paid_out(scene, poses)[0], lengths)


def test_scenes_with_eyelets_save_in_the_exits_form_and_load_back_equal(eyelets, tmp_path):
    for text in (PLANAR, SPATIAL):
        scene = _scene(text)
        path = save_scene(scene, tmp_path / f"{scene.name}.toml")
        assert "[[exits]]" in path.read_text() and 'kind = "eyelet"' in path.read_text()
        assert load_scene(path) == scene


def test_an_eyelet_refuses_a_cable_beyond_its_guide_and_names_itself_in_the_scene(eyelets):
    with pytest.raises(UnreachableError, match="more than its max_angle"):
        Eyelet((0.0, 0.0), max_angle=math.radians(10.0)).exit([1.0, -1.0])
    sideways = PLANAR.replace("guide_radius = 0.02", "guide_radius = 0.02\nmax_angle = 0.1", 1)
    with pytest.raises(UnreachableError, match=r"cannot be reached over exits\[0\] \(exits\[0\]\.point"):
        _scene(sideways)
    second_bad = PLANAR.replace("guide_radius = 0.02", "guide_radius = -0.02").replace("-0.02", "0.02", 1)
    with pytest.raises(SceneError, match=r"exits\[1\]\.guide_radius must be positive"):
        _scene(second_bad)
    with pytest.raises(SceneError, match=r"lacks exits\[0\]\.guide_radius \[m\]"):
        _scene(SPATIAL.replace("guide_radius = 0.02\n", "", 1))


def test_without_its_registry_entry_the_kind_is_unknown():
    with pytest.raises(SceneError, match=r"exits\[0\]\.kind must be 'point' or 'swivel', got 'eyelet'"):
        _scene(SPATIAL)


def _over_eyelets(scene, max_angle: float, trajectory=None):
    """``scene`` with an eyelet (guide radius 2 cm, ``max_angle``) at each of its point exits, in the exits form."""
    data = {key: value for key, value in scene.to_dict().items() if key not in ("cable_exit", "pulleys", "pulley")}
    data["dimension"] = scene.dimension
    data["exits"] = [{"kind": "eyelet", "point": list(exit_.point), "guide_radius": 0.02, "max_angle": max_angle}
                     for exit_ in scene.exits]
    if trajectory is not None:
        data["trajectory"] = trajectory
    return scene_from_dict(data)


def _short(name: str, end_time: float):
    scene = cdpr_exu.load_scene(name)
    assert {exit_.kind for exit_ in scene.exits} == {"point"}
    return scene.with_changes(solver=dataclasses.replace(scene.solver, end_time=end_time))


# The shipped scenes over point exits, one per dimension: the planar catenary held at its winches (15 elements
# per cable, 2 cables, hold) and the CoGiRo-class robot (8 cables of 20 elements, its circle).
SHIPPED_POINT_EXITS = {"planar": "paper-catenary-fixed", "spatial": "spatial-cogiro"}


@pytest.mark.parametrize("name", SHIPPED_POINT_EXITS.values(), ids=SHIPPED_POINT_EXITS.keys())
def test_a_shipped_scene_over_eyelets_runs_in_exudyn_as_over_its_point_exits(eyelets, name):
    """An eyelet whose cable stays within its guide angle is a fixed point: the run is the point-exit run."""
    scene = _short(name, 0.05)
    over_eyelets = _over_eyelets(scene, math.radians(89.0))
    point, eyelet = cdpr_exu.simulate(scene), cdpr_exu.simulate(over_eyelets)
    assert type(eyelet) is type(point) and eyelet.status == point.status == "completed"
    assert eyelet.dimension == scene.dimension and eyelet.steps == point.steps > 0
    assert np.array_equal(eyelet.time, point.time) and np.array_equal(eyelet.reference, point.reference)
    assert eyelet.pose == pytest.approx(point.pose, abs=RUN_ROUNDING_M, rel=0)
    assert eyelet.paid_out == pytest.approx(point.paid_out, abs=RUN_ROUNDING_M, rel=0)
    for ours, theirs in zip(eyelet.nodes, point.nodes, strict=True):
        assert ours == pytest.approx(theirs, abs=RUN_ROUNDING_M, rel=0)
    largest = max(float(np.max(np.abs(t))) for t in point.tensions)
    for ours, theirs in zip(eyelet.tensions, point.tensions, strict=True):
        assert ours == pytest.approx(theirs, abs=RUN_ROUNDING_TENSION * largest, rel=0)
    # the platform hangs on its cables (each holds more than 1 N at the end, 1 kg planar, tonnes in space):
    # the comparison is not of two idle runs
    assert min(float(np.max(t[-1])) for t in point.tensions) > 1.0


@pytest.mark.parametrize("name", SHIPPED_POINT_EXITS.values(), ids=SHIPPED_POINT_EXITS.keys())
def test_a_reference_leaving_an_eyelets_guide_angle_is_refused_before_the_run(eyelets, name):
    """Held 0.5 m aside (+x), a cable leaves its eyelet further from the vertical than any did at the start."""
    scene = _short(name, 0.05)
    start = np.asarray(scene.trajectory.pose(0.0), dtype=float)
    aside = start + 0.5 * np.eye(len(start))[0]

    def steepest(pose):  # the largest angle [rad] of a cable from the downward vertical at its exit
        offsets = scene.space.anchor_points(pose, np.asarray(scene.platform.anchors)) - scene.exit_points
        return float(np.max(np.arccos(-offsets[:, -1] / np.linalg.norm(offsets, axis=-1))))

    assert steepest(aside) > steepest(start)
    max_angle = 0.5 * (steepest(start) + steepest(aside))  # the start within the guides, the pose aside not
    runs = _over_eyelets(scene, max_angle)
    refused = _over_eyelets(scene, max_angle, {"kind": "hold", "pose": aside.tolist()})
    calls: list[float] = []
    with pytest.raises(UnreachableError, match=r"cannot be reached over exits\[\d\].*more than its max_angle"):
        cdpr_exu.simulate(refused, progress=lambda t, wall: calls.append(t))
    assert calls == []  # refused before a step
    assert cdpr_exu.simulate(runs).status == "completed"  # the same eyelets along the shipped reference
