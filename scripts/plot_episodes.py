#!/usr/bin/env python3
"""Pictures of a closed-loop run (called by the plant simulator; usable by hand).

  plot_episodes.py --csv RUN.csv --policy POLICY.h5 --initial-state "x0, x1, ..." \
                   --trajectories OUT1.png --values OUT2.png \
                   [--footprint "length, width, rear_to_reference, x_index, y_index, yaw_index"] \
                   [--scene SCENE.yaml]

OUT1: the episodes' trajectories over the sets in the x0/x1 plane (success green, failure red),
with the grid bounds, target (green), avoid (red) and safe (blue) boxes (every box of a set that
is a list of boxes) from the configuration stored in the policy file. With --footprint (a car: metres, the state coordinates of its reference
point and yaw) the car's body is drawn at every step of every episode; with --scene the picture's
scene (config/bmw_parking_scene.yaml: the bay, parked cars and kerbs, metres) is drawn under it,
and every footprint is checked against the scene's obstacles (the result is printed and in the
title). OUT2: V_0 over the x0/x1 slice of the grid, the other coordinates at the start state's
cell, with the sets outlined: for continuous-system bounds (guarantee: system) the lower bound
(this policy) and the upper bound (any controller) side by side on one colour scale; for the
abstraction its value, labelled as no guarantee for the real system. Needs python3-matplotlib,
python3-h5py, python3-yaml (Debian).
"""
import argparse
import csv
import sys

import matplotlib

matplotlib.use("Agg")
import h5py  # noqa: E402
import matplotlib.pyplot as plt  # noqa: E402
import numpy as np  # noqa: E402
import yaml  # noqa: E402
from matplotlib.patches import Polygon, Rectangle  # noqa: E402


def read_policy(path):
    with h5py.File(path, "r") as f:
        config_text = text_of(f["config"][()])
        lb = np.asarray(f["states/lb"][()], dtype=float)
        eta = np.asarray(f["states/eta"][()], dtype=float)
        counts = np.asarray(f["states/counts"][()], dtype=int)
        # Cell faces per dimension: stored by newer files (docs/policy_file.md), else uniform.
        if "faces" in f["states"]:
            faces = [np.asarray(f[f"states/faces/{d}"][()], dtype=float) for d in range(len(counts))]
        else:
            faces = [lb[d] + (np.arange(counts[d] + 1) - 0.5) * eta[d] for d in range(len(counts))]
        upper = None
        if "upper_values" in f:
            upper = np.asarray(f["upper_values"][()])
            # (horizon+1, n0, ...) for a bounded horizon, (n0, ...) for a stationary policy.
            upper = upper[0] if upper.ndim == f["values"].ndim else upper
        return {
            "config": yaml.safe_load(config_text),
            "faces": faces,
            "counts": counts,
            "values": np.asarray(f["values"][0]),  # V_0, shape (n0, n1, ...)
            "upper": upper,  # the upper bound at step 0 (guarantee: system, stationary), or None
            "system": text_of(f.attrs.get("guarantee", "")) == "system",
        }


def text_of(value):
    """A string dataset's or attribute's text (h5py gives bytes or str)."""
    return value.decode() if isinstance(value, bytes) else str(value)


def cell_index(faces, state):
    """The cell per dimension holding `state` (clipped to the grid)."""
    return np.array([int(np.clip(np.searchsorted(f, x, side="right") - 1, 0, len(f) - 2))
                     for f, x in zip(faces, state)])


def read_episodes(path):
    """{episode: {"states": array (steps, state dims), "x0": [...], "x1": [...], "success": bool}}"""
    episodes = {}
    with open(path) as f:
        reader = csv.DictReader(f)
        state_keys = [k for k in reader.fieldnames if k.startswith("x")]
        for row in reader:
            e = episodes.setdefault(int(row["episode"]), {"states": [], "success": row["success"] == "1"})
            e["states"].append([float(row[k]) for k in state_keys])
    for e in episodes.values():
        e["states"] = np.array(e["states"])
        e["x0"] = e["states"][:, 0]
        e["x1"] = e["states"][:, 1] if e["states"].shape[1] > 1 else np.zeros(len(e["states"]))
    return episodes


def body_corners(state, footprint):
    """The car's body at `state`: 4 corners (x, y) in metres, counter-clockwise."""
    length, width, rear, xi, yi, yawi = footprint
    x, y, yaw = state[int(xi)], state[int(yi)], state[int(yawi)]
    forward, left = np.array([np.cos(yaw), np.sin(yaw)]), np.array([-np.sin(yaw), np.cos(yaw)])
    back = np.array([x, y]) - rear * forward
    front = back + length * forward
    half = 0.5 * width * left
    return np.array([back - half, front - half, front + half, back + half])


def overlaps(polygon, box):
    """Whether a convex polygon and an axis-aligned box {lb, ub} share interior (separating axes)."""
    rect = np.array([[box["lb"][0], box["lb"][1]], [box["ub"][0], box["lb"][1]],
                     [box["ub"][0], box["ub"][1]], [box["lb"][0], box["ub"][1]]])
    for shape in (polygon, rect):
        for i in range(len(shape)):
            edge = shape[(i + 1) % len(shape)] - shape[i]
            axis = np.array([-edge[1], edge[0]])
            a, b = polygon @ axis, rect @ axis
            if a.max() <= b.min() or b.max() <= a.min():
                return False
    return True


def draw_scene(ax, scene):
    for bay in scene.get("bays", []):
        x0, y0, x1, y1 = bay["lb"][0], bay["lb"][1], bay["ub"][0], bay["ub"][1]
        ax.plot([x0, x0, x1, x1], [y1, y0, y0, y1], "-", color="0.55", lw=1.2)
    for i, obstacle in enumerate(scene.get("obstacles", [])):
        (x0, y0), (x1, y1) = obstacle["lb"], obstacle["ub"]
        ax.add_patch(Rectangle((x0, y0), x1 - x0, y1 - y0, fc="0.65", ec="0.35", lw=0.8, zorder=1,
                               label="parked cars, kerbs" if i == 0 else None))
        if obstacle.get("label"):
            ax.text(0.5 * (x0 + x1), 0.5 * (y0 + y1), obstacle["label"], ha="center", va="center", fontsize=6,
                    rotation=90 if y1 - y0 > x1 - x0 else 0, color="0.2")


def footprint_clearance(episodes, footprint, scene):
    """Lines about footprints that overlap an obstacle of the scene (empty when none does)."""
    touches = []
    for number, e in sorted(episodes.items()):
        for step, state in enumerate(e["states"]):
            corners = body_corners(state, footprint)
            for obstacle in scene.get("obstacles", []):
                if overlaps(corners, obstacle):
                    touches.append(f"episode {number} step {step}: the body overlaps {obstacle.get('label', 'an obstacle')}")
    return touches


def box_xy(box):
    lb, ub = box["lb"], box["ub"]
    y0, y1 = (lb[1], ub[1]) if len(lb) > 1 else (-0.5, 0.5)
    return lb[0], y0, ub[0] - lb[0], y1 - y0


def boxes_of(region):
    """The boxes of a specification set: one box {lb, ub} or a list of boxes."""
    return region if isinstance(region, list) else [region]


def draw_sets(ax, policy, suffix=""):
    faces = policy["faces"]
    lo = np.array([f[0] for f in faces])
    hi = np.array([f[-1] for f in faces])
    y0, y1 = (lo[1], hi[1]) if len(faces) > 1 else (-0.5, 0.5)
    ax.add_patch(Rectangle((lo[0], y0), hi[0] - lo[0], y1 - y0, fill=False, ec="0.3", lw=1.5, label="grid"))
    spec = policy["config"].get("spec", {}) or {}
    styles = {"target": dict(fc="tab:green", alpha=0.35), "avoid": dict(fc="tab:red", alpha=0.35),
              "safe": dict(fill=False, ec="tab:blue", lw=1.5)}
    for name, style in styles.items():
        for index, box in enumerate(boxes_of(spec.get(name) or [])):
            x, y, w, h = box_xy(box)
            # One legend entry per set, not per box.
            ax.add_patch(Rectangle((x, y), w, h, label=name + suffix if index == 0 else None, **style))
    # Obstacles of the configuration (world frame x, y: the footprint's reference point axes).
    for index, box in enumerate(boxes_of(spec.get("obstacles") or [])):
        x, y, w, h = box_xy(box)
        ax.add_patch(Rectangle((x, y), w, h, fc="0.4", alpha=0.5, hatch="//",
                               label="obstacles (configuration)" if index == 0 else None))
    # A margin of the outermost cell's width (eta on a uniform grid).
    ax.set_xlim(lo[0] - (faces[0][1] - faces[0][0]), hi[0] + (faces[0][-1] - faces[0][-2]))
    if len(faces) > 1:
        ax.set_ylim(y0 - (faces[1][1] - faces[1][0]), y1 + (faces[1][-1] - faces[1][-2]))
    else:
        ax.set_ylim(y0 - 0.5, y1 + 0.5)


def outline_sets(ax, policy):
    """The specification's sets as outlines over a values picture (target green, avoid red, safe blue)."""
    spec = policy["config"].get("spec", {}) or {}
    for name, color in (("target", "tab:green"), ("avoid", "tab:red"), ("safe", "tab:blue")):
        for index, box in enumerate(boxes_of(spec.get(name) or [])):
            x, y, w, h = box_xy(box)
            ax.add_patch(Rectangle((x, y), w, h, fill=False, ec=color, lw=1.5, label=name if index == 0 else None))


def plot_values(policy, start, name, path):
    """V_0 (system: lower and upper bound side by side) over the x0/x1 slice through the start's cell."""
    faces = policy["faces"]
    index = cell_index(faces, start)
    panels = [("lower bound (this policy)", policy["values"]), ("upper bound (any controller)", policy["upper"])] \
        if policy["system"] and policy["upper"] is not None else \
        [("abstraction's value, not a guarantee for the real system", policy["values"])]
    fig, axes = plt.subplots(1, len(panels), figsize=(6.5 * len(panels), 5.5 if len(faces) > 1 else 4), squeeze=False)
    for ax, (label, values) in zip(axes[0], panels):
        if values.ndim == 1:
            ax.step(faces[0], np.append(values, values[-1]), where="post")
            ax.set_xlabel("x0")
            ax.set_ylabel("V_0")
            ax.set_ylim(-0.02, 1.02)
            ax.set_title(label, fontsize=9)
            continue
        plane = values[(slice(None), slice(None)) + tuple(index[2:])]
        # pcolormesh draws each cell between its faces (cells of any widths).
        image = ax.pcolormesh(faces[0], faces[1], plane.T, vmin=0.0, vmax=1.0, cmap="viridis", shading="flat")
        outline_sets(ax, policy)
        ax.plot(start[0], start[1], "r*", ms=12, label="start")
        ax.set_xlim(faces[0][0], faces[0][-1])
        ax.set_ylim(faces[1][0], faces[1][-1])
        ax.set_xlabel("x0")
        ax.set_ylabel("x1")
        ax.legend(loc="best", fontsize=7)
        ax.set_title(label, fontsize=9)
        fig.colorbar(image, ax=ax, label="V_0 (probability)")
    title = f"{name}: V_0 over x0/x1"
    if len(faces) > 2:
        point = [0.5 * (f[k] + f[k + 1]) for f, k in zip(faces, index)]
        title += " at " + ", ".join(f"x{i} = {round(point[i], 9):g}" for i in range(2, len(faces)))
    fig.suptitle(title, fontsize=10)
    fig.tight_layout()
    fig.savefig(path, dpi=120)
    plt.close(fig)


def main():
    parser = argparse.ArgumentParser(description=__doc__, formatter_class=argparse.RawDescriptionHelpFormatter)
    parser.add_argument("--csv", required=True)
    parser.add_argument("--policy", required=True)
    parser.add_argument("--initial-state", required=True, help="comma-separated, state units")
    parser.add_argument("--trajectories", required=True)
    parser.add_argument("--values", required=True)
    parser.add_argument("--footprint", help="length, width, rear_to_reference (m), x_index, y_index, yaw_index")
    parser.add_argument("--scene", help="YAML: bays and obstacles as boxes {lb: [x, y], ub: [x, y], label} (m)")
    args = parser.parse_args()

    policy = read_policy(args.policy)
    episodes = read_episodes(args.csv)
    start = np.array([float(v) for v in args.initial_state.split(",")])
    name = policy["config"].get("name", "policy")

    footprint = [float(v) for v in args.footprint.split(",")] if args.footprint else None
    # Without --footprint, the configuration's own body (spec.footprint) when it has one.
    body = (policy["config"].get("spec", {}) or {}).get("footprint")
    if footprint is None and body:
        footprint = [float(body["length"]), float(body["width"]), float(body["rear_overhang"])] + \
                    [float(i) for i in body["pose"]]
    scene = {}
    if args.scene:
        with open(args.scene) as f:
            scene = yaml.safe_load(f) or {}
    fig, ax = plt.subplots(figsize=(8, 7) if footprint else (6.5, 6))
    if scene:
        draw_scene(ax, scene)
    draw_sets(ax, policy, " (reference point)" if footprint else "")
    successes = sum(e["success"] for e in episodes.values())
    # The body along the first episode's path (every other step) and at the end of every episode;
    # the clearance check below looks at every step of every episode.
    for number, e in sorted(episodes.items()):
        color = "tab:green" if e["success"] else "tab:red"
        if footprint:
            first = number == min(episodes)
            for step, state in enumerate(e["states"]):
                if (first and step % 2 == 0) or step == len(e["states"]) - 1:
                    ax.add_patch(Polygon(body_corners(state, footprint), closed=True, fill=False, ec=color,
                                         lw=0.8 if first else 0.5, alpha=0.7 if first else 0.4))
        ax.plot(e["x0"], e["x1"], "-", color=color, lw=1, alpha=0.7)
        ax.plot(e["x0"][-1], e["x1"][-1], "o", color=color, ms=3)
    ax.plot(start[0], start[1] if len(start) > 1 else 0.0, "k*", ms=12, label="start")
    title = f"{name}: {successes}/{len(episodes)} episodes succeeded"
    if scene.get("view"):
        ax.set_xlim(scene["view"]["lb"][0], scene["view"]["ub"][0])
        ax.set_ylim(scene["view"]["lb"][1], scene["view"]["ub"][1])
    if footprint:
        ax.add_patch(Polygon(body_corners(start, footprint), closed=True, fill=False, ec="k", lw=1.5, label="car at start"))
        ax.set_xlabel("x (m), position of the reference point")
        ax.set_ylabel("y (m)")
        turns = [np.degrees(e["states"][-1][int(footprint[5])] - e["states"][0][int(footprint[5])])
                 for e in episodes.values() if e["success"]]
        if turns:
            title += f"; yaw change {min(turns):.0f} to {max(turns):.0f} deg"
        if scene:
            touches = footprint_clearance(episodes, footprint, scene)
            for line in touches:
                print(line)
            verdict = "footprint clear of every obstacle at every step" if not touches else \
                f"footprint overlaps an obstacle at {len(touches)} steps"
            print(f"{name}: {verdict}")
            title += "\n" + verdict
        ax.set_aspect("equal")
    else:
        ax.set_xlabel("x0")
        ax.set_ylabel("x1")
        ax.set_aspect("auto")
    ax.set_title(title, fontsize=9)
    ax.legend(loc="best", fontsize=7)
    fig.tight_layout()
    fig.savefig(args.trajectories, dpi=120)
    plt.close(fig)

    plot_values(policy, start, name, args.values)
    print(args.trajectories)
    print(args.values)
    return 0


if __name__ == "__main__":
    sys.exit(main())
