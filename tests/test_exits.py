"""The exits (cdpr_exu.exits): point exits, planar pulleys, swivel pulleys, their registry and TOML tables."""

import numpy as np
import pytest

from cdpr_exu.core.errors import SceneError, UnreachableError
from cdpr_exu.core.geometry import pulley_exit, swivel_pulley_exit
from cdpr_exu.exits import EXIT_KINDS, Exit, PointExit, Pulley, Swivel, exit_from_dict
from cdpr_exu.scenes.scene import CableSpec, load_scene
from cdpr_exu.space import PLANE, SPACE
from cdpr_exu.statics import statics

# Geometry is closed-form: the only error is rounding, a few ulp of metre-sized lengths.
ROUNDING = 1e-12
ANCHORS = np.array([[0.1, -1.9], [2.0, -0.4], [-1.0, 0.6]])


def test_the_registry_holds_the_shipped_kinds_by_their_names():
    assert EXIT_KINDS == {"point": PointExit, "pulley": Pulley, "swivel": Swivel}
    assert all(issubclass(kind, Exit) and kind.kind == name for name, kind in EXIT_KINDS.items())


def test_a_planar_point_exit_is_the_planar_kernel_at_radius_zero_bit_for_bit():
    exit_ = PointExit((0.5, 0.2))
    result, kernel = exit_.exit(ANCHORS), pulley_exit((0.5, 0.2), 0.0, -1, ANCHORS)
    for name in ("tangent_point", "wrap_angle", "free_length", "unit_vector", "arc_length"):
        assert np.array_equal(getattr(result, name), getattr(kernel, name)), name
    offset = ANCHORS - np.array([0.5, 0.2])
    distance = np.linalg.norm(offset, axis=1)
    assert not exit_.wraps and exit_.radius == 0.0 and exit_.top == 0.2
    assert result.cable_length == pytest.approx(distance, abs=ROUNDING)
    assert np.all(result.wrap_angle == 0.0)
    assert result.unit_vector == pytest.approx(offset / distance[:, None], abs=ROUNDING)
    assert exit_.hang_point == pytest.approx([0.5, 0.2], abs=0.0)


def test_a_spatial_point_exit_is_the_swivel_kernel_at_radius_zero_bit_for_bit():
    exit_ = PointExit((0.5, -0.3, 2.0))
    anchors = np.array([[0.1, 0.2, 0.4], [-1.0, 0.5, 0.0]])
    result, kernel = exit_.exit(anchors), swivel_pulley_exit((0.5, -0.3, 2.0), 0.0, anchors)
    assert np.array_equal(result.unit_vector, kernel.unit_vector)
    assert np.array_equal(result.cable_length, kernel.cable_length)
    assert exit_.dimension == 3 and exit_.top == 2.0


def test_a_point_exit_refuses_an_anchor_on_it():
    with pytest.raises(UnreachableError, match="coincides with the point exit"):
        PointExit((0.0, 0.0)).exit([0.0, 0.0])


def test_the_paid_out_length_inverts_the_winch_end():
    for exit_ in (Pulley((-1.75, 0.0), 0.25, -1), PointExit((1.0, 0.5)), Swivel((0.0, 0.0, 1.0), 0.1)):
        for paid_out in (0.3, 2.9, 4.0):
            end = exit_.winch_end(4.0, paid_out)
            assert np.array_equal(end[:-1], exit_.hang_point[:-1])  # straight down the winch line
            assert exit_.paid_out_length(4.0, end) == pytest.approx(paid_out, abs=ROUNDING)


def test_the_cable_length_is_the_free_span_plus_the_arc_on_the_rim():
    # the paper's cable 1: wrap about 145.7 degrees, free length about 2.471 m (kinematics docstring)
    pulley = Pulley((-1.75, 0.0), 0.25, -1)
    exit_ = pulley.exit([-0.15, -1.9])
    assert np.degrees(exit_.wrap_angle) == pytest.approx(145.68, abs=0.01)
    assert exit_.free_length == pytest.approx(2.4713, abs=1e-4)
    assert pulley.cable_length([-0.15, -1.9]) == pytest.approx(exit_.free_length + 0.25 * exit_.wrap_angle,
                                                               abs=ROUNDING)
    assert pulley.cable_length([-0.15, -1.9]) == pulley_exit((-1.75, 0.0), 0.25, -1, [-0.15, -1.9]).cable_length
    # the tangent point is on the rim, and the span leaves it tangentially
    radial = exit_.tangent_point - np.array(pulley.center)
    assert np.linalg.norm(radial) == pytest.approx(0.25, abs=ROUNDING)
    assert radial @ exit_.unit_vector == pytest.approx(0.0, abs=ROUNDING)
    # the rim point and wrap of statics' angle parametrisation agree with the exit
    angle = np.arctan2(radial[1], radial[0])
    assert pulley.rim_point(angle) == pytest.approx(exit_.tangent_point, abs=ROUNDING)
    assert pulley.wrap_to(angle) == pytest.approx(exit_.wrap_angle, abs=ROUNDING)
    assert pulley.wraps and pulley.point == pulley.center and pulley.top == 0.25


def test_a_swivel_is_the_swivel_kernel_and_gives_its_contact_physics():
    swivel = Swivel((1.5, 1.5, 0.0), 0.1, contact_stiffness=2e6, winch_line=0.4)
    anchor = np.array([0.1, 0.1, -2.0])
    assert np.array_equal(swivel.exit(anchor).unit_vector, swivel_pulley_exit((1.5, 1.5, 0.0), 0.1, anchor).unit_vector)
    assert swivel.point == swivel.inlet and swivel.wraps and swivel.top == pytest.approx(0.1, abs=0.0)
    pulley = swivel.pulley()
    assert (pulley.inlet, pulley.radius, pulley.contact_stiffness) == (swivel.inlet, 0.1, 2e6)
    assert swivel.fewest_elements(CableSpec(unstrained_length=2.4)) == 48  # elements of 0.05 m at most
    assert PointExit((0.0, 0.0, 0.0)).fewest_elements(CableSpec()) == 1


def test_statics_takes_a_point_exit_as_its_exit_point():
    cable = statics.SuspendedCable(10.0, 1e5, pulley=PointExit((0.3, 0.0)))
    assert cable.pulley is None and cable.exit_point == (0.3, 0.0)


@pytest.mark.parametrize("make, field", [
    (lambda: Pulley(center=(float("nan"), 0.0)), "pulley.center"),
    (lambda: Pulley(radius=-0.1), "pulley.radius"),
    (lambda: Pulley(radius=0.0), "pulley.radius"),
    (lambda: Pulley(side=0), "pulley.side"),
    (lambda: PointExit((0.0, 1.0, 2.0, 3.0)), "point_exit.point"),
    (lambda: Swivel(radius=-0.1), "swivel.radius"),
    (lambda: Swivel(winch_line=0.0), "swivel.winch_line"),
])
def test_a_bad_exit_is_refused_naming_the_field(make, field):
    with pytest.raises(SceneError, match=field.replace(".", r"\.")):
        make()


@pytest.mark.parametrize("space, table, expected", [
    (PLANE, {"kind": "pulley", "center": [1.0, 0.0], "radius": 0.2, "side": 1}, Pulley((1.0, 0.0), 0.2, 1)),
    (PLANE, {"point": [1.0, 0.0]}, PointExit((1.0, 0.0))),
    (SPACE, {"point": [1.0, 0.0, 2.0]}, PointExit((1.0, 0.0, 2.0))),
    (SPACE, {"kind": "swivel", "inlet": [1.0, 0.0, 2.0], "radius": 0.2}, Swivel((1.0, 0.0, 2.0), 0.2)),
])
def test_an_exit_table_makes_its_kind_and_its_table_makes_it_again(space, table, expected):
    exit_ = exit_from_dict(table, "exits[0]", space)
    assert exit_ == expected
    data = exit_.to_dict()
    assert data["kind"] == expected.kind
    assert exit_from_dict(data, "exits[0]", space) == exit_


@pytest.mark.parametrize("space, table, words", [
    (SPACE, {"kind": "pulley", "center": [0.0, 0.0]}, "exits[1].kind = 'pulley': no such exit in a spatial scene"),
    (PLANE, {"kind": "swivel", "inlet": [0.0, 0.0, 0.0]}, "exits[1].kind = 'swivel': no such exit in a planar scene"),
    (SPACE, {"kind": "drum"}, "exits[1].kind must be 'point' or 'swivel', got 'drum'"),
    (SPACE, {"point": [1.0, 2.0]}, "exits[1].point must be a finite 3-vector (x, y, z) [m]"),
    (PLANE, {"point": [1.0, 2.0], "side": 1}, "exits[1]: a point exit has one field 'point' = [x, z]"),
    (SPACE, {"kind": "swivel", "inlet": [0.0, 0.0, 0.0], "radius": -1.0}, "exits[1].radius must be positive"),
    (PLANE, {"kind": "pulley", "centre": [0.0, 0.0]}, "exits[1] has unknown field(s) ['centre']"),
    (PLANE, 5, "exits[1] must be a table"),
])
def test_a_bad_exit_table_is_refused_naming_its_place(space, table, words):
    with pytest.raises(SceneError) as caught:
        exit_from_dict(table, "exits[1]", space)
    assert words in str(caught.value)


def test_the_planar_scene_decides_its_exits_once():
    scene = load_scene("paper-circle")
    assert all(isinstance(e, Pulley) for e in scene.exits) and scene.pulley_contact
    point = load_scene("paper-catenary-fixed")
    assert point.exits == (PointExit((-1.75, 0.0)), PointExit((1.75, 0.0)))
    assert not point.pulley_contact and [e.radius for e in point.exits] == [0.0, 0.0]
