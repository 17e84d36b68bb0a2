#!/usr/bin/python3
"""Kazhdan, Solomon & Ben-Chen 2012, Fig. 7: convergence (‖ΔX‖ per step), quasi-conformal error
and sphericity per step, MCF vs heat vs cMCF per model; singular stops marked with an x."""

import matplotlib.pyplot as plt

import common

PANELS = (("step_difference", "‖X$_{n+1}$ − X$_n$‖", True),
          # Log too: the error is >= 1 (1 = conformal), and a pinching MCF reaches 1e9 while
          # cMCF stays near 1; a linear axis flattens every other curve onto 0.
          ("metrics.quasi_conformal", "quasi-conformal error", True),
          ("metrics.sphericity", "sphericity (σ/μ of radius)", True))
FLOW_COLORS = {"mcf": "C3", "heat": "C2", "cmcf": "C0"}


def model_of(r):
    return common.short_value(common.get(r, "config.mesh", r["_stem"]))


def plot_model(model, cells, out_dir, reference, written, index):
    """One figure per model: three panels, one curve per flow (and other varying keys)."""
    keys = [k for k in common.varying_keys(cells) if k != "mesh"]
    fig, axes = plt.subplots(1, 3, figsize=(13, 3.6))
    for i, r in enumerate(cells):
        flow = common.get(r, "config.flow", "")
        color = FLOW_COLORS.get(flow, "C%d" % (i % 10)) if len(cells) <= 3 else "C%d" % (i % 10)
        for ax, (path, ylabel, logy) in zip(axes, PANELS):
            xs, ys = common.series(r, path)
            if xs:
                ax.plot(xs, ys, "-", color=color, lw=1.3, label=common.label(r, keys or ["flow"]))
                common.mark_stop(ax, r, xs, ys, color)
    for ax, (path, ylabel, logy) in zip(axes, PANELS):
        common.plot_reference_curves(ax, reference, path.split(".")[-1])
        ax.set_xlabel("step")
        ax.set_ylabel(ylabel)
        if logy:
            vals = [y for r in cells for y in common.series(r, path)[1]]
            common.log_if_positive(ax, vals)
        if not ax.get_legend_handles_labels()[0]:
            ax.text(0.5, 0.5, "not recorded", transform=ax.transAxes, ha="center", color="0.5")
    common.legend_beside(list(axes))
    title = "%s: MCF vs heat vs cMCF (SGP 2012 Fig. 7)" % model
    fig.suptitle(title)
    fig.text(0.01, -0.03, common.sources_line(cells), fontsize=6, wrap=True)
    common.save_figure(fig, out_dir, "cmcf_%02d" % index, cells, title, written)


def last(r, path):
    xs, ys = common.series(r, path)
    return ys[-1] if ys else None


def analytic_rows(cells):
    """Rows for runs on a sphere or an open cylinder without area normalisation, whose steps
    carry radial_error (mean_radius) or cylinder (ring_radius) beside the analytic radii."""
    rows = []
    for r in cells:
        steps = r.get("steps") or []
        if not steps:
            continue
        s = steps[-1]
        for key, measured in (("cylinder", "ring_radius"), ("radial_error", "mean_radius")):
            rec = s.get(key)
            if not isinstance(rec, dict) or not common.finite(rec.get(measured)):
                continue
            m, si, c = rec.get(measured), rec.get("radius_semi_implicit"), rec.get("radius_continuous")
            rows.append([model_of(r), common.get(r, "config.flow", "?"), common.fmt(common.get(r, "config.dt")),
                         common.fmt(s.get("t")), common.fmt(m, "%.5f"), common.fmt(si, "%.5f"), common.fmt(c, "%.5f"),
                         common.fmt(abs(m - si) if common.finite(si) else None, "%.2e"),
                         common.fmt(abs(m - c) if common.finite(c) else None, "%.2e")])
            break
    return rows


def summary(cells, out_dir, reference, written):
    """Markdown table: how each run ended and its last recorded metrics."""
    rows = []
    for r in cells:
        rows.append([model_of(r), common.get(r, "config.flow", "?"), common.fmt(common.get(r, "config.dt")),
                     r.get("status", "?"), common.get(r, "stop.step", len(r.get("steps", []))),
                     common.get(r, "stop.reason", ""), common.fmt(last(r, "step_difference")),
                     common.fmt(last(r, "metrics.quasi_conformal"), "%.4f"),
                     common.fmt(last(r, "metrics.sphericity"))])
    text = "## cMCF study: how each run ended\n\n" + common.markdown_table(
        ["model", "flow", "dt", "status", "stop step", "reason", "last ‖ΔX‖", "last QC error", "last sphericity"], rows)
    analytic = analytic_rows(cells)
    if analytic:
        text += ("\n\n## Analytic radii: sphere and the middle ring of a long open cylinder "
                 "(SGP 2012 Table 1)\n\nThe measured radius (the sphere's mean vertex radius, the "
                 "cylinder's middle ring) against the semi-implicit recursion of the same δ and the "
                 "continuous solution, at the last step; on the cylinder MCF, cMCF and heat differ "
                 "(sqrt(r0²−2t), r0 − t/r0, r0 exp(−t/r0²)), on the sphere cMCF equals MCF.\n\n" +
                 common.markdown_table(["model", "flow", "dt", "t", "measured", "semi-implicit", "continuous",
                                        "error vs semi-implicit", "error vs continuous"], analytic))
    paper = (reference or {}).get("notes") or (reference or {}).get("values")
    if paper:
        text += "\n\nPaper: %s\n" % paper
    common.save_markdown(text, out_dir, "cmcf_summary", cells, "cMCF study summary", written)


def make(results, out_dir, reference, written):
    """Write cmcf_NN.png per model and cmcf_summary.md."""
    cells = common.first_repetition(results)
    for i, (model, rs) in enumerate(common.group_by(cells, model_of).items()):
        plot_model(model, rs, out_dir, reference, written, i)
    summary(cells, out_dir, reference, written)
