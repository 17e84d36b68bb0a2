#!/usr/bin/python3
"""Do two runs of the work_precision study name the same fastest family at every error level?

    reports/work_precision_repeat.py RESULTS_A RESULTS_B [--out FILE.md] [--require-same]

For each case, size, error and level of the study's tables (reports/work_precision.py: 1.1x, 2x
and 10x the exact point's error of that run), the fastest setting of each run and its family
(the curve it lies on: "hat MG V(2,2)", "hat CG (MG V(2,2))", ...). Where the two families
differ, the row also gives how close the race was in each run: the time the other run's winning
family needs to reach the level, over the winner's (1.00 = a tie). Two runs agree on a level
strictly when they name the same family, and within the tie band when one run's winner is among
the other's families within work_precision.TIE of its winner (the report's "tie" note). A level
only one run has (an exact point missing in the other) is listed as such and agrees in neither
sense. Prints a markdown table and a summary line; exit 1 with --require-same when a level does
not agree strictly."""

import argparse
import os
import sys

sys.path.insert(0, os.path.dirname(os.path.abspath(__file__)))
import common  # noqa: E402
import work_precision as wp  # noqa: E402

STUDY = "work_precision"


def levels_of(folder):
    """{(title, error, factor): level} of the study's results in `folder` (error_levels' rows)."""
    results = [r for r in common.load_results(folder) if common.study_of(r) == STUDY]
    return {(lv["title"], lv["error"], lv["factor"]): lv for lv in wp.error_levels(wp.points_of(results))}


def family_time(level, family):
    """The time the fastest point of `family` needs to reach the level's error, or None."""
    best = wp.fastest_of_family(level["points"], family, level["error"], level["epsilon"])
    return best["time"] if best else None


def tie_set(level):
    """The winner's family and those tied with it at a level."""
    if not level or not level["best"]:
        return set()
    return {level["best"]["family"]} | {f for f, _ in level["ties"]}


def compare(a, b):
    """Rows [title, error, level, family A, family B, same, A's race, B's race], the count of
    levels that agree strictly and the count that agree within the tie band, over the union of
    both runs' levels."""
    rows, same, tied = [], 0, 0
    for key in sorted(set(a) | set(b), key=lambda k: (k[0], k[1], k[2])):
        title, error, factor = key
        la, lb = a.get(key), b.get(key)
        fa = la["best"]["family"] if la and la["best"] else None
        fb = lb["best"]["family"] if lb and lb["best"] else None
        agree = la is not None and lb is not None and fa == fb
        within = agree or (la is not None and lb is not None and (fa in tie_set(lb) or fb in tie_set(la)))
        same += agree
        tied += within
        race_a = race_b = "—"
        if la and lb and fa and fb and fa != fb:
            other_a, other_b = family_time(la, fb), family_time(lb, fa)
            race_a = common.fmt(other_a / la["best"]["time"], "%.2f") if other_a else "not reached"
            race_b = common.fmt(other_b / lb["best"]["time"], "%.2f") if other_b else "not reached"
        name = lambda lv, f: ("%s (%s s)" % (f, common.fmt(lv["best"]["time"])) if f  # noqa: E731
                              else ("none reaches it" if lv else "no level (no exact point)"))
        rows.append([title, error, "%gx exact" % factor, name(la, fa), name(lb, fb),
                     "yes" if agree else ("tie" if within else "**no**"), race_a, race_b])
    return rows, same, tied


def main(argv):
    p = argparse.ArgumentParser(description=__doc__, formatter_class=argparse.RawDescriptionHelpFormatter)
    p.add_argument("a", metavar="RESULTS_A")
    p.add_argument("b", metavar="RESULTS_B")
    p.add_argument("--out", help="also write the table to this markdown file")
    p.add_argument("--require-same", action="store_true", help="exit 1 unless every level's family agrees")
    args = p.parse_args(argv)
    for folder in (args.a, args.b):
        if not os.path.isdir(folder):
            print("error: no such results folder: %s" % folder, file=sys.stderr)
            return 2
    a, b = levels_of(args.a), levels_of(args.b)
    if not a and not b:
        print("error: neither folder has %s results with error levels" % STUDY, file=sys.stderr)
        return 2
    rows, same, tied = compare(a, b)
    text = (common.markdown_table(["case", "error", "level", "fastest in A", "fastest in B", "same family",
                                   "A: B's family / A's", "B: A's family / B's"], rows)
            + "\n\n%d of %d error levels name the same fastest family, %d within the tie band of %.0f%% "
              "(A: %s, B: %s).\n" % (same, len(rows), tied, 100 * wp.TIE, args.a, args.b))
    print(text)
    if args.out:
        common.write_text(args.out, text)
    return 1 if args.require_same and same != len(rows) else 0


if __name__ == "__main__":
    sys.exit(main(sys.argv[1:]))
