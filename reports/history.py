#!/usr/bin/python3
"""Performance over commits: one plot per history file, one line per benchmark (or cell).

usage: /usr/bin/python3 reports/history.py HISTORY.jsonl [HISTORY.jsonl ...] OUT_DIR

Reads the history lines that benchmarks/run_micro.sh (results/micro/history.jsonl: Google
Benchmark real times) and `mcfbench compare --history` (results/history.jsonl: per-cell medians)
append, one JSON object per measured commit, and writes OUT_DIR/history_<name>.png and
history.md. Each curve is normalised by its first value, so benchmarks of different sizes share
one axis and a regression reads as a rise above 1.
"""

import json
import os
import sys

import matplotlib

matplotlib.use("Agg")
import matplotlib.pyplot as plt  # noqa: E402


def load(path):
    """History entries in file order; broken lines are skipped with a warning."""
    entries = []
    with open(path) as f:
        for n, line in enumerate(f, 1):
            line = line.strip()
            if not line:
                continue
            try:
                entries.append(json.loads(line))
            except json.JSONDecodeError as e:
                print("history.py: %s:%d: skipped (%s)" % (path, n, e), file=sys.stderr)
    return entries


def series(entries):
    """{name: [(commit index, value)]} from micro (benchmarks) or compare (cells) entries."""
    out = {}
    for i, e in enumerate(entries):
        for name, b in (e.get("benchmarks") or {}).items():
            if isinstance(b, dict) and isinstance(b.get("real_time"), (int, float)):
                out.setdefault(name, []).append((i, b["real_time"]))
        for key, c in (e.get("cells") or {}).items():
            if isinstance(c, dict) and isinstance(c.get("median"), (int, float)):
                out.setdefault(c.get("label") or key, []).append((i, c["median"]))
    return out


def plot(path, entries, out_dir):
    name = os.path.splitext(os.path.basename(os.path.dirname(os.path.abspath(path))) + "_" +
                            os.path.basename(path))[0]
    data = series(entries)
    fig, ax = plt.subplots(figsize=(7.5, 4.2))
    for label, pts in sorted(data.items()):
        base = pts[0][1] or 1.0
        ax.plot([p[0] for p in pts], [p[1] / base for p in pts], "o-", ms=3, lw=1.2, label=label[:60])
    commits = [str(e.get("commit", "?"))[:12] for e in entries]
    ax.set_xticks(range(len(commits)))
    ax.set_xticklabels(commits, rotation=45, ha="right", fontsize=7)
    ax.axhline(1.0, color="0.6", lw=0.8)
    ax.set_ylabel("time / first measurement")
    ax.set_title("Performance over commits: %s" % os.path.basename(path), fontsize=9)
    if data:
        ax.legend(fontsize=6, ncol=2)
    fig.text(0.01, 0.0, "Source: %s" % path, fontsize=6)
    out = os.path.join(out_dir, "history_%s.png" % name)
    fig.savefig(out, dpi=120, bbox_inches="tight")
    plt.close(fig)
    print("wrote %s" % out)
    return out, data, commits


def main(argv):
    if len(argv) < 2:
        print(__doc__, file=sys.stderr)
        return 2
    *paths, out_dir = argv
    os.makedirs(out_dir, exist_ok=True)
    lines = ["## Performance over commits\n"]
    status = 0
    for path in paths:
        if not os.path.isfile(path):
            print("history.py: no such history file: %s" % path, file=sys.stderr)
            status = 1
            continue
        entries = load(path)
        png, data, commits = plot(path, entries, out_dir)
        lines.append("### %s\n\n![%s](%s)\n" % (path, os.path.basename(png), os.path.basename(png)))
        rows = [(label, pts[-2], pts[-1]) for label, pts in sorted(data.items()) if len(pts) >= 2]
        if rows:
            lines.append("| benchmark | previous (commit) | latest (commit) | ratio |\n|---|---|---|---|")
            for label, (ia, a), (ib, b) in rows:
                lines.append("| %s | %.4g (%s) | %.4g (%s) | %.2f |" % (label, a, commits[ia], b, commits[ib], b / a if a else float("nan")))
            lines.append("")
    out = os.path.join(out_dir, "history.md")
    with open(out, "w") as f:
        f.write("\n".join(lines) + "\n")
    print("wrote %s" % out)
    return status


if __name__ == "__main__":
    sys.exit(main(sys.argv[1:]))
