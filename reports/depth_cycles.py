#!/usr/bin/python3
"""Fig. 7 of Chuang & Kazhdan 2011: solver residual vs number of W-cycles per octree depth (real
model, left) and Hausdorff distance vs depth per number of W-cycles (sphere, right)."""

import statistics

import matplotlib.pyplot as plt
from matplotlib.ticker import MaxNLocator

import common


def final_residual(result):
    """Median over steps of the last relative residual the solver reported in each step."""
    vals = []
    for s in result.get("steps", []):
        res = common.get(s, "solver.residuals") or []
        if res and common.finite(res[-1]):
            vals.append(res[-1])
    return statistics.median(vals) if vals else None


def hausdorff(result):
    """Hausdorff distance of the run: the last reference_distance max, else (sphere) the last
    step's max radial error (on a sphere the radial error is the Hausdorff distance)."""
    ref = [e for e in result.get("reference_distance") or [] if common.finite(e.get("max"))]
    if ref:
        return ref[-1]["max"]
    xs, ys = common.series(result, "radial_error.max")
    return ys[-1] if ys else None


def is_sphere(result):
    """Cells with radial errors are the sphere half of the study."""
    return bool(common.series(result, "radial_error.max")[0])


def depth(r):
    return common.get(r, "config.octree.depth")


def cycles(r):
    return common.get(r, "config.solver.cycles")


def mesh(r):
    return common.get(r, "config.mesh")


def stabilized(r):
    """True for the normal-gradient stabilized system (a result without the key ran the paper's)."""
    return common.get(r, "config.octree.stabilization", "none") not in ("none", None)


def style(cells, stab, index):
    """Line style: a colour per depth (or cycles) value, solid for the stabilized system and dashed
    for the paper's when the panel has both, so each pair shares its colour."""
    both = len({stabilized(r) for r in cells}) > 1
    return {"color": "C%d" % (index % 10), "ls": "-" if stab or not both else "--"}


def system_name(cells, stab):
    """", stabilized" / ", paper's system" where the panel has both systems, else nothing."""
    if len({stabilized(r) for r in cells}) < 2:
        return ""
    return ", stabilized" if stab else ", paper's system"


def line_order(kv):
    """Lines by mesh (first seen) then by their number (depth or cycles), missing ones last."""
    n = kv[0][1]
    return (n is None, n or 0)


def named(m, text, cells):
    """A line's label: `text`, after the mesh where the panel has several ("icosphere:level=5, depth 6")."""
    return "%s, %s" % (common.short_value(m), text) if len({mesh(r) for r in cells}) > 1 else text


def plot_residuals(ax, cells):
    """Residual vs cycles, one line per mesh and depth. With one cycles value only, the per-cycle
    residual history of the first step stands in (same quantity, read inside a single solve)."""
    by_depth = common.group_by(cells, lambda r: (mesh(r), depth(r), stabilized(r)))
    meshes = list(dict.fromkeys(mesh(r) for r in cells))
    depths = sorted({depth(r) for r in cells if depth(r) is not None})
    distinct_cycles = {cycles(r) for r in cells}
    for (m, d, stab), rs in sorted(by_depth.items(),
                                   key=lambda kv: (meshes.index(kv[0][0]),) + line_order(kv) + (kv[0][2],)):
        if len(distinct_cycles) > 1:
            pts = sorted((cycles(r), final_residual(r)) for r in rs
                         if cycles(r) is not None and common.finite(final_residual(r)))
        else:
            res = common.get((rs[0].get("steps") or [{}])[0], "solver.residuals") or []
            pts = [(i + 1, v) for i, v in enumerate(res) if common.finite(v)]
        if pts:
            ax.plot([p[0] for p in pts], [p[1] for p in pts], marker="o", ms=3,
                    label=named(m, "depth %s%s" % (d, system_name(cells, stab)), cells),
                    **style(cells, stab, depths.index(d) if d in depths else len(depths)))
    ax.xaxis.set_major_locator(MaxNLocator(integer=True))
    ax.set_xlabel("W-cycles")
    ax.set_ylabel("relative residual")
    ax.set_yscale("log")
    title = "residual (%s)" % ("sphere" if all(is_sphere(r) for r in cells) else "model")
    if any(stabilized(r) for r in cells):
        # The stabilized solve is for the step's increment: its residual is relative to the
        # increment's right-hand side, far smaller than the position's, so compare slopes.
        title += "\nstabilized: relative to the increment's right-hand side"
    ax.set_title(title, fontsize=9)


def plot_hausdorff(ax, cells):
    """Hausdorff distance vs depth, one line per mesh and number of cycles."""
    meshes = list(dict.fromkeys(mesh(r) for r in cells))
    by_cycles = common.group_by(cells, lambda r: (mesh(r), cycles(r), stabilized(r)))
    counts = sorted({cycles(r) for r in cells if cycles(r) is not None})
    for (m, c, stab), rs in sorted(by_cycles.items(),
                                   key=lambda kv: (meshes.index(kv[0][0]),) + line_order(kv) + (kv[0][2],)):
        pts = sorted((depth(r), hausdorff(r)) for r in rs if depth(r) is not None and common.finite(hausdorff(r)))
        if pts:
            ax.plot([p[0] for p in pts], [p[1] for p in pts], marker="o", ms=3,
                    label=named(m, "%s W-cycle%s%s" % (c, "" if c == 1 else "s", system_name(cells, stab)), cells),
                    **style(cells, stab, counts.index(c) if c in counts else len(counts)))
    ax.xaxis.set_major_locator(MaxNLocator(integer=True))
    ax.set_xlabel("octree depth")
    ax.set_ylabel("Hausdorff distance")
    ax.set_yscale("log")
    ax.set_title("Hausdorff distance (sphere)", fontsize=9)


def make(results, out_dir, reference, written):
    """Write depth_cycles.png (the panels with data)."""
    cells = common.first_repetition(results)
    models = [r for r in cells if not is_sphere(r)]
    spheres = [r for r in cells if is_sphere(r)]
    # A study run on spheres only still shows residuals: the sphere cells stand in.
    panels = [(plot_residuals, models or spheres)]
    if spheres:
        panels.append((plot_hausdorff, spheres))
    fig, axes = plt.subplots(1, len(panels), figsize=(5 * len(panels), 3.8), squeeze=False)
    for ax, (plot, rs) in zip(axes[0], panels):
        plot(ax, rs)
        common.plot_reference_curves(ax, reference, "residual" if plot is plot_residuals else "hausdorff",
                                     xkey="cycles" if plot is plot_residuals else "depth")
        if ax.get_legend_handles_labels()[0]:
            ax.legend()
    title = "Depth and W-cycles (Fig. 7)"
    fig.suptitle(title)
    fig.text(0.01, -0.02, common.sources_line(cells), fontsize=6, wrap=True)
    common.save_figure(fig, out_dir, "depth_cycles", cells, title, written)
