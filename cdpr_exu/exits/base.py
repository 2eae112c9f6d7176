"""What every exit is: where a cable leaves the frame, one protocol for every kind, and their registry.

An exit is a frozen dataclass: a point exit (:class:`~cdpr_exu.exits.point.PointExit`), a
planar pulley (:class:`~cdpr_exu.exits.pulley.Pulley`), a swivel pulley
(:class:`~cdpr_exu.exits.swivel.Swivel`), or any kind a user adds. A consumer asks the
exit (its fixed point, the cable's exit towards an anchor, the cable's length, whether the
cable wraps over it) and never tests its kind. The kinds live in :data:`EXIT_KINDS` (the
package fills it with the shipped kinds), as the pulley contact models live in
:data:`cdpr_exu.scenes.contact_models.CONTACT_MODELS`: adding a kind is one module with its
class plus one entry ``EXIT_KINDS["name"] = Class``.

A scene file gives an exit as a table of ``[[exits]]`` naming its ``kind`` (``"point"`` when
absent) and its fields; :func:`exit_from_dict` makes it, in the scene's
:class:`~cdpr_exu.space.Space`. The ideal cable's geometry (tangent point, wrap, free length)
is computed by the pure kernels of :mod:`cdpr_exu.core.geometry`. Units SI.
"""

from __future__ import annotations

import dataclasses
from typing import Any, ClassVar, Mapping

import numpy as np

from cdpr_exu.core.errors import SceneError
from cdpr_exu.core.geometry import PulleyExit
from cdpr_exu.core.validation import from_table, shown

__all__ = ["Exit", "EXIT_KINDS", "exit_from_dict"]


class Exit:
    """Where a cable leaves the frame (the protocol every exit kind implements).

    Class attributes: ``kind`` (its name in scene files and :data:`EXIT_KINDS`), ``dimensions``
    it exists in, ``required_fields`` a scene file must give (with units; the loader names each
    one left out), ``path_head`` (the name its own messages give its fields, ``"pulley.radius"``,
    which the loader replaces with the exit's place, ``"exits[1].radius"``).

    Every kind has a ``point`` (its fixed point, shape (d,) [m]: a pulley's centre, a swivel's
    inlet, a point exit's point) and a ``radius`` [m] the cable wraps over (0: it leaves from
    the point); the methods below ask nothing else of it unless a kind overrides them.
    """

    kind: ClassVar[str] = ""
    dimensions: ClassVar[tuple[int, ...]] = ()
    required_fields: ClassVar[dict[str, str]] = {}
    path_head: ClassVar[str] = "exit"

    point: tuple
    radius: float
    #: The side a planar cable hangs from its exit's winch line, -1 (left) or 1 (right): a pulley's own; a
    #: kind that does not wrap hangs on the left.
    side = -1

    @property
    def dimension(self) -> int:
        """The dimension of the space the exit stands in: the size of its point."""
        return len(self.point)

    @property
    def wraps(self) -> bool:
        """True when the cable wraps over a disc of this exit (its radius is positive)."""
        return self.radius > 0.0

    @property
    def top(self) -> float:
        """Height [m] of the highest point the cable can leave this exit from: the fixed point's height
        plus the radius (the top of a pulley's rim or of a swivel's disc; a point exit's point).
        See :func:`cdpr_exu.core.geometry.above_exits`."""
        return self.point[-1] + self.radius

    @property
    def hang_point(self) -> np.ndarray:
        """Where the cable leaves its vertical winch line, shape (d,) [m]: the fixed point, unless the
        kind says otherwise (a planar pulley's hang point is beside its centre)."""
        return np.array(self.point)

    def exit(self, anchor_points) -> PulleyExit:
        """The ideal (straight, massless) cable's exit towards ``anchor_points`` (d,) or (N, d) [m]: its
        tangent point, wrap angle, free length, unit vector (towards the anchor) and arc length."""
        raise NotImplementedError

    def cable_length(self, anchor_points):
        """Ideal cable length [m] from the hang point to ``anchor_points`` (d,) or (N, d) [m]: a float, or (N,)."""
        return self.exit(anchor_points).cable_length

    def winch_end(self, unstrained_length: float, paid_out: float) -> np.ndarray:
        """Winch end of a cable of unstrained length ``L0`` [m] with ``paid_out`` [m] beyond the hang point:
        ``h - (L0 - lambda) up``, the cable straight down its winch line. Shape (d,) [m]."""
        end = self.hang_point
        end[-1] = end[-1] - (unstrained_length - paid_out)
        return end

    def paid_out_length(self, unstrained_length: float, winch_end) -> float:
        """Paid-out length lambda [m] of a cable of unstrained length ``L0`` [m] whose winch end is at
        ``winch_end`` (d,) [m]: all of the cable but the part hanging below the hang point (the inverse
        of :meth:`winch_end`)."""
        return float(unstrained_length - (self.point[-1] - winch_end[-1]))

    def fewest_elements(self, cable) -> int:
        """The fewest elements a cable (:class:`~cdpr_exu.scenes.scene.CableSpec`) over this exit may have: 1
        unless the kind needs short elements beside its disc."""
        return 1

    def paid_out_refusal(self, cable, index: int, lengths, lumped: bool, path: str):
        """The first sample at which the ideal lengths ``lengths`` (N,) [m] of ``cables[index]`` (``cable``) along a
        reference need more cable than this exit's winch can pay out, and what it needs (the end of a sentence
        "the reference pose ... needs ...", naming the fields; ``lumped``: the cable has elements), or None.
        None by default: the winch pays out through the exit without limit, or the cable is fixed there."""
        return None

    def check(self, cable, index: int, path: str) -> None:
        """Refuse a cable (:class:`~cdpr_exu.scenes.scene.CableSpec`, ``cables[index]``) that this exit
        (``path``, e.g. ``"exits[2]"``) cannot carry; the message names both. Nothing by default."""

    def describe(self, path: str) -> str:
        """The exit's geometry for a message, each field named under ``path``."""
        return f"{path}.point {list(self.point)} m, {path}.radius {self.radius} m"

    def to_dict(self) -> dict[str, Any]:
        """The exit's ``[[exits]]`` table: its ``kind`` and its fields (tuples as lists)."""
        return {"kind": self.kind, **{f.name: _listed(getattr(self, f.name)) for f in dataclasses.fields(self)}}

    @classmethod
    def from_dict(cls, data: Mapping[str, Any], path: str, space) -> "Exit":
        """The exit of one ``[[exits]]`` table (without its ``kind``), its messages naming ``path``."""
        return from_table(cls, data, path, cls.path_head)


def _listed(value: Any) -> Any:
    return list(value) if isinstance(value, tuple) else value


#: The exit kinds by name (``kind = "..."`` in a scene's ``[[exits]]``); the package
#: (``cdpr_exu/exits/__init__.py``) enters the shipped kinds: "point", "pulley", "swivel".
EXIT_KINDS: dict[str, type[Exit]] = {}


def exit_from_dict(data: Any, path: str, space) -> Exit:
    """The exit of one ``[[exits]]`` table in ``space`` (:class:`~cdpr_exu.space.Space`), by its ``kind``
    (``"point"`` when absent), naming ``path`` (e.g. ``"exits[2]"``) in its messages: SceneError for a
    table that is none, an unknown kind or one that does not exist in ``space``, and a bad field."""
    if not isinstance(data, Mapping):
        raise SceneError(f"{path} must be a table, got {shown(data)}")
    data = dict(data)
    kind = data.pop("kind", "point")
    kinds = [name for name, cls in EXIT_KINDS.items() if space.dimension in cls.dimensions]
    if not isinstance(kind, str) or kind not in EXIT_KINDS:
        raise SceneError(f"{path}.kind must be {' or '.join(map(repr, kinds))}, got {shown(kind)}")
    cls = EXIT_KINDS[kind]
    if space.dimension not in cls.dimensions:
        raise SceneError(f"{path}.kind = {kind!r}: no such exit in a {space.name} scene; its exits are "
                         f"{' or '.join(map(repr, kinds))}")
    return cls.from_dict(data, path, space)
