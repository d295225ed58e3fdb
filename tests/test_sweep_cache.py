"""benchmark.experiments.sweep: table shape, run cache, resume, OD50 table — with a fake run_camera.

The fake writes what :func:`benchmark.experiments.run.run_camera` writes (results.json last,
detections, scaled ground truth, images) from the seeded synthetic detector of
``synthetic_scoring``, whose range grows as the pixel shrinks and halves at
night, so no rendering or detector is needed. ``tests/test_report_html.py`` reuses it.
"""

from __future__ import annotations

import json
from dataclasses import dataclass
from pathlib import Path

import numpy as np
import pandas as pd
import pytest

from benchmark.experiments import sweep as sweep_module
from benchmark.camera import load_camera
from benchmark.scoring import ap_by_distance, bootstrap_od50
from synthetic_scoring import synthetic_collection

N_ENV = 4


@dataclass(frozen=True)
class FakeScene:
    scene_id: str
    image_id: int
    environment_id: int
    distance_m: float


class FakeCollection:
    """Duck-typed :class:`metricscenes.store.Collection` over the synthetic ground truth."""

    def __init__(self, root: Path, manifest_sha256: str = "f" * 64):
        self.root, self.name, self.protocol, self.manifest_sha256 = Path(root), "fake", "fake", manifest_sha256
        self.conditions = {"day": {"sky_day": 1.0}, "night": {"sky_night": 1.0}}
        self.condition_names = [*self.conditions, "day@1lux", "day@100lux"]  # an illuminance sweep
        self._gt, _ = synthetic_collection(N_ENV, seed=1)

    def scenes(self):
        return [FakeScene(im["scene_id"], im["id"], im["environment_id"], im["distance_m"]) for im in self._gt["images"]]

    def groundtruth(self):
        return json.loads(json.dumps(self._gt))

    def condition_record(self, scene_id, condition):  # fixed-weight conditions only
        return None

    def check_condition(self, condition):  # every light group is held
        if condition not in self.condition_names:
            raise ValueError(f"unknown condition {condition!r}")


class BlankCollection(FakeCollection):
    """A FakeCollection for the real run_camera with ``simulate`` replaced: no radiance."""

    def radiance(self, scene_id, condition, inset_resolution="car"):
        return None


class BlankCapture:
    """What a replaced ``simulate`` returns: a black 8 x 8 image."""

    rgb8 = np.zeros((8, 8, 3), np.uint8)
    exposure_s, exposure_short_s = 1e-3, None


class BlindDetector:
    """A detector that finds nothing (fast)."""

    name, family, sha256, input_size = "none", "none", "0" * 64, "native"

    def detect(self, images, **kw):
        return [[] for _ in images]


@dataclass
class FakeDetector:
    name: str = "fake-yolo"
    family: str = "yolov5"
    sha256: str = "d" * 64
    input_size: str = "multiscale"


def synthetic_detections(gt: dict, half_range_m: float, seed: int) -> list[dict]:
    """A seeded fake detector: finds the car with probability 1 / (1 + (d / half_range)^4),
    box jitter and score worsening with distance, plus one false positive per image."""
    dets = []
    for ann in gt["annotations"]:
        im = next(i for i in gt["images"] if i["id"] == ann["image_id"])
        rng = np.random.default_rng([seed, im["id"]])
        hardness = im["distance_m"] / half_range_m
        x, y, w, h = ann["bbox"]
        if rng.uniform() < 1.0 / (1.0 + hardness**4):
            j = rng.normal(0.0, 0.05 * hardness, 4)
            dets.append({"image_id": im["id"], "category_id": 3, "bbox": [x + j[0] * w, y + j[1] * h, w * np.exp(j[2]), h * np.exp(j[3])],
                         "score": float(rng.uniform(0.5, 1.0) / (1 + hardness))})
        dets.append({"image_id": im["id"], "category_id": 3, "bbox": [*rng.uniform(0, 0.5, 2) * [im["width"], im["height"]], 20.0, 10.0],
                     "score": float(rng.uniform(0.01, 0.3))})
    return dets


def fake_run_camera(collection, camera, condition, detector, out_dir, *, seed=0, save_images=True,
                    backend="faster-coco-eval", progress=None, captures=None):
    """Writes the files of a real run; detections from the synthetic detector (it simulates every
    camera, so ``captures`` must be None)."""
    assert captures is None, "fake_run_camera does not read another sweep's captures"
    from PIL import Image, ImageDraw

    from benchmark.experiments.collection_view import COMPOSITE
    from benchmark.experiments.run import sha256_bytes
    from benchmark.result_files import RunResults, write_results
    from metricscenes.groundtruth import scale_groundtruth

    out_dir = Path(out_dir)
    (out_dir / "images").mkdir(parents=True, exist_ok=True)
    light = {"day": 1.0, "night": 0.5, "day@1lux": 0.3, "day@100lux": 0.9}[condition]
    half_range = 400.0 / camera.pixel_um * light
    gt = scale_groundtruth(collection.groundtruth(), camera.width_px, camera.height_px)
    dets = synthetic_detections(gt, half_range, seed)
    scenes = collection.scenes()
    boxes = {a["image_id"]: a["bbox"] for a in gt["annotations"]}
    for i, scene in enumerate(scenes):
        if save_images:
            img = Image.new("RGB", (camera.width_px, camera.height_px), (90, 110, 90) if condition == "day" else (10, 10, 20))
            x, y, w, h = boxes[scene.image_id]
            ImageDraw.Draw(img).rectangle([x, y, x + w, y + h], fill=(200, 40, 40))
            img.save(out_dir / "images" / f"{scene.scene_id}.png", compress_level=1)
        if progress:
            progress(i + 1, len(scenes))
    per_distance = ap_by_distance(gt, dets, backend=backend)
    data = json.dumps(dets).encode()
    results = RunResults.model_validate({
        "camera": {"name": camera.name, "pixel_um": camera.pixel_um, "f_number": camera.f_number,
                   "width_px": camera.width_px, "height_px": camera.height_px, "spec_sha256": camera.sha256()},
        "condition": condition,
        "detector": {"name": detector.name, "sha256": detector.sha256, "input_size": detector.input_size},
        "collection": {"name": collection.name, "manifest_sha256": collection.manifest_sha256, "path": str(collection.root)},
        "seed": seed, "scoring_backend": backend, "per_distance": per_distance, "od50_m": None,
        "detections_sha256": sha256_bytes(data), "composite": COMPOSITE,
    })
    (out_dir / "detections.json").write_bytes(data)
    (out_dir / "groundtruth.json").write_text(json.dumps(gt))
    write_results(out_dir / "results.json", results)
    return results


def run_cameras_one_by_one(collection, cameras, condition, detector, out_dirs, *, captures=None, **kwargs):
    """``run_cameras`` as a loop over ``benchmark.experiments.run.run_camera`` (looked up when
    called), so that a test's fake ``run_camera`` stands for every camera a sweep groups."""
    from benchmark.experiments import run as run_module

    captures = captures or [None] * len(cameras)
    assert not kwargs.pop("also", None), "the fake runs write no pass policies' runs"
    progress = kwargs.pop("progress", None)  # scenes of the whole group: the last camera reports them
    return [run_module.run_camera(collection, camera, condition, detector, out_dir, captures=c,
                                  progress=progress if k == len(cameras) - 1 else None, **kwargs)
            for k, (camera, out_dir, c) in enumerate(zip(cameras, out_dirs, captures))]


def patch_runs(monkeypatch, run) -> None:
    """Every run of a sweep goes to ``run`` (a fake ``run_camera``)."""
    monkeypatch.setattr("benchmark.experiments.run.run_camera", run)
    monkeypatch.setattr("benchmark.experiments.run.run_cameras", run_cameras_one_by_one)


class CountingRun:
    """fake_run_camera that counts its calls and can die after ``die_after`` calls."""

    def __init__(self, die_after: int | None = None):
        self.calls: list[tuple[str, str]] = []
        self.die_after = die_after

    def __call__(self, collection, camera, condition, *args, **kwargs):
        if self.die_after is not None and len(self.calls) >= self.die_after:
            raise KeyboardInterrupt("killed")
        self.calls.append((camera.name, condition))
        return fake_run_camera(collection, camera, condition, *args, **kwargs)


CAMERAS = ("cam01", "cam12")


def make_fake_sweep(out: Path, monkeypatch, *, run=None, cameras=CAMERAS, conditions=("day", "night"), **kw):
    """A sweep folder from the fake runs (public helper for the report tests)."""
    patch_runs(monkeypatch, run or fake_run_camera)
    kw.setdefault("n_resamples", 50)
    kw.setdefault("mtf_source", "analytic")
    kw.setdefault("save_images", False)  # the report tests ask for them
    table = sweep_module.sweep(FakeCollection(out.parent), [load_camera(c) for c in cameras], list(conditions),
                               FakeDetector(), out, **kw)
    return table


def test_table_shape_and_columns(tmp_path, monkeypatch):
    events = []
    table = make_fake_sweep(tmp_path / "sw", monkeypatch, progress=lambda d, t, label: events.append((d, t)))
    assert list(table.columns) == sweep_module.TABLE_COLUMNS
    assert len(table) == len(CAMERAS) * 2 * 6  # cameras × conditions × distances
    assert set(table["camera"]) == set(CAMERAS) and set(table["condition"]) == {"day", "night"}
    assert (table["n_images"] == N_ENV).all()
    assert table["mtf50_source"].eq("analytic").all()
    # the analytic MTF50 of the smaller pixel (cam12, 1.4 um f/1.9) is the higher
    mtf = table.groupby("camera")["mtf50_cy_per_mm"].first()
    assert mtf["cam12"] > mtf["cam01"]
    on_disk = pd.read_csv(tmp_path / "sw" / "sweep.csv")
    pd.testing.assert_frame_equal(on_disk, table, check_dtype=False)
    meta = json.loads((tmp_path / "sw" / "sweep.json").read_text())
    assert len(meta["table"]) == len(table) and meta["cameras"] == list(CAMERAS)
    total = len(CAMERAS) * 2 * 6 * N_ENV
    assert events[0] == (0, total) and events[-1] == (total, total)
    assert all(a[0] <= b[0] for a, b in zip(events, events[1:]))
    again = []  # every run cached: reported at once (a log estimates the time left from the runs after it)
    make_fake_sweep(tmp_path / "sw", monkeypatch, progress=lambda d, t, label: again.append((d, t, label)))
    assert again == [(total, total, f"{len(CAMERAS) * 2} runs cached")]


def test_od50_table_matches_bootstrap(tmp_path, monkeypatch):
    make_fake_sweep(tmp_path / "sw", monkeypatch, n_resamples=40, seed=3)
    od = pd.read_csv(tmp_path / "sw" / "od50.csv")
    assert list(od.columns) == sweep_module.OD50_COLUMNS and len(od) == 4
    run = tmp_path / "sw" / "runs" / "cam01-day"
    oracle = bootstrap_od50(json.loads((run / "groundtruth.json").read_text()),
                            json.loads((run / "detections.json").read_text()), n_resamples=40, seed=3)
    row = od[(od.camera == "cam01") & (od.condition == "day")].iloc[0]
    assert row.od50_m == pytest.approx(oracle.od50_m)
    assert row.sd_m == pytest.approx(oracle.sd_m)
    assert (row.ci95_lo_m, row.ci95_hi_m) == pytest.approx(oracle.ci95_m)
    assert row.n_resamples == 40 and row.n_environments == N_ENV
    assert (row.ap_range_m, row.ap_range_sd_m) == pytest.approx((oracle.ap_range_m, oracle.ap_range_sd_m))
    assert (row.ap_range_ci95_lo_m, row.ap_range_ci95_hi_m) == pytest.approx(oracle.ap_range_ci95_m)


def test_od50_cache_without_ap_range_is_computed_again(tmp_path, monkeypatch):
    """An od50.json written before the AP range (same key) is not reused: its AP range is missing
    and its intervals predate the point-inside rule."""
    make_fake_sweep(tmp_path / "sw", monkeypatch, n_resamples=40)
    run = tmp_path / "sw" / "runs" / "cam01-day"
    stored = json.loads((run / "od50.json").read_text())
    old = {**stored, "od50": {k: v for k, v in stored["od50"].items() if not k.startswith("ap_range")}}
    (run / "od50.json").write_text(json.dumps(old, indent=1))
    boot = sweep_module.run_od50(run, n_resamples=40, seed=0)
    assert boot.ap_range_m is not None and json.loads((run / "od50.json").read_text()) == stored


def test_od50_cache_with_unscaled_intervals_is_computed_again(tmp_path, monkeypatch):
    """An od50.json written before intervals were widened for few environments (no
    ``interval_scale``) is not reused: its intervals are the bare percentile ones."""
    make_fake_sweep(tmp_path / "sw", monkeypatch, n_resamples=40)
    run = tmp_path / "sw" / "runs" / "cam01-day"
    stored = json.loads((run / "od50.json").read_text())
    assert stored["od50"]["interval_scale"] > 1.0
    old = {**stored, "od50": {k: v for k, v in stored["od50"].items() if k != "interval_scale"}}
    (run / "od50.json").write_text(json.dumps(old, indent=1))
    boot = sweep_module.run_od50(run, n_resamples=40, seed=0)
    assert boot.interval_scale is not None and json.loads((run / "od50.json").read_text()) == stored


def test_second_sweep_reuses_every_run(tmp_path, monkeypatch):
    first = CountingRun()
    t1 = make_fake_sweep(tmp_path / "sw", monkeypatch, run=first)
    assert len(first.calls) == 4
    mtimes = {p: p.stat().st_mtime_ns for p in (tmp_path / "sw" / "runs").rglob("*.json")}
    second = CountingRun()
    t2 = make_fake_sweep(tmp_path / "sw", monkeypatch, run=second)
    assert second.calls == []
    assert {p: p.stat().st_mtime_ns for p in mtimes} == mtimes  # nothing rewritten, bootstrap cached too
    pd.testing.assert_frame_equal(t1, t2)
    assert all(r["reused"] for r in json.loads((tmp_path / "sw" / "sweep.json").read_text())["runs"])


def test_changed_key_reruns_only_that_part(tmp_path, monkeypatch):
    make_fake_sweep(tmp_path / "sw", monkeypatch)
    other_seed = CountingRun()
    make_fake_sweep(tmp_path / "sw", monkeypatch, run=other_seed, seed=1)
    assert len(other_seed.calls) == 4  # the seed is part of the key
    night_only = CountingRun()
    make_fake_sweep(tmp_path / "sw", monkeypatch, run=night_only, seed=1, conditions=("night",))
    assert night_only.calls == []


def test_killed_sweep_resumes_and_equals_uninterrupted(tmp_path, monkeypatch):
    full = make_fake_sweep(tmp_path / "full", monkeypatch)
    killed = CountingRun(die_after=2)
    with pytest.raises(KeyboardInterrupt):
        make_fake_sweep(tmp_path / "resumed", monkeypatch, run=killed)
    assert len(killed.calls) == 2
    damaged = killed.calls[0]  # a finished run whose results.json was cut short
    (tmp_path / "resumed" / "runs" / "-".join(damaged) / "results.json").write_text('{"camera": ')
    resumed = CountingRun()
    table = make_fake_sweep(tmp_path / "resumed", monkeypatch, run=resumed)
    every = {(camera, condition) for camera in CAMERAS for condition in ("day", "night")}
    assert sorted(resumed.calls) == sorted(every - set(killed.calls[1:]))  # the rest, and the damaged one again
    pd.testing.assert_frame_equal(table, full)
    pd.testing.assert_frame_equal(pd.read_csv(tmp_path / "resumed" / "od50.csv"), pd.read_csv(tmp_path / "full" / "od50.csv"))


def test_mtf_sources_and_errors(tmp_path, monkeypatch):
    cam = load_camera("cam05")
    assert sweep_module.camera_mtf50(cam, "published_group") == (cam.mtf50_group_cy_per_mm, "published_group")
    analytic, source = sweep_module.camera_mtf50(cam, "analytic")
    assert source == "analytic" and 30 < analytic < 300
    with pytest.raises(ValueError, match="MTF50 source must be one of measured, analytic, published_group"):
        sweep_module.camera_mtf50(cam, "guess")
    with pytest.raises(ValueError, match="unknown condition 'dawn'"):
        make_fake_sweep(tmp_path / "sw", monkeypatch, conditions=("dawn",))
    with pytest.raises(ValueError, match="unique"):
        make_fake_sweep(tmp_path / "sw", monkeypatch, cameras=("cam01", "cam01"))


def test_json_is_strict(tmp_path, monkeypatch):
    from benchmark.result_files import json_safe

    assert json_safe([np.float64("nan"), np.inf, np.int64(2)]) == [None, "inf", 2]
    make_fake_sweep(tmp_path / "sw", monkeypatch)
    json.loads((tmp_path / "sw" / "sweep.json").read_text(), parse_constant=lambda c: pytest.fail(f"non-strict {c}"))


def test_mtf_policy_falls_through_sources_that_give_nothing(monkeypatch):
    """A camera the edge bench cannot image falls through to the analytic figure; one that no
    source can give reports (None, "none")."""
    from benchmark.measure import mtf as mtf_module

    cam = load_camera("cam05")

    def cannot_image(camera):
        raise ValueError("edge outside the sensor")

    monkeypatch.setattr(mtf_module, "measure_mtf50", cannot_image)
    value, source = mtf_module.camera_mtf50(cam)
    assert source == "analytic" and value == mtf_module.camera_mtf50(cam, "analytic")[0]
    monkeypatch.setattr(mtf_module, "mtf50_analytic_cy_per_mm", lambda *a, **k: float("nan"))
    assert mtf_module.camera_mtf50(cam.model_copy(update={"mtf50_group_cy_per_mm": None})) == (None, "none")


# --- camera images read back; what failed or killed sweeps leave ---------------------------

def seeded_capture(radiance, camera, seed):
    """A replaced ``simulate`` for the real run_camera: noise of the camera's size, seeded by the scene."""
    capture = BlankCapture()
    capture.rgb8 = np.random.default_rng(seed).integers(0, 256, (camera.height_px, camera.width_px, 3), np.uint8)
    return capture


def small_camera(folder: Path):
    spec = folder / "small.yaml"
    spec.write_text("name: small\noptics: {f_number: 2.0}\nsensor: {pixel_um: 11.2}\n")  # 240 x 135 px
    return load_camera(spec)


def test_an_image_changed_after_its_run_wrote_it_is_refused_where_it_is_read_back(tmp_path, monkeypatch):
    """A run records each image's sha256 (images.sha256, sha256sum's format). Runs that detect on
    its images (--captures-from) hold them as hard links, so a `cp` over one in any folder
    changes it in all: a run reading it back refuses it in one line and writes nothing."""
    import hashlib
    import re
    import shutil

    import benchmark.camera.pipeline
    from benchmark.experiments.run import read_captures, run_camera

    monkeypatch.setattr(benchmark.camera.pipeline, "simulate", seeded_capture)
    camera, collection = small_camera(tmp_path), BlankCollection(tmp_path)
    first, reader = tmp_path / "first", tmp_path / "reader"
    run_camera(collection, camera, "day", BlindDetector(), first)
    images = sorted((first / "images").iterdir())
    assert (first / "images.sha256").read_text() == "".join(
        f"{hashlib.sha256(p.read_bytes()).hexdigest()}  images/{p.name}\n" for p in images)
    run_camera(collection, camera, "day", BlindDetector(), reader, captures=first)
    assert (reader / "images.sha256").read_bytes() == (first / "images.sha256").read_bytes()

    black = tmp_path / "black.png"
    from PIL import Image

    Image.fromarray(np.zeros((camera.height_px, camera.width_px, 3), np.uint8)).save(black)
    shutil.copyfile(black, reader / "images" / images[0].name)  # as `cp` does: written through the shared file
    assert images[0].read_bytes() == black.read_bytes()  # the first run's image changed too
    with pytest.raises(ValueError, match=rf"^captures {re.escape(str(images[0]))}: its bytes changed since its run "
                                         r"wrote it \(sha256 [0-9a-f]{12}\.\.\., images.sha256 records") as refused:
        run_camera(collection, camera, "day", BlindDetector(), tmp_path / "again", captures=first)
    assert "\n" not in str(refused.value) and not (tmp_path / "again").exists()

    run_camera(collection, camera, "day", BlindDetector(), first, save_images=False)  # its old images vouched for no more
    assert not (first / "images.sha256").exists()
    with pytest.raises(ValueError, match="no images.sha256"):
        read_captures(first, camera, "day", collection, 0)


def test_a_running_sweep_folder_is_a_sweep_folder(tmp_path, monkeypatch):
    """A sweep stamps its folder when it starts: while it runs, `run --out` one of its later
    units (whose rerun once replaced the user's run), `run --out <sweep>/runs` and `export` into
    it are refused like any sweep folder's (sweep.json, sweep.csv: written at the end), and
    `report` says it is not finished."""
    from typer.testing import CliRunner

    from benchmark.cli.main import app as benchmark_app
    from metricscenes.cli import app as metricscenes_app

    out = tmp_path / "sw"
    attempts = []

    def meanwhile(done, total, label):
        if attempts:
            return
        for app, args in ((benchmark_app, ["run", "--camera", "cam01", "--collection", tmp_path / "none",
                                           "--out", out / "runs" / "cam12-night"]),
                          (benchmark_app, ["run", "--camera", "cam01", "--collection", tmp_path / "none",
                                           "--out", out / "runs"]),
                          (metricscenes_app, ["export", tmp_path / "none", out / "x.h5", "--scene", "env000-d025m"])):
            attempts.append(CliRunner().invoke(app, [str(a) for a in args]))
        attempts.append(CliRunner().invoke(benchmark_app, ["report", str(out)]))

    make_fake_sweep(out, monkeypatch, progress=meanwhile)
    assert len(attempts) == 4
    for result in attempts[:3]:
        assert result.exit_code == 2 and f"inside the sweep folder {out}" in result.output, result.output
    assert attempts[3].exit_code == 2 and "is a sweep that has not written its tables yet" in attempts[3].output
    assert json.loads((out / "runs" / "cam12-night" / "results.json").read_text())["seed"] == 0
    assert (out / "sweep.started").is_file()


def test_a_sweep_killed_after_its_runs_moved_into_place_leaves_nothing_once_rerun(tmp_path, monkeypatch):
    """A kill between a run's last rename and its clean-up leaves its resumable stage and lock
    in a finished run folder; the rerun, which reuses that run, removes them (and other staging
    folders), but keeps the stage another run (another seed) left to resume."""
    import socket
    import subprocess

    from benchmark.experiments import run as run_module
    from benchmark.experiments.keys import resume_key

    out = tmp_path / "sw"
    make_fake_sweep(out, monkeypatch)
    collection, detector = FakeCollection(tmp_path), FakeDetector()
    dead = subprocess.Popen(["true"])
    dead.wait()
    for name, seed in (("cam01-day", 0), ("cam12-day", 1)):
        folder = out / "runs" / name
        camera = load_camera(name.split("-")[0])
        run_module.resumable_stage(folder, resume_key(camera, "day", collection, seed, [detector], False, None))
        (folder / ".partial-a1b2c3").mkdir()
        (folder / "benchmark.lock").write_text(json.dumps({"pid": dead.pid, "host": socket.gethostname()}))
    rerun = CountingRun()
    make_fake_sweep(out, monkeypatch, run=rerun)
    assert rerun.calls == []  # every run reused
    leftovers = sorted(str(p.relative_to(out)) for p in (out / "runs").glob("*/*") if p.name.startswith((".", "bench")))
    assert leftovers == ["runs/cam12-day/.partial-resume"]  # the seed-1 run's, to resume


def test_a_failed_or_one_environment_sweep_leaves_no_folder(tmp_path, monkeypatch):
    """A sweep that fails before it writes any run (a full disk) leaves no empty runs/ nor its
    folder; one environment (no bootstrap SD) is refused before any run."""
    import errno

    from benchmark.experiments.subset import subset_collection

    def disk_full(*args, **kwargs):
        raise OSError(errno.ENOSPC, "No space left on device")

    with pytest.raises(OSError, match="No space left"):
        make_fake_sweep(tmp_path / "new" / "sw", monkeypatch, run=disk_full)
    assert not (tmp_path / "new").exists()
    (tmp_path / "mine").mkdir()
    with pytest.raises(OSError, match="No space left"):
        make_fake_sweep(tmp_path / "mine", monkeypatch, run=disk_full)
    assert list((tmp_path / "mine").iterdir()) == []  # the user's folder kept, empty as it was

    counting = CountingRun()
    patch_runs(monkeypatch, counting)
    one = subset_collection(FakeCollection(tmp_path), "0", None)
    with pytest.raises(ValueError, match="a sweep needs two or more environments .* this subset has 1: use `benchmark run`"):
        sweep_module.sweep(one, [load_camera("cam01")], ["day"], FakeDetector(), tmp_path / "one", n_resamples=20,
                           mtf_source="analytic", save_images=False)
    assert counting.calls == [] and not (tmp_path / "one").exists()
