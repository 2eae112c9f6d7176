"""Where the pulley rim contact acts: one object per model, chosen once when the scene is made.

``Effects.pulley_contact_model`` names the model; :data:`CONTACT_MODELS` holds the
object that says what each needs from the builder, the initial configuration, the
checks and the statics, so that no module branches on the name again:

* ``"node"``: Exudyn's sphere contact items push each node that enters the disc back
  out (:mod:`cdpr_exu.builder.pulley`), switched on and off in Exudyn's discontinuous iterations;
* ``"segment"``: the point of each element closest to the pulley centre is pushed out,
  shared by the element's two nodes, inside the cables' numba object
  (:mod:`cdpr_exu.physics.segment_contact`): straight elements cannot cut the disc as chords;
* ``"node_smooth"``: the node contact with a smooth onset, inside the cables' numba
  object (:mod:`cdpr_exu.physics.node_contact`).
"""

from __future__ import annotations

import math
from dataclasses import dataclass

__all__ = ["PulleyContactModel", "CONTACT_MODELS"]


@dataclass(frozen=True)
class PulleyContactModel:
    """What one pulley contact model needs from the rest of the simulator.

    Attributes
    ----------
    name : str
        The ``Effects.pulley_contact_model`` value.
    exudyn_items : bool
        Exudyn's contact items on the nodes (else the forces live in the cables' numba object).
    on_segments : bool
        The contact acts on the element segments, not only on the nodes.
    smooth_nodes : bool
        The smooth-onset node contact in the cables' numba object.
    """

    name: str
    exudyn_items: bool
    on_segments: bool
    smooth_nodes: bool

    def wrap_radius(self, pulley_radius: float, element_length: float) -> float:
        """Radius [m] on which the initial nodes wrap the pulley.

        With segment contact, nodes on the rim would make every wrapped element a chord
        cutting into the disc, which the contact would fire out at the first step; the
        nodes go on the circumscribed circle sqrt(r^2 + l0i^2 / 4) instead.
        """
        return math.hypot(pulley_radius, element_length / 2.0) if self.on_segments else pulley_radius

    @property
    def limits_element_length(self) -> bool:
        """Elements much longer than the pulley radius cut the disc as chords and slip through it."""
        return not self.on_segments


#: The contact models by name, in the order of ``Effects.pulley_contact_model``'s choices.
CONTACT_MODELS: dict[str, PulleyContactModel] = {
    "node": PulleyContactModel("node", exudyn_items=True, on_segments=False, smooth_nodes=False),
    "segment": PulleyContactModel("segment", exudyn_items=False, on_segments=True, smooth_nodes=False),
    "node_smooth": PulleyContactModel("node_smooth", exudyn_items=False, on_segments=False, smooth_nodes=True),
}
