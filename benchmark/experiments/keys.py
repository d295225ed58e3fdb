"""The cache keys of benchmark.experiments, in one place: what each decides and what invalidates it.

Each key is a plain dict (a tuple for :func:`grid_key`) compared with, or stored in, files that
earlier runs wrote: a change to what a builder returns (a field, a name, an order of a list)
silently invalidates every cache made before it, so its bytes are kept as they were.

- :func:`capture_key`: whether two runs' camera images are interchangeable (``read_captures``,
  ``benchmark sweep --captures-from``): camera spec sha256, condition, collection manifest
  sha256, seed, composite, and where present the camera's geometry (a window of the field),
  the collection subset and a read-time condition's definition. Any of them changed: the
  images are simulated again. :func:`results_capture_key` is the same key read back from a
  ``results.json``.
- :func:`run_key`: the sweep's run cache (``out_dir/runs/<run>/results.json``): the capture
  key plus the detector's model sha256, input size and class map. :func:`results_key` reads
  it back; a run folder of another key (or one naming no detector) is redone.
- :func:`resume_key`: a run's resumable stage (:mod:`benchmark.experiments.run_folder`): the
  capture key, the detectors (model, input size, class map; the run's own first), whether it
  saves images and the captures it reads. A stage of another key is started afresh.
- :func:`grid_key`: not stored; which cameras share one resample of a scene's radiance in a
  run of several cameras (pixel grid, pixel pitch, focal length, distortion).
- :func:`factor_unit_key`: a ``benchmark paper-factors`` unit file (``units/<camera>-envNNN.json``):
  the table format, manifest sha256, camera sha256, environment, its scenes, the rows'
  configuration and the seed. Another key: the unit is run again.
"""

from __future__ import annotations

from typing import TYPE_CHECKING

from benchmark.experiments.collection_view import COMPOSITE, camera_geometry, condition_spec

if TYPE_CHECKING:
    from benchmark.result_files import RunResults



PAPER_FACTORS_FORMAT = "metricscenes-paper-factors/1"
"""The format of `benchmark paper-factors`' table and of its units' keys (a new one invalidates them)."""

def capture_key(camera, condition: str, collection, seed: int) -> dict:
    """What makes two runs' camera images interchangeable: camera spec sha256, condition,
    collection manifest sha256, seed, and the camera's geometry and the collection subset
    where present (the detector is not part of it)."""

    key = {"camera_spec_sha256": camera.sha256(), "condition": condition,
           "manifest_sha256": collection.manifest_sha256, "seed": int(seed), "composite": COMPOSITE}
    geometry = camera_geometry(collection, camera)
    if geometry is not None:
        key["camera_geometry"] = geometry
    subset = getattr(collection, "subset", None)
    if subset:
        key["subset"] = subset
    spec = condition_spec(collection, condition)
    if spec is not None:  # a read-time condition: its definition is not in the manifest's hash
        key["condition_spec"] = spec
    return key


def results_capture_key(results: RunResults) -> dict:
    """The :func:`capture_key` a ``results.json`` was made with."""
    key = {"camera_spec_sha256": results.camera.spec_sha256, "condition": results.condition,
           "manifest_sha256": results.collection.manifest_sha256, "seed": results.seed,
           "composite": results.composite}
    if results.camera_geometry is not None:
        key["camera_geometry"] = results.camera_geometry.model_dump()
    if results.subset is not None:
        key["subset"] = results.subset.model_dump()
    if results.condition_spec is not None:
        key["condition_spec"] = results.condition_spec
    return key


def resume_key(camera, condition: str, collection, seed: int, detectors: list, save_images: bool,
               captures) -> dict:
    """What a staged run's scenes depend on: its capture key, the detectors' model and input
    sizes (the own first), whether it saves images and the captures it reads. A stage of
    another key is not resumed."""
    return {"capture": capture_key(camera, condition, collection, seed),
            "detectors": [[d.sha256, str(d.input_size), repr(getattr(d, "class_map", None))] for d in detectors],
            "save_images": bool(save_images), "captures": None if captures is None else str(captures)}


def grid_key(camera) -> tuple:
    """What a camera's resampled radiance depends on besides the scene: its pixel grid,
    field and distortion (cameras with equal keys share one resample)."""
    return (camera.width_px, camera.height_px, camera.pixel_um, camera.optics.focal_length_mm,
            camera.optics.distortion)


def run_key(camera, condition: str, detector, collection, seed: int) -> dict:
    """What makes two runs interchangeable (the cache key): what made the camera's images
    (:func:`capture_key`; a camera that sees a window of the
    collection's field adds its geometry, so runs made before cameras had their own field of
    view are redone, while the registry cameras' keys are unchanged) and the detector."""
    key = {**capture_key(camera, condition, collection, seed),
           "model_sha256": detector.sha256, "input_size": str(detector.input_size)}
    if getattr(detector, "class_map", None) is not None:  # the same model file read through another class map
        from benchmark.detectors.classmap import class_map_names

        key["class_map"] = class_map_names(detector.class_map)
    return key


def results_key(results: RunResults) -> dict | None:
    """The cache key recorded in a ``results.json`` (None for one that names no detector: never reused)."""
    if results.detector is None:
        return None
    key = {**results_capture_key(results),
           "model_sha256": results.detector.sha256, "input_size": str(results.detector.input_size)}
    if results.detector.class_map is not None:
        key["class_map"] = results.detector.class_map
    return key


def factor_unit_key(collection_sha: str, camera, env: int, scene_ids, rows_config, seed: int) -> dict:
    """What one unit of ``benchmark paper-factors`` (a camera × an environment through every row) was
    made with; a unit file under ``units/`` of another key is redone."""

    return {"format": PAPER_FACTORS_FORMAT, "manifest_sha256": collection_sha, "camera": camera.sha256(),
            "environment": env, "scenes": list(scene_ids), "rows": rows_config, "seed": seed}
