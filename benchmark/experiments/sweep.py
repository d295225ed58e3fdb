"""Every camera × condition on one collection: a tidy AP table and OD50 ± SD per run.

Each (camera, condition) pair is one run in ``out_dir/runs/<camera>-<condition>/``
(``<camera>-<condition>+<policy>/`` where a ``--exposure`` policy changed the camera's own, e.g. ``cam01-day+hdr-16``, so that sweeps
of several policies share one folder without overwriting). Runs are cached: a run folder whose
``results.json`` carries the same key — camera spec sha256, condition, detector sha256
and input size, collection manifest sha256, seed — is reused, not recomputed.
A collection subset (:class:`benchmark.experiments.subset.CollectionSubset`, ``--environments`` /
``--distances``) adds ``subset`` to the key and ``+subset-<hash>`` to the folder name.
A run writes ``results.json`` last, so a sweep that was killed resumes with
only its missing (or stale) runs. A condition's missing runs are done together, scene by
scene (:func:`benchmark.experiments.run.run_cameras`: each scene read once, resampled once per
pixel grid), in as many groups of cameras as the backend runs at once (:func:`camera_groups`;
on a running cluster, one group per pixel grid);
a group killed midway resumes at its next scene (each run's resumable stage:
:func:`benchmark.experiments.run_folder.resumable_stage`), with the same bytes. The groups may go to worker processes or a dask cluster
(``workers``, ``scheduler``: :mod:`metricscenes.backends`); each run writes only its own run
folder, and the sweep's tables are written here, in camera × condition order, so their bytes
do not depend on where the runs ran.

Outputs (DESIGN §4; Liu et al., EI 2023, Figs. 5-7), their schemas in :mod:`benchmark.result_files`:

- ``sweep.csv`` / ``sweep.json``: one row per camera × condition × distance with
  ``camera, pixel_um, f_number, mtf50_cy_per_mm, mtf50_source, condition, distance_m,
  ap, ap50, n_images, focal_length_mm, mtf50_cy_per_mrad`` (:class:`~benchmark.result_files.SweepRow`;
  sweep.json: :class:`~benchmark.result_files.SweepRecord`);
- ``od50.csv``: one row per camera × condition with OD50, its bootstrap SD over
  environments and the 95 % percentile interval, and the same for the AP range (area under
  AP vs distance) (:func:`benchmark.scoring.bootstrap_od50`;
  :class:`~benchmark.result_files.Od50Row`). Tables mark a figure from fewer than
  :data:`benchmark.scoring.MIN_ENVIRONMENTS` environments with :data:`benchmark.scoring.FEW_MARK`.

MTF50 comes from :func:`benchmark.measure.mtf.camera_mtf50` from ``mtf_source`` on: ``measured``
(ISO 12233 slanted edge through the camera), ``analytic`` (diffraction × pixel aperture)
or ``published_group`` (the paper's MTF50 group of a registry camera).
"""

from __future__ import annotations

import json
import os
import warnings
from contextlib import ExitStack, closing
from dataclasses import dataclass
from pathlib import Path
from typing import TYPE_CHECKING, Callable, Iterable

import numpy as np
import pandas as pd

from benchmark.experiments.collection_view import collection_field, collection_widest_field
from benchmark.experiments.keys import results_key, run_key
from benchmark.measure.mtf import MTF50_SOURCES, camera_mtf50
from benchmark.result_files import OD50_COLUMNS, TABLE_COLUMNS  # noqa: F401 (the sweep's columns, named here too)
from benchmark.result_files import (
    SWEEP_FORMAT, CollectionRecord, DetectorRecord, Od50Cache, Od50CacheKey,
    Od50Row, ResultsFileError, RunResults, Subset, SweepExposure, SweepRecord, SweepRow, SweepRun,
    read_od50_cache, read_od50_table, read_results, read_sweep_table, write_od50_cache, write_od50_table,
    write_sweep_record, write_sweep_table,
)
from benchmark.scoring.bootstrap import BOOTSTRAP_RESAMPLES, Od50Bootstrap
from benchmark.scoring.od50 import od50_censoring
from metricscenes.manifest import parse_illuminance_condition

if TYPE_CHECKING:
    from benchmark.camera.spec_exposure import ExposureSpec

# od50.csv's censored: "" (AP crosses 0.5 inside the measured distances), ">" (not yet at the farthest: od50_m is an
# extrapolation, report "> farthest m") or "<" (below 0.5 already at the nearest); see benchmark.scoring.od50


Progress = Callable[[int, int, str], None]


def run_name(camera_name: str, condition: str, exposure_tag: str | None = None) -> str:
    """Folder name of one run under ``out_dir/runs`` (``exposure_tag``: the overriding
    exposure policy's :func:`benchmark.camera.exposure.exposure_tag`). Its parts come from camera
    files and collection manifests, so each must pass :func:`benchmark.experiments.run.check_path_name`."""
    from benchmark.experiments.run import check_path_name

    check_path_name(camera_name, "camera name")
    check_path_name(condition, "condition")
    if exposure_tag:
        check_path_name(exposure_tag, "exposure tag")
    return f"{camera_name}-{condition}" + (f"+{exposure_tag}" if exposure_tag else "")


def captures_for(run_dir: Path, camera, condition: str, collection, seed: int) -> Path | None:
    """``run_dir`` if its images can stand for this run's camera (its capture key, an image
    per scene), else None."""
    from benchmark.experiments.run import read_captures

    try:
        read_captures(run_dir, camera, condition, collection, seed)
    except ValueError:
        return None
    return run_dir


def cached_results(run_dir: Path, key: dict) -> RunResults | None:
    """The results of ``run_dir`` if they are complete and carry ``key``, else None."""
    try:
        results = read_results(Path(run_dir) / "results.json")
    except (OSError, ResultsFileError):
        return None  # missing, half-written or foreign: redo
    if results_key(results) != key:
        return None
    if not all((Path(run_dir) / name).is_file() for name in ("detections.json", "groundtruth.json")):
        return None
    return results


def run_od50(run_dir: Path, *, n_resamples: int, seed: int) -> Od50Bootstrap:
    """Bootstrap OD50 of one run folder, cached in ``od50.json`` next to its detections."""
    from benchmark.scoring import bootstrap_od50

    run_dir = Path(run_dir)
    results = read_results(run_dir / "results.json")
    key = Od50CacheKey(detections_sha256=results.detections_sha256, n_resamples=n_resamples, seed=seed)
    cache = run_dir / "od50.json"
    try:
        stored = read_od50_cache(cache)
        if stored.key == key and None not in (stored.od50.ap_range_m, stored.od50.interval_scale):  # (older: redone)
            return stored.od50
    except (OSError, ResultsFileError):
        pass  # none yet, or unreadable: computed again
    gt = json.loads((run_dir / "groundtruth.json").read_text())
    dets = json.loads((run_dir / "detections.json").read_text())
    with warnings.catch_warnings(), np.errstate(invalid="ignore"):
        warnings.simplefilter("ignore", RuntimeWarning)  # inf - inf of resamples whose OD50 is infinite
        out = bootstrap_od50(gt, dets, n_resamples=n_resamples, seed=seed, backend=results.scoring_backend)
    write_od50_cache(cache, Od50Cache(key=key, od50=out))
    return out


@dataclass(frozen=True)
class SweepUnit:
    """One unit of a sweep: several cameras' runs under one condition, computed together in
    whichever process the sweep's backend gives it (:func:`compute_runs`). Everything the unit
    writes is in ``run_dirs`` (``od50.json`` too), which no other unit touches; ``captures``
    (another sweep's run folders, one per camera or None) are only read; ``also`` ({input size:
    run folders}) holds the runs of the detector's other passes; ``group_luminances``: a
    targeted condition's light-group luminances measured already (:func:`shared_group_luminances`)."""

    collection: object
    cameras: list
    condition: str
    detector: object
    run_dirs: list[Path]
    seed: int
    save_images: bool
    backend: str
    n_resamples: int
    progress: object = None
    captures: list[Path | None] | None = None
    also: dict | None = None
    group_luminances: dict | None = None


def compute_runs(unit: SweepUnit) -> list[tuple[str, str, RunResults]]:
    """A unit's runs (:func:`benchmark.experiments.run.run_cameras`: each scene read once for all
    its cameras) and their bootstrap OD50s. Returns (camera name, condition, results) per camera."""
    from benchmark.experiments import run as run_module
    from metricscenes.store import remember_group_luminances

    remember_group_luminances(unit.group_luminances or {})
    results = run_module.run_cameras(unit.collection, unit.cameras, unit.condition, unit.detector, unit.run_dirs,
                                     seed=unit.seed, save_images=unit.save_images, backend=unit.backend,
                                     progress=unit.progress, captures=unit.captures, also=unit.also)
    for run_dir in [*unit.run_dirs, *(d for dirs in (unit.also or {}).values() for d in dirs)]:
        run_od50(run_dir, n_resamples=unit.n_resamples, seed=unit.seed)  # cached in the run folder for the table
    return [(camera.name, unit.condition, r) for camera, r in zip(unit.cameras, results)]


def measure_group_luminances(collection, scene_ids: list[str], conditions: list[str]) -> dict[str, dict]:
    """One share of :func:`shared_group_luminances`, in whichever process the backend gives it."""
    return {condition: collection.group_luminances(scene_ids, condition) for condition in conditions}


def shared_group_luminances(collection, conditions: list[str], *, workers: int,
                            scheduler: str | None) -> dict[str, dict]:
    """{condition: its group luminances}: those the targeted ``conditions`` (the paper's night,
    ``day_paper``) weigh in every scene, each measured once, the scenes shared among the
    backend's workers a few environments each. Without them every unit of such a condition
    measures every scene again (a whole scene read and resampled onto the reference grid per
    light group: 2.8 core-s a scene for the paper's night on metric-300, here, in each unit)."""
    from metricscenes.backends import map_units

    targeted = [c for c in conditions if collection.is_targeted(c)]
    if not targeted:
        return {}
    scenes = collection.scenes()
    environments = sorted({s.environment_id for s in scenes})
    # (an environment's scenes together: its plate, which all six share, is read by one worker)
    shares = [[s.scene_id for s in scenes if s.environment_id in part]
              for part in np.array_split(np.array(environments), min(len(environments), 4 * max(1, workers)))]
    out: dict[str, dict] = {condition: {} for condition in targeted}
    jobs = [(collection, share, targeted) for share in shares if share]
    with closing(map_units(measure_group_luminances, jobs, workers=workers, scheduler=scheduler)) as measured:
        for part in measured:
            for condition, values in part.items():
                out[condition].update(values)
    return out


def camera_groups(cameras: list, n_groups: int) -> list[list]:
    """The cameras split into at most ``n_groups`` groups of about equal pixel counts (largest
    first, each to the lightest group), cameras of one pixel grid always together so that a
    scene's resample serves them all; deterministic, cameras in their given order within a grid."""
    from benchmark.experiments.keys import grid_key

    grids: dict[tuple, list] = {}
    for camera in cameras:
        grids.setdefault(grid_key(camera), []).append(camera)
    groups: list[list] = [[] for _ in range(max(1, min(n_groups, len(grids))))]
    load = [0] * len(groups)
    for same_grid in sorted(grids.values(), key=lambda cs: -sum(c.width_px * c.height_px for c in cs)):
        lightest = load.index(min(load))
        groups[lightest].extend(same_grid)
        load[lightest] += sum(c.width_px * c.height_px for c in same_grid)
    return [g for g in groups if g]


def sweep(collection, cameras: Iterable, conditions: Iterable[str], detector, out_dir, *, seed: int = 0,
          n_resamples: int = BOOTSTRAP_RESAMPLES, progress: Progress | None = None, mtf_source: str = "measured",
          backend: str = "faster-coco-eval", save_images: bool = True,
          exposure: ExposureSpec | None = None, workers: int = 1, scheduler: str | None = None,
          captures_from: str | os.PathLike | None = None, also: dict | None = None) -> pd.DataFrame:
    """Run every camera × condition (reusing cached runs); write and return the AP table.

    Args:
        collection: a :class:`metricscenes.store.Collection` or its folder.
        cameras: :class:`CameraSpec` s or names/paths accepted by ``load_camera``.
        conditions: condition names of the collection (``day``, ``night``, ...).
        detector: a loaded detector (:func:`benchmark.detectors.load_detector`).
        out_dir: sweep folder; runs go to ``out_dir/runs/<camera>-<condition>``. It is stamped
            (``sweep.started``) when the sweep starts, so that commands take it for a sweep
            folder while it runs (:mod:`metricscenes.outputs`); a sweep that fails before
            writing any run leaves nothing of it (nor of ``also``'s).
        seed: sensor-noise seed of every run and the bootstrap seed.
        n_resamples: bootstrap resamples of OD50 (over environments).
        progress: optional ``(done, total, label)`` callable; units are scenes, a cached
            run advances by all its scenes at once (a group of runs on a pool or cluster, by
            all of theirs).
        mtf_source: ``measured`` | ``analytic`` | ``published_group`` (see :func:`benchmark.measure.mtf.camera_mtf50`).
        exposure: an :class:`ExposureSpec` replacing every camera's exposure block (None:
            each camera's own); it changes the spec sha256 (the cache key) and tags the
            folders of the runs it changed (:func:`run_name`).
        workers, scheduler: where the runs that are not cached go
            (:func:`metricscenes.backends.map_units`): one after another here (default),
            ``workers`` processes, or dask (``scheduler`` ``local`` or ``tcp://HOST:PORT``).
            The detector is pickled as what builds it and loaded again in each worker. The
            outputs do not depend on these (``results.json`` ``timing_s`` aside).
        captures_from: another sweep folder on the same collection (another detector or
            input size): a run whose camera images it holds (same camera, condition,
            collection and seed; :func:`captures_for`) detects on them instead of simulating
            the camera again. Same detections either way; ``results.json`` records
            ``captures_from``.
        also: {input size: sweep folder} for the single-pass policies whose passes the
            detector runs (``detector.pass_policies()``: native and 640 for multiscale):
            each folder gets the sweep a detector of that input size would write (runs,
            tables, sweep.json; ``timing_s`` aside), from the same captures and inference.
            A run is computed where it is missing from any of the folders.

    Returns:
        The tidy table of ``sweep.csv`` (columns :data:`TABLE_COLUMNS`).
    """
    from benchmark.experiments import keys
    from benchmark.experiments import run as run_module
    from benchmark.experiments.subset import subset_tag
    from benchmark.experiments.run_folder import remove_finished_leftovers
    from benchmark.camera.pipeline import camera_window
    from benchmark.camera import load_camera
    from benchmark.camera.exposure import check_exposure_override, exposure_tag, with_exposure
    from benchmark.detectors.policy import parse_input_size
    from metricscenes.backends import check_scheduler, is_remote, map_units, runs_in_process
    from metricscenes.files import write_atomic
    from metricscenes.lock import output_lock
    from metricscenes.outputs import SWEEP_STAMP, SWEEP_STAMP_TEXT
    from metricscenes.store import Collection

    if mtf_source not in MTF50_SOURCES:
        raise ValueError(f"mtf_source must be one of {', '.join(MTF50_SOURCES)}, got {mtf_source!r}")
    if isinstance(collection, (str, os.PathLike)):
        collection = Collection.open(collection)
    own = [c if hasattr(c, "sha256") else load_camera(c) for c in cameras]
    for camera in own:  # a two-frame policy on an HDR pixel: refused before anything runs
        check_exposure_override(camera, exposure)
    cameras = [with_exposure(c, exposure) for c in own]
    # A run folder is tagged only where the policy changed the camera: cam01-day always
    # holds the camera's own spec, and `--exposure auto_peak` reuses the reference runs.
    tags = {c.name: exposure_tag(exposure) if c.exposure != o.exposure else None for c, o in zip(cameras, own)}
    subset = getattr(collection, "subset", None)
    # A subset's runs live in their own folders (cam01-day+subset-1a2b3c4d): a quick try never overwrites a full run.
    suffix = f"+{subset_tag(subset)}" if subset else ""
    conditions = list(conditions)
    if not cameras or not conditions:
        raise ValueError("sweep needs at least one camera and one condition")
    known = list(collection.condition_names)  # with the illuminance sweep's
    for condition in conditions:
        if condition not in known:
            from benchmark.suggest import did_you_mean

            raise ValueError(f"unknown condition {condition!r} (this collection has: {', '.join(known)})"
                             f"{did_you_mean(condition, known)}")
    names = [c.name for c in cameras]
    if len(set(names)) != len(names):
        raise ValueError(f"camera names must be unique, got {names}")
    field = collection_field(collection)
    for camera in cameras:  # every run folder name and camera field is valid before anything is written
        camera_window(camera, field, collection_widest_field(collection))
        for condition in conditions:
            run_name(camera.name, condition, tags[camera.name])
    check_scheduler(scheduler)
    out_dir = run_module.check_out_dir(out_dir)
    if captures_from is not None and Path(captures_from).resolve() == out_dir.resolve():
        raise ValueError(f"--captures-from {captures_from} is the sweep folder itself: name another sweep's folder")
    also = {parse_input_size(size): run_module.check_out_dir(folder, "--also-input-size")
            for size, folder in (also or {}).items()}
    run_module.check_pass_policies(detector, also)
    for size, folder in also.items():
        others = [out_dir, *([Path(captures_from)] if captures_from is not None else []),
                  *(f for s, f in also.items() if s != size)]
        if any(folder.resolve() == other.resolve() for other in others):
            raise ValueError(f"the sweep folder for input size {size}, {folder}, is another of this sweep's folders")
    environments = {s.environment_id for s in collection.scenes()}
    if len(environments) < 2:  # refused before any run, not after all of them
        raise ValueError(f"a sweep needs two or more environments (OD50's SD is a bootstrap over them), this "
                         f"{'subset' if subset else 'collection'} has {len(environments)}: use `benchmark run` for one")
    detectors = {None: detector, **{size: detector.with_input_size(size) for size in also}}
    folders = {None: out_dir, **also}
    made = {folder: [p for p in (folder, *folder.absolute().parents) if not p.exists()] for folder in folders.values()}
    locked: list[Path] = []
    try:
        with ExitStack() as held:
            for folder in folders.values():
                folder.mkdir(parents=True, exist_ok=True)
                held.enter_context(output_lock(folder, "benchmark sweep", "sweep folder"))  # one sweep writes a folder at a time
                locked.append(folder)
                if not (folder / SWEEP_STAMP).is_file():  # a sweep folder from now on, not only once its tables are written
                    write_atomic(folder / SWEEP_STAMP, SWEEP_STAMP_TEXT)
                (folder / "runs").mkdir(parents=True, exist_ok=True)

            n_scenes = len(collection.scenes())
            total, done = n_scenes * len(cameras) * len(conditions), 0
            run_names = {(camera.name, condition): run_name(camera.name, condition, tags[camera.name]) + suffix
                         for camera in cameras for condition in conditions}
            run_dirs = {(size, *k): folders[size] / "runs" / name for size in folders for k, name in run_names.items()}
            results: dict[tuple, RunResults] = {}

            def captures(camera, condition: str) -> Path | None:
                if captures_from is None:
                    return None
                return captures_for(Path(captures_from) / "runs" / run_names[camera.name, condition],
                                    camera, condition, collection, seed)

            def resume_key(camera, condition: str) -> dict:  # what the stage of this camera's runs is keyed by
                return keys.resume_key(camera, condition, collection, seed, list(detectors.values()),
                                             save_images, captures(camera, condition))

            todo = []
            for camera in cameras:
                for condition in conditions:
                    cached = {size: cached_results(run_dirs[size, camera.name, condition],
                                                   run_key(camera, condition, d, collection, seed))
                              for size, d in detectors.items()}
                    if any(r is None for r in cached.values()):  # (a missing policy's run: all of them again)
                        todo.append((camera, condition))
                        continue
                    results.update({(size, camera.name, condition): r for size, r in cached.items()})
                    done += n_scenes
                    for size in detectors:  # what a kill just after the run's files moved into place left
                        remove_finished_leftovers(run_dirs[size, camera.name, condition],
                                                  lambda: resume_key(camera, condition))
            reused = {(camera_name, condition) for size, camera_name, condition in results}
            if progress:  # before any unit: a log estimates the time left from what is done after this count
                progress(done, total, f"{len(reused)} runs cached")

            in_process = runs_in_process(workers, scheduler)

            def scene_progress(label: str, n_cameras: int):
                # (runs computed here report each scene; ``done`` is read when called: the runs before them)
                return (lambda d, t: progress(done + d * n_cameras, total, label)) if progress and in_process else None

            # One unit per condition and group of cameras: each scene is read once per unit, and once
            # per pixel grid resampled; as many groups as the backend runs units at once.
            luminances = {} if in_process else shared_group_luminances(
                collection, sorted({c for _, c in todo}), workers=workers, scheduler=scheduler)
            jobs = []
            for condition in conditions:
                pending = [camera for camera, c in todo if c == condition]
                # (a running cluster's size is its own business: there, one group per pixel grid)
                n_groups = 1 if in_process else len(pending) if is_remote(scheduler) else max(1, workers)
                for group in camera_groups(pending, n_groups):
                    label = f"{'+'.join(c.name for c in group)} · {condition}"
                    jobs.append((SweepUnit(
                        collection, group, condition, detector, [run_dirs[None, c.name, condition] for c in group],
                        seed, save_images, backend, n_resamples, progress=scene_progress(label, len(group)),
                        captures=[captures(c, condition) for c in group],
                        also={size: [run_dirs[size, c.name, condition] for c in group] for size in also},
                        group_luminances=luminances.get(condition)),))
            with closing(map_units(compute_runs, jobs, workers=workers, scheduler=scheduler)) as finished:
                for finished_runs in finished:  # in the order they finish
                    for camera_name, condition, run_results in finished_runs:
                        results[None, camera_name, condition] = run_results
                        for size in also:  # (written by the unit, read back here)
                            results[size, camera_name, condition] = read_results(run_dirs[size, camera_name, condition]
                                                                                 / "results.json")
                    done += n_scenes * len(finished_runs)
                    if progress:
                        progress(done, total, f"{'+'.join(name for name, _, _ in finished_runs)} · {finished_runs[0][1]}")

            tables = {size: _write_sweep(folders[size], collection, cameras, conditions, detectors[size],
                                         {k[1:]: r for k, r in results.items() if k[0] == size},
                                         {k[1:]: d for k, d in run_dirs.items() if k[0] == size}, reused,
                                         seed=seed, n_resamples=n_resamples, mtf_source=mtf_source, backend=backend,
                                         subset=subset, exposure=exposure)
                      for size in folders}
            return tables[None]
    except BaseException:
        for folder in locked:  # (never a folder another sweep holds)
            _remove_if_unused(folder, made[folder])
        raise


def _remove_if_unused(folder: Path, made: list[Path]) -> None:
    """What a sweep that failed before it wrote any run leaves of ``folder``: its empty
    ``runs/``, its stamp where nothing else is there, and the folders it created (``made``,
    innermost first) where empty. A folder that holds a run, a stage or a table is kept."""
    from metricscenes.outputs import SWEEP_STAMP

    for remove in (lambda: (folder / "runs").rmdir(),
                   lambda: [p.name for p in folder.iterdir()] == [SWEEP_STAMP] and (folder / SWEEP_STAMP).unlink(),
                   *(p.rmdir for p in made)):
        try:
            remove()
        except OSError:
            return

def _write_sweep(out_dir: Path, collection, cameras: list, conditions: list[str], detector, results: dict,
                 run_dirs: dict, reused: set, *, seed: int, n_resamples: int, mtf_source: str, backend: str,
                 subset, exposure) -> pd.DataFrame:
    """A sweep folder's tables (sweep.csv, od50.csv) and sweep.json from its runs' results and
    folders ({(camera, condition): ...}); returns the AP table."""
    from benchmark.camera.exposure import exposure_tag, format_exposure

    rows, od50_rows, runs = [], [], []
    for camera in cameras:
        mtf50, source = camera_mtf50(camera, mtf_source)
        ident = {"camera": camera.name, "pixel_um": camera.pixel_um, "f_number": camera.f_number,
                 "mtf50_cy_per_mm": mtf50, "mtf50_source": source,  # mtf50 None: NaN in the tables
                 "focal_length_mm": camera.optics.focal_length_mm, "mtf50_cy_per_mrad": camera.cy_per_mrad(mtf50)}
        for condition in conditions:
            run_dir, run_results = run_dirs[camera.name, condition], results[camera.name, condition]
            runs.append(SweepRun(camera=camera.name, condition=condition, path=str(run_dir.relative_to(out_dir)),
                                 reused=(camera.name, condition) in reused))
            for r in run_results.per_distance:
                rows.append(SweepRow(**ident, condition=condition, distance_m=r.distance_m, ap=r.ap, ap50=r.ap50,
                                     n_images=r.n_images))
            boot = run_od50(run_dir, n_resamples=n_resamples, seed=seed)
            lo, hi = boot.ci95_m
            range_lo, range_hi = boot.ap_range_ci95_m
            od50_rows.append(Od50Row(**ident, condition=condition, od50_m=boot.od50_m, sd_m=boot.sd_m, ci95_lo_m=lo,
                                     ci95_hi_m=hi, n_resamples=boot.n_resamples, n_environments=boot.n_environments,
                                     n_infinite=boot.n_infinite, censored=run_results.od50_censoring()[0],
                                     ap_range_m=boot.ap_range_m, ap_range_sd_m=boot.ap_range_sd_m,
                                     ap_range_ci95_lo_m=range_lo, ap_range_ci95_hi_m=range_hi))

    table = write_sweep_table(out_dir / "sweep.csv", rows)
    od50_table = write_od50_table(out_dir / "od50.csv", od50_rows)
    record = SweepRecord(
        format=SWEEP_FORMAT,
        collection=CollectionRecord(name=collection.name, manifest_sha256=collection.manifest_sha256,
                                    path=str(collection.root)),
        detector=DetectorRecord(name=detector.name, sha256=detector.sha256, input_size=str(detector.input_size)),
        seed=seed, n_resamples=n_resamples, mtf_source=mtf_source, scoring_backend=backend,
        cameras=[c.name for c in cameras], conditions=conditions, runs=runs,
        # the rows as the tables hold them (pandas' dtypes), as sweep.json has always written them
        table=table.to_dict(orient="records"), od50=od50_table.to_dict(orient="records"),
    )
    if subset:  # a quick try on part of the collection (other sweeps keep their bytes)
        record.subset = Subset(**subset)
    if exposure is not None:  # only then, so that other sweeps keep their bytes
        record.exposure = SweepExposure(policy=format_exposure(exposure), tag=exposure_tag(exposure),
                                        spec=exposure.model_dump(mode="json"))
    write_sweep_record(out_dir / "sweep.json", record)
    return table


def illuminance_table(table: pd.DataFrame) -> pd.DataFrame:
    """The illuminance-sweep rows of a sweep table with ``base_condition`` and
    ``illuminance_lux`` columns (the input of :func:`benchmark.experiments.spm.spm_illuminance`)."""
    parsed = table["condition"].map(parse_illuminance_condition)
    part = table[parsed.notna()].copy()
    part["base_condition"] = [p[0] for p in parsed[parsed.notna()]]
    part["illuminance_lux"] = [p[1] for p in parsed[parsed.notna()]]
    return part


def load_sweep(out_dir) -> tuple[pd.DataFrame, pd.DataFrame]:
    """(AP table, OD50 table) of a sweep folder (``sweep.csv``, ``od50.csv``)."""
    out_dir = Path(out_dir)
    table = read_sweep_table(out_dir / "sweep.csv")
    return table, with_censoring(read_od50_table(out_dir / "od50.csv"), table)


def with_censoring(od50: pd.DataFrame, table: pd.DataFrame) -> pd.DataFrame:
    """``od50`` with ``censored`` ("", ">", "<") and ``bound_m`` (the farthest or nearest measured
    distance where censored, else NaN) derived from the AP table's per-distance AP, so that
    sweeps written before the ``censored`` column show their bounds too."""
    od50 = od50.copy()
    censored, bounds = [], []
    groups = {key: part for key, part in table.groupby(["camera", "condition"], sort=False)}
    for cam, cond in od50[["camera", "condition"]].itertuples(index=False):
        part = groups.get((cam, cond))
        c, bound = ("", None) if part is None or len(part) < 2 else od50_censoring(part["distance_m"], part["ap"])
        censored.append(c)
        bounds.append(float("nan") if bound is None else bound)
    od50["censored"], od50["bound_m"] = censored, bounds
    return od50


def od50_cell(row) -> str:
    """One od50.csv row for people: "123.4 ± 5.6", "> 200" or "< 25" (censored: a bound), "∞";
    "†" appended where it rests on too few environments (:func:`benchmark.scoring.mark_few`)."""
    from benchmark.scoring import mark_few
    from benchmark.scoring.od50 import format_od50

    censored = str(row.get("censored", "") or "")
    bound = row.get("bound_m")
    bound = None if bound is None or bound != bound else float(bound)
    return mark_few(format_od50(row["od50_m"], censored, bound, row.get("sd_m"), unit=""), row.get("n_environments"))


def ap_range_cell(row) -> str:
    """The AP range of one od50.csv row for people: "156.8 ± 4.1" ("–" in sweeps written before
    it was recorded), marked as :func:`od50_cell` is."""
    from benchmark.scoring import mark_few

    value, sd = row.get("ap_range_m"), row.get("ap_range_sd_m")
    if value is None or value != value:
        return "–"
    text = f"{float(value):.1f}" + (f" ± {float(sd):.1f}" if sd is not None and sd == sd else "")
    return mark_few(text, row.get("n_environments"))
