#!/usr/bin/python3
"""The table of benchmarks/configs/hat_step_options.json's (or galerkin_refresh.json's) results (docs/benchmarks.md, "Floors"):
per flow and setting, the median over the interleaved repetitions of each repetition's median step
(steps 2 on), its ratio to CHOLMOD's, the Galerkin refresh's share (set-up of the system per step),
and the RMS distance of the last frame to the CHOLMOD flow's (the mesh in the unit cube).

usage: summarize_step_options.py RESULTS_DIR"""

import os
import sys

sys.path.insert(0, os.path.join(os.path.dirname(os.path.abspath(__file__)), "..", "reports"))
import common  # noqa: E402


def setting(r):
    s = common.get(r, "config.solver", {}) or {}
    if s.get("name") == "cholmod":
        return "CHOLMOD"
    name = "%s(%s,%s) x%s" % (s.get("cycle"), s.get("smooth"), s.get("smooth"), s.get("cycles"))
    if s.get("name") == "pcg":
        name = "CG + %s(%s,%s) to %g" % (s.get("cycle"), s.get("smooth"), s.get("smooth"),
                                        s.get("tolerance"))
    refresh = s.get("galerkin_refresh", 1) or 1
    extras = [e for e, on in (("by term", s.get("galerkin_by_term")),
                              ("mixed", s.get("precision") == "mixed"),
                              ("coarse every %d" % refresh, refresh > 1)) if on]
    return name + (", " + ", ".join(extras) if extras else "")


def main(argv):
    if len(argv) != 2:
        sys.exit(__doc__)
    results = common.load_results(argv[1])
    rows = {}
    for reps, timed in common.by_configuration(results):
        first = reps[0]
        flow = "%s, dt %g" % (common.get(first, "config.flow"), common.get(first, "config.dt"))
        step = common.median_of(timed, "timing.step_median_seconds")
        d = (first.get("reference_distance") or [{}])[-1].get("rms")
        fallbacks = sum(1 for r in reps for s in r.get("steps", [])
                        if (common.get(s, "solver.fallback_iterations", 0) or 0) > 0)
        rows.setdefault(flow, []).append((setting(first), step, d, all(common.contended(r) for r in timed),
                                          fallbacks, len(timed)))
    for flow, cells in sorted(rows.items()):
        base = next((c[1] for c in cells if c[0] == "CHOLMOD"), None)
        print("\n%s\n" % flow)
        print("| setting | ms / step | x CHOLMOD | RMS distance to CHOLMOD | steps that fell back | repetitions |")
        print("|---|---:|---:|---:|---:|---:|")
        for name, step, d, contended, fallbacks, n in sorted(cells, key=lambda c: (c[0] != "CHOLMOD", c[0])):
            print("| %s | %s%s | %s | %s | %d | %d |" % (
                name, common.fmt(1e3 * step if step else None), " (contended)" if contended else "",
                "%.3f" % (step / base) if step and base else "", common.fmt(d) if d is not None else "",
                fallbacks, n))


if __name__ == "__main__":
    main(sys.argv)
