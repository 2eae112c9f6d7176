"""Scene factories shared by the tests that run the real Exudyn solver.

Small scenes with one or two coarse cables, whose answer is known in closed form:
a cable hanging straight down, a cable pendulum, two cables in a V holding a point
mass. All have point exits (:class:`~cdpr_exu.exits.point.PointExit`) with fixed winches: node 0 of
each cable sits at its exit point, held by the winch constraints, and there is no pulley contact.
"""

from __future__ import annotations

import math

import pytest

from cdpr_exu.physics.catenary import CatenaryCable
from cdpr_exu.statics.statics import SuspendedCable, SuspendedPlatform
from cdpr_exu.exits import PointExit
from cdpr_exu.scenes.scene import CableSpec, Effects, PlatformSpec, Scene, SolverSpec, WinchSpec

#: Gravity used by the small scenes [m/s^2].
GRAVITY = 9.81


def settling_solver(end_time: float = 40.0, step_size: float = 0.2) -> SolverSpec:
    """Solver settings that bring a damped scene to rest cheaply (200 steps).

    Long implicit steps with spectral radius 0 annihilate every mode with
    omega h >> 1 (the axial modes, omega ~ 300 to 2000 rad/s) within a step or two,
    and damp the slow swinging modes (omega ~ 5 rad/s, omega h ~ 1) strongly; the
    Kelvin-Voigt creep of the stretch (time constant c_i / k_i = 1 s) has decayed as
    exp(-40) at the end. Measured: all velocities below 1e-14 m/s at 40 s. The static
    answer does not depend on the integrator.

    Integrate with Exudyn's initial-acceleration computation off (see
    ``test_model.settle``): with it on, the first 0.2 s step lifts the nodes by ~6 cm.
    """
    return SolverSpec(end_time=end_time, step_size=step_size, spectral_radius=0.0, output_period=step_size)


def hanging_cable_scene(n_elements: int = 4, length: float = 1.0, platform_mass: float = 1.0,
                        effects: Effects | None = None, solver: SolverSpec | None = None,
                        **cable_fields) -> Scene:
    """One cable hanging straight down from (0, 0) to a point-mass platform at (0, -length).

    Every element starts at its unstrained length; the platform is a point mass
    (anchor at its centre of mass). Cable fields default to the paper's cable.
    """
    cable = CableSpec(unstrained_length=length, n_elements=n_elements, **cable_fields)
    return Scene(
        name="hanging-cable",
        cables=(cable,),
        exits=(PointExit((0.0, 0.0)),),
        platform=PlatformSpec(mass=platform_mass, inertia=0.01, anchors=((0.0, 0.0),),
                              initial_pose=(0.0, -length, 0.0)),
        winch=WinchSpec(kind="fixed"),
        effects=effects or Effects.from_preset("full"),
        solver=solver or settling_solver(),
        gravity=GRAVITY,
    )


def pendulum_scene(step_size: float, end_time: float = 2.0, n_elements: int = 6, angle_deg: float = 45.0,
                   effects: Effects | None = None, spectral_radius: float = 1.0) -> Scene:
    """A cable pendulum: one 1 m cable from (0, 0) carrying a 1 kg rigid platform.

    The cable is attached 0.1 m above the platform's centre of mass, so the platform
    also rotates; it starts straight at ``angle_deg`` from the vertical, at rest.
    Default effects: everything of the paper except damping (axial and bending).
    """
    length, offset = 1.0, 0.1
    angle = math.radians(angle_deg)
    anchor = (length * math.sin(angle), -length * math.cos(angle))
    return Scene(
        name="cable-pendulum",
        cables=(CableSpec(unstrained_length=length, n_elements=n_elements),),
        exits=(PointExit((0.0, 0.0)),),
        platform=PlatformSpec(mass=1.0, inertia=0.01, anchors=((0.0, offset),),
                              initial_pose=(anchor[0], anchor[1] - offset, 0.0)),
        winch=WinchSpec(kind="fixed"),
        effects=effects or Effects.from_preset("full", axial_damping=False, bending_damping=False),
        solver=SolverSpec(end_time=end_time, step_size=step_size, spectral_radius=spectral_radius,
                          output_period=0.01),
        gravity=GRAVITY,
    )


def v_shaped_scene(effects: Effects | None = None, n_elements: int = 6, platform_mass: float = 1.0,
                   solver: SolverSpec | None = None) -> Scene:
    """The paper's static scene: two cables from (-1.75, 0) and (1.75, 0) holding a point mass.

    Both cables start straight at their unstrained length, at 45 and 135 degrees,
    meeting at (0, -1.75); they then sag under their own weight.
    """
    span = 1.75
    cable = CableSpec(unstrained_length=span * math.sqrt(2.0), n_elements=n_elements)
    return Scene(
        name="v-shaped-cables",
        cables=(cable, cable),
        exits=(PointExit((-span, 0.0)), PointExit((span, 0.0))),
        platform=PlatformSpec(mass=platform_mass, inertia=0.01, anchors=((0.0, 0.0), (0.0, 0.0)),
                              initial_pose=(0.0, -span, 0.0)),
        winch=WinchSpec(kind="fixed"),
        effects=effects or Effects.from_preset("full"),
        solver=solver or settling_solver(),
        gravity=GRAVITY,
    )


# --------------------------------------------------------------------------- spatial

#: The paper's cable (radius 5 mm, E = 1e9 Pa, 0.35 kg/m) as a catenary: w = 3.43 N/m, EA = 7.85e4 N.
PAPER_CATENARY_CABLE = CatenaryCable(1.0, 0.35 * 9.81, 1e9 * math.pi * 0.005**2)
#: Corner signs of the square frame, cable 1 to 4.
CORNERS = ((1, 1), (-1, 1), (-1, -1), (1, -1))
#: Unequal lengths [m] that make the four-cable robot hang off-centre and tilt.
ASYMMETRIC_LENGTHS = [2.4, 2.5, 2.6, 2.55]
#: Stiffness of the penalty spherical joints, in element axial stiffnesses: it adds 1/(100 n)
#: of a cable's compliance, a 3e-7 m shift at n = 40, below every discretisation error here.
PENALTY = 100.0


def four_cable_robot(rigid: bool, mass: float = 5.0) -> SuspendedPlatform:
    """The paper's cable from the corners of a 3 m x 3 m frame (exits at z = 0) to a point mass, or to
    a rigid 0.2 m square platform whose anchors sit 5 cm above its centre of mass."""
    w, ea = PAPER_CATENARY_CABLE.weight_per_length, PAPER_CATENARY_CABLE.axial_stiffness
    cables = [SuspendedCable(w, ea, anchor=(0.1 * sx, 0.1 * sy, 0.05) if rigid else (0.0, 0.0, 0.0),
                             exit_point=(1.5 * sx, 1.5 * sy, 0.0)) for sx, sy in CORNERS]
    return SuspendedPlatform(cables, mass=mass, inertia=(0.05, 0.05, 0.08))


@pytest.fixture
def hanging_cable():
    """Factory of :func:`hanging_cable_scene` scenes."""
    return hanging_cable_scene


@pytest.fixture
def pendulum():
    """Factory of :func:`pendulum_scene` scenes."""
    return pendulum_scene


@pytest.fixture
def v_shaped():
    """Factory of :func:`v_shaped_scene` scenes."""
    return v_shaped_scene


def small_spatial_scene(end_time: float = 0.3, n_elements: int = 4):
    """The shipped four-cable robot, coarse (4 elements per cable, bending on), moving its platform 5 cm
    along x in ``end_time``: a spatial scene that runs in well under a second, for the files a run writes
    and the commands that read them. Step 1e-2 s, output every 1e-2 s. Spring elements (``slack = false``):
    with tension-only elements the first steps shrink (194 instead of 31 steps measured over 0.3 s) and the
    samples then lie up to a step after the output times; with springs there are ``end_time / 0.01 + 1``
    samples, one per output time."""
    from dataclasses import replace

    import numpy as np

    from cdpr_exu.statics.statics import catenary_platform, solve_statics
    from cdpr_exu.scenes.scene import load_scene
    from cdpr_exu.scenes.trajectories import PointToPointTrajectory
    from cdpr_exu.space import SPACE

    scene = load_scene("spatial-four-cable")
    scene = replace(scene, cables=tuple(replace(c, n_elements=n_elements) for c in scene.cables),
                    effects=replace(scene.effects, slack=False),
                    solver=replace(scene.solver, end_time=end_time, step_size=1e-2, output_period=1e-2))
    rest = solve_statics(catenary_platform(scene), scene.unstrained_lengths)
    start = np.concatenate([rest.position, rest.rotation])
    end = start + np.array([0.05, 0.0, 0.0, 0.0, 0.0, 0.0])
    return replace(scene, name="small-spatial",
                   trajectory=PointToPointTrajectory(tuple(start), tuple(end), duration=end_time, space=SPACE))
