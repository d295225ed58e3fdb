#!/usr/bin/env bash
# metric-300's first K environments rendered on a CUDA machine (render.variant: auto →
# cuda_ad_spectral) and scored there by the 13-camera sweep, so the GPU's collection can be
# compared by score with the CPU's (docs/performance.md, "On a GPU"): only the small outputs
# come back (the runs' detections and results, the sweep's tables, the units' seconds).
#
# Here, once:   bash benchmarks/studies/gpu_scored_environments.sh prepare
#   (../shared/tools/gpu-wheels.sh's .whl/, with colour-science's coverage report and
#   colour-demosaicing's notebook left out so that the detector fits in the 64 MiB that
#   travels; the sweep's two wheels; the default detector in .gpu-models/)
# There:        bash benchmarks/studies/gpu_scored_environments.sh K SECONDS CAMERAS CONDITIONS
#   e.g.        bash benchmarks/studies/gpu_scored_environments.sh 10 540 all day,night
# Then here:    benchmark publish backend-scores ...  (compares with the CPU's runs)
set -uo pipefail

if [ "${1:-}" = prepare ]; then
  set -e
  [ -f .whl/mitsuba-stripped.zip ] || bash ../shared/tools/gpu-wheels.sh
  version() { python3 -c "import importlib.metadata as m; print(m.version('$1'))"; }
  plat=(--only-binary=:all: --python-version 3.12 --implementation cp --platform manylinux_2_28_x86_64
        --platform manylinux_2_27_x86_64 --platform manylinux_2_17_x86_64 --platform manylinux2014_x86_64)
  mkdir -p /tmp/gpu-sweep-wheels .gpu-models
  grep -qx '/.gpu-models/' .git/info/exclude || echo '/.gpu-models/' >> .git/info/exclude
  python3 -m pip download -q --no-deps "${plat[@]}" -d .whl "faster-coco-eval==$(version faster-coco-eval)"
  python3 -m pip download -q --no-deps "${plat[@]}" -d /tmp/gpu-sweep-wheels \
    "colour-demosaicing==$(version colour-demosaicing)"
  python3 - <<'PY'
import glob, os, zipfile
# (a zip, unpacked into the install folder like mitsuba-stripped.zip: a wheel whose RECORD no longer matches)
for pattern, out, drop in [(".whl/colour_science-*.whl", ".whl/colour-stripped.zip", ("colour/htmlcov/", "colour/examples/")),
                           ("/tmp/gpu-sweep-wheels/colour_demosaicing-*.whl", ".whl/demosaicing-stripped.zip",
                            ("colour_demosaicing/examples/",))]:
    src = sorted(glob.glob(pattern))[-1]
    with zipfile.ZipFile(src) as zin, zipfile.ZipFile(out, "w", zipfile.ZIP_DEFLATED) as zout:
        for i in zin.infolist():
            if not i.filename.startswith(drop) and "/tests/" not in i.filename:
                zout.writestr(i, zin.read(i.filename))
    if src.startswith(".whl/"):
        os.remove(src)
PY
  cp "${METRICSCENES_MODEL_DIR:-../shared/models}/yolov5n-dynamic.onnx" .gpu-models/
  du -shc .whl .gpu-models
  exit 0
fi

K=${1:-10}
TOTAL=${2:-540}
CAMERAS=${3:-all}
CONDITIONS=${4:-day,night}
OUT=${OUT:-/tmp/gpu-out}
mkdir -p "$OUT"
t0=$(date +%s)
left() { echo $(( TOTAL - ($(date +%s) - t0) )); }
stamp() { echo "$(( $(date +%s) - t0 )) s: $*" | tee -a "$OUT/info.txt"; }

if ! python3 -c "import mitsuba" 2>/dev/null; then
  python3 -m pip install -q --no-index --no-deps --no-compile --target /tmp/site .whl/*.whl \
    && python3 -c "import glob, zipfile; [zipfile.ZipFile(z).extractall('/tmp/site') for z in glob.glob('.whl/*.zip')]" \
    || exit 1
  export PYTHONPATH=/tmp/site:$PWD
fi
export PYTHONUNBUFFERED=1 METRICSCENES_MODEL_DIR=$PWD/.gpu-models
{ nvidia-smi -L; echo "cpus $(nproc)"; python3 --version; lscpu | grep -m1 'Model name'; } >> "$OUT/info.txt" 2>&1
variant=$(python3 -c "from metricscenes.render import resolve_variant; print(resolve_variant('auto'))") || exit 1
stamp "installed; auto resolves to $variant"

C=/tmp/m300-first$K
# the text the CPU's copy of these K environments is made from (python -m metricscenes.first_environments): one sha256
python3 -c 'import sys; from metricscenes.first_environments import first_manifest_text as first
sys.stdout.write(first(open(sys.argv[1]).read(), int(sys.argv[2])))' "${MANIFEST:-manifests/metric-300.yaml}" "$K" \
  > /tmp/first.yaml || exit 1
nvidia-smi dmon -s um -d 5 > "$OUT/dmon.log" 2>&1 &
dmon=$!
# 8 render workers: with fewer the GPU waited for the CPU's scene building and encoding
timeout $(( $(left) - 240 )) python3 -m metricscenes.cli generate --manifest /tmp/first.yaml --out $C --workers 8 \
  > "$OUT/generate.log" 2>&1
stamp "generate: exit $?, store $(du -sh $C/radiance.zarr | cut -f1)"
kill $dmon 2>/dev/null
( s=$(date +%s); timeout 200 python3 -m metricscenes.cli verify $C > "$OUT/verify.log" 2>&1
  echo "verify: exit $?, $(( $(date +%s) - s )) s" >> "$OUT/verify.log" ) &
verifying=$!
timeout $(( $(left) - 25 )) python3 -m benchmark.cli sweep --collection $C --cameras "$CAMERAS" \
  --conditions "$CONDITIONS" --out /tmp/sweep --workers "$(nproc)" --no-save-images --resamples 1000 --seed 0 \
  > "$OUT/sweep.log" 2>&1
stamp "sweep: exit $?"
wait $verifying
# the runs without images, the sweep's tables, the units' seconds
( cd /tmp && tar czf "$OUT/scored.tgz" --exclude=images --exclude=.partial-resume sweep \
    "m300-first$K/progress" "m300-first$K/groundtruth.json" "m300-first$K/manifest.resolved.yaml" 2>/dev/null )
stamp "packed $(du -sh $OUT/scored.tgz | cut -f1)"
cat "$OUT/info.txt" "$OUT/verify.log"
tail -3 "$OUT/sweep.log"
