"""Physics of spatial (3-D) cables, the first layer of the spatial robots (issue 15).

Pure numba kernels, no Exudyn: positions are flat arrays (x0, y0, z0, x1, ...) [m]
(``bending_3d``, ``swivel_pulley``); the Exudyn builders are ``chain_3d`` and ``swivel_chain``.
"""
