"""Where the pulley rim contact acts: one object per model (``Effects.pulley_contact_model``), so that no
module branches on the name again.

* ``"node"``: the law of Exudyn's sphere contact items pushes each node in the disc back out, its state
  frozen within Newton's iteration and switched after it (:class:`cdpr_exu.physics.node_contact.FrozenNodeContact`);
* ``"segment"``: each element's point closest to the centre, shared by its two nodes
  (:mod:`cdpr_exu.physics.segment_contact`): straight elements cannot cut the disc as chords;
* ``"node_smooth"``: the node contact with a smooth onset (:mod:`cdpr_exu.physics.node_contact`).
"""

from __future__ import annotations

import math
from dataclasses import dataclass


@dataclass(frozen=True)
class PulleyContactModel:
    """What one pulley contact model needs (its forces all live in the cables' numba object): the node contact
    switched after Newton's iteration (``frozen_nodes``), on the segments (``on_segments``), or else the smooth
    node contact."""

    name: str
    frozen_nodes: bool
    on_segments: bool

    def wrap_radius(self, pulley_radius: float, element_length: float) -> float:
        """Radius [m] the initial nodes wrap the pulley on: with segment contact, the circumscribed circle
        sqrt(r^2 + l0i^2 / 4) (chords on the rim would cut the disc and be fired out at the first step)."""
        return math.hypot(pulley_radius, element_length / 2.0) if self.on_segments else pulley_radius

    @property
    def limits_element_length(self) -> bool:
        """Elements much longer than the pulley radius cut the disc as chords and slip through it."""
        return not self.on_segments


CONTACT_MODELS: dict[str, PulleyContactModel] = {
    "node": PulleyContactModel("node", frozen_nodes=True, on_segments=False),
    "segment": PulleyContactModel("segment", frozen_nodes=False, on_segments=True),
    "node_smooth": PulleyContactModel("node_smooth", frozen_nodes=False, on_segments=False),
}
