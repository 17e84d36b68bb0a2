#!/usr/bin/python3
"""Fabricate small results folders, one per study (2–3 result files each, plus frames, a
singular stop, a one-cell study, the run plans and paper reference files), for the reports test.

usage: make_fake_results.py OUT_ROOT   ->  OUT_ROOT/<study>/*.json, OUT_ROOT/<study>/plans/*.json,
                                           OUT_ROOT/references/*.json
"""

import json
import math
import os
import sys

import numpy as np

sys.path.insert(0, os.path.join(os.path.dirname(os.path.abspath(__file__)), "..", "..", "reports"))
import plyio  # noqa: E402


def uv_sphere(n_theta, n_phi, radii=(1.0, 1.0, 1.0)):
    """A closed UV sphere (poles included) scaled per axis."""
    verts = [(0, 0, 1)]
    for i in range(1, n_theta):
        th = math.pi * i / n_theta
        for j in range(n_phi):
            ph = 2 * math.pi * j / n_phi
            verts.append((math.sin(th) * math.cos(ph), math.sin(th) * math.sin(ph), math.cos(th)))
    verts.append((0, 0, -1))
    tris = []
    ring = lambda i, j: 1 + (i - 1) * n_phi + (j % n_phi)  # noqa: E731
    for j in range(n_phi):
        tris.append((0, ring(1, j), ring(1, j + 1)))
        tris.append((len(verts) - 1, ring(n_theta - 1, j + 1), ring(n_theta - 1, j)))
    for i in range(1, n_theta - 1):
        for j in range(n_phi):
            a, b, c, d = ring(i, j), ring(i, j + 1), ring(i + 1, j), ring(i + 1, j + 1)
            tris += [(a, c, b), (b, c, d)]
    return np.array(verts) * np.array(radii), np.array(tris)


def step(n, dt, errscale=1e-4, extra=None, slow=1.0, residual=1e-2):
    """One fake step record with every key the reports read."""
    t = n * dt
    s = {"step": n, "t": t,
         "seconds": {"update": slow * (0.01 + 1e-4 * n), "solve": 0.002, "evaluate": 1e-4,
                     "total": slow * 0.0101 + 0.0021},
         "solver": {"iterations": 1, "residuals": [residual * 0.1 ** k for k in range(3)], "status": "converged"},
         "area": 4 * math.pi * (1 - 4 * t), "step_difference": 0.05 / n,
         "radial_error": {"rms": errscale * n, "max": 3 * errscale * n,
                          "rms_continuous": errscale * n * 2, "max_continuous": errscale * n * 5}}
    if extra:
        s.update(extra(n))
    return s


def result(study, index, assignment, config, steps, status="ok", reason="completed", repetition=0, commit="fake",
           quick=False, **more):
    """A result file's dict; cell.key names the repetition, cell.config_key does not (harness/cell_hash.cpp)."""
    r = {"schema": 1, "status": status, "stop": {"step": len(steps), "reason": reason},
         "config": config, "steps": steps,
         "environment": {"commit": commit, "cpu": "fake", "cores": 2, "threads": 2, "libraries": {}},
         "mesh": {"spec": config.get("mesh"), "vertices": 642, "faces": 1280, "boundary_loops": 0, "genus": 0},
         "system": {"dimension": 5000 + 100 * index, "split_triangles": 20000, "cubature_points": 60000,
                    "levels": 5, "setup_seconds": {"octree": 0.3, "clip": 0.2, "total": 0.5}},
         "cell": {"index": index, "key": "%s-%d-rep%d" % (study, index, repetition),
                  "config_key": "%s-%d" % (study, index), "assignment": assignment,
                  "repetition": repetition, "study": study, "quick": quick},
         "study_config": {"name": study}}
    r.update(more)
    return r


def config(**kw):
    c = {"mesh": "icosphere:level=3", "flow": "mcf", "basis": "octree", "dt": 1e-3, "steps": 10,
         "integrator": "semi-implicit", "extrapolate": True,
         "octree": {"tracking": "tracked", "depth": 6, "cubature": 3},
         "solver": {"name": "multigrid", "cycle": "W", "cycles": 1}}
    for k, v in kw.items():
        node = c
        *path, last = k.split("__")
        for p in path:
            node = node.setdefault(p, {})
        node[last] = v
    return c


def write(folder, name, r):
    os.makedirs(folder, exist_ok=True)
    with open(os.path.join(folder, name + ".json"), "w") as f:
        json.dump(r, f, indent=1)


def write_plan(folder, study, shard=(0, 1), cells=None, commit="fake", quick=False):
    """FOLDER/plans/<study>[-quick]@<commit>[.shard-i-of-n].json as `mcfbench run` writes it: `cells`
    ([{"index", "repetition", "assignment"}]), by default those of the results in FOLDER; "hash" (the
    result's file stem) for the cells of this shard. Returns the plan's path."""
    if cells is None:
        cells = []
        for name in sorted(os.listdir(folder)):
            if name.endswith(".json") and name != "index.json":
                try:
                    with open(os.path.join(folder, name)) as f:
                        c = json.load(f)["cell"]
                except (ValueError, KeyError, TypeError):
                    continue
                cells.append({"index": c["index"], "repetition": c["repetition"], "assignment": c["assignment"],
                              "hash": os.path.splitext(name)[0]})
        cells.sort(key=lambda c: c["index"])
    i, n = shard
    listed = []
    for c in cells:
        c = dict(c)
        if c["index"] % n != i:
            c.pop("hash", None)
        listed.append(c)
    name = study + ("-quick" if quick else "") + "@" + commit + (".shard-%d-of-%d" % (i, n) if n > 1 else "")
    path = os.path.join(folder, "plans", name + ".json")
    os.makedirs(os.path.dirname(path), exist_ok=True)
    with open(path, "w") as f:
        json.dump({"schema": 1, "plan": "mcfbench run", "study": study, "quick": quick, "commit": commit,
                   "source": "harness/configs/%s.json" % study, "shard": "%d/%d" % (i, n),
                   "cells_total": len(listed), "cells": listed, "study_config": {"name": study}}, f, indent=1)
    return path


def frames(folder, stem, count, n_theta=12, n_phi=24, stretch=1.6):
    """Frames of an ellipsoid relaxing to a sphere, binary and ASCII PLY alternately."""
    d = os.path.join(folder, "frames", stem)
    os.makedirs(d, exist_ok=True)
    for k in range(count):
        a = 1 + (stretch - 1) * (1 - k / max(1, count - 1))
        v, f = uv_sphere(n_theta, n_phi, (a, 1, 0.8))
        plyio.write_ply(os.path.join(d, "frame_%05d.ply" % (5 * k)), v * (1 - 0.05 * k), f, binary=(k % 2 == 0))


def table1_cells(folder, repetition=0, commit="fake", slow=1.0, names="cell_%03d", cells=(0, 1, 2)):
    """table1: one model, tracked + rebuilt; a second model with tracked only (missing variant).
    `slow` scales the per-step times."""
    s = "table1"
    for i, (mesh, mode, upd) in enumerate([("sphere:vertices=40000", "tracked", 0.01),
                                           ("sphere:vertices=40000", "rebuilt", 0.2),
                                           ("cgal:bunny00", "tracked", 0.02)]):
        if i not in cells:
            continue
        steps = [step(n, 1e-3, slow=slow * upd / 0.01) for n in range(1, 4)]
        if i == 0:  # the tracked step 1 also builds the solver's pattern: the paper's "+system"
            steps[0]["seconds"]["solve"] += 0.5
            steps[0]["seconds"]["total"] += 0.5
        write(folder, names % i, result(s, i, {"mesh": mesh, "octree.tracking": mode},
                                        config(mesh=mesh, octree__tracking=mode), steps,
                                        repetition=repetition, commit=commit))


def cubature_cells(folder, repetition=0, commit="fake", scale=1.0, names="cell_%03d", cells=(0, 1, 2)):
    """cubature: three rules, their radial errors times `scale`."""
    s = "cubature"
    for i, rule in enumerate([1, 3, 6]):
        if i in cells:
            write(folder, names % i,
                  result(s, i, {"octree.cubature": rule}, config(octree__cubature=rule),
                         [step(n, 1e-3, scale * 1e-4 * (3 if rule == 1 else 1)) for n in range(1, 11)],
                         repetition=repetition, commit=commit))


def time_order_cells(folder, repetition=0, names="cell_%03d", first=0, mesh="icosphere:level=3", quick=False,
                     offset=0.0, scale=1.0):
    """time_order: two integrators × dts and one unstable explicit run, each to t = 0.01, their
    mean radius sqrt(1 - 4t) + 0.3 δ^order (orders 1, 2, 1), and a Crank–Nicolson run at δ = 1.25e-4
    (cell 9) whose mean radius is sqrt(1 - 4t) exactly: the temporal reference. The RMS error against
    the continuous radius is a flat 1e-3 (the mesh's floor), so only errors measured as
    |mean radius − reference| fit the orders 1 and 2. Cells numbered from `first`; every radius plus
    `offset` (another mesh's spatial error), every temporal error times `scale`."""
    s = "time_order"
    end = 0.01
    runs = [(integ, order, dt) for integ, order in (("semi-implicit", 1), ("bdf2", 2), ("explicit", 1))
            for dt in (1e-3, 5e-4, 2.5e-4)] + [("crank-nicolson", None, 1.25e-4)]
    for i, (integ, order, dt) in enumerate(runs):
        err = scale * 0.3 * dt ** order if order else 0.0
        status = "error" if (integ == "explicit" and dt == 1e-3) else "ok"
        radius = lambda n, e=err, dt=dt: {"radial_error": {  # noqa: E731
            "rms_continuous": 1e-3, "mean_radius": offset + math.sqrt(1 - 4 * n * dt) + e * n * dt / end}}
        write(folder, names % (first + i),
              result(s, first + i, {"integrator": integ, "dt": dt}, config(integrator=integ, dt=dt, mesh=mesh),
                     [step(n, dt, extra=radius) for n in (1, round(end / dt))],
                     status=status, reason="diverged" if status != "ok" else "completed",
                     repetition=repetition, quick=quick))


def set_time(folder, pattern, when):
    """Give FOLDER's files whose names start with `pattern` the modification time `when` (seconds
    since 1970): reports order commits by their newest result file."""
    for name in os.listdir(folder):
        if name.startswith(pattern):
            os.utime(os.path.join(folder, name), (when, when))


def repetitions_and_commits(root):
    """ROOT/repeated/<study>: each cell twice, repetitions 0 (the files of ROOT/<study>) and 1
    (cell_NNN_r1, other values): reports draw repetition 0 alone, so their figures and tables
    equal those of ROOT/<study>. ROOT/commits/<study>: commit 0ld0ld's cells 0-2 (errors ×10,
    times ×10, files a_old_NNN, 2026-01-01) and commit c0ffee's cells 0 and 1 (ROOT/<study>'s
    values, files b_new_NNN, 2026-02-01): reports take c0ffee's cells 0 and 1 and 0ld0ld's cell 2."""
    rep = os.path.join(root, "repeated")
    cubature_cells(os.path.join(rep, "cubature"))
    cubature_cells(os.path.join(rep, "cubature"), repetition=1, scale=5.0, names="cell_%03d_r1")
    time_order_cells(os.path.join(rep, "time_order"))
    time_order_cells(os.path.join(rep, "time_order"), repetition=1, names="cell_%03d_r1")
    with open(os.path.join(rep, "time_order", "cell_003_r1.json")) as f:  # another value at bdf2's largest δ
        r = json.load(f)
    r["steps"][-1]["radial_error"]["mean_radius"] += 1e-6
    write(os.path.join(rep, "time_order"), "cell_003_r1", r)
    com = os.path.join(root, "commits")
    for study, cells in (("cubature", cubature_cells), ("table1", table1_cells)):
        folder = os.path.join(com, study)
        more = {"scale": 10.0} if study == "cubature" else {"slow": 10.0}
        cells(folder, commit="0ld0ld", names="a_old_%03d", **more)
        cells(folder, commit="c0ffee", names="b_new_%03d", cells=(0, 1))
        set_time(folder, "a_old_", 1767225600)  # 2026-01-01
        set_time(folder, "b_new_", 1769904000)  # 2026-02-01


def several_meshes(root):
    """ROOT/meshes/time_order: the time_order cells on icosphere:level=3 (cells 0-9), on
    icosphere:level=2 (10-19: radii 0.01 larger, temporal errors doubled) and a quick run on
    icosphere:level=3 (20-29: radii 0.02 larger); each set has its own reference, so each fits
    orders 1 and 2. ROOT/meshes/depth_cycles: depths 5, 6 × cycles 1, 2 on two meshes."""
    folder = os.path.join(root, "meshes", "time_order")
    time_order_cells(folder)
    time_order_cells(folder, first=10, mesh="icosphere:level=2", offset=0.01, scale=2.0)
    time_order_cells(folder, first=20, quick=True, offset=0.02)
    s = "depth_cycles"
    i = 0
    for mesh, worse in (("icosphere:level=3", 1), ("icosphere:level=2", 4)):
        for depth in (5, 6):
            for cyc in (1, 2):
                write(os.path.join(root, "meshes", s), "cell_%03d" % i,
                      result(s, i, {"mesh": mesh, "octree.depth": depth, "solver.cycles": cyc},
                             config(mesh=mesh, octree__depth=depth, solver__cycles=cyc),
                             [step(n, 1e-3, worse * 1e-3 / (depth * cyc), residual=worse * 0.1 ** (cyc + depth - 3))
                              for n in range(1, 6)]))
                i += 1


def many_frames(root):
    """ROOT/strips/cmcf: three flows × seven meshes, flow-major as `mcfbench run` numbers them,
    every cell with frames: more cells than frames.py draws strips for (MAX_CELLS = 8)."""
    s = "cmcf"
    folder = os.path.join(root, "strips", s)
    metrics = lambda n: {"metrics": {"quasi_conformal": 1 + 0.5 / n, "sphericity": 0.2 / n}}  # noqa: E731
    i = 0
    for flow in ("mcf", "heat", "cmcf"):
        for m in range(7):
            mesh = "torus:n_major=%d" % (10 + m)
            write(folder, "cell_%03d" % i, result(s, i, {"flow": flow, "mesh": mesh}, config(mesh=mesh, flow=flow),
                                                  [step(n, 1e-3, extra=metrics) for n in (1, 2)]))
            frames(folder, "cell_%03d" % i, 2, 4, 8)
            i += 1


def main(root):
    # table1: one model, tracked + rebuilt; a second model with tracked only (missing variant).
    s = "table1"
    table1_cells(os.path.join(root, s))
    # A model whose tracked flow stopped at step 1: no speed-up from it, named below the table.
    for i, (mode, status) in enumerate([("tracked", "singular"), ("rebuilt", "ok")]):
        mesh = "spiral:turns=3"
        write(os.path.join(root, s), "cell_%03d" % (3 + i),
              result(s, 3 + i, {"mesh": mesh, "octree.tracking": mode}, config(mesh=mesh, octree__tracking=mode),
                     [step(n, 1e-3, slow=0.001 if status != "ok" else 20) for n in range(1, 2 if status != "ok" else 4)],
                     status=status, reason="solver: not_positive_definite" if status != "ok" else "completed"))
    # sphere_error: three variants, one with frames.
    s = "sphere_error"
    for i, (basis, mode) in enumerate([("octree", "tracked"), ("octree", "rebuilt"), ("hat", "tracked")]):
        write(os.path.join(root, s), "cell_%03d" % i,
              result(s, i, {"basis": basis, "octree.tracking": mode}, config(basis=basis, octree__tracking=mode),
                     [step(n, 1e-3, 1e-4 * (i + 1)) for n in range(1, 21)]))
    frames(os.path.join(root, s), "cell_000", 4)
    # model_error: reference distances, one cell without them.
    s = "model_error"
    for i, mode in enumerate(["tracked", "rebuilt"]):
        write(os.path.join(root, s), "cell_%03d" % i,
              result(s, i, {"octree.tracking": mode}, config(mesh="cgal:bunny00", octree__tracking=mode),
                     [step(n, 1e-5) for n in range(1, 11)],
                     reference_distance=[{"step": n, "rms": 1e-4 * n * (i + 1), "max": 1e-3 * n * (i + 1)}
                                         for n in (1, 5, 10)]))
    write(os.path.join(root, s), "cell_002", result(s, 2, {"octree.tracking": "x"}, config(), []))
    # depth_cycles: depths × cycles on a sphere.
    s = "depth_cycles"
    i = 0
    for depth in (5, 6):
        for cyc in (1, 2):
            write(os.path.join(root, s), "cell_%03d" % i,
                  result(s, i, {"octree.depth": depth, "solver.cycles": cyc},
                         config(octree__depth=depth, solver__cycles=cyc),
                         [step(n, 1e-3, 1e-3 / (depth * cyc), residual=0.1 ** (cyc + depth - 3))
                          for n in range(1, 6)]))
            i += 1
    # cubature: three rules.
    cubature_cells(os.path.join(root, "cubature"))
    # cmcf: mcf stops singular, heat and cmcf converge; frames for cmcf.
    s = "cmcf"
    metrics = lambda n: {"metrics": {"quasi_conformal": 1 + 0.5 / n, "sphericity": 0.2 / n}}  # noqa: E731
    for i, (flow, status, steps) in enumerate([("mcf", "singular", 6), ("heat", "ok", 12), ("cmcf", "ok", 12)]):
        write(os.path.join(root, s), "cell_%03d" % i,
              result(s, i, {"flow": flow}, config(mesh="dumbbell", flow=flow),
                     [step(n, 1e-3, extra=metrics) for n in range(1, steps + 1)], status=status,
                     reason="pinched" if status != "ok" else "completed"))
    # An unnormalised open cylinder (cMCF: the middle ring against r0 - t/r0) for the analytic table.
    ring = lambda n: {"cylinder": {"ring_radius": 1 - n * 1e-3 - 5e-4, "radius_semi_implicit": 1 - n * 1e-3 + 1e-5,  # noqa: E731
                                   "radius_continuous": 1 - n * 1e-3, "ring_vertices": 32}}
    write(os.path.join(root, s), "cell_003",
          result(s, 3, {"flow": "cmcf", "mesh": "open_cylinder"}, config(mesh="open_cylinder", flow="cmcf"),
                 [step(n, 1e-3, extra=ring) for n in range(1, 11)]))
    frames(os.path.join(root, s), "cell_002", 8, 60, 120)  # 14k faces × ... decimation exercised below
    frames(os.path.join(root, s), "cell_001", 3, 110, 220)  # ~48k faces: decimated
    # time_order: two integrators × dts (error ∝ dt and dt²), one unstable explicit run.
    time_order_cells(os.path.join(root, "time_order"))
    # hat_multigrid: CHOLMOD, one W-cycle and a PCG on one flow; the cycle's residuals drop 10x per
    # iteration, its distance to CHOLMOD 1e-5 and its steps half as long.
    s = "hat_multigrid"
    solvers = [({"name": "cholmod"}, 1.0, None), ({"name": "multigrid", "cycle": "W", "cycles": 2, "smooth": 5}, 0.5, 1e-5),
               ({"name": "pcg", "preconditioner": "ichol"}, 3.0, 1e-11)]
    for i, (solver, slow, dist) in enumerate(solvers):
        extra = {"reference_distance": [{"step": 10, "rms": dist, "max": 2 * dist}]} if dist else {}
        write(os.path.join(root, s), "cell_%03d" % i,
              result(s, i, {"solver.name": solver["name"]}, config(basis="hat", solver=solver),
                     [step(n, 1e-3, slow=slow) for n in range(1, 11)], **extra))
    # hat_scaling: two solvers at two sizes.
    s = "hat_scaling"
    for i, (name, faces) in enumerate([("cholmod", 1000), ("cholmod", 4000), ("multigrid", 1000), ("multigrid", 4000)]):
        r = result(s, i, {"solver.name": name, "mesh": "m%d" % faces}, config(basis="hat", solver={"name": name}),
                   [step(n, 1e-3, slow=faces / 1000.0) for n in range(1, 4)])
        r["mesh"]["faces"] = faces
        write(os.path.join(root, s), "cell_%03d" % i, r)
    # A study with one cell and no steps at all.
    write(os.path.join(root, "single"), "only", result("cubature", 0, {"octree.cubature": 3}, config(), []))
    # Files a results folder may also hold: the runner's index, a truncated file, a non-result.
    with open(os.path.join(root, "time_order", "index.json"), "w") as f:
        json.dump({"cells": []}, f)
    with open(os.path.join(root, "time_order", "broken.json"), "w") as f:
        f.write('{"config": {')
    with open(os.path.join(root, "cubature", "notes.json"), "w") as f:
        json.dump([1, 2, 3], f)
    # The plans `mcfbench run` writes before its first cell (RESULTS_DIR/plans/, harness/runner.cpp
    # run_plan): every cell is planned and has its result, so the report is complete. depth_cycles
    # ran as two shards, whose plans list every cell and name the hashes of their own.
    for s in ("table1", "sphere_error", "model_error", "cubature", "cmcf", "time_order"):
        write_plan(os.path.join(root, s), s)
    write_plan(os.path.join(root, "depth_cycles"), "depth_cycles", shard=(0, 2))
    write_plan(os.path.join(root, "depth_cycles"), "depth_cycles", shard=(1, 2))
    repetitions_and_commits(root)
    several_meshes(root)
    many_frames(root)
    # Paper references.
    refs = os.path.join(root, "references")
    os.makedirs(refs, exist_ok=True)
    with open(os.path.join(refs, "table1.reference.json"), "w") as f:
        json.dump({"rows": [{"model": "Sphere", "mesh": "sphere:vertices=40000", "depth": 6,
                             "input_vertices": 3.7e5, "split_triangles": 3.8e6, "dimension": 5.1e5,
                             "setup_seconds": 6, "system_seconds": 3, "update_seconds": 1.4, "solve_seconds": 0.22}]}, f)
    with open(os.path.join(refs, "sphere_error.reference.json"), "w") as f:
        json.dump({"curves": {"tracked MG": {"step": [1, 10, 20], "rms": [1e-4, 1e-3, 2e-3],
                                             "max": [3e-4, 3e-3, 6e-3]}}}, f)
    with open(os.path.join(refs, "time_order.reference.json"), "w") as f:
        json.dump({"orders": {"semi-implicit": 1, "bdf2": 2}}, f)
    with open(os.path.join(refs, "cmcf.reference.json"), "w") as f:
        f.write("{ not json")  # a broken reference must be ignored, not fatal


if __name__ == "__main__":
    main(sys.argv[1])
