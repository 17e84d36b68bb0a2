#!/usr/bin/python3
"""The data manifest check of the test suite (ctest `data_manifest`).

usage: check_data_manifest.py --root REPO
       check_data_manifest.py --self-test

data/manifest.json lists every measured result set (data/README.md). Fails (exit 1, one line
per problem) when

- a file or folder directly under data/results/, or a machine folder under data/history/, has
  no entry in the manifest;
- an entry's path does not exist, lies outside data/results/ or data/history/, or is listed twice;
- an entry lacks one of the fields name, path, machine, commit, command, date, or one is empty;
  or its date is not YYYY-MM-DD, or its name is not its path's last component.

--self-test runs the check on small fabricated trees and fails unless each kind of problem above
is reported (and a clean tree passes), so the check cannot silently stop catching them.
"""

import argparse
import json
import os
import re
import sys
import tempfile

FIELDS = ("name", "path", "machine", "commit", "command", "date")
DATE = re.compile(r"^[0-9]{4}-[0-9]{2}-[0-9]{2}$")
LISTS = {"results": os.path.join("data", "results"), "history": os.path.join("data", "history")}


def check(root):
    problems = []
    path = os.path.join(root, "data", "manifest.json")
    try:
        with open(path, encoding="utf-8") as f:
            manifest = json.load(f)
    except (OSError, ValueError) as e:
        return ["data/manifest.json: %s" % e]
    for key, folder in LISTS.items():
        entries = manifest.get(key)
        if not isinstance(entries, list):
            problems.append("data/manifest.json: no list \"%s\"" % key)
            entries = []
        listed = set()
        for i, e in enumerate(entries):
            where = "data/manifest.json: %s[%d]" % (key, i)
            if not isinstance(e, dict):
                problems.append("%s: not an object" % where)
                continue
            where += " (%s)" % e.get("name", "?")
            for field in FIELDS:
                if not isinstance(e.get(field), str) or not e[field].strip():
                    problems.append("%s: no %s" % (where, field))
            p = e.get("path")
            if not isinstance(p, str) or not p:
                continue
            p = os.path.normpath(p)
            if os.path.dirname(p) != folder:
                problems.append("%s: path %s is not directly under %s/" % (where, p, folder))
            if not os.path.exists(os.path.join(root, p)):
                problems.append("%s: path %s does not exist" % (where, p))
            if p in listed:
                problems.append("%s: path %s listed twice" % (where, p))
            listed.add(p)
            if isinstance(e.get("name"), str) and e["name"] != os.path.basename(p):
                problems.append("%s: name is not the last part of its path %s" % (where, p))
            if isinstance(e.get("date"), str) and not DATE.match(e["date"]):
                problems.append("%s: date %s is not YYYY-MM-DD" % (where, e["date"]))
        full = os.path.join(root, folder)
        present = sorted(os.listdir(full)) if os.path.isdir(full) else []
        for name in present:
            if name == "README.md" and key == "history":
                continue
            if os.path.join(folder, name) not in listed:
                problems.append("%s/%s: not listed in data/manifest.json (\"%s\")" % (folder, name, key))
    return problems


def self_test():
    entry = {"name": "a.json", "path": "data/results/a.json", "machine": "m", "commit": "abc1234",
             "command": "cmd", "date": "2026-01-01"}
    hist = dict(entry, name="M-1", path="data/history/M-1")
    cases = {
        "clean": ([entry], [hist], ["data/results/a.json", "data/history/M-1/x"], None),
        "unlisted file": ([entry], [hist], ["data/results/a.json", "data/results/b",
                                           "data/history/M-1/x"], "not listed"),
        "unlisted machine": ([entry], [], ["data/results/a.json", "data/history/M-1/x"], "not listed"),
        "missing path": ([entry, dict(entry, name="c", path="data/results/c")], [hist],
                         ["data/results/a.json", "data/history/M-1/x"], "does not exist"),
        "missing field": ([{k: v for k, v in entry.items() if k != "commit"}], [hist],
                          ["data/results/a.json", "data/history/M-1/x"], "no commit"),
        "empty field": ([dict(entry, command="")], [hist],
                        ["data/results/a.json", "data/history/M-1/x"], "no command"),
        "bad date": ([dict(entry, date="Nov 2026")], [hist],
                     ["data/results/a.json", "data/history/M-1/x"], "not YYYY-MM-DD"),
        "listed twice": ([entry, entry], [hist], ["data/results/a.json", "data/history/M-1/x"],
                         "listed twice"),
    }
    failed = 0
    for label, (results, history, files, expect) in cases.items():
        with tempfile.TemporaryDirectory() as tmp:
            for f in files:
                os.makedirs(os.path.dirname(os.path.join(tmp, f)), exist_ok=True)
                open(os.path.join(tmp, f), "w").close()
            with open(os.path.join(tmp, "data", "manifest.json"), "w") as f:
                json.dump({"results": results, "history": history}, f)
            problems = check(tmp)
        ok = (not problems) if expect is None else any(expect in p for p in problems)
        print("%s: %s%s" % (label, "ok" if ok else "NOT CAUGHT", "" if ok else " " + repr(problems)))
        failed += not ok
    return 1 if failed else 0


def main():
    ap = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    ap.add_argument("--root")
    ap.add_argument("--self-test", action="store_true")
    args = ap.parse_args()
    if args.self_test:
        return self_test()
    if not args.root:
        ap.error("--root or --self-test")
    problems = check(args.root)
    for p in problems:
        print(p)
    if not problems:
        print("data manifest ok")
    return 1 if problems else 0


if __name__ == "__main__":
    sys.exit(main())
