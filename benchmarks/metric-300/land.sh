#!/usr/bin/env bash
# Bring what benchmarks/metric-300/chain.sh made under WORK into this checkout, and check it:
# the tables (docs/data/metric-300), the report's figures (docs/img/metric-300), the 13
# reference submissions with their detections (leaderboard/submissions), every submission `--check`ed
# (AP recomputed from the detections it ships; delete metric-300's made_before_detections pins in
# benchmark/leaderboard/data/protocols.yaml once its references ship theirs), the
# leaderboard rendered twice and compared byte for byte, the findings tests on the tables,
# and the markdown of metric-300's tables beside quick's (WORK/results-markdown.md, for
# docs/results.md). Refuses to start before the chain's tables are all there but day_paper's
# (its sweep, the chain's last step, is brought in when present: run this again once it is).
#
#   bash benchmarks/metric-300/land.sh /work /work/m300-code/docs/data/metric-300
#
# WORK: the chain's WORK; TABLES: the chain's DATA_OUT (in the checkout the chain ran from).
# LEADERBOARD (default leaderboard), DATA (docs/data/metric-300) and IMG (docs/img/metric-300)
# let it run on a stand-in (the findings tests then are not run).
set -euo pipefail
WORK=$(realpath "${1:?usage: land.sh WORK TABLES}")
TABLES=$(realpath "${2:?usage: land.sh WORK TABLES}")
cd "$(dirname "$0")/../.."
export PYTHONPATH=$PWD MPLBACKEND=Agg
LEADERBOARD=${LEADERBOARD:-leaderboard}
DATA=${DATA:-docs/data/metric-300}
IMG=${IMG:-docs/img/metric-300}
for table in sweep sweep-640 sweep-native sweep-illuminance od50 mtf50-groups; do
  [ -s "$TABLES/$table.csv" ] || { echo "error: $TABLES/$table.csv is missing: the chain is not done" >&2; exit 1; }
done

mkdir -p "$DATA" "$IMG" "$LEADERBOARD/submissions"
[ "$(realpath "$TABLES")" = "$(realpath "$DATA")" ] || cp "$TABLES"/*.csv "$DATA"/
for figure in ap_vs_distance spm_mtf50 od50_vs_mtf50; do
  cp "$WORK/reports/figures/$figure.png" "$IMG/$figure.png"
done
cp "$WORK"/reports/figures/spm_illuminance_*.png "$IMG/spm_illuminance.png"  # the one luminance camera
cp "$WORK"/leaderboard/submissions/ref-*-metric-300.json "$LEADERBOARD/submissions/"
for shipped in "$WORK"/leaderboard/submissions/ref-*-metric-300.detections; do  # each one's detections (docs/leaderboard.md)
  [ -d "$shipped" ] || { echo "error: $shipped is missing: submit the sweep again (its references ship detections)" >&2; exit 1; }
  rm -rf "$LEADERBOARD/submissions/$(basename "$shipped")" && cp -r "$shipped" "$LEADERBOARD/submissions/"
done

for submission in "$LEADERBOARD"/submissions/*.json; do
  benchmark submit --check "$submission" --leaderboard "$LEADERBOARD"
done
first=$(mktemp -d)
benchmark leaderboard --dir "$LEADERBOARD"
cp "$LEADERBOARD/README.md" "$LEADERBOARD/index.html" "$LEADERBOARD"/references-*.svg "$first/"
benchmark leaderboard --dir "$LEADERBOARD"
for page in "$first"/*; do cmp "$page" "$LEADERBOARD/$(basename "$page")"; done
echo "leaderboard: two builds byte-identical"
rm -r "$first"

benchmark publish markdown --data "$DATA" --against docs/data > "$WORK/results-markdown.md"
echo "markdown of the tables beside quick's: $WORK/results-markdown.md"
[ "$DATA" = docs/data/metric-300 ] && python -m pytest -q tests/test_metric300_findings.py
echo "landed; now: docs/results.md leads with metric-300, docs/performance.md the chain's '== STEP' times"
