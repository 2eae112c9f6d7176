"""Reproduce the paper's Fig. 8: the lumped cable model at rest against the elastic catenary.

Run:  python examples/catenary_validation.py [--out results/catenary_validation] [--max-elements 120]

Writes into the output folder:

* ``profiles.png``: the rest profiles of the lumped model (markers) and the elastic
  catenary (dashed red, as in the paper), for the cables fixed at the pulley centres
  (``paper-catenary-fixed``) and over the pulleys (``paper-catenary``), with and
  without bending; and the distance of each node from the catenary along the cable,
  with the bending boundary layers sqrt(EI/T) marked;
* ``convergence.png`` / ``convergence.csv``: bending off, n = 4 ... 120 elements, the
  errors of the rest position and of the cable length against the catenary, for the
  consistent and the paper's mass lumping, with the observed orders (fitted slopes);
* ``summary.json``: every number printed.

Two catenaries are compared with each lumped rest state:

* *forward*: the catenary with the same unstrained lengths and upper ends
  (``solve_statics``): where the catenary puts the platform;
* *inverse* (the paper's "inverse kineto-static analysis"): the catenary through the
  lumped model's rest position (``solve_inverse_statics``): the cable length the
  catenary needs to hold the platform there. The paper's 0.8 mm is a length difference
  of this kind; with the same unstrained length (forward), the stretched lengths of the
  two models differ only through their tensions (/EA), by nanometres.

Cable lengths are free-span lengths (see :mod:`cdpr_exu.run.rest`): for the pulley scene
from the point where the cable leaves the rim to the anchor, against the catenary's
suspended part. Profile distances are the distances of the free-span nodes from the
catenary curve (sampled at 4001 points; sampling error below 1e-7 m).
"""

from __future__ import annotations

import argparse
import csv
import json
import math
import time
from dataclasses import replace
from pathlib import Path

import numpy as np
from cdpr_exu.core.output import split_timing, write_summary
from matplotlib.backends.backend_agg import FigureCanvasAgg
from matplotlib.figure import Figure
from matplotlib.patches import Circle

from cdpr_exu.physics import catenary
from cdpr_exu.run.rest import Rest, solve_rest
from cdpr_exu.results.result import provenance
from cdpr_exu.scenes.scene import Effects, Scene, load_scene
from cdpr_exu.statics.statics import solve_statics, solve_inverse_statics
from cdpr_exu.statics.statics import catenary_platform

#: What the paper reports for Fig. 8 with 15 elements [m].
PAPER_LENGTH_DIFFERENCE = 0.8e-3
#: Element counts of the convergence study.
ELEMENT_COUNTS = (4, 8, 15, 30, 60, 120)
#: Smallest n used in the fit of the observed order (below it the error is not yet
#: in its asymptotic range).
FIT_FROM = 8
#: Samples of each catenary curve for the node-to-curve distances.
CURVE_SAMPLES = 4001
DPI = 150

#: How to read the numbers (written into summary.json).
NOTES = {
    "cable_length": "Free-span lengths. 'inverse_length_difference_m' = lumped stretched length minus the stretched "
                    "length of the catenary through the lumped rest position (the paper's inverse kineto-static "
                    "comparison). With the same unstrained length (forward) the stretched lengths differ only "
                    "through the tensions, by nanometres; the difference shows in the rest position instead.",
    "fixed_ends": "The clean comparison: same end points, no pulley. Bending off, consistent lumping: the lumped "
                  "rest converges to the catenary at second order (paper's lumping: first order).",
    "bending": "Bending straightens the cable over a boundary layer sqrt(EI/T) (0.22 m at the anchor, 0.17 m at "
               "the top) at its pinned ends; beyond it the cable runs like a catenary whose ends are moved by "
               "kappa EI/T towards the inside of the curve (14 mm at the anchor, 3.6 mm at the top). So the "
               "lumped cable sags about 8 mm less than the catenary through the same end points, the catenary "
               "needs about 3.2 mm more cable to put the platform where the lumped model does, and with the same "
               "cable the lumped platform hangs 4.4 mm lower. These do not vanish with n (n = 15, 30, 60 agree "
               "within 0.1 mm): they are the physics of a cable with EI = 0.49 N m^2, which the catenary lacks.",
    "pulleys": "Over the pulleys the comparison is dominated by the discretisation of the wrap: 0.25 m elements "
               "on a 0.25 m pulley wrap it as a polygon of chords about 26 mm shorter than the arc (chord_deficit_m),"
               " so the lumped platform hangs about 3 cm lower than the catenary with the same cable; where the "
               "polygon leaves the rim is uncertain by a good part of an element, which moves the free-span length "
               "by centimetres; and with bending (k_theta = 1.96 N m/rad per joint against T l0i = 3-4 N m) the "
               "cable does not follow the 0.25 m rim at all but lifts off it.",
}


# --------------------------------------------------------------------------- scenes


def with_elements(scene: Scene, n: int, lumping: str | None = None) -> Scene:
    """The scene with ``n`` elements per cable (and the given mass lumping)."""
    return scene.with_changes(cables=tuple(
        replace(c, n_elements=n, **({"mass_lumping": lumping} if lumping else {})) for c in scene.cables))


def over_pulleys(scene: Scene) -> bool:
    """True when the cables run over their pulleys (not from fixed exit points)."""
    return any(exit_.wraps for exit_ in scene.exits)


def bending_off(scene: Scene) -> Scene:
    """The scene with the "catenary" preset: mass and elasticity, no bending."""
    return scene.with_changes(effects=Effects.from_preset("catenary",
                                                          pulley_contact=over_pulleys(scene)))


# --------------------------------------------------------------------------- catenary side


def hang_point_unstrained_length(scene: Scene, rest: Rest, i: int) -> float:
    """Unstrained length of lumped cable ``i`` beyond its pulley's hang point [m].

    The hanging leg runs up from node 0 along x = c_x + side r_p; the hang point is where
    it reaches the pulley centre's height. The element crossing that height counts by
    the fraction of it below (its stretch is uniform). For a point exit: the whole cable.
    """
    cable = scene.cables[i]
    if not over_pulleys(scene):
        return cable.unstrained_length
    nodes, height = rest.nodes[i], scene.exits[i].center[1]
    k = int(np.flatnonzero(nodes[1:, 1] >= height)[0])
    fraction = (height - nodes[k, 1]) / (nodes[k + 1, 1] - nodes[k, 1])
    return cable.unstrained_length - (k + fraction) * cable.element_length


def catenary_curves(scene: Scene, equilibrium) -> list[np.ndarray]:
    """Points (x, z) of each catenary's suspended part, anchor first, shape (CURVE_SAMPLES, 2) [m]."""
    platform = catenary_platform(scene)
    curves = []
    for model, cable in zip(platform.cables, equilibrium.cables):
        shape = model.catenary(cable.suspended_length)
        s = np.linspace(0.0, cable.suspended_length, CURVE_SAMPLES)
        curves.append(cable.anchor_point + catenary.profile(shape, cable.catenary, s))
    return curves


def distances_to_curve(points: np.ndarray, curve: np.ndarray) -> np.ndarray:
    """Distance of each point from a polyline, shape (len(points),) [m]."""
    a, b = curve[:-1], curve[1:]
    d = b - a
    length2 = np.einsum("ij,ij->i", d, d)
    out = np.empty(len(points))
    for k, p in enumerate(points):
        t = np.clip(np.einsum("ij,ij->i", p - a, d) / length2, 0.0, 1.0)
        out[k] = np.sqrt(((a + t[:, None] * d - p) ** 2).sum(axis=1)).min()
    return out


def free_span_points(rest: Rest, i: int) -> np.ndarray:
    """The leave point (or node 0) and the free nodes of cable i, upper end first."""
    return np.vstack([rest.upper_points_m[i], rest.nodes[i][rest.first_free_node[i] + 1:]]) \
        if rest.first_free_node[i] > 0 else rest.nodes[i]


def compare(scene: Scene, rest: Rest) -> dict:
    """Forward and inverse catenary against a lumped rest state; numbers in SI."""
    platform = catenary_platform(scene)
    lengths = [hang_point_unstrained_length(scene, rest, i) for i in range(scene.n_cables)]
    forward = solve_statics(platform, lengths, initial_pose=rest.position)
    inverse = solve_inverse_statics(platform, rest.position)
    out = {
        "scene": scene.name, "effects": scene.effects.preset, "n_elements": scene.cables[0].n_elements,
        "mass_lumping": scene.cables[0].mass_lumping, "method": rest.method,
        "max_node_speed_m_s": rest.max_node_speed_m_s,
        "lumped_position_m": rest.position.tolist(),
        "catenary_position_m": forward.position.tolist(),
        "position_difference_m": (rest.position - forward.position).tolist(),
        "position_error_m": float(np.hypot(*(rest.position - forward.position))),
        "lumped_stretched_length_m": rest.cable_stretched_length_m.tolist(),
        "lumped_unstrained_length_m": rest.cable_unstrained_length_m.tolist(),
        "unstrained_length_beyond_hang_point_m": lengths,
    }
    curves_forward, curves_inverse = catenary_curves(scene, forward), catenary_curves(scene, inverse)
    per_cable = []
    for i in range(scene.n_cables):
        points = free_span_points(rest, i)
        d_forward = distances_to_curve(points, curves_forward[i])
        d_inverse = distances_to_curve(points, curves_inverse[i])
        cable = {
            "forward_stretched_length_m": forward.cables[i].catenary.stretched_length,
            "forward_length_difference_m": rest.cable_stretched_length_m[i] - forward.cables[i].catenary.stretched_length,
            "inverse_stretched_length_m": inverse.cables[i].catenary.stretched_length,
            "inverse_unstrained_length_m": inverse.cables[i].suspended_length,
            "inverse_length_difference_m": rest.cable_stretched_length_m[i] - inverse.cables[i].catenary.stretched_length,
            "inverse_unstrained_length_difference_m":
                rest.cable_unstrained_length_m[i] - inverse.cables[i].suspended_length,
            "max_distance_to_forward_catenary_m": float(d_forward.max()),
            "max_distance_to_inverse_catenary_m": float(d_inverse.max()),
            "node_distances_to_inverse_catenary_m": d_inverse.tolist(),
            "lumped_leave_point_m": rest.upper_points_m[i].tolist(),
            "catenary_tangent_point_m": inverse.cables[i].exit_point.tolist(),
            "lumped_platform_force_N": rest.platform_forces[i].tolist(),
            "inverse_platform_force_N": inverse.cables[i].force_on_platform.tolist(),
        }
        if over_pulleys(scene):
            # the whole cable beyond the hang point (wrap included), which the chords shorten
            cable["chord_deficit_m"] = chord_deficit(scene, rest, i)
            cable["inverse_total_unstrained_length_m"] = inverse.cables[i].unstrained_length
            cable["total_unstrained_length_difference_m"] = lengths[i] - inverse.cables[i].unstrained_length
        cable["lumped_sag_m"] = sag(points)
        cable["catenary_sag_m"] = sag(curves_inverse[i][::-1])
        per_cable.append(cable)
    out["cables"] = per_cable
    out["_curves"] = {"forward": curves_forward, "inverse": curves_inverse}
    return out


def sag(points: np.ndarray) -> float:
    """Largest distance of a polyline below the chord between its end points [m]."""
    chord = points[-1] - points[0]
    normal = np.array([chord[1], -chord[0]]) / np.hypot(*chord)
    if normal[1] > 0.0:
        normal = -normal
    return float(((points - points[0]) @ normal).max())


def chord_deficit(scene: Scene, rest: Rest, i: int) -> float:
    """How much shorter the lumped cable's path over the pulley is than the rim [m].

    From the hang point to the leave point, the lumped cable runs along straight chords
    (its nodes touch the rim, its elements cut inside it); a real cable follows the arc.
    Measured along the rest state: arc length minus the polygon's length.
    """
    pulley, nodes, c = scene.exits[i], rest.nodes[i], int(rest.first_free_node[i]) - 1
    center, radius = np.asarray(pulley.center), pulley.radius
    k = int(np.flatnonzero(nodes[1:, 1] >= center[1])[0])
    fraction = (center[1] - nodes[k, 1]) / (nodes[k + 1, 1] - nodes[k, 1])
    start = nodes[k] + fraction * (nodes[k + 1] - nodes[k])
    path = np.vstack([start, nodes[k + 1:c + 2]])
    polygon = np.linalg.norm(np.diff(path, axis=0), axis=1).sum() - np.hypot(*(nodes[c + 1] - rest.upper_points_m[i]))
    leave = rest.upper_points_m[i]
    phi = math.atan2(leave[1] - center[1], leave[0] - center[0])
    wrap = (math.pi - phi) % (2 * math.pi) if pulley.side < 0 else phi % (2 * math.pi)  # from the hang point
    arc = radius * wrap
    return float(arc - polygon)


# --------------------------------------------------------------------------- studies


def rest_comparisons(scenes: dict[str, Scene]) -> dict[str, tuple[Scene, Rest, dict]]:
    out = {}
    for label, scene in scenes.items():
        rest = solve_rest(scene)
        out[label] = (scene, rest, compare(scene, rest))
        c = out[label][2]
        print(f"{label:28s} {rest.method:28s} z = {rest.position[1]:.6f} m (catenary "
              f"{c['catenary_position_m'][1]:.6f}), free span {rest.cable_stretched_length_m[0]:.6f} m, "
              f"dL(inverse) = {1000 * c['cables'][0]['inverse_length_difference_m']:+.4f} mm, "
              f"max distance {1000 * c['cables'][0]['max_distance_to_inverse_catenary_m']:.3f} mm "
              f"({rest.wall_time_s:.1f} s)", flush=True)
    return out


def convergence(counts, lumpings=("consistent", "paper")) -> list[dict]:
    """Bending off, fixed ends: errors of the rest state against the catenary over n."""
    base = bending_off(load_scene("paper-catenary-fixed"))
    platform = catenary_platform(base)
    reference = solve_statics(platform, [c.unstrained_length for c in base.cables])
    reference_length = reference.cables[0].catenary.stretched_length
    rows = []
    for lumping in lumpings:
        for n in counts:
            scene = with_elements(base, n, lumping)
            rest = solve_rest(scene)
            inverse = solve_inverse_statics(platform, rest.position)
            row = {
                "mass_lumping": lumping, "n_elements": n,
                "position_error_m": float(np.hypot(*(rest.position - reference.position))),
                "z_error_m": float(rest.position[1] - reference.position[1]),
                "stretched_length_error_m": float(rest.cable_stretched_length_m[0] - reference_length),
                "inverse_length_error_m": float(base.cables[0].unstrained_length - inverse.cables[0].suspended_length),
                "max_node_speed_m_s": rest.max_node_speed_m_s,
                "wall_time_s": rest.wall_time_s,
            }
            rows.append(row)
            print(f"  {lumping:10s} n = {n:3d}: position error {row['position_error_m']:.3e} m, stretched length "
                  f"error {row['stretched_length_error_m']:+.3e} m, length the catenary needs "
                  f"{row['inverse_length_error_m']:+.3e} m ({rest.wall_time_s:.1f} s)", flush=True)
    return rows


def observed_order(rows: list[dict], lumping: str, key: str) -> float:
    """Slope of log|error| over log n for n >= FIT_FROM (error ~ n^-order)."""
    selected = [r for r in rows if r["mass_lumping"] == lumping and r["n_elements"] >= FIT_FROM]
    n = np.array([r["n_elements"] for r in selected], float)
    e = np.abs([r[key] for r in selected])
    return float(-np.polyfit(np.log(n), np.log(e), 1)[0])


# --------------------------------------------------------------------------- figures


def _figure(width, height):
    figure = Figure(figsize=(width, height))
    FigureCanvasAgg(figure)
    return figure


def plot_profiles(cases: dict, path: Path) -> Path:
    """The paper's Fig. 8 for both scenes, the node distances along the cable, and a pulley close-up."""
    figure = _figure(12.0, 9.6)
    boxes = ([0.06, 0.55, 0.42, 0.41], [0.56, 0.55, 0.42, 0.41], [0.06, 0.06, 0.42, 0.38], [0.56, 0.06, 0.42, 0.38])
    axes = [figure.add_axes(box) for box in boxes]
    panels = ((axes[0], "fixed, bending", "fixed, no bending", "cable ends fixed at the pulley centres"),
              (axes[1], "pulleys, bending", "pulleys, no bending", "over the pulleys"),
              (axes[3], "pulleys, bending", "pulleys, no bending", "close-up of the left pulley"))
    for ax, on, off, title in panels:
        scene, rest, comparison = cases[on]
        _, rest_off, comparison_off = cases[off]
        if over_pulleys(scene):
            for pulley in scene.exits:
                ax.add_patch(Circle(pulley.center, pulley.radius, facecolor="0.93", edgecolor="0.6", zorder=1))
        for i in range(scene.n_cables):
            for data, color, label in ((comparison, "red", "elastic catenary through the lumped rest position "
                                        "(bending on)"), (comparison_off, "tab:purple", None)):
                curve = data["_curves"]["inverse"][i]
                if data is comparison_off and ax is not axes[3]:
                    continue
                ax.plot(curve[:, 0], curve[:, 1], "--", color=color, linewidth=1.3, zorder=2,
                        label=(label if data is comparison else "elastic catenary through the bending-off rest")
                        if i == 0 else None)
            ax.plot(rest.nodes[i][:, 0], rest.nodes[i][:, 1], "o-", color="tab:blue", markersize=4, linewidth=0.5,
                    zorder=3, markerfacecolor="none", label="lumped, bending on (paper's model)" if i == 0 else None)
            ax.plot(rest_off.nodes[i][:, 0], rest_off.nodes[i][:, 1], "x", color="tab:green", markersize=5,
                    zorder=3, label="lumped, bending off" if i == 0 else None)
            if over_pulleys(scene):
                ax.plot(*rest.upper_points_m[i], "+", color="tab:blue", markersize=9, zorder=4)
                ax.plot(*rest_off.upper_points_m[i], "+", color="tab:green", markersize=9, zorder=4)
        x, z = rest.position
        ax.plot(x, z, "s", color="0.2", markersize=6, zorder=4, label="platform (1 kg point mass)")
        c_on, c_off = comparison["cables"][0], comparison_off["cables"][0]
        if ax is axes[3]:
            ax.set_xlim(-2.15, -0.95)
            ax.set_ylim(-0.45, 0.45)
            text = (f"chord deficit of the wrap: {1000 * c_off['chord_deficit_m']:.1f} mm (no bending)\n"
                    f"+: leave points of the lumped cable\n"
                    f"cable beyond the hang point, lumped - catenary:\n"
                    f"  {1000 * c_on['total_unstrained_length_difference_m']:+.1f} mm (bending), "
                    f"{1000 * c_off['total_unstrained_length_difference_m']:+.1f} mm (no bending)")
            ax.text(0.98, 0.98, text, transform=ax.transAxes, ha="right", va="top", fontsize=7.5,
                    bbox=dict(facecolor="white", edgecolor="0.7", alpha=0.9))
        else:
            text = (f"n = 15, free span, lumped - catenary:\nlength {1000 * c_on['inverse_length_difference_m']:+.2f} mm "
                    f"(bending), {1000 * c_off['inverse_length_difference_m']:+.2f} mm (no bending)\n"
                    f"max node distance {1000 * c_on['max_distance_to_inverse_catenary_m']:.2f} mm, "
                    f"{1000 * c_off['max_distance_to_inverse_catenary_m']:.2f} mm\n"
                    f"platform vs same-length catenary: {1000 * comparison['position_difference_m'][1]:+.2f} mm, "
                    f"{1000 * comparison_off['position_difference_m'][1]:+.2f} mm in z")
            ax.text(0.5, 0.98, text, transform=ax.transAxes, ha="center", va="top", fontsize=7.5,
                    bbox=dict(facecolor="white", edgecolor="0.7", alpha=0.9))
            ax.set_ylim(-1.95, 1.0)
        ax.set_aspect("equal")
        ax.set_title(f"{scene.name}: {title}", fontsize=9)
        ax.set_xlabel("x [m]")
        ax.set_ylabel("z [m]")
        ax.grid(True, linewidth=0.4, alpha=0.5)
    handles, labels = axes[3].get_legend_handles_labels()
    figure.legend(handles, labels, loc="center", bbox_to_anchor=(0.5, 0.495), ncol=3, fontsize=7.5, frameon=False)
    ax = axes[2]
    styles = (("fixed, bending", "tab:blue", "o", "bending on, n = 15"),
              ("fixed, bending, n = 30", "tab:cyan", "^", "bending on, n = 30"),
              ("fixed, bending, n = 60", "tab:gray", ".", "bending on, n = 60"),
              ("fixed, no bending", "tab:green", "x", "bending off, n = 15"))
    for label, color, marker, legend in styles:
        if label not in cases:
            continue
        scene, rest, comparison = cases[label]
        cable = scene.cables[0]
        d = np.asarray(comparison["cables"][0]["node_distances_to_inverse_catenary_m"])
        s = cable.unstrained_length - np.arange(len(d)) * cable.element_length  # from the anchor
        ax.plot(s, 1000 * d, marker=marker, color=color, linewidth=1.0, markersize=4, label=legend)
    scene, rest, comparison = cases["fixed, bending"]
    cable = scene.cables[0]
    layers = boundary_layers(scene, comparison)
    ax.axvspan(0.0, layers["anchor"]["length_m"], color="0.88", zorder=0,
               label="boundary layers sqrt(EI/T)")
    ax.axvspan(cable.unstrained_length - layers["upper_end"]["length_m"], cable.unstrained_length, color="0.88",
               zorder=0)
    for end, s_end in (("anchor", 0.0), ("upper_end", cable.unstrained_length)):
        ax.plot(s_end, 1000 * layers[end]["end_offset_m"], marker="*", color="k", markersize=9, zorder=5,
                label="predicted offset kappa EI/T at each end" if end == "anchor" else None)
    ax.set_xlabel("unstrained arc length from the anchor [m]")
    ax.set_ylabel("node distance from the catenary [mm]")
    ax.set_title("fixed ends: node distance from the catenary through the same end points", fontsize=9)
    ax.grid(True, linewidth=0.4, alpha=0.5)
    ax.legend(fontsize=7)
    path.parent.mkdir(parents=True, exist_ok=True)
    figure.savefig(path, dpi=DPI)
    return path


def boundary_layers(scene: Scene, comparison: dict) -> dict:
    """Bending boundary layer at each end of cable 0, from the catenary through the same end points.

    A cable of bending stiffness EI pinned at its ends (no moment there) cannot carry the
    catenary's curvature kappa = w H / T^2 right up to the end: over the length
    lambda = sqrt(EI / T) it straightens, and beyond that it runs like a catenary whose
    end is moved by kappa lambda^2 = kappa EI / T towards the inside of the curve.
    """
    cable = scene.cables[0]
    bending = cable.youngs_modulus * cable.second_moment
    weight = cable.linear_density * scene.gravity
    platform = catenary_platform(scene)
    equilibrium = solve_inverse_statics(platform, comparison["lumped_position_m"])
    state = equilibrium.cables[0].catenary
    out = {}
    for end, tension in (("anchor", state.tension_a), ("upper_end", state.tension_b)):
        curvature = weight * state.horizontal_tension / tension**2
        out[end] = {"tension_N": tension, "length_m": math.sqrt(bending / tension), "catenary_curvature_1_m": curvature,
                    "end_offset_m": curvature * bending / tension}
    return out


def plot_convergence(rows: list[dict], orders: dict, path: Path) -> Path:
    figure = _figure(10.0, 4.4)
    axes = [figure.add_axes(box) for box in ([0.08, 0.13, 0.39, 0.73], [0.58, 0.13, 0.39, 0.73])]
    styles = {"consistent": ("tab:blue", "o"), "paper": ("tab:orange", "s")}
    for ax, key, title in ((axes[0], "position_error_m", "rest position of the platform"),
                           (axes[1], "inverse_length_error_m", "cable length the catenary needs to rest there too")):
        for lumping, (color, marker) in styles.items():
            selected = [r for r in rows if r["mass_lumping"] == lumping]
            n = np.array([r["n_elements"] for r in selected])
            e = np.abs([r[key] for r in selected])
            ax.loglog(n, e, marker=marker, color=color,
                      label=f"{lumping} lumping: order {orders[lumping][key]:.2f}")
        n_ref = np.array([4.0, 120.0])
        first = [r for r in rows if r["mass_lumping"] == "paper"][0]
        second = [r for r in rows if r["mass_lumping"] == "consistent"][0]
        ax.loglog(n_ref, abs(first[key]) * 1.6 * (n_ref / first["n_elements"]) ** -1.0, ":", color="0.5",
                  label="slope 1")
        ax.loglog(n_ref, abs(second[key]) * 0.6 * (n_ref / second["n_elements"]) ** -2.0, "--", color="0.5",
                  label="slope 2")
        ax.axvline(15, color="0.8", linewidth=0.8)
        ax.set_xlabel("elements per cable n")
        ax.set_ylabel("|error| [m]")
        ax.set_title(title, fontsize=9)
        ax.grid(True, which="both", linewidth=0.3, alpha=0.5)
        ax.legend(fontsize=7.5)
    figure.suptitle("bending off, cable ends fixed: lumped model at rest vs elastic catenary "
                    f"(orders fitted for n >= {FIT_FROM})", fontsize=9)
    figure.savefig(path, dpi=DPI)
    return path


# --------------------------------------------------------------------------- main


def _clean(data):
    """JSON-ready copy (no curves, floats not numpy)."""
    if isinstance(data, dict):
        return {k: _clean(v) for k, v in data.items() if not k.startswith("_")}
    if isinstance(data, (list, tuple)):
        return [_clean(v) for v in data]
    if isinstance(data, (np.floating, np.integer)):
        return data.item()
    if isinstance(data, np.ndarray):
        return data.tolist()
    return data


def main(argv=None) -> int:
    parser = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    parser.add_argument("--out", default="results/catenary_validation")
    parser.add_argument("--max-elements", type=int, default=max(ELEMENT_COUNTS),
                        help="largest n of the convergence study (default 120: about a minute more)")
    args = parser.parse_args(argv)
    out = Path(args.out)
    out.mkdir(parents=True, exist_ok=True)
    start = time.perf_counter()

    fixed, pulleys = load_scene("paper-catenary-fixed"), load_scene("paper-catenary")
    print("(a, c) n = 15, rest states against the elastic catenary")
    cases = rest_comparisons({
        "fixed, bending": fixed, "fixed, no bending": bending_off(fixed),
        "fixed, no bending, paper lumping": with_elements(bending_off(fixed), 15, "paper"),
        "fixed, bending, paper lumping": with_elements(fixed, 15, "paper"),
        "fixed, bending, n = 30": with_elements(fixed, 30), "fixed, bending, n = 60": with_elements(fixed, 60),
        "pulleys, bending": pulleys, "pulleys, no bending": bending_off(pulleys),
    })
    plot_profiles(cases, out / "profiles.png")

    print("(b) convergence, bending off, fixed ends")
    rows = convergence([n for n in ELEMENT_COUNTS if n <= args.max_elements])
    keys = ("position_error_m", "stretched_length_error_m", "inverse_length_error_m")
    orders = {lumping: {key: observed_order(rows, lumping, key) for key in keys} for lumping in ("consistent", "paper")}
    stable_rows, _ = split_timing(rows)  # each run's wall time goes to timing.json, with the summary's
    with (out / "convergence.csv").open("w", newline="") as handle:
        writer = csv.DictWriter(handle, fieldnames=list(stable_rows[0]))
        writer.writeheader()
        writer.writerows(stable_rows)
    plot_convergence(rows, orders, out / "convergence.png")

    # (c) the bending effect, and the boundary layers it lives in
    scene, rest_on, c_on = cases["fixed, bending"]
    _, rest_off, c_off = cases["fixed, no bending"]
    layers = boundary_layers(scene, c_on)
    bending = {
        "EI_N_m2": scene.cables[0].youngs_modulus * scene.cables[0].second_moment,
        "boundary_layers": layers,
        "platform_lower_with_bending_m": float(rest_off.position[1] - rest_on.position[1]),
        "max_node_distance_between_bending_on_and_off_m":
            float(np.linalg.norm(rest_on.nodes[0] - rest_off.nodes[0], axis=1).max()),
        "anchor_angle_difference_deg": _anchor_angle_difference(rest_on, c_on),
        "by_n": {label: {"n_elements": c["n_elements"],
                         "max_distance_to_catenary_m": c["cables"][0]["max_distance_to_inverse_catenary_m"],
                         "length_difference_m": c["cables"][0]["inverse_length_difference_m"],
                         "platform_z_difference_to_same_length_catenary_m": c["position_difference_m"][1],
                         "lumped_sag_m": c["cables"][0]["lumped_sag_m"],
                         "catenary_sag_m": c["cables"][0]["catenary_sag_m"]}
                 for label, (_, _, c) in cases.items() if label.startswith("fixed")},
    }
    n15 = {lumping: next(r for r in rows if r["mass_lumping"] == lumping and r["n_elements"] == 15)
           for lumping in ("consistent", "paper")}
    summary = {
        "description": "The paper's Fig. 8 (scenario 2): lumped cable model at rest against the elastic catenary",
        "paper": {"length_difference_m": PAPER_LENGTH_DIFFERENCE, "n_elements": 15},
        "cases": {label: _clean(c) for label, (_, _, c) in cases.items()},
        "convergence": {"rows": rows, "observed_orders": orders, "fit_from_n": FIT_FROM, "n15": n15},
        "bending": bending,
        "notes": NOTES,
        "wall_time_s": time.perf_counter() - start,
        **provenance(),
    }
    write_summary(out, _clean(summary))  # wall time and date go to timing.json

    print("\n(d) cable length at n = 15 (catenary through the lumped rest position; the paper: 0.8 mm)")
    for label, (_, _, c) in cases.items():
        d = c["cables"][0]
        print(f"  {label:34s} stretched {1000 * d['inverse_length_difference_m']:+.4f} mm, unstrained "
              f"{1000 * d['inverse_unstrained_length_difference_m']:+.4f} mm; max node distance "
              f"{1000 * d['max_distance_to_inverse_catenary_m']:.3f} mm; platform vs same-length catenary "
              f"{1000 * c['position_difference_m'][1]:+.3f} mm in z")
    print("observed orders (n >= 8):", json.dumps(orders, indent=None))
    print(f"bending: boundary layers {layers['anchor']['length_m']:.3f} m (anchor), "
          f"{layers['upper_end']['length_m']:.3f} m (top), predicted end offsets "
          f"{1000 * layers['anchor']['end_offset_m']:.1f} mm and {1000 * layers['upper_end']['end_offset_m']:.1f} mm; "
          f"platform {1000 * bending['platform_lower_with_bending_m']:.2f} mm lower with bending; nodes move up to "
          f"{1000 * bending['max_node_distance_between_bending_on_and_off_m']:.2f} mm")
    for label, row in bending["by_n"].items():
        print(f"  {label:34s} max distance {1000 * row['max_distance_to_catenary_m']:.2f} mm, sag lumped "
              f"{1000 * row['lumped_sag_m']:.2f} mm, catenary {1000 * row['catenary_sag_m']:.2f} mm")
    print(f"written to {out}/ in {time.perf_counter() - start:.0f} s")
    return 0


def _anchor_angle_difference(rest: Rest, comparison: dict) -> float:
    """Angle between the lumped anchor element and the catenary's tangent at the anchor [deg]."""
    nodes = rest.nodes[0]
    lumped = nodes[-2] - nodes[-1]
    curve = comparison["_curves"]["inverse"][0]
    tangent = curve[1] - curve[0]
    return float(np.degrees(math.atan2(lumped[0] * tangent[1] - lumped[1] * tangent[0], lumped @ tangent)))


if __name__ == "__main__":
    raise SystemExit(main())
