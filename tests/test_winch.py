"""Winches: the servo drum's gain design (python-control) and its tracking on the real solver."""

from dataclasses import replace

import control
import exudyn as exu
import numpy as np
import pytest

from controllers.base import WinchCommand
from cdpr_exu.builder.model import build_model
from cdpr_exu.run.simulate import RUNS
from cdpr_exu.run.solver import solver_settings

from cdpr_exu.core.errors import SceneError
from cdpr_exu.scenes.scene import WinchSpec, load_scene
from cdpr_exu.run.simulate import simulate
from cdpr_exu.builder.winch import servo_gains


def _closed_loop_poles(spec):
    a = np.array([[0.0, 1.0, 0.0], [0.0, 0.0, 1.0], [0.0, 0.0, 0.0]])
    b = np.array([[0.0], [0.0], [1.0 / spec.drum_mass]])
    return np.linalg.eigvals(a - b @ servo_gains(spec)[None, :])


def test_pole_placement_puts_the_servo_poles_where_asked():
    spec = WinchSpec(kind="servo", servo_bandwidth=40.0)
    poles = np.sort(_closed_loop_poles(spec).real)
    np.testing.assert_allclose(poles, [-48.0, -44.0, -40.0], rtol=1e-8)  # -w, -1.1 w, -1.2 w


def test_lqr_servo_is_stable_and_about_as_fast_as_asked():
    spec = WinchSpec(kind="servo", servo_design="lqr", servo_bandwidth=40.0)
    poles = _closed_loop_poles(spec)
    assert np.all(poles.real < 0)
    # Bryson weights aim at the bandwidth: the slowest pole within a factor 2 of it.
    assert 20.0 < np.min(np.abs(poles)) < 80.0


def test_bad_drum_parameters_are_refused():
    with pytest.raises(SceneError, match="winch.drum_radius"):
        WinchSpec(kind="servo", drum_radius=0.0)
    with pytest.raises(SceneError, match="winch.servo_design"):
        WinchSpec(kind="servo", servo_design="pid")


@pytest.mark.slow
def test_servo_winch_tracks_the_command_and_matches_the_kinematic_winch():
    scene = load_scene("paper-circle")
    scene = scene.with_changes(solver=replace(scene.solver, end_time=3.0))
    kinematic = simulate(scene)
    servo = simulate(scene.with_changes(winch=WinchSpec(kind="servo")))
    assert servo.metadata["item_counts"]["servo_drums"] == 2
    # A 60 rad/s servo on a 2 kg equivalent drum: the paid-out length follows the
    # ideal-IK command to a few mm (tension disturbances of ~20 N, rates of 0.6 m/s).
    lag = np.abs(servo.paid_out - kinematic.paid_out)[servo.time > 0.5]
    assert lag.max() < 5e-3
    # ... so the platform moves as with the exact (kinematic) winch, to 5 mm.
    difference = np.linalg.norm(servo.pose[:, :2] - kinematic.pose[:, :2], axis=1)
    assert difference.max() < 5e-3


# --------------------------------------------------------------------------- servo drums in both dimensions

#: A servo scene of each dimension: the paper's planar robot over pulleys, the spatial one over swivel pulleys.
SERVO_SCENES = {2: "paper-circle", 3: "spatial-four-cable-swivel"}


def _servo_scene(dimension, end_time, step_size):
    scene = load_scene(SERVO_SCENES[dimension])
    return scene.with_changes(winch=WinchSpec(kind="servo"), solver=replace(
        scene.solver, end_time=end_time, step_size=step_size, output_period=step_size))


class _Step:
    """Holds every winch at its paid-out length at t = 0, cable 0 ``size`` [m] farther from ``at`` [s] on."""

    name, uses_pose, uses_tension = "step", False, False

    def __init__(self, at=np.inf, size=0.0):
        self.at, self.size = at, size

    def reset(self, scene, initial_paid_out):
        self.initial = np.array(initial_paid_out, dtype=float)

    def command(self, measurement):
        paid_out = self.initial.copy()
        paid_out[0] += self.size if measurement.time >= self.at else 0.0
        return WinchCommand(paid_out, np.zeros_like(paid_out))


def _held(scene):
    """(model, result) of ``scene``'s robot with every winch held at its paid-out length over the run."""
    model = build_model(scene)
    run = RUNS[type(model)](scene, model)
    hold = _Step()
    hold.reset(scene, model.initial_paid_out)
    run.begin(hold, None)
    model.mbs.SetPreStepUserFunction(run.pre_step)
    model.mbs.SetPostStepUserFunction(run.post_step)
    model.mbs.SolveDynamic(solver_settings(scene))
    result = run.result("hold", None)
    return model, result


@pytest.mark.parametrize("dimension", [2, 3])
def test_at_rest_the_servo_drum_s_motor_force_balances_the_winch_end_tension(dimension):
    """Held for 1 s (the robot settles from its start), the drum is still: its motor force is the pull
    of the winch node on it, and that is the winch element's tension less the winch node's weight and
    the bending joint's shear (measured 2.3 % and 2.7 % of the tension in the plane and in space)."""
    scene = _servo_scene(dimension, 1.0, 2e-3)
    model, result = _held(scene)
    assert len(model.servos) == scene.n_cables
    motor = np.array([model.mbs.GetLoadParameter(servo.load, "load") for servo in model.servos])
    pull = np.array([model.mbs.GetObjectOutput(servo.connector, exu.OutputVariableType.Force) for servo in model.servos])
    tension = np.array([t[-1, 0] for t in result.tensions])
    np.testing.assert_allclose(motor, -pull, rtol=1e-4)  # the drum at rest (2e-5 measured: the robot settles on)
    np.testing.assert_allclose(pull, tension, rtol=0.03)
    assert np.all(tension > 20.0)  # a taut cable: 21 N in the plane, 35 N in space
    # ... and the drum holds its commanded length (measured 6e-9 m and 1e-10 m)
    assert np.abs(result.paid_out[-1] - model.initial_paid_out).max() < 1e-7


@pytest.mark.parametrize("dimension", [2, 3])
def test_the_servo_drum_follows_a_length_step_with_its_designed_rise_time(dimension):
    """A 1 mm step of cable 0's command: the drum's 10-90 % rise time and overshoot are the designed
    closed loop's (python-control's step_info of s_cmd -> s from servo_gains: 17.4 ms, 24.8 % at 60 rad/s).
    Measured 15 ms and 24.5 % in the plane, 16 ms and 27.9 % in space, at 1 ms samples: the cable's
    tension, fed forward one step late, and the winch node's mass move them by up to 15 % and 3 points."""
    scene = _servo_scene(dimension, 0.4, 1e-3)
    result = simulate(scene, _Step(at=0.1, size=1e-3))
    spec = scene.winch
    k = servo_gains(spec)
    designed = control.step_info(control.tf([k[1], k[0]], [spec.drum_mass, k[2], k[1], k[0]]))
    after = result.time >= 0.1
    t, s = result.time[after] - 0.1, (result.paid_out[after, 0] - result.paid_out[0, 0]) / 1e-3
    rise = t[np.argmax(s >= 0.9)] - t[np.argmax(s >= 0.1)]
    assert abs(rise - designed["RiseTime"]) < 0.2 * designed["RiseTime"] + 1e-3
    assert abs(100.0 * (s.max() - 1.0) - designed["Overshoot"]) < 5.0
    assert abs(s[-1] - 1.0) < 1e-3  # settled on the command 0.3 s later (integral action; 1e-4 measured)


@pytest.mark.slow
def test_a_spatial_servo_run_over_swivel_pulleys_follows_the_reference_as_the_kinematic_winch():
    """The swivel robot's first second (the circle's ramp) at 2 ms steps: the drums' paid-out lengths stay
    within 0.1 mm of the kinematic winches' (measured 35 um: the tension, which changes by 36 N, is fed
    forward, and without it would push a 60 rad/s drum of 2 kg, stiffness m w^2 = 7.2 kN/m, 5 mm off),
    so the platform moves as with them (0.19 mm apart measured) and tracks the reference as well."""
    scene = load_scene("spatial-four-cable-swivel")
    scene = scene.with_changes(solver=replace(scene.solver, end_time=1.0, step_size=2e-3))
    kinematic = simulate(scene)
    servo = simulate(scene.with_changes(winch=WinchSpec(kind="servo")))
    assert np.abs(servo.paid_out - kinematic.paid_out).max() < 1e-4
    assert np.linalg.norm(servo.pose[:, :3] - kinematic.pose[:, :3], axis=1).max() < 5e-4
    errors = [np.linalg.norm(r.pose[:, :3] - r.reference[:, :3], axis=1).max() for r in (servo, kinematic)]
    assert abs(errors[0] - errors[1]) < 2e-4  # 7.27 mm and 7.23 mm measured


def test_a_spatial_scene_with_point_exits_refuses_servo_winches_naming_winch_kind():
    scene = load_scene("spatial-four-cable")
    with pytest.raises(SceneError, match=r"winch\.kind = 'servo' needs swivel exits: exits \[0, 1, 2, 3\] are points"):
        scene.with_changes(winch=WinchSpec(kind="servo"))


def _held_tension_swing(scene) -> float:
    """Largest peak-to-peak winch-end tension [N] of ``scene``'s robot held by its servo drums, after 0.5 s."""
    result = _held(scene)[1]
    late = result.time > 0.5
    return max(float(np.ptp(t[late, 0])) for t in result.tensions)


def test_a_servo_step_too_coarse_for_the_drum_on_its_cable_is_refused_and_the_largest_allowed_holds_still():
    """The drum's motor force is set once per step: a step beyond MAX_SERVO_STEP / sqrt(k / m) is refused
    before any run, naming solver.step_size and its limit (the shipped swivel robot's 10 ms: 1.28). Held
    for 1 s, its 35 N winch-end tensions swing by 0.6 N at 5 ms (0.64, allowed) and by 67 N at the refused
    10 ms (the scene forced past its check to show why)."""
    with pytest.raises(SceneError, match=r"solver\.step_size = 0\.01 s is too coarse .* <= 0\.0055 s"):
        _servo_scene(3, 1.0, 1e-2)
    allowed = _servo_scene(3, 1.0, 5e-3)
    assert _held_tension_swing(allowed) < 2.0  # 0.58 N measured
    forced = _servo_scene(3, 1.0, 5e-3)
    object.__setattr__(forced.solver, "step_size", 1e-2)  # past the check: what it refuses
    object.__setattr__(forced.solver, "output_period", 1e-2)
    assert _held_tension_swing(forced) > 20.0  # 67 N measured


# --------------------------------------------------------------------------- slack rope at the drum

from cdpr_exu.builder.winch import RESERVOIR_THRESHOLD, TAUT_MARGIN, reservoir_split  # noqa: E402


@pytest.mark.parametrize("change, node, surplus, length", [
    (0.10, 0.0, 0.0, 0.25), (0.10, 0.0, 0.0, 0.19), (0.12, 0.05, 0.03, 0.20), (-0.02, 0.05, 0.03, 0.30),
    (0.0, 0.05, 0.0, 0.10)])
def test_rope_is_conserved_between_the_node_and_the_drum(change, node, surplus, length):
    new_node, new_surplus = reservoir_split(change, node, surplus, length, 0.25)
    assert new_node + new_surplus == pytest.approx(change, abs=1e-15)
    assert new_surplus >= -1e-15


def test_a_taut_element_lets_the_node_follow_the_command():
    assert reservoir_split(0.004, 0.0, 0.0, 0.2501, 0.25) == (0.004, 0.0)
    assert reservoir_split(-0.004, 0.0, 0.0, 0.2501, 0.25) == (-0.004, 0.0)


def test_paying_out_slack_rope_stops_the_node_at_the_shortest_element():
    """The first element may shorten to RESERVOIR_THRESHOLD of its length, no further."""
    node, surplus = reservoir_split(0.10, 0.0, 0.0, 0.20, 0.25)
    assert 0.20 - node == pytest.approx(RESERVOIR_THRESHOLD * 0.25)
    assert surplus == pytest.approx(0.10 - node)


def test_hauling_in_a_slack_cable_takes_up_the_surplus_before_the_node_moves():
    # the first element 0.26 m long, its rest length 0.25 + 0.03 m: slack
    node, surplus = reservoir_split(0.06, 0.05, 0.03, 0.26, 0.25)  # hauled in 0.02 of the 0.03 surplus
    assert (node, surplus) == (pytest.approx(0.05), pytest.approx(0.01))
    # hauled in 0.05, more than the 0.02 of slack: 0.02 of the surplus goes, and a margin of
    # TAUT_MARGIN of the rest length (the element ends just past its rest length 0.25 + 0.01, taut but
    # off the law's kink, not stretched by the excess), the node takes the rest
    margin = TAUT_MARGIN * 0.25
    node, surplus = reservoir_split(0.03, 0.05, 0.03, 0.26, 0.25)
    assert (node, surplus) == (pytest.approx(0.02 + margin, abs=1e-15), pytest.approx(0.01 - margin, abs=1e-15))
    # 0.24 m long, 0.04 of slack: hauled in more than the whole 0.03 surplus, which all goes
    node, surplus = reservoir_split(0.03, 0.05, 0.03, 0.24, 0.25)
    assert (node, surplus) == (pytest.approx(0.03), pytest.approx(0.0))


def test_hauling_in_a_taut_cable_moves_the_node_and_keeps_the_surplus_in_the_element():
    # 0.30 m against a rest length of 0.28 m: taut, the surplus is taut rope of that element;
    # shrinking its rest instead would strain it at the haul-in rate (a 240-element paper
    # circle was refused at 5 % strain that way)
    node, surplus = reservoir_split(0.06, 0.05, 0.03, 0.30, 0.25)
    assert (node, surplus) == (pytest.approx(0.03), pytest.approx(0.03))


def test_the_massless_presets_keep_their_step_on_stiff_ropes_and_a_light_platform():
    """0.05 kg on E = 1e12 ropes at 1e-4 s: Newton converges at every step, so the
    adaptive step never shrinks (it did 350-fold at Exudyn's default tolerance)."""
    from cdpr_exu.scenes.scene import Effects

    paper = load_scene("paper-circle")
    scene = paper.with_changes(
        effects=Effects.from_preset("ideal"),
        cables=tuple(replace(c, youngs_modulus=1e12) for c in paper.cables),
        platform=replace(paper.platform, mass=0.05, inertia=paper.platform.inertia * 0.02),
        solver=replace(paper.solver, end_time=0.05, step_size=1e-4, output_period=1e-3))
    result = simulate(scene)
    assert result.steps <= scene.solver.n_steps + 1  # Exudyn counts the initial step too


def test_a_fine_cable_hauls_in_its_slack_rope_without_straining_the_winch_element():
    """240 elements on the paper circle's abrupt start: the winch element goes slack, keeps
    about 5 mm of surplus rope, and the cable is hauled in taut from t = 0.3 s on. The
    winch element stays below 0.2 % strain against its rest length (measured: at most
    0.024 %), where its shrinking rest length strained it to 5 % before (run refused at
    t = 0.52 s), and reeling in more surplus than its slack in the step it snapped taut,
    0.37 % (0.08 % in a run with shorter steps there). The snap itself is not resolved by
    the step: with another step history (Newton's Jacobian changed only) the element, paid
    out and snapping taut within one step, kept 0.76 % of Kelvin-Voigt strain, relaxing at
    d_n / E = 1 s, with the reservoir untouched."""
    paper = load_scene("paper-circle")
    scene = paper.with_changes(cables=tuple(replace(c, n_elements=240) for c in paper.cables),
                               solver=replace(paper.solver, end_time=0.6))
    result = simulate(scene)
    assert result.time[-1] == pytest.approx(0.6, abs=2e-3)
    assert result.winch_reservoir.max() > 1e-3  # the case has surplus rope at a drum
    cable = scene.cables[0]
    first = np.linalg.norm(result.nodes[0][:, 1] - result.nodes[0][:, 0], axis=1)
    rest = cable.element_length + result.winch_reservoir[:, 0]
    assert np.max(first / rest - 1.0) < 2e-3
