#!/usr/bin/env python3
"""Pictures of `pointhaptics experiment cut`: the object's surface, split along the cuts, frame by frame
(surface-frames.json) as surface-1.png ... and all of them in surface-series.png."""
import json
import sys
from pathlib import Path

import matplotlib

matplotlib.use("Agg")
import matplotlib.pyplot as plt  # noqa: E402
import numpy as np  # noqa: E402
from mpl_toolkits.mplot3d.art3d import Poly3DCollection  # noqa: E402

LIGHT = np.array([0.35, 0.8, 0.5]) / np.linalg.norm([0.35, 0.8, 0.5])


def draw(ax, frame, bounds):
    v = np.asarray(frame["vertices"], dtype=float)
    f = np.asarray(frame["faces"], dtype=int)
    triangles = v[f]
    normal = np.cross(triangles[:, 1] - triangles[:, 0], triangles[:, 2] - triangles[:, 0])
    normal /= np.linalg.norm(normal, axis=1)[:, None] + 1e-300
    shade = 0.35 + 0.65 * np.abs(normal @ LIGHT)
    colour = np.tile([0.62, 0.75, 0.9], (len(f), 1))
    cut = frame["cut_faces"]
    if cut:
        colour[-cut:] = [0.85, 0.35, 0.3]  # the faces of the cuts
    # the scene's y is up: drawn as matplotlib's z
    ax.add_collection3d(Poly3DCollection(triangles[:, :, [0, 2, 1]], facecolors=colour * shade[:, None], edgecolor="none"))
    lo, hi = bounds
    centre, half = (lo + hi) / 2, (hi - lo).max() / 2
    ax.set_xlim(centre[0] - half, centre[0] + half)
    ax.set_ylim(centre[2] - half, centre[2] + half)
    ax.set_zlim(centre[1] - half, centre[1] + half)
    ax.set_xlabel("x (m)")
    ax.set_ylabel("z (m)")
    ax.set_zlabel("y (m)")
    ax.view_init(elev=18, azim=-62)
    ax.set_title(frame["title"], fontsize=9)


def main(out: Path):
    frames = json.loads((out / "surface-frames.json").read_text())
    groups = {}
    for frame in frames:  # the same bounds for the frames of one object
        key = frame["title"].split(",")[0]
        v = np.asarray(frame["vertices"], dtype=float)
        lo, hi = groups.get(key, (v.min(0), v.max(0)))
        groups[key] = (np.minimum(lo, v.min(0)), np.maximum(hi, v.max(0)))
    columns = 3
    rows = (len(frames) + columns - 1) // columns
    series = plt.figure(figsize=(5 * columns, 4 * rows))
    for k, frame in enumerate(frames, start=1):
        bounds = groups[frame["title"].split(",")[0]]
        single = plt.figure(figsize=(6, 4.5))
        draw(single.add_subplot(projection="3d"), frame, bounds)
        single.savefig(out / f"surface-{k}.png", dpi=110, bbox_inches="tight")
        plt.close(single)
        draw(series.add_subplot(rows, columns, k, projection="3d"), frame, bounds)
    series.savefig(out / "surface-series.png", dpi=90, bbox_inches="tight")


if __name__ == "__main__":
    main(Path(sys.argv[1]))
