"""The golden cases: short runs, rests and statics of every kind the library has, planar and spatial.

Each case is a function returning a dict of arrays. ``tests/golden/make_golden.py`` stores
them once (``tests/golden/<case>.npz``) from a version of the code whose results are
trusted; ``tests/test_golden.py`` recomputes them with today's code and asks for the same
numbers bit for bit (``np.array_equal``). A restructuring of the library must leave them
all unchanged; a change that moves a number on purpose regenerates the file it moves and
says in its commit which numbers moved and by how much.

Cases call the library through its public entry points; when those move, the calls here
move with them, the stored numbers do not.
"""

from __future__ import annotations

from dataclasses import replace

import numpy as np

#: Every case, by name: a function returning {array name: ndarray}.
CASES = {}


def case(function):
    CASES[function.__name__] = function
    return function


# --------------------------------------------------------------------------- helpers


def _short(scene, end_time):
    return scene.with_changes(solver=replace(scene.solver, end_time=end_time))


def _planar(name, end_time, **changes):
    from cdpr_exu.scenes.scene import load_scene

    scene = _short(load_scene(name), end_time)
    return scene.with_changes(**changes) if changes else scene


def _spatial(name, end_time):
    from cdpr_exu.scenes.scene import load_scene

    return _short(load_scene(name), end_time)


def _run_arrays(result, pose, reference):
    """The arrays of a run that a restructuring must keep: poses, lengths, tensions, the last nodes."""
    arrays = {"time": np.asarray(result.time), "pose": np.asarray(pose), "reference": np.asarray(reference),
              "paid_out": np.asarray(result.paid_out), "steps": np.array(result.steps),
              "newton_iterations": np.array(result.newton_iterations)}
    for i, (nodes, tensions) in enumerate(zip(result.nodes, result.tensions)):
        arrays[f"tensions_{i}"] = np.asarray(tensions)
        arrays[f"last_nodes_{i}"] = np.asarray(nodes)[-1]
    return arrays


def _run(scene, controller=None):
    from cdpr_exu.run.simulate import simulate

    result = simulate(scene, controller)
    return _run_arrays(result, result.pose, result.reference)


_planar_run = _spatial_run = _run


def _comparison_scene(name="paper-circle", end_time=1.5):
    from cdpr_exu.studies.comparison import smooth_start

    return smooth_start(_planar(name, end_time))


# --------------------------------------------------------------------------- planar runs


@case
def planar_paper_circle_ideal_ik():
    return _planar_run(_planar("paper-circle", 1.0))


@case
def planar_preset_paper():
    from cdpr_exu.scenes.scene import Effects

    return _planar_run(_planar("paper-circle", 0.5, effects=Effects.from_preset("paper")))


@case
def planar_preset_catenary():
    from cdpr_exu.scenes.scene import Effects

    return _planar_run(_planar("paper-circle", 0.5, effects=Effects.from_preset("catenary")))


@case
def planar_preset_elastic():
    from cdpr_exu.scenes.scene import Effects

    return _planar_run(_planar("paper-circle", 0.5, effects=Effects.from_preset("elastic")))


@case
def planar_preset_ideal():
    from cdpr_exu.scenes.scene import Effects

    return _planar_run(_planar("paper-circle", 0.5, effects=Effects.from_preset("ideal")))


@case
def planar_linear_bending():
    from cdpr_exu.scenes.scene import Effects

    return _planar_run(_planar("paper-circle", 0.5, effects=Effects.from_preset("full", bending_model="linear")))


@case
def planar_segment_contact():
    from cdpr_exu.scenes.scene import Effects

    return _planar_run(_planar("paper-circle", 0.5,
                               effects=Effects.from_preset("full", pulley_contact_model="segment")))


@case
def planar_smooth_node_contact():
    from cdpr_exu.scenes.scene import Effects

    return _planar_run(_planar("paper-circle", 0.3,
                               effects=Effects.from_preset("full", pulley_contact_model="node_smooth")))


@case
def planar_servo_winch():
    from cdpr_exu.scenes.scene import WinchSpec

    return _planar_run(_planar("paper-circle", 0.5, winch=WinchSpec(kind="servo")))


@case
def planar_fine_cable_sparse_jacobian():
    scene = _planar("paper-circle", 0.3)
    return _planar_run(scene.with_changes(cables=tuple(replace(c, n_elements=40) for c in scene.cables),
                                          solver=replace(scene.solver, step_size=1e-2)))


@case
def planar_mismatch_tension_aware():
    from controllers.tension_aware import TensionAwareController

    return _planar_run(_comparison_scene("paper-circle-mismatch", 1.0), TensionAwareController())


# --------------------------------------------------------------------------- planar controllers


def _planar_controller(name, end_time=1.5):
    from controllers.registry import CONTROLLERS

    scene = _comparison_scene(end_time=end_time)
    return _planar_run(scene, CONTROLLERS[name](scene))


@case
def planar_controller_ideal_ik():
    return _planar_controller("ideal_ik")


@case
def planar_controller_tension_aware():
    return _planar_controller("tension_aware")


@case
def planar_controller_tension_aware_chordal():
    return _planar_controller("tension_aware_chordal")


@case
def planar_controller_tension_aware_dynamic_chordal():
    return _planar_controller("tension_aware_dynamic_chordal")


@case
def planar_controller_tension_aware_chain():
    return _planar_controller("tension_aware_chain")


@case
def planar_controller_closed_loop_tension_aware():
    return _planar_controller("closed_loop_tension_aware")


def _learning(name):
    from cdpr_exu.studies.learning import learners
    from controllers.ilc import StoppingRule
    from controllers.registry import CONTROLLERS

    scene = _comparison_scene(end_time=1.5)
    return _planar_run(scene, CONTROLLERS[name](scene, learner=learners(scene, StoppingRule(max_trials=2))))


@case
def planar_controller_ilc():
    return _learning("ilc")


@case
def planar_controller_model_feed_forward():
    return _learning("model_feed_forward")


@case
def planar_controller_closed_loop_model_feed_forward():
    return _learning("closed_loop_model_feed_forward")


# --------------------------------------------------------------------------- planar rest and statics


def _rest_arrays(rest):
    arrays = {"position": np.asarray(rest.position), "rotation": np.array(float(np.degrees(rest.rotation))),
              "anchor_tensions": np.asarray(rest.anchor_tensions)}
    for i, (nodes, tensions) in enumerate(zip(rest.nodes, rest.tensions)):
        arrays[f"nodes_{i}"], arrays[f"tensions_{i}"] = np.asarray(nodes), np.asarray(tensions)
    return arrays


@case
def planar_rest_over_pulleys():
    from cdpr_exu.run.rest import solve_rest

    return _rest_arrays(solve_rest(_planar("paper-catenary", 10.0)))


@case
def planar_rest_point_exits():
    from cdpr_exu.run.rest import solve_rest

    return _rest_arrays(solve_rest(_planar("paper-catenary-fixed", 10.0)))


@case
def planar_catenary_statics():
    from cdpr_exu.statics.statics import catenary_platform, solve_inverse_statics, solve_statics

    scene = _planar("paper-circle", 1.0)
    platform = catenary_platform(scene)
    inverse = solve_inverse_statics(platform, (0.2, -1.8))
    forward = solve_statics(platform, inverse.unstrained_lengths)
    return {"inverse_lengths": np.asarray(inverse.unstrained_lengths), "inverse_rotation": np.array(inverse.rotation),
            "forward_position": np.asarray(forward.position), "forward_rotation": np.array(forward.rotation),
            "forward_tensions": np.asarray(forward.tensions_at_anchor)}


@case
def planar_chain_statics():
    from cdpr_exu.statics.statics import catenary_platform, solve_inverse_statics
    from cdpr_exu.statics.chain_statics import chain_robot, solve_inverse_chain_statics

    scene = _planar("paper-circle", 1.0)
    start = solve_inverse_statics(catenary_platform(scene), (0.2, -1.8))
    equilibrium = solve_inverse_chain_statics(chain_robot(scene), (0.2, -1.8, start.rotation),
                                              tension_guess=[c.tension_at_anchor for c in start.cables])
    arrays = {"paid_out": np.asarray(equilibrium.paid_out), "rotation": np.array(equilibrium.rotation)}
    for i, nodes in enumerate(equilibrium.nodes):
        arrays[f"nodes_{i}"] = np.asarray(nodes)
    return arrays


# --------------------------------------------------------------------------- spatial runs


@case
def spatial_four_cable_ideal_ik():
    """The four-cable robot (no reference of its own) moved 5 cm across and 3 cm up from its rest."""
    from cdpr_exu.scenes.trajectories import PointToPointTrajectory
    from cdpr_exu.space import SPACE
    from cdpr_exu.statics.statics import catenary_platform, solve_statics

    scene = _spatial("spatial-four-cable", 0.6)
    rest = solve_statics(catenary_platform(scene), scene.unstrained_lengths)
    start = np.concatenate([rest.position, rest.rotation])
    end = start + np.array([0.05, 0.0, 0.03, 0.0, 0.0, 0.0])
    return _spatial_run(scene.with_changes(trajectory=PointToPointTrajectory(tuple(start), tuple(end),
                                                                              duration=0.5, space=SPACE)))


@case
def spatial_cogiro_ideal_ik():
    return _spatial_run(_spatial("spatial-cogiro", 0.5))


@case
def spatial_ipanema_ideal_ik():
    return _spatial_run(_spatial("spatial-ipanema", 0.5))


@case
def spatial_swivel_ideal_ik():
    return _spatial_run(_spatial("spatial-four-cable-swivel", 0.3))


def _spatial_controller(scene_name, name, end_time=0.6):
    from controllers.registry import CONTROLLERS

    scene = _spatial(scene_name, end_time)
    return _spatial_run(scene, CONTROLLERS[name](scene))


@case
def spatial_cogiro_tension_aware():
    return _spatial_controller("spatial-cogiro", "tension_aware")


@case
def spatial_cogiro_tension_aware_chain():
    return _spatial_controller("spatial-cogiro", "tension_aware_chain")


@case
def spatial_cogiro_closed_loop_tension_aware():
    return _spatial_controller("spatial-cogiro", "closed_loop_tension_aware")


@case
def spatial_ipanema_tension_aware_chain():
    return _spatial_controller("spatial-ipanema", "tension_aware_chain")


@case
def spatial_swivel_tension_aware_chain():
    return _spatial_controller("spatial-four-cable-swivel", "tension_aware_chain", end_time=0.3)


# --------------------------------------------------------------------------- spatial rest and statics


def _spatial_rest_arrays(rest):
    arrays = {"position": np.asarray(rest.position), "rotation": np.asarray(rest.rotation_matrix),
              "tensions_at_anchor": np.asarray(rest.anchor_tensions),
              "catenary_position": np.asarray(rest.catenary.position)}
    for i, nodes in enumerate(rest.nodes):
        arrays[f"nodes_{i}"] = np.asarray(nodes)
    return arrays


@case
def spatial_rest_four_cable():
    from cdpr_exu.run.rest import solve_rest

    return _spatial_rest_arrays(solve_rest(_spatial("spatial-four-cable", 1.0)))


@case
def spatial_rest_cogiro():
    from cdpr_exu.run.rest import solve_rest

    return _spatial_rest_arrays(solve_rest(_spatial("spatial-cogiro", 1.0)))


@case
def spatial_rest_swivel():
    from cdpr_exu.run.rest import solve_rest

    return _spatial_rest_arrays(solve_rest(_spatial("spatial-four-cable-swivel", 1.0)))


@case
def spatial_catenary_statics():
    from cdpr_exu.statics.statics import catenary_platform, solve_inverse_statics, solve_statics

    scene = _spatial("spatial-ipanema", 1.0)
    platform = catenary_platform(scene)
    rest = solve_statics(platform, scene.unstrained_lengths)
    pose = np.concatenate([rest.position + [0.05, -0.03, 0.02], [0.0, 0.0, 0.05]])
    guess = np.array([c.catenary.horizontal_tension for c in rest.cables])
    inverse = solve_inverse_statics(platform, pose, initial_guess=guess)
    return {"rest_position": np.asarray(rest.position), "rest_rotation": np.asarray(rest.rotation_matrix),
            "inverse_lengths": np.asarray(inverse.unstrained_lengths),
            "inverse_tensions": np.asarray(inverse.horizontal_tensions)}
