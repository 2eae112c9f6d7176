"""Physics of spatial (3-D) cables and robots, the first layer of the spatial robots (issue 15).

Numba kernels without Exudyn (``bending_3d``), elastic-catenary statics without Exudyn
(``spatial_statics``), and their Exudyn assemblies (``chain_3d``, ``spatial_robot``).
Positions are flat arrays (x0, y0, z0, x1, ...) [m]; z up, gravity along -z.
"""
