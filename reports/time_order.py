#!/usr/bin/python3
"""SGI note / DESIGN.md time_order study: error vs time step (log-log) per integrator with
fitted convergence slopes, and a Markdown table of fitted orders and the largest stable dt."""

import math

import matplotlib.pyplot as plt

import common


def final_error(result):
    """Error of a run at its final time: the last reference_distance RMS when the runner measured
    against a small-dt run (spatial error cancels), else the last RMS radial error against the
    continuous radius sqrt(1-4t)."""
    ref = [e for e in result.get("reference_distance") or [] if common.finite(e.get("rms"))]
    if ref:
        return ref[-1]["rms"]
    xs, ys = common.series(result, "radial_error.rms_continuous")
    return ys[-1] if ys else None


def stable(result, threshold=None):
    """A run is stable when it finished with a finite error (below the reference file's
    "stability_threshold" when it gives one, the SGI note's definition)."""
    e = final_error(result)
    if result.get("status") != "ok" or not common.finite(e):
        return False
    return not common.finite(threshold) or e < threshold


def variant(result):
    """Integrator name, with "(frozen)" when the operators were not extrapolated."""
    name = common.get(result, "config.integrator", "?")
    if common.get(result, "config.extrapolate") is False:
        name += " (frozen)"
    return name


def fit_slope(points):
    """Least-squares slope of log(error) vs log(dt); None with fewer than 2 distinct dt."""
    pts = [(math.log(dt), math.log(e)) for dt, e in points if dt > 0 and e > 0]
    if len({p[0] for p in pts}) < 2:
        return None
    mx = sum(p[0] for p in pts) / len(pts)
    my = sum(p[1] for p in pts) / len(pts)
    sxx = sum((p[0] - mx) ** 2 for p in pts)
    return sum((p[0] - mx) * (p[1] - my) for p in pts) / sxx


def make(results, out_dir, reference, written):
    """Write time_order.png and time_order.md."""
    cells = common.first_repetition(results)
    groups = common.group_by(cells, variant)
    fig, ax = plt.subplots(figsize=(6.5, 4.5))
    rows, values = [], []
    reference = reference if isinstance(reference, dict) else {}
    expected = reference.get("orders", {})
    threshold = reference.get("stability_threshold")
    for i, (name, rs) in enumerate(groups.items()):
        with_dt = [r for r in rs if common.finite(common.get(r, "config.dt"))]
        pts = sorted((common.get(r, "config.dt"), final_error(r)) for r in with_dt if stable(r, threshold))
        slope = fit_slope(pts)
        color = "C%d" % (i % 10)
        if pts:
            ax.plot([p[0] for p in pts], [p[1] for p in pts], "o-", color=color, ms=4,
                    label="%s (slope %s)" % (name, common.fmt(slope, "%.2f")))
            values += [p[1] for p in pts]
        stable_dts = [common.get(r, "config.dt") for r in with_dt if stable(r, threshold)]
        unstable = [common.get(r, "config.dt") for r in with_dt if not stable(r, threshold)]
        rows.append([name, common.fmt(slope, "%.2f"), len(pts), common.fmt(max(stable_dts) if stable_dts else None),
                     common.fmt(min(unstable) if unstable else None),
                     str(expected.get(name, expected.get(name.split(" ")[0], "—")))])
    ax.set_xscale("log")
    common.log_if_positive(ax, values)
    ax.set_xlabel("time step δ")
    ax.set_ylabel("error at final time")
    if ax.get_legend_handles_labels()[0]:
        ax.legend()
    title = "Temporal convergence: error vs δ per integrator"
    ax.set_title(title, fontsize=9)
    fig.text(0.01, -0.03, common.sources_line(cells), fontsize=6, wrap=True)
    common.save_figure(fig, out_dir, "time_order", cells, title, written)
    text = "## Temporal order per integrator\n\n" + common.markdown_table(
        ["integrator", "fitted order", "stable runs fitted", "largest stable δ", "smallest unstable δ",
         "expected (reference)"], rows)
    common.save_markdown(text, out_dir, "time_order", cells, "Fitted temporal orders", written)
