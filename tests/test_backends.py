"""Backends and the render variant: `generate` and `benchmark sweep`
write the same bytes in this process, on a process pool and on a dask LocalCluster;
``render.variant: auto`` is resolved, recorded and kept on resume; a ``--scheduler`` that
cannot be used is one line before anything is written."""

from __future__ import annotations

import json
import shutil
import sys
from pathlib import Path

import pytest
import yaml
from typer.testing import CliRunner

from conftest import SMOKE_MANIFEST, model_dir, require_model
from metricscenes import backends
from metricscenes.backends import BackendError, check_scheduler, map_units
from test_sweep_cli import fakes  # noqa: F401 (a fixture)

# Two environments (the bootstrap's minimum) at two distances, a 96 x 54 grid, daylight only:
# 6 units of about half a second, so that three renders and two sweeps stay short.
TINY = {**yaml.safe_load(SMOKE_MANIFEST.read_text()), "name": "tiny", "environments": 2, "distances_m": [50, 150],
        "reference_grid": {"width_px": 96, "height_px": 54},
        "render": {"plate_spp": 4, "inset_spp": 4, "inset_pixel_mrad": 0.5, "inset_max_px": 64, "max_depth": 3,
                   "variant": "auto"},
        "light_groups": ["sky_day"], "conditions": {"day": {"sky_day": 1.0}}}
del TINY["illuminance_sweep"]


def _auto_here() -> str:
    """What ``auto`` must resolve to on this machine, found by probing each variant in turn:
    CUDA where a device renders, else LLVM where a libLLVM >= 17 renders, else scalar."""
    from metricscenes.render import RenderError, check_variant

    for variant in ("cuda_ad_spectral", "llvm_ad_spectral"):
        try:
            check_variant(variant)
            return variant
        except RenderError:
            pass
    return "scalar_spectral"


@pytest.fixture(scope="module")
def tiny_manifest_file(tmp_path_factory) -> Path:
    path = tmp_path_factory.mktemp("tiny") / "tiny.yaml"
    path.write_text(yaml.safe_dump(TINY, sort_keys=False))
    return path


@pytest.fixture(scope="module")
def serial_collection(tiny_manifest_file, tmp_path_factory) -> Path:
    """The tiny collection rendered in this process (``--workers 1``)."""
    from metricscenes.generate import generate
    from metricscenes.manifest import load_manifest

    return generate(load_manifest(tiny_manifest_file), tmp_path_factory.mktemp("serial") / "c", workers=1)


# --- generate ------------------------------------------------------------------------------
@pytest.mark.slow
@pytest.mark.parametrize("options", [["--workers", "2"], ["--scheduler", "local", "--workers", "2"]],
                         ids=["process-pool", "dask-local"])
def test_generate_bytes_do_not_depend_on_the_backend(serial_collection, tiny_manifest_file, tmp_path, options):
    from metricscenes.cli import app

    out = tmp_path / "c"
    result = CliRunner().invoke(app, ["generate", "--manifest", str(tiny_manifest_file), "--out", str(out), *options])
    assert result.exit_code == 0, result.output
    for name in ("manifest.resolved.yaml", "groundtruth.json"):  # every array's sha256, the boxes, the variant
        assert (out / name).read_bytes() == (serial_collection / name).read_bytes(), name


@pytest.mark.slow
def test_auto_variant_is_resolved_recorded_and_kept_on_resume(serial_collection, tmp_path):
    from metricscenes.generate import generate
    from metricscenes.manifest import parse_manifest
    from metricscenes.store import CollectionError

    resolved = yaml.safe_load((serial_collection / "manifest.resolved.yaml").read_text())
    assert resolved["manifest"]["render"]["variant"] == "auto"
    assert resolved["render_variant"] == _auto_here()
    assert (serial_collection / "progress" / "render_variant").read_text().strip() == resolved["render_variant"]
    # The same manifest resumed where `auto` means another variant: refused, nothing touched.
    copy = shutil.copytree(serial_collection, tmp_path / "c")
    other = "scalar_spectral" if resolved["render_variant"] != "scalar_spectral" else "llvm_ad_spectral"
    (copy / "progress" / "render_variant").write_text(f"{other}\n")
    before = {p: p.read_bytes() for p in sorted(copy.rglob("*")) if p.is_file()}
    with pytest.raises(CollectionError, match=f"rendered with Mitsuba variant {other}") as refused:
        generate(parse_manifest(TINY), copy)
    assert "\n" not in str(refused.value)
    assert {p: p.read_bytes() for p in sorted(copy.rglob("*")) if p.is_file()} == before


def test_auto_variant_is_a_value_not_the_default():
    """(The default stays scalar_spectral: it is part of every manifest's sha256, which
    protocols.yaml pins; tests/test_leaderboard_submit.py checks those hashes.)"""
    from metricscenes.manifest import parse_manifest
    from metricscenes.render import resolve_variant

    assert parse_manifest(TINY).render.variant == "auto"
    default = {**TINY, "render": {k: v for k, v in TINY["render"].items() if k != "variant"}}
    assert parse_manifest(default).render.variant == "scalar_spectral"
    assert resolve_variant("auto") == _auto_here()


# --- benchmark sweep -----------------------------------------------------------------------
def _sweep_files(folder: Path) -> dict[str, bytes]:
    """Every file of a sweep folder, results.json without its wall-clock ``timing_s``."""
    files = {}
    for path in sorted(p for p in folder.rglob("*") if p.is_file()):
        data = path.read_bytes()
        if path.name == "results.json":
            results = json.loads(data)
            results.pop("timing_s")
            data = json.dumps(results).encode()
        files[str(path.relative_to(folder))] = data
    return files


def sweep_serial_and_pooled(collection, condition: str, tmp_path: Path):
    """Two small cameras of different f-numbers (fast) swept under ``condition`` with one and
    with two workers, into ``tmp_path/serial`` and ``tmp_path/pooled``: (cameras, the two tables)."""
    from benchmark.camera import load_camera
    from benchmark.detectors import load_detector
    from benchmark.experiments.sweep import sweep

    spec = tmp_path / "small.yaml"
    spec.write_text("name: small\noptics: {f_number: 2.0}\nsensor: {pixel_um: 11.2}\n")
    twin = tmp_path / "small-f4.yaml"
    twin.write_text("name: small-f4\noptics: {f_number: 4.0}\nsensor: {pixel_um: 8.4}\n")
    cameras = [load_camera(spec), load_camera(twin)]
    detector = load_detector("yolov5n-dynamic", input_size="native", model_dir=model_dir())
    options = dict(n_resamples=20, mtf_source="analytic")
    serial = sweep(collection, cameras, [condition], detector, tmp_path / "serial", **options)
    pooled = sweep(collection, cameras, [condition], detector, tmp_path / "pooled", workers=2, **options)
    return cameras, serial, pooled


def _small_cameras(folder: Path) -> list:
    """Two cameras of 240 x 135 and 320 x 180 px: a sweep of the tiny collection in seconds."""
    from benchmark.camera import load_camera

    cameras = []
    for name, f_number, pixel_um in (("small-a", 2.0, 11.2), ("small-b", 4.0, 8.4)):
        spec = folder / f"{name}.yaml"
        spec.write_text(f"name: {name}\noptics: {{f_number: {f_number}}}\nsensor: {{pixel_um: {pixel_um}}}\n")
        cameras.append(load_camera(spec))
    return cameras


@pytest.mark.slow
def test_sweep_bytes_do_not_depend_on_the_workers(serial_collection, tmp_path):
    require_model("yolov5n-dynamic.onnx")
    from benchmark.detectors import load_detector
    from benchmark.experiments.sweep import sweep

    cameras = _small_cameras(tmp_path)
    detector = load_detector("yolov5n-dynamic", input_size="native", model_dir=model_dir())
    options = dict(n_resamples=20, mtf_source="analytic")
    serial = sweep(serial_collection, cameras, ["day"], detector, tmp_path / "serial", **options)
    pooled = sweep(serial_collection, cameras, ["day"], detector, tmp_path / "pooled", workers=2, **options)
    assert serial.equals(pooled)
    files = _sweep_files(tmp_path / "serial")
    assert any(name.endswith(".png") for name in files) and "runs/small-b-day/od50.json" in files
    assert _sweep_files(tmp_path / "pooled") == files


@pytest.mark.slow
def test_cameras_run_together_write_what_each_writes_alone(serial_collection, tmp_path, monkeypatch):
    """run_cameras reads each scene once and resamples it once per pixel grid (small-a and its
    f/4 twin share one): every camera's files are those of its own run_camera, byte for byte."""
    require_model("yolov5n-dynamic.onnx")
    from benchmark.camera import load_camera
    from benchmark.detectors import load_detector
    from benchmark.experiments import run as run_module
    from metricscenes.radiance import SpectralScene
    from metricscenes.store import Collection

    twin = tmp_path / "small-a-f4.yaml"
    twin.write_text("name: small-a-f4\noptics: {f_number: 4.0}\nsensor: {pixel_um: 11.2}\n")
    cameras = [*_small_cameras(tmp_path), load_camera(twin)]
    detector = load_detector("yolov5n-dynamic", input_size="native", model_dir=model_dir())
    collection = Collection.open(serial_collection)
    alone = [run_module.run_camera(collection, c, "day", detector, tmp_path / "alone" / c.name) for c in cameras]
    composites = []
    original = SpectralScene.resample

    def counted(scene, cols, rows, extent=None):
        composites.append((id(scene), cols, rows, scene._last_resample.get((cols, rows, (extent or scene.extent).as_tuple())) is None))
        return original(scene, cols, rows, extent)

    monkeypatch.setattr(SpectralScene, "resample", counted)
    together = run_module.run_cameras(collection, cameras, "day", detector, [tmp_path / "together" / c.name for c in cameras])
    assert [r.detections_sha256 for r in together] == [r.detections_sha256 for r in alone]
    for camera in cameras:
        assert _sweep_files(tmp_path / "together" / camera.name) == _sweep_files(tmp_path / "alone" / camera.name)
    n_scenes = len(collection.scenes())
    grids = {(c.width_px, c.height_px) for c in cameras}
    composites = [c for c in composites if c[1:3] in grids]  # (not the MTF target's, measured for results.json)
    assert len(composites) == 3 * n_scenes and len({scene for scene, *_ in composites}) == n_scenes  # one read a scene
    assert sum(computed for *_, computed in composites) == 2 * n_scenes  # two grids: the twin's is reused


@pytest.mark.slow
def test_a_sweep_on_another_sweeps_captures_detects_the_same(serial_collection, tmp_path, monkeypatch):
    """--captures-from: a 640 sweep that detects on a native sweep's images writes what a 640
    sweep that simulates the cameras writes, without simulating them; a capture of another
    seed is not taken, and an image whose bytes are not those its run recorded is a one-line error."""
    require_model("yolov5n-dynamic.onnx")
    from benchmark.detectors import load_detector
    from benchmark.experiments import run as run_module
    from benchmark.experiments.sweep import sweep
    from metricscenes.store import Collection

    cameras = _small_cameras(tmp_path)
    options = dict(n_resamples=20, mtf_source="analytic")
    native = load_detector("yolov5n-dynamic", input_size="native", model_dir=model_dir())
    at_640 = load_detector("yolov5n-dynamic", input_size=640, model_dir=model_dir())
    sweep(serial_collection, cameras, ["day"], native, tmp_path / "native", **options)
    fresh = sweep(serial_collection, cameras, ["day"], at_640, tmp_path / "fresh", **options)

    def no_camera(*args, **kwargs):
        raise AssertionError("the camera was simulated")

    monkeypatch.setattr("benchmark.camera.pipeline.simulate", no_camera)
    reused = sweep(serial_collection, cameras, ["day"], at_640, tmp_path / "reused", captures_from=tmp_path / "native",
                   **options)
    assert reused.equals(fresh)
    files = _sweep_files(tmp_path / "reused")
    for name in [n for n in files if n.endswith("results.json")]:
        results = json.loads(files.pop(name))
        assert results.pop("captures_from") == str(tmp_path / "native" / Path(name).parent)
        assert json.loads(_sweep_files(tmp_path / "fresh")[name]) == results
    assert {k: v for k, v in _sweep_files(tmp_path / "fresh").items() if not k.endswith("results.json")} == files

    collection = Collection.open(serial_collection)
    with pytest.raises(ValueError, match="another camera, condition, collection or seed"):
        run_module.read_captures(tmp_path / "native" / "runs" / "small-a-day", cameras[0], "day", collection, seed=1)
    image = next((tmp_path / "native" / "runs" / "small-a-day" / "images").iterdir())
    image.write_bytes(image.read_bytes()[:100])
    with pytest.raises(ValueError, match=r"^captures .*: its bytes changed since its run wrote it"):
        run_module.run_camera(collection, cameras[0], "day", at_640, tmp_path / "damaged",
                              captures=tmp_path / "native" / "runs" / "small-a-day")
    assert not (tmp_path / "damaged").exists()
    with pytest.raises(ValueError, match="is the sweep folder itself"):
        sweep(serial_collection, cameras, ["day"], at_640, tmp_path / "native", captures_from=tmp_path / "native")


@pytest.mark.slow
def test_a_multiscale_sweep_also_writes_the_sweeps_of_its_passes(serial_collection, tmp_path, monkeypatch):
    """--also-input-size: a multiscale sweep also writes the native and 640 sweeps its two
    passes make, file for file what sweeps at those input sizes write (``timing_s`` aside),
    with one inference per pass and image; a run missing from one folder is made again; a size
    that is not one of the detector's passes is refused before anything is written."""
    require_model("yolov5n-dynamic.onnx")
    from benchmark.detectors import load_detector
    from benchmark.detectors.onnx_detector import OnnxDetector
    from benchmark.experiments.sweep import sweep
    from metricscenes.store import Collection

    cameras = _small_cameras(tmp_path)
    options = dict(n_resamples=20, mtf_source="analytic")
    detectors = {size: load_detector("yolov5n-dynamic", input_size=size, model_dir=model_dir())
                 for size in ("multiscale", "native", 640)}
    for size, detector in detectors.items():
        sweep(serial_collection, cameras, ["day"], detector, tmp_path / f"alone-{size}", **options)
    passes = []
    original = OnnxDetector._pass
    monkeypatch.setattr(OnnxDetector, "_pass", lambda self, images, p, *a: passes.append(p) or original(self, images, p, *a))
    also = {"native": tmp_path / "also-native", 640: tmp_path / "also-640"}
    table = sweep(serial_collection, cameras, ["day"], detectors["multiscale"], tmp_path / "also-multiscale",
                  also=also, **options)
    assert len(passes) == 2 * len(cameras) * len(Collection.open(serial_collection).scenes())
    for size in detectors:
        assert _sweep_files(tmp_path / f"also-{size}") == _sweep_files(tmp_path / f"alone-{size}"), size
    image = next((tmp_path / "also-640" / "runs" / "small-b-day" / "images").iterdir())  # linked, not copied
    assert image.stat().st_ino == (tmp_path / "also-multiscale" / "runs" / "small-b-day" / "images" / image.name).stat().st_ino
    assert len(table) == len(cameras) * 2  # (two distances)

    shutil.rmtree(tmp_path / "also-640" / "runs" / "small-a-day")  # (a folder lost: its camera's runs made again)
    sweep(serial_collection, cameras, ["day"], detectors["multiscale"], tmp_path / "also-multiscale", also=also, **options)
    again, alone = _sweep_files(tmp_path / "also-640"), _sweep_files(tmp_path / "alone-640")
    assert [r["reused"] for r in json.loads(again.pop("sweep.json"))["runs"]] == [False, True]
    alone.pop("sweep.json")
    assert again == alone

    for size, detector, message in ((320, detectors["multiscale"], "input size 320 is not a pass"),
                                    (640, detectors["native"], "its passes: one, its own")):
        with pytest.raises(ValueError, match=message):
            sweep(serial_collection, cameras, ["day"], detector, tmp_path / "refused", also={size: tmp_path / "x"},
                  **options)
    assert not (tmp_path / "refused").exists() and not (tmp_path / "x").exists()
    with pytest.raises(ValueError, match="another of this sweep's folders"):
        sweep(serial_collection, cameras, ["day"], detectors["multiscale"], tmp_path / "also-multiscale",
              also={640: tmp_path / "also-multiscale"}, **options)


@pytest.mark.slow
def test_a_run_killed_midway_resumes_at_its_next_scene_with_the_same_bytes(serial_collection, tmp_path):
    """A run interrupted after two scenes keeps its stage; the next run of the same camera,
    condition, detector and seed takes it up (simulating only the scenes left) and writes the
    files an uninterrupted run writes, a line cut by a kill included; another detector's run
    does not take it up."""
    require_model("yolov5n-dynamic.onnx")
    from benchmark.detectors import load_detector
    from benchmark.experiments import run as run_module
    from benchmark.experiments.keys import resume_key
    from metricscenes.store import Collection

    collection = Collection.open(serial_collection)
    camera = _small_cameras(tmp_path)[0]
    detector = load_detector("yolov5n-dynamic", input_size="multiscale", model_dir=model_dir())
    run_module.run_camera(collection, camera, "day", detector, tmp_path / "wholerun")

    class Interrupted:  # the detector, stopped by Ctrl-C at its third scene
        def __init__(self, calls):
            self.calls = calls

        def __getattr__(self, name):
            return getattr(detector, name)

        def detect(self, images, **kwargs):
            return self.detect_policies(images, **kwargs)[detector.input_size]

        def detect_policies(self, images, *args, **kwargs):
            self.calls.append(1)
            if len(self.calls) == 3:
                raise KeyboardInterrupt
            return detector.detect_policies(images, *args, **kwargs)

    out = tmp_path / "stopped"
    with pytest.raises(KeyboardInterrupt):
        run_module.run_camera(collection, camera, "day", Interrupted([]), out)
    stage = out / run_module.RESUMABLE_STAGE
    assert len((stage / run_module.CHECKPOINT).read_text().splitlines()) == 2 and not (out / "results.json").exists()
    with open(stage / run_module.CHECKPOINT, "a") as f:
        f.write('{"scene_id": "env001-d')  # a kill in the middle of the third line
    simulated = []
    original = run_module._CameraRun.add

    def add(self, scene, *args):
        if scene.scene_id not in self.done:
            simulated.append(scene.scene_id)
        original(self, scene, *args)

    with pytest.MonkeyPatch.context() as patch:
        patch.setattr(run_module._CameraRun, "add", add)
        counts = []
        run_module.run_camera(collection, camera, "day", detector, out, progress=lambda d, t: counts.append(d))
    assert len(simulated) == len(collection.scenes()) - 2
    assert counts == list(range(2, len(collection.scenes()) + 1))  # the two found done at once, then each made
    assert _sweep_files(out) == _sweep_files(tmp_path / "wholerun") and not stage.exists()

    # With a pass's run beside it: its stage lost, the camera's scenes are all made again.
    sibling = {640: [tmp_path / "stopped-640"]}
    with pytest.raises(KeyboardInterrupt):
        run_module.run_cameras(collection, [camera], "day", Interrupted([]), [out], also=sibling)
    shutil.rmtree(tmp_path / "stopped-640" / run_module.RESUMABLE_STAGE)
    simulated.clear()
    with pytest.MonkeyPatch.context() as patch:
        patch.setattr(run_module._CameraRun, "add", add)
        run_module.run_cameras(collection, [camera], "day", detector, [out], also=sibling)
    assert len(simulated) == len(collection.scenes()) and _sweep_files(out) == _sweep_files(tmp_path / "wholerun")

    with pytest.raises(KeyboardInterrupt):
        run_module.run_camera(collection, camera, "day", Interrupted([]), tmp_path / "other")
    at_640 = load_detector("yolov5n-dynamic", input_size=640, model_dir=model_dir())
    stage, resumed = run_module.resumable_stage(tmp_path / "other", resume_key(
        camera, "day", collection, 0, [at_640], True, None))
    assert not resumed and not (stage / run_module.CHECKPOINT).exists()  # another detector's scenes: begun again


# --- the backends themselves ---------------------------------------------------------------
def test_map_units_gives_every_result_whatever_the_backend():
    units = [(2, n) for n in range(5)]
    assert list(map_units(pow, units)) == [1, 2, 4, 8, 16]  # in this process: in order
    assert sorted(map_units(pow, units, workers=2)) == [1, 2, 4, 8, 16]  # as they finish
    with pytest.raises(ValueError, match="invalid literal"):  # a unit's error, raised in the client
        list(map_units(int, [("12",), ("twelve",)], workers=2))


@pytest.mark.parametrize("address", ["tcp://example.org", "http://example.org:8786", "tcp://host:99999", "tcp://:8786",
                                     "locale", ""])
def test_a_malformed_scheduler_is_one_line(address):
    with pytest.raises(BackendError, match="expected 'local' or a dask scheduler address") as refused:
        check_scheduler(address)
    assert "\n" not in str(refused.value)


def test_missing_dask_is_one_line(monkeypatch):
    monkeypatch.setitem(sys.modules, "distributed", None)  # import distributed -> ImportError
    with pytest.raises(BackendError, match=r"pip install 'metricscenes\[dask\]'"):
        check_scheduler("local")


def test_a_local_cluster_that_times_out_is_one_line_not_an_unwritable_output(monkeypatch):
    # a loaded machine: dask's LocalCluster timed out closing after every unit was written, and
    # the CLI reported the TimeoutError (an OSError) as "cannot write <out>"
    import distributed

    class SlowToClose:
        def __init__(self, *args, **kwargs):
            pass

        def __enter__(self):
            return self

        def __exit__(self, *exc):
            raise TimeoutError("cluster did not close in 30 s")

    monkeypatch.setattr(distributed, "LocalCluster", SlowToClose)
    monkeypatch.setattr(distributed, "Client", SlowToClose)
    with pytest.raises(BackendError, match="local: dask timed out .*run the same command again") as refused:
        with backends._dask_client("local", 2):
            pass
    assert "\n" not in str(refused.value)


def _closed_port() -> int:
    import socket

    with socket.socket() as s:
        s.bind(("127.0.0.1", 0))
        return s.getsockname()[1]


def test_unreachable_scheduler_is_one_line_before_any_output(tmp_path, monkeypatch):
    from metricscenes.cli import app

    monkeypatch.setattr(backends, "CONNECT_TIMEOUT_S", 0.5)
    address = f"tcp://127.0.0.1:{_closed_port()}"
    out = tmp_path / "c"
    result = CliRunner().invoke(app, ["generate", "--manifest", str(SMOKE_MANIFEST), "--out", str(out),
                                      "--scheduler", address])
    assert result.exit_code == 2 and "Traceback" not in result.output
    lines = [line for line in result.output.splitlines() if line.strip()]
    assert len(lines) == 1 and lines[0].startswith("error: ") and f"{address}: no dask scheduler answers" in lines[0]
    assert not out.exists()


def test_sweep_refuses_an_unusable_scheduler_in_one_line(fakes, monkeypatch):  # noqa: F811
    from benchmark.cli.main import app

    monkeypatch.setattr(backends, "CONNECT_TIMEOUT_S", 0.5)
    for address, message in ((f"tcp://127.0.0.1:{_closed_port()}", "no dask scheduler answers"),
                             ("tcp://nowhere", "expected 'local'")):
        result = CliRunner().invoke(app, ["sweep", "--collection", str(fakes), "--cameras", "cam01",
                                          "--out", str(fakes / "sw"), "--scheduler", address])
        assert result.exit_code == 2 and "Traceback" not in result.output
        assert len([line for line in result.output.splitlines() if line.strip()]) == 1 and message in result.output
        assert not (fakes / "sw").exists()


def test_an_image_a_killed_run_had_begun_is_replaced_not_written_through(tmp_path):
    """Resuming, a scene whose image a killed run had already linked (or copied) is linked
    again: a target that is the source itself (a hard link) or a stale file is replaced."""
    from benchmark.experiments.run import link_or_copy

    source, target, other = tmp_path / "source.png", tmp_path / "target.png", tmp_path / "other.png"
    source.write_bytes(b"new image")
    link_or_copy(source, target)
    link_or_copy(source, target)  # already a link to the source: no SameFileError
    assert target.read_bytes() == b"new image" and target.stat().st_ino == source.stat().st_ino
    other.write_bytes(b"old image")
    link_or_copy(other, target)  # a stale target: replaced, the old source untouched
    assert target.read_bytes() == b"old image" and source.read_bytes() == b"new image"
