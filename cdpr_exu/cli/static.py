"""``cdpr static``: a scene brought to rest (:mod:`cdpr_exu.run.rest`, :mod:`cdpr_exu.run.spatial_rest`).

Examples::

    cdpr static paper-catenary-fixed --out results/static_fixed
    cdpr static spatial-four-cable --out results/static_spatial
"""

from __future__ import annotations

import argparse
import sys
import warnings
from pathlib import Path

import numpy as np

from cdpr_exu.core.errors import EXIT_CODES, EXIT_OK, SolverFailure, SuspectAnswerWarning
from cdpr_exu.core.geometry import rotation_angles_deg
from cdpr_exu.core.output import check_output_folder, clear_outputs, fixed, write_summary
from cdpr_exu.results.result import provenance
from cdpr_exu.run.rest import DEFAULT_MAX_TIME, DEFAULT_TOLERANCE, solve_rest
from cdpr_exu.run.spatial_rest import SpatialRest, solve_spatial_rest
from cdpr_exu.scenes.scene import Scene, load_scene, save_scene

EPILOG = """examples:
  cdpr static paper-catenary-fixed --out results/static_fixed
  cdpr static paper-catenary --out results/static_pulleys --tolerance 1e-7
  cdpr static spatial-four-cable --out results/static_spatial

A spatial scene (dimension = 3) is solved directly by Exudyn's static solver, started on
its elastic-catenary statics (--tolerance, --max-time and --no-polish do not apply), and
reports the platform's position and rotation beside the catenary answer; it warns when the
two lie more than 5 % of the shortest cable apart or an element is compressed, and fails
(exit 3, with the cause) on an equilibrium that holds the platform above its exits.
"""


def _write_static_failure(scene: Scene, err: SolverFailure, out: Path) -> None:
    """Write what a failed ``cdpr static`` knows: the scene, the cause and the last state."""
    clear_outputs(out, "static")  # no file of an earlier `cdpr static` there stays beside these
    save_scene(scene, out / "scene.toml")
    partial = err.partial_result if isinstance(err.partial_result, dict) else {}
    write_summary(out, {"scene": scene.name, "status": f"failed: {err}", "failure_time_s": err.time,
                        "last_state": partial, **provenance()})


def _solved(scene, out: Path | None, solve):
    """``solve()``, the rest of ``scene``; on a solver failure the scene, the cause and the last state
    are written to ``out`` (and the console says so) before the failure goes on."""
    try:
        return solve()
    except SolverFailure as err:
        if out is not None:
            _write_static_failure(scene, err, out)
            print(f"cdpr static: the scene, the cause and the last state are written to {out}/", file=sys.stderr)
        raise


def _static_spatial(scene, out: Path | None, quiet: bool) -> int:
    """``cdpr static`` on a spatial scene (:mod:`cdpr_exu.run.spatial_rest`); its warnings go to the console
    (and are in summary.json), a failure writes the scene, the cause and the last state."""
    rest = _solved(scene, out, lambda: solve_spatial_rest(scene))
    if out is not None:
        from cdpr_exu.post.plots import plot_spatial_rest  # matplotlib only where a figure is drawn

        clear_outputs(out, "static")  # no file of an earlier `cdpr static` there stays beside these
        rest.save(out)
        plot_spatial_rest(rest, out / "rest_profile.png")
    if not quiet:
        print_spatial_rest(rest, out)
    for text in rest.warnings:
        warnings.warn(text, SuspectAnswerWarning, stacklevel=2)
    return EXIT_OK


def print_spatial_rest(rest: SpatialRest, out: Path | None) -> None:
    """The static mode's summary on the terminal (its :attr:`SpatialRest.warnings` are the caller's to issue)."""
    x, y, z = rest.position
    roll, pitch, yaw = rotation_angles_deg(rest.rotation)
    catenary = rest.catenary
    print(f"{rest.scene.name} at rest (Exudyn's static solver, {rest.scene.cables[0].n_elements} elements per cable, "
          f"{rest.anchor_joint}; {rest.wall_time:.2f} s)")
    print(f"  platform at x = {x:.6f} m, y = {y:.6f} m, z = {z:.6f} m; rotation vector "
          f"{np.round(rest.rotation_vector, 6).tolist()} rad (roll {roll:.4f}, pitch {pitch:.4f}, yaw {yaw:.4f} deg)")
    for i, (tension, force) in enumerate(zip(rest.tensions_at_anchor, rest.forces_on_platform)):
        print(f"  cable {i + 1}: {tension:.4f} N at the anchor (catenary {catenary.tensions_at_anchor[i]:.4f} N), "
              f"force on platform {np.round(force, 4).tolist()} N")
    print(f"  elastic catenaries (no bending): platform at {np.round(catenary.position, 6).tolist()} m, "
          f"{1000 * np.linalg.norm(rest.position - catenary.position):.3f} mm and "
          f"{np.degrees(np.linalg.norm(rest.rotation_vector - catenary.rotation)):.4f} deg from the lumped robot")
    if rest.swivel_angles is not None:
        azimuths = [np.degrees(np.arctan2(*(c.anchor_point - c.inlet)[1::-1])) if c.inlet is not None else None
                    for c in catenary.cables]
        for i, (psi, azimuth) in enumerate(zip(rest.swivel_angles, azimuths)):
            if azimuth is not None:
                print(f"  swivel pulley {i + 1}: psi = {np.degrees(psi):.4f} deg (anchor azimuth {azimuth:.4f} deg), "
                      f"wrap {np.degrees(catenary.cables[i].wrap_angle):.2f} deg")
    if out is not None:
        print(f"  written to {out}/")


def _cmd_static(args: argparse.Namespace) -> int:
    out = check_output_folder(args.out, command="static")
    scene = load_scene(args.scene)
    if scene.dimension == 3:  # one rest pipeline in issue 24, slice 9
        return _static_spatial(scene, out, args.quiet)
    rest = _solved(scene, out, lambda: solve_rest(scene, tolerance=args.tolerance, max_time=args.max_time,
                                                  polish=not args.no_polish))
    if out is not None:
        from cdpr_exu.post.plots import plot_rest  # matplotlib only where a figure is drawn

        clear_outputs(out, "static")  # no file of an earlier `cdpr static` there stays beside these
        rest.save(out)
        plot_rest(scene, rest, out / "rest_profile.png")
    if not args.quiet:
        x, z = rest.platform_position_m
        print(f"{scene.name} at rest after {rest.time_s:.2f} s simulated ({rest.method}), "
              f"largest node speed {rest.max_node_speed_m_s:.2g} m/s")
        print(f"  platform at x = {fixed(x, 6)} m, z = {fixed(z, 6)} m, rotation {fixed(rest.platform_rotation_deg, 4)} deg")
        for i in range(len(rest.nodes)):
            print(f"  cable {i + 1}: free span {rest.cable_stretched_length_m[i]:.6f} m "
                  f"(unstrained {rest.cable_unstrained_length_m[i]:.6f} m), force on platform "
                  f"{np.round(rest.platform_forces_N[i], 4).tolist()} N, on upper support "
                  f"{np.round(rest.upper_forces_N[i], 4).tolist()} N")
        for note in rest.notes:
            print(f"  note: {note}")
        if out is not None:
            print(f"  written to {out}/")
    return EXIT_OK


def add_commands(subparsers) -> None:
    """Register ``cdpr static``."""
    parser = subparsers.add_parser(
        "static", help="bring a scene to rest and write its static state",
        description="Bring a scene to rest (dynamics with its own damping, then Exudyn's static solver) with the "
        "winches held, and write summary.json (platform pose, free-span lengths, end forces, nodes), rest.npz and "
        "rest_profile.png.", epilog=EPILOG + "\n" + EXIT_CODES, formatter_class=argparse.RawDescriptionHelpFormatter)
    parser.add_argument("scene", help="shipped scene name (see `cdpr scenes`) or path to a .toml file")
    parser.add_argument("--out", help="output folder (created); nothing is written without it")
    parser.add_argument("--tolerance", type=float, default=DEFAULT_TOLERANCE,
                        help=f"largest node speed counted as rest [m/s] (default {DEFAULT_TOLERANCE:g})")
    parser.add_argument("--max-time", type=float, default=DEFAULT_MAX_TIME,
                        help=f"give up after this much simulated time [s] (default {DEFAULT_MAX_TIME:g})")
    parser.add_argument("--no-polish", action="store_true", help="skip Exudyn's static solver after the dynamics")
    parser.add_argument("-q", "--quiet", action="store_true", help="print nothing")
    parser.set_defaults(func=_cmd_static)
