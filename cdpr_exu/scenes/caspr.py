"""Robots from CASPR's model files: a spatial scene from a bodies and a cables XML file (``cdpr import caspr``).

CASPR (the cable robot toolbox, github.com/darwinlau/CASPR, ``data/model_config/models/``)
describes a robot by a bodies file (``<bodies_system>``: the links, each with its joint,
``q_initial``, mass, ``com_location`` and inertia) and a cables file (``<cables>``: cable sets,
each cable with its model, ``force_min`` / ``force_max`` and its attachments, link 0 the base
frame, link 1 the platform). :func:`caspr_scene` reads the two (``xml.etree``) and makes a
:class:`~cdpr_exu.scenes.scene.Scene`:

* exits: the link-0 attachments, point exits in CASPR's base frame (z up);
* anchors from the centre of mass: CASPR's link-1 attachments less ``com_location`` where
  ``attachment_reference = "joint"`` (from the platform's reference point), as given for ``"com"``;
* platform: the mass; the inertia about the centre of mass in platform axes (moved there from
  the joint with the parallel-axis rule for ``inertia ref="joint"``), its diagonal: a scene holds
  the moments about the platform axes, so products of inertia are left out (the header says so);
* cables: ``min_tension`` / ``max_tension`` from ``force_min`` / ``force_max``; the material and
  element count of the shipped ``spatial-cogiro`` unless given; each unstrained length the ideal
  straight length at the initial pose less its stretch under the tension distribution within the
  limits (:func:`~cdpr_exu.statics.tension_distribution.tensions`), so that sag alone moves the rest;
* the initial pose (``q_initial``: the reference point plus XYZ Euler angles, ``R = Rx Ry Rz``,
  moved to the centre of mass) held by a ``hold`` trajectory; effects, winch and solver as
  ``spatial-cogiro``.

Refused with the file, the element and the attribute named (SceneError), before anything is
written: a file that is missing or is not CASPR's XML, more than one link, a joint other than
``SPATIAL_EULER_XYZ``, a cable model other than ``cable_ideal``, a cable routed through more than
two attachments, a missing or non-numeric value. Units SI.
"""

from __future__ import annotations

from dataclasses import replace
from pathlib import Path
from xml.etree import ElementTree

import numpy as np
from scipy.spatial.transform import Rotation

from cdpr_exu.core.errors import SceneError
from cdpr_exu.core.validation import shown
from cdpr_exu.exits import PointExit
from cdpr_exu.scenes.scene import PlatformSpec, Scene, load_scene
from cdpr_exu.scenes.trajectories import HoldTrajectory
from cdpr_exu.space import SPACE
from cdpr_exu.statics.kinematics import ideal_paid_out
from cdpr_exu.statics.tension_distribution import tensions

__all__ = ["MATERIAL_FROM", "caspr_scene"]

#: The shipped scene whose cable material, element count, effects, winch and solver an imported robot takes.
MATERIAL_FROM = "spatial-cogiro"


def _root(path: str | Path, tag: str) -> ElementTree.Element:
    """The root element of a CASPR file, which must be ``<tag>``."""
    try:
        root = ElementTree.parse(path).getroot()
    except OSError as err:
        raise SceneError(f"{path}: cannot read the file: {err.strerror or err}") from None
    except ElementTree.ParseError as err:
        raise SceneError(f"{path} is not XML ({err}), so not a CASPR model file") from None
    if root.tag != tag:
        raise SceneError(f"{path} is not a CASPR {tag} file: its root element is <{root.tag}>, CASPR's is <{tag}>")
    return root


def _numbers(text: str | None, where: str, count: int) -> np.ndarray:
    """``count`` numbers from an element's text or an attribute, or SceneError naming ``where``."""
    try:
        values = np.array((text or "").split(), dtype=float)
    except ValueError:
        values = np.zeros(0)
    if values.shape != (count,) or not np.all(np.isfinite(values)):
        raise SceneError(f"{where} must give {count} finite number(s), got {shown(text)}")
    return values


def _child(element: ElementTree.Element, tag: str, where: str) -> ElementTree.Element:
    found = element.find(tag)
    if found is None:
        raise SceneError(f"{where} has no <{tag}>")
    return found


def _platform(path) -> tuple[str, dict, np.ndarray, tuple, list[str]]:
    """The link's name, mass, inertia and centre of mass, and its reference point's initial pose, from a bodies file.

    Returns (name, platform fields but anchors, ``com_location`` (3,) [m], pose of the reference point
    (position (3,) [m], rotation matrix (3, 3)), notes for the header).
    """
    links = _child(_root(path, "bodies_system"), "links", f"{path}: <bodies_system>")
    if len(links) != 1 or links[0].tag != "link_rigid":
        raise SceneError(f"{path}: <links> holds {[link.tag for link in links]}: a scene has one rigid platform, "
                         "CASPR's multi-link bodies cannot be expressed")
    link, where = links[0], f"{path}: <link_rigid name={shown(links[0].get('name'))}>"
    joint = _child(link, "joint", where)
    if joint.get("type") != "SPATIAL_EULER_XYZ":
        raise SceneError(f"{where}: <joint type={shown(joint.get('type'))}> cannot be expressed: a scene's platform "
                         "moves freely in space (CASPR's SPATIAL_EULER_XYZ)")
    q = _numbers(joint.get("q_initial"), f"{where}: <joint q_initial>", 6)
    physical = _child(link, "physical", where)
    mass = _numbers(_child(physical, "mass", where).text, f"{where}: <mass>", 1)[0]
    com = _numbers(_child(physical, "com_location", where).text, f"{where}: <com_location>", 3)
    inertia_element = _child(physical, "inertia", where)
    value = {name: _numbers(_child(inertia_element, name, where).text, f"{where}: <inertia><{name}>", 1)[0]
             for name in ("Ixx", "Iyy", "Izz", "Ixy", "Ixz", "Iyz")}
    inertia = np.array([[value["I" + "".join(sorted(a + b))] for b in "xyz"] for a in "xyz"])
    if inertia_element.get("ref") == "joint":  # parallel-axis rule: about the centre of mass
        inertia = inertia - mass * (com @ com * np.eye(3) - np.outer(com, com))
    elif inertia_element.get("ref") != "com":
        raise SceneError(f"{where}: <inertia ref={shown(inertia_element.get('ref'))}> must be 'com' or 'joint'")
    origin = _numbers(_child(_child(link, "parent", where), "location", where).text, f"{where}: <parent><location>", 3)
    products = inertia[np.triu_indices(3, 1)]
    notes = [(f"products of inertia about the centre of mass {np.round(products, 6).tolist()} kg m^2 left out "
              "(a scene holds the moments about the platform axes)")] if np.any(products) else []
    platform = {"mass": float(mass), "inertia": tuple(np.diag(inertia).tolist())}
    return link.get("name"), platform, com, (origin + q[:3], Rotation.from_euler("XYZ", q[3:]).as_matrix()), notes


def _cables(path, cable_set: str | None) -> tuple[list, list, list]:
    """Each cable's exit (3,) [m], anchor from the reference point or the centre of mass (3,) [m] with
    its ``attachment_reference``, and (force_min, force_max) [N], from a cables file."""
    root = _root(path, "cables")
    chosen = cable_set or root.get("default_cable_set")
    sets = {element.get("id"): element for element in root.findall("cable_set")}
    if chosen not in sets:
        raise SceneError(f"{path}: no <cable_set id={shown(chosen)}>; it has {sorted(map(str, sets))}")
    exits, anchors, limits = [], [], []
    for cable in sets[chosen]:
        where = f"{path}: <cable_set id={shown(chosen)}> <{cable.tag} name={shown(cable.get('name'))}>"
        if cable.tag != "cable_ideal":
            raise SceneError(f"{where}: CASPR's cable model {cable.tag} cannot be expressed; only cable_ideal "
                             "(a scene's cables bring their own elasticity and mass)")
        attachments = _child(cable, "attachments", where).findall("attachment")
        links = [(_child(a, "link", where).text or "").strip() for a in attachments]
        if sorted(links) != ["0", "1"]:
            raise SceneError(f"{where}: <attachments> on links {links}: a scene's cable runs from one exit (link 0) "
                             "to one anchor (link 1); routing through more attachments cannot be expressed")
        point = {link: _numbers(_child(a, "location", where).text, f"{where}: <attachment><location>", 3)
                 for link, a in zip(links, attachments)}
        reference = cable.get("attachment_reference", "joint")
        if reference not in ("joint", "com"):
            raise SceneError(f"{where}: attachment_reference={shown(reference)} must be 'joint' or 'com'")
        properties = _child(cable, "properties", where)
        exits.append(point["0"])
        anchors.append((point["1"], reference))
        limits.append(tuple(_numbers(_child(properties, name, where).text, f"{where}: <{name}>", 1)[0]
                            for name in ("force_min", "force_max")))
    if not exits:
        raise SceneError(f"{path}: <cable_set id={shown(chosen)}> holds no cable")
    return exits, anchors, limits


def caspr_scene(bodies: str | Path, cables: str | Path, *, cable_set: str | None = None, name: str | None = None,
                **material) -> tuple[Scene, list[str]]:
    """The scene of the robot CASPR's ``bodies`` and ``cables`` files describe (module notes).

    Parameters
    ----------
    bodies, cables : path
        CASPR's ``<name>_bodies.xml`` and ``<name>_cables.xml``.
    cable_set : str, optional
        The ``<cable_set id>`` to read (default the file's ``default_cable_set``).
    name : str, optional
        The scene's name (default the link's name).
    **material
        CableSpec fields shared by every cable (``radius`` [m], ``linear_density`` [kg/m],
        ``youngs_modulus`` [Pa], ``damping_constant`` [N s/m^2], ``n_elements``); the rest as
        :data:`MATERIAL_FROM`.

    Returns
    -------
    scene : Scene
    notes : list of str
        What the conversion left out or chose, for the scene file's header.

    Raises
    ------
    SceneError
        Naming the file, element and attribute CASPR gives that a scene cannot express (module notes).
    UnreachableError
        When no tensions within the limits hold the platform at its initial pose.
    """
    link_name, platform, com, (origin, turn), notes = _platform(bodies)
    exits, anchors, limits = _cables(cables, cable_set)
    base = load_scene(MATERIAL_FROM)
    cable = replace(base.cables[0], **material)
    pose = np.round(np.concatenate([origin + turn @ com, Rotation.from_matrix(turn).as_rotvec()]), 12)
    scene = base.with_changes(
        name=name or link_name or Path(bodies).stem,
        description=f"imported from CASPR's {Path(bodies).name} and {Path(cables).name}",
        exits=tuple(PointExit(tuple(point)) for point in exits),
        cables=tuple(replace(cable, min_tension=low, max_tension=high) for low, high in limits),
        platform=PlatformSpec(**platform, anchors=tuple(tuple(np.round(a - com if ref == "joint" else a, 12))
                                                          for a, ref in anchors)),
        trajectory=HoldTrajectory(tuple(pose), space=SPACE))
    ideal, _ = ideal_paid_out(scene, pose)
    held = tensions(scene, pose)
    stretched = ideal / (1.0 + held / np.array([c.axial_rigidity for c in scene.cables]))
    scene = scene.with_changes(cables=tuple(replace(c, unstrained_length=float(length))
                                            for c, length in zip(scene.cables, np.round(stretched, 5))))
    return scene, [(f"initial pose (centre of mass, rotation vector) {np.round(pose, 6).tolist()} [m, rad]; unstrained "
                    f"lengths: the ideal ones there less the stretch of tensions {np.round(held, 1).tolist()} N"), *notes]
