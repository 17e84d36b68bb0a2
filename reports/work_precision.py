#!/usr/bin/python3
"""Work-precision diagrams (docs/studies.md "work_precision"): per case and size, the error of the
final step against the time per step of every setting, one curve per method family traced by its
accuracy knob (cycles, tolerance, CG iterations), log-log, with the Pareto front marked; a table of
the fastest setting that reaches three error levels; and the time to reach an error level against
the mesh size.

Time is the median over repetitions of each repetition's median step over steps 2..N (the cell's
`timing.step_median_seconds`). A repetition that shared its cores with other work (`contention.
contended`) is not a measurement: a point all of whose repetitions were contended is drawn grey and
hollow, and is neither on the front nor in the tables. A cell that stopped before its last step has
no comparable error: it is listed, not plotted."""


import matplotlib.pyplot as plt

import common

# The error levels of the tables, as multiples of the exact point's error (hat + CHOLMOD on the
# case's own mesh): within 10%, within 2x, within 10x of what an exact solve of that discretization
# reaches.
EPSILON_FACTORS = (1.1, 2.0, 10.0)

# Families whose fastest point reaching a level is within this fraction of the winner's time are
# named beside it as a tie: a setting's step time moved by 2% (median) and 8% (90th percentile)
# between two full runs of the study on one machine (docs/studies.md), so a closer race is not
# decided by one run.
TIE = 0.10


# ---------------------------------------------------------------------------------------------
# Families and knobs, from the config alone

def family_and_knob(r):
    """(family label, knob label, knob value for ordering) of a result's config."""
    c = common.get(r, "config", {}) or {}
    s = c.get("solver", {}) or {}
    o = c.get("octree", {}) or {}
    name = s.get("name", "?")
    guarded = (s.get("stall_ratio") or 0) > 0 or (s.get("residual_bound") or 0) > 0
    fallback = " + guard" if name == "multigrid" and guarded else ""
    cycle = "%s(%s,%s)" % (s.get("cycle"), s.get("smooth"), s.get("smooth"))
    if c.get("basis") == "hat":
        if name == "cholmod":
            if o.get("refine_input"):
                return "reference: hat + CHOLMOD, refined mesh", "", 0
            return "hat + CHOLMOD", "", 0
        if name == "multigrid":
            return "hat MG %s%s" % (cycle, fallback), "x%s" % s.get("cycles"), s.get("cycles", 0)
        if name == "pcg":
            pre = s.get("preconditioner")
            if pre == "multigrid":
                pre = "MG " + cycle
            tol = s.get("tolerance", 0)
            return "hat CG (%s)" % pre, "tol %g" % tol, -tol
        if name == "petsc":  # the paper's baseline (GAMG) and hypre's BoomerAMG, by tolerance
            tol = s.get("tolerance", 0)
            amg = "BoomerAMG" if "boomeramg" in (s.get("petsc_options") or "") else "GAMG"
            return "hat CG (PETSc %s)" % amg, "tol %g" % tol, -tol
        return "hat + %s" % name, "", 0
    if o.get("tracking") == "rebuilt":
        system = "rebuilt octree"
    elif o.get("stabilization") == "none":
        system = "octree (paper's system)"
    else:
        system = "octree (stabilized, w %g)" % (o.get("stabilization_weight") or 0)
    if name == "cholmod":
        return system + " + CHOLMOD", "", 0
    if name == "multigrid":
        return "%s %s%s" % (system, cycle, fallback), "x%s" % s.get("cycles"), s.get("cycles", 0)
    if name == "pcg":
        if s.get("preconditioner") == "multigrid":
            k = s.get("max_iterations", 0)
            return "%s CG by its %s" % (system, cycle), "%s its" % k, k
        return "%s CG (%s)" % (system, s.get("preconditioner")), "tol %g" % s.get("tolerance", 0), 0
    return "%s + %s" % (system, name), "", 0


def is_exact_point(family):
    return family == "hat + CHOLMOD"


def is_reference(family):
    return family.startswith("reference:")


# ---------------------------------------------------------------------------------------------
# Cases and errors

def case_of(r):
    """(kind, mesh, flow, dt): sphere, model or degenerating (an MCF flow on a real model run to
    just before its singular stop)."""
    mesh = common.get(r, "config.mesh", "?")
    flow = common.get(r, "config.flow", "?")
    if mesh.startswith("sphere") or mesh.startswith("icosphere"):
        kind = "sphere"
    elif flow == "mcf":
        kind = "degenerating"
    else:
        kind = "model"
    return kind, mesh, flow, common.get(r, "config.dt")


def errors_of(r):
    """{error name: value} of the final step; empty for a cell that stopped early."""
    if r.get("status") not in ("ok",):
        return {}
    steps = r.get("steps") or []
    if not steps:
        return {}
    last = steps[-1]
    out = {}
    for name, path in (("radial error, semi-implicit", "radial_error.rms"),
                       ("radial error, continuous", "radial_error.rms_continuous")):
        v = common.get(last, path)
        if common.finite(v):
            out[name] = v
    final_step = last.get("step")
    for d in r.get("reference_distance") or []:
        if isinstance(d, dict) and d.get("step") == final_step and common.finite(d.get("rms")):
            out["RMS distance to the reference flow"] = d["rms"]
    return out


def vertices_of(r):
    v = common.get(r, "mesh.vertices")
    return v if common.finite(v) else None


# ---------------------------------------------------------------------------------------------
# Points and the front

def points_of(results):
    """One point per configuration: {family, knob, order, case, vertices, time, setup, flow_time,
    errors, contended, repetitions, status, result}. Time is the median over the uncontended
    repetitions (all repetitions, and `contended` set, where every one was contended)."""
    points = []
    for reps, quiet_or_all in common.by_configuration(results):
        first = reps[0]
        quiet = [r for r in reps if not common.contended(r)]
        timed = [r for r in quiet_or_all if common.finite(common.get(r, "timing.step_median_seconds"))]
        med = lambda path: common.median_of(timed, path)  # noqa: E731
        family, knob, order = family_and_knob(first)
        points.append({
            "family": family, "knob": knob, "order": order, "case": case_of(first),
            "vertices": vertices_of(first), "time": med("timing.step_median_seconds"),
            "setup": med("timing.setup_seconds"), "flow_time": med("timing.flow_seconds"),
            "errors": errors_of(first), "contended": not quiet, "repetitions": len(reps),
            "status": first.get("status", "?"), "result": first,
        })
    return points


def pareto_front(points, error):
    """The points (dicts with "time" and errors[error]) that no other point dominates: none is at
    least as fast and at least as accurate and better in one. Contended points and points without
    a time or that error are neither on the front nor dominate anything. Ordered by time."""
    usable = [p for p in points if not p.get("contended") and common.finite(p.get("time"))
              and common.finite(p.get("errors", {}).get(error))]
    front = []
    for p in usable:
        t, e = p["time"], p["errors"][error]
        dominated = any(q is not p and q["time"] <= t and q["errors"][error] <= e
                        and (q["time"] < t or q["errors"][error] < e) for q in usable)
        if not dominated:
            front.append(p)
    return sorted(front, key=lambda p: (p["time"], p["errors"][error]))


def fastest_within(points, error, epsilon):
    """The fastest uncontended point whose error is at most epsilon (None if none)."""
    ok = [p for p in points if not p.get("contended") and common.finite(p.get("time"))
          and common.finite(p.get("errors", {}).get(error)) and p["errors"][error] <= epsilon]
    return min(ok, key=lambda p: (p["time"], p["errors"][error])) if ok else None


def epsilons(points, error):
    """The table's error levels for one case and size: EPSILON_FACTORS times the exact point's
    error; empty without an exact point."""
    exact = [p for p in points if is_exact_point(p["family"]) and common.finite(p["errors"].get(error))]
    if not exact:
        return []
    return [f * exact[0]["errors"][error] for f in EPSILON_FACTORS]


def error_names(points):
    names = []
    for p in points:
        for e in p["errors"]:
            if e not in names:
                names.append(e)
    return names


# ---------------------------------------------------------------------------------------------
# Output

def family_colours(points):
    families = sorted({p["family"] for p in points if not is_reference(p["family"])})
    return {f: "C%d" % (i % 10) for i, f in enumerate(families)}, families


def marker(family):
    return "s" if family.startswith("hat") else ("^" if "rebuilt" in family else "o")


def draw_panel(ax, pts, error, colours, title):
    front = pareto_front(pts, error)
    for family in sorted({p["family"] for p in pts}):
        if is_reference(family):
            continue
        fam = sorted((p for p in pts if p["family"] == family and common.finite(p["time"])
                      and common.finite(p["errors"].get(error))), key=lambda p: p["order"])
        measured = [p for p in fam if not p["contended"]]
        if measured:
            ax.plot([p["time"] for p in measured], [p["errors"][error] for p in measured], "-" + marker(family),
                    color=colours[family], ms=4, lw=1, label=family)
        busy = [p for p in fam if p["contended"]]
        if busy:
            ax.plot([p["time"] for p in busy], [p["errors"][error] for p in busy], marker(family), ms=5,
                    mfc="none", color="0.6", label="contended (not measured)")
    if front:
        ax.plot([p["time"] for p in front], [p["errors"][error] for p in front], "-", color="k", lw=2.5,
                alpha=0.25, zorder=0, label="Pareto front")
    ax.set_xscale("log")
    ax.set_yscale("log")
    ax.set_xlabel("seconds per step (median, steps 2..N)")
    ax.set_ylabel(error, fontsize=8)
    ax.set_title(title, fontsize=8)


def describe(p):
    return p["family"] + (" " + p["knob"] if p["knob"] else "")


def case_title(case, vertices):
    kind, mesh, flow, dt = case
    return "%s: %s, %s, dt %g, %s vertices" % (kind, mesh, flow, dt or 0, vertices)


def panels_in_order(points):
    """[(case, vertices, points)] per case and size: kind order (sphere, model, degenerating), then
    flow and dt, then size."""
    kinds = {"sphere": 0, "model": 1, "degenerating": 2}
    by_case = common.group_by(points, lambda p: (p["case"], p["vertices"]))
    return [(case, vertices, pts) for (case, vertices), pts in sorted(by_case.items(), key=lambda kv: (
        kinds.get(kv[0][0][0], 3), str(kv[0][0][2:]), kv[0][1] or 0, kv[0][0][1]))]


def fastest_of_family(pts, family, error, epsilon):
    """The fastest uncontended point of `family` whose error is at most epsilon (None if none)."""
    return fastest_within([p for p in pts if p["family"] == family], error, epsilon)


def tied_families(pts, error, epsilon, best):
    """[(family, its time / best's)] of the other families whose fastest point reaching epsilon
    is within TIE of `best`'s time, closest first."""
    if not best:
        return []
    out = []
    for family in {p["family"] for p in pts} - {best["family"]}:
        q = fastest_of_family(pts, family, error, epsilon)
        if q and q["time"] <= (1 + TIE) * best["time"]:
            out.append((family, q["time"] / best["time"]))
    return sorted(out, key=lambda fr: (fr[1], fr[0]))


def error_levels(points):
    """The rows of the tables "fastest setting to reach error <= eps": one dict per case and size,
    error and level, {title, error, factor, epsilon, best (a point or None), ties (tied_families),
    exact_time, points (the case's and size's)}."""
    rows = []
    for case, vertices, pts in panels_in_order(points):
        exact_time = next((p["time"] for p in pts if is_exact_point(p["family"])), None)
        for error in error_names(pts):
            for factor, eps in zip(EPSILON_FACTORS, epsilons(pts, error)):
                best = fastest_within(pts, error, eps)
                rows.append({"title": case_title(case, vertices), "error": error, "factor": factor,
                             "epsilon": eps, "best": best, "ties": tied_families(pts, error, eps, best),
                             "exact_time": exact_time, "points": pts})
    return rows


def make(results, out_dir, reference, written):
    """Write work_precision.md, work_precision.png and work_precision_scaling.png."""
    points = points_of(results)
    cells = common.first_repetition(results)
    if not points:
        common.warn("work_precision: no results")
        return
    colours, families = family_colours(points)
    panels, sections, stopped = [], [], []
    levels = error_levels(points)
    for case, vertices, pts in panels_in_order(points):
        title = case_title(case, vertices)
        stopped += ["%s — %s: %s" % (title, describe(p), common.get(p["result"], "stop.reason", p["status"]))
                    for p in pts if p["status"] != "ok"]
        for error in error_names(pts):
            panels.append((title, pts, error))
            rows = []
            for level in (lv for lv in levels if lv["title"] == title and lv["error"] == error):
                best, eps, factor, exact_time = level["best"], level["epsilon"], level["factor"], level["exact_time"]
                tie = "; ".join("%s +%.0f%%" % (f, 100 * (r - 1)) for f, r in level["ties"])
                rows.append(["%.3g (%gx exact)" % (eps, factor),
                             (describe(best) + (" (tie within %.0f%%: %s)" % (100 * TIE, tie) if tie else ""))
                             if best else "none reaches it",
                             common.fmt(best["time"]) if best else "—",
                             common.fmt(best["time"] / exact_time, "%.2f") if best and common.finite(exact_time) else "—",
                             common.fmt(best["setup"]) if best else "—",
                             common.fmt(best["flow_time"]) if best else "—",
                             common.fmt(best["errors"][error]) if best else "—"])
            front = pareto_front(pts, error)
            busy = sum(1 for p in pts if p["contended"])
            sections.append(
                "### %s — %s\n\n" % (title, error)
                + (common.markdown_table(["error ≤", "fastest setting", "s / step", "/ hat + CHOLMOD",
                                          "set-up s", "whole flow s", "its error"], rows) if rows
                   else "No exact point (hat + CHOLMOD) for this case: no error levels.")
                + "\n\nPareto front (fastest first): "
                + ("; ".join("%s (%s s, %s)" % (describe(p), common.fmt(p["time"]), common.fmt(p["errors"][error]))
                             for p in front) or "none")
                + (".\n\n%d contended point(s) left out." % busy if busy else "."))
    sections += degenerating_sections(points)
    text = ("Error of the final step against the time per step (the median over repetitions of each "
            "repetition's median step over steps 2..N; repetitions interleaved). Error levels are "
            "multiples of the exact point's error (hat + CHOLMOD on the same mesh). Set-up (hierarchy, "
            "symbolic analysis, octree) and the whole flow's time are given apart.\n\n"
            + "\n\n".join(sections)
            + ("\n\n### Stopped before the last step (no comparable error)\n\n" + "\n".join("- " + s for s in stopped)
               if stopped else ""))
    common.save_markdown(text, out_dir, "work_precision", cells, "Work-precision: the fastest setting per error level",
                         written)
    ncol = min(3, len(panels))
    nrow = (len(panels) + ncol - 1) // ncol
    fig, axes = plt.subplots(nrow, ncol, figsize=(4.6 * ncol, 3.9 * nrow), squeeze=False)
    for ax, (title, pts, error) in zip(axes.flat, panels):
        draw_panel(ax, pts, error, colours, title)
    for ax in list(axes.flat)[len(panels):]:
        ax.axis("off")
    handles = {}
    for ax in axes.flat:
        for h, l in zip(*ax.get_legend_handles_labels()):
            handles.setdefault(l, h)
    fig.legend(list(handles.values()), list(handles.keys()), loc="upper center", ncol=3, fontsize=7,
               bbox_to_anchor=(0.5, 0.0))
    fig.tight_layout()
    common.save_figure(fig, out_dir, "work_precision", cells, "Work-precision diagrams", written)
    draw_scaling(points, colours, out_dir, cells, written)


def fallback_steps(result):
    """(steps that needed more than their cycles, extra cycles in all, CG iterations in all, steps a
    factorization finished) of a result."""
    steps = [s for s in result.get("steps") or [] if common.get(s, "solver.fallback")]
    return (len(steps), sum(common.get(s, "solver.fallback.extra_cycles", 0) or 0 for s in steps),
            sum(common.get(s, "solver.fallback.iterations", 0) or 0 for s in steps),
            sum(1 for s in steps if (common.get(s, "solver.fallback.direct_solves", 0) or 0) > 0))


def degenerating_sections(points):
    """Per degenerating case: each fixed-work setting with its guard (the residual bound and the
    stall test) against CHOLMOD on the same system (same basis and octree system): the ratio of
    their errors, the steps each completed, and what the guard added."""
    out = []
    for case, pts in common.group_by([p for p in points if p["case"][0] == "degenerating"],
                                     lambda p: (p["case"], p["vertices"])).items():
        rows = []
        for p in pts:
            if not p["family"].endswith(" + guard"):
                continue
            system = p["family"].split(" V(")[0].split(" W(")[0].replace("hat MG", "hat")
            exact = next((q for q in pts if q["family"] == system + " + CHOLMOD"), None)
            name = "distance to the reference flow"
            e, x = p["errors"].get("RMS distance to the reference flow"), (exact or {}).get("errors", {}).get(
                "RMS distance to the reference flow")
            n, extra, its, direct = fallback_steps(p["result"])
            rows.append([describe(p), common.fmt(e), exact["family"] if exact else "—", common.fmt(x),
                         common.fmt(e / x, "%.2f") if common.finite(e) and common.finite(x) else "—",
                         "%s / %s" % (common.get(p["result"], "stop.step", "?"),
                                      common.get(exact["result"], "stop.step", "?") if exact else "—"),
                         "%d steps, %d extra cycles, %d CG iterations, %d factorized" % (
                             n, extra, its, direct)])
        if rows:
            out.append("### Degenerating: %s, %s vertices — the fixed-work settings with their guard\n\n" % (
                case[0][1], case[1]) + common.markdown_table(
                    ["setting", name, "CHOLMOD on the same system", "its distance", "ratio", "steps (ours / CHOLMOD)",
                     "guard"], rows))
    return out


def draw_scaling(points, colours, out_dir, cells, written):
    """Time to reach 2x the exact point's error against the mesh size, per case kind and error."""
    factor = EPSILON_FACTORS[1]
    kinds = common.group_by(points, lambda p: p["case"][0])
    series = []
    for kind, pts in sorted(kinds.items()):
        for error in error_names(pts):
            curves = {}
            for (case, vertices), group in common.group_by(pts, lambda p: (p["case"], p["vertices"])).items():
                levels = epsilons(group, error)
                if not levels or not common.finite(vertices):
                    continue
                eps = levels[1] if factor == EPSILON_FACTORS[1] else levels[0]
                for family in {p["family"] for p in group if not is_reference(p["family"])}:
                    best = fastest_within([p for p in group if p["family"] == family], error, eps)
                    if best:
                        curves.setdefault(family, []).append((vertices, best["time"]))
            if curves:
                series.append(("%s — %s" % (kind, error), curves))
    if not series:
        common.warn("work_precision: no case has an exact point and timed settings at any size; no scaling figure")
        return
    fig, axes = plt.subplots(1, len(series), figsize=(4.6 * len(series), 3.9), squeeze=False)
    for ax, (title, curves) in zip(axes[0], series):
        for family, xy in sorted(curves.items()):
            xy.sort()
            ax.plot([x for x, _ in xy], [y for _, y in xy], "-" + marker(family), color=colours.get(family, "k"),
                    ms=4, lw=1, label=family)
        ax.set_xscale("log")
        ax.set_yscale("log")
        ax.set_xlabel("vertices")
        ax.set_ylabel("seconds per step to reach %gx the exact error" % factor, fontsize=8)
        ax.set_title(title, fontsize=8)
    handles = {}
    for ax in axes[0]:
        for h, l in zip(*ax.get_legend_handles_labels()):
            handles.setdefault(l, h)
    fig.legend(list(handles.values()), list(handles.keys()), loc="upper center", ncol=3, fontsize=7,
               bbox_to_anchor=(0.5, 0.0))
    fig.tight_layout()
    common.save_figure(fig, out_dir, "work_precision_scaling", cells,
                       "Work-precision: time to reach 2x the exact error against mesh size", written)
