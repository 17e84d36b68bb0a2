#!/usr/bin/python3
"""Solvers for the hat basis (docs/surface-multigrid.md): per flow (mesh, flow, dt) a table of each
solver's mean seconds per step, its ratio to CHOLMOD's step, the multigrid's contraction per cycle
and the RMS distance of its last frame to the CHOLMOD flow's, and a figure of distance against time
per step. The tracked octree runs beside the hat basis on the same flows."""

import statistics

import matplotlib.pyplot as plt

import common
import table1


def flow_key(r):
    """The flow a cell belongs to: (mesh, flow, dt)."""
    return (common.get(r, "config.mesh"), common.get(r, "config.flow"), common.get(r, "config.dt"))


def solver_name(r):
    """"hat, multigrid W(5,5) x1", "hat, pcg (ichol)", "octree, multigrid W(5,5) x1", ..."""
    s = common.get(r, "config.solver", {}) or {}
    name = s.get("name", "?")
    if name == "multigrid":
        name += " %s(%s,%s) x%s" % (s.get("cycle"), s.get("smooth"), s.get("smooth"), s.get("cycles"))
    elif name == "pcg":
        pre = s.get("preconditioner")
        if pre == "multigrid":
            pre = "multigrid %s(%s,%s)" % (s.get("cycle"), s.get("smooth"), s.get("smooth"))
        name += " (%s)" % pre
    elif name == "petsc":  # the KSP and PC as the run named them: petsc-cg-gamg, ...
        name = r.get("solver_name") or name
    return "%s, %s" % (common.get(r, "config.basis", "?"), name)


def last_distance(r):
    """RMS distance to the reference flow at the last frame that has one, and that step."""
    best = None
    for e in r.get("reference_distance") or []:
        if isinstance(e, dict) and common.finite(e.get("rms")) and (best is None or e["step"] > best[1]):
            best = (e["rms"], e["step"])
    return best or (None, None)


def contraction(r):
    """Median over steps of the residual ratio per cycle after the first (multigrid with two or
    more cycles a step); None otherwise."""
    ratios = []
    for s in r.get("steps") or []:
        res = common.get(s, "solver.residuals") or []
        for a, b in zip(res[:-1], res[1:]):
            if common.finite(a) and common.finite(b) and a > 0:
                ratios.append(b / a)
    return statistics.median(ratios) if ratios else None


def make(results, out_dir, reference, written):
    """Write hat_multigrid.md and hat_multigrid.png."""
    cells = common.first_repetition(results)
    flows = common.group_by(cells, flow_key)
    sections, panels = [], []
    for key in sorted(flows, key=str):
        group = flows[key]
        base = [r for r in group if common.get(r, "config.basis") == "hat"
                and common.get(r, "config.solver.name") == "cholmod"]
        base_step = table1.mean_step(base[0], "total") if base else None
        rows, points = [], []
        for r in sorted(group, key=solver_name):
            step = table1.mean_step(r, "total")
            dist, at = last_distance(r)
            ratio = step / base_step if common.finite(step) and common.finite(base_step) else None
            rows.append([solver_name(r), r.get("status", "?"), common.time_text(r, step), common.fmt(ratio, "%.2f"),
                         common.fmt(table1.mean_step(r, "solve")), common.fmt(contraction(r), "%.2f"),
                         common.fmt(dist), at if at is not None else "—"])
            if common.finite(step) and common.finite(dist) and dist > 0 and not common.contended(r):
                points.append((solver_name(r), step, dist))
        title = "%s, %s, dt = %s" % key
        sections.append("### " + title + "\n\n" + common.markdown_table(
            ["solver", "status", "s / step", "/ CHOLMOD", "solve s", "contraction", "RMS to CHOLMOD", "at step"],
            rows))
        panels.append((title, points, base_step))
    text = ("Mean seconds per step over steps 2 on; contraction: median residual ratio per cycle where a "
            "step runs several (PCG: per iteration); RMS distance of the last frame to the CHOLMOD flow's "
            "(absolute: the models lie in the unit cube, the sphere has radius 1).\n\n" + "\n\n".join(sections))
    common.save_markdown(text, out_dir, "hat_multigrid", cells, "Hat-basis solvers against CHOLMOD", written)
    if not any(p for _, p, _ in panels):
        common.warn("hat_multigrid: no cell has both a step time and a distance to CHOLMOD; no figure")
        return
    fig, axes = plt.subplots(1, len(panels), figsize=(4.2 * len(panels), 3.8), squeeze=False)
    names = sorted({n for _, pts, _ in panels for n, _, _ in pts})
    for ax, (title, pts, base_step) in zip(axes[0], panels):
        for n, x, y in pts:
            ax.plot([x], [y], "o", color="C%d" % (names.index(n) % 10), label=n)
        if common.finite(base_step):
            ax.axvline(base_step, color="k", ls=":", lw=1, label="hat, cholmod (the reference's time)")
        ax.set_xscale("log")
        ax.set_yscale("log")
        ax.set_xlabel("seconds per step")
        ax.set_title(title, fontsize=8)
    axes[0][0].set_ylabel("RMS distance to the CHOLMOD flow")
    handles = {}
    for ax in axes[0]:
        for h, l in zip(*ax.get_legend_handles_labels()):
            handles.setdefault(l, h)
    fig.legend(list(handles.values()), list(handles.keys()), loc="lower center", ncol=3, fontsize=7,
               bbox_to_anchor=(0.5, -0.12))
    fig.text(0.01, -0.2, common.sources_line(cells), fontsize=6, wrap=True)
    common.save_figure(fig, out_dir, "hat_multigrid", cells, "Hat-basis solvers: distance to CHOLMOD against time",
                       written)
