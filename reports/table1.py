#!/usr/bin/python3
"""Table 1 of Chuang & Kazhdan 2011: per model and depth, input vertices, split triangles,
dimension, set-up time, per-step system update + solve for tracked and rebuilt octrees, and the
tracked-vs-rebuilt speed-up, with the paper's row beside ours when the reference file has one.

Reference format (harness/configs/table1.reference.json), read if present:
  {"rows": [{"model": "Bimba", "mesh": "<our stand-in spec, optional>", "depth": 8,
             "input_vertices": 3.0e5, "split_triangles": 2.7e6, "dimension": 3.4e5,
             "setup_seconds": 4, "system_seconds": 3, "update_seconds": 0.9, "solve_seconds": 0.14}]}
"""

import statistics

import common


def mean_step(result, phase):
    """Mean per-step seconds of one phase (update / solve / evaluate / total) over steps 2 on
    (step 1 alone when the flow has one): the solver builds its pattern and hierarchy in step 1,
    the paper's "+system" in Table 1, which it counts apart from the per-step times."""
    xs, ys = common.series(result, "seconds." + phase)
    steady = [y for x, y in zip(xs, ys) if x >= 2]
    ys = steady or ys
    return statistics.mean(ys) if ys else None


def system_seconds(result):
    """Step 1's total beyond the later steps' mean (the solver's pattern and hierarchy: the
    paper's "+system"), or None with fewer than two steps."""
    xs, ys = common.series(result, "seconds.total")
    later = [y for x, y in zip(xs, ys) if x >= 2]
    first = [y for x, y in zip(xs, ys) if x == 1]
    if not later or not first:
        return None
    return max(0.0, first[0] - statistics.mean(later))


def median_over(results, fn):
    """Median over repetitions of fn(result), ignoring missing values and, where any repetition
    ran uncontended, the contended ones (common.quiet_or_all)."""
    vals = [v for v in (fn(r) for r in common.quiet_or_all(results)) if common.finite(v)]
    return statistics.median(vals) if vals else None


def setup_seconds(result):
    """system.setup_seconds.total, else the sum of its phases: the paper's "set-up time"."""
    s = common.get(result, "system.setup_seconds")
    if isinstance(s, dict):
        if common.finite(s.get("total")):
            return s["total"]
        vals = [v for v in s.values() if common.finite(v)]
        return sum(vals) if vals else None
    return s if common.finite(s) else None


def tracking(r):
    """The cell's mode: "tracked" or "rebuilt", with ", stabilized" for the normal-gradient
    stabilized system (a result without the key ran the paper's system)."""
    mode = common.get(r, "config.octree.tracking") or common.get(r, "config.basis", "?")
    stabilized = common.get(r, "config.octree.stabilization", "none") not in ("none", None)
    return mode + (", stabilized" if stabilized else "")


def model_key(r):
    """A row: the model, its depth and the commit that ran it (a speed-up never divides one
    commit's times by another's)."""
    return (common.get(r, "config.mesh", r["_stem"]), common.get(r, "config.octree.depth"), common.commit_of(r))


def find_paper_row(reference, mesh, depth):
    """The reference row for our mesh spec (its "mesh" field), or None."""
    for row in (reference or {}).get("rows", []) if isinstance(reference, dict) else []:
        if isinstance(row, dict) and row.get("mesh") == mesh and row.get("depth", depth) == depth:
            return row
    return None


def paper_table(reference):
    """The paper's own Table 1 from the reference file, as Markdown."""
    rows = []
    for row in reference.get("rows", []):
        rows.append([row.get("model", "?"), row.get("depth", "—"), common.fmt(row.get("input_vertices")),
                     common.fmt(row.get("split_triangles")), common.fmt(row.get("dimension")),
                     "%s (+%s)" % (common.fmt(row.get("setup_seconds")), common.fmt(row.get("system_seconds"))),
                     "%s + %s" % (common.fmt(row.get("update_seconds")), common.fmt(row.get("solve_seconds")))])
    return common.markdown_table(["model", "depth", "input vertices", "split triangles", "dimension",
                                  "set-up (+system) s", "update + solve s"], rows)


def make(results, out_dir, reference, written):
    """Write table1.md."""
    # Of a cell run by several commits, the newest commit's repetitions (as the figures draw).
    results = common.newest_commits(results)[0]
    several = len({common.commit_of(r) for r in results}) > 1
    rows, left_out = [], []
    for (mesh, depth, commit), all_rs in common.group_by(results, model_key).items():
        name = common.short_value(mesh) + (" @%s" % commit if several else "")
        # A flow that stopped (singular, error) timed fewer or other steps than the flow asked
        # for: its means would pass for a speed-up, so it is named below the table instead.
        rs = [r for r in all_rs if r.get("status") == "ok"]
        for r in all_rs:
            if r.get("status") != "ok":
                left_out.append("%s at depth %s, %s: %s (%s)" % (
                    name, common.fmt(depth, "%d"), tracking(r), r.get("status", "?"),
                    common.get(r, "stop.reason", "?")))
        by_mode = common.group_by(rs, tracking)
        tr, rb = by_mode.get("tracked", []), by_mode.get("rebuilt", [])
        st = by_mode.get("tracked, stabilized", [])
        base = tr or st or rb or rs or all_rs
        upd_t, sol_t = median_over(tr, lambda r: mean_step(r, "update")), median_over(tr, lambda r: mean_step(r, "solve"))
        upd_r, sol_r = median_over(rb, lambda r: mean_step(r, "update")), median_over(rb, lambda r: mean_step(r, "solve"))
        upd_s, sol_s = median_over(st, lambda r: mean_step(r, "update")), median_over(st, lambda r: mean_step(r, "solve"))
        tot_t, tot_r = median_over(tr, lambda r: mean_step(r, "total")), median_over(rb, lambda r: mean_step(r, "total"))
        speedup = tot_r / tot_t if common.finite(tot_t) and common.finite(tot_r) and tot_t > 0 else None
        paper = find_paper_row(reference, mesh, depth)
        paper_cell = ("%s + %s" % (common.fmt(paper.get("update_seconds")), common.fmt(paper.get("solve_seconds")))
                      if paper else "—")
        rows.append([name, common.fmt(depth, "%d"),
                     common.fmt(median_over(base, lambda r: common.get(r, "mesh.vertices")), "%.3g"),
                     common.fmt(median_over(base, lambda r: common.get(r, "system.split_triangles")), "%.3g"),
                     common.fmt(median_over(base, lambda r: common.get(r, "system.dimension")), "%.3g"),
                     "%s (+%s)" % (common.fmt(median_over(base, setup_seconds)),
                                   common.fmt(median_over(tr, system_seconds))),
                     "%s + %s" % (common.fmt(upd_t), common.fmt(sol_t)),
                     "%s + %s" % (common.fmt(upd_s), common.fmt(sol_s)),
                     "%s + %s" % (common.fmt(upd_r), common.fmt(sol_r)),
                     common.fmt(speedup, "%.1f×"), paper_cell])
    header = ["model", "depth", "input vertices", "split triangles", "dimension", "set-up (+system) s",
              "tracked update + solve s/step", "tracked, stabilized update + solve s/step",
              "rebuilt update + solve s/step", "speed-up (total/step)",
              "paper update + solve"]
    text = "## Table 1: performance (Chuang & Kazhdan 2011)\n\n" + common.markdown_table(header, rows)
    text += ("\n\nThe tracked and rebuilt columns solve the paper's system, the stabilized column the "
             "normal-gradient stabilized one (docs/octree-multigrid.md); the speed-up is rebuilt over "
             "tracked, both on the paper's system.")
    text += ("\n\nTimes are medians over repetitions of the mean per-step seconds of steps 2 on. Step 1 also "
             "builds the solver's pattern and hierarchy, the paper's \"+system\": shown beside the set-up as "
             "the tracked step 1's time beyond the later steps' mean (a rebuilt step builds them every step).")
    if several:
        text += ("\n\nThe results come from several commits: a row per model and commit (\"@commit\"), its "
                 "times the medians over that commit's repetitions; of a cell several commits ran, the newest "
                 "commit's results only (index.md names the commits).")
    if left_out:
        text += ("\n\nLeft out of the times (the flow stopped):\n\n" +
                 "\n".join("- " + line for line in left_out))
    if isinstance(reference, dict) and reference.get("rows"):
        text += "\n\n### Paper (Table 1)\n\n" + paper_table(reference)
    common.save_markdown(text, out_dir, "table1", results, "Table 1: performance", written)
