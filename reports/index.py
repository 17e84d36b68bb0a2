#!/usr/bin/python3
"""OUT_DIR/index.md: one section per study linking every figure and table written."""

import os


def errored_cell_line(result):
    """'- cell 3 `integrator=bdf2 dt=0.001`: the error' for a result with status "error"."""
    cell = result.get("cell", {}) or {}
    assignment = cell.get("assignment", {}) or {}
    what = " ".join("%s=%s" % (k, v) for k, v in sorted(assignment.items())) or "defaults"
    reason = result.get("error") or (result.get("stop", {}) or {}).get("reason", "?")
    reason = " ".join(str(reason).split())
    return "- cell %s `%s`: %s" % (cell.get("index", "?"), what, reason[:200] + ("…" if len(reason) > 200 else ""))


def make(out_dir, sections):
    """sections: [(study, results folder(s), [{"path", "title", "kind"}], [errored results])].
    Returns the index path."""
    lines = ["# mcfbench report", "",
             "Generated from result files only (reports/make_report.py); each item's sources are in "
             "its `.sources.txt` sidecar.", ""]
    for study, folders, written, errored in sections:
        lines += ["## %s" % study, "", "Results: " + ", ".join("`%s`" % f for f in folders), ""]
        if errored:
            lines += ["**%d cell(s) errored** and are missing from the figures and tables below "
                      "(a rerun of `mcfbench run` retries them):" % len(errored), ""]
            lines += [errored_cell_line(r) for r in sorted(errored, key=lambda r: (r.get("cell", {}) or {}).get("index", 0))]
            lines += [""]
        if not written:
            lines += ["(nothing could be drawn from these results)", ""]
        for w in written:
            rel = os.path.relpath(w["path"], out_dir)
            side = os.path.splitext(rel)[0] + ".sources.txt"
            if w["kind"] == "figure":
                lines += ["### %s" % w["title"], "", "![%s](%s)" % (w["title"], rel), "",
                          "[%s](%s) · [sources](%s)" % (rel, rel, side), ""]
            else:
                lines += ["- [%s](%s) · [sources](%s)" % (w["title"], rel, side), ""]
    path = os.path.join(out_dir, "index.md")
    with open(path, "w") as f:
        f.write("\n".join(lines))
    print("wrote " + path)
    return path
