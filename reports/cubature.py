#!/usr/bin/python3
"""Fig. 8 of Chuang & Kazhdan 2011: RMS / max radial error per step for each cubature rule
(1-point, 3-point, degree-6) on the sphere."""

import common
import sphere_error


def make(results, out_dir, reference, written):
    """Write cubature.png: one curve per rule (plus any other varying key)."""
    keys = common.varying_keys(results)
    if "octree.cubature" not in keys and any("octree.cubature" in common.assignment(r) for r in results):
        keys = ["octree.cubature"] + keys  # always name the rule, even with a single cell
    sphere_error.plot_radial_errors(results, out_dir, "cubature",
                                    "Cubature rules: radial error per step (Fig. 8)", reference, written, keys)
