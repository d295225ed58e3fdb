"""Bad inputs to `metricscenes generate` and `benchmark run`:
each ends in a non-zero exit and one line, never a traceback, and nothing is created or
lost (no `--out`, existing files byte-identical). Also the writer's lock per collection
and a detector whose outputs are NaN."""

import hashlib
import json
import os
import shutil
import socket
import subprocess
import sys
from pathlib import Path

import numpy as np
import pytest
import yaml

from cli_output import error_lines
from conftest import REPO, SMOKE_MANIFEST

# A one-scene manifest: should a refusal fail to happen, the render is still short.
TINY = {**yaml.safe_load(SMOKE_MANIFEST.read_text()), "environments": 1, "distances_m": [25]}


def _run(module, *args, env=None, timeout=300):
    return subprocess.run([sys.executable, "-m", module, *map(str, args)], capture_output=True, text=True,
                          cwd=REPO, timeout=timeout, env={**os.environ, **(env or {})})


def _one_line_error(proc) -> str:
    assert proc.returncode != 0, proc.stdout + proc.stderr
    assert "Traceback" not in proc.stderr + proc.stdout
    lines = error_lines(proc.stderr)  # (progress lines may come first: cli_output)
    assert len(lines) == 1, proc.stderr
    assert lines[0].startswith("error: ")
    return lines[0]


def _snapshot(root: Path) -> dict[str, str]:
    """Every file under ``root`` (and the folders) by relative path: sha256 of its bytes."""
    return {str(p.relative_to(root)): hashlib.sha256(p.read_bytes()).hexdigest() if p.is_file() else "dir"
            for p in sorted(root.rglob("*"))}


def _manifest(tmp_path: Path, data=None, text: str | None = None, name="m.yaml") -> Path:
    path = tmp_path / name
    if text is not None:
        path.write_text(text)
    else:
        path.write_text(yaml.safe_dump(data, sort_keys=False))
    return path


def _tiny(**changes) -> dict:
    data = json.loads(json.dumps(TINY))
    data.update(changes)
    return data


def _generate_refused(tmp_path, manifest: Path, *extra, env=None) -> str:
    out = tmp_path / "out"
    line = _one_line_error(_run("metricscenes.cli", "generate", "--manifest", manifest, "--out", out, *extra, env=env))
    assert not out.exists(), "a refused generate created --out"
    return line


# --- manifests refused as a whole, before any output ------------------------------------
SMOKE_TEXT = SMOKE_MANIFEST.read_text()


def _edit(change):
    data = _tiny()
    change(data)
    return data


BAD_MANIFESTS = {
    # point 7: accepted silently before
    "environments_true": (_edit(lambda d: d.update(environments=True)), "environments"),
    "seed_as_string": (_edit(lambda d: d.update(seed="20230115")), "seed"),
    "spp_as_float": (_edit(lambda d: d["render"].update(plate_spp=4.0)), "render.plate_spp"),
    "infinite_weight": (_edit(lambda d: d["conditions"]["day"].update(sky_day=float("inf"))), "conditions.day.sky_day"),
    "huge_weight": (_edit(lambda d: d["conditions"]["day"].update(sky_day=1e300)), "conditions.day.sky_day"),
    "repeated_light_group": (_edit(lambda d: d.update(light_groups=[*d["light_groups"], "sky_day"])), "light_groups"),
    "repeated_sweep_level": (_edit(lambda d: d["illuminance_sweep"].update(levels_lux=[1, 100, 1])), "levels_lux"),
    "sweep_levels_with_one_name": (_edit(lambda d: d["illuminance_sweep"].update(levels_lux=[1, 1.0000001])),
                                   "levels_lux"),
    "repeated_lamp_group": (_edit(lambda d: d["illuminance_sweep"].update(lamps_on=["car_lights", "car_lights"])),
                            "lamps_on"),
    "condition_named_like_a_sweep_level": (_edit(lambda d: d["conditions"].update({"day@1lux": {"sky_day": 1.0}})),
                                           "reserved"),
    "condition_escaping_its_folder": (_edit(lambda d: d["conditions"].update({"../../x": {"sky_day": 1.0}})),
                                      "condition name"),
    "condition_with_a_newline": (_edit(lambda d: d["conditions"].update({"a\nb": {"sky_day": 1.0}})),
                                 "condition name"),
    "condition_lighting_nothing": (_edit(lambda d: d["conditions"].update(dark={"sky_day": 0.0})), "lights nothing"),
    # point 6: a NaN distance failed only after --out was stamped
    "nan_distance": (_edit(lambda d: d.update(distances_m=[25, float("nan")])), "distances_m"),
}


@pytest.mark.parametrize("case", list(BAD_MANIFESTS))
def test_bad_manifest_is_refused_before_any_output(tmp_path, case):
    data, words = BAD_MANIFESTS[case]
    line = _generate_refused(tmp_path, _manifest(tmp_path, data))
    assert words in line, line


@pytest.mark.parametrize("case, text, words", [
    ("duplicate_top_level_key", SMOKE_TEXT.replace("seed: 20230115", "seed: 20230115\nseed: 7"),
     "duplicate key 'seed' at line"),
    ("duplicate_nested_key", SMOKE_TEXT.replace("day: {sky_day: 1.0}", "day: {sky_day: 1.0, sky_day: 2.0}"),
     "duplicate key 'sky_day' at line"),
    ("duplicate_condition", SMOKE_TEXT.replace("  day: {sky_day: 1.0}", "  day: {sky_day: 1.0}\n  day: {sky_day: 2.0}"),
     "duplicate key 'day' at line"),
    ("nesting_too_deep", "name: " + "[" * 50000 + "]" * 50000 + "\n", "nested too deeply"),
    ("larger_than_a_manifest", "description: '" + "x" * (1 << 21) + "'\n", "larger than 1 MiB"),
])
def test_bad_manifest_text_is_refused(tmp_path, case, text, words):
    line = _generate_refused(tmp_path, _manifest(tmp_path, text=text))
    assert words in line, line


def test_non_utf8_manifest_is_one_line(tmp_path):
    path = tmp_path / "latin1.yaml"
    path.write_bytes(SMOKE_TEXT.replace("Two environments", "Zwei Umgebungen f\u00fcr").encode("latin-1"))
    line = _generate_refused(tmp_path, path)
    assert "not UTF-8" in line and "0xfc" in line


def test_committed_manifests_still_load_with_the_strict_loader():
    """Duplicate keys, strict types and reserved names do not touch the committed
    manifests: their sha256 (which the leaderboard's protocols name) is unchanged."""
    from metricscenes.manifest import UniqueKeyLoader, load_manifest, parse_manifest

    for name in ("smoke", "quick", "metric-300"):
        path = REPO / "manifests" / f"{name}.yaml"
        strict = load_manifest(path)
        assert strict == parse_manifest(yaml.safe_load(path.read_text()))
        assert yaml.load(path.read_text(), Loader=UniqueKeyLoader) == yaml.safe_load(path.read_text())
        assert strict.sha256() in (REPO / "benchmark" / "leaderboard" / "data" / "protocols.yaml").read_text()


# --- memory estimate ---------------------------------------------------------------------
def test_memory_estimate_refused_above_the_limit_says_how_much(tmp_path):
    data = _tiny(reference_grid={"width_px": 4096, "height_px": 2304})
    line = _generate_refused(tmp_path, _manifest(tmp_path, data), env={"METRICSCENES_MAX_MEMORY_GIB": "4"})
    assert "about 4.9 GiB" in line and "limit of 4.0 GiB" in line and "4096x2304" in line, line


def test_memory_estimate_counts_the_workers(tmp_path):
    data = _tiny(reference_grid={"width_px": 1920, "height_px": 1080})
    line = _generate_refused(tmp_path, _manifest(tmp_path, data), "--workers", "32",
                             env={"METRICSCENES_MAX_MEMORY_GIB": "16"})
    assert "32 workers x 1.4 GiB" in line and "limit of 16.0 GiB" in line, line


def test_memory_estimate_of_fine_insets_is_tens_of_gib(monkeypatch):
    from metricscenes.manifest import ManifestError, check_memory, load_manifest, parse_manifest

    data = yaml.safe_load((REPO / "manifests" / "quick.yaml").read_text())
    data["render"].update(inset_max_px=8192, inset_pixel_mrad=0.01)
    big = parse_manifest(data)
    assert 30 * 2**30 < big.memory_estimate_bytes() < 40 * 2**30
    monkeypatch.setenv("METRICSCENES_MAX_MEMORY_GIB", "24")
    with pytest.raises(ManifestError, match=r"about 32\.\d GiB"):
        check_memory(big)
    # The committed ones: under 1 GiB a process (scalar), 10 GiB for metric-300 (auto: its LLVM
    # wavefront in bands of 2**24 lanes; 7.9 GiB measured), so two workers fit in 24 GB.
    for name, gib in (("smoke", 1), ("quick", 1), ("metric-300", 10)):
        assert check_memory(load_manifest(REPO / "manifests" / f"{name}.yaml")) < gib * 2**30
    metric = load_manifest(REPO / "manifests" / "metric-300.yaml")
    scalar = metric.model_copy(update={"render": metric.render.model_copy(update={"variant": "scalar_spectral"})})
    assert scalar.memory_estimate_bytes() < 2 * 2**30 < 7 * 2**30 < metric.memory_estimate_bytes()
    monkeypatch.setenv("METRICSCENES_MAX_MEMORY_GIB", "lots")
    with pytest.raises(ManifestError, match="positive number of GiB"):
        check_memory(big)


# --- --out and the render variant, before any output -------------------------------------
def test_generate_out_naming_a_file_is_one_line(tmp_path):
    out = tmp_path / "taken"
    out.write_text("precious\n")
    manifest = _manifest(tmp_path, _tiny())
    line = _one_line_error(_run("metricscenes.cli", "generate", "--manifest", manifest, "--out", out))
    assert "is a file" in line
    assert out.read_text() == "precious\n"
    line = _one_line_error(_run("metricscenes.cli", "generate", "--manifest", _manifest(tmp_path, _tiny()),
                                "--out", out / "sub"))
    assert "is a file" in line and out.read_text() == "precious\n"


def test_generate_out_that_holds_other_files_or_lies_in_a_collection(tmp_path):
    notes = tmp_path / "notes"
    notes.mkdir()
    (notes / "todo.txt").write_text("x")
    line = _one_line_error(_run("metricscenes.cli", "generate", "--manifest", _manifest(tmp_path, _tiny()),
                                "--out", notes))
    assert "holds other files (todo.txt)" in line
    assert _snapshot(notes) == {"todo.txt": hashlib.sha256(b"x").hexdigest()}
    fake = tmp_path / "collection"
    (fake / "progress").mkdir(parents=True)
    (fake / "progress" / "manifest_sha256").write_text("0" * 64 + "\n")
    line = _one_line_error(_run("metricscenes.cli", "generate", "--manifest", _manifest(tmp_path, _tiny()),
                                "--out", fake / "nested"))
    assert "inside the collection" in line and not (fake / "nested").exists()


def test_cuda_variant_without_a_gpu_fails_before_any_output(tmp_path):
    data = _tiny()
    data["render"]["variant"] = "cuda_ad_spectral"
    out = tmp_path / "out"
    proc = _run("metricscenes.cli", "generate", "--manifest", _manifest(tmp_path, data), "--out", out)
    if proc.returncode == 0:  # a machine with a usable CUDA GPU: it renders
        assert (out / "groundtruth.json").exists()
        return
    line = _one_line_error(proc)
    assert "cuda_ad_spectral" in line and "scalar_spectral" in line
    assert not out.exists()


def test_a_run_that_failed_before_finishing_a_unit_does_not_block_the_corrected_manifest(tmp_path, smoke_manifest):
    """A folder stamped by a run that finished no unit (a render error) is not 'another
    manifest's collection'; one with a finished unit still is."""
    from metricscenes.store import CollectionError
    from metricscenes.writer import CollectionWriter

    root = tmp_path / "c"
    (root / "progress").mkdir(parents=True)
    (root / "progress" / "manifest_sha256").write_text("f" * 64 + "\n")
    variant = smoke_manifest.render.variant
    CollectionWriter(root).prepare(smoke_manifest, variant)
    assert (root / "progress" / "manifest_sha256").read_text().strip() == smoke_manifest.sha256()
    (root / "progress" / "env000.json").write_text("{}")
    with pytest.raises(CollectionError, match="another manifest"):
        CollectionWriter(root).prepare(smoke_manifest.model_copy(update={"seed": 1}), variant)


# --- the writer's lock -------------------------------------------------------------------
def _start_ticks(pid: int) -> int:
    return int(Path(f"/proc/{pid}/stat").read_text().rsplit(")", 1)[1].split()[19])


def test_second_generate_is_refused_naming_the_holder(tmp_path):
    from metricscenes.lock import collection_lock

    out = tmp_path / "out"
    out.mkdir()
    with collection_lock(out) as lock:
        holder = json.loads(lock.read_text())
        assert holder["pid"] == os.getpid() and holder["host"] == socket.gethostname()
        before = _snapshot(out)
        line = _one_line_error(_run("metricscenes.cli", "generate", "--manifest", _manifest(tmp_path, _tiny()),
                                    "--out", out))
        assert f"PID {os.getpid()} on host {socket.gethostname()}" in line and "generate.lock" in line, line
        assert _snapshot(out) == before  # nothing written, the holder's lock intact
    assert not lock.exists()  # released on exit


@pytest.mark.skipif(not Path("/proc/self/stat").exists(), reason="needs /proc")
def test_stale_lock_is_taken_over_and_a_live_one_is_not(tmp_path):
    from metricscenes.lock import LockError, collection_lock

    dead = subprocess.Popen(["true"])
    dead.wait()
    lock = tmp_path / "generate.lock"
    host = socket.gethostname()
    lock.write_text(json.dumps({"pid": dead.pid, "host": host, "since": "earlier"}))
    notices = []
    with collection_lock(tmp_path, notice=notices.append):
        assert json.loads(lock.read_text())["pid"] == os.getpid()
    assert notices == [f"taking over the stale lock of PID {dead.pid} on host {host} since earlier (no longer running)"]
    assert not lock.exists()
    # A lock file naming a live process on this host (written where flock is not shared) is honoured...
    sleeper = subprocess.Popen(["sleep", "60"])
    try:
        lock.write_text(json.dumps({"pid": sleeper.pid, "host": host, "process_start": _start_ticks(sleeper.pid)}))
        with pytest.raises(LockError, match=f"PID {sleeper.pid} on host"):
            with collection_lock(tmp_path):
                pass
        assert json.loads(lock.read_text())["pid"] == sleeper.pid  # and left alone
        # ...unless the PID was reused: another start time is another process.
        lock.write_text(json.dumps({"pid": sleeper.pid, "host": host, "process_start": _start_ticks(sleeper.pid) - 1}))
        with collection_lock(tmp_path, notice=notices.append):
            pass
        assert not lock.exists()
    finally:
        sleeper.kill()
        sleeper.wait()


def test_lock_is_released_when_generate_fails(tmp_path, smoke_manifest):
    from metricscenes.generate import generate
    from metricscenes.lock import LockError, collection_lock
    from metricscenes.store import CollectionError

    out = tmp_path / "other"
    (out / "progress").mkdir(parents=True)
    (out / "progress" / "manifest_sha256").write_text("f" * 64 + "\n")
    (out / "progress" / "env000.json").write_text("{}")
    before = _snapshot(out)
    with pytest.raises(CollectionError, match="another manifest"):
        generate(smoke_manifest, out)
    assert not (out / "generate.lock").exists() and _snapshot(out) == before
    with pytest.raises(RuntimeError, match="boom"):
        with collection_lock(out):
            raise RuntimeError("boom")
    assert not (out / "generate.lock").exists()
    with collection_lock(out):  # and can be taken again; a second holder in the same process is refused
        with pytest.raises(LockError, match=f"PID {os.getpid()}"):
            with collection_lock(out):
                pass


# --- benchmark run -----------------------------------------------------------------------
def test_run_out_naming_a_file_is_one_line(tmp_path):
    out = tmp_path / "results.txt"
    out.write_text("precious\n")
    line = _one_line_error(_run("benchmark.cli.main", "run", "--camera", "cam12", "--collection", tmp_path, "--out", out))
    assert "is a file" in line and out.read_text() == "precious\n"


def _nan_yolov8(tmp_path: Path, dynamic: bool) -> Path:
    from test_detectors_errors import write_onnx

    constant = np.full((1, 84, 84), np.nan, dtype=np.float32)
    shape = ["batch", 3, "height", "width"] if dynamic else [1, 3, 64, 64]
    return write_onnx(tmp_path / ("nan-dynamic.onnx" if dynamic else "nan.onnx"), shape, [1, 84, 84], constant)


def test_nan_model_is_refused_not_read_as_no_detections(tmp_path):
    from benchmark.detectors import DetectorError, load_detector

    with pytest.raises(DetectorError) as info:  # a dynamic model: at load, by its probe
        load_detector(_nan_yolov8(tmp_path, dynamic=True))
    assert "\n" not in str(info.value) and "not finite" in str(info.value) and "all" in str(info.value)
    det = load_detector(_nan_yolov8(tmp_path, dynamic=False), input_size=64)  # a static one: on its first image
    with pytest.raises(DetectorError, match="not finite"):
        det.detect([np.zeros((64, 64, 3), np.uint8)])


def _copy(smoke_collection: Path, tmp_path: Path) -> Path:
    root = tmp_path / "collection"
    shutil.copytree(smoke_collection, root)
    return root


def _truncate_a_late_chunk(root: Path) -> None:
    folder = root / "radiance.zarr" / "insets" / "env001-d150m" / "sky_day"
    chunk = next(p for p in folder.rglob("*") if p.is_file() and p.name != "zarr.json")
    chunk.write_bytes(chunk.read_bytes()[:1000])


@pytest.mark.slow
def test_run_on_a_truncated_chunk_leaves_no_partial_images(smoke_collection, tmp_path):
    """The damaged scene is the tenth: the nine images before it are not left behind, and
    a results folder that existed keeps its bytes."""
    root = _copy(smoke_collection, tmp_path)
    _truncate_a_late_chunk(root)
    fresh = tmp_path / "runs" / "fresh"
    line = _one_line_error(_run("benchmark.cli.main", "run", "--camera", "cam12", "--collection", root, "--out", fresh))
    assert "scene env001-d150m" in line and "insets/env001-d150m/sky_day" in line
    assert not (tmp_path / "runs").exists()
    kept = tmp_path / "kept"
    (kept / "images").mkdir(parents=True)
    (kept / "results.json").write_text("{}")
    (kept / "images" / "env000-d025m.png").write_bytes(b"old")
    before = _snapshot(kept)
    _one_line_error(_run("benchmark.cli.main", "run", "--camera", "cam12", "--collection", root, "--out", kept))
    assert _snapshot(kept) == before


@pytest.mark.slow
def test_run_with_a_nan_model_fails_halfway_without_output(smoke_collection, tmp_path):
    out = tmp_path / "out"
    line = _one_line_error(_run("benchmark.cli.main", "run", "--camera", "cam12", "--collection", smoke_collection,
                                "--model", _nan_yolov8(tmp_path, dynamic=False), "--input-size", "64", "--out", out))
    assert "not finite" in line and "nan.onnx" in line
    assert not out.exists()


@pytest.mark.slow
@pytest.mark.parametrize("damage, words", [
    ("empty_groundtruth", "groundtruth.json is not a collection's COCO ground truth"),
    ("missing_root_zarr_json", "radiance.zarr is missing or unreadable"),
])
def test_damaged_collection_files_are_one_line(smoke_collection, tmp_path, damage, words):
    root = _copy(smoke_collection, tmp_path)
    if damage == "empty_groundtruth":
        (root / "groundtruth.json").write_text("{}")
    else:
        (root / "radiance.zarr" / "zarr.json").unlink()
    before = _snapshot(root)
    out = tmp_path / "out"
    line = _one_line_error(_run("benchmark.cli.main", "run", "--camera", "cam12", "--collection", root, "--out", out))
    assert words in line and not out.exists()
    line = _one_line_error(_run("metricscenes.cli", "info", root))
    assert words in line
    assert _snapshot(root) == before


@pytest.mark.slow
def test_generate_takes_over_a_stale_lock_and_leaves_the_collection_identical(smoke_collection, tmp_path):
    root = _copy(smoke_collection, tmp_path)
    dead = subprocess.Popen(["true"])
    dead.wait()
    (root / "generate.lock").write_text(json.dumps({"pid": dead.pid, "host": socket.gethostname()}))
    before = _snapshot(root)
    del before["generate.lock"]
    proc = _run("metricscenes.cli", "generate", "--manifest", SMOKE_MANIFEST, "--out", root)
    assert proc.returncode == 0, proc.stderr
    assert f"taking over the stale lock of PID {dead.pid}" in proc.stderr
    assert _snapshot(root) == before  # lock released, nothing re-rendered


# --- messages that said too little, and a folder of other files ----------------------------
def _fake_benchmark(monkeypatch, tmp_path):
    """`benchmark run` and `sweep` on the fake collection and detector of test_sweep_cache."""
    import benchmark.detectors
    import metricscenes.store
    from test_sweep_cache import FakeCollection, FakeDetector

    monkeypatch.setattr(metricscenes.store.Collection, "open", classmethod(lambda cls, path: FakeCollection(tmp_path)))
    monkeypatch.setattr(benchmark.detectors, "load_detector", lambda model, **kw: FakeDetector(name=model))


def _invoked_one_line(args) -> str:
    from typer.testing import CliRunner

    from benchmark.cli.main import app

    result = CliRunner().invoke(app, [str(a) for a in args])
    assert result.exit_code == 2 and (result.exception is None or isinstance(result.exception, SystemExit)), result.output
    lines = error_lines(result.output)
    assert len(lines) == 1 and lines[0].startswith("error: "), result.output
    return lines[0]


def test_run_and_sweep_on_a_full_disk_name_the_folder_and_the_reason(tmp_path, monkeypatch):
    import errno

    from test_sweep_cache import patch_runs

    def disk_full(*args, **kwargs):
        raise OSError(errno.ENOSPC, "No space left on device")

    _fake_benchmark(monkeypatch, tmp_path)
    patch_runs(monkeypatch, disk_full)
    line = _invoked_one_line(["run", "--camera", "cam01", "--collection", tmp_path, "--out", tmp_path / "r"])
    assert line == f"error: cannot write {tmp_path / 'r'}: No space left on device"
    line = _invoked_one_line(["sweep", "--collection", tmp_path, "--cameras", "cam01", "--conditions", "day",
                              "--out", tmp_path / "s", "--resamples", "20", "--mtf-source", "analytic"])
    assert line == f"error: cannot write {tmp_path / 's'}: No space left on device"
    assert not (tmp_path / "r").exists() and not (tmp_path / "s").exists()


def test_run_out_into_a_folder_of_other_files_is_refused(tmp_path, monkeypatch):
    """As generate refuses the same case: a run would write among the user's files."""
    _fake_benchmark(monkeypatch, tmp_path)
    mine = tmp_path / "mine"
    mine.mkdir()
    (mine / "notes.txt").write_text("kept\n")
    before = _snapshot(mine)
    line = _invoked_one_line(["run", "--camera", "cam01", "--collection", tmp_path, "--out", mine])
    assert f"--out {mine} holds other files (notes.txt) and is not a run folder" in line
    assert _snapshot(mine) == before


def test_also_input_size_into_a_collection_names_its_option(smoke_collection, tmp_path):
    from conftest import require_model

    require_model("yolov5n-dynamic.onnx")
    line = _invoked_one_line(["sweep", "--collection", smoke_collection, "--cameras", "cam12", "--conditions", "day",
                              "--out", tmp_path / "s", "--also-input-size", f"native={smoke_collection}"])
    assert f"--also-input-size {smoke_collection} is the collection" in line and "--out" not in line
    assert not (tmp_path / "s").exists()


def test_score_refuses_boxes_that_are_not_finite(tmp_path):
    from synthetic_scoring import synthetic_collection

    gt, dets = synthetic_collection(n_environments=4, seed=3)
    (tmp_path / "groundtruth.json").write_text(json.dumps(gt))
    for bad in ([float("nan"), 1.0, 2.0, 3.0], [1.0, 1.0, float("inf"), 3.0], [1.0, 1.0, -5.0, 3.0]):
        dets[7]["bbox"] = bad
        (tmp_path / "detections.json").write_text(json.dumps(dets))
        line = _invoked_one_line(["score", tmp_path])
        assert f"detection 7 (image {dets[7]['image_id']}): bbox" in line and "must be four finite numbers" in line


@pytest.mark.slow
def test_a_symlinked_array_folder_is_named_with_the_reason(smoke_collection, tmp_path):
    """generate rewrites a damaged array by removing its folder, which zarr cannot do through
    a symbolic link: the line named neither ("cannot write …: OSError")."""
    root = _copy(smoke_collection, tmp_path)
    array = root / "radiance.zarr" / "plates" / "env000" / "sky_day"
    shutil.move(array, tmp_path / "elsewhere")
    array.symlink_to(tmp_path / "elsewhere", target_is_directory=True)
    chunk = next(p for p in (tmp_path / "elsewhere").rglob("*") if p.is_file() and p.name != "zarr.json")
    chunk.write_bytes(chunk.read_bytes()[:100])  # damaged: rendered again
    proc = _run("metricscenes.cli", "generate", "--manifest", SMOKE_MANIFEST, "--out", root)
    assert proc.returncode == 2 and "Traceback" not in proc.stderr, proc.stderr
    errors = [line for line in error_lines(proc.stderr) if not line.startswith("rendering ")]  # (its notice first)
    assert len(errors) == 1 and errors[0].startswith("error: "), proc.stderr
    assert "radiance.zarr/plates/env000/sky_day is a symbolic link" in errors[0] and "remove the link" in errors[0]
