"""The spatial winches' paid-out length reaches the integrator's inertia, not only the weight (real solver)."""

from types import SimpleNamespace

import exudyn as exu
import exudyn.itemInterface as eii
import numpy as np

from cdpr_exu.builder.chain_3d import add_spatial_chain
from cdpr_exu.exits import PointExit
from cdpr_exu.run.run_3d import _SpatialWinches


def test_a_chain_paid_out_to_twice_its_length_accelerates_as_its_doubled_mass_says():
    # A free 4-element chain (2 m, 1 kg/m) out of gravity, pulled along itself by 1 N shared among its nodes
    # as their masses (no element stretches); at t = 0.5 s its winch doubles the paid-out length, and with it
    # every node's mass: the chain accelerates at F / M(t), 0.5 m/s^2, then 0.25 m/s^2.
    n, length, force = 4, 2.0, 1.0
    masses = np.r_[0.25, np.full(n - 1, 0.5), 0.25]  # rho l_e lumped: 2 kg in all
    container = exu.SystemContainer()
    mbs = container.AddSystem()
    chain = add_spatial_chain(mbs, np.c_[np.linspace(0.0, length, n + 1), np.zeros((n + 1, 2))], masses, 1e5, 10.0,
                              0.0, gravity=0.0, hold_first=False, tension_only=True)
    for marker, mass in zip(chain.markers, masses):
        mbs.AddLoad(eii.LoadForceVector(markerNumber=marker, loadVector=[force * mass / masses.sum(), 0.0, 0.0]))
    mbs.Assemble()
    scene = SimpleNamespace(cables=[SimpleNamespace(n_elements=n, axial_rigidity=1e5 * length / n)],
                            exits=[PointExit((0.0, 0.0, 0.0))])
    items = SimpleNamespace(chains=[chain], node_masses=[masses], unstrained_lengths=np.array([length]),
                            axial_dampings=np.array([10.0]), bending_stiffnesses=np.zeros(1),
                            bending_dampings=np.zeros(1))
    winches = _SpatialWinches(mbs, scene, items, np.array([length]))
    momentum = []

    def pre_step(mbs_, t):
        winches.set_lengths(np.array([length * (2.0 if t >= 0.5 - 1e-9 else 1.0)]), np.zeros(1))
        return True

    def post_step(mbs_, t):
        velocities = mbs_.systemData.GetODE2Coordinates_t().reshape(-1, 3)
        momentum.append((t, float(velocities[:, 0] @ masses)))  # with the masses the chain starts with
        return True

    mbs.SetPreStepUserFunction(pre_step)
    mbs.SetPostStepUserFunction(post_step)
    settings = exu.SimulationSettings()
    settings.timeIntegration.numberOfSteps, settings.timeIntegration.endTime = 100, 1.0
    settings.timeIntegration.verboseMode = 0
    settings.linearSolver.solverType = exu.LinearSolverType.EigenSparse
    mbs.SolveDynamic(settings)
    t, p = np.array(momentum).T
    centre_velocity = p / masses.sum()

    def slope(start, end):  # of the centre's velocity [m/s^2]
        return float(np.diff(np.interp([start, end], t, centre_velocity))[0] / (end - start))

    # the generalised-alpha steps carry the change of acceleration as a transient decaying within a few steps
    # (2e-4 relative at t = 0.6 s): 1e-3 on the slope after it; the old code kept 0.5 m/s^2 after the change
    assert abs(slope(0.1, 0.45) - 0.5) < 1e-9
    assert abs(slope(0.6, 1.0) - 0.25) < 0.25e-3
