"""The cables' Jacobian as sparse triplets: the same matrix as the dense kernels, the same path."""

from dataclasses import replace

import numpy as np
import pytest

from cdpr_exu.physics.sparse_blocks import block_pattern
from cdpr_exu.physics import axial
from cdpr_exu.physics import bending
from cdpr_exu.builder.model import build_model
from cdpr_exu.scenes.scene import Effects, load_scene
from cdpr_exu.run.simulate import simulate


def _assembled(rows, columns, values, size):
    matrix = np.zeros((size, size))
    np.add.at(matrix, (rows, columns), values)  # Exudyn sums repeated triplets the same way
    return matrix


def _chain(seed, nodes=12):
    rng = np.random.default_rng(seed)
    positions = np.cumsum(rng.normal(0.0, 0.05, size=(nodes, 2)) + [0.25, -0.02], axis=0).ravel()
    velocities = rng.normal(0.0, 0.3, size=2 * nodes)
    return positions, velocities


@pytest.mark.parametrize("seed", [0, 1])
def test_bending_triplets_assemble_to_the_dense_jacobian(seed):
    positions, velocities = _chain(seed)
    joints = bending.cable_joints([6, 6])
    stiffness, damping = np.full(len(joints), 1.96), np.full(len(joints), 1.96)
    size = positions.size
    dense = np.zeros((size, size))
    bending.bending_jacobian_kernel(positions, velocities, joints, stiffness, damping, 0.7, 0.003,
                                    np.empty(0), dense, np.empty((0, 0)))
    rows, columns = block_pattern(joints, 2)
    values = bending.bending_triplet_values(positions, velocities, joints, stiffness, damping, 0.7, 0.003,
                                            np.zeros(rows.size))
    # The same floating-point terms summed in another order: round-off only.
    np.testing.assert_allclose(_assembled(rows, columns, values, size), dense, rtol=0, atol=1e-12 * np.abs(dense).max())


@pytest.mark.parametrize("seed", [0, 1])
def test_slack_triplets_assemble_to_the_dense_jacobian(seed):
    positions, velocities = _chain(seed)
    elements = axial.cable_elements([6, 6])
    lengths = np.linalg.norm(np.diff(positions.reshape(-1, 2), axis=0), axis=1)
    rest = np.delete(lengths, 5) * np.linspace(0.95, 1.05, len(elements))  # some taut, some slack
    k, c = np.full(len(elements), 3.14e5), np.full(len(elements), 3.14e5)
    size = positions.size
    dense = axial.slack_axial_jacobian(positions, velocities, elements, rest, k, c, 0.7, 0.003, np.zeros((size, size)))
    rows, columns = axial.slack_triplet_pattern(elements)
    values = axial.slack_triplet_values(positions, velocities, elements, rest, k, c, 0.7, 0.003, np.zeros(rows.size))
    assert np.abs(dense).max() > 0.0  # some element is taut
    np.testing.assert_allclose(_assembled(rows, columns, values, size), dense, rtol=0, atol=1e-12 * np.abs(dense).max())


@pytest.mark.parametrize("slack", [False, True], ids=["spring", "tension_only"])
def test_the_sparse_and_the_dense_jacobian_give_the_same_path(slack):
    paper = load_scene("paper-circle")
    scene = paper.with_changes(cables=tuple(replace(c, n_elements=30) for c in paper.cables),
                               effects=Effects.from_preset("full", slack=slack),
                               solver=replace(paper.solver, end_time=0.3))
    paths = []
    for sparse in (True, False):
        result = simulate(scene, sparse_jacobian=sparse)
        paths.append(result.pose)
        assert result.metadata["item_counts"]["cable_force_objects"] == 1
    # Same Newton iterates up to round-off: measured 1e-14 m at 15 to 240 elements.
    np.testing.assert_allclose(paths[0], paths[1], rtol=0, atol=1e-10)


def test_fine_cables_get_the_sparse_jacobian_by_default():
    paper = load_scene("paper-circle")
    fine = paper.with_changes(cables=tuple(replace(c, n_elements=60) for c in paper.cables))
    functions = build_model(fine).cable_forces.user_functions
    assert functions[2].__name__ == "jacobian_function" and "_sparse_jacobian_function" in functions[2].__qualname__


@pytest.mark.parametrize("seed", [0, 1])
def test_the_fused_force_and_jacobian_are_the_separate_kernels_bit_for_bit(seed):
    # One compiled call does the bending and the tension-only kernels in the same order:
    # the same floating-point operations, so exactly the same numbers.
    from cdpr_exu.physics import cable_forces

    positions, velocities = _chain(seed)
    joints = bending.cable_joints([6, 6])
    stiffness, damping = np.full(len(joints), 1.96), np.full(len(joints), 0.4)
    elements = axial.cable_elements([6, 6])
    rest = np.full(len(elements), 0.24)  # some elements slack, some taut
    k, c = np.full(len(elements), 4e5), np.full(len(elements), 3e2)
    reference = positions - 0.01
    q = positions - reference
    size = positions.size
    separate = bending.bending_force_kernel(reference + q, velocities, joints, stiffness, damping, np.zeros(size))
    axial.slack_axial_force(reference + q, velocities, elements, rest, k, c, separate)
    fused = cable_forces.cable_force(reference, q, velocities, np.zeros(size), joints, stiffness, damping,
                                     elements, rest, k, c, np.zeros(size))
    assert np.array_equal(fused, separate)
    dense = np.zeros((size, size))
    bending.bending_jacobian_kernel(reference + q, velocities, joints, stiffness, damping, 0.7, 0.003,
                                    np.empty(0), dense, np.empty((0, 0)))
    axial.slack_axial_jacobian(reference + q, velocities, elements, rest, k, c, 0.7, 0.003, dense)
    fused_jacobian = cable_forces.cable_jacobian(reference, q, velocities, np.zeros(size), joints, stiffness,
                                                 damping, elements, rest, k, c, 0.7, 0.003, np.empty(0),
                                                 np.empty((0, 0)), np.zeros((size, size)))
    assert np.array_equal(fused_jacobian, dense)
    assert np.any(fused != 0.0) and np.any(fused_jacobian != 0.0)
