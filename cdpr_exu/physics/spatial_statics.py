"""Elastic-catenary statics of a spatial cable robot: the platform's pose from the cables' lengths.

Each cable runs from a fixed exit point ``e_i`` (world frame, a point exit: no pulley)
to an anchor ``b_i`` on the platform (platform frame), and hangs in the vertical plane
through its two ends. In that plane it is the 2-D elastic catenary of
:mod:`cdpr_exu.physics.catenary` (Irvine's model: weight, axial elasticity, no bending), with
end A at the anchor and end B at the exit point; the 2-D answer is rotated back to
3-D (MoorPy's trick for its mooring lines). z is up, gravity along -z, SI units.

With ``a_i`` the anchor's world position, ``d = e_i - a_i`` the span, ``h`` its
horizontal length and ``u = (d_x, d_y) / h`` its horizontal direction, the cable's
2-D span is ``(h, d_z)`` and its force on the platform is ``H u + V_A e_z``. Its
3-D end stiffness follows from the 2-D one ``K2`` (:func:`cdpr_exu.physics.catenary.end_stiffness`)
and the turning of ``u``::

    dF/da = Q K2 Q^T - (H / h) (P_h - u u^T),   Q = [u, e_z],  P_h = diag(1, 1, 0)

(a sideways step of the anchor turns the horizontal pull). For a vertical cable
(``h -> 0``) the sideways stiffness ``H / h`` tends to the in-plane one, ``-K2[0, 0]``.

Swivel pulleys
--------------
A cable whose exit is a swivel pulley (``SpatialCable.pulley_radius > 0``; the exit
point is then the pulley's inlet, :class:`cdpr_exu.exits.Swivel`) comes up
the vertical axis through the inlet, wraps over the disc and hangs to the anchor. The
suspended part hangs in a vertical plane, and the disc, free to turn about the axis,
has no torque on it only when that plane contains the axis: the pulley's azimuth is
the anchor's, ``e_rho`` the horizontal unit vector from the axis to the anchor. In the
plane ``(rho, z)`` from the inlet the cable is the planar pulley cable of
:mod:`cdpr_exu.statics.statics` (pulley centre ``(r_p, 0)``, side -1, hang point at the
inlet; frictionless, the wrap's weight carried by the disc, the unstrained length
counted from the inlet, wrap included). Its force on the platform is
``f_rho e_rho + f_z e_z`` and, the plane turning about the axis when the anchor moves
sideways, its 3-D end stiffness is ``Q K2 Q^T + (f_rho / rho) (P_h - e_rho e_rho^T)``,
``Q = [e_rho, e_z]``, ``rho`` the anchor's distance from the axis.

Platform
--------
* a **point mass** (every anchor at the centre of mass): unknowns the position
  ``r`` (3);
* a **rigid body**: unknowns ``r`` and a **rotation vector** ``theta`` (6), anchors at
  ``r + R(theta) b_i`` with ``R = exp([theta]x)`` (Rodrigues). A rotation vector is
  minimal (no constraint to carry, unlike Euler parameters, whose unit norm would be
  a seventh equation), zero at the reference orientation where a symmetric robot
  hangs, smooth there, and singular only at ``|theta| = 2 pi``, far from any hanging
  pose (Tait-Bryan angles lock at a pitch of 90 degrees). Its derivative enters via
  the left Jacobian of SO(3): a change ``d theta`` turns the body by the world-frame
  angle ``J_l(theta) d theta``, so the generalised force on ``theta`` is
  ``J_l^T M`` with ``M`` the moment about the centre of mass.

The equilibrium is the minimum of the potential energy (cables are conservative
elastic catenaries with fixed exits, the platform weight is ``M g z``); it is found by
Newton's method with the analytic stiffness and the energy line search of
:mod:`cdpr_exu.statics.statics`, started from the pose on straight, massless, elastic cables
(which exists also when some cables are slack). This covers statically indeterminate
robots (4 cables on a point mass, 8 on a rigid body): the cables' elasticity picks
the equilibrium, no tension distribution is assumed.
"""

from __future__ import annotations

import math
from dataclasses import dataclass, field

import numpy as np
from scipy.optimize import minimize

from cdpr_exu.physics.catenary import DEFAULT_MAX_STRAIN, STANDARD_GRAVITY, CatenaryCable, CatenaryState, end_stiffness, \
    profile, solve_forward, solve_inverse
from cdpr_exu.core.errors import SceneError, UnreachableError
from cdpr_exu.core.geometry import left_jacobian, rotation_from_vector, rotation_vector, skew
from cdpr_exu.core.geometry import swivel_pulley_exit
# the planar statics' line search, and its cable over a pulley in the swivel's vertical plane, reused
from cdpr_exu.statics.statics import PlatformEquilibriumViews, forward_cable, minimise_energy, swivel_plane_cable
from cdpr_exu.statics.statics import inverse_cable as planar_inverse_cable
from cdpr_exu.core.validation import non_negative, positive, real_array, shown, vector

_RELATIVE_TOLERANCE = 1e-12
"""Target of the scaled wrench residual (the cables are solved to 1e-12 of their length)."""

_E_Z = np.array([0.0, 0.0, 1.0])
_HORIZONTAL = np.diag([1.0, 1.0, 0.0])


# ---------------------------------------------------------------------------
# parameters
# ---------------------------------------------------------------------------
def _point3(name, value):
    return vector(name, value, 3, " (x, y, z) [m]")


@dataclass(frozen=True)
class SpatialCable:
    """One cable of a spatial robot: where it leaves the frame, where it holds the platform, its material.

    Parameters
    ----------
    exit_point : (float, float, float) [m]
        Fixed exit point, world frame (a point exit; no pulley).
    weight_per_length : float [N/m]
        ``w >= 0``, weight per unstrained length.
    axial_stiffness : float [N]
        ``EA > 0``.
    anchor : (float, float, float) [m], optional
        Anchor on the platform, platform frame (centre of mass at 0); default the centre.
    pulley_radius : float [m], optional
        0 (default): ``exit_point`` is a point exit. Positive: the cable leaves over a
        swivel pulley of this radius whose inlet is ``exit_point`` (module notes).

    Raises
    ------
    SceneError
        Naming the field, if a value is not finite or out of range.
    """

    exit_point: tuple
    weight_per_length: float
    axial_stiffness: float
    anchor: tuple = (0.0, 0.0, 0.0)
    pulley_radius: float = 0.0

    def __post_init__(self):
        object.__setattr__(self, "pulley_radius", non_negative("pulley_radius", self.pulley_radius))
        object.__setattr__(self, "exit_point", tuple(_point3("exit_point", self.exit_point)))
        object.__setattr__(self, "weight_per_length", non_negative("weight_per_length", self.weight_per_length))
        object.__setattr__(self, "axial_stiffness", positive("axial_stiffness", self.axial_stiffness))
        object.__setattr__(self, "anchor", tuple(_point3("anchor", self.anchor)))

    def catenary(self, unstrained_length):
        """The :class:`~cdpr_exu.physics.catenary.CatenaryCable` of this cable with the given unstrained length [m]."""
        return CatenaryCable(unstrained_length, self.weight_per_length, self.axial_stiffness)


@dataclass(frozen=True)
class SpatialPlatform:
    """A platform hung on spatial cables: a point mass, or a rigid body when some anchor is off its centre.

    Parameters
    ----------
    cables : sequence of SpatialCable
    mass : float [kg]
        ``M >= 0``; its weight acts at the centre of mass along -z.
    gravity : float [m/s^2], optional
        Default 9.81.
    inertia : (float, float, float) [kg m^2], optional
        Principal moments of inertia about the centre of mass, along the platform axes;
        only the dynamics (:mod:`cdpr_exu.builder.spatial_robot`) use them.

    Raises
    ------
    SceneError
        Naming the field: no cables, a negative mass, two cables sharing an exit point,
        two cables of a rigid platform sharing an anchor, too few cables to hang it (a
        point mass needs one; a rigid body two, and anchors not all on one line
        through its centre of mass, around which it would turn freely).
    """

    cables: tuple
    mass: float
    gravity: float = STANDARD_GRAVITY
    inertia: tuple = (0.0, 0.0, 0.0)

    def __post_init__(self):
        try:
            cables = tuple(self.cables)
        except TypeError:
            raise SceneError(f"cables must be a sequence of SpatialCable, got {shown(self.cables)}") from None
        if not all(isinstance(c, SpatialCable) for c in cables):
            raise SceneError(f"cables must be a sequence of SpatialCable, got {shown(self.cables)}")
        object.__setattr__(self, "cables", cables)
        object.__setattr__(self, "mass", non_negative("mass", self.mass))
        object.__setattr__(self, "gravity", non_negative("gravity", self.gravity))
        inertia = vector("inertia", self.inertia, 3, " (principal moments) [kg m^2]")
        if np.any(inertia < 0.0):
            raise SceneError(f"inertia must be zero or positive, got {shown(self.inertia)}")
        object.__setattr__(self, "inertia", tuple(inertia))
        exits = np.array([c.exit_point for c in cables]).reshape(-1, 3)
        anchors = np.array([c.anchor for c in cables]).reshape(-1, 3)
        size = max(1.0, float(np.abs(exits).max(initial=0.0)))
        for i in range(len(cables)):
            for j in range(i):
                if np.linalg.norm(exits[i] - exits[j]) <= 1e-9 * size:
                    raise SceneError(f"cables[{j}] and cables[{i}] share the exit_point {shown(exits[i])} m")
        needed = 1 if self.is_point_mass else 2
        if len(cables) < needed:
            kind = "a point mass" if needed == 1 else "a rigid platform"
            raise SceneError(f"cables: {kind} needs at least {needed} cable(s) to hang, got {len(cables)}")
        if not self.is_point_mass:
            arm = max(float(np.linalg.norm(anchors, axis=1).max()), 1e-300)
            for i in range(len(cables)):
                for j in range(i):
                    if np.linalg.norm(anchors[i] - anchors[j]) <= 1e-9 * arm:
                        raise SceneError(f"cables[{j}] and cables[{i}] share the anchor {shown(anchors[i])} m "
                                         f"on a rigid platform")
            if np.linalg.matrix_rank(anchors, tol=1e-9 * arm) < 2:
                raise SceneError(f"cables: the anchors {anchors.tolist()} m lie on one line through the centre "
                                 f"of mass; the platform would turn freely about it")

    @property
    def is_point_mass(self):
        """True when every anchor is at the centre of mass."""
        return all(c.anchor == (0.0, 0.0, 0.0) for c in self.cables)

    @property
    def degrees_of_freedom(self):
        """3 for a point mass ``r``, 6 for a rigid body ``(r, theta)``."""
        return 3 if self.is_point_mass else 6

    @property
    def exit_points(self):
        """Exit points, shape (n_cables, 3) [m]."""
        return np.array([c.exit_point for c in self.cables])

    @property
    def anchors(self):
        """Anchors in the platform frame, shape (n_cables, 3) [m]."""
        return np.array([c.anchor for c in self.cables])

    def anchor_points(self, position, rotation=None):
        """World positions of the anchors, shape (n_cables, 3) [m], for a rotation matrix (default identity)."""
        rotation = np.eye(3) if rotation is None else np.asarray(rotation, dtype=float)
        return np.asarray(position, dtype=float) + self.anchors @ rotation.T


# ---------------------------------------------------------------------------
# results
# ---------------------------------------------------------------------------
@dataclass(frozen=True, eq=False)
class SpatialCableEquilibrium:
    """One cable in a platform equilibrium.

    Attributes
    ----------
    catenary : CatenaryState
        The 2-D catenary in the cable's vertical plane, A at the anchor, B at the exit.
    unstrained_length : float [m]
    anchor_point, exit_point : ndarray, shape (3,) [m]
        World positions of the two ends.
    horizontal_direction : ndarray, shape (3,)
        ``u``: unit horizontal vector from the anchor towards the exit (the plane's x
        axis); any horizontal unit vector for a vertical cable. Over a swivel pulley,
        ``e_rho``, from the axis towards the anchor (the catenary's horizontal sign then
        says which way the exit lies).
    force_on_platform : ndarray, shape (3,) [N]
        Force the cable exerts on the platform at its anchor.
    force_on_exit : ndarray, shape (3,) [N]
        Force the cable exerts on its exit point (on a swivel pulley: at the tangent point).
    cable : CatenaryCable
        The 2-D catenary parameters of the suspended part (its unstrained length, weight, ``EA``).
    guess : tuple
        Warm start of the next solve of this cable.
    pulley_radius : float [m]
        0 for a point exit; else the swivel pulley's: ``exit_point`` is then the tangent
        point where the cable leaves the disc, ``inlet`` the pulley's inlet.
    wrap_angle : float [rad]
        Angle the cable wraps on the swivel pulley (0 for a point exit).
    inlet : ndarray, shape (3,) [m] or None
    """

    catenary: CatenaryState
    unstrained_length: float
    anchor_point: np.ndarray
    exit_point: np.ndarray
    horizontal_direction: np.ndarray
    force_on_platform: np.ndarray
    force_on_exit: np.ndarray
    cable: CatenaryCable = field(repr=False)
    guess: tuple = field(default=None, repr=False)
    pulley_radius: float = 0.0
    wrap_angle: float = 0.0
    inlet: np.ndarray | None = None

    @property
    def suspended_length(self):
        """Unstrained length of the suspended part, anchor to exit or tangent point [m]."""
        return self.cable.unstrained_length

    @property
    def tension_at_anchor(self):
        """Tension at the anchor [N]."""
        return self.catenary.tension_a

    @property
    def tension_at_exit(self):
        """Tension at the exit point [N]."""
        return self.catenary.tension_b

    def points(self, s):
        """Points of the loaded cable at unstrained arc lengths ``s`` (n,) [m] from the anchor, shape (n, 3) [m].

        On a swivel pulley, arc lengths beyond the suspended part lie on the wrap (stretched
        by the tension at the tangent point), up to ``unstrained_length`` at the inlet."""
        s = np.atleast_1d(np.asarray(s, dtype=float))
        suspended = self.suspended_length
        hanging = s <= suspended if self.pulley_radius > 0.0 else np.ones(s.shape, bool)
        points = np.empty((s.size, 3))
        if hanging.any():
            planar = profile(self.cable, self.catenary, s[hanging])
            points[hanging] = (self.anchor_point + np.outer(planar[:, 0], self.horizontal_direction)
                               + np.outer(planar[:, 1], _E_Z))
        if not hanging.all():
            radius = self.pulley_radius
            stretch = 1.0 + self.tension_at_exit / self.cable.axial_stiffness
            # rim angle in the plane (rho, z) about the centre (r_p, 0): the inlet is at pi
            angle = np.minimum(math.pi - self.wrap_angle + (s[~hanging] - suspended) * stretch / radius, math.pi)
            points[~hanging] = (self.inlet + np.outer(radius * (1.0 + np.cos(angle)), self.horizontal_direction)
                                + np.outer(radius * np.sin(angle), _E_Z))
        return points


@dataclass(frozen=True, eq=False)
class SpatialEquilibrium(PlatformEquilibriumViews):
    """A static equilibrium of the platform on its cables.

    Attributes
    ----------
    position : ndarray, shape (3,) [m]
        Centre of mass.
    rotation_vector : ndarray, shape (3,) [rad]
        Zero for a point mass.
    rotation : ndarray, shape (3, 3)
        ``R``: platform frame to world frame.
    cables : tuple of SpatialCableEquilibrium
    stiffness : ndarray, shape (k, k)
        ``-d(generalised force)/d(pose)`` at fixed unstrained lengths, ``k = 3``
        (``r``) or 6 (``r``, ``theta``); N/m, N/rad, N m/m, N m/rad.
    net_wrench : ndarray, shape (6,) [N, N m]
        Remaining force and moment (about the centre of mass) on the platform:
        cables, weight and external load; zero to solver tolerance.
    """

    position: np.ndarray
    rotation_vector: np.ndarray
    rotation: np.ndarray
    cables: tuple
    stiffness: np.ndarray = field(repr=False)
    net_wrench: np.ndarray = field(repr=False)

    @property
    def tensions_at_exit(self):
        """Tension of each cable at its exit point, shape (n_cables,) [N]."""
        return np.array([c.tension_at_exit for c in self.cables])

    @property
    def anchor_points(self):
        """World positions of the anchors, shape (n_cables, 3) [m]."""
        return np.array([c.anchor_point for c in self.cables])


# ---------------------------------------------------------------------------
# the lumped cable's masses (the spatial builder's and the spatial chain statics')
# ---------------------------------------------------------------------------
def chain_element_mass(cable, length, n_elements, gravity):
    """Mass of one of the ``n_elements`` equal elements of ``cable`` (a :class:`SpatialCable`) of unstrained
    ``length`` [m] [kg]: its weight per length over ``gravity`` [m/s^2] (> 0)."""
    return cable.weight_per_length / gravity * length / n_elements


def node_masses_along(n_elements, element_mass, mass_lumping="consistent"):
    """Lumped masses of the n + 1 nodes of a cable of equal elements, exit first, shape (n + 1,) [kg]:
    "consistent" puts half of each element on each of its nodes; "paper" puts it on its far node,
    the held exit node getting half an element."""
    masses = np.full(n_elements + 1, float(element_mass))
    masses[0] = 0.5 * element_mass
    if mass_lumping == "consistent":
        masses[-1] = 0.5 * element_mass
    return masses


# ---------------------------------------------------------------------------
# one cable
# ---------------------------------------------------------------------------
def solve_cable(cable, unstrained_length, anchor_point, guess=None, max_strain=DEFAULT_MAX_STRAIN,
                max_tension=None):
    """Solve one cable from a given anchor point to its exit point.

    Parameters
    ----------
    cable : SpatialCable
    unstrained_length : float [m]
    anchor_point : ndarray, shape (3,) [m]
        World position of the anchor.
    guess : (H, V_B) [N], optional
        Warm start of the 2-D catenary.
    max_strain, max_tension : float, optional
        As in :func:`cdpr_exu.physics.catenary.solve_forward`.

    Returns
    -------
    equilibrium : SpatialCableEquilibrium
    stiffness : ndarray, shape (3, 3) [N/m]
        ``d(force on platform)/d(anchor point)``.

    Raises
    ------
    UnreachableError
        If the span is beyond the cable's reach at its tension limit.
    """
    if cable.pulley_radius > 0.0:
        return _solve_swivel_cable(cable, unstrained_length, np.asarray(anchor_point, dtype=float), guess, max_strain,
                                   max_tension)
    catenary_cable = cable.catenary(unstrained_length)
    exit_point = np.array(cable.exit_point)
    span = exit_point - anchor_point
    horizontal = float(math.hypot(span[0], span[1]))
    direction = np.array([span[0], span[1], 0.0]) / horizontal if horizontal > 0.0 else np.array([1.0, 0.0, 0.0])
    state = solve_forward(catenary_cable, (horizontal, span[2]), initial_guess=guess, max_strain=max_strain,
                          max_tension=max_tension)
    planar = end_stiffness(catenary_cable, state)
    basis = np.column_stack([direction, _E_Z])
    stiffness = basis @ planar @ basis.T
    vertical = horizontal <= 1e-9 * max(unstrained_length, float(np.linalg.norm(span)))
    sideways = -planar[0, 0] if vertical else state.horizontal_tension / horizontal
    stiffness -= sideways * (_HORIZONTAL - np.outer(direction, direction))
    equilibrium = SpatialCableEquilibrium(
        catenary=state,
        unstrained_length=float(unstrained_length),
        anchor_point=np.array(anchor_point, dtype=float),
        exit_point=exit_point,
        horizontal_direction=direction,
        force_on_platform=state.force_on_a[0] * direction + state.force_on_a[1] * _E_Z,
        force_on_exit=state.force_on_b[0] * direction + state.force_on_b[1] * _E_Z,
        cable=catenary_cable,
        guess=(state.horizontal_tension, state.vertical_tension_b),
    )
    return equilibrium, stiffness


def _swivel_plane(cable, anchor_point):
    """The vertical plane through a swivel pulley's axis and ``anchor_point`` (3,) [m], where its cable hangs.

    Returns the inlet (3,) [m], the plane's horizontal unit vector e_rho (3,), the anchor's
    span from the inlet in the plane (rho, dz) (2,) [m], and the planar pulley cable of
    :mod:`cdpr_exu.statics.statics` whose disc touches the axis at the plane's origin.

    Raises
    ------
    UnreachableError
        If the anchor lies on the axis (its azimuth, and so the plane, is undefined).
    """
    inlet = np.array(cable.exit_point)
    offset = np.asarray(anchor_point, dtype=float) - inlet
    rho = float(math.hypot(offset[0], offset[1]))
    if rho <= 1e-12 * (float(np.linalg.norm(offset)) + cable.pulley_radius):
        raise UnreachableError(f"anchor {np.asarray(anchor_point).tolist()} lies on the axis of the swivel pulley at "
                               f"{inlet.tolist()}: its azimuth is undefined")
    e_rho = np.array([offset[0], offset[1], 0.0]) / rho
    radius = cable.pulley_radius
    planar_cable = swivel_plane_cable(cable.weight_per_length, cable.axial_stiffness, radius)
    return inlet, e_rho, np.array([rho, offset[2]]), planar_cable


def _solve_swivel_cable(cable, unstrained_length, anchor_point, guess, max_strain, max_tension):
    """:func:`solve_cable` over a swivel pulley: the planar pulley cable in the plane through the axis and the anchor."""
    inlet, e_rho, span, planar_cable = _swivel_plane(cable, anchor_point)
    rho = span[0]
    radius = cable.pulley_radius
    planar, planar_stiffness, new_guess = forward_cable(planar_cable, float(unstrained_length), span, guess,
                                                        max_strain, max_tension)
    basis = np.column_stack([e_rho, _E_Z])
    force = planar.force_on_platform
    stiffness = basis @ planar_stiffness @ basis.T + force[0] / rho * (_HORIZONTAL - np.outer(e_rho, e_rho))
    tangent = inlet + planar.upper_point[0] * e_rho + planar.upper_point[1] * _E_Z
    state = planar.catenary
    equilibrium = SpatialCableEquilibrium(
        catenary=state,
        unstrained_length=float(unstrained_length),
        anchor_point=np.array(anchor_point, dtype=float),
        exit_point=tangent,
        horizontal_direction=e_rho,
        force_on_platform=force[0] * e_rho + force[1] * _E_Z,
        force_on_exit=state.force_on_b[0] * e_rho + state.force_on_b[1] * _E_Z,
        cable=cable.catenary(planar.suspended_length),
        guess=tuple(new_guess),
        pulley_radius=radius,
        wrap_angle=float(planar.wrap_angle),
        inlet=inlet,
    )
    return equilibrium, stiffness


# ---------------------------------------------------------------------------
# the platform
# ---------------------------------------------------------------------------
def checked_unstrained_lengths(platform, unstrained_lengths):
    """The cables' unstrained lengths [m] as a float array, one per cable of ``platform``, each positive.

    Raises
    ------
    SceneError
        Naming ``unstrained_lengths``, if they are not numbers, not one per cable or not positive.
    """
    lengths = real_array("unstrained_lengths", unstrained_lengths)
    if lengths.shape != (len(platform.cables),):
        raise SceneError(f"unstrained_lengths must have one entry per cable ({len(platform.cables)}), "
                         f"got {shown(unstrained_lengths)}")
    if np.any(lengths <= 0.0):
        raise SceneError(f"unstrained_lengths must be positive, got {shown(unstrained_lengths)}")
    return lengths


def _wrench(external_wrench):
    if external_wrench is None:
        return np.zeros(6)
    return vector("external_wrench", external_wrench, 6, " (fx, fy, fz, mx, my, mz) [N, N m]")


def _check_reach(platform, lengths, max_strain, max_tension):
    """Refuse cables that cannot all meet the platform: exits farther apart than two cables and the anchors reach."""
    reaches = []
    for cable, length in zip(platform.cables, lengths):
        limit = max_strain * cable.axial_stiffness
        if max_tension is not None:
            limit = min(limit, max_tension)
        reaches.append(length * (1.0 + limit / cable.axial_stiffness))
    exits, anchors = platform.exit_points, platform.anchors
    for i in range(len(lengths)):
        for j in range(i):
            gap = float(np.linalg.norm(exits[i] - exits[j]))
            reach = reaches[i] + reaches[j] + float(np.linalg.norm(anchors[i] - anchors[j]))
            if gap > reach:
                raise UnreachableError(
                    f"unstrained_lengths: cables[{j}] and cables[{i}] cannot both reach the platform: their exit "
                    f"points are {gap:g} m apart, beyond the {reach:g} m their lengths ({lengths[j]:g}, "
                    f"{lengths[i]:g} m, at the tension limit) and anchors span")


def _pose(platform, coordinates):
    """Position, rotation matrix and rotation vector from the unknowns."""
    position = coordinates[:3]
    theta = coordinates[3:6] if platform.degrees_of_freedom == 6 else np.zeros(3)
    return position, rotation_from_vector(theta), theta


def _straight_path(cable, exit_point, point):
    """Length [m] of a straight, massless cable from its exit to ``point`` (3,), and the unit
    vector (3,) along its last straight part towards ``point`` (the length's gradient in ``point``).

    Over a swivel pulley the path wraps the disc in the plane through the axis and ``point``
    (:func:`cdpr_exu.core.geometry.swivel_pulley_exit`: arc plus free length);
    where that is undefined (``point`` on the axis or inside the disc, only ever an iterate of
    the starting guess) the straight distance from the inlet stands in.
    """
    span = point - exit_point
    distance = float(np.linalg.norm(span))
    if cable.pulley_radius > 0.0:
        try:
            path = swivel_pulley_exit(exit_point, cable.pulley_radius, point)
        except UnreachableError:
            pass
        else:
            return float(path.arc_length + path.free_length), np.asarray(path.unit_vector, dtype=float)
    return distance, span / distance if distance > 0.0 else np.zeros(3)


def straight_cable_pose(platform, unstrained_lengths, external_wrench=None):
    """Equilibrium pose on straight, massless, elastic cables that may go slack (the starting guess).

    Minimises ``M g z - wrench . pose + sum k_i max(l_i - L_i, 0)^2 / 2`` with ``l_i``
    the straight anchor-exit distance (over a swivel pulley: the wrapped arc plus the
    tangent, :func:`_straight_path`; the inlet distance overestimated the reach there, and
    the shrunk swivel scene's statics started beyond it) and ``k_i = EA_i / L_i``.

    Parameters
    ----------
    platform : SpatialPlatform
    unstrained_lengths : array_like, shape (n_cables,) [m]
    external_wrench : array_like, shape (6,) [N, N m], optional

    Returns
    -------
    ndarray, shape (3,) or (6,)
        ``r`` [m] (and the rotation vector ``theta`` [rad] for a rigid body).
    """
    lengths = checked_unstrained_lengths(platform, unstrained_lengths)
    wrench = _wrench(external_wrench)
    dof = platform.degrees_of_freedom
    stiffness = np.array([c.axial_stiffness for c in platform.cables]) / lengths
    exits = platform.exit_points
    weight = platform.mass * platform.gravity
    scale = weight + sum(c.weight_per_length * L for c, L in zip(platform.cables, lengths)) + 1e-12

    def energy(q):
        position, rotation, theta = _pose(platform, q)
        arms = platform.anchors @ rotation.T
        value = weight * position[2] - wrench[:3] @ position - (wrench[3:] @ theta if dof == 6 else 0.0)
        force = np.array([0.0, 0.0, weight]) - wrench[:3]
        moment = -wrench[3:].copy()
        for cable, arm, exit_point, length, k in zip(platform.cables, arms, exits, lengths, stiffness):
            distance, direction = _straight_path(cable, exit_point, position + arm)
            if distance > length:
                value += 0.5 * k * (distance - length) ** 2
                pull = k * (distance - length) * direction
                force += pull
                moment += np.cross(arm, pull)
        gradient = force if dof == 3 else np.concatenate([force, left_jacobian(theta).T @ moment])
        return value / scale, gradient / scale

    # Unknowns in metres (the rotation vector times the largest arm), so that a step turns
    # the anchors as far as it moves them: with stiff cables (EA / L of 3e5 N/m, CoGiRo)
    # unscaled steps spun the platform through several turns.
    arm = float(np.linalg.norm(platform.anchors, axis=1).max()) if dof == 6 else 1.0
    unit = np.array([1.0] * 3 + [max(arm, 1e-3)] * 3)[:dof]

    def scaled_energy(x):
        value, gradient = energy(x / unit)
        return value, gradient / unit

    # Start at the exits' centroid, unrotated: inside the frame, the cables slack or short of
    # their lengths, so the weight and the taut cables pull the platform onto its equilibrium.
    # (Starting a cable length below the exits stretched CoGiRo's stiff cables by metres.)
    start = np.zeros(dof)
    start[:3] = exits.mean(axis=0)
    solution = minimize(scaled_energy, start * unit, jac=True, method="BFGS", options={"gtol": 1e-10, "maxiter": 5000})
    return solution.x / unit


def solve_spatial_statics(platform, unstrained_lengths, initial_pose=None, external_wrench=None,
                          max_strain=DEFAULT_MAX_STRAIN, max_tension=None):
    """Equilibrium pose of the platform and every cable's forces, for given unstrained lengths.

    Newton's method on the net generalised force (force, and ``J_l^T`` moment for a
    rigid body), with the analytic stiffness assembled from the cables' 3-D end
    stiffnesses and a line search on the energy; every evaluation solves each cable's
    catenary, warm-started from the previous iterate.

    Parameters
    ----------
    platform : SpatialPlatform
    unstrained_lengths : array_like, shape (n_cables,) [m]
    initial_pose : array_like, shape (3,) or (6,), optional
        Start ``r`` [m] (and ``theta`` [rad]); default :func:`straight_cable_pose`.
    external_wrench : array_like, shape (6,) [N, N m], optional
        Extra force and moment (about the centre of mass) on the platform.
    max_strain, max_tension : float, optional
        Cable tension limits, as in :func:`cdpr_exu.physics.catenary.solve_forward`.

    Returns
    -------
    SpatialEquilibrium

    Raises
    ------
    SceneError
        Naming the argument, if an input is invalid (checked before any solve).
    UnreachableError
        If two cables cannot both reach the platform (checked before any solve), or if
        no equilibrium is found within the tension limits.
    """
    if not isinstance(platform, SpatialPlatform):
        raise SceneError(f"platform must be a SpatialPlatform, got {shown(platform)}")
    lengths = checked_unstrained_lengths(platform, unstrained_lengths)
    wrench = _wrench(external_wrench)
    max_strain = positive("max_strain", max_strain)
    if max_tension is not None:
        max_tension = positive("max_tension", max_tension)
    dof = platform.degrees_of_freedom
    if initial_pose is not None:
        start = real_array("initial_pose", initial_pose)
        if start.shape != (dof,):
            raise SceneError(f"initial_pose must have {dof} entries for this platform, got {shown(initial_pose)}")
    _check_reach(platform, lengths, max_strain, max_tension)
    if initial_pose is None:
        start = straight_cable_pose(platform, lengths, wrench)

    weight = platform.mass * platform.gravity
    force_scale = max(weight + sum(c.weight_per_length * L for c, L in zip(platform.cables, lengths))
                      + float(np.linalg.norm(wrench[:3])), 1e-12)
    arm = float(np.linalg.norm(platform.anchors, axis=1).max())
    length_scale = arm if arm > 0.0 else 1.0
    residual_scale = np.array([force_scale] * 3 + [force_scale * length_scale] * 3)[:dof]
    pose_scale = np.array([1.0] * 3 + [length_scale] * 3)[:dof]  # unknowns in metres
    stiffest = max(c.axial_stiffness for c in platform.cables)
    noise = 1e3 * _RELATIVE_TOLERANCE * (1.0 + stiffest / force_scale)
    guesses = [None] * len(platform.cables)
    cache = {}

    def evaluate(coordinates):
        position, rotation, theta = _pose(platform, coordinates)
        arms = platform.anchors @ rotation.T
        wrench_total = wrench.copy()
        wrench_total[2] -= weight
        jacobian = np.zeros((6, 6))  # d(force, moment)/d(r, world rotation)
        equilibria = []
        for i, (cable, length, arm_) in enumerate(zip(platform.cables, lengths, arms)):
            equilibrium, stiffness = solve_cable(cable, length, position + arm_, guesses[i], max_strain, max_tension)
            guesses[i] = equilibrium.guess
            equilibria.append(equilibrium)
            force = equilibrium.force_on_platform
            wrench_total[:3] += force
            wrench_total[3:] += np.cross(arm_, force)
            arm_skew = skew(arm_)
            jacobian[:3, :3] += stiffness
            jacobian[:3, 3:] -= stiffness @ arm_skew
            jacobian[3:, :3] += arm_skew @ stiffness
            jacobian[3:, 3:] += -arm_skew @ stiffness @ arm_skew + skew(force) @ arm_skew
        cache["last"] = (position, rotation, theta, equilibria, wrench_total)
        if dof == 3:
            return wrench_total[:3], jacobian[:3, :3]
        tangent = left_jacobian(theta)
        residual = np.concatenate([wrench_total[:3], tangent.T @ wrench_total[3:]])
        # d(J_l^T M)/d(theta) also has a term in dJ_l/d(theta) M, which vanishes at equilibrium: left out
        generalised = jacobian @ np.block([[np.eye(3), np.zeros((3, 3))], [np.zeros((3, 3)), tangent]])
        generalised[3:] = tangent.T @ generalised[3:]
        return residual, generalised

    def function(scaled):
        residual, jacobian = evaluate(scaled / pose_scale)
        return residual / residual_scale, jacobian / residual_scale[:, None] / pose_scale[None, :]

    try:
        scaled, _, _ = minimise_energy(function, start * pose_scale, _RELATIVE_TOLERANCE, noise,
                                       what="spatial statics")
    except UnreachableError as error:
        raise UnreachableError(f"no equilibrium found for unstrained_lengths {lengths.tolist()} m: {error}") from None
    coordinates = scaled / pose_scale
    _, jacobian = evaluate(coordinates)  # the accepted point, with its own cable states
    position, rotation, theta, equilibria, wrench_total = cache["last"]
    return SpatialEquilibrium(
        position=np.array(position, dtype=float),
        rotation_vector=rotation_vector(rotation) if dof == 6 else np.zeros(3),
        rotation=rotation,
        cables=tuple(equilibria),
        stiffness=-jacobian,
        net_wrench=wrench_total,
    )


# ---------------------------------------------------------------------------
# the inverse: lengths that hold a pose
# ---------------------------------------------------------------------------
@dataclass(frozen=True, eq=False)
class SpatialInverse:
    """Unstrained lengths that hold the platform at a pose on elastic catenaries.

    Attributes
    ----------
    unstrained_lengths : ndarray, shape (n_cables,) [m]
    horizontal_tensions : ndarray, shape (n_cables,) [N]
    forces_on_platform : ndarray, shape (n_cables, 3) [N]
    residual : float [N]
        Largest remaining force (and moment / arm) imbalance of the platform.
    """

    unstrained_lengths: np.ndarray
    horizontal_tensions: np.ndarray
    forces_on_platform: np.ndarray
    residual: float


def _inverse_cable(cable, anchor_point, horizontal_tension):
    """Unstrained length [m] and force on the platform (3,) [N] of one cable at horizontal tension H."""
    if cable.pulley_radius > 0.0:
        return _inverse_swivel_cable(cable, anchor_point, horizontal_tension)
    exit_point = np.array(cable.exit_point)
    span = exit_point - anchor_point
    horizontal = float(math.hypot(span[0], span[1]))
    if horizontal <= 0.0:
        raise UnreachableError(f"cable from {shown(exit_point)} hangs vertically above its anchor: its horizontal "
                               "tension is zero and the inverse catenary has no answer")
    direction = np.array([span[0], span[1], 0.0]) / horizontal
    length, state = solve_inverse((horizontal, span[2]), cable.weight_per_length, cable.axial_stiffness,
                                  horizontal_tension)
    return length, state.force_on_a[0] * direction + state.force_on_a[1] * _E_Z


def _inverse_swivel_cable(cable, anchor_point, horizontal_tension):
    """:func:`_inverse_cable` over a swivel pulley: the planar pulley cable's inverse (``statics.inverse_cable``)
    in the vertical plane through the axis and the anchor, as :func:`_solve_swivel_cable` solves it forward.
    The length counts from the inlet, the wrap included."""
    _, e_rho, span, planar_cable = _swivel_plane(cable, anchor_point)
    planar, _, _, _ = planar_inverse_cable(planar_cable, float(horizontal_tension), span, None,
                                           DEFAULT_MAX_STRAIN, None)
    force = planar.force_on_platform
    return planar.unstrained_length, force[0] * e_rho + force[1] * _E_Z


def solve_inverse_spatial_statics(platform, pose, horizontal_guess, external_wrench=None, tolerance=1e-9,
                                  max_iterations=30):
    """Unstrained lengths that hold ``platform`` at ``pose`` on elastic catenaries, tensions nearest a guess.

    The cables' horizontal tensions ``H`` (m,) are chosen closest to ``horizontal_guess``
    (least squares) among those whose catenaries balance the platform: the force, and for
    a rigid platform held by at least six cables the moment too (with fewer, the rotation is
    left free, as a suspended platform does). Gauss-Newton on the balance, each cable's
    force derivative by a forward difference of its inverse catenary
    (:func:`cdpr_exu.physics.catenary.solve_inverse`). Continuing from the previous sample's tensions
    along a trajectory gives the tension path with the least change: an over-constrained
    robot keeps the internal tension it started with.

    Parameters
    ----------
    platform : SpatialPlatform
    pose : array_like, shape (3,) or (6,) [m, rad]
        Centre of mass and (rigid) rotation vector.
    horizontal_guess : array_like, shape (n_cables,) [N]
        Positive horizontal tensions to stay close to (eg the previous sample's).
    external_wrench : array_like, shape (6,) [N, N m], optional
        Extra load on the platform (eg the d'Alembert force of an acceleration).

    Returns
    -------
    SpatialInverse

    Raises
    ------
    UnreachableError
        If no positive tensions balance the platform there (the balance does not converge,
        or a tension would have to be negative: outside the wrench-feasible workspace).
    """
    pose = real_array("pose", pose)
    dof = platform.degrees_of_freedom
    if pose.shape != (6,) and not (dof == 3 and pose.shape == (3,)):
        raise SceneError(f"pose must have 6 entries (3 for a point mass), got {shown(pose.tolist())}")
    guess = real_array("horizontal_guess", horizontal_guess)
    if guess.shape != (len(platform.cables),) or np.any(guess <= 0.0):
        raise SceneError(f"horizontal_guess must be one positive tension per cable, got {shown(horizontal_guess)}")
    wrench = _wrench(external_wrench)
    position = pose[:3]
    rotation = rotation_from_vector(pose[3:6]) if pose.shape == (6,) and dof == 6 else np.eye(3)
    arms = platform.anchors @ rotation.T
    anchor_points = position + arms
    rows = 6 if (dof == 6 and len(platform.cables) >= 6) else 3
    weight = platform.mass * platform.gravity
    arm_scale = max(float(np.linalg.norm(platform.anchors, axis=1).max()), 1e-3)
    scale = np.array([1.0, 1.0, 1.0, 1.0 / arm_scale, 1.0 / arm_scale, 1.0 / arm_scale])[:rows]

    def balance(tensions):
        lengths, forces = zip(*(_inverse_cable(c, p, h) for c, p, h in zip(platform.cables, anchor_points, tensions)))
        forces = np.array(forces)
        total = np.concatenate([forces.sum(axis=0) + wrench[:3] - [0.0, 0.0, weight],
                                np.cross(arms, forces).sum(axis=0) + wrench[3:]])[:rows] * scale
        return np.array(lengths), forces, total

    tensions = guess.copy()
    for _ in range(max_iterations):
        lengths, forces, total = balance(tensions)
        residual = float(np.abs(total).max())
        if residual <= tolerance * max(weight, float(np.abs(forces).max()), 1e-12):
            return SpatialInverse(lengths, tensions, forces, residual)
        jacobian = np.zeros((rows, len(tensions)))
        for i, (cable, point, h) in enumerate(zip(platform.cables, anchor_points, tensions)):
            step = 1e-6 * h
            _, shifted = _inverse_cable(cable, point, h + step)
            derivative = (shifted - forces[i]) / step
            jacobian[:, i] = np.concatenate([derivative, np.cross(arms[i], derivative)])[:rows] * scale
        # the change nearest the guess that cancels the imbalance to first order
        offset = tensions - guess
        correction = -offset + np.linalg.pinv(jacobian) @ (jacobian @ offset - total)
        tensions = tensions + correction
        if np.any(tensions <= 0.0):
            raise UnreachableError(f"pose {np.round(pose, 6).tolist()}: the catenaries balance the platform only if "
                                   f"a cable pushes (horizontal tensions {np.round(tensions, 3).tolist()} N): it is "
                                   "outside the wrench-feasible workspace")
    raise UnreachableError(f"pose {np.round(pose, 6).tolist()}: the catenaries' balance did not converge "
                           f"(imbalance {residual:.3g} N after {max_iterations} iterations)")
