#!/usr/bin/python3
"""The list of studies, read from its one source, harness/configs/studies.json.

usage: /usr/bin/python3 reports/study_manifest.py [--default] [--manifest FILE]

prints the studies' names, one a line, in the report's order; --default: only those
scripts/run_studies.sh runs when no study is named. A manifest that does not parse, or an entry
without a name, is an error naming the file (exit 1).
"""

import argparse
import json
import os
import sys

MANIFEST = os.path.join(os.path.dirname(os.path.dirname(os.path.abspath(__file__))),
                        "harness", "configs", "studies.json")


class ManifestError(Exception):
    pass


def load(path=MANIFEST):
    """[(name, run_by_default)] of the manifest, in its order."""
    try:
        with open(path) as f:
            manifest = json.load(f)
        studies = manifest["studies"]
        entries = [(s["name"], bool(s.get("run_by_default", False))) for s in studies]
    except (OSError, ValueError) as e:
        raise ManifestError("%s: %s" % (path, e)) from e
    except (KeyError, TypeError) as e:
        raise ManifestError("%s: expected {\"studies\": [{\"name\": ..., \"run_by_default\": ...}]}: "
                            "missing or wrong %s" % (path, e)) from e
    for name, _ in entries:
        if not isinstance(name, str) or not name:
            raise ManifestError("%s: a study's name must be a non-empty string, not %r" % (path, name))
    return entries


def names(path=MANIFEST, default_only=False):
    return [name for name, default in load(path) if default or not default_only]


def main(argv):
    p = argparse.ArgumentParser(description=__doc__, formatter_class=argparse.RawDescriptionHelpFormatter)
    p.add_argument("--default", action="store_true", help="only the studies run when none is named")
    p.add_argument("--manifest", default=MANIFEST, help="the manifest (default: harness/configs/studies.json)")
    args = p.parse_args(argv)
    try:
        print("\n".join(names(args.manifest, args.default)))
    except ManifestError as e:
        print("study_manifest.py: %s" % e, file=sys.stderr)
        return 1
    return 0


if __name__ == "__main__":
    sys.exit(main(sys.argv[1:]))
