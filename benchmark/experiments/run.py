"""One camera on one collection under one condition: images → detections → AP per distance.

The chain, each stage from its own module: collection radiance (metricscenes store)
→ :func:`benchmark.camera.pipeline.simulate` (optics, sensor, exposure, ISP) → detector →
:func:`benchmark.scoring.ap_by_distance`. Outputs, in the results folder:

- ``results.json``: camera, condition, detector, collection, AP/AP50 per distance, OD50
  (:class:`benchmark.result_files.RunResults`, where its schema is defined);
- ``detections.json``: every detection (score ≥ 0.001) in COCO results format, boxes in
  the camera's pixels;
- ``groundtruth.json``: the collection's ground truth on the camera's grid (scaled, or
  mapped onto the camera's window of the field: :func:`benchmark.experiments.collection_view.camera_geometry`);
- ``images/<scene>.png``: the camera's sRGB images (optional), and ``images.sha256``, the
  sha256 of each (``sha256sum`` format). Runs that share an image hold it as one file (hard
  links), so a write over it in one folder changes it in all of them: a run that reads images
  back (``captures``) checks each against the sha256 its run recorded and refuses one whose
  bytes changed.

The camera's images depend on the camera, condition, collection and seed only
(:func:`benchmark.experiments.keys.capture_key`), not on the detector: a run given ``captures`` (an earlier run folder
of the same capture key, with its images) detects on those images and skips the radiance and
the camera, with the same detections as a run that simulates them (another detector, input
size or class map on the same captures: ``benchmark sweep --captures-from``). A multiscale
run also writes, where asked (``also``), the runs of the single-pass policies its passes
make (native, 640): the same files those policies' runs write, from one inference.

A run on a :class:`benchmark.experiments.subset.CollectionSubset` (``--environments 0-2,5 --distances 25,50``, a quick
try) records ``subset`` in results.json; `benchmark submit` refuses it and a sweep never
reuses it as a full run.
"""

from __future__ import annotations

import hashlib
import json
import os
import shutil
import time
from dataclasses import dataclass, field
from pathlib import Path

import numpy as np

from benchmark.detectors.policy import parse_input_size
from benchmark.experiments.keys import capture_key, grid_key, results_capture_key, resume_key
from benchmark.experiments.collection_view import (COMPOSITE, collection_field, collection_widest_field, condition_spec,
                                                   geometry_record)
from benchmark.experiments.run_folder import (  # noqa: F401 (RESUMABLE_STAGE: named here too)
    CHECKPOINT, RESUMABLE_STAGE, link_or_copy, move_into_place, remove_stale_stages, resumable_stage,
)
from benchmark.scoring.ap import AP_SCORE_THRESHOLD, CAR_CLASSES
from metricscenes.files import sha256_file
from metricscenes.numeric_pins import numeric_provenance
from benchmark.result_files import (
    IMAGE_HASHES_FILE, RESULTS_FORMAT, CameraGeometry, CameraRecord, CollectionRecord, DetectorRecord, DistanceAP,
    RunResults, Subset, write_image_hashes, write_results,
)

# What a name that becomes a file or folder name may not hold (one rule for all of them):
# a way out of its folder, a separator on any OS, or characters that break a line or a C string.
FORBIDDEN_IN_NAMES = ("..", "/", "\\", "\0", "\n", "\r")


def check_path_name(name: str, what: str) -> str:
    """``name`` if it can name one folder or file: not empty, no ``..``, ``/``, ``\\``,
    NUL or newline; else a one-line ValueError naming ``what`` it is."""
    if not isinstance(name, str) or not name or any(bad in name for bad in FORBIDDEN_IN_NAMES):
        raise ValueError(f"{what} {name!r} cannot name a folder (it must be non-empty, without '..', '/', "
                         "'\\', NUL or newline)")
    return name


def check_out_dir(out_dir, what: str = "--out") -> Path:
    """An output folder for benchmark: its own name follows :func:`check_path_name`, it is
    not a file nor under one, and it is not a collection nor inside one (collections are
    read-only to benchmark). ``what``: the option that named it, for the message."""
    from metricscenes.store import collection_containing, file_in_the_way

    out_dir = Path(out_dir)
    check_path_name(out_dir.name, f"{what} folder name")  # as typed: 'runs/..' and '.' name no folder
    if problem := file_in_the_way(out_dir, what):
        raise ValueError(problem)
    inside = collection_containing(out_dir)
    if inside is not None:
        where = "is" if inside == Path(os.path.abspath(out_dir)).resolve() else "is inside"
        raise ValueError(f"{what} {out_dir} {where} the collection {inside}: collections are read-only to "
                         "benchmark, choose a folder outside it")
    return out_dir


def read_scene(collection, scene_id: str, condition: str):
    """A scene under ``condition`` for every camera: its radiance, or for a condition that
    meets its target at each camera's image plane, its parts and how to weigh them
    (:class:`benchmark.camera.image_plane.ImagePlaneParts`: each camera its own weights)."""
    if getattr(collection, "targets_camera", lambda _: False)(condition):
        from benchmark.camera.image_plane import ImagePlaneParts

        parts = {name: collection.radiance(scene_id, weights, inset_resolution=COMPOSITE)
                 for name, weights in collection.condition_parts(condition).items()}
        return ImagePlaneParts(parts, lambda lux, at: collection.camera_weights(scene_id, condition, lux, at))
    return collection.radiance(scene_id, condition, inset_resolution=COMPOSITE)


@dataclass(frozen=True)
class Captures:
    """A finished run folder whose camera images stand for another run's (:func:`read_captures`)."""

    folder: Path
    results: RunResults
    image_sha256: dict[str, str]  # image file name -> sha256 of the bytes its run wrote (images.sha256)


def read_captures(captures, camera, condition: str, collection, seed: int) -> Captures:
    """The run folder ``captures`` if its images can stand for this run's camera (same
    :func:`capture_key`, an image and its recorded sha256 for every scene); ValueError (one
    line) if not. Each image's bytes are checked when it is read (:func:`_captured_image`)."""
    from benchmark.result_files import ResultsFileError, read_image_hashes, read_results

    captures = Path(captures)
    try:
        results = read_results(captures / "results.json")
    except (OSError, ResultsFileError) as exc:
        raise ValueError(f"captures {captures}: no finished run there ({str(exc).splitlines()[0]})") from None
    if results_capture_key(results) != capture_key(camera, condition, collection, seed):
        raise ValueError(f"captures {captures}: made with another camera, condition, collection or seed")
    try:
        hashes = read_image_hashes(captures / IMAGE_HASHES_FILE)
    except OSError:
        raise ValueError(f"captures {captures}: no {IMAGE_HASHES_FILE} (its images were saved before their sha256 "
                         "was recorded, or not at all): run it again to use its images") from None
    except ResultsFileError as exc:
        raise ValueError(f"captures {exc}") from None
    missing = [s.scene_id for s in collection.scenes()
               if f"{s.scene_id}.png" not in hashes or not (captures / "images" / f"{s.scene_id}.png").is_file()]
    if missing:
        raise ValueError(f"captures {captures}: no image of {len(missing)} scene(s), e.g. {missing[0]}.png")
    return Captures(captures, results, hashes)


def _captured_image(captures: Captures, scene_id: str, camera) -> tuple[np.ndarray, str]:
    """The 8-bit sRGB image a run saved of ``scene_id`` (PNG: the very array it detected on)
    and its sha256, which must be the one its run recorded: an image is a hard link shared by
    several runs' folders, and one write over it in any of them changes it in all."""
    import io

    from PIL import Image

    path = captures.folder / "images" / f"{scene_id}.png"
    try:
        data = path.read_bytes()
    except OSError as exc:
        raise ValueError(f"captures {path}: unreadable image ({exc.strerror or type(exc).__name__})") from None
    digest, recorded = sha256_bytes(data), captures.image_sha256[path.name]
    if digest != recorded:
        raise ValueError(f"captures {path}: its bytes changed since its run wrote it (sha256 {digest[:12]}..., "
                         f"{IMAGE_HASHES_FILE} records {recorded[:12]}...): detect without --captures-from, or remove "
                         f"{captures.folder} and run the sweep that made it again")
    try:
        with Image.open(io.BytesIO(data)) as image:
            rgb8 = np.asarray(image)
    except OSError as exc:
        raise ValueError(f"captures {path}: unreadable image ({str(exc).splitlines()[0]})") from None
    if rgb8.dtype != np.uint8 or rgb8.shape != (camera.height_px, camera.width_px, 3):
        raise ValueError(f"captures {path}: {rgb8.shape} {rgb8.dtype} image, the camera makes "
                         f"({camera.height_px}, {camera.width_px}, 3) uint8")
    return rgb8, digest


@dataclass
class Timings:
    """Seconds spent per stage, summed over the scenes."""

    seconds: dict[str, float] = field(default_factory=dict)

    def add(self, stage: str, started: float) -> None:
        self.seconds[stage] = self.seconds.get(stage, 0.0) + time.perf_counter() - started


def scene_seed(seed: int, image_id: int) -> int:
    """Noise seed of one capture: depends on the run seed and the scene only."""
    return int(np.random.SeedSequence([seed, image_id]).generate_state(1, dtype=np.uint32)[0])


def sha256_bytes(data: bytes) -> str:
    return hashlib.sha256(data).hexdigest()


def run_camera(collection, camera, condition: str, detector, out_dir: Path, *, seed: int = 0,
               save_images: bool = True, backend: str = "faster-coco-eval", progress=None,
               captures: Path | None = None) -> RunResults:
    """Simulate ``camera`` on every scene of ``collection`` under ``condition``, detect, score.

    ``progress`` is an optional callable ``(done, total)``. ``captures``: a finished run
    folder of the same :func:`capture_key` whose images are detected instead of simulating
    the camera again (:func:`read_captures`; recorded as ``captures_from``). Returns the
    results (also written to ``out_dir/results.json``).

    Everything is written to a staging folder inside ``out_dir`` first and moved into place
    only when the run succeeded: a damaged scene or a broken model met halfway leaves
    ``out_dir`` as it was (the folders the run created are removed). The run holds
    ``out_dir/benchmark.lock`` (:func:`metricscenes.lock.output_lock`) throughout, so a second
    run on the same folder is refused (:class:`~metricscenes.lock.LockError`), and removes the
    staging folders that killed runs left there. A run killed or interrupted midway leaves its
    resumable stage (:data:`RESUMABLE_STAGE`: each finished scene's detections, exposures and
    image); the next run of the same :func:`resume_key` takes it up at the next scene and ends
    with the same bytes as a run never stopped.
    """
    return run_cameras(collection, [camera], condition, detector, [out_dir], seed=seed, save_images=save_images,
                       backend=backend, progress=progress, captures=[captures])[0]


def run_cameras(collection, cameras, condition: str, detector, out_dirs, *, seed: int = 0,
                save_images: bool = True, backend: str = "faster-coco-eval", progress=None,
                captures=None, also: dict | None = None) -> list[RunResults]:
    """:func:`run_camera` for several cameras at once, scene by scene: each scene's radiance
    is read once for all of them, and resampled once per pixel grid (the cameras are taken
    grid by grid; :meth:`metricscenes.radiance.SpectralScene.resample` keeps the last).
    Each camera's outputs are those :func:`run_camera` writes for it alone, byte for byte
    (``results.json``'s ``timing_s`` aside, where ``read_radiance`` is the shared read).

    ``out_dirs``: one folder per camera; ``captures``: None, or one entry per camera (None or
    a run folder, as :func:`run_camera` takes it). ``also``: {input size: one folder per
    camera} for policies among ``detector.pass_policies()`` (a multiscale detector's native
    and 640 passes): each gets the run a detector of that input size would write there
    (images linked, not copied), from the same inference. ``progress`` ``(done, total)``
    counts scenes. Returns the runs in ``out_dirs`` (the others are on disk). The runs succeed
    or fail together: a failure before the last scene is scored leaves every folder as it was
    (one while the files move leaves the runs moved so far, each results.json last).
    """
    from contextlib import ExitStack

    from benchmark.camera.pipeline import camera_window
    from metricscenes.lock import output_lock

    cameras, out_dirs = list(cameras), list(out_dirs)
    captures = [None] * len(cameras) if captures is None else list(captures)
    also = {parse_input_size(size): list(dirs) for size, dirs in (also or {}).items()}
    if not (len(out_dirs) == len(captures) == len(cameras)) or any(len(d) != len(cameras) for d in also.values()):
        raise ValueError("run_cameras needs one output folder (and one captures entry) per camera")
    check_pass_policies(detector, also)
    policies = [detector] + [detector.with_input_size(size) for size in also]
    folders = [[check_out_dir(d) for d in dirs] for dirs in [out_dirs, *also.values()]]  # before anything is written
    every = [d for dirs in folders for d in dirs]
    if len({d.resolve() for d in every}) != len(every):
        raise ValueError("run_cameras needs a distinct output folder per camera")
    field = collection_field(collection)
    widest = collection_widest_field(collection)
    windows = [camera_window(camera, field, widest) for camera in cameras]  # a camera wider than the collection: refused here
    captured = [None if c is None else read_captures(c, camera, condition, collection, seed)
                for camera, c in zip(cameras, captures)]
    created = [[p for p in (d, *d.parents) if not p.exists()] for d in every]
    interrupted = False
    try:
        with ExitStack() as held:
            for d in every:
                d.mkdir(parents=True, exist_ok=True)
                held.enter_context(output_lock(d, "benchmark run", "run folder"))
                remove_stale_stages(d)
            keys = [resume_key(camera, condition, collection, seed, policies, save_images, c)
                    for camera, c in zip(cameras, captures)]
            opened = [[resumable_stage(d, keys[k]) for k, d in enumerate(dirs)] for dirs in folders]
            stages = [[stage for stage, _ in row] for row in opened]
            for k in range(len(cameras)):  # a policy's stage begun again (its images gone): all of the camera's
                if not all(row[k][1] for row in opened):
                    (stages[0][k] / CHECKPOINT).unlink(missing_ok=True)
            # Removed when the runs succeed or fail; kept for the next run when they are
            # interrupted (Ctrl-C here; a killed process runs nothing).
            held.callback(lambda: interrupted or [shutil.rmtree(stage, ignore_errors=True)
                                                  for row in stages for stage in row])
            runs = [_CameraRun(collection, camera, condition, policies, [row[k] for row in stages], field, window,
                               seed=seed, save_images=save_images, backend=backend, captures=c)
                    for k, (camera, window, c) in enumerate(zip(cameras, windows, captured))]
            try:
                results = _run_scenes(collection, condition, runs, progress)
            except KeyboardInterrupt:
                interrupted = True
                raise
            for dirs, row in zip(folders, stages):
                for d, stage in zip(dirs, row):
                    move_into_place(stage, d, save_images)
            return results
    except BaseException:
        for made in created:  # the folders these runs made, innermost first, if still empty
            for folder in made:
                try:
                    folder.rmdir()
                except OSError:
                    break
        raise


def check_pass_policies(detector, sizes) -> None:
    """ValueError (one line) unless every input size of ``sizes`` is one of the single-pass
    policies whose passes ``detector`` runs (``pass_policies``: native and 640 for multiscale)."""
    passes = detector.pass_policies() if sizes else []
    for size in sizes:
        if parse_input_size(size) not in passes:
            raise ValueError(f"input size {size} is not a pass of {detector.name} at input size {detector.input_size}"
                             f" (its passes: {', '.join(map(str, passes)) or 'one, its own'})")


def _run_scenes(collection, condition: str, runs: list["_CameraRun"], progress) -> list[RunResults]:
    """Every scene through every run, the radiance read once per scene (only where a run
    simulates its camera); then each run scored. Runs of one pixel grid go one after
    another, so the scene's last resample serves them all."""
    order = sorted(range(len(runs)), key=lambda k: (str(grid_key(runs[k].camera)), k))
    scenes = collection.scenes()
    found = [all(scene.scene_id in run.done for run in runs) for scene in scenes]  # a resumed run's
    if progress:  # those first, at once: a log estimates the time left from the scenes made after them
        progress(sum(found), len(scenes))
    for i, scene in enumerate(scenes):
        record = collection.condition_record(scene.scene_id, condition)  # a targeted condition's weights, once
        radiance, read_s = None, 0.0
        if any(run.captures is None and scene.scene_id not in run.done for run in runs):
            t = time.perf_counter()
            radiance = read_scene(collection, scene.scene_id, condition)
            read_s = time.perf_counter() - t
        for k in order:
            runs[k].add(scene, radiance, read_s, record)
        if progress and not found[i]:
            progress(i + 1, len(scenes))
    return [run.finish() for run in runs]


class _CameraRun:
    """One camera's run in its staging folders, one per input-size policy (``detectors[0]``
    the detector's own, then those of its passes: ``stages`` alike): :meth:`add` takes the
    scenes one by one (simulate or read the captured image, detect, save), :meth:`finish`
    scores them and writes detections, ground truth and results.json in each stage.
    ``window`` is the part of the collection's ``field`` the camera samples (and its ground
    truth follows); ``captures``: the run whose images stand for the camera's."""

    def __init__(self, collection, camera, condition: str, detectors: list, stages: list[Path], field, window, *,
                 seed: int, save_images: bool, backend: str, captures: Captures | None):
        self.collection, self.camera, self.condition, self.detectors = collection, camera, condition, detectors
        self.stages, self.field, self.window = stages, field, window
        self.seed, self.save_images, self.backend, self.captures = seed, save_images, backend, captures
        for stage in stages:
            (stage / "images" if save_images else stage).mkdir(parents=True, exist_ok=True)
        self.timings = Timings()
        self.detections: list[list[dict]] = [[] for _ in detectors]
        self.exposures: dict[str, float] = {}
        self.short_exposures: dict[str, float] = {}  # the hdr policy's second frame
        self.targeted: dict[str, dict] = {}  # a targeted condition's target and weights per scene
        self.image_sha256: dict[str, str] = {}  # image file name -> sha256 of its bytes (images.sha256)
        self.checkpoint = stages[0] / CHECKPOINT
        self.done = self._staged_scenes()  # scenes an interrupted run of the same key finished

    def _staged_scenes(self) -> dict[str, dict]:
        """The scenes the checkpoint holds (a line cut by a kill is dropped, and the file
        cut back to its last whole line so that the next scene starts a line of its own)."""
        try:
            data = self.checkpoint.read_bytes()
        except FileNotFoundError:
            return {}
        whole = data[: data.rfind(b"\n") + 1]
        if len(whole) != len(data):
            with open(self.checkpoint, "r+b") as f:
                f.truncate(len(whole))
        done = {}
        for line in whole.splitlines():
            try:
                entry = json.loads(line)
            except ValueError:
                continue
            done[entry["scene_id"]] = entry
        return done

    def add(self, scene, radiance, read_s: float, record: dict | None) -> None:
        """One scene: ``radiance`` its :class:`~metricscenes.radiance.SpectralScene` under the
        condition (None where this run detects on captured images), read in ``read_s`` s;
        ``record``: what a targeted condition did in it (None for another condition)."""
        from PIL import Image

        from benchmark.camera.image_plane import ImagePlaneParts
        from benchmark.camera.pipeline import simulate
        from benchmark.coco import coco_category_id

        camera, captures, timings = self.camera, self.captures, self.timings
        if record is not None:
            self.targeted[scene.scene_id] = record
        staged = self.done.pop(scene.scene_id, None)
        if staged is not None:  # finished before an interruption: its outputs are in the stage
            for detections, found in zip(self.detections, staged["detections"]):
                detections.extend(found)
            self.exposures[scene.scene_id] = staged["exposure_s"]
            if staged.get("condition_weights") is not None:  # weights of this camera's own (target_at: camera)
                self.targeted[scene.scene_id] = staged["condition_weights"]
            if staged["exposure_short_s"] is not None:
                self.short_exposures[scene.scene_id] = staged["exposure_short_s"]
            if self.save_images:  # (a stage begun before images had their sha256 recorded: hashed now)
                name = f"{scene.scene_id}.png"
                self.image_sha256[name] = staged.get("image_sha256") or sha256_file(self.stages[0] / "images" / name)
            return
        found_here = [len(d) for d in self.detections]
        if captures is None:
            timings.seconds["read_radiance"] = timings.seconds.get("read_radiance", 0.0) + read_s
            t = time.perf_counter()
            if isinstance(radiance, ImagePlaneParts):  # its weights are this camera's own
                capture, self.targeted[scene.scene_id] = radiance.simulate(camera, seed=scene_seed(self.seed,
                                                                                                   scene.image_id))
            else:
                capture = simulate(radiance, camera, seed=scene_seed(self.seed, scene.image_id))
            timings.add("camera", t)
            rgb8, self.exposures[scene.scene_id] = capture.rgb8, capture.exposure_s
            if capture.exposure_short_s is not None:
                self.short_exposures[scene.scene_id] = capture.exposure_short_s
        else:
            t = time.perf_counter()
            rgb8, captured_sha256 = _captured_image(captures, scene.scene_id, camera)
            self.exposures[scene.scene_id] = captures.results.exposure_s[scene.scene_id]
            if record is None and (captures.results.condition_weights or {}).get(scene.scene_id) is not None:
                self.targeted[scene.scene_id] = captures.results.condition_weights[scene.scene_id]  # the camera's own
            if captures.results.exposure_short_s is not None:
                self.short_exposures[scene.scene_id] = captures.results.exposure_short_s[scene.scene_id]
            timings.add("read_captures", t)
        t = time.perf_counter()
        # multi_label: every class above threshold per box, as YOLOv5's val.py does for COCO mAP.
        detector, also = self.detectors[0], [d.input_size for d in self.detectors[1:]]
        if also:  # the passes' own policies from the same inference
            by_policy = detector.detect_policies([rgb8], also, conf_threshold=AP_SCORE_THRESHOLD, multi_label=True)
            found_by = [by_policy[d.input_size][0] for d in self.detectors]
        else:
            found_by = detector.detect([rgb8], conf_threshold=AP_SCORE_THRESHOLD, multi_label=True)
        timings.add("detect", t)
        for detections, found in zip(self.detections, found_by):
            for d in found:
                x1, y1, x2, y2 = (float(v) for v in d.box_xyxy)
                detections.append({
                    "image_id": scene.image_id, "category_id": coco_category_id(d.class_id),
                    "bbox": [round(x1, 3), round(y1, 3), round(x2 - x1, 3), round(y2 - y1, 3)],
                    "score": round(float(d.score), 6),
                })
        if self.save_images:
            t = time.perf_counter()
            name = f"{scene.scene_id}.png"
            source = self.stages[0] / "images" / name
            if captures is None:
                Image.fromarray(rgb8).save(source, compress_level=1)
                self.image_sha256[name] = sha256_file(source)
            else:
                link_or_copy(captures.folder / "images" / name, source)
                self.image_sha256[name] = captured_sha256
            for stage in self.stages[1:]:
                link_or_copy(source, stage / "images" / name)
            timings.add("save_images", t)
        entry = {"scene_id": scene.scene_id, "detections": [d[n:] for d, n in zip(self.detections, found_here)],
                 "exposure_s": self.exposures[scene.scene_id],
                 "exposure_short_s": self.short_exposures.get(scene.scene_id)}
        if self.save_images:
            entry["image_sha256"] = self.image_sha256[f"{scene.scene_id}.png"]
        if isinstance(radiance, ImagePlaneParts):  # weights that are the camera's own are staged with its scene
            entry["condition_weights"] = self.targeted[scene.scene_id]
        with open(self.checkpoint, "a") as f:  # after the image: a scene listed here is whole
            f.write(json.dumps(entry) + "\n")

    def finish(self) -> RunResults:
        """Score and write every policy's stage; the detector's own run's results."""
        from benchmark.camera.pipeline import lens_mapping
        from metricscenes.store import scale_groundtruth

        camera = self.camera
        sensor_window, to_sensor = lens_mapping(camera, self.field, collection_widest_field(self.collection))
        groundtruth = scale_groundtruth(self.collection.groundtruth(), camera.width_px, camera.height_px,
                                        field=self.field, window=sensor_window, to_sensor=to_sensor)
        return [self._write(groundtruth, detector, stage, detections)
                for detector, stage, detections in zip(self.detectors, self.stages, self.detections)][0]

    def _write(self, groundtruth: dict, detector, stage: Path, detections: list[dict]) -> RunResults:
        from benchmark.scoring import ap_by_distance, od50, working_point
        from metricscenes import __version__

        collection, camera, timings = self.collection, self.camera, self.timings
        geometry = geometry_record(camera, self.field, self.window)
        t = time.perf_counter()
        per_distance = ap_by_distance(groundtruth, detections, backend=self.backend)
        working = working_point(groundtruth, detections)  # miss rate and false positives per image beside AP
        timings.add("score", t)
        detections_bytes = json.dumps(detections, separators=(",", ":")).encode()
        per_distance = [DistanceAP(**row, **working[row["distance_m"]]) for row in per_distance]
        detector_record = DetectorRecord(name=detector.name, family=detector.family, sha256=detector.sha256,
                                         input_size=detector.input_size, score_threshold=AP_SCORE_THRESHOLD,
                                         multi_label=True)
        class_map = getattr(detector, "class_map", None)
        if class_map is not None:  # a detector with other classes than COCO's 80 (docs/detection.md)
            from benchmark.detectors.classmap import class_map_names

            detector_record.class_map = class_map_names(class_map)
        results = RunResults(
            format=RESULTS_FORMAT,
            package_version=__version__,
            numerics=numeric_provenance(),
            composite=COMPOSITE,
            camera=camera_record(camera),
            condition=self.condition,
            detector=detector_record,
            collection=CollectionRecord(name=collection.name, protocol=collection.protocol,
                                        manifest_sha256=collection.manifest_sha256, path=str(collection.root)),
            seed=self.seed,
            scoring_backend=self.backend,
            per_distance=per_distance,
            od50_m=_finite_or_none(od50([r.distance_m for r in per_distance], [r.ap for r in per_distance])),
            exposure_s=self.exposures,
            detections_file="detections.json",
            detections_sha256=sha256_bytes(detections_bytes),
            timing_s={k: round(v, 3) for k, v in timings.seconds.items()},
            car_classes=list(CAR_CLASSES),  # what the AP above counts as the car, stated in every run
        )
        # The optional fields are set only where they apply, so that other results keep their bytes
        # (results.json holds the fields set: benchmark.result_files).
        if self.targeted:
            results.condition_weights = self.targeted
        spec = condition_spec(collection, self.condition)
        if spec is not None:  # a read-time condition: what defined it (the manifest's hash does not)
            results.condition_spec = spec
        if geometry is not None:  # a camera that sees a window of the field
            results.camera_geometry = CameraGeometry(**geometry)
        subset = getattr(collection, "subset", None)
        if subset:  # a quick try on part of the collection: never a full run (sweep key, `benchmark submit`)
            results.subset = Subset(**subset)
        if self.short_exposures:  # hdr only; exposure_s holds the long frames
            results.exposure_short_s = self.short_exposures
        if self.captures is not None:  # detected on an earlier run's images
            results.captures_from = str(self.captures.folder)
        if self.save_images:
            write_image_hashes(stage / IMAGE_HASHES_FILE, self.image_sha256)
        (stage / "detections.json").write_bytes(detections_bytes)
        (stage / "groundtruth.json").write_text(json.dumps(groundtruth))
        write_results(stage / "results.json", results)
        return results


def camera_record(camera) -> CameraRecord:
    """results.json's ``camera``: name, headline numbers, focal length and field of view,
    MTF50 on the sensor (cycles/mm, :func:`benchmark.measure.mtf.camera_mtf50`) and in object
    space (cycles/mrad: × focal length / 1000, what compares cameras of different focal
    lengths), the spec sha256 and the spec."""
    from benchmark.measure.mtf import camera_mtf50

    mtf50, source = camera_mtf50(camera)
    angular = camera.cy_per_mrad(mtf50)
    return CameraRecord(name=camera.name, pixel_um=camera.pixel_um, f_number=camera.f_number,
                        width_px=camera.width_px, height_px=camera.height_px,
                        focal_length_mm=camera.optics.focal_length_mm,
                        fov_deg=[round(camera.hfov_deg, 4), round(camera.vfov_deg, 4)],
                        mtf50_cy_per_mm=None if mtf50 is None else round(mtf50, 2),
                        mtf50_cy_per_mrad=None if angular is None else round(angular, 4), mtf50_source=source,
                        spec_sha256=camera.sha256(), spec=camera.model_dump(mode="json"))


def _finite_or_none(value: float) -> float | None:
    return round(float(value), 3) if np.isfinite(value) else None
