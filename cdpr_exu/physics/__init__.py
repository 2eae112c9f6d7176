"""The physics of the cables, pure maths without Exudyn.

Planar: the elastic catenary (``catenary``), the numba kernels of exact-angle bending
(``bending``), tension-only axial elements (``axial``) and pulley contact on nodes or
segments (``node_contact``, ``segment_contact``). Spatial: exact-angle bending and
tension-only elements in 3-D (``bending_3d``, ``axial_3d``), the swivel pulley's contact on a
turning disc (``swivel_pulley``),
and CoGiRo's published geometry (``cogiro``). Their Exudyn
assemblies are in :mod:`cdpr_exu.builder`. Units SI; spatial: z up, gravity along -z.
"""
