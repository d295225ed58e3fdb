#!/usr/bin/env bash
# What a sweep spends giving its large arrays back to the kernel: the same small sweep with
# glibc's default (every block over 32 MB is mmap'ed and unmapped when freed, so each new
# array is page-faulted in and zeroed by the kernel again) and with large blocks kept in the
# heap for reuse (benchmarks/metric-300/heap-malloc.env, what the metric-300 chain sweeps with), alternated
# twice; prints user, system and wall seconds, minor page faults and peak RSS of each, the
# ratio of their CPU times, and whether the two settings' detections are byte-identical
# (they must be: only where the memory comes from differs). Results: docs/performance.md, "Large arrays kept in the heap".
#
#   bash benchmarks/timing/bench_malloc.sh /work/collections/metric-300-first2 cam08,cam12,cam05 day
set -euo pipefail
COLLECTION=${1:?usage: bench_malloc.sh COLLECTION [CAMERAS] [CONDITION]}
CAMERAS=${2:-cam08,cam12,cam05}
CONDITION=${3:-day}
OUT=$(mktemp -d)
trap 'rm -rf "$OUT"' EXIT
mapfile -t HEAP < <(grep -v '^#' "$(dirname "$0")/../metric-300/heap-malloc.env")  # the chain's setting
for round in 1 2; do
  for setting in default heap; do
    rm -rf "$OUT/$setting"
    [ $setting = heap ] && settings=("${HEAP[@]}") || settings=()
    env "${settings[@]}" /usr/bin/time -o "$OUT/$setting-$round.time" -f "%U %S %e %R %M" \
      benchmark sweep --collection "$COLLECTION" --cameras "$CAMERAS" --conditions "$CONDITION" \
      --environments 0-1 --distances 25,50 --out "$OUT/$setting" --no-save-images --resamples 20 --workers 1 \
      > /dev/null
    read -r user sys wall faults rss < "$OUT/$setting-$round.time"
    echo "round $round $setting: user $user s, system $sys s, wall $wall s, minor faults $faults, peak RSS $((rss / 1024)) MB"
  done
  python - "$OUT/default-$round.time" "$OUT/heap-$round.time" <<'EOF'
import sys
cpu = [sum(map(float, open(p).read().split()[:2])) for p in sys.argv[1:]]
print(f"  CPU time, default / heap: {cpu[0] / cpu[1]:.2f}x")
EOF
done
for detections in "$OUT"/default/runs/*/detections.json; do
  cmp "$detections" "$OUT/heap/runs/$(basename "$(dirname "$detections")")/detections.json"
done
echo "detections byte-identical under both settings ($(ls "$OUT"/default/runs | wc -l) runs)"
