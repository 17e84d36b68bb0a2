#!/usr/bin/python3
"""OUT_DIR/index.md: one section per study linking every figure and table written."""

import os


def make(out_dir, sections):
    """sections: [(study, results folder(s), [{"path", "title", "kind"}])]. Returns the index path."""
    lines = ["# mcfbench report", "",
             "Generated from result files only (reports/make_report.py); each item's sources are in "
             "its `.sources.txt` sidecar.", ""]
    for study, folders, written in sections:
        lines += ["## %s" % study, "", "Results: " + ", ".join("`%s`" % f for f in folders), ""]
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
