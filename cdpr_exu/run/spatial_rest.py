"""The static mode of a spatial scene: the lumped robot at rest, beside its elastic catenaries.

:func:`solve_spatial_rest` solves the scene twice, by two independent methods:

* the **catenary statics** (:func:`cdpr_exu.statics.statics.solve_statics`):
  each cable a continuous elastic catenary in its own vertical plane, the platform's
  pose from the cables' unstrained lengths (no bending);
* the **lumped robot in Exudyn** (:mod:`cdpr_exu.builder.robot_3d`): the scene's
  chains with its effects (bending included), started on the catenary solution and
  brought to equilibrium by Exudyn's static solver (``mbs.SolveStatic``). Over swivel
  pulleys, where Exudyn's static solver does not converge from the catenary start, the
  chain statics (:mod:`cdpr_exu.statics.chain_statics`, the same discrete model)
  first take it to equilibrium (:func:`cdpr_exu.run.settle.start_at_rest`),
  and Exudyn's static solver confirms it.

and reports the lumped robot's pose (position, rotation vector and the rotation as
angles), its tensions and end forces, and how far the catenary answer lies from it
(the discretisation error, about n^-2, plus the effect of bending). A rigid platform's
cable ends are held by stiff penalty joints in the static solve (Exudyn's static
solver diverges on ``ObjectJointSpherical`` when the body must turn, see
:mod:`cdpr_exu.builder.robot_3d`); they add 1 / (:data:`PENALTY` n) of a cable's
compliance. The static solve uses spring elements also where the scene's cables are
tension-only (``effects.slack``): a slack element has no stiffness, and Exudyn's static
solver fails from such a start; while every element is taut the two give the same
equilibrium, and a compressed element is reported. Units SI; z up, gravity along -z.
"""

from __future__ import annotations

import math
import time as _time
from dataclasses import dataclass
from pathlib import Path

import exudyn as exu
import numpy as np

from cdpr_exu.core.errors import SolverFailure
from cdpr_exu.core.geometry import rotation_angles_deg
from cdpr_exu.core.output import write_summary
from cdpr_exu.builder.robot_3d import build_spatial_robot, chain_positions, element_forces, scene_chain_spec, swivel_angles
from cdpr_exu.run.settle import solve_static, start_at_rest
from cdpr_exu.statics.statics import catenary_platform, solve_statics
from cdpr_exu.results.result import provenance
from cdpr_exu.scenes.scene import Scene

__all__ = ["SpatialRest", "solve_spatial_rest", "PENALTY"]

#: Stiffness of the penalty spherical joints of a rigid platform, in element axial
#: stiffnesses: they add 1 / (100 n) of a cable's compliance (3e-7 m at n = 40 on the
#: four-cable robot, measured in tests/test_spatial_robot.py).
PENALTY = 100.0

#: A static answer farther than this fraction of the shortest cable's unstrained length from
#: its own elastic-catenary answer is flagged (``warnings`` in the summary, and on the console).
#: The two differ by the discretisation (n^-2: at most 0.5 mm on the shipped point-exit
#: robots) and by the bending the catenary leaves out: the shipped swivel robot, whose cables
#: wrap 0.1 m pulleys, rests 22 mm from its catenaries, 0.9 % of its 2.4 m cables (measured).
#: 5 % is over five times that; beyond it the answer is the bending model's more than a
#: hanging cable's (E = 1e10 Pa on the same robot: 132 mm, 5.5 %; 1e11 Pa: above its pulleys).
FAR_FROM_CATENARY = 0.05


@dataclass(frozen=True, eq=False)
class SpatialRest:
    """A spatial scene at rest: the lumped robot (Exudyn) and the catenary statics.

    Attributes
    ----------
    scene : Scene
    position : ndarray, shape (3,) [m]
        Platform centre of mass (lumped robot).
    rotation : ndarray, shape (3, 3)
        Platform frame to world frame.
    rotation_vector : ndarray, shape (3,) [rad]
    tensions_at_anchor : ndarray, shape (m,) [N]
    forces_on_platform : ndarray, shape (m, 3) [N]
        Force each cable exerts on the platform at its anchor.
    nodes : tuple of ndarray, each shape (n + 1, 3) [m]
        Node positions of each cable, exit first.
    catenary : PlatformEquilibrium
        The catenary statics of the same scene.
    element_tensions : tuple of ndarray, each shape (n,) [N]
        Axial force of each element, exit first (negative: compressed, which a real cable
        cannot be; the static solve uses spring elements, see the module notes).
    anchor_joint : str
        How the cable ends are held in the static solve.
    wall_time : float [s]
        Both solves together.
    """

    scene: Scene
    position: np.ndarray
    rotation: np.ndarray
    rotation_vector: np.ndarray
    tensions_at_anchor: np.ndarray
    forces_on_platform: np.ndarray
    nodes: tuple
    element_tensions: tuple
    catenary: object
    anchor_joint: str
    wall_time: float
    swivel_angles: np.ndarray | None = None

    @property
    def lowest_element_tension(self) -> float:
        """The lowest axial force of all elements [N] (negative: compressed)."""
        return float(min(t.min() for t in self.element_tensions))

    @property
    def catenary_distance(self) -> float:
        """Distance [m] from the lumped robot's platform position to its elastic catenaries' answer."""
        return float(np.linalg.norm(self.position - self.catenary.position))

    @property
    def warnings(self) -> list[str]:
        """What makes this answer suspect (empty: nothing): an answer far from the catenaries'
        (:data:`FAR_FROM_CATENARY`) and compressed elements, each with its figures."""
        found = []
        shortest = float(self.scene.unstrained_lengths.min())
        if self.catenary_distance > FAR_FROM_CATENARY * shortest:
            found.append(
                f"the lumped robot rests {1000 * self.catenary_distance:.0f} mm from its elastic catenaries' answer, "
                f"more than {100 * FAR_FROM_CATENARY:g} % of its shortest cable ({shortest:.4g} m); "
                + bending_text(self.scene, self.catenary, "what the catenary leaves out and moves it"))
        lowest = self.lowest_element_tension
        if lowest < 0.0:
            found.append(f"an element is compressed ({lowest:.3g} N), which a real cable cannot be (the static solve "
                         "uses spring elements): a cable is slack at rest (longer than the catenary the lumped model "
                         "can hang), or the cables' bending holds the platform up")
        return found

    def summary(self) -> dict:
        """Plain data for summary.json (SI units in the key names)."""
        catenary = self.catenary
        return {
            "scene": self.scene.name,
            "dimension": 3,
            "method": f"Exudyn static solver on the lumped robot ({self.scene.cables[0].n_elements} elements per "
                      f"cable, {self.anchor_joint}), started on the elastic-catenary statics"
                      + (" and, over swivel pulleys, on the chain statics' equilibrium from there"
                         if any(self.scene.swivel_exits) else ""),
            "platform_position_m": self.position.tolist(),
            "platform_rotation_vector_rad": self.rotation_vector.tolist(),
            "platform_roll_pitch_yaw_deg": rotation_angles_deg(self.rotation).tolist(),
            "platform_rotation_matrix": self.rotation.tolist(),
            "tension_at_anchor_N": self.tensions_at_anchor.tolist(),
            "force_on_platform_N": self.forces_on_platform.tolist(),
            "catenary_platform_position_m": catenary.position.tolist(),
            "catenary_platform_rotation_vector_rad": catenary.rotation.tolist(),
            "catenary_tension_at_anchor_N": catenary.tensions_at_anchor.tolist(),
            "min_element_tension_N": self.lowest_element_tension,
            "elements_pushed": self.lowest_element_tension < 0.0,
            "lumped_minus_catenary_position_m": self.catenary_distance,
            "lumped_minus_catenary_rotation_rad": float(np.linalg.norm(self.rotation_vector - catenary.rotation)),
            "wall_time_s": self.wall_time,
            **({} if self.swivel_angles is None else {
                "swivel_angle_rad": [None if np.isnan(a) else float(a) for a in self.swivel_angles],
                "catenary_wrap_angle_rad": [float(c.wrap_angle) for c in catenary.cables]}),
            "warnings": self.warnings,
            **provenance(),
        }

    def save(self, out: str | Path) -> list[Path]:
        """Write summary.json to the folder ``out``; returns its path in a list. The figure
        (``rest_profile.png``) is :func:`cdpr_exu.post.plots.plot_spatial_rest`'s."""
        out = Path(out)
        out.mkdir(parents=True, exist_ok=True)
        return [write_summary(out, self.summary())]


def bending_text(scene: Scene, catenary, what: str) -> str:
    """The cables' bending against their pulleys, for messages: ``what`` (e.g. "what moves it") is
    the bending E J [N m^2] whose bending length sqrt(E J / T) at the catenaries' largest tension T
    is compared with the smallest swivel radius (or the shortest cable: point exits)."""
    cable = scene.cables[0]
    if not scene.effects.bending:
        return "the cables have no bending (effects.bending = false)"
    stiffness = cable.youngs_modulus * cable.second_moment
    tension = float(np.max(catenary.tensions_at_anchor))
    length = math.sqrt(stiffness / tension) if tension > 0.0 else math.inf
    radii = scene.pulley_radii[scene.pulley_radii > 0.0]
    scale, name = ((float(radii.min()), "the pulleys' radius") if radii.size
                   else (float(scene.unstrained_lengths.min()), "the shortest cable"))
    return (f"{what} is the cables' bending: E J = {stiffness:.3g} N m^2 (cables[0].youngs_modulus = "
            f"{cable.youngs_modulus:.3g} Pa on the solid section pi r^4 / 4) has a bending length sqrt(E J / T) = "
            f"{length:.3g} m at the catenaries' tension T = {tension:.4g} N, {length / scale:.2g} times {name} "
            f"({scale:.4g} m)")


def rest_above_exits(scene: Scene, position, rotation, lowest_tension: float, catenary) -> str | None:
    """Why a rest of the lumped robot with every anchor above its exit is no cable robot's rest, or None.

    Such a rest is held by elements that push or by the cables' bending, not by hanging cables
    (:meth:`Scene.above_exits`): cables whose bending length sqrt(E J / T) is many
    times their pulleys' radius stand up like rods rather than wrap their pulleys (measured on
    the swivel robot: E = 1e11 Pa, 16.8 kg: 6.9 times, platform 0.14 m above the inlets).

    Parameters
    ----------
    position : (3,) [m]; rotation : (3, 3)
        The platform's pose at that rest.
    lowest_tension : float [N]
        The lowest element force there (negative: compressed).
    catenary : PlatformEquilibrium
        The scene's elastic-catenary statics.
    """
    above = scene.above_exits(position, rotation)
    if above is None:
        return None
    return (f"the lumped robot's equilibrium holds the platform at z = {float(position[2]):.4g} m (its elastic "
            f"catenaries hang it at z = {float(catenary.position[2]):.4g} m, {1000 * float(np.linalg.norm(np.asarray(position) - catenary.position)):.0f} mm away) and {above}; "
            + bending_text(scene, catenary, "what holds it up")
            + f", and its lowest element force is {lowest_tension:.3g} N. Give the cables a smaller "
            "youngs_modulus or radius (a wire rope bends far more easily than a solid rod of its modulus)")


def solve_spatial_rest(scene: Scene) -> SpatialRest:
    """Bring a spatial scene to rest: catenary statics, then Exudyn's static solve of the lumped robot.

    The answer's :attr:`SpatialRest.warnings` say what makes it suspect (far from the catenaries,
    compressed elements); an equilibrium with the platform above its exits is refused.

    Raises
    ------
    UnreachableError
        If the catenary statics find no equilibrium (cables that cannot hold the platform).
    SolverFailure
        If Exudyn's static solver does not converge, or its equilibrium holds the platform above
        its exits (:func:`rest_above_exits` gives the cause); ``partial_result`` is then the
        rest's summary.
    """
    start = _time.perf_counter()
    platform = catenary_platform(scene)
    lengths = scene.unstrained_lengths
    catenary = solve_statics(platform, lengths)
    rigid = not platform.is_point_mass
    chain = scene_chain_spec(scene, anchor_spring_factor=PENALTY if rigid else None, tension_only=False)
    mbs = exu.SystemContainer().AddSystem()
    items = build_spatial_robot(mbs, platform, lengths, chain, initial=catenary, swivels=scene.swivel_exits)
    mbs.Assemble()
    if any(scene.swivel_exits):
        start_at_rest(mbs, items)  # Exudyn's static solver does not converge from the catenary start over a swivel pulley
    static = solve_static(mbs, items)
    nodes = tuple(chain_positions(mbs, items, i) for i in range(scene.n_cables))
    tensions = tuple(element_forces(mbs, items, i) for i in range(scene.n_cables))
    joint = f"penalty spherical joints of {PENALTY:g} element stiffnesses" if rigid else "exact spherical joints"
    rest = SpatialRest(scene, static.position, static.rotation, static.rotation_vector, static.tensions_at_anchor,
                       static.forces_on_platform, nodes, tensions, catenary, joint, _time.perf_counter() - start,
                       swivel_angles(mbs, items) if any(scene.swivel_exits) else None)
    above = rest_above_exits(scene, rest.position, rest.rotation, rest.lowest_element_tension, catenary)
    if above is not None:
        raise SolverFailure(f"no rest of a cable robot: {above}", partial_result=rest.summary())
    return rest
