#!/usr/bin/python3
"""Time per step of the hat basis's flow against mesh size, per solver (docs/surface-multigrid.md):
hat_scaling.png (log-log) and hat_scaling.md. A point is the median over the configuration's
uncontended repetitions (all, marked contended, where every one shared its cores)."""

import matplotlib.pyplot as plt

import common
import hat_multigrid
import table1


def step_seconds(repetitions, phase):
    """The median over the repetitions of each one's per-step seconds of `phase` (steps 2 on,
    table1.mean_step): one sample per repetition, as the repetitions were interleaved."""
    return common.median([t for t in (table1.mean_step(r, phase) for r in repetitions) if common.finite(t)])


def make(results, out_dir, reference, written):
    """Write hat_scaling.png and hat_scaling.md."""
    cells = common.first_repetition(results)
    by_solver = {}
    for reps, timed in common.by_configuration(results):
        by_solver.setdefault(hat_multigrid.solver_name(reps[0]), []).append((reps[0], timed))
    fig, ax = plt.subplots(figsize=(6.0, 4.2))
    rows = []
    for i, name in enumerate(sorted(by_solver)):
        pts = sorted((common.get(first, "mesh.faces"), step_seconds(timed, "total"),
                      step_seconds(timed, "solve"), all(common.contended(r) for r in timed), len(timed))
                     for first, timed in by_solver[name] if common.finite(common.get(first, "mesh.faces")))
        pts = [p for p in pts if common.finite(p[1])]
        quiet = [p for p in pts if not p[3]]
        if quiet:
            ax.plot([p[0] for p in quiet], [p[1] for p in quiet], "o-", color="C%d" % i, label=name)
        busy = [p for p in pts if p[3]]
        if busy:  # shared its cores with other work: drawn, but not as a measurement
            ax.plot([p[0] for p in busy], [p[1] for p in busy], "o", mfc="none", color="0.6",
                    label="contended (not measured)")
        rows += [[name, "%d" % p[0], common.fmt(p[1]) + (" (contended)" if p[3] else ""), common.fmt(p[2]),
                  "%d" % p[4]] for p in pts]
    ax.set_xscale("log")
    ax.set_yscale("log")
    ax.set_xlabel("faces")
    ax.set_ylabel("seconds per step (steps 2 on)")
    ax.legend()
    title = "Hat basis: time per step against mesh size"
    ax.set_title(title, fontsize=9)
    fig.text(0.01, -0.03, common.sources_line(cells), fontsize=6, wrap=True)
    common.save_figure(fig, out_dir, "hat_scaling", cells, title, written)
    common.save_markdown(common.markdown_table(["solver", "faces", "s / step", "solve s", "repetitions"], rows), out_dir,
                         "hat_scaling", cells, title, written)
