#!/bin/sh
# Run every scenario in tools/scenarios with the release build and print a Markdown table of
# the XTE figures (scored against the simulator's ground truth). Usage, from the repository:
#   cargo build --release && tools/scenarios/run.sh [extra agsteer demo options, e.g. --set ...]
set -eu
bin=${AGSTEER:-./target/release/agsteer}
out=${OUT:-/tmp/agsteer-scenarios}
echo "| scenario | finished | lines | XTE rms cm | XTE p95 cm | XTE max cm | acquisition max cm | engaged % | disengagements |"
echo "|---|---|---|---|---|---|---|---|---|"
for f in tools/scenarios/*.toml; do
    name=$(basename "$f" .toml)
    "$bin" demo --config "$f" --out "$out/$name" --json "$@" 2>/dev/null | python3 -c '
import json, sys
r = json.load(sys.stdin)
d = ", ".join("%s %s" % kv for kv in sorted(r["disengagements"].items())) or "-"
cm = lambda k: "%.2f" % (100 * r[k])
print("| %s | %s | %d/%d | %s | %s | %s | %s | %.2f | %s |" % (
    sys.argv[1], r["finished"], r["lines_completed"], r["lines_planned"], cm("xte_rms_m"),
    cm("xte_p95_m"), cm("xte_max_m"), cm("acquisition_xte_max_m"),
    100 * r["engaged_fraction"], d))
' "$name"
done
