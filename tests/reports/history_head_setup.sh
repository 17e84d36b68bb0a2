# Sourced by the history tests that run the repository's own HEAD through
# scripts/history_runner.sh without compiling it: with root and bin (the built mcfbench) set,
# sets head (HEAD's 40 hex; exit 77, skipped, outside a git checkout) and work (a temporary
# folder removed at exit) holding builds/<head>/mcfbench, or builds/<head>/$exe where exe is set
# (the build cache the runners read through $MCFBENCH_HISTORY_BUILDS, here a link to bin) and
# tiny.json (two quick cells).
head=$(git -C "$root" rev-parse HEAD 2>/dev/null) || { echo "SKIP: not a git checkout"; exit 77; }
work=$(mktemp -d)
trap 'rm -rf "$work"' EXIT
mkdir -p "$work/builds/$head"
ln -s "$bin" "$work/builds/$head/${exe:-mcfbench}"
cat >"$work/tiny.json" <<'JSON'
{"name": "tiny", "defaults": {"mesh": "icosphere:level=2", "steps": 3, "dt": 1e-4, "threads": 1},
 "axes": {"solver.name": ["cholmod", "pcg"]},
 "quick": {"defaults": {"steps": 3}}}
JSON
