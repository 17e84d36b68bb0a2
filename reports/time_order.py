#!/usr/bin/python3
"""SGI note / time_order study (docs/studies.md): error vs time step (log-log) per integrator with
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


def setting(result):
    """(flow, mesh, quick): the runs measured against one reference run and drawn in one panel.
    Runs on another mesh (or of a quick run, on its smaller mesh) have another spatial error,
    which only their own reference cancels."""
    return (common.get(result, "config.flow", "mcf"), common.get(result, "config.mesh"),
            bool(common.get(result, "cell.quick", False)))


def reference_runs(cells):
    """Per setting() (flow, mesh, quick flag), the run with the smallest dt among second-order
    extrapolated schemes (Crank-Nicolson, else BDF2): the temporal reference. Measuring against it
    on the same mesh cancels the spatial error (docs/design.md 'Conventions'); against sqrt(1-4t)
    the mesh puts a floor under every scheme."""
    refs = {}
    for name in ("crank-nicolson", "bdf2"):
        for r in cells:
            where = setting(r)
            if where in refs or common.get(r, "config.integrator") != name or \
                    common.get(r, "config.extrapolate") is False or r.get("status") != "ok":
                continue
            best = min((c for c in cells if setting(c) == where and
                        common.get(c, "config.integrator") == name and common.get(c, "config.extrapolate") is not False
                        and c.get("status") == "ok" and final_mean_radius(c) is not None),
                       key=lambda c: common.get(c, "config.dt", 1e9), default=None)
            if best is not None:
                refs[where] = best
    return refs


def final_error(result, refs=None):
    """Error of a run at its final time: |mean radius - the reference run's| when a temporal
    reference of the same flow, mesh, quick flag and final time exists, else the last
    reference_distance RMS, else the last RMS radial error against the continuous radius."""
    ref = (refs or {}).get(setting(result))
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
    """(flow, integrator, frozen, mesh, quick): what tells a study's runs apart besides δ; frozen
    when the operators were not extrapolated. key[:3] names the scheme, (key[0],) + key[3:] is
    its setting() (panel and reference)."""
    flow, mesh, quick = setting(result)
    return (flow, common.get(result, "config.integrator", "?"), common.get(result, "config.extrapolate") is False,
            mesh, quick)


def panel_of(key):
    """A variant() key's setting (flow, mesh, quick)."""
    return (key[0], key[3], key[4])


def panel_name(panel, panels):
    """"mcf", or where the study ran several meshes or full and quick runs "mcf on icosphere:level=3
    (quick)": the flow, with the mesh and the quick flag only where they tell panels apart."""
    flow, mesh, quick = panel
    name = flow
    if len({p[1] for p in panels}) > 1:
        name += " on " + common.short_value(mesh)
    if len({p[2] for p in panels}) > 1:
        name += " (quick)" if quick else " (full)"
    return name


def variant_name(key, with_flow=True, panels=()):
    """"mcf: bdf2 (frozen)", or without the flow "bdf2 (frozen)" (inside the flow's own panel);
    with the mesh and quick flag (panel_name) when `panels` lists several."""
    integrator, frozen = key[1], key[2]
    name = integrator + (" (frozen)" if frozen else "")
    where = panel_name(panel_of(key), panels) if panels else key[0]
    return where + ": " + name if with_flow else name


def fit_slope(points):
    """Least-squares slope of log(error) vs log(dt); None with fewer than 2 distinct dt."""
    pts = [(math.log(dt), math.log(e)) for dt, e in points if dt > 0 and e > 0]
    if len({p[0] for p in pts}) < 2:
        return None
    mx = sum(p[0] for p in pts) / len(pts)
    my = sum(p[1] for p in pts) / len(pts)
    sxx = sum((p[0] - mx) ** 2 for p in pts)
    return sum((p[0] - mx) * (p[1] - my) for p in pts) / sxx


def fitted_points(pts, unstable):
    """The stable (δ, error) points the order is fitted to: all of them, except that when some
    larger δ was unstable and three or more stable points remain, the one at the stability edge
    (the largest stable δ below the smallest unstable one) is left out. There the scheme's
    highest modes are barely damped and its error is theirs, not the truncation error (explicit
    Euler on MCF at the edge: 5e-2 where the trend gives 2e-4)."""
    pts = sorted(pts)
    if not unstable or len(pts) < 3:
        return pts
    edge = max((p for p in pts if p[0] < min(unstable)), default=None)
    return [p for p in pts if p is not edge]


# Integrators in the order docs/design.md "Time integrators" lists them: each keeps its colour and
# marker in every flow's panel, so one integrator reads the same in the mcf and the heat panel.
INTEGRATORS = ("explicit-euler", "semi-implicit", "crank-nicolson", "bdf2", "taylor2", "neumann2")
MARKERS = "osD^vP*Xhp<>"


def styles(keys):
    """{variant() key: (colour, marker, linestyle, marker face)}: colour and marker by integrator,
    dashed with open markers when the operators were frozen. A known integrator has its place in
    INTEGRATORS, so it looks the same in every report whichever others ran; others follow it,
    sorted. Distinct within a flow for up to 10 integrators."""
    others = sorted({key[1] for key in keys} - set(INTEGRATORS))
    out = {}
    for key in keys:
        integ, frozen = key[1], key[2]
        i = INTEGRATORS.index(integ) if integ in INTEGRATORS else len(INTEGRATORS) + others.index(integ)
        color = "C%d" % (i % 10)
        out[key] = (color, MARKERS[i % len(MARKERS)], "--" if frozen else "-", "none" if frozen else color)
    return out


def coinciding(curves, rel=0.02):
    """{key: earlier key} for each curve that lies on an earlier one of the same panel (flow,
    mesh, quick flag): at two or more δs run by both, and at every such δ, errors within `rel` of each other (either may have
    runs the other lacks). Where they share δs the later curve is drawn over the earlier one,
    so the legend says so. On the heat flow explicit Euler, semi-implicit Euler and Neumann-2
    have local errors of ±δ²/2 A²X, so their errors agree to leading order."""
    out = {}
    keys = list(curves)
    for i, k in enumerate(keys):
        a = dict(curves[k])
        for earlier in keys[:i]:
            b = dict(curves[earlier])
            shared = a.keys() & b.keys()
            if panel_of(earlier) != panel_of(k) or earlier in out or len(shared) < 2:
                continue
            if all(abs(a[d] - b[d]) <= rel * max(abs(a[d]), abs(b[d])) for d in shared):
                out[k] = earlier
                break
    return out


def order_guides(ax, pts):
    """Grey dotted lines of slope 1 and 2 through the middle of a panel's points, to read the
    fitted orders against."""
    dts = sorted({p[0] for p in pts})
    errs = sorted(p[1] for p in pts)
    if len(dts) < 2 or errs[0] <= 0:
        return
    x0, y0 = math.sqrt(dts[0] * dts[-1]), math.sqrt(errs[0] * errs[-1])
    for order, style in ((1, ":"), (2, "-.")):
        ax.plot([dts[0], dts[-1]], [y0 * (dts[0] / x0) ** order, y0 * (dts[-1] / x0) ** order], style,
                color="0.6", lw=1, label="δ%s guide" % ("¹" if order == 1 else "²"))


def make(results, out_dir, reference, written):
    """Write time_order.png (one log-log panel per flow, and per mesh and quick flag where the
    study has several, its legend beside it) and time_order.md."""
    cells = common.first_repetition(results)
    refs = reference_runs(cells)
    # The reference runs themselves are left out of the fits.
    groups = common.group_by([c for c in cells if not any(c is r for r in refs.values())], variant)
    panels = list(dict.fromkeys(panel_of(key) for key in groups)) or [("mcf", None, False)]
    style = styles(list(groups))
    fig, axes = plt.subplots(len(panels), 1, figsize=(6.5, 3.4 * len(panels)), squeeze=False)
    axes = {panel: ax for panel, ax in zip(panels, axes[:, 0])}
    rows, values, panel_pts, curves = [], {p: [] for p in panels}, {p: [] for p in panels}, {}
    reference = reference if isinstance(reference, dict) else {}
    expected = reference.get("orders", {})
    threshold = reference.get("stability_threshold")
    for key, rs in groups.items():
        integrator = key[1]
        name = variant_name(key, panels=panels)
        # One pass: each run is stable (a point of the fit) or not (its δ bounds the stable range).
        pts, unstable = [], []
        for r in rs:
            dt = common.get(r, "config.dt")
            if not common.finite(dt):
                continue
            if stable(r, threshold, refs):
                pts.append((dt, final_error(r, refs)))
            else:
                unstable.append(dt)
        pts.sort()
        fit = fitted_points(pts, unstable)
        slope = fit_slope(fit)
        if pts:
            curves[key] = (pts, slope)
        rows.append([name, common.fmt(slope, "%.2f"), len(fit), common.fmt(pts[-1][0] if pts else None),
                     common.fmt(min(unstable) if unstable else None),
                     str(expected.get(name, expected.get(variant_name(key), expected.get(
                         variant_name(key, False), expected.get(integrator, "—")))))])
    on_top = coinciding({key: pts for key, (pts, _) in curves.items()})
    for key, (pts, slope) in curves.items():
        panel = panel_of(key)
        color, marker, line, face = style[key]
        label = "%s (slope %s)" % (variant_name(key, False), common.fmt(slope, "%.2f"))
        if key in on_top:
            label += ", on %s" % variant_name(on_top[key], False)
        axes[panel].plot([p[0] for p in pts], [p[1] for p in pts], line, color=color, marker=marker, ms=4,
                         mfc=face, label=label)
        values[panel] += [p[1] for p in pts]
        panel_pts[panel] += pts
    for panel, ax in axes.items():
        order_guides(ax, panel_pts[panel])
        ax.set_xscale("log")
        common.log_if_positive(ax, values[panel])
        ax.set_xlabel("time step δ")
        ax.set_ylabel("error at final time")
        ax.set_title(panel_name(panel, panels), fontsize=9)
        if ax.get_legend_handles_labels()[0]:
            ax.legend(loc="center left", bbox_to_anchor=(1.02, 0.5))
    title = "Temporal convergence: error vs δ per integrator"
    fig.suptitle(title, fontsize=10)
    fig.tight_layout()
    fig.text(0.01, -0.03 / len(panels), common.sources_line(cells), fontsize=6, wrap=True)
    common.save_figure(fig, out_dir, "time_order", cells, title, written)
    same = "flow" if len(set(refs)) == len({where[0] for where in refs}) else "flow, mesh and quick flag"
    note = "Errors are |mean radius − reference| at the final time, the reference being the smallest-δ " \
        "extrapolated Crank–Nicolson run of the same %s (%s).\n\n" % (same, ", ".join(
            "%s: δ = %s" % (panel_name(where, panels + [w for w in refs if w not in panels]),
                            common.fmt(common.get(r, "config.dt"))) for where, r in refs.items())) if refs else ""
    note += "A scheme with unstable runs and three or more stable ones has its order fitted without the " \
        "stable run at the stability edge (drawn, not fitted): there barely damped high-frequency modes, " \
        "not the truncation error, set its error.\n\n"
    if on_top:
        note += "Curves that lie on an earlier one where both ran (errors within 2%% at two or more shared δs, " \
            "and at all of them), drawn over it there; their legend entries say so: %s.\n\n" % "; ".join(
                "%s on %s" % (variant_name(k, panels=panels), variant_name(e, False)) for k, e in on_top.items())
    text = "## Temporal order per integrator\n\n" + note + common.markdown_table(
        ["integrator", "fitted order", "stable runs fitted", "largest stable δ", "smallest unstable δ",
         "expected (reference)"], rows)
    common.save_markdown(text, out_dir, "time_order", cells, "Fitted temporal orders", written)
