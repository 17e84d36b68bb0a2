#!/usr/bin/python3
"""Fig. 6 (right) of Chuang & Kazhdan 2011: RMS and max radial error of a flowing sphere vs the
semi-implicit ground-truth radius, per step, one curve per variant."""

import matplotlib.pyplot as plt

import common


def plot_radial_errors(results, out_dir, name, title, reference, written, keys=None):
    """Two panels (RMS, max) of steps[*].radial_error vs step; one colour per variant, named once
    in a legend beside the panels.
    Shared with cubature.py (Fig. 8 has the same axes)."""
    cells = common.first_repetition(results)
    keys = keys if keys is not None else common.varying_keys(cells)
    fig, axes = plt.subplots(1, 2, figsize=(10, 3.8), sharex=True)
    everything = []
    for i, r in enumerate(cells):
        color = "C%d" % (i % 10)
        for ax, metric in zip(axes, ("rms", "max")):
            xs, ys = common.series(r, "radial_error." + metric)
            if not xs:
                continue
            # Earlier curves drawn wider, so a curve that coincides with a later one (3-point and
            # degree-6 cubature, the paper's point in Fig. 8) still shows at its edges.
            ax.plot(xs, ys, "-" if metric == "rms" else "--", color=color, lw=max(1.2, 3.0 - 0.6 * i),
                    label=common.label(r, keys))
            common.mark_stop(ax, r, xs, ys, color)
            everything += ys
    for ax, metric in zip(axes, ("rms", "max")):
        common.plot_reference_curves(ax, reference, metric)
        ax.set_xlabel("step")
        ax.set_ylabel("%s radial error" % ("RMS" if metric == "rms" else "max"))
        common.log_if_positive(ax, everything)
    common.legend_beside(list(axes))
    fig.suptitle(title)
    fig.text(0.01, -0.02, common.sources_line(cells), fontsize=6, wrap=True)
    return common.save_figure(fig, out_dir, name, cells, title, written)


def make(results, out_dir, reference, written):
    """Write sphere_error.png."""
    plot_radial_errors(results, out_dir, "sphere_error",
                       "Sphere: radial error vs semi-implicit radius (Fig. 6 right)", reference, written)
