#!/bin/sh
# Plan every scenario of tools/maneuvers/ with `agsteer maneuver` (run from the repository
# root): prints one summary line per scenario and writes out/maneuvers/NAME.svg.
# Usage: tools/maneuvers/run.sh [AGSTEER] [extra agsteer maneuver options, e.g. --curve rs]
set -eu
AGSTEER=${1:-target/release/agsteer}
[ $# -gt 0 ] && shift
mkdir -p out/maneuvers
for toml in tools/maneuvers/*.toml; do
    name=$(basename "$toml" .toml)
    args=$(python3 - "$toml" <<'PY'
import sys, tomllib
d = tomllib.load(open(sys.argv[1], "rb"))
pose = lambda p: ",".join(str(v) for v in p)
out = ["--map", "tools/maneuvers/" + d["map"], "--from", pose(d["from"]), "--to", pose(d["to"])]
for s in d.get("set", []):
    out += ["--set", s]
print(" ".join(out))
PY
)
    printf '%-18s ' "$name"
    # shellcheck disable=SC2086
    "$AGSTEER" maneuver --config config/demo.toml $args --svg "out/maneuvers/$name.svg" "$@" || true
done
