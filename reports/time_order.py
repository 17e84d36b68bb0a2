#!/usr/bin/python3
"""SGI note / DESIGN.md time_order study: error vs time step (log-log) per integrator with
fitted convergence slopes, and a Markdown table of fitted orders and the largest stable dt."""

import math

import matplotlib.pyplot as plt

import common


def final_mean_radius(result):
    """Mean vertex radius at the final step (spheres), or None."""
    xs, ys = common.series(result, "radial_error.mean_radius")
    return ys[-1] if ys else None


def final_time(result):
    steps = result.get("steps") or []
    return steps[-1].get("t") if steps else None


def reference_runs(cells):
    """Per flow, the run with the smallest dt among second-order extrapolated schemes
    (Crank-Nicolson, else BDF2): the temporal reference. Measuring against it on the same mesh
    cancels the spatial error (DESIGN.md 'Time integrators'); against sqrt(1-4t) the mesh puts a
    floor under every scheme."""
    refs = {}
    for name in ("crank-nicolson", "bdf2"):
        for r in cells:
            flow = common.get(r, "config.flow", "mcf")
            if flow in refs or common.get(r, "config.integrator") != name or \
                    common.get(r, "config.extrapolate") is False or r.get("status") != "ok":
                continue
            best = min((c for c in cells if common.get(c, "config.flow", "mcf") == flow and
                        common.get(c, "config.integrator") == name and common.get(c, "config.extrapolate") is not False
                        and c.get("status") == "ok" and final_mean_radius(c) is not None),
                       key=lambda c: common.get(c, "config.dt", 1e9), default=None)
            if best is not None:
                refs[flow] = best
    return refs


def final_error(result, refs=None):
    """Error of a run at its final time: |mean radius - the reference run's| when a temporal
    reference of the same flow and final time exists, else the last reference_distance RMS, else
    the last RMS radial error against the continuous radius."""
    ref = (refs or {}).get(common.get(result, "config.flow", "mcf"))
    mine = final_mean_radius(result)
    if ref is not None and ref is not result and mine is not None and final_mean_radius(ref) is not None and \
            common.finite(final_time(result)) and abs(final_time(result) - final_time(ref)) < 1e-9:
        return abs(mine - final_mean_radius(ref))
    dist = [e for e in result.get("reference_distance") or [] if common.finite(e.get("rms"))]
    if dist:
        return dist[-1]["rms"]
    xs, ys = common.series(result, "radial_error.rms_continuous")
    return ys[-1] if ys else None


def stable(result, threshold=None, refs=None):
    """A run is stable when it finished with a finite error (below the reference file's
    "stability_threshold" when it gives one, the SGI note's definition)."""
    e = final_error(result, refs)
    if result.get("status") != "ok" or not common.finite(e):
        return False
    return not common.finite(threshold) or e < threshold


def variant(result):
    """Flow and integrator name, with "(frozen)" when the operators were not extrapolated."""
    name = common.get(result, "config.flow", "mcf") + ": " + common.get(result, "config.integrator", "?")
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
    refs = reference_runs(cells)
    # The reference runs themselves are left out of the fits.
    groups = common.group_by([c for c in cells if not any(c is r for r in refs.values())], variant)
    fig, ax = plt.subplots(figsize=(6.5, 4.5))
    rows, values = [], []
    reference = reference if isinstance(reference, dict) else {}
    expected = reference.get("orders", {})
    threshold = reference.get("stability_threshold")
    for i, (name, rs) in enumerate(groups.items()):
        with_dt = [r for r in rs if common.finite(common.get(r, "config.dt"))]
        pts = sorted((common.get(r, "config.dt"), final_error(r, refs)) for r in with_dt if stable(r, threshold, refs))
        slope = fit_slope(pts)
        color = "C%d" % (i % 10)
        if pts:
            ax.plot([p[0] for p in pts], [p[1] for p in pts], "o-", color=color, ms=4,
                    label="%s (slope %s)" % (name, common.fmt(slope, "%.2f")))
            values += [p[1] for p in pts]
        stable_dts = [common.get(r, "config.dt") for r in with_dt if stable(r, threshold, refs)]
        unstable = [common.get(r, "config.dt") for r in with_dt if not stable(r, threshold, refs)]
        rows.append([name, common.fmt(slope, "%.2f"), len(pts), common.fmt(max(stable_dts) if stable_dts else None),
                     common.fmt(min(unstable) if unstable else None),
                     str(expected.get(name, expected.get(name.split(": ")[-1],
                                                          expected.get(name.split(": ")[-1].split(" ")[0], "—"))))])
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
    note = "Errors are |mean radius − reference| at the final time, the reference being the smallest-δ " \
        "extrapolated Crank–Nicolson run of the same flow (%s).\n\n" % ", ".join(
            "%s: δ = %s" % (f, common.fmt(common.get(r, "config.dt"))) for f, r in refs.items()) if refs else ""
    text = "## Temporal order per integrator\n\n" + note + common.markdown_table(
        ["integrator", "fitted order", "stable runs fitted", "largest stable δ", "smallest unstable δ",
         "expected (reference)"], rows)
    common.save_markdown(text, out_dir, "time_order", cells, "Fitted temporal orders", written)
