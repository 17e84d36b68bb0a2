#!/usr/bin/python3
"""reports/work_precision.py on fabricated result files: the marked Pareto front is exactly the
non-dominated set (against a brute-force check over random points), contended cells are neither on
it nor dominate anything, the table names the fastest setting within each error level, and the
report writes its files. Exit 77 (skip) without matplotlib."""

import json
import os
import random
import sys
import tempfile

try:
    import matplotlib  # noqa: F401
except ImportError:
    print("SKIP: /usr/bin/python3 has no matplotlib")
    sys.exit(77)

sys.path.insert(0, os.path.join(os.path.dirname(os.path.abspath(__file__)), "..", "..", "reports"))
import common  # noqa: E402
import work_precision as wp  # noqa: E402

failures = []


def check(cond, what):
    if not cond:
        failures.append(what)


def fake(index, basis, solver, time, error, repetition=0, contended=False, mesh="sphere:vertices=1000",
         octree=None, status="ok"):
    """A result file as `mcfbench run` writes it, with the fields the report reads."""
    steps = [{"step": s, "seconds": {"total": time}, "radial_error": {"rms": error, "rms_continuous": 10 * error}}
             for s in (1, 2, 3)]
    return {"status": status, "stop": {"step": 3, "reason": "completed"},
            "config": {"mesh": mesh, "flow": "mcf", "dt": 1e-3, "basis": basis, "solver": solver,
                       "octree": octree or {"tracking": "tracked", "stabilization": "normal-gradient",
                                            "stabilization_weight": 0.5, "refine_input": False}},
            "steps": steps, "mesh": {"vertices": 1000},
            "timing": {"step_median_seconds": time, "setup_seconds": 0.1, "flow_seconds": 3 * time + 0.1},
            "contention": {"contended": contended},
            "environment": {"commit": "fake"},
            "cell": {"index": index, "repetition": repetition, "config_key": "k%d" % index, "study": "work_precision",
                     "quick": False, "assignment": {}},
            "_stem": "c%d-%d" % (index, repetition), "_path": "/fake/c%d-%d.json" % (index, repetition),
            "_mtime": 0}


# 1. The front against brute force, on random points, some contended.
rng = random.Random(3)
for trial in range(200):
    pts = [{"time": rng.choice([rng.uniform(0.1, 10), 1.0]), "errors": {"e": rng.choice([rng.uniform(1e-6, 1e-3), 1e-4])},
            "contended": rng.random() < 0.2} for _ in range(rng.randint(1, 25))]
    front = wp.pareto_front(pts, "e")
    usable = [p for p in pts if not p["contended"]]
    expected = [p for p in usable
                if not any(q["time"] <= p["time"] and q["errors"]["e"] <= p["errors"]["e"]
                           and (q["time"] < p["time"] or q["errors"]["e"] < p["errors"]["e"]) for q in usable)]
    check(sorted(map(id, front)) == sorted(map(id, expected)), "trial %d: front differs from the non-dominated set" % trial)
    check(not any(p["contended"] for p in front), "trial %d: a contended point on the front" % trial)

# 2. A contended point that would dominate everything is left out; the table skips it too.
cg = {"name": "cholmod"}
mg = lambda k: {"name": "multigrid", "cycle": "V", "smooth": 2, "cycles": k}  # noqa: E731
results = [fake(0, "hat", cg, 1.0, 1e-5),
           fake(1, "hat", mg(1), 0.2, 5e-5), fake(2, "hat", mg(2), 0.3, 1.05e-5), fake(3, "hat", mg(4), 0.5, 0.9e-5),
           fake(4, "hat", mg(8), 0.01, 1e-9, contended=True)]
# A second repetition of cell 1: contended, slower; the point's time is the quiet repetition's.
results.append(fake(1, "hat", mg(1), 5.0, 5e-5, repetition=1, contended=True))
points = wp.points_of(results)
by_knob = {(p["family"], p["knob"]): p for p in points}
check(by_knob[("hat MG V(2,2)", "x1")]["time"] == 0.2, "the contended repetition's time was used")
check(by_knob[("hat MG V(2,2)", "x8")]["contended"], "an all-contended point is not marked contended")
front = wp.pareto_front(points, "radial error, semi-implicit")
check([p["knob"] for p in front] == ["x1", "x2", "x4"], "front: %s" % [p["knob"] for p in front])
levels = wp.epsilons(points, "radial error, semi-implicit")
check([round(e / 1e-5, 6) for e in levels] == [1.1, 2.0, 10.0], "error levels %s" % levels)
check(wp.fastest_within(points, "radial error, semi-implicit", levels[0])["knob"] == "x2", "fastest within 1.1x")
check(wp.fastest_within(points, "radial error, semi-implicit", levels[2])["knob"] == "x1", "fastest within 10x")
check(wp.fastest_within(points, "radial error, semi-implicit", 1e-7) is None, "nothing reaches 1e-7 uncontended")

# 3. Families and knobs from the config alone.
check(wp.family_and_knob(fake(9, "octree", {"name": "pcg", "preconditioner": "multigrid", "cycle": "W", "smooth": 5,
                                             "max_iterations": 3}, 1.0, 1e-5,
                              octree={"stabilization": "none", "tracking": "tracked"}))[:2]
      == ("octree (paper's system) CG by its W(5,5)", "3 its"), "octree CG family")
check(wp.family_and_knob(fake(9, "hat", {"name": "cholmod"}, 1.0, 1e-5, octree={"refine_input": True}))[0].startswith("reference"),
      "the refined reference")

# 4. The degenerating case's table: a fixed-work setting with its guard against CHOLMOD on its system.
def degenerate(index, solver, distance):
    r = fake(index, "hat", solver, 0.1, 1.0, mesh="cgal:dino")
    r["reference_distance"] = [{"step": 3, "rms": distance}]
    r["steps"][1]["solver"] = {"fallback": {"solves": 1, "extra_cycles": 2, "iterations": 7}}
    return r


dino = [degenerate(20, {"name": "cholmod"}, 2e-4),
        degenerate(21, dict(mg(2), stall_ratio=0.5), 2.5e-4)]
section = "\n".join(wp.degenerating_sections(wp.points_of(dino)))
check("| hat MG V(2,2) + guard x2 | 0.00025 | hat + CHOLMOD | 0.0002 | 1.25 | 3 / 3 | 1 steps, 2 extra cycles, 7 CG iterations, 0 factorized |"
      in section, "degenerating table:\n" + section)
results += dino

# 5. The report end to end, with a stopped cell listed and not plotted.
results.append(fake(5, "octree", mg(1), 0.4, 1e-4, status="singular"))
with tempfile.TemporaryDirectory() as out:
    written = []
    wp.make(results, out, None, written)
    for name in ("work_precision.md", "work_precision.png", "work_precision_scaling.png"):
        check(os.path.getsize(os.path.join(out, name)) > 0, "missing " + name)
    text = open(os.path.join(out, "work_precision.md")).read()
    check("hat MG V(2,2) x2" in text, "the table names the fastest setting within 1.1x")
    check("Stopped before the last step" in text, "the stopped cell is not listed")
    check("1 contended point(s) left out" in text, "contended points are not counted")

# A planned cell and its result are the same cell when the index differs: an edit of the config's
# exclusions shifts the indices of cells a resumed run kept (common.cell_identity).
planned_cell = {"index": 7, "repetition": 2, "assignment": {"mesh": "m", "solver.cycles": 2}}
kept = {"cell": dict(planned_cell, index=3, study="s")}
check(common.cell_identity("s", False, planned_cell) == common.result_identity(kept),
      "a result whose index shifted is not matched to its planned cell")
check(common.cell_identity("s", False, planned_cell)
      != common.cell_identity("s", False, dict(planned_cell, repetition=1)),
      "two repetitions of one cell are matched to each other")

# 6. Two runs compared level by level (reports/work_precision_repeat.py): the same results agree
# everywhere; a second run where CG overtakes two cycles is named at the levels both reach (1.1x
# and 2x, of both errors) and nowhere else, with how close each race was.
import work_precision_repeat as repeat  # noqa: E402


def run_folder(folder, cg_time):
    pcg = {"name": "pcg", "preconditioner": "jacobi", "tolerance": 1e-8}
    rs = [fake(0, "hat", cg, 1.0, 1e-5), fake(1, "hat", mg(1), 0.2, 5e-5), fake(2, "hat", mg(2), 0.3, 1.05e-5),
          fake(3, "hat", pcg, cg_time, 1.0e-5)]
    for r in rs:
        r["cell"]["study"] = "work_precision"
        with open(os.path.join(folder, r["_stem"] + ".json"), "w") as f:
            json.dump({k: v for k, v in r.items() if not k.startswith("_")}, f)


with tempfile.TemporaryDirectory() as a, tempfile.TemporaryDirectory() as b, tempfile.TemporaryDirectory() as c:
    run_folder(a, 0.4)
    run_folder(b, 0.4)
    run_folder(c, 0.25)
    rows, same, tied = repeat.compare(repeat.levels_of(a), repeat.levels_of(b))
    # Two errors (semi-implicit and continuous radial) x three levels.
    check(same == tied == len(rows) == 6, "identical runs: %d of %d levels agree" % (same, len(rows)))
    rows, same, tied = repeat.compare(repeat.levels_of(a), repeat.levels_of(c))
    differ = [r for r in rows if r[5] != "yes"]
    check(same == 2 and tied == 2 and len(differ) == 4 and all(r[5] == "**no**" for r in differ),
          "CG faster in run C: %d agree, %d within the band, differing %s" % (same, tied, differ))
    check(all(r[2] in ("1.1x exact", "2x exact") and r[3].startswith("hat MG V(2,2)")
              and r[4].startswith("hat CG (jacobi)") for r in differ), "the differing levels: %s" % differ)
    # In A, CG reaches the level in 0.4 s against two cycles' 0.3 s; in C two cycles take 0.3 s
    # against CG's 0.25 s.
    check(all(r[6] == "1.33" and r[7] == "1.20" for r in differ), "race ratios: %s" % differ)
    check(repeat.main([a, c, "--require-same"]) == 1 and repeat.main([a, b, "--require-same"]) == 0,
          "--require-same exit status")
    # Within the tie band (CG 5% slower than two cycles in run D) the differing levels are ties, and
    # the report's table names the runner-up beside the winner.
    d = os.path.join(c, "d")
    os.mkdir(d)
    run_folder(d, 0.315)
    rows, same, tied = repeat.compare(repeat.levels_of(c), repeat.levels_of(d))
    check(same == 2 and tied == 6 and sum(r[5] == "tie" for r in rows) == 4,
          "a 5%% race: %d agree, %d within the band: %s" % (same, tied, rows))
    level = next(lv for lv in repeat.levels_of(d).values() if lv["factor"] == 1.1)
    check([f for f, _ in level["ties"]] == ["hat CG (jacobi)"] and abs(level["ties"][0][1] - 1.05) < 1e-9,
          "ties at 1.1x: %s" % level["ties"])

if failures:
    print("FAIL:\n  " + "\n  ".join(failures))
    sys.exit(1)
print("work_precision report: front, contention, table and files checked")
