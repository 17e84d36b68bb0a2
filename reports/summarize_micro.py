#!/usr/bin/python3
"""Turns the Google Benchmark JSON of mcfbench_micro (benchmarks/micro_octree.cpp) into the Markdown
tables of docs/benchmarks.md: rebuilt phases per mesh, and the per-step ratios (tracked vs rebuilt,
tracked vs hat + CHOLMOD, 2 vs 1 threads, W-cycle / SpMV, bytes per cubature point) with their
targets and the paper's values, and each multigrid level's visits and own time per V- and
W-cycle. Ratios only compare benchmarks of the same JSON file (same run); with
--benchmark_repetitions each benchmark counts as the median of its repetitions.

With BM_Floor_* benchmarks in the file (benchmarks/micro_floor.cpp), also the Floors table of
docs/benchmarks.md: per phase its time, the bytes and flops of its floor (solvers/phase_floor.h),
the bandwidth achieved as a fraction of BM_StreamTriad at the same thread count (from the same
file), its floor max(bytes / triad, flops / peak) and its time as a multiple of that floor. The
peak is BM_PeakFlops at the same thread count (from the same file: fused multiply-adds in
registers), or --peak-gflops when given (per thread: the machine's figure times the threads);
without either the floor is the bytes' alone.

With BM_Floor_* or BM_Step_* benchmarks at more than two thread counts ($MCFBENCH_THREADS,
benchmarks/many_core.sh), also a scaling table: each benchmark's time on one thread and its
speed-up at every other count, and the hat multigrid step against CHOLMOD's at its best count.

Usage: reports/summarize_micro.py [--peak-gflops G] micro.json [> table.md]
"""
import json
import re
import sys


# Google Benchmark's time units in milliseconds.
UNIT_MS = {"ns": 1e-6, "us": 1e-3, "ms": 1.0, "s": 1e3}


def median(xs):
    xs = sorted(xs)
    n = len(xs)
    return xs[n // 2] if n % 2 else 0.5 * (xs[n // 2 - 1] + xs[n // 2])


def load(path):
    """(context, {name: benchmark}). With --benchmark_repetitions=N each benchmark has N
    iteration runs (interleaved with the others under --benchmark_enable_random_interleaving):
    its real time and every numeric counter are then their medians over the repetitions, so one
    slow repetition does not set a ratio; "repetitions" says how many there were."""
    data = json.load(open(path))
    runs = {}
    for b in data.get("benchmarks", []):
        if b.get("run_type", "iteration") != "iteration":
            continue
        name = b.get("run_name", b["name"])
        # "BM_X/threads:2/iterations:5/real_time" -> "BM_X/threads:2"
        name = "/".join(p for p in name.split("/") if p != "real_time" and not p.startswith("iterations:"))
        runs.setdefault(name, []).append(b)
    out = {}
    for name, rs in runs.items():
        b = dict(rs[-1])
        if len(rs) > 1:
            # Repetitions share their unit; convert anyway so a mixed file cannot skew the median.
            b["real_time"] = median([ms(r) for r in rs]) / UNIT_MS[b.get("time_unit", "ns")]
            for k, v in b.items():
                if k != "real_time" and isinstance(v, (int, float)) and not isinstance(v, bool) and \
                        all(isinstance(r.get(k), (int, float)) for r in rs):
                    b[k] = median([r[k] for r in rs])
        b["repetitions"] = len(rs)
        # Each counter's smallest and largest repetition (the bandwidth probe's spread).
        b["spread"] = {k: (min(r[k] for r in rs), max(r[k] for r in rs)) for k in rs[0]
                       if isinstance(rs[0][k], (int, float)) and not isinstance(rs[0][k], bool)
                       and all(isinstance(r.get(k), (int, float)) for r in rs)}
        out[name] = b
    return data.get("context", {}), out


def ms(b):
    return b["real_time"] * UNIT_MS[b.get("time_unit", "ns")]


def fmt(x, digits=3):
    if x is None:
        return "—"
    if isinstance(x, float) and (abs(x) >= 1e4 or (abs(x) < 1e-2 and x != 0)):
        return f"{x:.{digits}g}"
    if isinstance(x, float):
        return f"{x:.{digits}g}" if abs(x) < 100 else f"{x:.0f}"
    return str(x)


def floor_table(b, peak_gflops=None):
    """Markdown lines of the Floors table, [] without BM_Floor_* benchmarks. A benchmark skipped
    for a level the mesh lacks (error_occurred) is left out."""
    triad, triad_spread = {}, {}
    # "BM_StreamTriad/0" (all cores) first, so that an explicit thread count of the same value wins.
    for name, x in sorted(b.items(), key=lambda kv: not kv[0].startswith("BM_StreamTriad/0")):
        if name.startswith("BM_StreamTriad/") and "bandwidth_GBps" in x:
            threads = int(x.get("threads", 0))
            triad[threads] = x["bandwidth_GBps"] * 1e9
            triad_spread[threads] = x.get("spread", {}).get("bandwidth_GBps")
    probe_peak = {}
    for name, x in sorted(b.items(), key=lambda kv: not kv[0].startswith("BM_PeakFlops/0")):
        if name.startswith("BM_PeakFlops/") and "flops_per_second" in x:
            probe_peak[int(x.get("threads", 0))] = x["flops_per_second"]
    rows = []
    for name, x in b.items():
        if not name.startswith("BM_Floor_") or x.get("error_occurred") or "bytes" not in x:
            continue
        seconds = ms(x) * 1e-3
        threads = int(x.get("threads", 0))
        probe = triad.get(threads)
        nbytes, flops = float(x["bytes"]), float(x["flops"])
        peak = peak_gflops * 1e9 * threads if peak_gflops else probe_peak.get(threads)
        floor = max(nbytes / probe if probe else 0.0, flops / peak if peak else 0.0)
        achieved = nbytes / seconds if seconds > 0 else None
        label = name[len("BM_Floor_"):] + (f" ({x['label']})" if x.get("label") else "")
        rows.append(f"| {label} | {fmt(ms(x))} | {fmt(nbytes / 1e6)} | {fmt(flops / 1e6)} | "
                    f"{fmt(achieved / 1e9 if achieved else None)} | "
                    f"{fmt(achieved / probe if achieved and probe else None)} | "
                    f"{fmt(floor * 1e3 if floor > 0 else None)} | "
                    f"{fmt(seconds / floor if floor > 0 else None)} |")
    if not rows:
        return []
    def spread(t):
        lo, hi = triad_spread.get(t) or (None, None)
        return f" ({fmt(lo)}–{fmt(hi)} over its repetitions)" if lo is not None and hi > lo else ""

    probes = ", ".join(f"{t} thread{'s' if t != 1 else ''} {fmt(v / 1e9)} GB/s{spread(t)}"
                       for t, v in sorted(triad.items())) or "none in this file"
    # A probe whose repetitions differ by more than a fifth: the machine's bandwidth moved during
    # the run (on a shared host it does), and a ratio to the floor moves with it.
    unsteady = [t for t, lo_hi in triad_spread.items() if lo_hi and lo_hi[0] > 0
                and lo_hi[1] > 1.2 * lo_hi[0]]
    warning = ([f"The triad's repetitions differ by more than 20% ({', '.join(str(t) for t in sorted(unsteady))}"
                f" thread{'s' if unsteady != [1] else ''}): the bandwidth moved during the run, and"
                " a phase's `x floor` moves with it; a ratio within that of a bound is on neither"
                " side of it.\n"] if unsteady else [])
    if peak_gflops:
        peak = f"{peak_gflops} GFLOP/s per thread"
    elif probe_peak:
        peak = "BM_PeakFlops " + ", ".join(
            f"{t} thread{'s' if t != 1 else ''} {fmt(v / 1e9)} GFLOP/s"
            for t, v in sorted(probe_peak.items()))
    else:
        peak = "not given (bytes alone)"
    return [f"Floors: STREAM triad {probes}; compute peak {peak}.\n"] + warning + [
            "| phase | ms | floor MB | floor Mflop | GB/s | of triad | floor ms | x floor |",
            "|---|---:|---:|---:|---:|---:|---:|---:|"] + rows + [""]


def scaling_table(b):
    """Markdown lines of the many-core scaling table, [] unless some BM_Floor_* or BM_Step_*
    benchmark ran at more than two thread counts, one of them 1 ($MCFBENCH_THREADS,
    benchmarks/many_core.sh): per benchmark its time on one thread and its speed-up over that at
    every other count; then the hat multigrid step's (two V-cycles) against one thread and against
    CHOLMOD's step at CHOLMOD's best thread count."""
    families = {}
    for name, x in b.items():
        if not name.startswith(("BM_Floor_", "BM_Step_")) or x.get("error_occurred"):
            continue
        m = re.search(r"/threads:(\d+)", name)
        if m:
            family = name[:m.start()] + name[m.end():]
            families.setdefault(family, {})[int(m.group(1))] = ms(x)
    if not any(len(ts) > 2 and 1 in ts for ts in families.values()):
        return []
    counts = sorted({t for ts in families.values() for t in ts if t != 1})
    lines = ["Scaling: time on one thread, and the speed-up over it at each thread count.\n",
             "| benchmark | 1 thread (ms) | " + " | ".join(f"{t} threads" for t in counts) + " |",
             "|---|---:|" + "---:|" * len(counts)]
    for family, ts in sorted(families.items()):
        if 1 not in ts or len(ts) < 2:
            continue
        cells = [f"{fmt(ts[1] / ts[t])}x" if t in ts and ts[t] > 0 else "—" for t in counts]
        lines.append(f"| {family[len('BM_'):]} | {fmt(ts[1])} | " + " | ".join(cells) + " |")
    mg = families.get("BM_Step_HatMultigrid/cycle:1", {})
    chol = families.get("BM_Step_HatCholmod", {})
    if mg and 1 in mg:
        top = max(mg)
        line = (f"\nThe hat multigrid step (two V(2,2)-cycles) at {top} threads: {fmt(mg[top])} ms, "
                f"{fmt(mg[1] / mg[top])}x its time on one thread (target ≥ 8x at 16 threads)")
        if chol:
            best = min(chol, key=chol.get)
            line += (f"; CHOLMOD's step at its best count ({best} thread{'s' if best != 1 else ''})"
                     f" {fmt(chol[best])} ms, so the multigrid step is {fmt(mg[top] / chol[best])}x"
                     " CHOLMOD's best")
        lines.append(line + ".")
    return lines + [""]


def main():
    args = sys.argv[1:]
    peak_gflops = None
    if len(args) == 3 and args[0] == "--peak-gflops":
        peak_gflops = float(args[1])
        args = args[2:]
    if len(args) != 1:
        print(__doc__, file=sys.stderr)
        sys.exit(2)
    ctx, b = load(args[0])
    floors = floor_table(b, peak_gflops) + scaling_table(b)
    if floors and all(n.startswith(("BM_Floor_", "BM_Stream", "BM_PeakFlops", "BM_Step_Hat"))
                      for n in b):
        print("\n".join(floors))  # floors (and hat steps) alone: no octree step tables to fill
        return
    get = b.get
    lines = []
    lines.append(f"Machine: {ctx.get('host_name', '?')}, {ctx.get('num_cpus', '?')} CPUs "
                 f"@ {ctx.get('mhz_per_cpu', '?')} MHz, run {ctx.get('date', '?')}\n")
    reps = sorted({x["repetitions"] for x in b.values()})
    if reps and reps != [1]:
        n = str(reps[0]) if len(reps) == 1 else f"{reps[0]}–{reps[-1]}"
        lines.append(f"Times and counters: medians of {n} repetitions per benchmark.\n")

    # Rebuilt phases, one column per mesh.
    meshes = [(0, "armadillo"), (1, "sphere")]
    phases = [("octree build", "BM_Rebuilt_Octree/mesh:{m}"), ("clipping", "BM_Rebuilt_Clip/mesh:{m}"),
              ("integration", "BM_Rebuilt_Integrate/mesh:{m}"),
              ("hierarchy (prolongations + colours)", "BM_Rebuilt_Hierarchy/mesh:{m}"),
              ("multigrid set_matrix (numeric)", "BM_Rebuilt_SetMatrix/mesh:{m}"),
              ("one V-cycle (5 GS)", "BM_Rebuilt_Cycle/mesh:{m}/W:0"),
              ("one W-cycle (5 GS)", "BM_Rebuilt_Cycle/mesh:{m}/W:1"),
              ("five fine Gauss-Seidel sweeps", "BM_Rebuilt_Sweep/mesh:{m}"),
              ("one fine SpMV (3 columns)", "BM_Rebuilt_SpMV/mesh:{m}")]
    present = [(m, n) for m, n in meshes if any(k.format(m=m) in b for _, k in phases)]
    if present:
        def any_bench(m):
            for _, k in phases:
                if k.format(m=m) in b:
                    return b[k.format(m=m)]
            return {}
        head = []
        for m, n in present:
            x = any_bench(m)
            head.append(f"{x.get('label', n)} depth {int(x.get('depth', 0))}")
        lines.append("| rebuilt phase (ms) | " + " | ".join(head) + " |")
        lines.append("|---|" + "---:|" * len(present))
        for name, k in phases:
            row = [fmt(ms(b[k.format(m=m)])) if k.format(m=m) in b else "—" for m, _ in present]
            lines.append(f"| {name} | " + " | ".join(row) + " |")
        for cname, label in [("vertices", "input vertices"), ("split_triangles", "split triangles"),
                             ("dimension", "dimension"), ("cubature_points", "cubature points"),
                             ("levels", "levels"), ("nnz", "fine nonzeros")]:
            row = [fmt(float(any_bench(m).get(cname, 0)), 3) for m, _ in present]
            lines.append(f"| {label} | " + " | ".join(row) + " |")
        row = []
        for m, _ in present:
            w = get(f"BM_Rebuilt_Cycle/mesh:{m}/W:1")
            row.append(fmt(w.get("wcycle_over_spmv")) if w else "—")
        lines.append("| W-cycle / SpMV (target ≤ 20) | " + " | ".join(row) + " |")
        row = []
        for m, _ in present:
            w = get(f"BM_Rebuilt_Sweep/mesh:{m}")
            row.append(fmt(w.get("sweep_over_spmv")) if w else "—")
        lines.append("| one fine sweep / SpMV | " + " | ".join(row) + " |")
        lines.append("")
        sph = get("BM_Rebuilt_Clip/mesh:1") or get("BM_Rebuilt_Cycle/mesh:1/W:1")
        if sph:
            lines.append(f"Sphere at depth {int(sph['depth'])}: {int(sph['vertices'])} vertices, "
                         f"{int(sph['split_triangles'])} split triangles, dimension {int(sph['dimension'])} "
                         f"(paper, 3.7e5-vertex sphere at depth 8: 3.8e6 split triangles, dimension 5.1e5).\n")

    # Where one cycle's time goes, level by level (MultigridLevelWork counters).
    for m, n in meshes:
        cyc = [(c, get(f"BM_Rebuilt_Cycle/mesh:{m}/W:{w}")) for c, w in (("V", 0), ("W", 1))]
        cyc = [(c, x) for c, x in cyc if x and "level0_ms" in x]
        if not cyc:
            continue
        nl = int(cyc[0][1]["mg_levels"])
        lines.append(f"| {n}: level (0 = coarsest) | " +
                     " | ".join(f"{c} visits | {c} ms | {c} share" for c, _ in cyc) + " |")
        lines.append("|---|" + "---:|---:|---:|" * len(cyc))
        for l in reversed(range(nl)):
            row = []
            for _, x in cyc:
                t = x[f"level{l}_ms"]
                row += [fmt(x[f"level{l}_visits"]), fmt(t), f"{100 * t / x['solve_ms']:.0f}%"]
            lines.append(f"| {l} | " + " | ".join(row) + " |")
        row = []
        for _, x in cyc:
            rest = x["solve_ms"] - sum(x[f"level{l}_ms"] for l in range(nl))
            row += ["", fmt(rest), f"{100 * rest / x['solve_ms']:.0f}%"]
        lines.append("| outside the cycle (copies, final residual) | " + " | ".join(row) + " |")
        row = []
        for _, x in cyc:
            row += ["", fmt(x["solve_ms"]), "100%"]
        lines.append("| solve | " + " | ".join(row) + " |")
        lines.append("")

    # Per-step comparisons.
    t2, t1 = get("BM_Step_Tracked/threads:2"), get("BM_Step_Tracked/threads:1")
    rb, hat = get("BM_Step_Rebuilt/threads:2"), get("BM_Step_HatCholmod/threads:2")
    # The stabilized tracked steps (docs/octree-multigrid.md "Stabilization"), by cycle and sweeps.
    # Every 2-thread variant the file holds, in its order; labels read "Nx W(5,5) mesh" (files
    # written before the cycles argument: "W(5,5) mesh"), the mesh dropped here.
    stab = [(" ".join((x.get("label") or "?").split()[:-1]) or "?", x) for n, x in b.items()
            if n.startswith("BM_Step_TrackedStabilized/threads:2/")]
    def steal(x):
        # CPU time the hypervisor took per step (all vCPUs); absent from older benchmark files.
        v = x.get("steal_ms")
        return f", steal {fmt(v)}" if isinstance(v, (int, float)) and v >= 0 else ""

    lines.append("| per step (armadillo, one W-cycle, 5 GS) | ms | breakdown (ms) |")
    lines.append("|---|---:|---|")
    if t2:
        lines.append(f"| tracked, 2 threads | {fmt(ms(t2))} | update {fmt(t2['update_ms'])}, set_matrix "
                     f"{fmt(t2['set_matrix_ms'])}, solve {fmt(t2['solve_ms'])}, evaluate {fmt(t2['evaluate_ms'])}{steal(t2)} |")
    if t1:
        lines.append(f"| tracked, 1 thread | {fmt(ms(t1))} | update {fmt(t1['update_ms'])}, set_matrix "
                     f"{fmt(t1['set_matrix_ms'])}, solve {fmt(t1['solve_ms'])}, evaluate {fmt(t1['evaluate_ms'])}{steal(t1)} |")
    for name, x in stab:
        lines.append(f"| tracked, stabilized, {name}, 2 threads | {fmt(ms(x))} | update {fmt(x['update_ms'])}, "
                     f"set_matrix {fmt(x['set_matrix_ms'])}, solve {fmt(x['solve_ms'])}, "
                     f"evaluate {fmt(x['evaluate_ms'])}{steal(x)} |")
    if rb:
        lines.append(f"| rebuilt, 2 threads | {fmt(ms(rb))} | rebuild {fmt(rb['rebuild_ms'])}, set_matrix "
                     f"{fmt(rb['set_matrix_ms'])}, solve {fmt(rb['solve_ms'])}, evaluate {fmt(rb['evaluate_ms'])}{steal(rb)} |")
    if hat:
        lines.append(f"| hat + CHOLMOD, 2 threads | {fmt(ms(hat))} | update {fmt(hat['update_ms'])}, "
                     f"refactorize {fmt(hat['factorize_ms'])}, solve {fmt(hat['solve_ms'])}{steal(hat)} |")
    lines.append("")
    lines.append("| ratio | ours | target | paper |")
    lines.append("|---|---:|---:|---:|")

    def ratio(a, c):
        return ms(a) / ms(c) if a and c else None

    lines.append(f"| rebuilt / tracked per step | {fmt(ratio(rb, t2))}× | ≥ 7× | ~7× |")
    r = ratio(hat, t2)
    lines.append(f"| hat+CHOLMOD / tracked per step | {fmt(r)}× | ≥ 3× | — |")
    for name, x in stab:
        lines.append(f"| tracked, stabilized {name} / hat+CHOLMOD per step | {fmt(ratio(x, hat))}× "
                     f"| ≤ 0.67× (W(5,5)) | — |")
    lines.append(f"| tracked 1 thread / 2 threads | {fmt(ratio(t1, t2))}× | ≥ 1.7× | — |")
    for m, n in meshes:
        w = get(f"BM_Rebuilt_Cycle/mesh:{m}/W:1")
        if w:
            lines.append(f"| W-cycle / fine SpMV ({n}) | {fmt(w['wcycle_over_spmv'])} | ≤ 20 | — |")
    tb = t2 or t1
    if tb:
        lines.append(f"| bytes of preprocessed data per cubature point | {fmt(tb['bytes_per_cubature_point'])} "
                     f"| ≤ 33 | 100 |")
    print("\n".join(lines + ([""] + floors if floors else [])))


if __name__ == "__main__":
    main()
