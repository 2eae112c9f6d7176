"""Time the bending force and Jacobian: numba kernels against a vectorised NumPy reference.

Scene size: 2 cables of 16 nodes (N = 32 nodes, 64 coordinates, 28 joints), one call
over all cables. Run: ``python benchmarks/bench_bending.py``.
"""

import timeit

import numpy as np

from cdpr_exu.physics.bending import (
    BendingSpringDamper,
    bending_force_kernel,
    bending_jacobian_kernel,
    cable_joints,
)


# --------------------------------------------------------------------------- NumPy reference

def _atan2_gradient_and_hessian(e):
    """g (J, 2) and H (J, 2, 2) of atan2(e_y, e_x) for edges e (J, 2)."""
    x, y = e[:, 0], e[:, 1]
    r2 = x * x + y * y
    g = np.column_stack([-y, x]) / r2[:, None]
    r4 = r2 * r2
    h = np.empty((len(e), 2, 2))
    h[:, 0, 0] = 2.0 * x * y / r4
    h[:, 0, 1] = h[:, 1, 0] = (y * y - x * x) / r4
    h[:, 1, 1] = -h[:, 0, 0]
    return g, h


def numpy_force(positions, velocities, joints, stiffness, damping):
    """Vectorised NumPy bending force (2N,), the reference for the numba kernel."""
    p = positions.reshape(-1, 2)
    v = velocities.reshape(-1, 2)
    a, b, c = joints.T
    e1 = p[b] - p[a]
    e2 = p[c] - p[b]
    dtheta = np.arctan2(e1[:, 0] * e2[:, 1] - e1[:, 1] * e2[:, 0], np.einsum("ij,ij->i", e1, e2))
    g1 = np.column_stack([-e1[:, 1], e1[:, 0]]) / np.einsum("ij,ij->i", e1, e1)[:, None]
    g2 = np.column_stack([-e2[:, 1], e2[:, 0]]) / np.einsum("ij,ij->i", e2, e2)[:, None]
    rate = np.einsum("ij,ij->i", g1, v[a]) - np.einsum("ij,ij->i", g1 + g2, v[b]) + np.einsum("ij,ij->i", g2, v[c])
    moment = (stiffness * dtheta + damping * rate)[:, None]
    force = np.zeros_like(p)
    np.add.at(force, a, -moment * g1)
    np.add.at(force, b, moment * (g1 + g2))
    np.add.at(force, c, -moment * g2)
    return force.ravel()


def numpy_jacobian(positions, velocities, joints, stiffness, damping):
    """Vectorised NumPy K = -df/dq and D = -df/dv, dense (2N, 2N)."""
    p = positions.reshape(-1, 2)
    a, b, c = joints.T
    e1 = p[b] - p[a]
    e2 = p[c] - p[b]
    dtheta = np.arctan2(e1[:, 0] * e2[:, 1] - e1[:, 1] * e2[:, 0], np.einsum("ij,ij->i", e1, e2))
    g1, h1 = _atan2_gradient_and_hessian(e1)
    g2, h2 = _atan2_gradient_and_hessian(e2)
    n_joints = len(joints)
    grad = np.concatenate([g1, -g1 - g2, g2], axis=1)  # (J, 6)
    hess = np.zeros((n_joints, 6, 6))
    hess[:, 0:2, 0:2] = -h1
    hess[:, 0:2, 2:4] = h1
    hess[:, 2:4, 0:2] = h1
    hess[:, 2:4, 2:4] = h2 - h1
    hess[:, 2:4, 4:6] = -h2
    hess[:, 4:6, 2:4] = -h2
    hess[:, 4:6, 4:6] = h2
    index = np.stack([2 * a, 2 * a + 1, 2 * b, 2 * b + 1, 2 * c, 2 * c + 1], axis=1)  # (J, 6)
    v_local = velocities[index]
    rate = np.einsum("ji,ji->j", grad, v_local)
    hess_v = np.einsum("jim,jm->ji", hess, v_local)
    moment = stiffness * dtheta + damping * rate
    k_local = (grad[:, :, None] * (stiffness[:, None, None] * grad[:, None, :] + damping[:, None, None] * hess_v[:, None, :])
               + moment[:, None, None] * hess)
    d_local = damping[:, None, None] * grad[:, :, None] * grad[:, None, :]
    n = positions.size
    rows = np.broadcast_to(index[:, :, None], (n_joints, 6, 6)).ravel()
    cols = np.broadcast_to(index[:, None, :], (n_joints, 6, 6)).ravel()
    flat = rows * n + cols
    stiffness_matrix = np.bincount(flat, weights=k_local.ravel(), minlength=n * n).reshape(n, n)
    damping_matrix = np.bincount(flat, weights=d_local.ravel(), minlength=n * n).reshape(n, n)
    return stiffness_matrix, damping_matrix


# --------------------------------------------------------------------------- benchmark

def scene(n_cables=2, nodes_per_cable=16, element_length=0.1, seed=0):
    rng = np.random.default_rng(seed)
    parts = []
    for cable in range(n_cables):
        heading = np.cumsum(rng.normal(0.0, 0.4, nodes_per_cable - 1)) + cable
        steps = element_length * np.column_stack([np.cos(heading), np.sin(heading)])
        parts.append(np.vstack([[cable, 0.0], [cable, 0.0] + np.cumsum(steps, axis=0)]).ravel())
    positions = np.concatenate(parts)
    velocities = rng.normal(0.0, 0.5, positions.size)
    joints = cable_joints([nodes_per_cable] * n_cables)
    stiffness = np.full(len(joints), 1.5)
    damping = np.full(len(joints), 0.05)
    return positions, velocities, joints, stiffness, damping


def per_call_seconds(function, repeat=7, target=0.2):
    timer = timeit.Timer(function)
    number, _ = timer.autorange()
    number = max(1, int(number * target / 0.2))
    return min(timer.repeat(repeat=repeat, number=number)) / number


def main():
    args = scene()
    positions, velocities, joints, stiffness, damping = args
    n = positions.size
    out, out_k, out_d = np.empty(n), np.empty((n, n)), np.empty((n, n))

    # agreement before timing (same formulas, different summation order: round-off only)
    springs = BendingSpringDamper(n // 2, joints, stiffness, damping)
    force_numba, k_numba, d_numba = springs.force_and_jacobian(positions, velocities)
    k_numpy, d_numpy = numpy_jacobian(*args)
    assert np.allclose(force_numba, numpy_force(*args), rtol=1e-12, atol=1e-12)
    assert np.allclose(k_numba, k_numpy, rtol=1e-12, atol=1e-10)
    assert np.allclose(d_numba, d_numpy, rtol=1e-12, atol=1e-12)

    empty_vector = np.empty(0)
    timings = {
        "force, NumPy reference": lambda: numpy_force(*args),
        "force, BendingSpringDamper.force": lambda: springs.force(positions, velocities),
        "force, numba kernel": lambda: bending_force_kernel(*args, out),
        "jacobian K, D, NumPy reference": lambda: numpy_jacobian(*args),
        "jacobian K, D, BendingSpringDamper": lambda: springs.jacobian(positions, velocities),
        "force+K+D, BendingSpringDamper": lambda: springs.force_and_jacobian(positions, velocities),
        "jacobian K, D, numba kernel": lambda: bending_jacobian_kernel(
            *args, 1.0, 0.0, empty_vector, out_k, out_d),
    }
    results = {name: per_call_seconds(function) for name, function in timings.items()}
    print(f"2 cables x 16 nodes: {n} coordinates, {len(joints)} joints")
    for name, seconds in results.items():
        print(f"  {name:40s} {seconds * 1e6:9.2f} us")
    print("ratios NumPy / numba:")
    for what, numba_name in [("force", "force, BendingSpringDamper.force"), ("force", "force, numba kernel"),
                             ("jacobian K, D", "jacobian K, D, BendingSpringDamper"),
                             ("jacobian K, D", "jacobian K, D, numba kernel")]:
        ratio = results[f"{what}, NumPy reference"] / results[numba_name]
        print(f"  {numba_name:40s} {ratio:7.1f} x faster")


if __name__ == "__main__":
    main()
