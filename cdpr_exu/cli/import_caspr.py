"""``cdpr import caspr``: a scene file from CASPR's model files (:mod:`cdpr_exu.scenes.caspr`).

Example::

    cdpr import caspr tests/data/caspr/CoGiRo_bodies.xml tests/data/caspr/CoGiRo_cables.xml --out cogiro.toml
"""

from __future__ import annotations

import argparse
from pathlib import Path

import tomli_w

from cdpr_exu.core.errors import EXIT_CODES, EXIT_OK, OutputError
from cdpr_exu.scenes.caspr import MATERIAL_FROM, caspr_scene

EPILOG = f"""examples:
  cdpr import caspr tests/data/caspr/CoGiRo_bodies.xml tests/data/caspr/CoGiRo_cables.xml --out cogiro.toml
  cdpr import caspr IPAnema_1_bodies.xml IPAnema_1_cables.xml --cable-set IROS_CASPR_2016 --n-elements 10 --out ipanema.toml

The scene holds CASPR's exits, anchors (moved to the centre of mass), mass, inertia (its diagonal),
tension limits and initial pose (held by a "hold" trajectory); the cables' material, effects, winch
and solver are those of {MATERIAL_FROM} unless given. Then: cdpr static cogiro.toml, cdpr run cogiro.toml.
Nothing is written when the files hold what a scene cannot express (more than one link, a cable model
other than cable_ideal, a cable through more than two attachments); the message names the element.
"""

#: The cable options: (option, CableSpec field, type, help).
MATERIAL_OPTIONS = (("--radius", "radius", float, "cable radius [m]"),
                    ("--linear-density", "linear_density", float, "mass per length [kg/m]"),
                    ("--youngs-modulus", "youngs_modulus", float, "effective Young's modulus [Pa]"),
                    ("--damping-constant", "damping_constant", float, "Kelvin-Voigt damping [N s/m^2]"),
                    ("--n-elements", "n_elements", int, "elements per cable"))


def _cmd_caspr(args: argparse.Namespace) -> int:
    out = Path(args.out)
    if out.is_dir():
        raise OutputError(f"--out {str(out)!r} is a folder; give the scene file to write (e.g. robot.toml)")
    material = {field: getattr(args, field) for _, field, _, _ in MATERIAL_OPTIONS if getattr(args, field) is not None}
    scene, notes = caspr_scene(args.bodies, args.cables, cable_set=args.cable_set, name=args.name, **material)
    header = [f"# {scene.description} (cdpr import caspr).", *(f"# {note}." for note in notes),
              "# Units SI; z up, gravity along -z.", ""]
    out.parent.mkdir(parents=True, exist_ok=True)
    out.write_text("\n".join(header) + tomli_w.dumps(scene.to_dict()))
    print(f"{scene.name}: {scene.n_cables} cables, {scene.platform.mass:g} kg platform; written to {out}")
    return EXIT_OK


def add_commands(subparsers) -> None:
    """Register ``cdpr import caspr``."""
    importer = subparsers.add_parser("import", help="write a scene from another tool's model files",
                                     epilog="example:\n  cdpr import caspr BODIES.xml CABLES.xml --out robot.toml\n\n"
                                     + EXIT_CODES, formatter_class=argparse.RawDescriptionHelpFormatter)
    caspr = importer.add_subparsers(dest="format", required=True).add_parser(
        "caspr", help="a spatial scene from CASPR's <robot>_bodies.xml and <robot>_cables.xml",
        description="Write a spatial scene (TOML) from CASPR's model files: one rigid link, ideal cables.",
        epilog=EPILOG + "\n" + EXIT_CODES, formatter_class=argparse.RawDescriptionHelpFormatter)
    caspr.add_argument("bodies", help="CASPR's bodies file (<bodies_system>)")
    caspr.add_argument("cables", help="CASPR's cables file (<cables>)")
    caspr.add_argument("--out", required=True, help="the scene file to write (.toml)")
    caspr.add_argument("--cable-set", help="the <cable_set id> to read (default: the file's default_cable_set)")
    caspr.add_argument("--name", help="the scene's name (default: the link's name)")
    for option, field, kind, text in MATERIAL_OPTIONS:
        caspr.add_argument(option, dest=field, type=kind, help=f"{text} (default: {MATERIAL_FROM}'s)")
    caspr.set_defaults(func=_cmd_caspr)
