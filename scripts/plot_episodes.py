#!/usr/bin/env python3
"""Pictures of a closed-loop run (called by the plant simulator; usable by hand).

  plot_episodes.py --csv RUN.csv --policy POLICY.h5 --initial-state "x0, x1, ..." \
                   --trajectories OUT1.png --values OUT2.png

OUT1: the episodes' trajectories over the sets in the x0/x1 plane (success green, failure red),
with the grid bounds, target (green), avoid (red) and safe (blue) boxes from the configuration
stored in the policy file. OUT2: V_0 over the x0/x1 slice of the grid, the other coordinates at
the start state's cell. Needs python3-matplotlib, python3-h5py, python3-yaml (Debian).
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
from matplotlib.patches import Rectangle  # noqa: E402


def read_policy(path):
    with h5py.File(path, "r") as f:
        config_text = f["config"][()]
        if isinstance(config_text, bytes):
            config_text = config_text.decode()
        return {
            "config": yaml.safe_load(config_text),
            "lb": np.asarray(f["states/lb"][()], dtype=float),
            "eta": np.asarray(f["states/eta"][()], dtype=float),
            "counts": np.asarray(f["states/counts"][()], dtype=int),
            "values": np.asarray(f["values"][0]),  # V_0, shape (n0, n1, ...)
        }


def read_episodes(path):
    episodes = {}
    with open(path) as f:
        for row in csv.DictReader(f):
            e = episodes.setdefault(int(row["episode"]), {"x0": [], "x1": [], "success": row["success"] == "1"})
            e["x0"].append(float(row["x0"]))
            e["x1"].append(float(row["x1"]) if "x1" in row else 0.0)
    return episodes


def box_xy(box):
    lb, ub = box["lb"], box["ub"]
    y0, y1 = (lb[1], ub[1]) if len(lb) > 1 else (-0.5, 0.5)
    return lb[0], y0, ub[0] - lb[0], y1 - y0


def draw_sets(ax, policy):
    lb, eta, counts = policy["lb"], policy["eta"], policy["counts"]
    lo = lb - eta / 2
    hi = lb + (counts - 1) * eta + eta / 2
    y0, y1 = (lo[1], hi[1]) if len(lb) > 1 else (-0.5, 0.5)
    ax.add_patch(Rectangle((lo[0], y0), hi[0] - lo[0], y1 - y0, fill=False, ec="0.3", lw=1.5, label="grid"))
    spec = policy["config"].get("spec", {}) or {}
    styles = {"target": dict(fc="tab:green", alpha=0.35), "avoid": dict(fc="tab:red", alpha=0.35),
              "safe": dict(fill=False, ec="tab:blue", lw=1.5)}
    for name, style in styles.items():
        if spec.get(name):
            x, y, w, h = box_xy(spec[name])
            ax.add_patch(Rectangle((x, y), w, h, label=name, **style))
    ax.set_xlim(lo[0] - eta[0], hi[0] + eta[0])
    ax.set_ylim(y0 - (eta[1] if len(eta) > 1 else 0.5), y1 + (eta[1] if len(eta) > 1 else 0.5))


def main():
    parser = argparse.ArgumentParser(description=__doc__, formatter_class=argparse.RawDescriptionHelpFormatter)
    parser.add_argument("--csv", required=True)
    parser.add_argument("--policy", required=True)
    parser.add_argument("--initial-state", required=True, help="comma-separated, state units")
    parser.add_argument("--trajectories", required=True)
    parser.add_argument("--values", required=True)
    args = parser.parse_args()

    policy = read_policy(args.policy)
    episodes = read_episodes(args.csv)
    start = np.array([float(v) for v in args.initial_state.split(",")])
    name = policy["config"].get("name", "policy")

    fig, ax = plt.subplots(figsize=(6.5, 6))
    draw_sets(ax, policy)
    successes = sum(e["success"] for e in episodes.values())
    for e in episodes.values():
        ax.plot(e["x0"], e["x1"], "-", color="tab:green" if e["success"] else "tab:red", lw=1, alpha=0.7)
        ax.plot(e["x0"][-1], e["x1"][-1], "o", color="tab:green" if e["success"] else "tab:red", ms=3)
    ax.plot(start[0], start[1] if len(start) > 1 else 0.0, "k*", ms=12, label="start")
    ax.set_xlabel("x0")
    ax.set_ylabel("x1")
    ax.set_title(f"{name}: {successes}/{len(episodes)} episodes succeeded")
    ax.legend(loc="best", fontsize=8)
    ax.set_aspect("auto")
    fig.tight_layout()
    fig.savefig(args.trajectories, dpi=120)
    plt.close(fig)

    values = policy["values"]
    lb, eta, counts = policy["lb"], policy["eta"], policy["counts"]
    index = np.clip(np.floor((start - lb) / eta + 0.5).astype(int), 0, counts - 1)
    if values.ndim == 1:
        fig, ax = plt.subplots(figsize=(6.5, 4))
        ax.plot(lb[0] + np.arange(counts[0]) * eta[0], values, "-o", ms=3)
        ax.set_xlabel("x0")
        ax.set_ylabel("V_0")
    else:
        slice_index = (slice(None), slice(None)) + tuple(index[2:])
        plane = values[slice_index]
        fig, ax = plt.subplots(figsize=(6.5, 5.5))
        extent = [lb[0] - eta[0] / 2, lb[0] + (counts[0] - 0.5) * eta[0],
                  lb[1] - eta[1] / 2, lb[1] + (counts[1] - 0.5) * eta[1]]
        image = ax.imshow(plane.T, origin="lower", extent=extent, vmin=0.0, vmax=1.0, cmap="viridis",
                          aspect="auto", interpolation="nearest")
        fig.colorbar(image, ax=ax, label="V_0 (probability)")
        ax.plot(start[0], start[1], "r*", ms=12, label="start")
        ax.set_xlabel("x0")
        ax.set_ylabel("x1")
        ax.legend(loc="best", fontsize=8)
        if len(lb) > 2:
            others = ", ".join(f"x{i} = {lb[i] + index[i] * eta[i]:g}" for i in range(2, len(lb)))
            ax.set_title(f"{name}: V_0 over x0/x1 at {others}", fontsize=9)
        else:
            ax.set_title(f"{name}: V_0 over x0/x1")
    fig.tight_layout()
    fig.savefig(args.values, dpi=120)
    plt.close(fig)
    print(args.trajectories)
    print(args.values)
    return 0


if __name__ == "__main__":
    sys.exit(main())
