#!/usr/bin/env bash
# The history dashboard in a real browser (ctest `history_dashboard`): a store of 12 commits
# with a 30% slowdown planted at the eighth is published, headless Chromium loads the page
# offline and its DOM must report both charts laid out (the page's own check writes
# data-charts-rendered on <body>) and list the planted commit as a regression and link the study
# report given; a screenshot must come out. Exit 77 (skipped) when chromium is absent and cannot be installed.
set -euo pipefail
root=$(cd "$(dirname "$0")/../.." && pwd)
browser=$(command -v chromium || command -v chromium-browser || true)
if [ -z "$browser" ] && [ "$(id -u)" = 0 ] && command -v apt-get >/dev/null; then
  DEBIAN_FRONTEND=noninteractive apt-get install -y --no-install-recommends chromium >/dev/null 2>&1 || true
  browser=$(command -v chromium || true)
fi
[ -n "$browser" ] || { echo "SKIP: no chromium"; exit 77; }
work=$(mktemp -d)
trap 'rm -rf "$work"' EXIT

# A store written directly (the runner and git are tested in test_perf_history.py).
/usr/bin/python3 - "$work/store" <<'PY'
import hashlib, json, os, sys
store = sys.argv[1]
folder = os.path.join(store, "Fake-CPU-2c-2t-00000000", "fake")
os.makedirs(folder)
json.dump({"cpu": "Fake CPU", "cores": 2, "threads": 2}, open(os.path.join(store, "Fake-CPU-2c-2t-00000000", "machine.json"), "w"))
prev = []
for i in range(12):
    c = hashlib.sha1(b"commit %d" % i).hexdigest()
    slow = 1.3 if i >= 7 else 1.0
    bench = {}
    for name, base in (("solver.name=slowed", slow), ("solver.name=steady", 1.0)):
        s = [base * (1 + 0.01 * ((i * 7 + k * 3) % 5 - 2)) for k in range(3)]
        bench[name] = {"key": name, "samples": s, "median": sorted(s)[1], "failed": 0}
    json.dump({"schema": 1, "commit": c, "date": "2026-01-%02dT00:00:00Z" % (i + 1),
               "parents": prev, "subject": "commit %d" % i, "config": "fake",
               "machine": "Fake-CPU-2c-2t-00000000", "benchmarks": bench},
              open(os.path.join(folder, c + ".json"), "w"))
    prev = [c]
    if i == 7:
        open(os.path.join(store, "planted"), "w").write(c[:12])
PY
mkdir -p "$work/report"
echo "# fake study" >"$work/report/index.md"
/usr/bin/python3 "$root/reports/perf_history.py" publish "$work/site" --store "$work/store" \
  --report "$work/report/index.md" >/dev/null
planted=$(cat "$work/store/planted")

flags=(--headless --no-sandbox --disable-gpu --no-first-run --disable-extensions
       --user-data-dir="$work/profile" --virtual-time-budget=2000)
timeout 60 "$browser" "${flags[@]}" --dump-dom "file://$work/site/index.html" >"$work/dom.html" 2>"$work/err" || {
  cat "$work/err"; echo "FAIL: chromium --dump-dom"; exit 1; }
fail=0
grep -q 'data-charts-rendered="2"' "$work/dom.html" || { echo "FAIL: the DOM does not report 2 charts rendered"; grep -o '<body[^>]*>' "$work/dom.html"; fail=1; }
sed -n '/id="regressions"/,/<\/table>/p' "$work/dom.html" | grep -q "<code>$planted</code>" \
  || { echo "FAIL: the regressions list lacks the planted commit $planted"; fail=1; }
sed -n '/id="reports"/,/<\/ul>/p' "$work/dom.html" | grep -q 'href="../report/index.md"' \
  || { echo "FAIL: the study report is not linked"; fail=1; }
timeout 60 "$browser" "${flags[@]}" --screenshot="$work/shot.png" --window-size=1200,900 "file://$work/site/index.html" >/dev/null 2>&1 || true
[ "$(stat -c %s "$work/shot.png" 2>/dev/null || echo 0)" -gt 10000 ] || { echo "FAIL: no screenshot"; fail=1; }
[ $fail = 0 ] && echo "ok: dashboard rendered in $browser, regression $planted listed"
exit $fail
