#!/usr/bin/python3
"""OUT_DIR/index.md: one section per study linking every figure and table written."""

import os

import common


MAX_MISSING_LISTED = 50  # a longer list ends with a count; `mcfbench collect` lists them all


def cell_words(cell):
    """'cell 3 `dt=0.001 integrator=bdf2`' for a cell ({"index", "assignment"}) of a result or plan."""
    assignment = cell.get("assignment", {}) or {}
    what = " ".join("%s=%s" % (k, v) for k, v in sorted(assignment.items())) or "defaults"
    return "cell %s `%s`" % (cell.get("index", "?"), what)


def errored_cell_line(result):
    """'- cell 3 `dt=0.001 integrator=bdf2`: the error' for a result with status "error"."""
    cell = result.get("cell", {}) or {}
    reason = result.get("error") or (result.get("stop", {}) or {}).get("reason", "?")
    reason = " ".join(str(reason).split())
    return "- %s: %s" % (cell_words(cell), reason[:200] + ("…" if len(reason) > 200 else ""))


def missing_cell_line(cell, quick_mixed):
    """'- cell 3 `dt=0.001 integrator=bdf2` rep 1 (quick run)' for a planned cell without a result."""
    rep = cell.get("repetition", 0) or 0
    return "- %s%s%s" % (cell_words(cell), " rep %d" % rep if rep else "",
                         (" (quick run)" if cell.get("quick") else " (full run)") if quick_mixed else "")


def gap_lines(gap):
    """The index's note on a study whose planned cells do not all have a result (make_report's gaps)."""
    missing = gap["missing"]
    lines = ["**Incomplete: %d of %d planned cells have results.** The figures and tables below lack "
             "the %d cell(s) `mcfbench run` planned that have none yet (the run stopped or is still going; "
             "rerunning it computes them):" % (gap["have"], gap["total"], len(missing)), ""]
    lines += [missing_cell_line(c, gap["quick_mixed"]) for c in missing[:MAX_MISSING_LISTED]]
    if len(missing) > MAX_MISSING_LISTED:
        lines += ["- … and %d more (`mcfbench collect` lists them all)" % (len(missing) - MAX_MISSING_LISTED)]
    return lines + [""]


def make(out_dir, sections):
    """sections: [(study, results folder(s), [{"path", "title", "kind"}], [errored results],
    gap, commits)], gap None or {"have", "total", "missing": [planned cells], "quick_mixed"} for
    a study whose planned cells do not all have a result, commits None or a line naming the
    commits whose results the study mixed (common.commits_note). A written item of kind "note"
    is a line of text ("text"), not a file. Returns the index path."""
    lines = ["# mcfbench report", "",
             "Generated from result files only (reports/make_report.py); each item's sources are in "
             "its `.sources.txt` sidecar.", ""]
    gaps = [(study, gap) for study, _, _, _, gap, _ in sections if gap]
    if gaps:
        lines += ["**Incomplete report:** planned cells have no result yet in %s; each study's section "
                  "lists them, and its figures and tables say \"incomplete\"." % ", ".join(
                      "%s (%d of %d)" % (study, gap["have"], gap["total"]) for study, gap in gaps), ""]
    for study, folders, written, errored, gap, commits in sections:
        lines += ["## %s" % study, "", "Results: " + ", ".join("`%s`" % f for f in folders), ""]
        if commits:
            lines += ["**Several commits:** " + commits, ""]
        if gap:
            lines += gap_lines(gap)
        if errored:
            lines += ["**%d cell(s) errored** and are missing from the figures and tables below "
                      "(a rerun of `mcfbench run` retries them):" % len(errored), ""]
            lines += [errored_cell_line(r) for r in sorted(errored, key=lambda r: (r.get("cell", {}) or {}).get("index", 0))]
            lines += [""]
        if not [w for w in written if w["kind"] != "note"]:
            lines += ["(nothing could be drawn from these results)", ""]
        for w in written:
            if w["kind"] == "note":
                lines += [w["text"], ""]
                continue
            rel = os.path.relpath(w["path"], out_dir)
            side = os.path.splitext(rel)[0] + ".sources.txt"
            if w["kind"] == "figure":
                lines += ["### %s" % w["title"], "", "![%s](%s)" % (w["title"], rel), "",
                          "[%s](%s) · [sources](%s)" % (rel, rel, side), ""]
            else:
                lines += ["- [%s](%s) · [sources](%s)" % (w["title"], rel, side), ""]
    path = os.path.join(out_dir, "index.md")
    common.write_text(path, "\n".join(lines))
    print("wrote " + common.shown(path))
    return path
