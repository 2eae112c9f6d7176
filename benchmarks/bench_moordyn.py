"""Side by side with MoorDyn: two lumped-mass lines holding a 1 kg point mass.

The paper's static scene with the cable ends fixed at the pulley centres
(``paper-catenary-fixed``): two lines of 15 segments (the paper's cable, Table 2)
from (-1.75, 0) and (1.75, 0) m hold a 1 kg point mass; both start straight and
unstrained and drop under gravity for 10 s. Like physics on both sides: axial
stiffness, axial Kelvin-Voigt damping, consistent lumped masses, gravity; no bending,
no pulley contact, no fluid (MoorDyn: water density, drag and added mass 0).

Two dampings:

- the paper's, d_n = 1e9 N s/m^2 (BA = d_n A = 78 540 N s): over-damped axial modes,
  c_i / m_i ~ 1e7 1/s. MoorDyn is explicit (its default RK2) and is stable only near
  6e-8 s steps; 10 s would take hours, so a short stretch is timed and the time scaled
  (said in the output); its final position is then not available.
- 0.8 of critical per segment (MoorDyn's ``BA = -0.8``: c = 0.8 l sqrt(E rho)): both
  codes run the full 10 s.

Our side: ``Effects.from_preset("catenary", pulley_contact=False)`` on the scene,
Exudyn's implicit generalized-alpha at the scene's step (2e-3 s) and spectral radius
(0: numerical damping of the stiff modes), and at spectral radius 1 (none).

MoorDyn starts its lines on a catenary profile; this script overwrites the line
states (through ``Serialize``/``Deserialize``) with the straight lines of our model,
so that both drop from straight. MoorDyn's frame is 3D with z up: our (x, z) is its
(x, z) with the whole scene 10 m below its free surface.

Run: ``python benchmarks/bench_moordyn.py [--short 0.002]``. Needs ``pip install moordyn``
(the ``moordyn`` extra); without it, the script says so and exits cleanly.
Timings are wall times on this (shared) machine, one process each; compare ratios.
"""

from __future__ import annotations

import argparse
import contextlib
import math
import os
import sys
import tempfile
import time
from dataclasses import replace
from pathlib import Path

import numpy as np

from cdpr_exu.scene import Effects, load_scene
from cdpr_exu.simulate import simulate

END_TIME = 10.0
#: MoorDyn's scene sits this far below its free surface [m] (no fluid anyway).
DEPTH_OFFSET = 10.0
#: Fraction of critical damping per segment of the moderate case (MoorDyn's -BA).
DAMPING_RATIO = 0.8


@contextlib.contextmanager
def _quiet_stdout():
    """Silence MoorDyn's C++ console output (it prints every coupling step)."""
    sys.stdout.flush()
    saved = os.dup(1)
    with open(os.devnull, "w") as null:
        os.dup2(null.fileno(), 1)
        try:
            yield
        finally:
            sys.stdout.flush()
            os.dup2(saved, 1)
            os.close(saved)


def moordyn_input(scene, axial_damping_ns: float, time_step: float) -> str:
    """MoorDyn v2 input file of the scene's two lines and point mass."""
    cable = scene.cables[0]
    (xa, za), (xb, zb) = scene.pulleys[0].center, scene.pulleys[1].center
    x0, z0, _ = scene.platform.initial_pose
    d = -DEPTH_OFFSET
    return f"""--------------------- MoorDyn Input File -------------------------------------
cdpr-exu: two cables holding a point mass (paper-catenary-fixed), no fluid
----------------------- LINE TYPES ------------------------------------------
TypeName   Diam    Mass/m     EA     BA/-zeta    EI    Cd     Ca     CdAx    CaAx
(name)     (m)     (kg/m)     (N)    (N-s/-)     (N-m^2) (-)  (-)    (-)     (-)
cable      {2 * cable.radius!r}  {cable.linear_density!r}  {cable.axial_rigidity!r}  {axial_damping_ns!r}  0.0  0.0  0.0  0.0  0.0
---------------------- POINTS --------------------------------
ID   Attachment  X       Y     Z     M      V     CdA   CA
(#)   (-)        (m)    (m)   (m)   (kg)   (m^3)  (m^2) (-)
1     Fixed     {xa!r}    0    {za + d!r}     0      0      0     0
2     Fixed     {xb!r}    0    {zb + d!r}     0      0      0     0
3     Free      {x0!r}    0    {z0 + d!r}  {scene.platform.mass!r}    0      0     0
---------------------- LINES --------------------------------------
ID    LineType   AttachA  AttachB  UnstrLen  NumSegs   Outputs
(#)   (name)     (#)      (#)      (m)       (-)       (-)
1     cable      1        3        {cable.unstrained_length!r}  {cable.n_elements}   -
2     cable      2        3        {cable.unstrained_length!r}  {cable.n_elements}   -
---------------------- OPTIONS -----------------------------------------
0        writeLog
{time_step!r}     dtM
{scene.gravity!r}      g
0.0      WtrDnsty
1000     WtrDpth
0        TmaxIC
----------------------- OUTPUTS --------------------------------------------
END
------------------------- need this line --------------------------------------
"""


def _start_straight(moordyn, system, n_lines: int) -> int:
    """Overwrite MoorDyn's catenary initial line profiles with straight lines.

    Finds each interior node's (x, y, z) in the serialized state and replaces every
    occurrence by the point on the straight line between the line's ends. Returns the
    number of node triples replaced (at least one per interior node, else it raises).
    """
    data = bytearray(moordyn.Serialize(system))
    values = np.frombuffer(data[: len(data) // 8 * 8], dtype=np.float64).copy()
    replaced = 0
    for number in range(1, n_lines + 1):
        line = moordyn.GetLine(system, number)
        count = moordyn.GetLineNumberNodes(line)
        first = np.array(moordyn.GetLineNodePos(line, 0))
        last = np.array(moordyn.GetLineNodePos(line, count - 1))
        for i in range(1, count - 1):
            node = np.array(moordyn.GetLineNodePos(line, i))
            straight = first + (last - first) * i / (count - 1)
            hits = [k for k in np.flatnonzero(values[:-2] == node[0])
                    if values[k + 1] == node[1] and values[k + 2] == node[2]]
            if not hits:
                raise RuntimeError(f"MoorDyn line {number} node {i} not found in its serialized state")
            for k in hits:
                values[k:k + 3] = straight
                replaced += 1
    data[: values.size * 8] = values.tobytes()
    moordyn.Deserialize(system, bytes(data))
    return replaced


def run_moordyn(scene, axial_damping_ns: float, time_step: float, end_time: float,
                coupling_step: float = 0.01) -> dict:
    """Run MoorDyn to ``end_time``; wall time [s] and the point mass's final (x, z) [m]."""
    import moordyn

    with tempfile.TemporaryDirectory() as folder:
        path = Path(folder) / "lines.txt"
        path.write_text(moordyn_input(scene, axial_damping_ns, time_step))
        with _quiet_stdout():
            system = moordyn.Create(str(path))
            moordyn.Init_NoIC(system, [], [])
            _start_straight(moordyn, system, 2)
            point = moordyn.GetPoint(system, 3)
            start_position = np.array(moordyn.GetPointPos(point))
            line = moordyn.GetLine(system, 1)
            straightness = _max_deviation_from_chord(
                [moordyn.GetLineNodePos(line, i) for i in range(moordyn.GetLineNumberNodes(line))])
            coupling_step = min(coupling_step, end_time)
            steps = int(round(end_time / coupling_step))
            start = time.perf_counter()
            t = 0.0
            try:
                for _ in range(steps):
                    moordyn.Step(system, [], [], t, coupling_step)
                    t += coupling_step
                position = np.array(moordyn.GetPointPos(point))
            except RuntimeError:  # MoorDyn raises when its explicit integration blows up (NaN)
                position = np.full(3, np.nan)
            wall = time.perf_counter() - start
            scheme = moordyn.GetTimeScheme(system) if hasattr(moordyn, "GetTimeScheme") else None
            moordyn.Close(system)
    finite = bool(np.all(np.isfinite(position)))
    return {"wall_time": wall, "simulated": t, "position": (position[0], position[2] + DEPTH_OFFSET),
            "start": (start_position[0], start_position[2] + DEPTH_OFFSET), "finite": finite,
            "initial_sag": straightness, "scheme": scheme or "RK2 (default)"}


def _max_deviation_from_chord(points) -> float:
    points = np.asarray(points, dtype=float)
    chord = points[-1] - points[0]
    chord /= np.linalg.norm(chord)
    offsets = points - points[0]
    return float(np.linalg.norm(offsets - np.outer(offsets @ chord, chord), axis=1).max())


def largest_stable_step(scene, axial_damping_ns: float, candidates, probe_time: float) -> float | None:
    """The largest MoorDyn step among ``candidates`` that stays finite over ``probe_time``."""
    for step in sorted(candidates, reverse=True):
        run = run_moordyn(scene, axial_damping_ns, step, probe_time, coupling_step=probe_time)
        if run["finite"] and abs(run["position"][1] - run["start"][1]) < 0.5:
            return step
    return None


def run_ours(scene, damping_constant: float, spectral_radius: float) -> dict:
    cables = tuple(replace(c, damping_constant=damping_constant) for c in scene.cables)
    solver = replace(scene.solver, end_time=END_TIME, spectral_radius=spectral_radius)
    run_scene = scene.with_changes(cables=cables, solver=solver,
                                   effects=Effects.from_preset("catenary", pulley_contact=False))
    simulate(run_scene.with_changes(solver=replace(solver, end_time=4 * solver.step_size)))  # warm-up
    result = simulate(run_scene)
    x, z, _ = result.platform_pose[-1]
    return {"wall_time": result.wall_time, "position": (x, z), "step": solver.step_size,
            "newton": result.newton_iterations / max(result.steps, 1)}


def main() -> int:
    parser = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    parser.add_argument("--short", type=float, default=2.0e-3,
                        help="simulated time of MoorDyn's timed stretch with the paper's damping [s]")
    args = parser.parse_args()
    try:
        import moordyn  # noqa: F401
    except ImportError:
        print("MoorDyn is not installed (pip install moordyn, or the project's 'moordyn' extra): skipped.")
        return 0

    scene = load_scene("paper-catenary-fixed")
    cable = scene.cables[0]
    # MoorDyn's damping ratio: c = zeta l sqrt(E rho) (stress per strain rate), rho = w / A.
    moderate_dn = DAMPING_RATIO * cable.element_length * math.sqrt(cable.youngs_modulus * cable.linear_density / cable.area)
    cases = (("paper's d_n = 1e9 N s/m^2", cable.damping_constant),
             (f"{DAMPING_RATIO} of critical per segment (d_n = {moderate_dn:.3g} N s/m^2)", moderate_dn))
    print(f"paper-catenary-fixed: 2 lines x {cable.n_elements} segments, 1 kg point mass, dropped from straight, "
          f"{END_TIME:g} s; no bending, no contact, no fluid")
    print(f"{'case':58s} {'code':28s} {'wall [s]':>10s} {'x real time':>12s} {'final x, z [m]':>22s}")
    for name, dn in cases:
        ba = dn * cable.area  # N s: MoorDyn's BA
        ours = {rho: run_ours(scene, dn, rho) for rho in (0.0, 1.0)}
        c_segment = dn * cable.area / cable.element_length
        stability_guess = 2.0 * (cable.element_mass / 2.0) / (2.0 * c_segment)  # ~ m / c of a node
        if dn > 1e8:
            candidates = [2e-8, 4e-8, 6e-8, 8e-8, 1e-7, 1.5e-7]
            step = largest_stable_step(scene, ba, candidates, probe_time=2e-4)
            if step is None:
                print(f"{name}: MoorDyn unstable at every step tried ({candidates}); skipped")
                continue
            short = run_moordyn(scene, ba, step, args.short, coupling_step=args.short / 10)
            scaled = short["wall_time"] * END_TIME / short["simulated"]
            md = {"wall_time": scaled, "position": (math.nan, math.nan), "step": step,
                  "note": f"timed {short['simulated']:g} s, scaled x {END_TIME / short['simulated']:g}"}
        else:
            candidates = [2e-5, 5e-5, 1e-4, 2e-4, 5e-4, 1e-3]
            step = largest_stable_step(scene, ba, candidates, probe_time=0.5)
            full = run_moordyn(scene, ba, step, END_TIME)
            md = {"wall_time": full["wall_time"], "position": full["position"], "step": step,
                  "note": f"full {END_TIME:g} s; its lines started straight to {full['initial_sag']:.1e} m"}
        for rho, run in ours.items():
            label = f"cdpr-exu implicit, h={run['step']:g}, rho={rho:g}"
            print(f"{name:58s} {label:28s} {run['wall_time']:10.2f} {END_TIME / run['wall_time']:12.1f} "
                  f"{run['position'][0]:+10.5f} {run['position'][1]:+10.5f}")
        label = f"MoorDyn RK2, dtM={md['step']:g}"
        position = md["position"]
        where = "   (not run to the end)" if math.isnan(position[1]) else f"{position[0]:+10.5f} {position[1]:+10.5f}"
        print(f"{name:58s} {label:28s} {md['wall_time']:10.2f} {END_TIME / md['wall_time']:12.3g} {where}")
        print(f"{'':58s} MoorDyn: {md['note']}; explicit step limit ~ m_node / c_i = {stability_guess:.1e} s")
        print(f"{'':58s} wall-time ratio MoorDyn / cdpr-exu (rho 0): {md['wall_time'] / ours[0.0]['wall_time']:.3g}")
        if not math.isnan(position[1]):
            for rho, run in ours.items():
                dz = 1000 * (run["position"][1] - position[1])
                print(f"{'':58s} final z difference cdpr-exu (rho {rho:g}) - MoorDyn: {dz:+.2f} mm")
    return 0


if __name__ == "__main__":
    sys.exit(main())
