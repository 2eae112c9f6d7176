"""Scenes: the frozen, validated description of one CDPR simulation.

A :class:`Scene` is a tree of frozen dataclasses (cables, pulleys, platform, winch,
effects, solver settings and the reference trajectory). It is validated when it is
made: a bad field raises :class:`~cdpr_exu.core.errors.SceneError` naming the field and
its value, before any simulation starts. Scenes load from and save to TOML.

Units are SI throughout (m, kg, s, N, rad). Planar scenes live in the paper's
vertical x-z plane with gravity along -z; positions are given as ``(x, z)`` pairs.
Only the Exudyn builder maps them onto Exudyn's x-y plane (paper z -> Exudyn y).
"""

from __future__ import annotations

import dataclasses
import math
import tomllib
import warnings
from dataclasses import dataclass, field, fields, replace
from importlib import resources
from pathlib import Path
from typing import Any, Mapping

import numpy as np

from cdpr_exu.core.errors import CoarseOutputWarning, SceneError, UnreachableError
from cdpr_exu.scenes.contact_models import CONTACT_MODELS, PulleyContactModel
from cdpr_exu.core.geometry import Pulley, above_exits, anchor_points
from cdpr_exu.core.validation import finite, non_negative, positive, shown
from cdpr_exu.scenes.trajectories import Trajectory, trajectory_from_dict

# --------------------------------------------------------------------------- checks


def _vector(path: str, value: Any, length: int, unit: str = "") -> tuple[float, ...]:
    """Return ``value`` as a tuple of ``length`` finite floats; ``unit`` is named in the messages."""
    units = f" [{unit}]" if unit else ""
    if isinstance(value, (str, bytes, Mapping)):
        raise SceneError(f"{path} must be a list of {length} numbers{units}, got {shown(value)}")
    try:
        items = list(value)
    except TypeError:
        raise SceneError(f"{path} must be a list of {length} numbers{units}, got {shown(value)}") from None
    if len(items) != length:
        raise SceneError(f"{path} must have {length} entries{units}, got {len(items)}: {shown(value)}")
    return tuple(finite(f"{path}[{i}]", v) for i, v in enumerate(items))


def _choice(path: str, value: Any, choices: tuple[str, ...]) -> str:
    if value not in choices:
        raise SceneError(f"{path} must be one of {', '.join(map(repr, choices))}, got {shown(value)}")
    return value


def _whole(path: str, value: Any, low: int, high: int) -> int:
    """Return ``value`` as an int in [low, high], or raise SceneError naming ``path``."""
    if isinstance(value, bool) or not isinstance(value, (int, np.integer)) or not low <= value <= high:
        raise SceneError(f"{path} must be a whole number from {low} to {high}, got {shown(value)}")
    return int(value)


#: Most elements per cable a scene may ask for (the paper uses 15). The cables'
#: bending object carries dense (2 n_nodes)^2 matrices over all cables: 300 elements
#: on each of 2 cables are 1204 coordinates, 12 MB per matrix, and cost about 50 s
#: per simulated second; a few thousand would exhaust memory instead of failing.
MAX_ELEMENTS = 300
#: Most time steps of a run (Exudyn counts steps in a 32-bit integer).
MAX_STEPS = 1.0e9
#: Most Newton iterations per step (beyond a few dozen, more never converge).
MAX_NEWTON_ITERATIONS = 1000


def check_weight(mass: float, gravity: float) -> None:
    """Refuse a platform whose weight, ``mass`` [kg] x ``gravity`` [m/s^2], is out of floating-point range
    (naming platform.mass and gravity; each alone is finite)."""
    if not math.isfinite(mass * gravity):
        raise SceneError(f"platform.mass = {shown(mass)} kg and gravity = {shown(gravity)} m/s^2 give a weight of "
                         f"{shown(mass * gravity)} N, out of floating-point range")


def _set(obj: Any, name: str, value: Any) -> None:
    """Normalise a field of a frozen dataclass inside ``__post_init__``."""
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
        "consistent": each node carries half the mass of each element it touches;
        "paper": each element's whole mass sits at its far (platform-side) node.
    min_tension, max_tension : float or None [N]
        The cable's tension limits t_min and t_max (None: no limit). A reference the
        limits cannot hold is refused before the run
        (:func:`cdpr_exu.statics.workspace.check_reference`); a run reports every element
        tension outside them (``tension_limit_violations`` in its summary).
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
        causes = {  # derived quantity: the fields it grows with, the likeliest culprit first
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

    # Derived quantities of the paper's Table 2 -------------------------------------
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

        The consistent lumping puts m_i / 2 on both ends of each element. The paper's
        lumping puts m_i on the far node of each element; the winch node, whose motion
        is prescribed, then gets m_i / 2 so that it is not massless (its mass never
        enters the platform's dynamics).
        """
        n, m = self.n_elements, self.element_mass
        masses = np.full(n + 1, m)
        if self.mass_lumping == "consistent":
            masses[0] = masses[-1] = m / 2.0
        else:
            masses[0] = m / 2.0
        return masses


@dataclass(frozen=True)
class PulleySpec(Pulley):
    """A pulley the cable runs over, and on which side the cable hangs to its winch.

    The cable comes up from the winch along the vertical line x = x_c + side * radius,
    wraps over the top of the pulley and leaves it tangentially towards the anchor. A
    :class:`~cdpr_exu.core.geometry.Pulley` (its geometry: hang point, exit, wrap) with the
    parameters of the rim contact.

    Parameters
    ----------
    center : (x, z) [m]
    radius : float [m]
        Rim radius r_p. Must be positive when the cable runs over the pulley.
    side : {-1, +1}
        -1: the cable hangs on the pulley's left (x < x_c), +1: on its right.
    contact_stiffness : float [N/m]
        Penalty stiffness k_p of the rim contact.
    contact_damping : float [N s/m]
        Damping c_p on the normal velocity of a node in contact.
    """

    center: tuple[float, float] = (0.0, 0.0)
    radius: float = 0.25
    side: int = -1
    contact_stiffness: float = 1.0e7
    contact_damping: float = 10.0

    def __post_init__(self) -> None:
        _set(self, "center", _vector("pulley.center", self.center, 2, "m"))
        _set(self, "radius", positive("pulley.radius", self.radius, "m"))
        if self.side not in (-1, 1) or isinstance(self.side, bool):
            raise SceneError(f"pulley.side must be -1 (left) or +1 (right), got {shown(self.side)}")
        _set(self, "side", int(self.side))
        _set(self, "contact_stiffness", positive("pulley.contact_stiffness", self.contact_stiffness, "N/m"))
        _set(self, "contact_damping", non_negative("pulley.contact_damping", self.contact_damping, "N s/m"))


@dataclass(frozen=True)
class PlatformSpec:
    """The rigid planar platform (paper sec. 2.3).

    Parameters
    ----------
    mass : float [kg]
    inertia : float [kg m^2]
        Moment of inertia J_MP about the centre of mass, out of the plane.
    anchors : sequence of (x, z) [m]
        Cable anchor points b_i in the platform frame, one per cable, shape (m, 2).
        All zero for a point-mass platform.
    initial_pose : (x, z, rotation) [m, m, rad]
        Pose at t = 0; rotation positive counter-clockwise (paper eq. 17).
    size : (width, height) [m]
        Rectangle drawn in figures and animations (no effect on the dynamics).
    """

    mass: float = 2.5
    inertia: float = 0.0271
    anchors: tuple[tuple[float, float], ...] = ((-0.15, 0.1), (0.15, 0.1))
    initial_pose: tuple[float, float, float] = (0.0, -2.0, 0.0)
    size: tuple[float, float] = (0.3, 0.2)

    def __post_init__(self) -> None:
        _set(self, "mass", positive("platform.mass", self.mass, "kg"))
        _set(self, "inertia", positive("platform.inertia", self.inertia, "kg m^2"))
        anchors = np.asarray(self.anchors, dtype=object)
        if anchors.ndim != 2 or anchors.shape[1] != 2 or anchors.shape[0] < 1:
            raise SceneError(
                f"platform.anchors must be a list of (x, z) pairs, shape (m, 2), got {shown(self.anchors)}"
            )
        _set(self, "anchors", tuple(_vector(f"platform.anchors[{i}]", a, 2, "m") for i, a in enumerate(self.anchors)))
        _set(self, "initial_pose", _vector("platform.initial_pose", self.initial_pose, 3, "m, m, rad"))
        size = _vector("platform.size", self.size, 2, "m")
        for i, s in enumerate(size):
            non_negative(f"platform.size[{i}]", s, "m")
        _set(self, "size", size)

    @property
    def is_point_mass(self) -> bool:
        """True when every anchor sits at the centre of mass."""
        return bool(np.allclose(self.anchors, 0.0))


@dataclass(frozen=True)
class WinchSpec:
    """How the winch end (node 0) of each cable is driven.

    Parameters
    ----------
    kind : {"kinematic", "servo", "fixed"}
        "kinematic": node 0 follows the commanded paid-out length exactly, moving along
        the vertical line below the pulley (the paper's flow source along -z).
        "servo": a drum of inertia ``drum_inertia`` and radius ``drum_radius`` reels the
        cable; a motor torque from state feedback with integral action (gains designed
        with python-control for ``servo_bandwidth``) tracks the command, and the cable
        tension loads the drum. "fixed": node 0 is held where it starts (static scenes).
    drum_radius : float [m]
    drum_inertia : float [kg m^2]
        Drum and motor inertia about the drum axis.
    servo_design : {"pole_placement", "lqr"}
        Pole placement puts the three closed-loop poles near -servo_bandwidth; LQR
        weights position error against motor force for about that bandwidth.
    servo_bandwidth : float [rad/s]
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


#: The model ladder: which effects each preset switches on. A cable cannot push, so the
#: lumped-mass presets ("full", the default, and "catenary") have tension-only elements;
#: "paper" is the paper's model as published, whose axial spring-dampers also push when
#: compressed (kept to reproduce it). "ideal" and "elastic" are the massless references
#: of inverse kinematics (ropes that may push; a run reports it when they do).
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


#: Where the pulley contact acts: on the nodes (Exudyn's sphere contact items), on the
#: element segments, or on the nodes with a smooth onset in the cables' numba object
#: (:mod:`cdpr_exu.scenes.contact_models`).
PULLEY_CONTACT_MODELS = tuple(CONTACT_MODELS)


@dataclass(frozen=True)
class Effects:
    """The physical effects a scene simulates; the builder adds items only for these.

    Parameters
    ----------
    preset : str
        Name of the preset the flags started from (see :data:`PRESETS`), for reports:
        "ideal" (massless inextensible ropes), "elastic" (massless elastic ropes),
        "catenary" (lumped mass and elasticity, no bending), "full" (the paper's model with
        tension-only elements, the default), "paper" (the paper's model as published: its
        spring-dampers push when compressed, which a real cable cannot).
    cable_mass, axial_elasticity, axial_damping, bending, bending_damping,
    pulley_contact, slack, gravity : bool
        Switches of the individual effects. Without ``cable_mass`` each cable is one
        massless rope over its pulley (Exudyn's reeving system); without
        ``axial_elasticity`` the elements (or the rope) are inextensible. ``slack``
        (on in every preset but "paper") makes the elements (or the rope) tension-only:
        a cable cannot push.
    bending_model : {"exact", "linear"}
        Formulation of the bending spring: "exact" is the paper's relative joint angle;
        "linear" the curvature-vector spring (k_theta / l0i^2) |p_a - 2 p_b + p_c|^2 / 2
        with constant matrices, cheaper but with moment k_theta sin(theta) (see
        docs/accuracy.md for how far it moves the answer).
    pulley_contact_model : {"node", "segment", "node_smooth"}
        Where the pulley rim contact acts (with ``pulley_contact``): "node" pushes each
        node that enters the disc back out (Exudyn's sphere contact, k_p [N/m] times the
        penetration [m] plus c_p [N s/m] on the normal velocity [m/s], switched on and off
        in Exudyn's discontinuous iterations); "node_smooth" is the same law switched on
        smoothly over the first 1e-5 m of penetration, computed in the cables' numba
        object (:mod:`cdpr_exu.physics.node_contact`; measured slower, see docs/accuracy.md);
        "segment" does the same for the point of each element closest to the pulley
        centre, shared by the element's two nodes (:mod:`cdpr_exu.physics.segment_contact`), so
        that straight elements cannot cut the disc as chords and coarser cables can run
        over the pulley.
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

        Inextensible lumped cables (``axial_elasticity = False`` with ``cable_mass``) have
        no springs to make tension-only, so a preset's ``slack`` is dropped for them unless
        it is asked for explicitly (which is refused).
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
    end_time : float [s]
    step_size : float [s]
    spectral_radius : float
        Spectral radius at infinity rho_inf of generalized-alpha, in [0, 1]. The default
        0 damps the stiff, heavily over-damped axial modes fully; 0.5 lets their damping
        force ring from step to step (negative tensions of -20 N on the paper scene, with
        the same path to 1 mm); 1 conserves energy but leaves them undamped.
    newton : {"modified", "full"}
        Modified Newton (Jacobian updated once per step) or full Newton.
    output_period : float [s]
        Sampling period of the stored result.
    max_newton_iterations : int
        Newton iterations per step before the step counts as failed (1 to
        :data:`MAX_NEWTON_ITERATIONS`).
    integrator : {"generalized_alpha", "rk44"}
        "generalized_alpha": Exudyn's implicit solver (the project's). "rk44": Exudyn's
        explicit classical Runge-Kutta, for comparison only: it needs steps below about
        1e-7 s on the paper's cable (c_i / m_i = 3.6e6 1/s), and the cable ends are then
        joined to the platform by stiff spring-dampers (see :mod:`cdpr_exu.builder.platform`).
        ``spectral_radius``, ``newton`` and ``max_newton_iterations`` do not apply to it.
    initial_accelerations : bool
        Start generalized-alpha from the consistent initial accelerations (Exudyn's
        ``computeInitialAccelerations``) instead of zero. Off by default: on a cable that
        starts straight, the free nodes' consistent acceleration (-g) is cut off by the
        Kelvin-Voigt damping within microseconds, and carried into the first step it
        injects an energy jolt (13 J on the paper scene at 1.7e-2 s steps). On, the error
        of a drop from rest is of second order in the step instead of first
        (`benchmarks/bench_moordyn.py`: 0.19 mm instead of 0.84 mm at 2e-3 s).
    newton_tolerance : float
        Newton's relative tolerance per step (Exudyn's ``newton.relativeTolerance``), in
        (0, 1e-3]. The default 1e-6 (Exudyn's is 1e-8) matches the answers asked of this
        model, millimetres: on the paper circle it moves the path by 0.14 micrometres at 15
        elements and 33 micrometres at 60 elements and a 1e-2 s step, and cuts the Newton
        iterations per step from 3.0 to 2.2 and from 12.3 to 8.7. On stiff massless ropes
        Exudyn's 1e-8 sits at the residual's round-off and stalls Newton (the step then
        shrinks up to 350-fold). Without bending the path over 10 s is sensitive to any
        perturbation: 1e-8 and 1e-9 already differ by 1.7 cm there.
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

    def __post_init__(self) -> None:
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

    @property
    def n_steps(self) -> int:
        """Number of time steps of the run."""
        return int(round(self.end_time / self.step_size))


# --------------------------------------------------------------------------- controller model

#: Fields the controllers' model may override, by part. Left out: where the platform
#: starts and its drawing size (the run starts from the plant's state, which the
#: controllers are told: the paid-out lengths at t = 0) and the tension limits (the
#: robot's requirements, one set for plant and controllers).
MODEL_FIELDS: dict[str, tuple[str, ...]] = {
    "cable": ("unstrained_length", "radius", "linear_density", "youngs_modulus", "damping_constant",
              "n_elements", "mass_lumping"),
    "pulley": ("center", "radius", "side", "contact_stiffness", "contact_damping"),
    "platform": ("mass", "inertia", "anchors"),
}


def _overrides(path: str, data: Any, part: str) -> dict[str, Any]:
    """A copy of one override table, refusing keys the controllers' model cannot override."""
    if not isinstance(data, Mapping):
        raise SceneError(f"{path} must be a table, got {shown(data)}")
    known = MODEL_FIELDS[part]
    unknown = sorted(set(data) - set(known))
    if unknown:
        raise SceneError(f"{path} has unknown or non-model field(s) {unknown}; the controllers' model may "
                         f"override: {list(known)}")
    return {key: _tupled(value) for key, value in data.items()}


def _tupled(value: Any) -> Any:
    """Lists to tuples, recursively (so that overrides compare equal after a TOML round trip)."""
    if isinstance(value, (list, tuple)):
        return tuple(_tupled(v) for v in value)
    return value


@dataclass(frozen=True)
class ControllerModel:
    """What the controllers believe of the robot, where it differs from the simulated plant.

    Overrides of the plant's parameters; everything not named is the plant's. A scene
    with a controller model simulates its own parts (the plant) and hands the controllers
    :meth:`Scene.controller_scene`, the plant with these overrides applied. In TOML::

        [controller_model.platform]   # the paper's platform, while the plant's is heavier
        mass = 2.5
        inertia = 0.0271
        [controller_model.cable]      # shared by every cable
        linear_density = 0.35
        [[controller_model.cables]]   # optional, one per cable, over [controller_model.cable]
        youngs_modulus = 0.9e9

    Parameters
    ----------
    cable : mapping
        Overrides of every cable's :class:`CableSpec` fields (see :data:`MODEL_FIELDS`).
    cables : sequence of mappings
        Per-cable overrides (none, or one per cable), applied after ``cable``.
    pulley, pulleys : mapping, sequence of mappings
        The same for the :class:`PulleySpec` fields.
    platform : mapping
        Overrides of :class:`PlatformSpec` fields: mass [kg], inertia [kg m^2], anchors [m].
    gravity : float or None [m/s^2]
        The gravitational acceleration the controllers assume (None: the plant's).
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
            entries = getattr(self, name)
            if isinstance(entries, (str, bytes, Mapping)) or not hasattr(entries, "__iter__"):
                raise SceneError(f"controller_model.{name} must be an array of tables, got {shown(entries)}")
            _set(self, name, tuple(_overrides(f"controller_model.{name}[{i}]", e, part)
                                   for i, e in enumerate(entries)))
        if self.gravity is not None:
            _set(self, "gravity", non_negative("controller_model.gravity", self.gravity, "m/s^2"))

    def is_empty(self) -> bool:
        """True when it overrides nothing (the controllers know the plant)."""
        return not (self.cable or self.cables or self.pulley or self.pulleys or self.platform
                    or self.gravity is not None)

    def apply(self, scene: "Scene") -> "Scene":
        """``scene`` with these overrides applied (and no controller model of its own).

        Raises
        ------
        SceneError
            If an override is invalid or the per-cable lists do not match the cables;
            the message names the ``controller_model`` field.
        """
        m = scene.n_cables
        for name in ("cables", "pulleys"):
            if getattr(self, name) and len(getattr(self, name)) != m:
                raise SceneError(f"controller_model.{name} must list one table per cable ({m}), "
                                 f"got {len(getattr(self, name))}")
        cables = tuple(_override(c, {**self.cable, **(self.cables[i] if self.cables else {})}, f"cables[{i}]", "cable")
                       for i, c in enumerate(scene.cables))
        pulleys = tuple(_override(p, {**self.pulley, **(self.pulleys[i] if self.pulleys else {})}, f"pulleys[{i}]",
                                  "pulley") for i, p in enumerate(scene.pulleys))
        platform = _override(scene.platform, self.platform, "platform", "platform")
        gravity = scene.gravity if self.gravity is None else self.gravity
        try:
            return replace(scene, cables=cables, pulleys=pulleys, platform=platform, gravity=gravity,
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
    """``part`` (a frozen spec) with ``changes``; an invalid value is named under controller_model."""
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
    if not isinstance(data, Mapping):
        raise SceneError(f"controller_model must be a table, got {shown(data)}")
    known = {f.name for f in fields(ControllerModel)}
    unknown = sorted(set(data) - known)
    if unknown:
        raise SceneError(f"controller_model has unknown field(s) {unknown}; known: {sorted(known)}")
    values = dict(data)
    for name in ("cables", "pulleys"):
        if name in values and not (isinstance(values[name], list) and all(isinstance(e, Mapping) for e in values[name])):
            raise SceneError(f"controller_model.{name} must be an array of tables, got {shown(values[name])}")
    return ControllerModel(**values)


# --------------------------------------------------------------------------- scene


@dataclass(frozen=True)
class Scene:
    """A complete CDPR simulation: robot, effects, solver settings and reference.

    Parameters
    ----------
    name : str
    description : str
    cables : tuple of CableSpec
        One per cable; cable i runs over ``pulleys[i]`` to ``platform.anchors[i]``.
    pulleys : tuple of PulleySpec
    platform : PlatformSpec
    winch : WinchSpec
    effects : Effects
    solver : SolverSpec
    trajectory : Trajectory
        Reference pose of the platform over time (x, z, rotation).
    gravity : float [m/s^2]
        Magnitude of the gravitational acceleration, acting along -z.
    cable_exit : {"pulley", "point"}
        "pulley": each cable wraps over its pulley and hangs to its winch (paper).
        "point": the cable's winch end is fixed at the pulley centre and there is no
        pulley contact (used to compare with the catenary's fixed end points).
    controller_model : ControllerModel or None
        What the controllers believe where it differs from this (simulated) robot;
        :meth:`controller_scene` applies it. None: the controllers know the plant.
    """

    name: str = "scene"
    description: str = ""
    cables: tuple[CableSpec, ...] = (CableSpec(), CableSpec())
    pulleys: tuple[PulleySpec, ...] = (
        PulleySpec(center=(-1.75, 0.0), side=-1),
        PulleySpec(center=(1.75, 0.0), side=1),
    )
    platform: PlatformSpec = field(default_factory=PlatformSpec)
    winch: WinchSpec = field(default_factory=WinchSpec)
    effects: Effects = field(default_factory=Effects)
    solver: SolverSpec = field(default_factory=SolverSpec)
    trajectory: Trajectory | None = None
    gravity: float = 9.81
    cable_exit: str = "pulley"
    controller_model: ControllerModel | None = None

    def __post_init__(self) -> None:
        if not isinstance(self.name, str) or not self.name:
            raise SceneError(f"name must be a non-empty string, got {shown(self.name)}")
        if not isinstance(self.description, str):
            raise SceneError(f"description must be a string, got {shown(self.description)}")
        for name, kind in (("cables", CableSpec), ("pulleys", PulleySpec)):
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
        if self.trajectory is not None and not isinstance(self.trajectory, Trajectory):
            raise SceneError(f"trajectory must be a Trajectory, got {shown(self.trajectory)}")
        m = len(self.cables)
        if m < 1:
            raise SceneError("cables must list at least one cable")
        if len(self.pulleys) != m:
            raise SceneError(f"pulleys must list one pulley per cable ({m}), got {len(self.pulleys)}")
        if len(self.platform.anchors) != m:
            raise SceneError(
                f"platform.anchors must list one anchor per cable ({m}), got {len(self.platform.anchors)}"
            )
        _set(self, "gravity", non_negative("gravity", self.gravity, "m/s^2"))
        check_weight(self.platform.mass, self.gravity)
        _choice("cable_exit", self.cable_exit, ("pulley", "point"))
        if self.winch.kind == "servo" and not self.effects.cable_mass:
            raise SceneError("winch.kind = 'servo' needs effects.cable_mass = true (a lumped cable to reel)")
        if self.cable_exit == "point" and self.winch.kind != "fixed":
            raise SceneError("cable_exit = 'point' needs winch.kind = 'fixed' (the cable starts at the pulley centre)")
        if self.solver.integrator != "generalized_alpha" and self.winch.kind != "fixed":
            raise SceneError(
                f"solver.integrator = {shown(self.solver.integrator)} needs winch.kind = 'fixed', got "
                f"{shown(self.winch.kind)}: Exudyn's explicit solvers eliminate the winch's coordinate constraints "
                "and hold them at their initial value, ignoring every winch command")
        if self.trajectory is None:
            from cdpr_exu.scenes.trajectories import HoldTrajectory

            _set(self, "trajectory", HoldTrajectory(tuple(self.platform.initial_pose)))
        self._check_reachable()
        if self.controller_model is not None:
            if not isinstance(self.controller_model, ControllerModel):
                raise SceneError(f"controller_model must be a ControllerModel, got {shown(self.controller_model)}")
            if self.controller_model.is_empty():
                _set(self, "controller_model", None)
            else:
                self.controller_model.apply(self)  # refuse a model that is no valid robot now, not at the run

    def controller_scene(self) -> "Scene":
        """The robot the controllers believe in: this scene with its controller model applied.

        Without a controller model, the scene itself. The trajectory, solver settings,
        effects and the initial pose are the plant's.
        """
        if self.controller_model is None:
            return self
        return self.controller_model.apply(self)

    def _check_reachable(self) -> None:
        """Refuse an initial pose the cables cannot reach or hold (before any simulation)."""
        anchors = anchor_points(np.asarray(self.platform.initial_pose), np.asarray(self.platform.anchors))
        above = above_exits(anchors[:, 1], [exit_.top for exit_ in self.exits])
        if above is not None and self.gravity > 0.0 and self.effects.gravity:
            raise UnreachableError(
                f"platform.initial_pose {list(self.platform.initial_pose)} (x [m], z [m], rotation [rad]) is above "
                f"the pulleys: {above}; give a platform.initial_pose below them")
        for i, (cable, pulley, exit_) in enumerate(zip(self.cables, self.pulleys, self.exits)):
            if exit_.is_point_exit:
                needed = float(np.linalg.norm(anchors[i] - np.asarray(exit_.center)))
            else:
                try:
                    needed = exit_.cable_length(anchors[i])
                except UnreachableError as err:
                    raise UnreachableError(
                        f"platform.anchors[{i}] at platform.initial_pose {list(self.platform.initial_pose)} cannot be "
                        f"reached over pulleys[{i}] (pulleys[{i}].center {list(pulley.center)} m, "
                        f"pulleys[{i}].radius {pulley.radius} m, pulleys[{i}].side {pulley.side}): {err}") from None
            if needed > cable.unstrained_length * (1 + 1e-9):
                raise SceneError(
                    f"cables[{i}].unstrained_length = {cable.unstrained_length} m is shorter than the "
                    f"{needed:.4f} m needed to reach platform.initial_pose {self.platform.initial_pose}"
                )

    # Convenience -------------------------------------------------------------------
    @property
    def exits(self) -> tuple[Pulley, ...]:
        """Where each cable leaves the frame, decided once from ``cable_exit``.

        The cable's pulley, or for ``cable_exit = "point"`` a point exit (a
        :class:`~cdpr_exu.core.geometry.Pulley` of radius 0) at the pulley's centre.
        """
        if self.cable_exit == "point":
            return tuple(Pulley(p.center, 0.0, p.side) for p in self.pulleys)
        return tuple(self.pulleys)

    @property
    def pulley_contact(self) -> bool:
        """True when the cables touch their pulleys: contact is on and the cables run over pulleys."""
        return self.effects.pulley_contact and self.cable_exit == "pulley"

    @property
    def contact_model(self) -> PulleyContactModel | None:
        """The pulley contact model the cables run with, decided once (None: no contact)."""
        return CONTACT_MODELS[self.effects.pulley_contact_model] if self.pulley_contact else None

    @property
    def n_cables(self) -> int:
        return len(self.cables)

    @property
    def tension_limits(self) -> np.ndarray | None:
        """Each cable's (t_min, t_max) [N], shape (m, 2), 0 and inf where not given; None without any limit."""
        return tension_limits(self.cables)

    def with_changes(self, **changes: Any) -> "Scene":
        """A copy with top-level fields replaced (validated again)."""
        return replace(self, **changes)

    def to_dict(self) -> dict[str, Any]:
        """Plain-data form (TOML-ready) of the scene."""
        data: dict[str, Any] = {
            "name": self.name,
            "description": self.description,
            "gravity": self.gravity,
            "cable_exit": self.cable_exit,
            "cables": [{k: v for k, v in dataclasses.asdict(c).items() if v is not None} for c in self.cables],
            "pulleys": [_listify(dataclasses.asdict(p)) for p in self.pulleys],
            "platform": _listify(dataclasses.asdict(self.platform)),
            "winch": dataclasses.asdict(self.winch),
            "effects": dataclasses.asdict(self.effects),
            "solver": dataclasses.asdict(self.solver),
            "trajectory": self.trajectory.to_dict(),
        }
        if self.controller_model is not None:
            data["controller_model"] = self.controller_model.to_dict()
        return data


def _listify(value: Any) -> Any:
    """Tuples to lists, recursively (TOML arrays)."""
    if isinstance(value, dict):
        return {k: _listify(v) for k, v in value.items()}
    if isinstance(value, (tuple, list)):
        return [_listify(v) for v in value]
    return value


# --------------------------------------------------------------------------- TOML


def _build(cls: type, data: Mapping[str, Any], path: str) -> Any:
    """Make dataclass ``cls`` from a mapping, refusing unknown keys."""
    if not isinstance(data, Mapping):
        raise SceneError(f"{path} must be a table, got {shown(data)}")
    known = {f.name for f in fields(cls)}
    unknown = set(data) - known
    if unknown:
        raise SceneError(f"{path} has unknown field(s) {sorted(unknown)}; known: {sorted(known)}")
    try:
        return cls(**data)
    except SceneError as err:
        # Prefix the field path with its position in the tree, e.g. cables[1].radius.
        message = str(err)
        head = cls.__name__.replace("Spec", "").lower()
        if path != head and message.startswith(head + "."):
            message = path + message[len(head):]
        raise SceneError(message) from None
    except TypeError as err:
        raise SceneError(f"{path}: {err}") from None


def _per_cable(data: Mapping[str, Any], single: str, plural: str, defaults: list[dict[str, Any]]) -> list[dict[str, Any]]:
    """Merge the shared table ``[single]`` into each entry of ``[[plural]]`` (or of ``defaults``)."""
    shared = data.get(single, {})
    if not isinstance(shared, Mapping):
        raise SceneError(f"{single} must be a table, got {shown(shared)}")
    shared = dict(shared)
    entries = data.get(plural, defaults)
    if not isinstance(entries, list) or not all(isinstance(e, Mapping) for e in entries):
        raise SceneError(f"{plural} must be an array of tables, got {shown(entries)}")
    return [{**e, **shared} if plural not in data else {**shared, **dict(e)} for e in entries]


#: The fields a scene file (or its plain data) must give, with their units: the robot's
#: geometry, lengths and masses, for which no default would be the robot its author meant.
#: Which of them apply depends on the scene (a pulley's radius and side only where the
#: cables run over pulleys, a platform's inertia only where an anchor is off its centre of
#: mass): :func:`missing_fields` is given the names that apply. Every other field keeps a
#: documented default that is a model choice (the paper's cable material, elements, contact
#: law, solver settings, effect flags).
REQUIRED_FIELDS: dict[str, str] = {
    "unstrained_length": "m", "center": "m", "radius": "m", "side": "-1 or +1", "mass": "kg",
    "inertia": "kg m^2", "anchors": "m", "initial_pose": "m, m, rad", "point": "m", "inlet": "m",
}


def missing_fields(path: str, given: Mapping[str, Any], names: tuple[str, ...]) -> list[str]:
    """The required ``names`` (keys of :data:`REQUIRED_FIELDS`) that the table ``given`` leaves
    out, each as a field path ``path.name`` with its unit, e.g. ``"platform.mass [kg]"``."""
    return [f"{path}.{name} [{REQUIRED_FIELDS[name]}]" for name in names if name not in given]


def refuse_missing(missing: list[str], source: str | None = None) -> None:
    """Raise SceneError naming every required field a scene leaves out (see :func:`missing_fields`).

    Called once the values given are checked, and before the scene's parts are put together
    (so that no default stands in for a missing field in a later check or message).
    """
    if missing:
        where = "scene" if source is None else f"scene {shown(source)}"
        raise SceneError(f"{where} lacks {', '.join(missing)}: a scene must give "
                         f"{'it' if len(missing) == 1 else 'each'}, as no default would be the robot you mean "
                         "(see the scene reference in the README)")


def _planar_missing(data: Mapping[str, Any], cable_dicts, pulley_dicts, platform: "PlatformSpec") -> list[str]:
    """The required fields a planar scene's plain data leaves out (its tables are checked apart)."""
    missing = [field_ for i, c in enumerate(cable_dicts)
               for field_ in missing_fields(f"cables[{i}]", c, ("unstrained_length",))]
    over_pulleys = data.get("cable_exit", "pulley") == "pulley"
    for i, p in enumerate(pulley_dicts):
        missing += missing_fields(f"pulleys[{i}]", p, ("center", "radius", "side") if over_pulleys else ("center",))
    if isinstance(data.get("platform"), Mapping):
        names = ("mass", "anchors", "initial_pose") + (() if platform.is_point_mass else ("inertia",))
        missing += missing_fields("platform", data["platform"], names)
    return missing


def scene_from_dict(data: Mapping[str, Any], source: str | None = None) -> Scene:
    """Make a validated Scene from plain data (as read from TOML).

    ``[cable]`` and ``[pulley]`` tables hold values shared by every cable or pulley;
    ``[[cables]]`` and ``[[pulleys]]`` entries override them one by one. ``[effects]``
    may name a ``preset`` and override single effects. The values given are checked
    first; then the tables (:data:`REQUIRED_TABLES`) and fields (:data:`REQUIRED_FIELDS`)
    a scene must give are required. ``source`` names the file in those messages.
    """
    if not isinstance(data, Mapping):
        raise SceneError(f"a scene must be a table (mapping), got {shown(data)}")
    data = dict(data)
    if data.get("dimension", 2) != 2:
        raise SceneError(f"dimension must be 2 (planar) or 3 (spatial), got {shown(data['dimension'])}")
    data.pop("dimension", None)
    top_known = {
        "name", "description", "gravity", "cable_exit", "cable", "cables", "pulley", "pulleys",
        "platform", "winch", "effects", "solver", "trajectory", "controller_model",
    }
    unknown = set(data) - top_known
    if unknown:
        raise SceneError(f"scene has unknown field(s) {sorted(unknown)}; known: {sorted(top_known)}")
    default = Scene.__dataclass_fields__
    default_pulleys = [_listify(dataclasses.asdict(p)) for p in default["pulleys"].default]
    pulley_dicts = _per_cable(data, "pulley", "pulleys", default_pulleys)
    cable_dicts = _per_cable(data, "cable", "cables", [{} for _ in pulley_dicts])
    cables = tuple(_build(CableSpec, c, f"cables[{i}]") for i, c in enumerate(cable_dicts))
    pulleys = tuple(_build(PulleySpec, p, f"pulleys[{i}]") for i, p in enumerate(pulley_dicts))
    platform = _build(PlatformSpec, data.get("platform", {}), "platform")
    effects_data = data.get("effects", {})
    if not isinstance(effects_data, Mapping):
        raise SceneError(f"effects must be a table, got {shown(effects_data)}")
    effects_data = dict(effects_data)
    preset = effects_data.pop("preset", "full")
    effects = Effects.from_preset(preset, **effects_data)
    trajectory = None
    if "trajectory" in data:
        trajectory = trajectory_from_dict(data["trajectory"])
    kwargs: dict[str, Any] = dict(
        cables=cables,
        pulleys=pulleys,
        platform=platform,
        winch=_build(WinchSpec, data.get("winch", {}), "winch"),
        effects=effects,
        solver=_build(SolverSpec, data.get("solver", {}), "solver"),
        trajectory=trajectory,
        controller_model=controller_model_from_dict(data["controller_model"]) if "controller_model" in data else None,
    )
    for key in ("name", "description", "gravity", "cable_exit"):
        if key in data:
            kwargs[key] = data[key]
    _check_required_tables(data, source)
    refuse_missing(_planar_missing(data, cable_dicts, pulley_dicts, platform), source)
    return Scene(**kwargs)


def tension_limits(cables) -> np.ndarray | None:
    """Each cable's (t_min, t_max) [N], shape (m, 2), 0 and inf where not given; None without any limit."""
    if all(c.min_tension is None and c.max_tension is None for c in cables):
        return None
    return np.array([[c.min_tension or 0.0, math.inf if c.max_tension is None else c.max_tension] for c in cables])


class SpatialSceneError(SceneError):
    """A spatial scene (``dimension = 3``) given where only planar scenes are taken."""


def _refuse_spatial(source: str | Path) -> None:
    raise SpatialSceneError(
        f"scene {shown(str(source))} is spatial (dimension = 3): `cdpr static`, `run`, `compare`, `study sweep`, "
        "`study accuracy` and `animate` take spatial scenes; `view` takes planar scenes only (see docs/spatial.md)")


def is_scene_file(source: str | Path) -> bool:
    """True when ``source`` names a file (a ``.toml`` path, or anything that exists) rather than a shipped scene."""
    path = Path(source)
    return path.suffix == ".toml" or path.exists()


def read_scene_file(source: str | Path) -> dict[str, Any]:
    """The plain data of the TOML scene file ``source``, or SceneError naming the file and what is wrong.

    Refused: a folder, a missing or unreadable file, a file that is not UTF-8 text (TOML is UTF-8:
    a Latin-1 or binary file), and text that is not valid TOML. An empty file is valid TOML (no
    tables); the loaders then say which tables it lacks.
    """
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
    """Load a planar scene by shipped name (e.g. ``"paper-circle"``) or from a TOML file path.

    Raises
    ------
    SpatialSceneError
        For a spatial scene (:func:`cdpr_exu.scenes.spatial_scene.load_spatial_scene` loads those).
    SceneError
        For a file that cannot be read as a scene (:func:`read_scene_file`), and for a bad scene.
    """
    if is_scene_file(source):
        data = read_scene_file(source)
    else:
        name = str(source).replace("-", "_") + ".toml"
        resource = resources.files("cdpr_exu.scenes").joinpath(name)
        if not resource.is_file() and resources.files("cdpr_exu.scenes").joinpath("spatial", name).is_file():
            _refuse_spatial(source)
        if not resource.is_file():
            raise unknown_scene(source)
        data = parse_scene_text(resource.read_text(encoding="utf-8"), source)
    if isinstance(data, Mapping) and data.get("dimension") == 3:
        _refuse_spatial(source)
    return scene_from_dict(data, source=str(source))


#: What a scene file must say: no default would be the robot or the motion its author meant.
REQUIRED_TABLES: dict[str, str] = {
    "pulleys": "[[pulleys]] with each pulley's center (where the cables run)",
    "platform": "[platform] with its anchors and mass",
    "trajectory": "[trajectory] (the reference motion; kind = \"hold\" with a pose to hold still)",
}


def _check_required_tables(data: Mapping[str, Any], source: str | None) -> None:
    """Refuse a planar scene file that leaves out a table it cannot sensibly do without."""
    missing = [name for name in REQUIRED_TABLES if name not in data]
    if "pulleys" in missing and isinstance(data.get("pulley"), Mapping) and "center" in data["pulley"]:
        missing.remove("pulleys")
    if missing:
        where = "scene" if source is None else f"scene {shown(source)}"
        raise SceneError(f"{where} lacks {', '.join(missing)}: a scene file must give "
                         + "; ".join(REQUIRED_TABLES[name] for name in missing)
                         + " (see the scene reference in the README)")


def shipped_names(folder: str | None = None) -> list[str]:
    """Names of the scenes shipped in the package's ``scenes`` folder (or its sub-folder ``folder``)."""
    files = resources.files("cdpr_exu.scenes")
    files = files if folder is None else files.joinpath(folder)
    return sorted(p.name[:-5].replace("_", "-") for p in files.iterdir() if p.name.endswith(".toml"))


def shipped_scenes() -> list[str]:
    """Names of the planar scenes shipped with the package."""
    return shipped_names()


def closest_names(name: str, names: list[str]) -> list[str]:
    """The names a misspelt ``name`` most likely meant: those that contain it, else those whose
    similarity (difflib's ratio) is at least 0.6 and within 0.1 of the best, the closest first."""
    import difflib

    key = name.replace("_", "-").lower()
    if len(key) >= 3 and any(key in n for n in names):
        return [n for n in names if key in n]
    scores = {n: difflib.SequenceMatcher(None, key, n).ratio() for n in names}
    floor = max(0.6, max(scores.values(), default=0.0) - 0.1)
    return sorted((n for n in names if scores[n] >= floor), key=lambda n: -scores[n])


def unknown_scene(source: str | Path) -> SceneError:
    """The refusal of a scene name that no shipped scene has: it lists every shipped scene, planar and
    spatial (``cdpr scenes``), after the likeliest (:func:`closest_names`), e.g. "did you mean 'spatial-cogiro'?"."""
    from cdpr_exu.scenes.spatial_scene import SPATIAL_FOLDER

    name = str(source)
    planar, spatial = shipped_names(), shipped_names(SPATIAL_FOLDER)
    close = closest_names(name, planar + spatial)
    guess = f"did you mean {' or '.join(map(repr, close))}? " if close else ""
    return SceneError(f"no scene named {shown(name)}; {guess}shipped scenes: {', '.join(planar)}; spatial: "
                      f"{', '.join(spatial)} (or give the path of a .toml scene file)")


def save_scene(scene: Scene, path: str | Path) -> Path:
    """Write the scene as TOML; :func:`load_scene` reads it back to an equal Scene."""
    import tomli_w

    path = Path(path)
    path.parent.mkdir(parents=True, exist_ok=True)
    path.write_text(tomli_w.dumps(scene.to_dict()))
    return path
