"""Scenes: the frozen, validated description of one CDPR simulation, planar or spatial.

A :class:`Scene` is a tree of frozen dataclasses (cables, exits, platform, winch, effects,
solver settings, reference trajectory) with its ``dimension``: 2, the paper's vertical x-z
plane (``(x, z)`` pairs; only the builder maps them onto Exudyn's x-y plane, paper z ->
Exudyn y), or 3, space with z up; gravity along -z in both. A bad field raises
:class:`~cdpr_exu.core.errors.SceneError` naming it, before any simulation. Scenes load from
and save to TOML in either form: ``[[exits]]`` (a table per cable with its ``kind``) or the
planar ``[[pulleys]]`` and ``cable_exit`` (README's scene reference). Units SI.
"""

from __future__ import annotations

import dataclasses
import difflib
import math
import tomllib
import warnings
from dataclasses import dataclass, field, fields, replace
from importlib import resources
from pathlib import Path
from typing import Any, Callable, ClassVar, Mapping

import numpy as np
import tomli_w

from cdpr_exu.core.errors import CoarseOutputWarning, SceneError, UnreachableError
from cdpr_exu.core.geometry import all_at_centre, above_exits
from cdpr_exu.core.validation import entries, finite, from_table, non_negative, positive, shown
from cdpr_exu.exits import EXIT_KINDS, Exit, PointExit, Pulley, exit_from_dict
from cdpr_exu.scenes.contact_models import CONTACT_MODELS, PulleyContactModel
from cdpr_exu.scenes.trajectories import HoldTrajectory, Trajectory, trajectory_from_dict
from cdpr_exu.space import DIMENSIONS, PLANE, SPACE, Space, space_of
from cdpr_exu.statics.statics import catenary_platform

# --------------------------------------------------------------------------- checks


def _choice(path: str, value: Any, choices: tuple[str, ...]) -> str:
    if value not in choices:
        raise SceneError(f"{path} must be one of {', '.join(map(repr, choices))}, got {shown(value)}")
    return value


def _whole(path: str, value: Any, low: int, high: int) -> int:
    if isinstance(value, bool) or not isinstance(value, (int, np.integer)) or not low <= value <= high:
        raise SceneError(f"{path} must be a whole number from {low} to {high}, got {shown(value)}")
    return int(value)


#: Most elements per cable (the paper uses 15): the bending object's dense (2 n_nodes)^2 matrices
#: are 12 MB at 300 on each of 2 cables (about 50 s per simulated second); thousands exhaust memory.
MAX_ELEMENTS = 300
#: Most time steps of a run (Exudyn counts steps in a 32-bit integer).
MAX_STEPS = 1.0e9
#: Most Newton iterations per step (beyond a few dozen, more never converge).
MAX_NEWTON_ITERATIONS = 1000


def check_weight(mass: float, gravity: float) -> None:
    """Refuse a platform weight ``mass`` [kg] x ``gravity`` [m/s^2] out of floating-point range."""
    if not math.isfinite(mass * gravity):
        raise SceneError(f"platform.mass = {shown(mass)} kg and gravity = {shown(gravity)} m/s^2 give a weight of "
                         f"{shown(mass * gravity)} N, out of floating-point range")


def _set(obj: Any, name: str, value: Any) -> None:
    """Set a field of a frozen dataclass inside ``__post_init__``."""
    object.__setattr__(obj, name, value)


# --------------------------------------------------------------------------- parts


@dataclass(frozen=True)
class CableSpec:
    """One cable, discretised into ``n_elements`` lumped-mass elements (paper sec. 2.1).

    Parameters
    ----------
    unstrained_length : float [m]
        Total unstrained length l0 of the cable, winch end to platform anchor.
    radius : float [m]
        Cable radius r; the cross-section is A0 = pi r^2, J = pi r^4 / 4.
    linear_density : float [kg/m]
        Mass per unstrained length rho0.
    youngs_modulus : float [Pa]
        Modulus of elasticity E.
    damping_constant : float [N s/m^2]
        Normal damping material constant dn (Kelvin-Voigt).
    n_elements : int
        Number of elements n (at least 2), each of unstrained length l0 / n.
    mass_lumping : {"consistent", "paper"}
        "consistent": half of each element's mass on each of its nodes; "paper": all of it
        on its far (platform-side) node (:meth:`node_masses`).
    min_tension, max_tension : float or None [N]
        Tension limits (None: none). A reference they cannot hold is refused before the run;
        a run reports every element tension outside them.
    """

    unstrained_length: float = 3.75
    radius: float = 0.005
    linear_density: float = 0.35
    youngs_modulus: float = 1.0e9
    damping_constant: float = 1.0e9
    n_elements: int = 15
    mass_lumping: str = "consistent"
    min_tension: float | None = None
    max_tension: float | None = None

    max_elements: ClassVar[int] = MAX_ELEMENTS

    def __post_init__(self) -> None:
        _set(self, "unstrained_length", positive("cable.unstrained_length", self.unstrained_length, "m"))
        for name in ("min_tension", "max_tension"):
            if getattr(self, name) is not None:
                _set(self, name, non_negative(f"cable.{name}", getattr(self, name), "N"))
        if self.min_tension is not None and self.max_tension is not None and self.min_tension >= self.max_tension:
            raise SceneError(f"cable.min_tension = {shown(self.min_tension)} N must be below cable.max_tension = "
                             f"{shown(self.max_tension)} N")
        _set(self, "radius", positive("cable.radius", self.radius, "m"))
        _set(self, "linear_density", positive("cable.linear_density", self.linear_density, "kg/m"))
        _set(self, "youngs_modulus", positive("cable.youngs_modulus", self.youngs_modulus, "Pa"))
        _set(self, "damping_constant", non_negative("cable.damping_constant", self.damping_constant, "N s/m^2"))
        if isinstance(self.n_elements, bool) or not isinstance(self.n_elements, (int, np.integer)):
            raise SceneError(f"cable.n_elements must be a whole number, got {shown(self.n_elements)}")
        if self.n_elements < 2:
            raise SceneError(f"cable.n_elements must be at least 2, got {shown(self.n_elements)}")
        if self.n_elements > MAX_ELEMENTS:
            raise SceneError(f"cable.n_elements must be at most {MAX_ELEMENTS}, got {shown(self.n_elements)}")
        _set(self, "n_elements", int(self.n_elements))
        _choice("cable.mass_lumping", self.mass_lumping, ("consistent", "paper"))
        self._check_derived()

    def _check_derived(self) -> None:
        """Refuse fields whose derived element properties overflow or underflow (e.g. radius 1e300)."""
        causes = {  # derived quantity: the fields it grows with
            "area": ("radius",), "second_moment": ("radius",),
            "element_mass": ("linear_density", "unstrained_length"),
            "axial_stiffness": ("youngs_modulus", "radius", "unstrained_length"),
            "bending_stiffness": ("youngs_modulus", "radius", "unstrained_length"),
            "axial_damping": ("damping_constant", "radius", "unstrained_length"),
            "bending_damping": ("damping_constant", "radius", "unstrained_length"),
        }
        for name, fields_ in causes.items():
            try:
                value = getattr(self, name)
            except OverflowError:
                value = math.inf
            zero_allowed = name.endswith("damping") and self.damping_constant == 0.0
            if not math.isfinite(value) or (value <= 0.0 and not zero_allowed):
                given = ", ".join(f"cable.{f} = {shown(getattr(self, f))}" for f in fields_)
                raise SceneError(f"{given} give(s) an element {name.replace('_', ' ')} of {shown(value)}, "
                                 "out of floating-point range")

    # Derived quantities of the paper's Table 2
    @property
    def area(self) -> float:
        """Unstrained cross-section A0 = pi r^2 [m^2]."""
        return math.pi * self.radius**2

    @property
    def second_moment(self) -> float:
        """Second moment of area J = pi r^4 / 4 [m^4]."""
        return math.pi * self.radius**4 / 4.0

    @property
    def element_length(self) -> float:
        """Unstrained element length l0i = l0 / n [m]."""
        return self.unstrained_length / self.n_elements

    @property
    def element_mass(self) -> float:
        """Element mass m_i = rho0 l0 / n [kg]."""
        return self.linear_density * self.element_length

    @property
    def mass(self) -> float:
        """Total cable mass rho0 l0 [kg]."""
        return self.linear_density * self.unstrained_length

    @property
    def axial_rigidity(self) -> float:
        """EA0 [N]."""
        return self.youngs_modulus * self.area

    @property
    def axial_stiffness(self) -> float:
        """Element axial stiffness k_i = E A0 / l0i [N/m]."""
        return self.youngs_modulus * self.area / self.element_length

    @property
    def axial_damping(self) -> float:
        """Element axial damping c_i = dn A0 / l0i [N s/m]."""
        return self.damping_constant * self.area / self.element_length

    @property
    def bending_stiffness(self) -> float:
        """Joint bending stiffness k_theta = E J / l0i [N m/rad]."""
        return self.youngs_modulus * self.second_moment / self.element_length

    @property
    def bending_damping(self) -> float:
        """Joint bending damping c_theta = dn J / l0i [N m s/rad]."""
        return self.damping_constant * self.second_moment / self.element_length

    def node_masses(self) -> np.ndarray:
        """Masses of the n + 1 nodes, winch end first, shape (n + 1,) [kg].

        The paper's lumping gives the winch node (prescribed motion) m_i / 2 so that it is
        not massless; its mass never enters the platform's dynamics.
        """
        n, m = self.n_elements, self.element_mass
        masses = np.full(n + 1, m)
        if self.mass_lumping == "consistent":
            masses[0] = masses[-1] = m / 2.0
        else:
            masses[0] = m / 2.0
        return masses


#: What a platform that leaves a field out gets, by its Space: planar, the paper's (Table 2); spatial, no
#: inertia for a point mass (a rigid one must give it), no initial pose (the run starts at its rest).
PLATFORM_DEFAULTS: dict[Space, dict[str, Any]] = {
    PLANE: {"inertia": 0.0271, "point_mass_inertia": 0.0271, "initial_pose": (0.0, -2.0, 0.0), "size": (0.3, 0.2)},
    SPACE: {"inertia": None, "point_mass_inertia": (0.0, 0.0, 0.0), "initial_pose": None, "size": None},
}


@dataclass(frozen=True)
class PlatformSpec:
    """The platform (paper sec. 2.3), planar or spatial as its anchors: ``(x, z)`` pairs or ``(x, y, z)``.

    A field left out (None) takes :data:`PLATFORM_DEFAULTS` of its :attr:`space`.

    Parameters
    ----------
    mass : float [kg]
        Positive for a rigid platform; a spatial point mass may weigh nothing.
    inertia : float, or (float, float, float) [kg m^2]
        Planar: J_MP about the centre of mass; spatial: the principal moments along the
        platform axes (zero for a point mass).
    anchors : sequence of (x, z) or (x, y, z) [m]
        Anchor points b_i in the platform frame, shape (m, d); all zero for a point mass.
    initial_pose : (x, z, rotation) [m, m, rad], or None
        Planar: the pose at t = 0 (paper eq. 17). Spatial: None, the start is the rest.
    size : (width, height) [m], or None
        Rectangle drawn in planar figures (no effect on the dynamics).
    """

    mass: float = 2.5
    inertia: float | tuple[float, float, float] | None = None
    anchors: tuple = ((-0.15, 0.1), (0.15, 0.1))
    initial_pose: tuple | None = None
    size: tuple[float, float] | None = None

    def __post_init__(self) -> None:
        anchors = np.asarray(self.anchors, dtype=object)
        if isinstance(self.anchors, (str, bytes, Mapping)) or anchors.ndim != 2 or anchors.shape[0] < 1 \
                or anchors.shape[1] not in DIMENSIONS:
            raise SceneError(f"platform.anchors must be a list of (x, z) pairs, shape (m, 2), or of (x, y, z) "
                             f"points, shape (m, 3), got {shown(self.anchors)}")
        space = space_of(anchors.shape[1])
        _set(self, "anchors", tuple(entries(f"platform.anchors[{i}]", a, space.position_size, "m")
                                    for i, a in enumerate(self.anchors)))
        rigid = space.is_rigid(self.is_point_mass)
        _set(self, "mass", (positive if rigid else non_negative)("platform.mass", self.mass, "kg"))
        defaults = PLATFORM_DEFAULTS[space]
        inertia = self.inertia
        if inertia is None:
            inertia = defaults["point_mass_inertia" if self.is_point_mass else "inertia"]
            if inertia is None:  # a rigid spatial platform: its turning depends on it
                refuse_missing(missing_fields("platform", {}, ("inertia",)))
        _set(self, "inertia", space.inertia("platform.inertia", inertia, rigid))
        pose = defaults["initial_pose"] if self.initial_pose is None else self.initial_pose
        if defaults["initial_pose"] is None and pose is not None:
            raise SceneError(f"platform.initial_pose = {shown(pose)}: a {space.name} scene starts at its rest "
                             "(cdpr static finds it); leave platform.initial_pose out")
        if pose is not None:
            pose = entries("platform.initial_pose", pose, space.pose_size, ", ".join(space.pose_units))
        _set(self, "initial_pose", pose)
        size = defaults["size"] if self.size is None else self.size
        if size is not None:
            size = entries("platform.size", size, 2, "m")
            for i, s in enumerate(size):
                non_negative(f"platform.size[{i}]", s, "m")
        _set(self, "size", size)

    @property
    def space(self) -> Space:
        """The :class:`~cdpr_exu.space.Space` of its anchors."""
        return space_of(len(self.anchors[0]))

    @property
    def is_point_mass(self) -> bool:
        """True when every anchor sits at the centre of mass."""
        return all_at_centre(self.anchors)

    def to_dict(self) -> dict[str, Any]:
        """Plain-data form (TOML-ready), None left out."""
        return {f.name: _listify(getattr(self, f.name)) for f in fields(self) if getattr(self, f.name) is not None}


@dataclass(frozen=True)
class WinchSpec:
    """How the winch end (node 0) of each cable is driven.

    Parameters
    ----------
    kind : {"kinematic", "servo", "fixed"}
        "kinematic": node 0 follows the command exactly along the vertical line below the
        pulley (the paper's flow source). "servo": a drum (``drum_inertia`` [kg m^2], drum and
        motor, ``drum_radius`` [m]) reels the cable under a motor torque from state feedback
        with integral action, loaded by the cable tension (in space over swivel exits only: the drum moves
        the winch end along the swivel axis). "fixed": node 0 held (static scenes).
    servo_design : {"pole_placement", "lqr"}
        Pole placement puts the three closed-loop poles near -``servo_bandwidth`` [rad/s];
        LQR weights position error against motor force for about that bandwidth.
    """

    kind: str = "kinematic"
    drum_radius: float = 0.05
    drum_inertia: float = 0.005
    servo_design: str = "pole_placement"
    servo_bandwidth: float = 60.0

    def __post_init__(self) -> None:
        _choice("winch.kind", self.kind, ("kinematic", "servo", "fixed"))
        _set(self, "drum_radius", positive("winch.drum_radius", self.drum_radius, "m"))
        _set(self, "drum_inertia", positive("winch.drum_inertia", self.drum_inertia, "kg m^2"))
        _choice("winch.servo_design", self.servo_design, ("pole_placement", "lqr"))
        _set(self, "servo_bandwidth", positive("winch.servo_bandwidth", self.servo_bandwidth, "rad/s"))

    @property
    def drum_mass(self) -> float:
        """Inertia of the drum seen along the cable, J / r^2 [kg]."""
        return self.drum_inertia / self.drum_radius**2


#: The model ladder: which effects each preset switches on. "full" and "catenary" have tension-only
#: elements; "paper" is the paper's as published (its spring-dampers push when compressed); "ideal" and
#: "elastic" are the massless references of inverse kinematics (a run reports ropes that push).
PRESETS: dict[str, dict[str, bool]] = {
    "ideal": dict(
        cable_mass=False, axial_elasticity=False, axial_damping=False, bending=False,
        bending_damping=False, pulley_contact=False, slack=False, gravity=True,
    ),
    "elastic": dict(
        cable_mass=False, axial_elasticity=True, axial_damping=True, bending=False,
        bending_damping=False, pulley_contact=False, slack=False, gravity=True,
    ),
    "full": dict(
        cable_mass=True, axial_elasticity=True, axial_damping=True, bending=True,
        bending_damping=True, pulley_contact=True, slack=True, gravity=True,
    ),
    "paper": dict(
        cable_mass=True, axial_elasticity=True, axial_damping=True, bending=True,
        bending_damping=True, pulley_contact=True, slack=False, gravity=True,
    ),
    "catenary": dict(
        cable_mass=True, axial_elasticity=True, axial_damping=True, bending=False,
        bending_damping=False, pulley_contact=True, slack=True, gravity=True,
    ),
}


#: Where the pulley contact acts (:mod:`cdpr_exu.scenes.contact_models`).
PULLEY_CONTACT_MODELS = tuple(CONTACT_MODELS)


@dataclass(frozen=True)
class Effects:
    """The physical effects a scene simulates; the builder adds items only for these.

    Parameters
    ----------
    preset : str
        The preset the flags started from (:data:`PRESETS`), for reports.
    cable_mass, axial_elasticity, axial_damping, bending, bending_damping,
    pulley_contact, slack, gravity : bool
        Switches of the effects. Without ``cable_mass`` each cable is one massless rope
        (Exudyn's reeving system); without ``axial_elasticity`` it is inextensible;
        ``slack`` makes the elements (or the rope) tension-only.
    bending_model : {"exact", "linear"}
        "exact": the paper's relative joint angle; "linear": the curvature-vector spring
        (k_theta / l0i^2) |p_a - 2 p_b + p_c|^2 / 2, cheaper, with moment k_theta sin(theta)
        (docs/accuracy.md).
    pulley_contact_model : {"node", "segment", "node_smooth"}
        Where the rim contact acts (:mod:`cdpr_exu.scenes.contact_models`): k_p [N/m] times the
        penetration plus c_p [N s/m] on the normal velocity, on each node, on each element's
        point closest to the centre (straight elements cannot cut the disc as chords), or on
        the nodes with a smooth onset over the first 1e-5 m.
    """

    preset: str = "full"
    cable_mass: bool = True
    axial_elasticity: bool = True
    axial_damping: bool = True
    bending: bool = True
    bending_damping: bool = True
    pulley_contact: bool = True
    slack: bool = True
    gravity: bool = True
    bending_model: str = "exact"
    pulley_contact_model: str = "node"

    def __post_init__(self) -> None:
        _choice("effects.preset", self.preset, tuple(PRESETS))
        for f in fields(self):
            if f.type in ("bool", bool) and not isinstance(getattr(self, f.name), bool):
                raise SceneError(f"effects.{f.name} must be true or false, got {shown(getattr(self, f.name))}")
        _choice("effects.bending_model", self.bending_model, ("exact", "linear"))
        _choice("effects.pulley_contact_model", self.pulley_contact_model, PULLEY_CONTACT_MODELS)
        if not self.cable_mass:
            for name in ("bending", "pulley_contact"):
                if getattr(self, name):
                    raise SceneError(
                        f"effects.{name} = true needs effects.cable_mass = true: a massless cable is one "
                        "straight rope over frictionless sheaves, with no nodes to bend or touch the pulley")
        if not self.axial_elasticity and self.slack and self.cable_mass:
            raise SceneError("effects.slack = true needs effects.axial_elasticity = true (slack elements are springs)")
        if not self.axial_elasticity and self.axial_damping:
            raise SceneError("effects.axial_damping = true needs effects.axial_elasticity = true")
        if self.bending_damping and not self.bending:
            raise SceneError("effects.bending_damping needs effects.bending = true")

    @classmethod
    def from_preset(cls, preset: str = "full", **overrides: Any) -> "Effects":
        """Effects of a named preset, with single effects overridden.

        Inextensible lumped cables have no springs to make tension-only: a preset's ``slack``
        is dropped for them unless asked for (then refused).
        """
        _choice("effects.preset", preset, tuple(PRESETS))
        unknown = set(overrides) - {f.name for f in fields(cls)}
        if unknown:
            raise SceneError(f"effects has no field(s) {sorted(unknown)}")
        flags = {**PRESETS[preset], **overrides}
        if flags["cable_mass"] and flags["axial_elasticity"] is False and "slack" not in overrides:
            flags["slack"] = False
        return cls(preset=preset, **flags)


@dataclass(frozen=True)
class SolverSpec:
    """Settings of Exudyn's implicit generalized-alpha integration.

    Parameters
    ----------
    end_time, step_size, output_period : float [s]
        The run's end, the time step and the sampling period of the stored result.
    spectral_radius : float
        rho_inf of generalized-alpha, in [0, 1]. The default 0 damps the stiff, over-damped
        axial modes fully; 0.5 lets their damping force ring (-20 N tensions on the paper
        scene); 1 conserves energy but leaves them undamped.
    newton : {"modified", "full"}
        Modified Newton (Jacobian once per step) or full Newton.
    max_newton_iterations : int
        Per step before it counts as failed (1 to :data:`MAX_NEWTON_ITERATIONS`).
    integrator : {"generalized_alpha", "rk44"}
        Exudyn's implicit solver (the project's), or its explicit Runge-Kutta for comparison
        only: it needs steps below about 1e-7 s on the paper's cable (c_i / m_i = 3.6e6 1/s),
        and takes no spectral radius or Newton settings.
    initial_accelerations : bool
        Start from the consistent initial accelerations instead of zero. Off by default: on a
        straight cable they are cut off by the damping within microseconds and inject an
        energy jolt (13 J on the paper scene at 1.7e-2 s steps); on, a drop from rest is
        second-order accurate (`benchmarks/bench_moordyn.py`: 0.19 instead of 0.84 mm).
    newton_tolerance : float
        Relative Newton tolerance per step, in (0, 1e-3]. The default 1e-6 (Exudyn's 1e-8)
        moves the paper circle by 0.14 um at 15 elements and cuts Newton iterations from 3.0
        to 2.2 per step; on stiff massless ropes 1e-8 sits at round-off and stalls Newton.
    start : {"paper", "steady"}
        The planar lumped cables' initial state. "paper" (default): straight, unstrained and at rest,
        the paper's start, which the platform's weight then sags and the winches' first command (the
        reference's velocity at t = 0) jolts. "steady": as if the robot had been following the reference:
        each cable's nodes on its elastic catenary at the initial pose, every element strained to its static
        tension (:func:`cdpr_exu.builder.model.presag_nodes`), and the platform and the nodes moving with the
        reference at t = 0 (:func:`~cdpr_exu.builder.model.start_velocities`; at rest under a held
        reference); same unstrained lengths and paid-out bookkeeping. A different start, so a different
        path (docs/accuracy.md, "The start"). Spatial scenes start at their chain statics' rest already
        and take "paper" only.
    """

    end_time: float = 10.0
    step_size: float = 2.0e-3
    spectral_radius: float = 0.0
    newton: str = "modified"
    output_period: float = 0.01
    max_newton_iterations: int = 25
    integrator: str = "generalized_alpha"
    initial_accelerations: bool = False
    newton_tolerance: float = 1e-6
    start: str = "paper"

    def __post_init__(self) -> None:
        _choice("solver.start", self.start, ("paper", "steady"))
        if not isinstance(self.initial_accelerations, bool):
            raise SceneError(f"solver.initial_accelerations must be true or false, got {shown(self.initial_accelerations)}")
        _set(self, "end_time", positive("solver.end_time", self.end_time, "s"))
        _set(self, "step_size", positive("solver.step_size", self.step_size, "s"))
        if self.step_size > self.end_time:
            raise SceneError(f"solver.step_size ({self.step_size}) must not exceed solver.end_time ({self.end_time})")
        if self.end_time / self.step_size > MAX_STEPS:
            raise SceneError(f"solver.step_size ({self.step_size}) and solver.end_time ({self.end_time}) make "
                             f"{self.end_time / self.step_size:.3g} steps; at most {MAX_STEPS:.0e} are allowed")
        rho = finite("solver.spectral_radius", self.spectral_radius)
        if not 0.0 <= rho <= 1.0:
            raise SceneError(f"solver.spectral_radius must lie in [0, 1], got {shown(self.spectral_radius)}")
        _set(self, "spectral_radius", rho)
        _choice("solver.newton", self.newton, ("modified", "full"))
        _set(self, "output_period", positive("solver.output_period", self.output_period, "s"))
        if self.output_period < self.step_size * (1 - 1e-9):
            samples = int(math.floor(self.end_time / self.step_size + 1e-9)) + 1
            warnings.warn(
                f"solver.step_size = {self.step_size} s is longer than solver.output_period = {self.output_period} s: "
                f"the result is sampled once per step ({samples} samples over {self.end_time} s), and its error "
                "figures are maxima over those samples only; lower solver.step_size for a finer output",
                CoarseOutputWarning, stacklevel=3)
            _set(self, "output_period", self.step_size)
        _set(self, "max_newton_iterations", _whole("solver.max_newton_iterations", self.max_newton_iterations,
                                                   1, MAX_NEWTON_ITERATIONS))
        _choice("solver.integrator", self.integrator, ("generalized_alpha", "rk44"))
        tolerance = positive("solver.newton_tolerance", self.newton_tolerance)
        if tolerance > 1e-3:
            raise SceneError(f"solver.newton_tolerance must be at most 1e-3 (relative), got {shown(self.newton_tolerance)}")
        _set(self, "newton_tolerance", tolerance)

    def to_dict(self) -> dict[str, Any]:
        """Plain-data form; the paper's start (the default) left out, so that scene files read as before."""
        return {k: v for k, v in dataclasses.asdict(self).items() if k != "start" or v != "paper"}

    @property
    def n_steps(self) -> int:
        """Number of time steps of the run."""
        return int(round(self.end_time / self.step_size))


# --------------------------------------------------------------------------- controller model

#: Fields the controllers' model may override, by part (not the start, which is the plant's, nor the
#: tension limits, one set for plant and controllers).
MODEL_FIELDS: dict[str, tuple[str, ...]] = {
    "cable": ("unstrained_length", "radius", "linear_density", "youngs_modulus", "damping_constant",
              "n_elements", "mass_lumping"),
    "pulley": ("center", "radius", "side", "contact_stiffness", "contact_damping"),
    "platform": ("mass", "inertia", "anchors"),
}


def _overrides(path: str, data: Any, part: str) -> dict[str, Any]:
    """A copy of one override table, refusing keys the model cannot override."""
    if not isinstance(data, Mapping):
        raise SceneError(f"{path} must be a table, got {shown(data)}")
    known = MODEL_FIELDS[part]
    unknown = sorted(set(data) - set(known))
    if unknown:
        raise SceneError(f"{path} has unknown or non-model field(s) {unknown}; the controllers' model may "
                         f"override: {list(known)}")
    return {key: _tupled(value) for key, value in data.items()}


def _tupled(value: Any) -> Any:
    """Lists to tuples, recursively (overrides compare equal after a TOML round trip)."""
    if isinstance(value, (list, tuple)):
        return tuple(_tupled(v) for v in value)
    return value


@dataclass(frozen=True)
class ControllerModel:
    """What the controllers believe of the robot: overrides of the plant's parameters.

    The scene simulates its own parts and hands the controllers :meth:`Scene.controller_scene`,
    the plant with these applied. In TOML::

        [controller_model.platform]   # the paper's platform, while the plant's is heavier
        mass = 2.5
        inertia = 0.0271
        [controller_model.cable]      # shared by every cable
        linear_density = 0.35
        [[controller_model.cables]]   # optional, one per cable, over [controller_model.cable]
        youngs_modulus = 0.9e9

    Parameters
    ----------
    cable, cables : mapping, sequence of mappings
        Overrides of every cable's fields (:data:`MODEL_FIELDS`), then per cable (none or one each).
    pulley, pulleys : mapping, sequence of mappings
        The same for the pulleys (refused where the exits are not pulleys).
    platform : mapping
        Overrides of the platform's mass [kg], inertia [kg m^2], anchors [m].
    gravity : float or None [m/s^2]
        What the controllers assume (None: the plant's).
    """

    cable: Mapping[str, Any] = field(default_factory=dict)
    cables: tuple[Mapping[str, Any], ...] = ()
    pulley: Mapping[str, Any] = field(default_factory=dict)
    pulleys: tuple[Mapping[str, Any], ...] = ()
    platform: Mapping[str, Any] = field(default_factory=dict)
    gravity: float | None = None

    def __post_init__(self) -> None:
        for name in ("cable", "pulley", "platform"):
            _set(self, name, _overrides(f"controller_model.{name}", getattr(self, name), name))
        for name, part in (("cables", "cable"), ("pulleys", "pulley")):
            tables = getattr(self, name)
            if isinstance(tables, (str, bytes, Mapping)) or not hasattr(tables, "__iter__"):
                raise SceneError(f"controller_model.{name} must be an array of tables, got {shown(tables)}")
            _set(self, name, tuple(_overrides(f"controller_model.{name}[{i}]", e, part)
                                   for i, e in enumerate(tables)))
        if self.gravity is not None:
            _set(self, "gravity", non_negative("controller_model.gravity", self.gravity, "m/s^2"))

    def is_empty(self) -> bool:
        """True when it overrides nothing (the controllers know the plant)."""
        return not (self.cable or self.cables or self.pulley or self.pulleys or self.platform
                    or self.gravity is not None)

    def apply(self, scene: "Scene") -> "Scene":
        """``scene`` with these overrides applied (and no controller model of its own); SceneError naming the
        ``controller_model`` field for an invalid override or per-cable lists that do not match the cables."""
        m = scene.n_cables
        for name in ("cables", "pulleys"):
            if getattr(self, name) and len(getattr(self, name)) != m:
                raise SceneError(f"controller_model.{name} must list one table per cable ({m}), "
                                 f"got {len(getattr(self, name))}")
        cables = tuple(_override(c, {**self.cable, **(self.cables[i] if self.cables else {})}, f"cables[{i}]", "cable")
                       for i, c in enumerate(scene.cables))
        if self.pulley or self.pulleys:
            others = [(i, exit_.kind) for i, exit_ in enumerate(scene.exits) if not isinstance(exit_, Pulley)]
            if others:
                raise SceneError(f"controller_model.pulley / controller_model.pulleys: this scene has exits, not pulleys "
                                 f"({scene.exits_table}[{others[0][0]}] is a {others[0][1]!r} exit); its controller "
                                 "model overrides cable, cables, platform and gravity")
        exits = tuple(_override(e, {**self.pulley, **(self.pulleys[i] if self.pulleys else {})}, f"pulleys[{i}]",
                                "pulley") for i, e in enumerate(scene.exits))
        platform = _override(scene.platform, self.platform, "platform", "platform")
        gravity = scene.gravity if self.gravity is None else self.gravity
        try:
            return replace(scene, cables=cables, exits=exits, platform=platform, gravity=gravity,
                           controller_model=None)
        except SceneError as err:
            raise SceneError(f"controller_model: the controllers' model is not a valid robot: {err}") from None

    def to_dict(self) -> dict[str, Any]:
        """Plain-data form (TOML-ready): only the overrides given."""
        data: dict[str, Any] = {}
        for name in ("cable", "pulley", "platform"):
            if getattr(self, name):
                data[name] = _listify(dict(getattr(self, name)))
        for name in ("cables", "pulleys"):
            if getattr(self, name):
                data[name] = [_listify(dict(e)) for e in getattr(self, name)]
        if self.gravity is not None:
            data["gravity"] = self.gravity
        return data


def _override(part: Any, changes: Mapping[str, Any], path: str, head: str) -> Any:
    """``part`` with ``changes``; an invalid value is named under controller_model."""
    if not changes:
        return part
    try:
        return replace(part, **changes)
    except SceneError as err:
        message = str(err)
        if message.startswith(head + "."):
            message = path + message[len(head):]
        raise SceneError(f"controller_model.{message}") from None
    except TypeError as err:
        raise SceneError(f"controller_model.{path}: {err}") from None


def controller_model_from_dict(data: Any) -> ControllerModel:
    """A :class:`ControllerModel` from its TOML table, refusing unknown keys (named)."""
    for name in ("cables", "pulleys"):
        if isinstance(data, Mapping) and name in data and not (
                isinstance(data[name], list) and all(isinstance(e, Mapping) for e in data[name])):
            raise SceneError(f"controller_model.{name} must be an array of tables, got {shown(data[name])}")
    return from_table(ControllerModel, data, "controller_model", "controller_model")


# --------------------------------------------------------------------------- scene


@dataclass(frozen=True)
class Scene:
    """A complete CDPR simulation, planar or spatial: robot, effects, solver settings and reference.

    Parameters
    ----------
    dimension : {2, 3}
        2: the paper's vertical x-z plane; 3: space, z up; its :attr:`space` is made from it.
    cables, exits : tuple of CableSpec, tuple of Exit
        Cable i leaves the frame at ``exits[i]`` (:mod:`cdpr_exu.exits`) and holds ``platform.anchors[i]``.
    trajectory : Trajectory or None
        Reference pose over time (default: hold a planar initial pose; a spatial scene without
        one has a static mode only).
    gravity : float [m/s^2]
        Magnitude, along -z.
    controller_model : ControllerModel or None
        What the controllers believe (:meth:`controller_scene`); None: they know the plant.

    Raises
    ------
    SceneError
        Naming the field: a part of the wrong type, counts that do not match, parts of another
        dimension, and what the dimension's builder cannot build (:data:`DIMENSION_RULES`).
    UnreachableError
        A planar initial pose the cables cannot reach or hold.
    """

    name: str = "scene"
    description: str = ""
    dimension: int = 2
    cables: tuple[CableSpec, ...] = (CableSpec(), CableSpec())
    exits: tuple[Exit, ...] = (Pulley(center=(-1.75, 0.0), side=-1), Pulley(center=(1.75, 0.0), side=1))
    platform: PlatformSpec = field(default_factory=PlatformSpec)
    winch: WinchSpec = field(default_factory=WinchSpec)
    effects: Effects = field(default_factory=Effects)
    solver: SolverSpec = field(default_factory=SolverSpec)
    trajectory: Any = None
    gravity: float = 9.81
    controller_model: ControllerModel | None = None

    def __post_init__(self) -> None:
        if not isinstance(self.name, str) or not self.name:
            raise SceneError(f"name must be a non-empty string, got {shown(self.name)}")
        if not isinstance(self.description, str):
            raise SceneError(f"description must be a string, got {shown(self.description)}")
        space = space_of(self.dimension)
        _set(self, "dimension", space.dimension)
        rules = DIMENSION_RULES[space]
        for name, kind in (("cables", CableSpec), ("exits", Exit)):
            parts = getattr(self, name)
            if isinstance(parts, (str, bytes, Mapping)) or not hasattr(parts, "__iter__"):
                raise SceneError(f"{name} must be a sequence of {kind.__name__}, got {shown(parts)}")
            parts = tuple(parts)
            for i, part in enumerate(parts):
                if not isinstance(part, kind):
                    raise SceneError(f"{name}[{i}] must be a {kind.__name__}, got {shown(part)}")
            _set(self, name, parts)
        for name, kind in (("platform", PlatformSpec), ("winch", WinchSpec), ("effects", Effects),
                           ("solver", SolverSpec)):
            if not isinstance(getattr(self, name), kind):
                raise SceneError(f"{name} must be a {kind.__name__}, got {shown(getattr(self, name))}")
        if self.trajectory is not None and not (isinstance(self.trajectory, Trajectory) and self.trajectory.space is space):
            raise SceneError(f"trajectory must be a Trajectory of the {space.name} space, got {shown(self.trajectory)}")
        m = len(self.cables)
        if m < 1:
            raise SceneError("cables must list at least one cable")
        table = self.exits_table
        if len(self.exits) != m:
            raise SceneError(f"{table} must list one exit per cable ({m}), got {len(self.exits)}")
        if len(self.platform.anchors) != m:
            raise SceneError(f"platform.anchors must list one anchor per cable ({m}), got {len(self.platform.anchors)}")
        labels = ", ".join(space.position_labels)
        if self.platform.space is not space:
            raise SceneError(f"platform.anchors must be ({labels}) points in a {space.name} scene (dimension = "
                             f"{space.dimension}), got {shown(self.platform.anchors)}")
        for i, exit_ in enumerate(self.exits):
            if space.dimension not in exit_.dimensions or len(exit_.point) != space.position_size:
                raise SceneError(f"exits[{i}] is a {exit_.dimension}-D {exit_.kind!r} exit; a {space.name} scene "
                                 f"(dimension = {space.dimension}) needs ({labels}) exits")
        _set(self, "gravity", non_negative("gravity", self.gravity, "m/s^2"))
        check_weight(self.platform.mass, self.gravity)
        for i, (cable, exit_) in enumerate(zip(self.cables, self.exits)):
            exit_.check(cable, i, f"{table}[{i}]")
        rules.check(self)
        _check_servo_step(self)
        if self.trajectory is None and self.platform.initial_pose is not None:
            _set(self, "trajectory", HoldTrajectory(tuple(self.platform.initial_pose), space=space))
        self._check_start()
        if self.controller_model is not None:
            if not isinstance(self.controller_model, ControllerModel):
                raise SceneError(f"controller_model must be a ControllerModel, got {shown(self.controller_model)}")
            if self.controller_model.is_empty():
                _set(self, "controller_model", None)
            else:
                self.controller_model.apply(self)  # refuse a model that is no valid robot now, not at the run

    @property
    def space(self) -> Space:
        """The :class:`~cdpr_exu.space.Space` of the scene."""
        return space_of(self.dimension)

    def controller_scene(self) -> "Scene":
        """The robot the controllers believe in: this scene with its controller model applied (if any)."""
        if self.controller_model is None:
            return self
        return self.controller_model.apply(self)

    def _check_start(self) -> None:
        """Refuse an initial pose the cables cannot reach or hold (before any simulation)."""
        pose = self.platform.initial_pose
        if pose is None:  # the scene starts at its rest
            return
        space, table = self.space, self.exits_table
        anchors = space.anchor_points(np.asarray(pose), np.asarray(self.platform.anchors))
        above = above_exits(anchors[:, space.vertical], self.exit_tops, exits=table)
        if above is not None and self.gravity > 0.0 and self.effects.gravity:
            units = ", ".join(f"{label} [{unit}]" for label, unit in zip(space.pose_labels, space.pose_units))
            raise UnreachableError(f"platform.initial_pose {list(pose)} ({units}) is above the {table}: {above}; "
                                   "give a platform.initial_pose below them")
        for i, (cable, exit_) in enumerate(zip(self.cables, self.exits)):
            try:
                needed = float(exit_.cable_length(anchors[i]))
            except UnreachableError as err:
                raise UnreachableError(
                    f"platform.anchors[{i}] at platform.initial_pose {list(pose)} cannot be reached over "
                    f"{table}[{i}] ({exit_.describe(f'{table}[{i}]')}): {err}") from None
            if needed > cable.unstrained_length * (1 + 1e-9):
                raise SceneError(
                    f"cables[{i}].unstrained_length = {cable.unstrained_length} m is shorter than the "
                    f"{needed:.4f} m needed to reach platform.initial_pose {pose}")

    @property
    def exits_table(self) -> str:
        """The scene file's name of the exits: ``"pulleys"`` for a planar scene whose exits are all pulleys or
        all point exits (the planar form), else ``"exits"``."""
        kinds = {exit_.kind for exit_ in self.exits}
        return "pulleys" if self.space is PLANE and kinds in ({"pulley"}, {"point"}) else "exits"

    @property
    def exit_points(self) -> np.ndarray:
        """Each exit's fixed point (a pulley's centre, a swivel's inlet, a point exit's point), shape (m, d) [m]."""
        return np.array([exit_.point for exit_ in self.exits], dtype=float)

    @property
    def exit_tops(self) -> np.ndarray:
        """Each exit's :attr:`~cdpr_exu.exits.base.Exit.top`, shape (m,) [m]."""
        return np.array([exit_.top for exit_ in self.exits], dtype=float)

    def above_exits(self, position, rotation=None) -> str | None:
        """:func:`cdpr_exu.core.geometry.above_exits` for the centre at ``position`` (d,) [m], the frame
        turned by ``rotation`` (d, d) (default: not); None for a platform without weight."""
        if self.gravity == 0.0 or not self.effects.gravity:
            return None
        anchors, up = np.asarray(self.platform.anchors, dtype=float), self.space.vertical
        turned = anchors if rotation is None else anchors @ np.asarray(rotation, dtype=float).T
        return above_exits(float(position[up]) + turned[:, up], self.exit_tops, exits=self.exits_table)

    @property
    def pulley_contact(self) -> bool:
        """True when contact is on and a cable wraps over its exit."""
        return self.effects.pulley_contact and any(exit_.wraps for exit_ in self.exits)

    @property
    def contact_model(self) -> PulleyContactModel | None:
        """The pulley contact model the cables run with, decided once (None: no contact)."""
        return CONTACT_MODELS[self.effects.pulley_contact_model] if self.pulley_contact else None

    @property
    def n_cables(self) -> int:
        return len(self.cables)

    @property
    def unstrained_lengths(self) -> np.ndarray:
        """Unstrained length of each cable, shape (m,) [m]."""
        return np.array([c.unstrained_length for c in self.cables])

    @property
    def tension_limits(self) -> np.ndarray | None:
        """Each cable's (t_min, t_max) [N], shape (m, 2), 0 and inf where not given; None without any limit."""
        return tension_limits(self.cables)

    def with_changes(self, **changes: Any) -> "Scene":
        """A copy with top-level fields replaced (validated again)."""
        return replace(self, **changes)

    def to_dict(self) -> dict[str, Any]:
        """Plain-data form (TOML-ready), in the form of :attr:`exits_table`; :func:`scene_from_dict` reads
        it back to an equal scene."""
        cables = [{k: v for k, v in dataclasses.asdict(c).items() if v is not None} for c in self.cables]
        if self.exits_table == "pulleys":
            data: dict[str, Any] = {
                "name": self.name, "description": self.description, "gravity": self.gravity,
                "cable_exit": self.exits[0].kind, "cables": cables,
                "pulleys": [_pulley_table(exit_) for exit_ in self.exits],
                "platform": self.platform.to_dict(),
                "winch": dataclasses.asdict(self.winch),
                "effects": dataclasses.asdict(self.effects),
                "solver": self.solver.to_dict(),
                "trajectory": self.trajectory.to_dict(),
            }
        else:
            data = {
                "name": self.name, "description": self.description, "dimension": self.dimension,
                "gravity": self.gravity, "cables": cables, "exits": [exit_.to_dict() for exit_ in self.exits],
                "platform": self.platform.to_dict(),
                "effects": dataclasses.asdict(self.effects),
                "solver": self.solver.to_dict(),
                "winch": dataclasses.asdict(self.winch),
            }
            if self.trajectory is not None:
                data["trajectory"] = self.trajectory.to_dict()
        if self.controller_model is not None:
            data["controller_model"] = self.controller_model.to_dict()
        return data


def _pulley_table(exit_: Exit) -> dict[str, Any]:
    """An exit as its ``[[pulleys]]`` table: a pulley's fields, a point exit's centre."""
    if exit_.wraps:
        return {name: value for name, value in exit_.to_dict().items() if name != "kind"}
    return {"center": list(exit_.point)}


def _listify(value: Any) -> Any:
    """Tuples to lists, recursively (TOML arrays)."""
    if isinstance(value, dict):
        return {k: _listify(v) for k, v in value.items()}
    if isinstance(value, (tuple, list)):
        return [_listify(v) for v in value]
    return value


#: Largest step times the drum-on-cable frequency sqrt(k / m) a servo winch takes [-]: its motor force is set
#: once per step and feeds the winch-end tension forward one step late. Measured on the held
#: spatial-four-cable-swivel: 0.64 (5 ms) rings by +-1 N, 1.28 (10 ms) between 15 and 72 N; the paper robot
#: runs at 0.20 (2 ms).
MAX_SERVO_STEP = 0.7


def _check_servo_step(scene: Scene) -> None:
    """Refuse a servo winch whose step cannot resolve its drum (mass J / r^2) on the stiffest cable (EA / l0)."""
    if scene.winch.kind != "servo":
        return
    stiffness = max(cable.axial_rigidity / cable.unstrained_length for cable in scene.cables)
    frequency = float(np.sqrt(stiffness / scene.winch.drum_mass))
    limit = MAX_SERVO_STEP / frequency
    if scene.solver.step_size > limit:
        raise SceneError(
            f"solver.step_size = {scene.solver.step_size:g} s is too coarse for winch.kind = 'servo': the drum "
            f"({scene.winch.drum_mass:.3g} kg along the cable) on its cable ({stiffness:.3g} N/m) rings at "
            f"{frequency:.3g} rad/s and its motor force is set once per step; use solver.step_size <= {limit:.2g} s "
            "or a heavier drum (winch.drum_inertia)")


def _planar_rules(scene: Scene) -> None:
    """What the planar builder builds so far (:mod:`cdpr_exu.builder.model`)."""
    if scene.winch.kind == "servo" and not scene.effects.cable_mass:
        raise SceneError("winch.kind = 'servo' needs effects.cable_mass = true (a lumped cable to reel)")
    wraps = [exit_.wraps for exit_ in scene.exits]
    if any(wraps) and not all(wraps):
        raise SceneError(f"exits: cable {wraps.index(False)} leaves a point while cable {wraps.index(True)} wraps over "
                         "a pulley; the planar builder takes exits that all wrap or all none so far")
    if not any(wraps) and scene.winch.kind != "fixed":
        raise SceneError("point exits (cable_exit = 'point') need winch.kind = 'fixed' (the cable starts at the "
                         "exit point)")
    if scene.solver.integrator != "generalized_alpha" and scene.winch.kind != "fixed":
        raise SceneError(
            f"solver.integrator = {shown(scene.solver.integrator)} needs winch.kind = 'fixed', got "
            f"{shown(scene.winch.kind)}: Exudyn's explicit solvers eliminate the winch's coordinate constraints "
            "and hold them at their initial value, ignoring every winch command")
    if scene.solver.start != "paper" and not (scene.effects.cable_mass and all(wraps)):
        raise SceneError(f"solver.start = {shown(scene.solver.start)} needs lumped cables (effects.cable_mass) over "
                         "pulleys: it places their nodes on the catenary up to the pulley and the winch line below it")


def _spatial_rules(scene: Scene) -> None:
    """What the spatial builder builds so far (:mod:`cdpr_exu.builder.robot_3d`)."""
    if not (scene.effects.cable_mass and scene.effects.axial_elasticity):
        raise SceneError(f"effects.preset = {shown(scene.effects.preset)}: a spatial scene needs lumped, elastic "
                         "cables (effects.cable_mass and effects.axial_elasticity); use the 'full' or 'catenary' preset")
    first = scene.cables[0]
    for i, cable in enumerate(scene.cables[1:], start=1):
        for name in ("n_elements", "radius", "youngs_modulus", "damping_constant", "mass_lumping"):
            if getattr(cable, name) != getattr(first, name):
                raise SceneError(f"cables[{i}].{name} = {shown(getattr(cable, name))} differs from cables[0].{name} = "
                                 f"{shown(getattr(first, name))}: the cables of a spatial scene share one "
                                 "discretisation, damping and bending so far")
    catenary_platform(scene)  # refuses coincident exits, too few cables, anchors on one line
    points = [i for i, exit_ in enumerate(scene.exits) if not exit_.wraps]
    if scene.winch.kind == "servo" and points:
        raise SceneError(f"winch.kind = 'servo' needs swivel exits: exits {points} are points, where the winch changes "
                         "every element's rest length and no winch node moves for a drum; use exits of kind 'swivel'")
    if scene.solver.integrator != "generalized_alpha":
        raise SceneError("solver.integrator must be 'generalized_alpha' for a spatial scene")
    if scene.solver.start != "paper":
        raise SceneError(f"solver.start = {shown(scene.solver.start)}: a spatial scene starts at its chain statics' "
                         "rest already; leave solver.start out")


@dataclass(frozen=True)
class DimensionRules:
    """What a scene of one dimension takes: what its item family builds (``check`` refuses the rest, naming
    the field, before anything is built), the platform fields a scene file must give (besides a rigid
    platform's inertia) and whether it must give ``[trajectory]``."""

    check: Callable[[Scene], None]
    platform_fields: tuple[str, ...]
    trajectory_required: bool


DIMENSION_RULES: dict[Space, DimensionRules] = {
    PLANE: DimensionRules(_planar_rules, ("mass", "anchors", "initial_pose"), trajectory_required=True),
    SPACE: DimensionRules(_spatial_rules, ("mass", "anchors"), trajectory_required=False),
}


def _build(cls: type, data: Mapping[str, Any], path: str) -> Any:
    """The scene part ``cls`` from its table at ``path`` (e.g. cables[1])."""
    return from_table(cls, data, path, cls.__name__.replace("Spec", "").lower())


def _per_cable(data: Mapping[str, Any], single: str, plural: str, defaults: list[dict[str, Any]]) -> list[dict[str, Any]]:
    """Merge the shared table ``[single]`` into each entry of ``[[plural]]`` (or of ``defaults``)."""
    shared = data.get(single, {})
    if not isinstance(shared, Mapping):
        raise SceneError(f"{single} must be a table, got {shown(shared)}")
    shared = dict(shared)
    tables = data.get(plural, defaults)
    if not isinstance(tables, list) or not all(isinstance(e, Mapping) for e in tables):
        raise SceneError(f"{plural} must be an array of tables, got {shown(tables)}")
    return [{**e, **shared} if plural not in data else {**shared, **dict(e)} for e in tables]


#: The fields of cables and platforms a scene must give, with their units: lengths and masses, for which
#: no default would be the robot meant (each exit kind names its own; other defaults are model choices).
REQUIRED_FIELDS: dict[str, str] = {
    "unstrained_length": "m", "mass": "kg", "inertia": "kg m^2", "anchors": "m", "initial_pose": "m, m, rad",
}


def missing_fields(path: str, given: Mapping[str, Any], names, units: Mapping[str, str] = REQUIRED_FIELDS) -> list[str]:
    """The required ``names`` the table ``given`` leaves out, as ``"platform.mass [kg]"``."""
    return [f"{path}.{name} [{units[name]}]" for name in names if name not in given]


def refuse_missing(missing: list[str], source: str | None = None) -> None:
    """Raise SceneError naming every required field a scene leaves out (after the values given are
    checked, before the parts are put together: no default stands in for a missing field)."""
    if missing:
        where = "scene" if source is None else f"scene {shown(source)}"
        raise SceneError(f"{where} lacks {', '.join(missing)}: a scene must give "
                         f"{'it' if len(missing) == 1 else 'each'}, as no default would be the robot you mean "
                         "(see the scene reference in the README)")


def _platform_missing(platform_data: Any, platform: PlatformSpec, rules: DimensionRules) -> list[str]:
    """The required fields ``[platform]`` leaves out (the inertia where an anchor is off the centre)."""
    if not isinstance(platform_data, Mapping):
        return []
    names = rules.platform_fields + (() if platform.is_point_mass else ("inertia",))
    return missing_fields("platform", platform_data, names)


#: The top-level fields of a scene in the planar form (``[[pulleys]]``) and in the form with ``[[exits]]``.
PLANAR_FORM_FIELDS = {"name", "description", "dimension", "gravity", "cable_exit", "cable", "cables", "pulley",
                      "pulleys", "platform", "winch", "effects", "solver", "trajectory", "controller_model"}
EXITS_FORM_FIELDS = PLANAR_FORM_FIELDS - {"cable_exit", "pulley", "pulleys"} | {"exits"}


def scene_from_dict(data: Mapping[str, Any], source: str | None = None) -> Scene:
    """A validated Scene, planar or spatial (``dimension``, 2 when absent), from plain data (TOML's).

    Exits come as ``[[exits]]`` (one table per cable with its ``kind``, ``"point"`` when absent)
    or in the planar form, ``[[pulleys]]`` and ``cable_exit`` (``"pulley"`` or ``"point"``: each
    cable leaves from its pulley's centre). ``[cable]`` and ``[pulley]`` hold values shared by
    every entry of ``[[cables]]`` and ``[[pulleys]]``; ``[effects]`` may name a ``preset``. The
    values given are checked first, then the required tables and fields; ``source`` names the file
    (its folder is where a trajectory file is read).
    """
    if not isinstance(data, Mapping):
        raise SceneError(f"a scene must be a table (mapping), got {shown(data)}")
    data = dict(data)
    space = space_of(data.get("dimension", 2))
    rules = DIMENSION_RULES[space]
    planar_form = space is PLANE and "exits" not in data
    known = PLANAR_FORM_FIELDS if planar_form else EXITS_FORM_FIELDS
    unknown = set(data) - known
    if unknown:
        raise SceneError(f"scene has unknown field(s) {sorted(unknown)}; known: {sorted(known)}")
    exits, exits_missing, required = _planar_form_exits(data) if planar_form else _exits_form_exits(data, space)
    cable_dicts = _per_cable(data, "cable", "cables", [{} for _ in exits] if planar_form else [])
    cables = tuple(_build(CableSpec, c, f"cables[{i}]") for i, c in enumerate(cable_dicts))
    platform_data = data.get("platform", {})
    if isinstance(platform_data, Mapping) and "anchors" not in platform_data and not planar_form:
        # a stand-in point mass to check the values given: refused as missing below
        platform_data = {**platform_data, "anchors": [[0.0] * space.position_size] * max(1, len(exits))}
    platform = _build(PlatformSpec, platform_data, "platform")
    effects_data = data.get("effects", {})
    if not isinstance(effects_data, Mapping):
        raise SceneError(f"effects must be a table, got {shown(effects_data)}")
    effects_data = dict(effects_data)
    effects = Effects.from_preset(effects_data.pop("preset", "full"), **effects_data)
    kwargs: dict[str, Any] = dict(
        dimension=space.dimension, cables=cables, exits=exits, platform=platform,
        winch=_build(WinchSpec, data.get("winch", {}), "winch"), effects=effects,
        solver=_build(SolverSpec, data.get("solver", {}), "solver"),
        trajectory=trajectory_from_dict(data["trajectory"], space, source and Path(source).parent)
        if "trajectory" in data else None,
        controller_model=controller_model_from_dict(data["controller_model"]) if "controller_model" in data else None,
    )
    for key in ("name", "description", "gravity"):
        if key in data:
            kwargs[key] = data[key]
    _check_required_tables(data, required, source)
    missing = [field_ for i, c in enumerate(cable_dicts)
               for field_ in missing_fields(f"cables[{i}]", c, ("unstrained_length",))]
    refuse_missing(missing + exits_missing + _platform_missing(data.get("platform"), platform, rules), source)
    return Scene(**kwargs)


def _planar_form_exits(data: Mapping[str, Any]) -> tuple[tuple[Exit, ...], list[str], dict[str, str]]:
    """The planar form's exits (pulleys, or point exits at their centres), the required fields their tables
    leave out and the tables the scene must give."""
    cable_exit = _choice("cable_exit", data.get("cable_exit", "pulley"), ("pulley", "point"))
    default = [_pulley_table(exit_) for exit_ in Scene.__dataclass_fields__["exits"].default]
    tables = _per_cable(data, "pulley", "pulleys", default)
    pulleys = [from_table(Pulley, table, f"pulleys[{i}]", Pulley.path_head) for i, table in enumerate(tables)]
    over_pulleys = cable_exit == "pulley"
    names = Pulley.required_fields if over_pulleys else {"center": "m"}
    missing = [field_ for i, table in enumerate(tables) for field_ in missing_fields(f"pulleys[{i}]", table, names, names)]
    required = dict(REQUIRED_TABLES)
    if isinstance(data.get("pulley"), Mapping) and "center" in data["pulley"]:
        required.pop("pulleys")
    exits = tuple(pulleys) if over_pulleys else tuple(PointExit(pulley.center) for pulley in pulleys)
    return exits, missing, required


def _exits_form_exits(data: Mapping[str, Any], space: Space) -> tuple[tuple[Exit, ...], list[str], dict[str, str]]:
    """The exits of ``[[exits]]``, the required fields (each kind's) their tables leave out and the tables
    the scene must give."""
    tables = data.get("exits", [])
    if not isinstance(tables, list):
        raise SceneError(f"exits must be an array of tables, each an exit with its kind ({', '.join(map(repr, EXIT_KINDS))}) "
                         f"and fields, e.g. a point exit (point = [{', '.join(space.position_labels)}]), got {shown(tables)}")
    exits = tuple(exit_from_dict(table, f"exits[{i}]", space) for i, table in enumerate(tables))
    missing = [field_ for i, (table, exit_) in enumerate(zip(tables, exits))
               for field_ in missing_fields(f"exits[{i}]", table, exit_.required_fields, exit_.required_fields)]
    required = {"cables": "[[cables]] (one per cable, at least its unstrained_length)",
                "exits": "[[exits]] (one per cable, each with its kind and its fields)",
                "platform": "[platform] (its mass and anchors)"}
    if DIMENSION_RULES[space].trajectory_required:
        required["trajectory"] = REQUIRED_TABLES["trajectory"]
    return exits, missing, required


def tension_limits(cables) -> np.ndarray | None:
    """Each cable's (t_min, t_max) [N], shape (m, 2), 0 and inf where not given; None without any limit."""
    if all(c.min_tension is None and c.max_tension is None for c in cables):
        return None
    return np.array([[c.min_tension or 0.0, math.inf if c.max_tension is None else c.max_tension] for c in cables])


def is_scene_file(source: str | Path) -> bool:
    """True when ``source`` names a file (a ``.toml`` path, or anything that exists), not a shipped scene."""
    path = Path(source)
    return path.suffix == ".toml" or path.exists()


def read_scene_file(source: str | Path) -> dict[str, Any]:
    """The plain data of the TOML scene file ``source``; SceneError naming the file for a folder, a missing
    or unreadable file, one that is not UTF-8 text, or text that is not TOML."""
    path = Path(source)
    if path.is_dir():
        raise SceneError(f"scene {shown(str(path))} is a directory; give a .toml scene file or a shipped "
                         "scene name (see `cdpr scenes`)")
    if not path.is_file():
        raise SceneError(f"scene file {shown(str(path))} does not exist")
    try:
        raw = path.read_bytes()
    except OSError as err:
        raise SceneError(f"scene file {shown(str(path))} cannot be read: {err.strerror or err}") from None
    try:
        text = raw.decode("utf-8")
    except UnicodeDecodeError as err:
        raise SceneError(f"scene file {shown(str(path))} is not UTF-8 TOML: byte {err.start} is 0x{raw[err.start]:02x} "
                         "(a binary file, or text saved in another encoding such as Latin-1); save it as UTF-8 "
                         "text") from None
    return parse_scene_text(text, source)


def parse_scene_text(text: str, source: str | Path) -> dict[str, Any]:
    """The plain data of a scene's TOML ``text``; SceneError naming ``source`` if it is not valid TOML."""
    try:
        return tomllib.loads(text)
    except tomllib.TOMLDecodeError as err:
        raise SceneError(f"scene {shown(str(source))} is not valid TOML: {err}") from None


def load_scene(source: str | Path) -> Scene:
    """Load a scene by shipped name (e.g. ``"paper-circle"``, ``"spatial-cogiro"``) or TOML file path;
    SceneError for an unknown name, a file that cannot be read, or a bad scene."""
    if is_scene_file(source):
        data = read_scene_file(source)
    else:
        text = shipped_scene_text(str(source))
        if text is None:
            raise unknown_scene(source)
        data = parse_scene_text(text, source)
    return scene_from_dict(data, source=str(source))


#: The tables a scene file in the planar form must give.
REQUIRED_TABLES: dict[str, str] = {
    "pulleys": "[[pulleys]] with each pulley's center (where the cables run)",
    "platform": "[platform] with its anchors and mass",
    "trajectory": "[trajectory] (the reference motion; kind = \"hold\" with a pose to hold still)",
}


def _check_required_tables(data: Mapping[str, Any], required: Mapping[str, str], source: str | None) -> None:
    """Refuse a scene file that leaves out a table of ``required`` (name -> what to give)."""
    missing = [name for name in required if name not in data]
    if missing:
        where = "scene" if source is None else f"scene {shown(source)}"
        raise SceneError(f"{where} lacks {', '.join(missing)}: a scene file must give "
                         + "; ".join(required[name] for name in missing)
                         + " (see the scene reference in the README)")


SPATIAL_FOLDER = "spatial"


def shipped_names(folder: str | None = None) -> list[str]:
    """Names of the scenes shipped in the package's ``scenes`` folder (or its sub-folder ``folder``)."""
    files = resources.files("cdpr_exu.scenes")
    files = files if folder is None else files.joinpath(folder)
    return sorted(p.name[:-5].replace("_", "-") for p in files.iterdir() if p.name.endswith(".toml"))


def shipped_scenes() -> list[str]:
    """Names of the scenes shipped with the package, planar and spatial, sorted."""
    return sorted(shipped_names() + shipped_names(SPATIAL_FOLDER))


def shipped_scene_text(name: str) -> str | None:
    """The TOML text of the shipped scene ``name`` (planar or spatial), or None."""
    file_name = str(name).replace("-", "_") + ".toml"
    for resource in (resources.files("cdpr_exu.scenes").joinpath(file_name),
                     resources.files("cdpr_exu.scenes").joinpath(SPATIAL_FOLDER, file_name)):
        if resource.is_file():
            return resource.read_text(encoding="utf-8")
    return None


def closest_names(name: str, names: list[str]) -> list[str]:
    """The names a misspelt ``name`` likely meant: those that contain it, else those at least 0.6 similar
    (difflib) and within 0.1 of the best, the closest first."""
    key = name.replace("_", "-").lower()
    if len(key) >= 3 and any(key in n for n in names):
        return [n for n in names if key in n]
    scores = {n: difflib.SequenceMatcher(None, key, n).ratio() for n in names}
    floor = max(0.6, max(scores.values(), default=0.0) - 0.1)
    return sorted((n for n in names if scores[n] >= floor), key=lambda n: -scores[n])


def unknown_scene(source: str | Path) -> SceneError:
    """The refusal of an unknown scene name, listing the likeliest (:func:`closest_names`) and every shipped
    scene."""
    name = str(source)
    planar, spatial = shipped_names(), shipped_names(SPATIAL_FOLDER)
    close = closest_names(name, planar + spatial)
    guess = f"did you mean {' or '.join(map(repr, close))}? " if close else ""
    return SceneError(f"no scene named {shown(name)}; {guess}shipped scenes: {', '.join(planar)}; spatial: "
                      f"{', '.join(spatial)} (or give the path of a .toml scene file)")


def save_scene(scene: Scene, path: str | Path) -> Path:
    """Write the scene as TOML; :func:`load_scene` reads it back to an equal Scene."""
    path = Path(path)
    path.parent.mkdir(parents=True, exist_ok=True)
    path.write_text(tomli_w.dumps(scene.to_dict()))
    return path
