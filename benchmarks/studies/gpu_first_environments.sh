#!/usr/bin/env bash
# metric-300's first K environments on a CUDA machine, as committed (render.variant: auto),
# twice: with an empty Dr.Jit kernel cache (cold) and again into a new folder (warm), so the
# difference is the kernel compilation. Brings back, under $OUT, the logs, the units'
# seconds (progress/*.json) and each environment's block luminances for
#   python benchmarks/studies/backend_agreement.py compare gpu-env000.npz cpu-env000.npz
# against the same units rendered with llvm_ad_spectral on a CPU (docs/performance.md, "On a GPU").
#
# Prepare here: bash ../shared/tools/gpu-wheels.sh   (writes .whl/, which the device run carries)
# Run there:    bash benchmarks/studies/gpu_first_environments.sh K SECONDS   (K environments, SECONDS in all)
set -uo pipefail
K=${1:-2}
TOTAL=${2:-540}
OUT=${OUT:-/tmp/gpu-out}
mkdir -p "$OUT"
t0=$(date +%s)
left() { echo $(( TOTAL - ($(date +%s) - t0) )); }

python3 -m pip install -q --no-index --no-deps --no-compile --target /tmp/site .whl/*.whl \
  && python3 -c "import glob, zipfile; [zipfile.ZipFile(z).extractall('/tmp/site') for z in glob.glob('.whl/*.zip')]" \
  || exit 1  # (mitsuba-stripped.zip, and the stripped colour packages of gpu_scored_environments.sh prepare)
export PYTHONPATH=/tmp/site:$PWD PYTHONUNBUFFERED=1
{ nvidia-smi -L; echo "cpus $(nproc)"; python3 --version; echo "installed in $(( $(date +%s) - t0 )) s"; } | tee "$OUT/info.txt"
variant=$(python3 -c "from metricscenes.render import resolve_variant; print(resolve_variant('auto'))") || exit 1
echo "auto resolves to $variant" | tee -a "$OUT/info.txt"
[ "$variant" = cuda_ad_spectral ] || exit 1

sed "s/^environments: 50/environments: $K/; s/^name: metric-300/name: metric-300-first$K/" \
  manifests/metric-300.yaml > /tmp/first.yaml
nvidia-smi dmon -s um -d 5 > "$OUT/dmon.log" 2>&1 &
run() {  # folder, seconds at most
  local s=$(date +%s)
  timeout "$2" python3 -m metricscenes.cli generate --manifest /tmp/first.yaml --out "/tmp/$1" --workers 1 \
    > "$OUT/$1.log" 2>&1
  echo "$1: exit $?, $(( $(date +%s) - s )) s wall, store $(du -sh /tmp/$1/radiance.zarr | cut -f1)" | tee -a "$OUT/info.txt"
}
run cold $(( $(left) - 150 ))
for env in $(seq -f 'env%03g' 0 $(( K - 1 ))); do
  units=$(cd /tmp/cold/progress 2>/dev/null && ls | grep -E "^$env(-d[0-9]+m)?\.json$" | sed 's/\.json$//')
  [ -n "$units" ] && python3 benchmarks/studies/backend_agreement.py stats /tmp/cold --units $units --out "$OUT/gpu-$env.npz"
done
{ s=$(date +%s); timeout 60 python3 -m metricscenes.cli verify /tmp/cold; echo "verify: exit $?, $(( $(date +%s) - s )) s"; } \
  >> "$OUT/info.txt" 2>&1
[ "$(left)" -gt 60 ] && run warm $(( $(left) - 20 ))
tar czf "$OUT/progress.tgz" -C /tmp cold/progress cold/manifest.resolved.yaml warm/progress 2>/dev/null
kill %1 2>/dev/null
cat "$OUT/info.txt"
