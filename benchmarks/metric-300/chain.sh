#!/usr/bin/env bash
# metric-300 from nothing to its published tables, one resumable step after another:
# generate, verify, the reference sweep (13 cameras x day, dusk and both nights, with its
# 640 and native passes from the same inference), the illuminance sweep, the MTF50 groups'
# pairs, docs/data/metric-300's tables, the report and the 13 reference submissions, then
# day_paper. Each step skips what is done (generate and sweep resume unit by unit and scene
# by scene; generate and verify leave a marker when done), so after a killed session run the same command again.
# Long: about 11.5 h of generation and 4-5 h of sweep on 2 AVX2 cores (docs/performance.md).
#
#   nohup setsid bash benchmarks/metric-300/chain.sh /work/m300 >> /work/m300-chain.log 2>&1 &
#
# WORK (the first argument) holds the collection, the sweep folders and the markers, outside
# git. Run it from a checkout nobody commits to while it runs (a `git worktree` of a landed
# commit): a sweep must not mix two versions of the code. Writes nothing into this checkout
# but $DATA_OUT (docs/data/metric-300: the published tables); the report and the submissions
# go under WORK. To try the chain on a small stand-in first: MANIFEST=<a shrunk copy of
# metric-300.yaml> CAMERAS=cam12,cam01 DATA_OUT=<a folder outside git> (the submissions then
# need WORK/leaderboard/protocols.yaml to accept the stand-in's manifest sha256).
# Then benchmarks/metric-300/land.sh, from the checkout that commits, brings tables, figures
# and submissions in and checks them.
set -euo pipefail
WORK=$(realpath -m "${1:?usage: chain.sh WORK}")
cd "$(dirname "$0")/../.."
export PYTHONPATH=$PWD  # this checkout's code, even where the venv's editable install points at another
export METRICSCENES_MODEL_DIR=$(realpath "${METRICSCENES_MODEL_DIR:-../shared/models}")
export MPLBACKEND=Agg PYTHONUNBUFFERED=1
MANIFEST=${MANIFEST:-manifests/metric-300.yaml}
CAMERAS=${CAMERAS:-all}
DATA_OUT=${DATA_OUT:-docs/data/metric-300}
COLLECTION=$WORK/collections/metric-300
RESULTS=$WORK/results
mkdir -p "$DATA_OUT" "$RESULTS"
SWEEP=(--no-save-images --resamples 1000 --seed 0 --workers 2)
# verify and the sweeps keep their large arrays in the heap (same bytes, less CPU time; the
# file says why). Not generate: the audit behind it did not cover the renderer (docs/performance.md).
mapfile -t HEAP_MALLOC < <(grep -v '^#' benchmarks/metric-300/heap-malloc.env)
# timed STEP COMMAND...: the command, then "== STEP (this sitting): N s wall" (a resumed step counts its sitting only)
timed() { local step=$1 t0; shift; t0=$(date +%s); echo "== $(date -u +%FT%TZ) $*"; "$@"; echo "== $step (this sitting): $(( $(date +%s) - t0 )) s wall"; }

# A finished collection is not checked again at every restart (generate reads every unit back:
# ≈ 8 min for metric-300); verify below reads it all once, and every later read checks what it reads.
if [ ! -e "$WORK/generated" ]; then
  timed generate metricscenes generate --manifest "$MANIFEST" --out "$COLLECTION" --workers 1
  touch "$WORK/generated"
fi
if [ ! -e "$WORK/verified" ]; then
  timed verify env "${HEAP_MALLOC[@]}" metricscenes verify "$COLLECTION"
  touch "$WORK/verified"
fi
timed sweep env "${HEAP_MALLOC[@]}" benchmark sweep --collection "$COLLECTION" --cameras "$CAMERAS" --conditions day,dusk,night,night_regulation \
  --out "$RESULTS/metric-300" --also-input-size 640="$RESULTS/metric-300-640" \
  --also-input-size native="$RESULTS/metric-300-native" "${SWEEP[@]}"
timed lux-sweep env "${HEAP_MALLOC[@]}" benchmark sweep --collection "$COLLECTION" --cameras cameras/lux-sweep-1.4um-f2.4.yaml \
  --conditions day@0.25lux,day@1lux,day@5lux,day@10lux,day@50lux,day@100lux,day@500lux \
  --out "$RESULTS/metric-300-lux" "${SWEEP[@]}"
benchmark publish mtf50-groups --sweep "$RESULTS/metric-300" --conditions day,dusk,night \
  --out "$DATA_OUT/mtf50-groups.csv"
benchmark publish sweeps --results "$RESULTS" --collection metric-300 \
  --out "$DATA_OUT"
benchmark report "$RESULTS/metric-300" "$RESULTS/metric-300-lux" --out "$WORK/reports/metric-300.html"
# The 13 reference submissions, into a leaderboard folder of WORK's (copied to leaderboard/ by hand).
mkdir -p "$WORK/leaderboard/submissions"
[ "$CAMERAS" = all ] && cameras=$(seq -f "cam%02g" 1 13) || cameras=${CAMERAS//,/ }
for camera in $cameras; do
  ref="$WORK/leaderboard/submissions/ref-$camera-yolov5n-metric-300"
  [ -d "$ref.detections" ] || rm -f "$ref.json"  # one made before detections shipped: submitted again, with them
  [ -e "$ref.json" ] \
    || benchmark submit "$RESULTS/metric-300" --camera "$camera" --name "ref-{camera}-yolov5n-metric-300" \
         --submitter "metricscenes reference" --leaderboard "$WORK/leaderboard"
  benchmark submit --check "$WORK/leaderboard/submissions/ref-$camera-yolov5n-metric-300.json" --leaderboard "$WORK/leaderboard"
done
timed day-paper-sweep env "${HEAP_MALLOC[@]}" benchmark sweep --collection "$COLLECTION" --cameras "$CAMERAS" --conditions day_paper \
  --out "$RESULTS/metric-300-day-paper" "${SWEEP[@]}"
benchmark publish sweeps --results "$RESULTS" --collection metric-300 \
  --out "$DATA_OUT"
echo "== $(date -u +%FT%TZ) metric-300 chain done"
