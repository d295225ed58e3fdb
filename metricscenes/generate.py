"""Render a collection: plan, render every unit of work, write the store.

Units of work are the plates (one per environment: its background without the car,
once per light group) and the insets (one per scene: a window around the car at
finer angular sampling, once per light group, plus a whole frame of the car's own
lamps at plate sampling, since their light reaches far beyond the window). Each unit writes its own zarr arrays
and then a small record under ``progress/``; a rerun skips units whose record exists
and whose arrays still match the record's sha256 (a damaged or deleted array is
rendered again), so a killed run resumes and a damaged collection is repaired, and
because every unit is a pure function of the manifest the result is bit-identical to
an uninterrupted run, whatever the number of workers.
"""

from __future__ import annotations

import hashlib
import json
import math
import os
import time
from contextlib import closing
from dataclasses import asdict, dataclass
from pathlib import Path

import numpy as np
import yaml

from metricscenes import __version__
from metricscenes.backends import check_scheduler, is_remote, map_units, threads_per_unit
from metricscenes.files import write_atomic
from metricscenes.geometry import TanExtent
from metricscenes.groundtruth import box_iou, box_tan_to_xywh, car_box_tan, coco_groundtruth, mask_box_tan
from metricscenes.manifest import AUTO_VARIANT, PLATE_LIGHT_GROUPS, Manifest
from metricscenes.plan import EnvironmentPlan, ScenePlan, plan_collection
from metricscenes.store import (
    GROUNDTRUTH_FILE, PROGRESS_DIR, RADIANCE_STORE, RESOLVED_MANIFEST_FILE, CollectionError, read_checked,
    resolved_content_sha256, write_mask, write_radiance,
)

# Margins of the inset window around the car's projected box, as fractions of the box:
# the sides and top catch reflections and antialiasing; the bottom catches the shadow
# and the lamps' footprint on the road.
INSET_MARGIN = {"left": 0.3, "right": 0.3, "top": 0.2, "bottom": 0.6}
VARIANT_STAMP = "render_variant"
"""File under ``progress/`` naming the Mitsuba variant that renders the collection."""


@dataclass(frozen=True)
class Unit:
    kind: str  # 'plate' | 'inset'
    key: str
    environment: EnvironmentPlan
    distance_m: float | None
    seed: int


def plan_units(scenes: list[ScenePlan]) -> list[Unit]:
    units: dict[str, Unit] = {}
    for s in scenes:
        env = s.environment
        units.setdefault(env.key, Unit("plate", env.key, env, None, env.seed))
        units[s.scene_id] = Unit("inset", s.scene_id, env, s.distance_m, s.seed)
    return list(units.values())


def inset_window(box_tan, manifest: Manifest) -> tuple[int, int, int, int, int]:
    """Choose the inset film: scale ``k`` of the reference grid and the crop (x, y, w, h)
    in that film's pixels. ``k`` gives ``inset_pixel_mrad`` sampling unless the window
    would exceed ``inset_max_px`` (near cars, which are large in every camera anyway)."""
    ref_w, ref_h = manifest.reference_grid.width_px, manifest.reference_grid.height_px
    e = manifest.reference_grid.field
    bw, bh = box_tan[2] - box_tan[0], box_tan[3] - box_tan[1]
    x0 = max(e.x0, box_tan[0] - INSET_MARGIN["left"] * bw)
    x1 = min(e.x1, box_tan[2] + INSET_MARGIN["right"] * bw)
    y0 = max(e.y0, box_tan[1] - INSET_MARGIN["top"] * bh)
    y1 = min(e.y1, box_tan[3] + INSET_MARGIN["bottom"] * bh)
    ref_pitch_mrad = 1e3 * e.width / ref_w
    window_ref_px = max((x1 - x0) / e.width * ref_w, (y1 - y0) / e.height * ref_h)
    k_fine = math.ceil(ref_pitch_mrad / manifest.render.inset_pixel_mrad)
    k_cap = math.floor(manifest.render.inset_max_px / max(window_ref_px, 1e-9))
    k = max(1, min(k_fine, k_cap))
    big_w, big_h = ref_w * k, ref_h * k
    cx0 = max(0, math.floor((x0 - e.x0) / e.width * big_w))
    cx1 = min(big_w, math.ceil((x1 - e.x0) / e.width * big_w))
    cy0 = max(0, math.floor((y0 - e.y0) / e.height * big_h))
    cy1 = min(big_h, math.ceil((y1 - e.y0) / e.height * big_h))
    return k, cx0, cy0, cx1 - cx0, cy1 - cy0


def render_unit(manifest_json: dict, unit: Unit, out_dir: str, threads: int | None, variant: str) -> dict:
    """Render and write one unit (runs in a worker process) with the Mitsuba ``variant``
    (the manifest's, ``auto`` resolved); return its progress record."""
    from metricscenes import scene as scene_mod
    from metricscenes.photometry import radiance_to_xyz
    from metricscenes.render import Film, illuminance_meter, render_radiance, use_variant

    manifest = Manifest.model_validate(manifest_json)
    use_variant(variant, threads)
    root = Path(out_dir)
    ref_w, ref_h = manifest.reference_grid.width_px, manifest.reference_grid.height_px
    field = manifest.reference_grid.field
    env = unit.environment
    parts = scene_mod.environment_parts(env)
    record: dict = {"unit": unit.key, "kind": unit.kind, "arrays": {}}
    mantissa_bits = manifest.store.mantissa_bits if manifest.store else None  # None: lossless
    started = time.perf_counter()
    if unit.kind == "plate":
        groups = [g for g in manifest.light_groups if g in PLATE_LIGHT_GROUPS]
        jobs = [("plates", g, Film(ref_w, ref_h, field=field), manifest.render.plate_spp, field) for g in groups]
    else:
        env_parts = parts
        pose = scene_mod.car_pose(env, unit.distance_m)
        parts = parts.merged(scene_mod.car_parts(env, pose))
        film, extent = _inset_film(manifest, scene_mod.car_vertices(env, pose), record)
        record.update(pose=asdict(pose), **_ground_truth(manifest, unit, root, env_parts, parts, film, extent, record))
        jobs = [("insets", g, film, manifest.render.inset_spp, extent) for g in manifest.light_groups]
        if "car_lights" in manifest.light_groups:
            # The car's lamps light the road far outside its inset (an oncoming car's beams
            # reach the camera): that group also gets a whole frame at plate sampling.
            jobs.append(("frames", "car_lights", Film(ref_w, ref_h, field=field), manifest.render.plate_spp, field))
    for i, (kind, group, film, spp, extent) in enumerate(jobs):
        if not scene_mod.has_emitters(parts, group):
            continue
        sd = scene_mod.scene_dict(env, parts, group, film, spp=spp, seed=unit.seed + 7919 * i,
                                  max_depth=manifest.render.max_depth)
        sha = write_radiance(root, kind, unit.key, group, render_radiance(sd, spp), extent,
                             {"spp": spp, "seed": unit.seed}, mantissa_bits)
        record["arrays"][f"{kind}/{unit.key}/{group}"] = sha
        if unit.kind == "plate":
            irradiance = illuminance_meter(sd, seed=unit.seed + 7919 * i)
            record.setdefault("illuminance_lux", {})[group] = round(float(radiance_to_xyz(irradiance)[1]), 9)
    record["seconds"] = round(time.perf_counter() - started, 3)
    return record


def _inset_film(manifest: Manifest, car_vertices_m: np.ndarray, record: dict):
    """The inset's film (a crop of a k-times finer reference film) and its extent in
    tangent coordinates; records the projected car box and k."""
    from metricscenes.render import Film

    ref_w, ref_h = manifest.reference_grid.width_px, manifest.reference_grid.height_px
    box = car_box_tan(car_vertices_m)
    k, cx, cy, cw, ch = inset_window(box, manifest)
    e = manifest.reference_grid.field
    film = Film(ref_w * k, ref_h * k, cx, cy, cw, ch, field=e)
    extent = TanExtent(e.x0 + cx / film.width * e.width, e.y0 + cy / film.height * e.height,
                       e.x0 + (cx + cw) / film.width * e.width, e.y0 + (cy + ch) / film.height * e.height)
    record.update(projected_box_tan=list(box), inset_scale=k)
    return film, extent


def _ground_truth(manifest: Manifest, unit: Unit, root: Path, env_parts, parts, film, extent, record: dict) -> dict:
    """Instance mask (the rays whose first hit moves when the car is added), written to
    the store; returns the mask box and its agreement with the projected mesh box."""
    from metricscenes import scene as scene_mod
    from metricscenes.render import RenderError, render_depth

    group = manifest.light_groups[0]
    depth_with, depth_without = (
        render_depth(scene_mod.scene_dict(unit.environment, p, group, film, spp=1, seed=unit.seed, max_depth=2), film)
        for p in (parts, env_parts))
    mask = (depth_with > 0) & (depth_with != depth_without)
    mask_box = mask_box_tan(mask, extent)
    if mask_box is None:
        raise RenderError(f"{unit.key}: the car is not visible in its inset")
    record["arrays"][f"masks/{unit.key}"] = write_mask(root, unit.key, mask, extent)
    grid = manifest.reference_grid
    return {"box_tan": list(mask_box), "mask_iou": round(box_iou(mask_box, record["projected_box_tan"]), 4),
            "bbox_xywh": box_tan_to_xywh(mask_box, grid.width_px, grid.height_px, grid.field)}


def _progress_path(root: Path, key: str) -> Path:
    return root / PROGRESS_DIR / f"{key}.json"


def _load_record(root: Path, key: str) -> dict | None:
    try:
        record = json.loads(_progress_path(root, key).read_text())
    except (OSError, json.JSONDecodeError):
        return None  # absent or torn: redo the unit
    return record if record.get("unit") == key else None


def _record_problem(root: Path, group, record: dict, manifest: Manifest) -> str | None:
    """Why a finished unit must be rendered again (an array missing, unreadable or not
    the bytes its record names; a mask that does not give the recorded box), or None:
    the progress record is a claim, not proof."""
    key = record["unit"]
    try:
        for path, sha in sorted(record["arrays"].items()):
            read_checked(root, group, path, sha, key)
        if record["kind"] == "inset":  # the box goes into groundtruth.json: it must be the mask's
            path = f"masks/{key}"  # (records written before masks had a sha256 have none for it)
            mask, attrs = read_checked(root, group, path, record["arrays"].get(path), key)
            box = mask_box_tan(mask.astype(bool), TanExtent(*attrs["extent_tan"]))
            grid = manifest.reference_grid
            if (box is None or list(box) != record["box_tan"]
                    or box_tan_to_xywh(box, grid.width_px, grid.height_px, grid.field) != record["bbox_xywh"]):
                return f"{key}: masks/{key} does not give the recorded box"
    except CollectionError as exc:
        return str(exc)
    except (KeyError, TypeError, AttributeError, ValueError):
        return f"{key}: its progress record is incomplete"
    return None


def check_out_dir(out_dir: str | Path) -> Path:
    """Refuse (:class:`CollectionError`, one line) an ``--out`` that cannot hold this
    collection, before anything is created: a file, a path through a file, a folder inside
    another collection, or a folder that holds other files and is not a collection."""
    from metricscenes.lock import LOCK_FILE
    from metricscenes.store import collection_containing, file_in_the_way

    root = Path(out_dir)
    if problem := file_in_the_way(root):
        raise CollectionError(f"{problem}; choose a folder for the collection")
    inside = collection_containing(root)
    if inside is not None and inside != Path(os.path.abspath(root)).resolve():
        raise CollectionError(f"--out {root} is inside the collection {inside}; choose a folder outside it")
    if inside is None and root.is_dir():
        try:
            # (a run killed before its stamp leaves at most its lock and an empty progress/)
            other = sorted(p.name for p in root.iterdir() if p.name != LOCK_FILE
                           and not (p.name == PROGRESS_DIR and p.is_dir() and not any(p.iterdir())))
        except OSError as exc:
            raise CollectionError(f"--out {root}: cannot list it ({exc.strerror})") from None
        if other:
            raise CollectionError(f"--out {root} holds other files ({', '.join(other[:3])}"
                                  f"{', ...' if len(other) > 3 else ''}) and is not a collection; "
                                  "choose a new or empty folder")
    return root


def render_variant(manifest: Manifest, scheduler: str | None = None) -> str:
    """The Mitsuba variant the units will render with, checked where they will run
    (:class:`~metricscenes.render.RenderError`, one line, if it cannot run there): the
    manifest's ``render.variant``, ``auto`` resolved (:func:`metricscenes.render.resolve_variant`)."""
    from metricscenes.render import resolve_variant

    if is_remote(scheduler):  # the cluster's machines render, and this one may have no GPU: ask one of them
        with closing(map_units(resolve_variant, [(manifest.render.variant,)], scheduler=scheduler)) as answer:
            return next(answer)
    return resolve_variant(manifest.render.variant)


def check_before_writing(manifest: Manifest, out_dir: str | Path, workers: int = 1,
                         scheduler: str | None = None) -> Path:
    """Everything that can refuse a run without rendering, before any output exists: the
    ``--out`` folder, the ``--scheduler``, the memory the render needs, the Mitsuba variant."""
    return _checked_root_and_variant(manifest, out_dir, workers, scheduler)[0]


def _checked_root_and_variant(manifest: Manifest, out_dir: str | Path, workers: int,
                              scheduler: str | None) -> tuple[Path, str]:
    """:func:`check_before_writing`, also returning the variant it resolved (on a running
    cluster, resolving it is a round trip to one of its workers)."""
    from metricscenes.manifest import check_memory

    root = check_out_dir(out_dir)
    check_scheduler(scheduler)
    if not is_remote(scheduler):  # a running cluster's workers have their own machines' memory
        check_memory(manifest, workers, source=f"manifest {manifest.name}")
    variant = render_variant(manifest, scheduler)  # an LLVM variant can abort the process, CUDA needs a GPU
    return root, variant


def _has_finished_work(root: Path) -> bool:
    return any((root / PROGRESS_DIR).glob("*.json")) or (root / RESOLVED_MANIFEST_FILE).exists()


def _recorded_variant(root: Path, manifest: Manifest) -> str | None:
    """The variant that rendered the units already in ``root`` (None: unknown)."""
    try:
        return (root / PROGRESS_DIR / VARIANT_STAMP).read_text().strip()
    except OSError:  # collections made before the stamp could only use the variant their manifest names
        return None if manifest.render.variant == AUTO_VARIANT else manifest.render.variant


def _prepare(root: Path, manifest: Manifest, variant: str | None = None) -> None:
    """Stamp ``root`` with the manifest's sha256 and the Mitsuba ``variant`` (default: the
    manifest's, resolved here) and create the store, refusing (:class:`CollectionError`) a
    folder whose finished units came from another manifest or another variant."""
    import zarr

    from metricscenes.render import resolve_variant

    variant = variant or resolve_variant(manifest.render.variant)
    (root / PROGRESS_DIR).mkdir(exist_ok=True)
    stamp = root / PROGRESS_DIR / "manifest_sha256"
    finished = _has_finished_work(root)  # (a run that finished no unit, e.g. a render error, left nothing to keep)
    if finished and stamp.exists() and stamp.read_text().strip() != manifest.sha256():
        raise CollectionError(f"{root}: holds a collection of another manifest; choose another --out or delete it")
    recorded = _recorded_variant(root, manifest)
    if finished and recorded != variant:
        # The same manifest with render.variant: auto, resumed on a machine that resolves it otherwise.
        raise CollectionError(
            f"{root}: rendered with Mitsuba variant {recorded or '(unknown)'}, this run would render with {variant} "
            f"(render.variant: {manifest.render.variant}); finish it where it was started or choose another --out")
    write_atomic(stamp, manifest.sha256() + "\n")
    write_atomic(root / PROGRESS_DIR / VARIANT_STAMP, variant + "\n")
    zroot = zarr.open_group(str(root / RADIANCE_STORE), mode="a")
    zroot.attrs.update({"units": "W sr-1 m-2 nm-1", "manifest_sha256": manifest.sha256(),
                        "dimension_names": ["y", "x", "wavelength"]})
    for name in ("plates", "insets", "frames", "masks"):
        zroot.require_group(name)


def generate(manifest: Manifest, out_dir: str | Path, *, workers: int = 1, threads: int | None = None,
             scheduler: str | None = None, progress=None, notice=None) -> Path:
    """Render ``manifest`` into ``out_dir`` (resuming what is already done, repairing
    what is damaged).

    ``workers`` processes render units in parallel; each uses ``threads`` render
    threads (default: the CPU count divided by the workers). ``scheduler`` runs them on
    dask instead (:mod:`metricscenes.backends`): ``local`` starts a LocalCluster of
    ``workers`` processes, ``tcp://HOST:PORT`` uses that scheduler's cluster (whose
    workers must see ``out_dir`` at the same path; ``threads`` default: each worker's
    CPUs). The bytes do not depend on any of these. ``progress`` is an
    optional callable ``(done, total, unit_key)``; ``notice`` an optional callable that
    gets one line per finished unit found damaged (it is rendered again) and one when a
    stale lock is taken over.

    Before anything is created, :func:`check_before_writing` refuses a bad ``out_dir``, a
    scheduler that cannot be used, a render that would not fit in memory and a Mitsuba
    variant that cannot run here; while it writes, ``generate`` holds ``out_dir/generate.lock``
    (:mod:`metricscenes.lock`), so a second writer on the same folder is refused.
    """
    from metricscenes.lock import collection_lock

    root, variant = _checked_root_and_variant(manifest, out_dir, workers, scheduler)
    root.mkdir(parents=True, exist_ok=True)
    with collection_lock(root, notice=notice):  # one writer at a time; released on errors too
        _generate(manifest, root, variant, workers, threads, scheduler, progress, notice)
    return root


def _generate(manifest: Manifest, root: Path, variant: str, workers: int, threads: int | None,
              scheduler: str | None, progress, notice) -> None:
    import zarr

    _prepare(root, manifest, variant)
    scenes = plan_collection(manifest)
    units = plan_units(scenes)
    records = {u.key: _load_record(root, u.key) for u in units}
    group = zarr.open_group(str(root / RADIANCE_STORE), mode="r")
    for key, record in records.items():
        problem = None if record is None else _record_problem(root, group, record, manifest)
        if problem:
            records[key] = None
            if notice:
                notice(f"rendering {key} again: {problem}")
    todo = [u for u in units if records[u.key] is None]
    threads = threads_per_unit(threads, workers, scheduler)
    manifest_json = manifest.model_dump(mode="json")
    done = len(units) - len(todo)
    if progress:
        progress(done, len(units), None)
    # Units finish in any order; each record is written here, by the client, as it arrives.
    jobs = [(manifest_json, u, str(root), threads, variant) for u in todo]
    with closing(map_units(render_unit, jobs, workers=workers, scheduler=scheduler)) as finished:
        for record in finished:
            write_atomic(_progress_path(root, record["unit"]), json.dumps(record, indent=1, sort_keys=True))
            records[record["unit"]] = record
            done += 1
            if progress:
                progress(done, len(units), record["unit"])
    _finalize(root, manifest, scenes, records, variant)


def _finalize(root: Path, manifest: Manifest, scenes: list[ScenePlan], records: dict[str, dict], variant: str) -> None:
    ref_w, ref_h = manifest.reference_grid.width_px, manifest.reference_grid.height_px
    images, boxes = [], []
    for s in scenes:
        rec = records[s.scene_id]
        env = s.environment
        images.append({
            "id": s.image_id, "file_name": f"{s.scene_id}.png", "width": ref_w, "height": ref_h,
            "scene_id": s.scene_id, "environment_id": env.environment_id, "distance_m": s.distance_m,
            "car_id": env.car_id, "road_id": env.road_id, "heading": env.heading,
            "mask_vs_projection_iou": rec["mask_iou"],
        })
        boxes.append(rec["bbox_xywh"])
    info = {"description": f"metricscenes collection {manifest.name}", "version": __version__,
            "protocol": manifest.protocol, "manifest_sha256": manifest.sha256()}
    gt_text = json.dumps(coco_groundtruth(images, boxes, info), indent=1)
    arrays = {path: sha for key in sorted(records) for path, sha in sorted(records[key]["arrays"].items())}
    resolved = {
        "package_version": __version__,
        "manifest_sha256": manifest.sha256(),
        "manifest": manifest.model_dump(mode="json"),
        "render_variant": variant,  # the Mitsuba variant that rendered the arrays (render.variant: auto resolved)
        "arrays": arrays,
        # Horizontal illuminance at the camera (0, 0, 1.5 m) per environment and light group.
        # (sorted: a record read back from progress/ has sorted keys, one just rendered has not)
        "illuminance_lux": {key: dict(sorted(records[key].get("illuminance_lux", {}).items()))
                            for key in sorted(records) if records[key]["kind"] == "plate"},
        "plan": [s.summary() for s in scenes],
        "groundtruth_sha256": hashlib.sha256(gt_text.encode()).hexdigest(),
    }
    # Last, over all of the above: an edited illuminance or hash is caught on open.
    resolved["content_sha256"] = resolved_content_sha256(resolved)
    write_atomic(root / GROUNDTRUTH_FILE, gt_text)
    write_atomic(root / RESOLVED_MANIFEST_FILE, yaml.safe_dump(resolved, sort_keys=False))
