"""Spatial scenes: a 3-D cable robot declared in TOML, validated once (issue 15).

A spatial scene says ``dimension = 3`` at its top. Its cables use the planar scenes'
``[cable]`` / ``[[cables]]`` tables (material, unstrained length, elements: they do not
depend on the dimension); each cable leaves the frame at an exit given in ``[[exits]]``:
a fixed exit point (``point = [x, y, z]``, the default ``kind = "point"``) or a swivel
pulley (``kind = "swivel"``, :class:`SwivelSpec`: its inlet, radius, contact and swivel
bearing; the winch side runs down its vertical axis); the platform is a point mass
(every anchor at its centre of mass) or a rigid 6-DOF body. Frame: z up, gravity along
-z, SI units. Example (the shipped ``spatial-four-cable``)::

    name = "spatial-four-cable"
    dimension = 3
    [cable]
    radius = 0.005
    ...
    [[cables]]
    unstrained_length = 2.40
    [[exits]]
    point = [1.5, 1.5, 0.0]
    [platform]
    mass = 5.0
    inertia = [0.05, 0.05, 0.08]       # principal moments about the centre of mass
    anchors = [[0.1, 0.1, 0.05], ...]  # platform frame

``cdpr static`` brings a spatial scene to rest (:mod:`cdpr_exu.run.spatial_rest`); ``cdpr run``
follows its ``[trajectory]`` (a 6-DOF reference, :mod:`cdpr_exu.scenes.spatial_trajectories`) with
``[winch] kind = "kinematic"`` winches under ideal inverse kinematics, with its ``[solver]``
settings (:mod:`cdpr_exu.run.spatial_run`). The other commands refuse spatial scenes with a
message that says so.
"""

from __future__ import annotations

import math
from dataclasses import dataclass, field, replace
from importlib import resources
from pathlib import Path
from typing import Any, ClassVar, Mapping

import numpy as np

from cdpr_exu.physics.catenary import STANDARD_GRAVITY
from cdpr_exu.core.errors import SceneError
from cdpr_exu.core.geometry import above_exits
from cdpr_exu.physics.spatial_statics import SpatialCable, SpatialPlatform
from cdpr_exu.scenes.scene import (MAX_ELEMENTS, CableSpec, ControllerModel, Effects, Scene, SolverSpec,
                                  SpatialSceneError, WinchSpec, _build, _override, _per_cable, check_weight,
                                  controller_model_from_dict, is_scene_file, load_scene, missing_fields,
                                  parse_scene_text, read_scene_file, refuse_missing, shipped_names, unknown_scene)
from cdpr_exu.core.validation import non_negative, positive, shown, vector

__all__ = ["SpatialPlatformSpec", "SwivelSpec", "SpatialScene", "spatial_scene_from_dict", "load_spatial_scene",
           "shipped_spatial_scenes", "is_spatial", "load_any_scene", "any_scene_from_dict", "save_any_scene"]

#: Where the shipped spatial scenes live, inside the package's ``scenes`` folder.
SPATIAL_FOLDER = "spatial"


@dataclass(frozen=True)
class SpatialPlatformSpec:
    """The platform of a spatial robot: a point mass, or a rigid body when an anchor is off its centre.

    Parameters
    ----------
    mass : float [kg]
    inertia : (float, float, float) or None [kg m^2]
        Principal moments of inertia about the centre of mass, along the platform axes
        (positive for a rigid platform). None (not given): zero for a point mass; refused
        for a rigid platform, whose turning it decides.
    anchors : sequence of (x, y, z) [m]
        Cable anchor points in the platform frame (centre of mass at 0), one per cable.
    """

    mass: float = 1.0
    inertia: tuple | None = None
    anchors: tuple = ()

    def __post_init__(self) -> None:
        object.__setattr__(self, "mass", non_negative("platform.mass", self.mass, "kg"))
        if isinstance(self.anchors, (str, bytes, Mapping)) or not isinstance(self.anchors, (list, tuple, np.ndarray)):
            raise SceneError(f"platform.anchors must be a list of (x, y, z) points, got {shown(self.anchors)}")
        anchors = tuple(tuple(float(v) for v in vector(f"platform.anchors[{i}]", a, 3, " (x, y, z) [m]"))
                        for i, a in enumerate(self.anchors))
        object.__setattr__(self, "anchors", anchors)
        if self.inertia is None:
            if not self.is_point_mass:
                refuse_missing(missing_fields("platform", {}, ("inertia",)))
            object.__setattr__(self, "inertia", (0.0, 0.0, 0.0))
        inertia = vector("platform.inertia", self.inertia, 3, " (principal moments) [kg m^2]")
        if np.any(inertia < 0.0):
            raise SceneError(f"platform.inertia must be zero or positive, got {shown(self.inertia)}")
        object.__setattr__(self, "inertia", tuple(float(v) for v in inertia))
        if not self.is_point_mass and (self.mass <= 0.0 or min(self.inertia) <= 0.0):
            raise SceneError(f"a rigid platform (an anchor off its centre of mass) needs platform.mass > 0 and "
                             f"every platform.inertia > 0, got mass {shown(self.mass)}, inertia {shown(self.inertia)}")

    @property
    def is_point_mass(self) -> bool:
        """True when every anchor is at the centre of mass."""
        return all(a == (0.0, 0.0, 0.0) for a in self.anchors)


@dataclass(frozen=True)
class SwivelSpec:
    """A swivel-pulley exit of a spatial scene (``[[exits]]`` with ``kind = "swivel"``).

    The pulley turns about the vertical axis through its inlet; the cable comes up that
    axis from its winch, wraps over the disc and leaves it towards the anchor
    (:mod:`cdpr_exu.physics.swivel_pulley`, :mod:`cdpr_exu.physics.spatial_kinematics`).
    The cable's ``unstrained_length`` counts from the inlet to the anchor, the wrap
    included: the paid-out length of the ideal kinematics.

    Parameters
    ----------
    inlet : (x, y, z) [m]
        Where the cable leaves the swivel axis onto the disc (the disc's centre is
        ``radius`` from the axis, at the inlet's height).
    radius : float [m]
        Groove-bottom radius r_p of the disc.
    contact_stiffness : float [N/m]
        Penalty stiffness k_p of the node-on-disc contact.
    contact_damping : float [N s/m]
        Damping on the penetration rate (0: none).
    swivel_inertia : float [kg m^2]
        J_s of the turning part about the axis.
    bearing_damping : float [N m s]
        Viscous torque d_s psi_dot of the swivel bearing.
    groove_radius, flange_height : float [m]
        The groove's sideways curvature radius and the height of its flanks.
    winch_line : float [m]
        Unstrained cable between the winch end (held on the axis below the inlet) and
        the inlet at the start; the winch can pay out at most this much less a
        margin of two elements during a run.
    """

    inlet: tuple = (0.0, 0.0, 0.0)
    radius: float = 0.1
    contact_stiffness: float = 1.0e6
    contact_damping: float = 0.0
    swivel_inertia: float = 1.0e-2
    bearing_damping: float = 1.0e-3
    groove_radius: float = 0.01
    flange_height: float = 0.01
    winch_line: float = 0.3

    def __post_init__(self) -> None:
        object.__setattr__(self, "winch_line", positive("swivel.winch_line", self.winch_line, "m"))
        pulley = self.pulley()  # refuses bad fields, naming them swivel.<field>
        for name in ("inlet", "radius", "contact_stiffness", "contact_damping", "swivel_inertia", "bearing_damping",
                     "groove_radius", "flange_height"):
            object.__setattr__(self, name, getattr(pulley, name))

    def pulley(self):
        """The physics' :class:`cdpr_exu.physics.swivel_pulley.SwivelPulley` of this exit."""
        from cdpr_exu.physics.swivel_pulley import SwivelPulley

        return SwivelPulley(inlet=self.inlet, radius=self.radius, groove_radius=self.groove_radius,
                            flange_height=self.flange_height, contact_stiffness=self.contact_stiffness,
                            contact_damping=self.contact_damping, swivel_inertia=self.swivel_inertia,
                            bearing_damping=self.bearing_damping)

    def to_dict(self) -> dict[str, Any]:
        """The ``[[exits]]`` table of this exit."""
        import dataclasses

        data = {"kind": "swivel", **dataclasses.asdict(self)}
        data["inlet"] = list(self.inlet)
        return data


def _exit_from_dict(entry: Any, index: int):
    """One ``[[exits]]`` table: a point (3-tuple) or a :class:`SwivelSpec`."""
    path = f"exits[{index}]"
    if not isinstance(entry, Mapping):
        raise SceneError(f"{path} must be a table, got {shown(entry)}")
    entry = dict(entry)
    kind = entry.pop("kind", "point")
    if kind == "point":
        if set(entry) != {"point"}:
            raise SceneError(f"{path}: a point exit has one field 'point' = [x, y, z] (and kind = 'point'), "
                             f"got {sorted(entry)}")
        return entry["point"]
    if kind == "swivel":
        return _build(SwivelSpec, entry, path)
    raise SceneError(f"{path}.kind must be 'point' or 'swivel', got {shown(kind)}")


@dataclass(frozen=True)
class SpatialScene:
    """A spatial cable robot: cables from fixed exit points to a platform, z up, SI units.

    Parameters
    ----------
    name, description : str
    cables : tuple of CableSpec
        Material, unstrained length [m] and elements of each cable (as in planar scenes).
    exits : tuple of (x, y, z) [m]
        Where each cable leaves the frame, world frame: the exit point of a point exit,
        the inlet of a swivel pulley.
    swivels : tuple of (SwivelSpec or None)
        Each cable's swivel pulley (None: a point exit); empty: point exits only. A
        swivel's inlet is its cable's exit (give either, or both equal).
    platform : SpatialPlatformSpec
    gravity : float [m/s^2]
        Along -z.
    effects : Effects
        Which physics the lumped model includes: cable mass and gravity, axial elasticity
        and damping, bending, tension-only elements (``slack``: the cables cannot push,
        :mod:`cdpr_exu.physics.axial_3d`); point exits have no pulley contact.
    trajectory : spatial trajectory or None
        The reference of ``cdpr run`` (:mod:`cdpr_exu.scenes.spatial_trajectories`); None: the
        scene has a static mode only.
    solver : SolverSpec
        The implicit integration of ``cdpr run`` (as in planar scenes).
    winch : WinchSpec
        ``kind = "kinematic"`` (the winches pay out what the controller commands) or
        ``"fixed"``; servo drums are planar only so far.
    controller_model : ControllerModel or None
        What the controllers believe of the robot where it differs from the plant
        (``[controller_model]``, as in planar scenes: overrides of ``cable``, ``cables``,
        ``platform`` (mass, inertia, anchors) and ``gravity``; a spatial scene has exits,
        not pulleys). The controllers get :meth:`controller_scene`.

    Raises
    ------
    SceneError
        Naming the field: counts that do not match, two cables on one exit point,
        effects the spatial model does not have, cables that differ in elements,
        damping or bending (one chain description serves all cables so far).
    """

    name: str = "spatial-scene"
    description: str = ""
    cables: tuple = ()
    exits: tuple = ()
    swivels: tuple = ()
    platform: SpatialPlatformSpec = field(default_factory=SpatialPlatformSpec)
    gravity: float = STANDARD_GRAVITY
    effects: Effects = field(default_factory=lambda: Effects.from_preset("full"))
    trajectory: Any = None
    solver: SolverSpec = field(default_factory=SolverSpec)
    winch: WinchSpec = field(default_factory=WinchSpec)
    controller_model: ControllerModel | None = None

    #: Spatial scenes are 3-D; planar :class:`~cdpr_exu.scenes.scene.Scene` objects have no such attribute.
    dimension: ClassVar[int] = 3

    def __post_init__(self) -> None:
        if not self.cables or not all(isinstance(c, CableSpec) for c in self.cables):
            raise SceneError(f"cables must be a non-empty list of cable tables, got {shown(self.cables)}")
        object.__setattr__(self, "cables", tuple(self.cables))
        self._set_swivels()
        exits = tuple(tuple(float(v) for v in vector(f"exits[{i}].point", e, 3, " (x, y, z) [m]"))
                      for i, e in enumerate(self.exits))
        object.__setattr__(self, "exits", exits)
        object.__setattr__(self, "gravity", non_negative("gravity", self.gravity, "m/s^2"))
        check_weight(self.platform.mass, self.gravity)
        m = len(self.cables)
        if len(exits) != m:
            raise SceneError(f"exits must give one exit point per cable ({m}), got {len(exits)}")
        if len(self.platform.anchors) != m:
            raise SceneError(f"platform.anchors must give one anchor per cable ({m}), got {len(self.platform.anchors)}")
        if not isinstance(self.effects, Effects):
            raise SceneError(f"effects must be an effects table, got {shown(self.effects)}")
        if not (self.effects.cable_mass and self.effects.axial_elasticity):
            raise SceneError(f"effects.preset = {shown(self.effects.preset)}: a spatial scene needs lumped, elastic cables "
                             "(effects.cable_mass and effects.axial_elasticity); use the 'full' or 'catenary' preset")
        first = self.cables[0]
        for i, cable in enumerate(self.cables[1:], start=1):
            for name in ("n_elements", "radius", "youngs_modulus", "damping_constant", "mass_lumping"):
                if getattr(cable, name) != getattr(first, name):
                    raise SceneError(f"cables[{i}].{name} = {shown(getattr(cable, name))} differs from cables[0].{name} = "
                                     f"{shown(getattr(first, name))}: the cables of a spatial scene share one "
                                     "discretisation, damping and bending so far")
        self.catenary_platform()  # refuses coincident exits, too few cables, anchors on one line
        if self.winch.kind == "servo":
            raise SceneError("winch.kind = 'servo': servo drums are planar only so far; use 'kinematic' or 'fixed'")
        if not isinstance(self.solver, SolverSpec) or self.solver.integrator != "generalized_alpha":
            raise SceneError("solver.integrator must be 'generalized_alpha' for a spatial scene")
        if self.controller_model is not None:
            if not isinstance(self.controller_model, ControllerModel):
                raise SceneError(f"controller_model must be a controller-model table, got {shown(self.controller_model)}")
            if self.controller_model.pulley or self.controller_model.pulleys:
                raise SceneError("controller_model.pulley / controller_model.pulleys: a spatial scene has exits, "
                                 "not pulleys; its controller model overrides cable, cables, platform and gravity")
            if self.controller_model.is_empty():
                object.__setattr__(self, "controller_model", None)
            else:
                self.controller_scene()  # refuses a model that is not a valid robot, naming the field

    def controller_scene(self) -> "SpatialScene":
        """The robot the controllers believe in: this scene with its controller model applied.

        Without a controller model, the scene itself. The trajectory, solver settings,
        effects and exits are the plant's.

        Raises
        ------
        SceneError
            If an override is invalid or the per-cable list does not match the cables.
        """
        model = self.controller_model
        if model is None:
            return self
        m = self.n_cables
        if model.cables and len(model.cables) != m:
            raise SceneError(f"controller_model.cables must list one table per cable ({m}), got {len(model.cables)}")
        cables = tuple(_override(c, {**model.cable, **(model.cables[i] if model.cables else {})}, f"cables[{i}]",
                                 "cable") for i, c in enumerate(self.cables))
        platform = _override(self.platform, model.platform, "platform", "platform")
        gravity = self.gravity if model.gravity is None else model.gravity
        try:
            return replace(self, cables=cables, platform=platform, gravity=gravity, controller_model=None)
        except SceneError as err:
            raise SceneError(f"controller_model: the controllers' model is not a valid robot: {err}") from None

    def _set_swivels(self) -> None:
        """Normalise ``swivels`` to one entry per cable; a swivel's inlet is its cable's exit."""
        m = len(self.cables)
        swivels = tuple(self.swivels) if self.swivels else (None,) * len(self.exits)
        if len(swivels) != len(self.exits) or not all(s is None or isinstance(s, SwivelSpec) for s in swivels):
            raise SceneError(f"swivels must give a SwivelSpec or None per exit ({len(self.exits)}), got {shown(self.swivels)}")
        exits = list(self.exits)
        for i, swivel in enumerate(swivels):
            if swivel is None:
                continue
            if exits[i] is None or isinstance(exits[i], SwivelSpec):
                exits[i] = swivel.inlet
            elif np.any(np.asarray(exits[i], dtype=float) != np.asarray(swivel.inlet)):
                raise SceneError(f"exits[{i}].inlet = {list(swivel.inlet)} differs from exits[{i}] = {shown(exits[i])}: "
                                 "a swivel pulley's cable leaves the frame at its inlet")
            if swivel.radius >= self.cables[min(i, m - 1)].unstrained_length:
                raise SceneError(f"exits[{i}].radius = {shown(swivel.radius)} m: the cable (cables[{i}].unstrained_length = "
                                 f"{shown(self.cables[min(i, m - 1)].unstrained_length)} m) would not reach past the disc")
            from cdpr_exu.physics.swivel_pulley import SAFE_ELEMENT_FRACTION

            cable = self.cables[min(i, m - 1)]
            if cable.element_length > SAFE_ELEMENT_FRACTION * swivel.radius * (1.0 + 1e-9):
                needed = cable.unstrained_length / (SAFE_ELEMENT_FRACTION * swivel.radius)
                give = (f"give at least {math.ceil(needed)}" if needed <= MAX_ELEMENTS else
                        f"it would take {needed:.3g}, more than the {MAX_ELEMENTS} allowed: give a larger radius")
                raise SceneError(
                    f"cables[{i}].n_elements = {cable.n_elements}: its elements ({cable.element_length:.4g} m) are longer "
                    f"than {SAFE_ELEMENT_FRACTION:g} of the swivel pulley's radius (exits[{i}].radius = {shown(swivel.radius)} "
                    f"m); {give} (measured: coarser chains lose the wrap and gain energy, and Exudyn's static solver "
                    "fails)")
        object.__setattr__(self, "exits", tuple(exits))
        object.__setattr__(self, "swivels", swivels if any(s is not None for s in swivels) else ())

    @property
    def n_cables(self) -> int:
        return len(self.cables)

    @property
    def swivel_exits(self) -> tuple:
        """Each cable's :class:`SwivelSpec` or None (a point exit), shape (m,)."""
        return self.swivels if self.swivels else (None,) * len(self.cables)

    @property
    def pulley_radii(self) -> np.ndarray:
        """Each exit's pulley radius [m], 0 for a point exit, shape (m,) (the ideal kinematics' ``pulley_radii``)."""
        return np.array([0.0 if s is None else s.radius for s in self.swivel_exits])

    @property
    def exit_tops(self) -> np.ndarray:
        """Height [m] of the highest point each cable can leave its exit from, shape (m,): an exit point's
        height, a swivel pulley's inlet height plus its radius (:func:`cdpr_exu.core.geometry.above_exits`)."""
        return np.asarray(self.exits, dtype=float)[:, 2] + self.pulley_radii

    def anchor_heights(self, position, rotation=None) -> np.ndarray:
        """Height [m] of each anchor, shape (m,), with the platform's centre of mass at ``position`` (3,) [m]
        and its frame turned by ``rotation`` (3, 3) (default: not turned)."""
        anchors = np.asarray(self.platform.anchors, dtype=float)
        turned = anchors if rotation is None else anchors @ np.asarray(rotation, dtype=float).T
        return float(position[2]) + turned[:, 2]

    def above_exits(self, position, rotation=None) -> str | None:
        """Why no cable can hold the platform at this pose (every anchor at or above its exit's top), or
        None (:func:`cdpr_exu.core.geometry.above_exits`); None also when the platform has no weight."""
        if self.gravity == 0.0 or not self.effects.gravity:
            return None
        return above_exits(self.anchor_heights(position, rotation), self.exit_tops, exits="exits")

    def to_dict(self) -> dict[str, Any]:
        """Plain-data form (TOML-ready) of the scene; :func:`spatial_scene_from_dict` reads it back."""
        import dataclasses

        data: dict[str, Any] = {
            "name": self.name, "description": self.description, "dimension": 3, "gravity": self.gravity,
            "cables": [{k: v for k, v in dataclasses.asdict(c).items() if v is not None} for c in self.cables],
            "exits": [{"point": list(e)} if s is None else s.to_dict() for e, s in zip(self.exits, self.swivel_exits)],
            "platform": {"mass": self.platform.mass, "inertia": list(self.platform.inertia),
                         "anchors": [list(a) for a in self.platform.anchors]},
            "effects": dataclasses.asdict(self.effects),
            "solver": dataclasses.asdict(self.solver),
            "winch": dataclasses.asdict(self.winch),
        }
        if self.trajectory is not None:
            data["trajectory"] = self.trajectory.to_dict()
        if self.controller_model is not None:
            data["controller_model"] = self.controller_model.to_dict()
        return data

    def with_changes(self, **changes: Any) -> "SpatialScene":
        """A copy with fields replaced (validated again)."""
        return replace(self, **changes)

    @property
    def unstrained_lengths(self) -> np.ndarray:
        """Unstrained length of each cable, shape (m,) [m]."""
        return np.array([c.unstrained_length for c in self.cables])

    def catenary_platform(self) -> SpatialPlatform:
        """The scene as elastic catenaries (:mod:`cdpr_exu.physics.spatial_statics`)."""
        gravity = self.gravity if self.effects.gravity else 0.0
        weighs = self.effects.cable_mass and self.effects.gravity
        weights = [c.linear_density * gravity if weighs else 0.0 for c in self.cables]
        for i, (cable, weight) in enumerate(zip(self.cables, weights)):
            if not math.isfinite(weight):
                raise SceneError(f"cables[{i}].linear_density = {shown(cable.linear_density)} kg/m and gravity = "
                                 f"{shown(gravity)} m/s^2 give a weight per length of {shown(weight)} N/m, out of "
                                 "floating-point range")
        cables = [SpatialCable(e, w, c.axial_rigidity, anchor=a, pulley_radius=r)
                  for c, w, e, a, r in zip(self.cables, weights, self.exits, self.platform.anchors, self.pulley_radii)]
        return SpatialPlatform(cables, self.platform.mass, gravity, self.platform.inertia)

    def chain_spec(self, anchor_spring_factor: float | None = None, tension_only: bool | None = None):
        """The lumped cables (:mod:`cdpr_exu.builder.spatial_robot`), with the scene's effects.

        ``tension_only`` defaults to ``effects.slack``; the static mode asks for False (Exudyn's
        static solver needs every element's stiffness, which a slack element has not).
        """
        from cdpr_exu.builder.spatial_robot import SpatialChainSpec  # the builder's: Exudyn loads with it

        cable = self.cables[0]
        return SpatialChainSpec(
            tension_only=self.effects.slack if tension_only is None else bool(tension_only),
            n_elements=cable.n_elements,
            axial_damping_constant=cable.damping_constant * cable.area if self.effects.axial_damping else 0.0,
            flexural_rigidity=cable.youngs_modulus * cable.second_moment if self.effects.bending else 0.0,
            bending_damping_constant=(cable.damping_constant * cable.second_moment
                                      if self.effects.bending and self.effects.bending_damping else 0.0),
            anchor_spring_factor=anchor_spring_factor, mass_lumping=cable.mass_lumping)


def is_spatial(scene: Any) -> bool:
    """True for a spatial scene (``dimension = 3``)."""
    return getattr(scene, "dimension", 2) == 3


def spatial_scene_from_dict(data: Mapping[str, Any], source: str | None = None) -> SpatialScene:
    """Make a validated SpatialScene from plain data (as read from TOML).

    ``[cable]`` holds values shared by every cable; ``[[cables]]`` entries override them
    one by one (at least one entry per cable). ``[[exits]]`` give each cable's exit
    ``point``; ``[effects]`` may name a ``preset`` and override single effects. The values
    given are checked first; then the fields a scene must give are required (each cable's
    ``unstrained_length``, a swivel's ``inlet`` and ``radius``, the platform's ``mass``,
    ``anchors`` and, with an anchor off its centre, ``inertia``). ``source`` names the file
    in that message.
    """
    if not isinstance(data, Mapping):
        raise SceneError(f"a scene must be a table (mapping), got {shown(data)}")
    known = {"name", "description", "dimension", "gravity", "cable", "cables", "exits", "platform", "effects",
             "trajectory", "solver", "winch", "controller_model"}
    unknown = set(data) - known
    if unknown:
        raise SceneError(f"spatial scene has unknown field(s) {sorted(unknown)}; known: {sorted(known)}")
    if data.get("dimension") != 3:
        raise SceneError(f"dimension must be 3 for a spatial scene, got {shown(data.get('dimension'))}")
    for table in ("cables", "exits", "platform"):
        if table not in data:
            raise SceneError(f"scene lacks {table}: a spatial scene must give [[cables]] (one per cable, at least "
                             "its unstrained_length), [[exits]] (each with a point) and [platform] (mass, anchors)")
    exits = data["exits"]
    if not isinstance(exits, list):
        raise SceneError(f"exits must be an array of tables, each a point exit (point = [x, y, z]) or a swivel "
                         f"pulley (kind = 'swivel', inlet = [x, y, z], radius, ...), got {shown(exits)}")
    exit_dicts = exits
    exits = [_exit_from_dict(e, i) for i, e in enumerate(exits)]
    swivels = tuple(e if isinstance(e, SwivelSpec) else None for e in exits)
    cable_dicts = _per_cable(data, "cable", "cables", [])
    cables = tuple(_build(CableSpec, c, f"cables[{i}]") for i, c in enumerate(cable_dicts))
    effects_data = data.get("effects", {})
    if not isinstance(effects_data, Mapping):
        raise SceneError(f"effects must be a table, got {shown(effects_data)}")
    effects_data = dict(effects_data)
    effects = Effects.from_preset(effects_data.pop("preset", "full"), **effects_data)
    platform = _build(SpatialPlatformSpec, data["platform"], "platform")
    kwargs: dict[str, Any] = dict(cables=cables, exits=tuple(None if isinstance(e, SwivelSpec) else e for e in exits),
                                  swivels=swivels if any(swivels) else (), platform=platform, effects=effects,
                                  solver=_build(SolverSpec, data.get("solver", {}), "solver"),
                                  winch=_build(WinchSpec, data.get("winch", {}), "winch"))
    if "trajectory" in data:
        from cdpr_exu.scenes.spatial_trajectories import spatial_trajectory_from_dict

        kwargs["trajectory"] = spatial_trajectory_from_dict(data["trajectory"])
    if "controller_model" in data:
        kwargs["controller_model"] = controller_model_from_dict(data["controller_model"])
    for key in ("name", "description", "gravity"):
        if key in data:
            kwargs[key] = data[key]
    refuse_missing(_spatial_missing(cable_dicts, exit_dicts, swivels, data["platform"], platform), source)
    return SpatialScene(**kwargs)


def _spatial_missing(cable_dicts, exit_dicts, swivels, platform_data, platform: SpatialPlatformSpec) -> list[str]:
    """The required fields (:data:`cdpr_exu.scenes.scene.REQUIRED_FIELDS`) a spatial scene's plain data
    leaves out: each cable's length, each swivel pulley's inlet and radius (a point exit's point is
    checked with its table), the platform's mass and anchors, and its inertia when an anchor is off
    its centre of mass."""
    missing = [field_ for i, c in enumerate(cable_dicts)
               for field_ in missing_fields(f"cables[{i}]", c, ("unstrained_length",))]
    for i, (entry, swivel) in enumerate(zip(exit_dicts, swivels)):
        if swivel is not None:
            missing += missing_fields(f"exits[{i}]", entry, ("inlet", "radius"))
    names = ("mass", "anchors") + (() if platform.is_point_mass else ("inertia",))
    return missing + missing_fields("platform", platform_data, names)


def shipped_spatial_scenes() -> list[str]:
    """Names of the spatial scenes shipped with the package."""
    return shipped_names(SPATIAL_FOLDER)


def shipped_spatial_text(name: str) -> str | None:
    """The TOML text of the shipped spatial scene ``name``, or None."""
    resource = resources.files("cdpr_exu.scenes").joinpath(SPATIAL_FOLDER, str(name).replace("-", "_") + ".toml")
    return resource.read_text(encoding="utf-8") if resource.is_file() else None


def load_spatial_scene(source: str | Path) -> SpatialScene:
    """Load a spatial scene by shipped name (e.g. ``"spatial-four-cable"``) or from a TOML file path."""
    if is_scene_file(source):
        data = read_scene_file(source)
    else:
        text = shipped_spatial_text(str(source))
        if text is None:
            raise unknown_scene(source)
        data = parse_scene_text(text, source)
    return spatial_scene_from_dict(data, source=str(source))


def load_any_scene(source: str | Path) -> Scene | SpatialScene:
    """Load a planar or a spatial scene, by shipped name or TOML file path."""
    try:
        return load_scene(source)
    except SpatialSceneError:
        return load_spatial_scene(source)


def any_scene_from_dict(data: Mapping[str, Any]) -> Scene | SpatialScene:
    """A planar or a spatial scene from plain data, by its ``dimension`` (2 when absent)."""
    from .scene import scene_from_dict

    if isinstance(data, Mapping) and data.get("dimension") == 3:
        return spatial_scene_from_dict(data)
    return scene_from_dict(data)


def save_any_scene(scene: Scene | SpatialScene, path: str | Path) -> Path:
    """Write a planar or spatial scene as TOML; :func:`load_any_scene` reads it back to an equal scene."""
    import tomli_w

    path = Path(path)
    path.parent.mkdir(parents=True, exist_ok=True)
    path.write_text(tomli_w.dumps(scene.to_dict()))
    return path

