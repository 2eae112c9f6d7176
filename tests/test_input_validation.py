"""Bad input gets a clear error naming the field and the value (issue 4).

Sections: every field of every scene dataclass refused on NaN, infinities, signs,
zero, wrong types and shapes; whole scenes (consistency between parts, wrong part
types, plain-data and TOML forms); the public functions of kinematics, catenary,
statics and bending; a property test feeding malformed and extreme scene dicts, each
of which must be refused with the project's own error or run 0.05 s without a crash,
a hang or a NaN.
"""

from __future__ import annotations

import copy
import dataclasses
import re
import time
import tomllib

import numpy as np
import pytest
from hypothesis import HealthCheck, given, seed, settings
from hypothesis import strategies as st

from cdpr_exu.physics import bending
from cdpr_exu.physics import catenary
from cdpr_exu.core import geometry
from cdpr_exu.statics import kinematics
from cdpr_exu.statics import statics
from cdpr_exu.core.errors import CdprError, SceneError, SolverFailure, UnreachableError
from cdpr_exu.exits import PointExit, Pulley, Swivel
from cdpr_exu.scenes.scene import (
    MAX_ELEMENTS,
    CableSpec,
    Effects,
    PlatformSpec,
    Scene,
    SolverSpec,
    WinchSpec,
    load_scene,
    scene_from_dict,
    shipped_scene_text,
)
from cdpr_exu.run.simulate import simulate
from cdpr_exu.scenes.trajectories import CircleTrajectory, HoldTrajectory, PointToPointTrajectory
from cdpr_exu.space import PLANE, SPACE

NAN, INF = float("nan"), float("inf")

# ============================================================================ scene fields

#: Values no positive quantity may take, with the words the message must contain.
NOT_POSITIVE = [0.0, -1.0, NAN, INF, -INF, "abc", None, True, [1.0]]
NOT_NON_NEGATIVE = [-1.0, -1e-300, NAN, INF, -INF, "abc", None, False, [0.0]]
NOT_A_PAIR = [[1.0], [1.0, 2.0, 3.0], [NAN, 0.0], [0.0, INF], ["a", 0.0], [None, 0.0], 5.0, None, "ab"]
NOT_A_TRIPLE = [[1.0, 2.0], [1.0, 2.0, 3.0, 4.0], [0.0, NAN, 0.0], [0.0, -2.0, INF], 5.0, None]


def field_cases():
    """(dataclass, field, bad value) for every field of every scene dataclass."""
    positive = {
        CableSpec: ["unstrained_length", "radius", "linear_density", "youngs_modulus"],
        Pulley: ["radius", "contact_stiffness"],
        PlatformSpec: ["mass", "inertia"],
        SolverSpec: ["end_time", "step_size", "output_period"],
    }
    non_negative = {CableSpec: ["damping_constant"], Pulley: ["contact_damping"]}
    cases = []
    for cls, names in positive.items():
        # a platform's inertia left out (None) takes its dimension's default (PLATFORM_DEFAULTS)
        cases += [(cls, name, value) for name in names for value in NOT_POSITIVE
                  if not (cls is PlatformSpec and name == "inertia" and value is None)]
    for cls, names in non_negative.items():
        cases += [(cls, name, value) for name in names for value in NOT_NON_NEGATIVE]
    cases += [(CableSpec, "n_elements", v) for v in (1, 0, -15, 2.5, 15.0, "15", True, None, MAX_ELEMENTS + 1, 10**30)]
    cases += [(CableSpec, "mass_lumping", v) for v in ("lumpy", "", None, 1, ["paper"])]
    cases += [(Pulley, "center", v) for v in NOT_A_PAIR]
    cases += [(Pulley, "side", v) for v in (0, 2, -2, 0.5, True, "left", None, NAN)]
    cases += [(PlatformSpec, "anchors", v) for v in (
        [[0.1, 0.2, 0.3, 0.4]], [0.1, 0.2], [], [[0.1]], [[NAN, 0.0]], [[0.0, INF]], [["a", 0.0]], 5.0, None, "ab")]
    # None: left out, the plane's default (PLATFORM_DEFAULTS)
    cases += [(PlatformSpec, "initial_pose", v) for v in NOT_A_TRIPLE if v is not None]
    cases += [(PlatformSpec, "size", v) for v in NOT_A_PAIR + [[-0.3, 0.2]] if v is not None]
    cases += [(WinchSpec, "kind", v) for v in ("hydraulic", "", None, 1)]
    cases += [(SolverSpec, "spectral_radius", v) for v in (-0.1, 1.5, NAN, INF, "abc", None)]
    cases += [(SolverSpec, "newton", v) for v in ("quasi", None, 1)]
    cases += [(SolverSpec, "max_newton_iterations", v) for v in (0, -1, 2.5, "25", None, True, NAN, 10**9)]
    cases += [(SolverSpec, "integrator", v) for v in ("euler", "RK44", None, 4)]
    cases += [(Effects, "bending_model", v) for v in ("cubic", None, 1)]
    cases += [(Effects, "pulley_contact_model", v) for v in ("segments", "", None, 1)]
    for name in ("cable_mass", "axial_elasticity", "axial_damping", "bending", "bending_damping",
                 "pulley_contact", "slack", "gravity"):
        cases += [(Effects, name, v) for v in (1, 0, "yes", None)]
    return cases


def _owner(cls) -> str:
    return {CableSpec: "cable", Pulley: "pulley", PlatformSpec: "platform", WinchSpec: "winch",
            SolverSpec: "solver", Effects: "effects"}[cls]


def _scalar_text(value) -> str | None:
    """What the message must quote for a scalar bad value (None for containers)."""
    if isinstance(value, (list, tuple, dict)):
        return None
    return repr(value)


@pytest.mark.parametrize("cls, name, value", [
    pytest.param(cls, name, value, id=f"{cls.__name__}.{name}={value!r}") for cls, name, value in field_cases()])
def test_every_scene_field_refuses_bad_values_naming_field_and_value(cls, name, value):
    with pytest.raises(SceneError) as caught:
        cls(**{name: value})
    message = str(caught.value)
    assert f"{_owner(cls)}.{name}" in message  # the field, e.g. cable.radius or platform.anchors[0][1]
    quoted = _scalar_text(value)
    if quoted is not None:
        assert quoted in message, message  # and its value
    else:  # a container: its offending entry or its length is quoted
        assert "got" in message


def test_valid_edge_values_are_accepted():
    """Zero where zero is meaningful: no damping, no gravity, a point-mass platform."""
    assert CableSpec(damping_constant=0.0).axial_damping == 0.0
    assert Pulley(contact_damping=0.0).contact_damping == 0.0
    assert SolverSpec(spectral_radius=0.0).spectral_radius == 0.0
    assert SolverSpec(spectral_radius=1.0).spectral_radius == 1.0
    assert CableSpec(n_elements=MAX_ELEMENTS).n_elements == MAX_ELEMENTS
    assert CableSpec(n_elements=np.int64(15)).n_elements == 15
    assert Pulley(side=1.0).side == 1
    assert PlatformSpec(anchors=((0.0, 0.0), (0.0, 0.0))).is_point_mass
    assert SolverSpec(integrator="rk44").integrator == "rk44"


@pytest.mark.parametrize("radius, word", [(1e300, "inf"), (1e-300, "0.0"), (1e-200, "0.0")])
def test_cable_fields_that_overflow_the_element_properties_are_refused(radius, word):
    """radius 1e300 made Exudyn's builder raise OverflowError (pi r^4); 1e-300 a zero area."""
    with pytest.raises(SceneError, match=rf"cable\.radius = {re.escape(repr(radius))} .* of {word}"):
        CableSpec(radius=radius)


def test_step_counts_beyond_exudyns_integer_are_refused():
    with pytest.raises(SceneError, match=r"solver\.step_size .* steps; at most"):
        SolverSpec(end_time=10.0, step_size=1e-300)
    with pytest.raises(SceneError, match=r"solver\.step_size \(1\.0\) must not exceed solver\.end_time \(0\.5\)"):
        SolverSpec(end_time=0.5, step_size=1.0)


@pytest.mark.parametrize("overrides, field", [
    (dict(cable_mass=False, bending=True), "effects.bending"),
    (dict(cable_mass=False, bending=False, bending_damping=False, pulley_contact=True), "effects.pulley_contact"),
    (dict(axial_elasticity=False, axial_damping=True), "effects.axial_damping"),
    (dict(axial_elasticity=False, axial_damping=False, slack=True), "effects.slack"),
    (dict(bending=False, bending_damping=True), "effects.bending_damping"),
    (dict(colour=True), "colour"),
])
def test_inconsistent_effects_are_refused_naming_the_effect(overrides, field):
    with pytest.raises(SceneError, match=re.escape(field)):
        Effects.from_preset("full", **overrides)


@pytest.mark.parametrize("preset", ["nonsense", None, 1])
def test_unknown_preset_is_refused(preset):
    with pytest.raises(SceneError, match=r"effects\.preset"):
        Effects.from_preset(preset)


# ============================================================================ trajectories


#: A good circle centre and pose of each space, beside the bad value a case gives.
_GOOD = {PLANE: ((0.0, -1.6), (0.0, -2.0, 0.0)), SPACE: ((0.0, 0.0, 2.0), (0.0, 0.0, 2.0, 0.0, 0.0, 0.0))}


def _circle(space, **fields):
    return CircleTrajectory(fields.pop("center", _GOOD[space][0]), space=space, **fields)


def _move(space, **fields):
    pose = _GOOD[space][1]
    return PointToPointTrajectory(fields.pop("start", pose), fields.pop("end", pose), space=space, **fields)


@pytest.mark.parametrize("space", [PLANE, SPACE], ids=["planar", "spatial"])
@pytest.mark.parametrize("make, field", [
    (lambda s, v: _circle(s, center=v), "center"),
    (lambda s, v: _circle(s, radius=v), "radius"),
    (lambda s, v: _circle(s, angular_rate=v), "angular_rate"),
    (lambda s, v: _circle(s, ramp_time=v), "ramp_time"),
    (lambda s, v: HoldTrajectory(v, space=s), "pose"),
    (lambda s, v: _move(s, start=v), "start"),
    (lambda s, v: _move(s, duration=v), "duration"),
    (lambda s, v: _move(s, start_time=v), "start_time"),
])
@pytest.mark.parametrize("value", [NAN, INF, "abc", None, [1.0, NAN, 0.0]])
def test_trajectory_fields_refuse_non_finite_and_non_numeric_values(space, make, field, value):
    with pytest.raises(SceneError, match=field):
        make(space, value)


@pytest.mark.parametrize("space", [PLANE, SPACE], ids=["planar", "spatial"])
@pytest.mark.parametrize("make, field", [
    (lambda s: _circle(s, radius=-0.4), "radius"),
    (lambda s: _circle(s, ramp_time=-1.0), "ramp_time"),
    (lambda s: _move(s, duration=0.0), "duration"),
    (lambda s: _move(s, end=(0.0, -1.6)), "end"),
    (lambda s: _circle(s, center=(0.0, 0.0, 0.0, 0.0)), "center"),
])
def test_trajectory_fields_refuse_bad_signs_and_shapes(space, make, field):
    with pytest.raises(SceneError, match=field):
        make(space)


# ============================================================================ whole scenes


@pytest.mark.parametrize("changes, field", [
    (dict(name=""), "name"),
    (dict(name=3), "name"),
    (dict(description=3), "description"),
    (dict(gravity=-9.81), "gravity"),
    (dict(gravity=NAN), "gravity"),
    (dict(gravity="g"), "gravity"),
    (dict(cables=()), "cables"),
    (dict(cables=5), "cables"),
    (dict(cables="ab"), "cables"),
    (dict(cables=(CableSpec(), "cable")), r"cables\[1\]"),
    (dict(exits=(Pulley(),)), "pulleys"),
    (dict(exits=(Pulley(), None)), r"exits\[1\]"),
    (dict(exits=(Pulley(), PointExit((1.75, 0.0)))), "exits: cable 1 leaves a point while cable 0 wraps"),
    (dict(exits=(Pulley(), PointExit((1.75, 0.0, 0.0)))), r"exits\[1\] is a 3-D 'point' exit"),
    (dict(dimension=4), "dimension must be 2 \\(planar\\) or 3 \\(spatial\\), got 4"),
    (dict(platform=PlatformSpec(anchors=((0.0, 0.0),))), "platform.anchors"),
    (dict(platform={"mass": 2.5}), "platform"),
    (dict(winch="kinematic"), "winch"),
    (dict(effects="full"), "effects"),
    (dict(solver=None), "solver"),
    (dict(trajectory="circle"), "trajectory"),
    (dict(cables=(CableSpec(unstrained_length=2.0), CableSpec(unstrained_length=2.0))), r"cables\[0\]\.unstrained_length"),
    (dict(exits=(PointExit((-1.75, 0.0)), PointExit((1.75, 0.0)))), "winch.kind = 'fixed'"),
    (dict(solver=SolverSpec(integrator="rk44")), "winch.kind = 'fixed'"),
])
def test_inconsistent_or_mistyped_scene_parts_are_refused_naming_them(changes, field):
    with pytest.raises(SceneError, match=field):
        Scene(**changes)


def test_rk44_with_fixed_winches_is_accepted():
    scene = Scene(solver=SolverSpec(integrator="rk44"), winch=WinchSpec(kind="fixed"))
    assert scene.to_dict()["solver"]["integrator"] == "rk44"


@pytest.mark.parametrize("data, words", [
    (5, "a scene must be a table"),
    (None, "a scene must be a table"),
    ({"name": "x", "effects": 5}, "effects must be a table"),
    ({"name": "x", "effects": "full"}, "effects must be a table"),
    ({"name": "x", "cable": [1, 2]}, "cable must be a table"),
    ({"name": "x", "cables": {"radius": 1}}, "cables must be an array of tables"),
    ({"name": "x", "cables": [5, 6]}, "cables must be an array of tables"),
    ({"name": "x", "platform": 5}, "platform must be a table"),
    ({"name": "x", "solver": [1]}, "solver must be a table"),
    ({"name": "x", "trajectory": {"kind": "spiral"}}, "trajectory.kind"),
    ({"name": "x", "trajectory": {"kind": "circle", "speed": 2}}, "unknown key"),
    ({"name": "x", "trajectory": 5}, "trajectory must be a table"),
    ({"name": "x", "cables": [{}, {"n_elements": "many"}]}, r"cables\[1\]\.n_elements"),
    ({"name": "x", "pulleys": [{"center": [-1.75, 0]}, {"center": [1.75, "zero"]}]}, r"pulleys\[1\]\.center\[1\]"),
    ({"name": "x", "solver": {"step_size": -1e-3}}, r"solver\.step_size"),
    ({"name": "x", "weather": "rain"}, "unknown field"),
    ({"name": "x", "cable_exit": "drum"}, "cable_exit must be one of 'pulley', 'point', got 'drum'"),
    ({"name": "x", "exits": [{"point": [0.0, 0.0]}], "pulleys": []}, r"unknown field\(s\) \['pulleys'\]"),
    ({"name": "x", "dimension": 3, "exits": 5}, "exits must be an array of tables"),
])
def test_malformed_plain_data_is_refused_naming_the_field(data, words):
    with pytest.raises(SceneError, match=words):
        scene_from_dict(data)


def test_malformed_toml_file_is_refused_naming_the_file(tmp_path):
    path = tmp_path / "broken.toml"
    path.write_text("name = 'x'\n[cable\nradius = 1\n")
    with pytest.raises(SceneError, match="is not valid TOML"):
        load_scene(path)
    with pytest.raises(SceneError, match="does not exist"):
        load_scene(tmp_path / "missing.toml")


# ============================================================================ required fields, numbers (issue 23.2)

#: A scene of each kind as plain data (every field given): planar, spatial rigid, spatial over swivel pulleys.
SCENE_DATA = {
    "planar": load_scene("paper-circle").to_dict(),
    "spatial": tomllib.loads(shipped_scene_text("spatial-four-cable")),
    "swivel": tomllib.loads(shipped_scene_text("spatial-four-cable-swivel")),
}


def _from_dict(kind, data):
    return scene_from_dict(data)  # planar or spatial alike


@pytest.mark.parametrize("kind, path, field", [
    # a 1 kg platform instead (274 mm off on a spatial run), a 3.75 m cable, a platform at (0, -2):
    # each was a silent default before
    ("planar", ("platform", "mass"), "platform.mass [kg]"),
    ("planar", ("cables", 1, "unstrained_length"), "cables[1].unstrained_length [m]"),
    ("planar", ("platform", "anchors"), "platform.anchors [m]"),
    ("planar", ("platform", "inertia"), "platform.inertia [kg m^2]"),  # its anchors are off the centre
    ("planar", ("platform", "initial_pose"), "platform.initial_pose [m, m, rad]"),
    ("planar", ("pulleys", 0, "center"), "pulleys[0].center [m]"),
    ("planar", ("pulleys", 1, "radius"), "pulleys[1].radius [m]"),
    ("planar", ("pulleys", 1, "side"), "pulleys[1].side [-1 or +1]"),
    ("spatial", ("platform", "mass"), "platform.mass [kg]"),
    ("spatial", ("cables", 2, "unstrained_length"), "cables[2].unstrained_length [m]"),
    ("spatial", ("platform", "inertia"), "platform.inertia [kg m^2]"),
    ("swivel", ("platform", "mass"), "platform.mass [kg]"),
    ("swivel", ("exits", 0, "inlet"), "exits[0].inlet [m]"),
    ("swivel", ("exits", 3, "radius"), "exits[3].radius [m]"),
])
def test_a_scene_without_a_required_field_is_refused_naming_it_with_its_unit(kind, path, field):
    data = copy.deepcopy(SCENE_DATA[kind])
    del _get(data, path[:-1])[path[-1]]
    with pytest.raises(SceneError, match=re.escape(f"lacks {field}")):
        _from_dict(kind, data)


def test_a_point_mass_needs_no_inertia_and_a_point_exit_no_pulley_radius():
    """Required only where it changes the answer: a point mass feels no moment; a cable fixed at the
    pulley centre (cable_exit = "point") never touches the pulley."""
    spatial = copy.deepcopy(SCENE_DATA["swivel"])  # a point-mass platform
    assert "inertia" not in spatial["platform"]
    assert scene_from_dict(spatial).platform.inertia == (0.0, 0.0, 0.0)
    planar = load_scene("paper-catenary-fixed").to_dict()
    assert all(set(pulley) == {"center"} for pulley in planar["pulleys"])  # a point exit is its centre
    del planar["platform"]["inertia"]
    assert scene_from_dict(planar).platform.is_point_mass


def test_a_required_field_is_asked_for_only_after_the_values_given_are_checked():
    data = copy.deepcopy(SCENE_DATA["planar"])
    del data["platform"]["mass"]
    data["cables"][1]["radius"] = -1.0
    with pytest.raises(SceneError, match=r"cables\[1\]\.radius must be positive"):
        scene_from_dict(data)


@pytest.mark.parametrize("kind, path, value, field", [
    ("planar", ("platform", "mass"), "2.5", "platform.mass"),
    ("planar", ("platform", "mass"), True, "platform.mass"),
    ("planar", ("cables", 0, "radius"), "0.005", "cables[0].radius"),
    ("planar", ("gravity",), "9.8", "gravity"),
    ("planar", ("platform", "initial_pose", 1), "-2.0", "platform.initial_pose[1]"),
    ("planar", ("pulleys", 0, "center", 0), False, "pulleys[0].center[0]"),
    ("planar", ("trajectory", "radius"), "0.4", "trajectory.radius"),
    ("planar", ("trajectory", "angular_rate"), True, "trajectory.angular_rate"),
    ("spatial", ("platform", "mass"), "1.0", "platform.mass"),
    ("spatial", ("platform", "mass"), True, "platform.mass"),
    ("spatial", ("platform", "inertia", 0), "0.05", "platform.inertia"),
    ("spatial", ("platform", "inertia", 1), True, "platform.inertia"),
    ("spatial", ("platform", "anchors", 0, 2), "0.05", "platform.anchors[0]"),
    ("spatial", ("exits", 1, "point", 0), True, "exits[1].point"),
    ("spatial", ("cables", 3, "unstrained_length"), "2.55", "cables[3].unstrained_length"),
    ("swivel", ("exits", 0, "inlet", 2), False, "exits[0].inlet"),
    ("swivel", ("exits", 0, "winch_line"), "0.3", "exits[0].winch_line"),
    ("swivel", ("trajectory", "center", 2), "-0.842", "trajectory.center[2]"),
    ("swivel", ("solver", "step_size"), "1e-2", "solver.step_size"),
])
def test_text_and_booleans_are_refused_where_a_number_belongs(kind, path, value, field):
    """The string "1.0" and true/false were taken as numbers (float() accepts both)."""
    data = copy.deepcopy(SCENE_DATA[kind])
    _get(data, path[:-1])[path[-1]] = value
    with pytest.raises(SceneError, match=re.escape(field)) as caught:
        _from_dict(kind, data)
    assert "number" in str(caught.value), str(caught.value)


@pytest.mark.parametrize("value", ["1.0", True, np.bool_(True), None, b"1"])
def test_the_one_number_check_refuses_text_and_booleans_and_takes_numpy_numbers(value):
    from cdpr_exu.core.validation import finite, real_array, vector

    for check in (lambda v: finite("x", v), lambda v: real_array("x", [1.0, v]), lambda v: vector("x", [v, 0.0], 2)):
        with pytest.raises(SceneError, match="x must be"):
            check(value)
    assert finite("x", np.float32(1.5)) == 1.5 and finite("x", np.int64(3)) == 3.0
    assert vector("x", np.array([1, 2]), 2).tolist() == [1.0, 2.0]


# ============================================================================ public functions

PULLEY = ((-1.75, 0.0), 0.25, -1)
ANCHORS = [[-0.15, 0.1], [0.15, 0.1]]
CENTERS = [[-1.75, 0.0], [1.75, 0.0]]
CABLE = catenary.CatenaryCable(3.75, 0.35 * 9.81, 7.85e4)
POINT_PLATFORM = statics.SuspendedPlatform(
    (statics.SuspendedCable(3.43, 7.85e4, exit_point=(-1.75, 0.0)),
     statics.SuspendedCable(3.43, 7.85e4, exit_point=(1.75, 0.0))), mass=1.0)
POSITIONS = [0.0, 0.0, 1.0, 0.0, 2.0, 0.1]
JOINTS = [[0, 1, 2]]

#: (call, error type, words the message must contain): one row per way to get an
#: argument wrong that the functions catch today.
PUBLIC_CALLS = {
    "anchor_points pose NaN": (lambda: geometry.anchor_points([NAN, 0, 0], ANCHORS), SceneError, "pose must be finite"),
    "anchor_points pose text": (lambda: geometry.anchor_points("abc", ANCHORS), SceneError, "pose must be numeric"),
    "anchor_points pose shape": (lambda: geometry.anchor_points([0, 0], ANCHORS), SceneError, "pose must have trailing shape"),
    "anchor_points anchors shape": (lambda: geometry.anchor_points([0, 0, 0], [[[0, 0]]]), SceneError, "anchors must have shape"),
    "anchor_velocities rate shape": (lambda: geometry.anchor_velocities([0, 0, 0], [[0, 0, 0]], ANCHORS), SceneError, "pose_rate"),
    "pulley_exit inside the disc": (lambda: geometry.pulley_exit(*PULLEY, [-1.7, 0.0]), UnreachableError, "inside the pulley"),
    "pulley_exit above the outer side": (lambda: geometry.pulley_exit(*PULLEY, [-2.5, 1.0]), UnreachableError, "outer side"),
    "pulley_exit side 0": (lambda: geometry.pulley_exit((0, 0), 0.25, 0, [1, -1]), SceneError, "side must be -1"),
    "pulley_exit radius negative": (lambda: geometry.pulley_exit((0, 0), -1, -1, [1, -1]), SceneError, "radius must be >= 0"),
    "pulley_exit radius array": (lambda: geometry.pulley_exit((0, 0), [1, 2], -1, [1, -1]), SceneError, "radius must be a scalar"),
    "pulley_exit center None": (lambda: geometry.pulley_exit(None, 0.25, -1, [1, -1]), SceneError, "center"),
    "pulley_exit anchor inf": (lambda: geometry.pulley_exit(*PULLEY, [INF, -1]), SceneError, "anchor must be finite"),
    "structure_matrix pose shape": (lambda: kinematics.structure_matrix(Scene(), [0, 0]), SceneError, "pose must have trailing shape"),
    "straight_cable_nodes n 0": (lambda: kinematics.straight_cable_nodes([0, 0], [1, 1], 0), SceneError, "n_elements"),
    "straight_cable_nodes n 2.5": (lambda: kinematics.straight_cable_nodes([0, 0], [1, 1], 2.5), SceneError, "n_elements"),
    "initial_cable_nodes element 0": (lambda: kinematics.initial_cable_nodes(*PULLEY, [0, -2], 0.0, 4), SceneError, "element_length"),
    "initial_cable_nodes element NaN": (lambda: kinematics.initial_cable_nodes(*PULLEY, [0, -2], NAN, 4), SceneError, "element_length"),
    "pulley_exit side 2": (lambda: geometry.pulley_exit((0, 0), 0.25, 2, [1.0, -1.0]), SceneError, "side"),
    "CatenaryCable length negative": (lambda: catenary.CatenaryCable(-1, 1, 1), SceneError, "unstrained_length must be positive"),
    "CatenaryCable weight NaN": (lambda: catenary.CatenaryCable(1, NAN, 1), SceneError, "weight_per_length must be finite"),
    "CatenaryCable length text": (lambda: catenary.CatenaryCable("a", 1, 1), SceneError, "unstrained_length must be a real number"),
    "CatenaryCable EA 0": (lambda: catenary.CatenaryCable(1, 1, 0), SceneError, "axial_stiffness must be positive"),
    "solve_forward span NaN": (lambda: catenary.solve_forward(CABLE, [NAN, 0]), SceneError, "span"),
    "solve_forward span shape": (lambda: catenary.solve_forward(CABLE, [1, 0, 0]), SceneError, "span"),
    "solve_forward beyond reach": (lambda: catenary.solve_forward(CABLE, [10, 0]), UnreachableError, "beyond the reach"),
    "solve_forward max_strain 0": (lambda: catenary.solve_forward(CABLE, [2, -2], max_strain=0), SceneError, "max_strain"),
    "solve_forward max_tension negative": (lambda: catenary.solve_forward(CABLE, [2, -2], max_tension=-1), SceneError, "max_tension"),
    "solve_inverse vertical span": (lambda: catenary.solve_inverse([0, 1], 1, 1e5, 10), UnreachableError, "vertical"),
    "solve_inverse tension negative": (lambda: catenary.solve_inverse([1, 1], 1, 1e5, -10), SceneError, "horizontal_tension"),
    "solve_inverse weight NaN": (lambda: catenary.solve_inverse([1, 1], NAN, 1e5, 10), SceneError, "weight_per_length"),
    "state_from_end_forces tension negative": (lambda: catenary.state_from_end_forces(CABLE, -1, 1), SceneError, "horizontal_tension"),
    "state_from_end_forces tension text": (lambda: catenary.state_from_end_forces(CABLE, "a", 1), SceneError, "horizontal_tension"),
    "profile s beyond the cable": (lambda: catenary.profile(CABLE, catenary.solve_forward(CABLE, [2, -2]), [5.0]), SceneError, "s must lie in"),
    "statics Pulley side 0": (lambda: statics.Pulley((0, 0), 0.25, 0), SceneError, "side"),
    "statics Pulley radius negative": (lambda: statics.Pulley((0, 0), -0.25, -1), SceneError, "radius"),
    "statics Pulley center NaN": (lambda: statics.Pulley((NAN, 0), 0.25, -1), SceneError, "center"),
    "SuspendedCable both ends": (lambda: statics.SuspendedCable(1, 1e5, exit_point=(0, 0), pulley=statics.Pulley((0, 0), 0.25)), SceneError, "exactly one"),
    "SuspendedCable no end": (lambda: statics.SuspendedCable(1, 1e5), SceneError, "exactly one"),
    "SuspendedCable pulley text": (lambda: statics.SuspendedCable(1, 1e5, pulley="p"), SceneError, "pulley must be a Pulley"),
    "SuspendedPlatform no cables": (lambda: statics.SuspendedPlatform((), 1), SceneError, "cables"),
    "SuspendedPlatform mass NaN": (lambda: statics.SuspendedPlatform(POINT_PLATFORM.cables, NAN), SceneError, "mass"),
    "solve_statics lengths count": (lambda: statics.solve_statics(POINT_PLATFORM, [1.0]), SceneError, "unstrained_lengths"),
    "solve_statics length negative": (lambda: statics.solve_statics(POINT_PLATFORM, [-1.0, 2.0]), SceneError, "unstrained_lengths"),
    "solve_statics wrench shape": (lambda: statics.solve_statics(POINT_PLATFORM, [2.5, 2.5], external_wrench=[1, 2]), SceneError, "external_wrench"),
    "solve_statics pose NaN": (lambda: statics.solve_statics(POINT_PLATFORM, [2.5, 2.5], initial_pose=[NAN, 0]), SceneError, "initial_pose"),
    "inertial_wrench acceleration NaN": (lambda: statics.inertial_wrench(POINT_PLATFORM, (NAN, 0)), SceneError, "acceleration"),
    "solve_inverse_statics position NaN": (lambda: statics.solve_inverse_statics(POINT_PLATFORM, (NAN, -1)), SceneError, "pose"),
    "solve_inverse_statics above the exits": (lambda: statics.solve_inverse_statics(POINT_PLATFORM, (0, 1)), UnreachableError, "pulling cables"),
    "bending positions odd": (lambda: bending.bending_energy([0, 0, 1], JOINTS, 1.0), SceneError, "positions"),
    "bending joints out of range": (lambda: bending.bending_energy(POSITIONS, [[0, 1, 3]], 1.0), SceneError, "joints refer to nodes outside"),
    "bending joints repeat a node": (lambda: bending.bending_energy(POSITIONS, [[0, 0, 2]], 1.0), SceneError, "must not repeat"),
    "bending joints shape": (lambda: bending.bending_energy(POSITIONS, [0, 1, 2], 1.0), SceneError, "joints must be an integer array"),
    "bending stiffness NaN": (lambda: bending.bending_energy(POSITIONS, JOINTS, NAN), SceneError, "stiffness must be finite"),
    "bending stiffness shape": (lambda: bending.bending_energy(POSITIONS, JOINTS, [1.0, 2.0]), SceneError, "stiffness"),
    "bending velocities count": (lambda: bending.BendingSpringDamper(3, JOINTS, 1.0, 0.0).force(POSITIONS, [0, 0]), SceneError, "velocities"),
    "cable_joints one node": (lambda: bending.cable_joints([1]), SceneError, "nodes_per_cable"),
    "curvature matrix element 0": (lambda: bending.curvature_stiffness_matrix(3, JOINTS, 1.0, 0.0), SceneError, "element_length"),
}


@pytest.mark.parametrize("name", list(PUBLIC_CALLS))
def test_public_functions_refuse_bad_arguments_with_the_projects_errors(name):
    call, error, words = PUBLIC_CALLS[name]
    with pytest.raises(error, match=words):
        call()


#: Former gaps: arguments these functions let through, or refused with a bare Python
#: error instead of SceneError, until cdpr_exu.core.validation's array checks were used at
#: their entry points.
FORMER_GAPS = {
    "bending positions text -> ValueError": lambda: bending.bending_energy("abc", JOINTS, 1.0),
    "bending positions NaN -> energy NaN": lambda: bending.bending_energy([NAN, 0, 1, 0, 2, 0], JOINTS, 1.0),
    "bending joints 2.5 truncated to 2": lambda: bending.bending_energy(POSITIONS, [[0, 1, 2.5]], 1.0),
    "bending joints text -> ValueError": lambda: bending.bending_energy(POSITIONS, "abc", 1.0),
    "bending stiffness text -> ValueError": lambda: bending.bending_energy(POSITIONS, JOINTS, "k"),
    "bending stiffness negative accepted": lambda: bending.BendingSpringDamper(3, JOINTS, -1.0, 0.0),
    "cable_joints 3.7 truncated to 3": lambda: bending.cable_joints([3.7]),
    "cable_joints text -> ValueError": lambda: bending.cable_joints(["a"]),
    "rotation_matrix text -> ValueError": lambda: geometry.rotation_matrix("a"),
    "solve_forward cable text -> AttributeError": lambda: catenary.solve_forward("cable", [2, -2]),
    "solve_forward initial_guess text -> ValueError": lambda: catenary.solve_forward(CABLE, [2, -2], initial_guess="ab"),
    "span_and_jacobian tension NaN -> span NaN": lambda: catenary.span_and_jacobian(CABLE, NAN, 1.0),
    "span_and_jacobian tension negative accepted": lambda: catenary.span_and_jacobian(CABLE, -5.0, 1.0),
    "profile s text -> ValueError": lambda: catenary.profile(CABLE, catenary.solve_forward(CABLE, [2, -2]), "a"),
    "SuspendedPlatform cables 5 -> TypeError": lambda: statics.SuspendedPlatform(5, 1.0),
    "solve_statics platform text -> AttributeError": lambda: statics.solve_statics("p", [1.0]),
    "solve_statics pose text -> ValueError": lambda: statics.solve_statics(POINT_PLATFORM, [2.5, 2.5], initial_pose="ab"),
}


@pytest.mark.parametrize("name", list(FORMER_GAPS))
def test_former_validation_gaps_are_refused_with_scene_error(name):
    with pytest.raises(SceneError):
        FORMER_GAPS[name]()


#: Bad values given as NumPy numbers (as a study or a script passes them): each message shows
#: plain numbers (issue 23.9: "got np.float64(-2.0)", "got array([nan])").
NUMPY_VALUES = {
    "PlatformSpec mass": lambda: PlatformSpec(mass=np.float64(-2.0)),
    "CableSpec n_elements": lambda: CableSpec(n_elements=np.int64(1)),
    "Pulley side": lambda: Pulley(side=np.int64(0)),
    "SolverSpec spectral_radius": lambda: SolverSpec(spectral_radius=np.float64(1.5)),
    "CircleTrajectory radius": lambda: CircleTrajectory((0.0, -1.6), radius=np.float64(-2.0)),
    "PointToPointTrajectory end": lambda: PointToPointTrajectory((0.0, -2.0, 0.0), np.array([0.0, -1.6])),
    "spatial PlatformSpec mass": lambda: _spatial_platform(mass=np.float64(-2.0)),
    "spatial PlatformSpec inertia": lambda: _spatial_platform(inertia=np.array([-1.0, 1.0, 1.0])),
    "Swivel radius": lambda: Swivel(inlet=(0.0, 0.0, 0.0), radius=np.float64(-0.1)),
    "real_array NaN": lambda: _validation().real_array("x", np.array([np.nan, 1.0])),
    "per_item negative": lambda: _validation().per_item("x", np.array([-1.0, 1.0]), 2),
    "CatenaryCable length": lambda: catenary.CatenaryCable(np.float64(-1.0), 1.0, 1.0),
    "pulley_exit radius": lambda: geometry.pulley_exit((0.0, 0.0), np.float64(-1.0), -1, [1.0, -1.0]),
    "solve_statics lengths": lambda: statics.solve_statics(POINT_PLATFORM, np.array([-1.0, 2.0])),
    "SuspendedPlatform mass": lambda: statics.SuspendedPlatform(POINT_PLATFORM.cables, np.float64(np.nan)),
}


def _spatial_platform(**changes):
    return PlatformSpec(**{"mass": 5.0, "inertia": (1.0, 1.0, 1.0), "anchors": ((0.1, 0.0, 0.0),), **changes})


def _validation():
    from cdpr_exu.core import validation

    return validation


@pytest.mark.parametrize("name", list(NUMPY_VALUES))
def test_refusals_show_numpy_values_as_plain_numbers(name):
    with pytest.raises(SceneError) as caught:
        NUMPY_VALUES[name]()
    message = str(caught.value)
    assert "np." not in message and "array(" not in message and "float64" not in message, message


@pytest.mark.parametrize("value, text", [
    (np.float64(-2.0), "-2.0"), (np.int64(3), "3"), (np.array([1.0, np.nan]), "[1.0, nan]"), ("abc", "'abc'"),
    ((np.float64(1.5), 2), "(1.5, 2)"), (None, "None"), (np.bool_(True), "True"),
])
def test_shown_gives_plain_numbers_and_quoted_text(value, text):
    from cdpr_exu.core.validation import shown

    assert shown(value) == text


# ============================================================================ property test

PAPER_DICT = load_scene("paper-circle").to_dict()


def _get(data, path):
    for key in path:
        data = data[key]
    return data


def _paths(data, path=()):
    """Every leaf and container of a plain-data scene, as key paths."""
    if path:
        yield path
    if isinstance(data, dict):
        for key, value in data.items():
            yield from _paths(value, path + (key,))
    elif isinstance(data, list):
        for index, value in enumerate(data):
            yield from _paths(value, path + (index,))


def _number_paths(base, paths):
    """The paths to numbers (not booleans) of ``base``."""
    return [path for path in paths if isinstance(_get(base, path), (int, float)) and not isinstance(_get(base, path), bool)]


PATHS = sorted(_paths(PAPER_DICT), key=repr)
#: The numbers among them, drawn half the time: their mutants are accepted more
#: often, so that the simulation itself meets extreme values, not only the validation.
NUMBER_PATHS = _number_paths(PAPER_DICT, PATHS)

EXTREME_NUMBERS = st.sampled_from([0.0, -0.0, -1.0, 1e300, -1e300, 1e-300, 5e-324, NAN, INF, -INF, 10**30, 3, 2.5, 1e-9])
WRONG_TYPES = st.sampled_from([None, True, "abc", "", [], {}, [1.0], {"a": 1}, [[1.0, 2.0]], "1.0", False])


def _broken(draw, base, paths, number_paths):
    """``base`` (plain scene data) with one to three of its fields broken: an extreme number, a
    scaled one, a wrong type, a list of the wrong length, or the field removed."""
    data = copy.deepcopy(base)
    for _ in range(draw(st.integers(1, 3))):
        path = draw(st.sampled_from(number_paths) | st.sampled_from(paths))
        try:
            parent, old = _get(data, path[:-1]), _get(data, path)
        except (KeyError, IndexError, TypeError):
            continue  # an earlier mutation removed or replaced this path
        if not isinstance(parent, (dict, list)):
            continue  # replaced by text, which indexes too
        kind = draw(st.sampled_from(["number", "scaled", "type", "length", "delete"]))
        if kind == "number":
            new = draw(EXTREME_NUMBERS | st.floats(allow_nan=True, allow_infinity=True))
        elif kind == "scaled" and isinstance(old, (int, float)) and not isinstance(old, bool):
            new = old * draw(st.sampled_from([-1.0, 0.0, 1e-12, 1e-3, 1e3, 1e12, 1.0000001]))
        elif kind == "length" and isinstance(old, list):
            new = old[: draw(st.integers(0, max(len(old) - 1, 0)))] if draw(st.booleans()) else old + old[:1] * 2
        elif kind == "delete" and isinstance(parent, dict):
            del parent[path[-1]]
            continue
        else:
            new = draw(WRONG_TYPES)
        parent[path[-1]] = new
    return data


@st.composite
def malformed_scene_dicts(draw):
    """The paper scene's plain data with one to three fields broken."""
    return _broken(draw, PAPER_DICT, PATHS, NUMBER_PATHS)


#: Spatial scenes as plain data: a rigid platform on point exits (no trajectory), a point mass
#: over swivel pulleys (with trajectory, solver and winch).
SPATIAL_DICTS = [load_scene(name).to_dict() for name in ("spatial-four-cable", "spatial-four-cable-swivel")]
SPATIAL_PATHS = [sorted(_paths(base), key=repr) for base in SPATIAL_DICTS]
SPATIAL_NUMBER_PATHS = [_number_paths(base, paths) for base, paths in zip(SPATIAL_DICTS, SPATIAL_PATHS)]


@st.composite
def malformed_spatial_scene_dicts(draw):
    """A shipped spatial scene's plain data (rigid on point exits, or over swivel pulleys) with one to
    three fields broken, as :func:`malformed_scene_dicts` breaks the planar one."""
    k = draw(st.integers(0, len(SPATIAL_DICTS) - 1))
    return _broken(draw, SPATIAL_DICTS[k], SPATIAL_PATHS[k], SPATIAL_NUMBER_PATHS[k])


def _short(scene: Scene) -> Scene:
    """0.05 s, or 500 steps if the step is so small that 0.05 s would take minutes."""
    step = scene.solver.step_size
    end = max(step, min(0.05, 500 * step))
    return scene.with_changes(solver=dataclasses.replace(scene.solver, end_time=end, output_period=end / 5))


@settings(max_examples=25, deadline=None, derandomize=True, suppress_health_check=[HealthCheck.too_slow])
@given(malformed_scene_dicts())
def test_malformed_scenes_are_refused_or_run_without_crash_hang_or_nan(data):
    try:
        scene = scene_from_dict(data)
    except CdprError:
        return  # refused with the project's own error: fine
    start = time.perf_counter()
    try:
        result = simulate(_short(scene))
    except (SolverFailure, UnreachableError, SceneError) as err:
        assert str(err)  # a clear stop is acceptable; it must say something
        return
    # At most 500 steps of at most 2 x 301 nodes: seconds, not minutes.
    assert time.perf_counter() - start < 120.0
    for series in [result.pose, result.velocity, *result.nodes, *result.tensions]:
        assert np.all(np.isfinite(series))


@seed(20261124)
@settings(max_examples=300, deadline=None, suppress_health_check=[HealthCheck.too_slow])
@given(malformed_spatial_scene_dicts())
def test_malformed_spatial_scenes_are_refused_with_the_projects_errors_only(data):
    """Issue 23 (evidence): the planar fuzz extended to spatial scene dicts; validation and the
    reference check that runs before any spatial run give SceneError or UnreachableError, never
    another exception (a TypeError, an IndexError, a ValueError of NumPy's). (A colleague's fuzz
    runs the accepted ones.)"""
    from cdpr_exu.statics.workspace import check_reference

    try:
        scene = scene_from_dict(data)
        if scene.trajectory is not None:
            check_reference(scene)
    except (SceneError, UnreachableError) as err:
        assert str(err)


#: What the spatial fuzz found (issue 23), each a foreign exception or a message naming no field before:
#: (scene, key path, value, words of the refusal).
FUZZ_FINDINGS = [
    (0, ("gravity",), 1.7976931348623157e308, "give a weight of inf N"),  # ValueError in nnls
    (1, ("gravity",), 1.7976931348623157e308, "platform.mass = 5.0 kg and gravity"),
    (1, ("trajectory", "angular_rate"), 1e300, "trajectory is out of floating-point range: its acceleration at "
     "t = 0.010 s is [-inf, inf, 0.0, "),  # ValueError in nnls
    (1, ("cables", 0, "unstrained_length"), 1e308, "it would take inf, more than the 300 allowed"),  # OverflowError
    (0, ("platform", "anchors"), True, "platform.anchors must be a list of (x, z) pairs, shape (m, 2), or of "
     "(x, y, z) points, shape (m, 3), got True"),  # TypeError
    (0, ("exits", 1, "point"), [1.5, 1.5, 0.0], "share the exit_point [1.5, 1.5, 0.0] m"),  # np.float64(1.5)
    (0, ("dimension",), None, "dimension must be 2 (planar) or 3 (spatial), got None"),
    (1, ("cables", 0, "linear_density"), 1e308, "give a weight per length of inf N/m"),  # 'weight_per_length'
]


@pytest.mark.parametrize("k, path, value, words", FUZZ_FINDINGS)
def test_what_the_spatial_fuzz_found_is_refused_naming_the_field(k, path, value, words):
    from cdpr_exu.statics.workspace import check_reference

    data = copy.deepcopy(SPATIAL_DICTS[k])
    _get(data, path[:-1])[path[-1]] = value
    with pytest.raises((SceneError, UnreachableError), match=re.escape(words)):
        scene = scene_from_dict(data)
        check_reference(scene)


def test_a_spatial_rotation_vector_of_1e300_rad_gives_a_rotation_matrix():
    """rotation_from_vector squared the angle (OverflowError beyond 1e154 rad): the fuzz's trajectory.rotation."""
    from cdpr_exu.core.geometry import rotation_from_vector

    rotation = rotation_from_vector([1e300, 0.0, 0.05])
    assert np.all(np.isfinite(rotation)) and np.allclose(rotation @ rotation.T, np.eye(3), atol=1e-12)
    assert np.allclose(rotation[0], [1.0, 0.0, 0.0], atol=1e-12)  # about x (the 0.05 is lost at 1e300)


def test_a_planar_circle_too_fast_to_sample_is_refused_naming_its_rate():
    """The planar reference check took one sample per quarter turn: at 1e300 rad/s NumPy's "Maximum
    allowed size exceeded" (a ValueError, found while hunting the spatial fuzz's findings)."""
    from cdpr_exu.statics.workspace import check_reference

    data = copy.deepcopy(PAPER_DICT)
    data["trajectory"]["angular_rate"] = 1e300
    with pytest.raises(SceneError, match=r"trajectory\.angular_rate = 1e\+300 rad/s makes 6\.37e\+300 quarter turns"):
        check_reference(scene_from_dict(data))


@pytest.mark.parametrize("value", [0.0, -1e-6, 1e-2, float("nan"), "tight"])
def test_newton_tolerance_out_of_range_is_refused_naming_the_field(value):
    with pytest.raises(SceneError, match=r"solver\.newton_tolerance"):
        SolverSpec(newton_tolerance=value)
