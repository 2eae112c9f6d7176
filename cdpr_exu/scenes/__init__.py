"""Scenes: the scene description (planar and spatial), its effects, reference trajectories and
the pulley contact models, validated once; and the shipped scene files (``*.toml``, ``spatial/*.toml``)."""
