#!/usr/bin/python3
"""Strips of shaded renders of a cell's saved frames side by side, like Figs. 2–5 of Chuang &
Kazhdan 2011 and Figs. 2–6 of the cMCF paper. Orthographic projection, per-face Lambert shading
with a fixed light, painter's algorithm (faces drawn far to near) through a PolyCollection."""

import glob
import json
import os
import re

import numpy as np
import matplotlib.pyplot as plt
from matplotlib.collections import PolyCollection

import common
import plyio

MAX_FACES = 30000      # above this, meshes are decimated (vertex clustering) for speed
MAX_FRAMES = 6         # frames per strip (evenly spaced, first and last included)
MAX_CELLS = 8          # strips per study (spread over the cells: spread())
SPREAD_FIRST = ("flow", "mesh")  # keys spread() balances first, in this order
LIGHT = np.array([0.3, 0.5, 1.0]) / np.linalg.norm([0.3, 0.5, 1.0])
# A fixed three-quarter view: rotate about y then x, so flat-on axis-aligned shapes still show depth.
_a, _b = np.radians(25), np.radians(-20)
VIEW = (np.array([[1, 0, 0], [0, np.cos(_b), -np.sin(_b)], [0, np.sin(_b), np.cos(_b)]])
        @ np.array([[np.cos(_a), 0, np.sin(_a)], [0, 1, 0], [-np.sin(_a), 0, np.cos(_a)]]))


def frames_of(result):
    """Sorted frame files of a result: RESULTS_DIR/frames/<stem>/frame_*.ply (runner layout),
    else frame_*.ply beside a `mcfbench flow` result.json."""
    folder = os.path.join(result["_folder"], "frames", result["_stem"])
    files = glob.glob(os.path.join(folder, "frame_*.ply"))
    if not files and os.path.basename(result["_path"]) == "result.json":
        files = glob.glob(os.path.join(os.path.dirname(result["_path"]), "frame_*.ply"))
    def number(p):
        m = re.search(r"frame_(\d+)", os.path.basename(p))
        return int(m.group(1)) if m else 0
    return sorted(files, key=number), number


def pick(items, n):
    """n items evenly spaced, keeping the first and the last."""
    if len(items) <= n:
        return list(items)
    idx = np.unique(np.round(np.linspace(0, len(items) - 1, n)).astype(int))
    return [items[i] for i in idx]


def decimate(v, f, max_faces):
    """Vertex-clustering decimation: snap vertices to a grid, average each cell, drop collapsed
    and duplicate faces. Crude but hole-free and fast, which is all a thumbnail needs."""
    if len(f) <= max_faces:
        return v, f
    extent = np.ptp(v, axis=0).max() or 1.0
    cells = max(8, int(np.sqrt(max_faces / 2)))  # ~2·cells² faces on a sphere-like surface
    q = np.floor((v - v.min(axis=0)) / extent * cells).astype(np.int64)
    keys = (q[:, 0] * (cells + 1) + q[:, 1]) * (cells + 1) + q[:, 2]
    uniq, cluster = np.unique(keys, return_inverse=True)
    nv = np.zeros((len(uniq), 3))
    np.add.at(nv, cluster, v)
    nv /= np.bincount(cluster, minlength=len(uniq))[:, None]
    nf = cluster[f]
    keep = (nf[:, 0] != nf[:, 1]) & (nf[:, 1] != nf[:, 2]) & (nf[:, 0] != nf[:, 2])
    nf = nf[keep]
    _, first = np.unique(np.sort(nf, axis=1), axis=0, return_index=True)
    return nv, nf[np.sort(first)]


def render(ax, v, f, centre, scale):
    """Draw one mesh: orthographic view, Lambert shading (two-sided), painter's order."""
    p = (v - centre) @ VIEW.T / scale
    tri = p[f]
    n = np.cross(tri[:, 1] - tri[:, 0], tri[:, 2] - tri[:, 0])
    norm = np.linalg.norm(n, axis=1)
    n = n / np.where(norm > 0, norm, 1)[:, None]
    shade = 0.15 + 0.85 * np.abs(n @ LIGHT)
    order = np.argsort(tri[:, :, 2].mean(axis=1))  # far (small z, camera on +z) first
    colors = np.outer(shade[order], [0.85, 0.78, 0.62])
    ax.add_collection(PolyCollection(tri[order][:, :, :2], facecolors=colors, edgecolors="none",
                                     antialiaseds=False))
    ax.set_xlim(-1.05, 1.05)
    ax.set_ylim(-1.05, 1.05)
    ax.set_aspect("equal")
    ax.axis("off")


def strip(result, files, number, out_dir, written, index, keys):
    """One PNG with up to MAX_FRAMES frames of a cell, all at the first frame's scale (so the
    shrinking of MCF is visible)."""
    chosen = pick(files, MAX_FRAMES)
    meshes = []
    for p in chosen:
        try:
            v, f = plyio.read_ply(p)
        except (OSError, ValueError, KeyError) as e:
            common.warn("frames: cannot read %s: %s" % (p, e))
            continue
        if len(v) and len(f):
            meshes.append((p, *decimate(v, f, MAX_FACES)))
    if not meshes:
        return
    v0 = meshes[0][1]
    centre = (v0.min(axis=0) + v0.max(axis=0)) / 2
    radius = np.linalg.norm((v0 - centre) @ VIEW.T, axis=1).max() or 1.0
    fig, axes = plt.subplots(1, len(meshes), figsize=(2.2 * len(meshes), 2.5), squeeze=False)
    for ax, (p, v, f) in zip(axes[0], meshes):
        render(ax, v, f, centre, radius)
        ax.set_title("step %d" % number(p), fontsize=8)
    title = "Frames: %s" % common.label(result, keys)
    fig.suptitle(title, fontsize=9)
    fig.text(0.01, 0.0, "Sources: %s; frames %s" % (os.path.basename(result["_path"]),
                                                   ", ".join(os.path.basename(m[0]) for m in meshes)), fontsize=5)
    name = "frames_%s_%02d" % (common.study_of(result), index)
    common.save_figure(fig, out_dir, name, [result], title, written)


def spread(cells, keys, n):
    """The indices (sorted) of up to n of `cells` spread over the values of `keys` (the keys that
    vary): flow first, then mesh, then the others sorted. Each pick is the cell whose flow has
    the fewest strips so far, among those the one whose mesh has the fewest, and so on, the
    earliest cell on a tie, so every flow, then every mesh, gets a strip before any gets a
    second (as far as n allows). Deterministic: it depends on the cells' order only."""
    if len(cells) <= n:
        return list(range(len(cells)))
    order = [k for k in SPREAD_FIRST if k in keys] + [k for k in keys if k not in SPREAD_FIRST]
    values = [[(k, json.dumps(common.assignment(c).get(k), sort_keys=True)) for k in order] for c in cells]
    counts, chosen, left = {}, [], list(range(len(cells)))
    while len(chosen) < n:
        best = min(left, key=lambda i: tuple(counts.get(v, 0) for v in values[i]) + (i,))
        chosen.append(best)
        left.remove(best)
        for v in values[best]:
            counts[v] = counts.get(v, 0) + 1
    return sorted(chosen)


def cell_name(result):
    """'cell 3 `flow=mcf mesh=dumbbell`' (index.cell_words) for a result."""
    import index
    return index.cell_words(result.get("cell") or {"index": result["_stem"], "assignment": common.assignment(result)})


def make(results, out_dir, reference, written):
    """Write frames_<study>_NN.png for up to MAX_CELLS cells that saved frames, spread over the
    flows, meshes and other varying keys (spread()); the cells left out are counted on stdout
    and listed in index.md (a "note" in `written`)."""
    cells = [(r, *frames_of(r)) for r in common.first_repetition(results)]
    cells = [c for c in cells if c[1]]
    keys = common.varying_keys([c[0] for c in cells])
    chosen = spread([c[0] for c in cells], keys, MAX_CELLS)
    left_out = [c[0] for i, c in enumerate(cells) if i not in chosen]
    if left_out:
        study = common.study_of(cells[0][0])
        over = [k for k in SPREAD_FIRST if k in keys] + [k for k in keys if k not in SPREAD_FIRST]
        names = ", ".join(cell_name(r) for r in left_out)
        # A note, not a warning: the cap is by design (every full cmcf run meets it); which cells
        # have no strip is in index.md.
        print("frames: %s: %d cells saved frames, strips for %d of them (at most %d, spread over %s); "
              "the others are listed in index.md" % (study, len(cells), len(chosen), MAX_CELLS, ", ".join(over) or "the cells"))
        written.append({"kind": "note", "text": "Frame strips for %d of the %d cells that saved frames (at most "
                        "%d, spread over %s); left out: %s." % (len(chosen), len(cells), MAX_CELLS,
                                                               ", ".join(over) or "the cells", names)})
    for n, i in enumerate(chosen):
        r, files, number = cells[i]
        strip(r, files, number, out_dir, written, n, keys)
