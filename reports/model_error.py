#!/usr/bin/python3
"""Fig. 6 (left) of Chuang & Kazhdan 2011: RMS (solid) and Hausdorff (dashed) Metro distance of
octree flows to the cotangent reference, per step."""

import matplotlib.pyplot as plt

import common


def reference_series(result, metric):
    """(steps, values) of the result's reference_distance list for `metric` ("rms" or "max")."""
    xs, ys = [], []
    for e in result.get("reference_distance") or []:
        if isinstance(e, dict) and common.finite(e.get(metric)) and e.get("step") is not None:
            xs.append(e["step"])
            ys.append(e[metric])
    return xs, ys


def make(results, out_dir, reference, written):
    """Write model_error.png (cells without reference_distance are listed, not plotted)."""
    cells = [r for r in common.first_repetition(results) if r.get("reference_distance")]
    if not cells:
        common.warn("model_error: no result has reference_distance; nothing to plot")
        return
    keys = common.varying_keys(cells)
    fig, ax = plt.subplots(figsize=(6.5, 4.2))
    values = []
    for i, r in enumerate(cells):
        color = "C%d" % (i % 10)
        for metric, style, suffix in (("rms", "-", "RMS"), ("max", "--", "Hausdorff")):
            xs, ys = reference_series(r, metric)
            if xs:
                ax.plot(xs, ys, style, color=color, lw=1.4, marker=".", ms=3,
                        label="%s (%s)" % (common.label(r, keys), suffix))
                common.mark_stop(ax, r, xs, ys, color)
                values += ys
    common.plot_reference_curves(ax, reference, "rms")
    common.plot_reference_curves(ax, reference, "max")
    ax.set_xlabel("step")
    ax.set_ylabel("distance to cotangent reference")
    common.log_if_positive(ax, values)
    common.legend_beside([ax])
    title = "Real model: distance to the cotangent-Laplacian flow (Fig. 6 left)"
    ax.set_title(title, fontsize=9)
    fig.text(0.01, -0.03, common.sources_line(cells), fontsize=6, wrap=True)
    common.save_figure(fig, out_dir, "model_error", cells, title, written)
