"""Mechanical energy of a lumped-mass run, from its Result: the check of conservation.

With all damping off the total must stay constant to the integrator's accuracy;
with damping on, and no work put in by the winches, it must never rise. Units: J.
"""

from __future__ import annotations

from dataclasses import dataclass

import numpy as np

from cdpr_exu.physics.bending import bending_energy, cable_joints
from cdpr_exu.core.errors import SceneError
from cdpr_exu.core.geometry import penetration
from cdpr_exu.results.result import Result
from cdpr_exu.scenes.scene import Scene


@dataclass(frozen=True)
class EnergyParts:
    """The energies of a run at each output time, each shape (N,) [J]: ``kinetic`` (nodes, platform
    translation and rotation), ``gravitational`` (m g z), ``axial`` (k_i (l - l0i)^2 / 2 per element, only
    l > l0i for slack elements), ``bending`` (k_theta dtheta^2 / 2 per interior node), ``contact``
    (k_p d^2 / 2 per node at penetration depth d); zero where the effect is off."""

    kinetic: np.ndarray
    gravitational: np.ndarray
    axial: np.ndarray
    bending: np.ndarray
    contact: np.ndarray

    @property
    def total(self) -> np.ndarray:
        """Total mechanical energy, shape (N,) [J]."""
        return self.kinetic + self.gravitational + self.axial + self.bending + self.contact


def energy_parts(scene: Scene, result: Result) -> EnergyParts:
    """The energies of ``result`` (a planar run of ``scene``) at each output time; SceneError for massless
    cables, whose rope points carry no mass or stretch of their own."""
    if not scene.effects.cable_mass:
        raise SceneError("energy_parts needs lumped-mass cables (effects.cable_mass = true)")
    g = scene.gravity if scene.effects.gravity else 0.0
    platform = scene.platform
    velocity = result.velocity
    kinetic = 0.5 * platform.mass * np.sum(velocity[:, :2] ** 2, axis=1) + 0.5 * platform.inertia * velocity[:, 2] ** 2
    gravitational = platform.mass * g * result.pose[:, 1]
    axial = np.zeros_like(kinetic)
    bending = np.zeros_like(kinetic)
    contact = np.zeros_like(kinetic)
    with_contact = scene.pulley_contact
    for cable, pulley, nodes, node_velocities in zip(scene.cables, scene.exits, result.nodes,
                                                     result.node_velocities):
        masses = cable.node_masses()
        kinetic = kinetic + 0.5 * np.einsum("j,tjk,tjk->t", masses, node_velocities, node_velocities)
        gravitational = gravitational + g * nodes[:, :, 1] @ masses
        stretch = np.linalg.norm(np.diff(nodes, axis=1), axis=-1) - cable.element_length
        if scene.effects.slack:  # tension-only: no energy stored in a slack element
            stretch = np.maximum(stretch, 0.0)
        axial = axial + 0.5 * cable.axial_stiffness * np.sum(stretch**2, axis=1)
        if scene.effects.bending:
            joints = cable_joints([cable.n_elements + 1])
            bending = bending + np.array([bending_energy(x.ravel(), joints, cable.bending_stiffness) for x in nodes])
        if with_contact:
            contact = contact + 0.5 * pulley.contact_stiffness * np.sum(penetration(pulley, nodes) ** 2, axis=1)
    return EnergyParts(kinetic, gravitational, axial, bending, contact)


def mechanical_energy(scene: Scene, result: Result) -> np.ndarray:
    """Total mechanical energy of ``result`` at each output time, shape (N,) [J]."""
    return energy_parts(scene, result).total


def energy_rise(energy: np.ndarray) -> float:
    """Largest increase of ``energy`` over any earlier sample [J] (0 if it never rises)."""
    return float(np.max(energy - np.minimum.accumulate(energy))) if len(energy) else 0.0
