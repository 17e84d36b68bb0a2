#!/usr/bin/python3
"""Regenerate the studies' figures and tables from result folders.

usage: /usr/bin/python3 reports/make_report.py RESULTS_DIR [RESULTS_DIR ...] OUT_DIR
                                               [--references bench/configs]

Each results folder holds one study's result JSON files (index.json ignored); results are
grouped by cell.study and handed to the study's module; frames strips are drawn for any study
whose cells saved frames; OUT_DIR/index.md links everything. Nothing is rerun.
"""

import argparse
import importlib
import os
import sys
import traceback

sys.path.insert(0, os.path.dirname(os.path.abspath(__file__)))

import common  # noqa: E402
import index  # noqa: E402

STUDIES = ["table1", "sphere_error", "model_error", "depth_cycles", "cubature", "cmcf", "time_order"]


def parse_args(argv):
    p = argparse.ArgumentParser(description=__doc__, formatter_class=argparse.RawDescriptionHelpFormatter)
    p.add_argument("paths", nargs="+", metavar="DIR", help="results folder(s), then the output folder")
    p.add_argument("--references", default=common.DEFAULT_REFERENCES,
                   help="folder of <study>.reference.json paper values (default: bench/configs)")
    args = p.parse_args(argv)
    if len(args.paths) < 2:
        p.error("need at least one RESULTS_DIR and an OUT_DIR")
    return args


def run_module(name, results, out_dir, reference, written):
    """Call module `name`.make; a failing module is reported, never fatal for the others."""
    try:
        importlib.import_module(name).make(results, out_dir, reference, written)
        return True
    except Exception:  # noqa: BLE001 - partial data must not stop the other studies
        common.warn("%s failed:\n%s" % (name, traceback.format_exc()))
        return False


def main(argv):
    args = parse_args(argv)
    *folders, out_dir = args.paths
    os.makedirs(out_dir, exist_ok=True)
    by_study = {}
    for folder in folders:
        if not os.path.isdir(folder):
            common.warn("no such results folder: %s" % folder)
            continue
        for r in common.load_results(folder):
            entry = by_study.setdefault(common.study_of(r), ([], []))
            entry[0].append(r)
            if folder not in entry[1]:
                entry[1].append(folder)
    ok = True
    sections = []
    for study in sorted(by_study, key=lambda s: (STUDIES.index(s) if s in STUDIES else len(STUDIES), s)):
        results, src = by_study[study]
        written = []
        reference = common.load_reference(study, args.references)
        print("%s: %d result file(s)%s" % (study, len(results), "" if reference is None else ", paper reference found"))
        if study in STUDIES:
            ok &= run_module(study, results, out_dir, reference, written)
        elif any(common.series(r, "radial_error.rms")[0] for r in results):
            # Plain `mcfbench flow` runs or a new study: at least show the radial errors.
            import sphere_error
            try:
                sphere_error.plot_radial_errors(results, out_dir, "%s_radial_error" % study,
                                                "%s: radial error per step" % study, reference, written)
            except Exception:  # noqa: BLE001
                common.warn("radial error plot for %s failed:\n%s" % (study, traceback.format_exc()))
                ok = False
        else:
            common.warn("no report module for study %r; frames only" % study)
        ok &= run_module("frames", results, out_dir, reference, written)
        # A cell whose flow threw has no steps: the figures cannot show it, so the index says so.
        errored = [r for r in results if r.get("status") == "error"]
        if errored:
            common.warn("%s: %d cell(s) errored and are missing from its figures (listed in index.md)"
                        % (study, len(errored)))
        sections.append((study, src, written, errored))
    index.make(out_dir, sections)
    return 0 if ok else 1


if __name__ == "__main__":
    sys.exit(main(sys.argv[1:]))
