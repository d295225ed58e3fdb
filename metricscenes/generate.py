"""Render a collection: plan, render every unit of work, write the store.

Units of work are the plates (one per environment: its background without the car,
once per light group) and the insets (one per scene: a window around the car at
finer angular sampling, once per light group, plus a whole frame of the car's own
lamps at plate sampling, since their light reaches far beyond the window). Each unit
writes its own zarr arrays and then a small record under ``progress/``, all through
:class:`metricscenes.writer.CollectionWriter`; a rerun skips units whose record exists
and whose arrays still match the record's sha256 (a damaged or deleted array is
rendered again), so a killed run resumes and a damaged collection is repaired, and
because every unit is a pure function of the manifest the result is bit-identical to
an uninterrupted run, whatever the number of workers.

A run may render some of the manifest's light groups only (``generate --conditions day``:
:func:`requested_light_groups`); a later run with more adds the missing ones to each unit.
A group's render keeps the seed and window it has in a render of all of them, so its
bytes do not depend on which others were rendered with it (:func:`light_groups_to_render`).
"""

from __future__ import annotations

import math
import os
import time
from contextlib import closing
from dataclasses import asdict, dataclass, replace
from pathlib import Path

import numpy as np

from metricscenes.backends import check_scheduler, is_remote, map_units, threads_per_unit
from metricscenes.geometry import TanExtent
from metricscenes.groundtruth import box_iou, box_tan_to_xywh, car_box_tan, mask_box_tan
from metricscenes.manifest import PLATE_LIGHT_GROUPS, WIDE_KINDS, Manifest, ManifestError
from metricscenes.plan import EnvironmentPlan, ScenePlan, plan_collection
from metricscenes.records import PLATE, InsetTruth, RecordError, UnitRecord
from metricscenes.store import PROGRESS_DIR, RADIANCE_STORE, CollectionError, read_checked
from metricscenes.writer import CollectionWriter

# Margins of the inset window around the car's projected box, as fractions of the box:
# the sides and top catch reflections and antialiasing; the bottom catches the shadow
# and the lamps' footprint on the road.
INSET_MARGIN = {"left": 0.3, "right": 0.3, "top": 0.2, "bottom": 0.6}


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


# The road surface the car stands on (metricscenes.assets.roads: paved road at z = 0), onto
# which render.inset_shadow projects the car along its sky's sun or moon.
SHADOW_PLANE_Z_M = 0.0
# A shadow point closer ahead than this is taken at this distance (projected far below the
# field, so the window reaches the field's bottom edge, which clips it).
_SHADOW_MIN_AHEAD_M = 1.0


def shadow_light_directions(env: EnvironmentPlan, light_groups) -> list[tuple[float, float, float]]:
    """Unit vectors (world frame) towards each directional light that casts the car's shadow
    in the rendered sky groups of ``light_groups``: the day sky's sun, the dusk sky's sun only
    if above the horizon (never in the library: its sunsky has no sun disk), the moonlit night
    sky's moon (:mod:`metricscenes.assets.skies`). Lights at or below the horizon add none."""
    from metricscenes.assets import skies

    out = []
    for group, attr in (("sky_day", "sky_day_id"), ("sky_dusk", "sky_dusk_id"), ("sky_night", "sky_night_id")):
        if group not in light_groups:
            continue
        sky = skies.sky_spec(getattr(env, attr))
        if sky.kind in ("day", "dusk") and sky.sun_elevation_deg > 0.0:
            out.append(tuple(skies._direction(sky.sun_elevation_deg, sky.sun_azimuth_deg)))
        if sky.kind == "night" and sky.moon_normal_illuminance_lux > 0.0 and sky.moon_elevation_deg > 0.0:
            out.append(tuple(skies._direction(sky.moon_elevation_deg, sky.moon_azimuth_deg)))
    return out


def shadow_vertices(vertices_world_m: np.ndarray, towards_light, plane_z_m: float = SHADOW_PLANE_Z_M) -> np.ndarray:
    """The car's vertices projected along the light (``towards_light``: a direction to the
    source, above the horizon) onto the plane z = ``plane_z_m``: their shadow's points."""
    v = np.asarray(vertices_world_m, dtype=np.float64)
    d = np.asarray(towards_light, dtype=np.float64)
    if d[2] <= 0.0:
        raise ValueError(f"the light must be above the horizon, got direction {tuple(d)}")
    height = np.maximum(v[:, 2] - plane_z_m, 0.0)  # (vertices under the plane stay where they are)
    out = v - height[:, None] * (d / d[2])[None, :]
    out[:, 2] = np.where(v[:, 2] > plane_z_m, plane_z_m, v[:, 2])
    out[:, 0] = np.maximum(out[:, 0], _SHADOW_MIN_AHEAD_M)
    return out


def shadow_box_tan(manifest: Manifest, env: EnvironmentPlan, car_vertices_m: np.ndarray):
    """The box (tangent coordinates) of the car's shadows on the road under every sky's sun
    or moon of the manifest when ``render.inset_shadow`` is set, else None (also when no sky
    has one)."""
    if not manifest.render.inset_shadow:
        return None
    # Every sky of the manifest, rendered in this run or not: a group added later lands in the same window.
    lights = shadow_light_directions(env, manifest.light_groups)
    boxes = [car_box_tan(shadow_vertices(car_vertices_m, d)) for d in lights]
    if not boxes:
        return None
    return (min(b[0] for b in boxes), min(b[1] for b in boxes), max(b[2] for b in boxes), max(b[3] for b in boxes))


def inset_window(box_tan, manifest: Manifest, cover_tan=None) -> tuple[int, int, int, int, int]:
    """Choose the inset film: scale ``k`` of the reference grid and the crop (x, y, w, h)
    in that film's pixels. ``k`` gives ``inset_pixel_mrad`` sampling unless the window
    would exceed ``inset_max_px`` (near cars, which are large in every camera anyway).
    ``cover_tan``, a box (tangent coordinates) the window must also hold before its margins
    (the car's shadow: :func:`shadow_box_tan`), or None; the margins stay shares of the car's
    box ``box_tan``. With ``render.inset_feather`` the window also holds the ramp over which
    the reader blends it into the plate (:func:`metricscenes.radiance.feather_weights`)."""
    ref_w, ref_h = manifest.reference_grid.width_px, manifest.reference_grid.height_px
    e = manifest.reference_grid.field
    bw, bh = box_tan[2] - box_tan[0], box_tan[3] - box_tan[1]
    held = box_tan if cover_tan is None else (min(box_tan[0], cover_tan[0]), min(box_tan[1], cover_tan[1]),
                                              max(box_tan[2], cover_tan[2]), max(box_tan[3], cover_tan[3]))
    x0, x1 = held[0] - INSET_MARGIN["left"] * bw, held[2] + INSET_MARGIN["right"] * bw
    y0, y1 = held[1] - INSET_MARGIN["top"] * bh, held[3] + INSET_MARGIN["bottom"] * bh
    if manifest.render.inset_feather:
        # The blend ramp (a share f of the window at each side) lies outside the margins, so the
        # car and all it changes nearby keep the inset's full weight: W' (1 - 2 f) = W.
        grow = manifest.render.inset_feather / (1.0 - 2.0 * manifest.render.inset_feather)
        x0, x1, y0, y1 = x0 - grow * (x1 - x0), x1 + grow * (x1 - x0), y0 - grow * (y1 - y0), y1 + grow * (y1 - y0)
    x0, x1, y0, y1 = max(e.x0, x0), min(e.x1, x1), max(e.y0, y0), min(e.y1, y1)
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


def render_unit(manifest_json: dict, unit: Unit, out_dir: str, threads: int | None, variant: str,
                light_groups: tuple[str, ...] | None = None, held: UnitRecord | None = None) -> UnitRecord:
    """Render and write one unit (runs in a worker process) with the Mitsuba ``variant``
    (the manifest's, ``auto`` resolved); return its progress record (the caller writes it).

    ``light_groups``: the groups to render (None: all of the manifest's; on a JIT variant
    whole passes of :func:`light_groups_to_render`). ``held``: the unit's record, whose
    groups are kept and to which these are added (its mask and box too), or None."""
    from metricscenes import scene as scene_mod
    from metricscenes.photometry import radiance_to_xyz
    from metricscenes.lightgroups import meter_pass, render_pass
    from metricscenes.render import Film, illuminance_meter, is_jit_variant, use_variant

    manifest = Manifest.model_validate(manifest_json)
    use_variant(variant, threads)
    # This unit's arrays, and nothing else: every array has one writer.
    store = manifest.store
    arrays = CollectionWriter(out_dir).unit_arrays(unit.key, store.mantissa_bits if store else None,
                                                   store.spectral_basis if store else None)
    ref_w, ref_h = manifest.reference_grid.width_px, manifest.reference_grid.height_px
    field = manifest.reference_grid.field
    env = unit.environment
    parts = scene_mod.environment_parts(env, ground_to_horizon=bool(manifest.render.ground_to_horizon),
                                        road_end_m=manifest.render.road_end_m)
    inset = None if held is None else held.inset
    started = time.perf_counter()
    if unit.kind == PLATE:
        groups = [g for g in manifest.light_groups if g in PLATE_LIGHT_GROUPS]
        jobs = [("plates", g, Film(ref_w, ref_h, field=field), manifest.render.plate_spp, field) for g in groups]
        wide = manifest.wide_plate
        if wide is not None:  # after the plates' jobs: theirs keep their indices, and so their seeds
            jobs += [("wide_plates", g, Film(wide.width_px, wide.height_px, field=wide.field), wide.spp, wide.field)
                     for g in groups]
    else:
        env_parts = parts
        pose = scene_mod.car_pose(env, unit.distance_m)
        parts = parts.merged(scene_mod.car_parts(env, pose, plate_lamp=bool(manifest.render.plate_lamp),
                                                 rear_retroreflectors=bool(manifest.render.rear_retroreflectors)))
        film, extent, projected_box, k = _inset_film(manifest, scene_mod.car_vertices(env, pose), env)
        if held is None:  # (a unit adding groups keeps its mask, which no light group changes)
            mask, mask_box = _instance_mask(manifest, unit, env_parts, parts, film, extent)
            arrays.write_mask(mask, extent)
            grid = manifest.reference_grid
            inset = InsetTruth(pose=asdict(pose), projected_box_tan=tuple(projected_box), inset_scale=k,
                               box_tan=tuple(mask_box), mask_iou=round(box_iou(mask_box, projected_box), 4),
                               bbox_xywh=tuple(box_tan_to_xywh(mask_box, grid.width_px, grid.height_px, grid.field)))
        jobs = [("insets", g, film, manifest.render.inset_spp, extent) for g in manifest.light_groups]
        if "car_lights" in manifest.light_groups:
            # The car's lamps light the road far outside its inset (an oncoming car's beams
            # reach the camera): that group also gets a whole frame at plate sampling, or coarser.
            jobs.append(("frames", "car_lights", Film(*manifest.frame_grid_px(), field=field),
                         manifest.render.plate_spp, field))
            wide = manifest.wide_plate
            if wide is not None:  # (and beyond the reference field, for the wide plate's cameras)
                jobs.append(("wide_frames", "car_lights", Film(*manifest.wide_frame_grid_px(), field=wide.field),
                             wide.spp, wide.field))
    illuminance = {}
    # Every job keeps its index among all of the unit's jobs, and so its seed, whichever are rendered now.
    lit = [(i, job) for i, job in enumerate(jobs) if scene_mod.has_emitters(parts, job[1])]
    one_pass = is_jit_variant(variant)
    wanted = set(manifest.light_groups if light_groups is None else light_groups)
    for seeds, (kind, film, spp, extent), groups in _renders(lit, one_pass=one_pass):
        if not wanted & set(groups):
            continue
        images = render_pass(env, parts, groups, film, spp=spp, seed=unit.seed + 7919 * seeds[0],
                             max_depth=manifest.render.max_depth)
        for group in groups:
            arrays.write_radiance(kind, group, images[group], extent, {"spp": spp, "seed": unit.seed})
        if kind != "plates":  # the illuminance at the camera is the plate's, metered once
            continue
        if one_pass:  # the pass's groups in one trace, with a kernel shared by every plate
            irradiance = meter_pass(env, parts, groups, seed=unit.seed + 7919 * seeds[0],
                                    max_depth=manifest.render.max_depth)
        else:
            irradiance = {group: illuminance_meter(
                scene_mod.scene_dict(env, parts, group, film, spp=spp, seed=unit.seed + 7919 * i,
                                     max_depth=manifest.render.max_depth), seed=unit.seed + 7919 * i)
                for i, group in zip(seeds, groups)}
        illuminance.update({g: round(float(radiance_to_xyz(e)[1]), 9) for g, e in irradiance.items()})
    written, attributes, seconds = arrays.sha256, arrays.attributes_sha256, time.perf_counter() - started
    if held is not None:  # what the unit held, and what it rendered now
        written, attributes = {**held.arrays, **written}, {**(held.attributes or {}), **attributes}
        illuminance = {**(held.illuminance_lux or {}), **illuminance}
        seconds += held.seconds
        wanted |= set(unit_light_groups(held, manifest))
    return UnitRecord(unit=unit.key, kind=unit.kind, arrays=written, seconds=round(seconds, 3),
                      illuminance_lux=illuminance or None,  # (a plate no group lights records none)
                      inset=inset, attributes=attributes, light_groups=_fewer_than_all(wanted, manifest))


def unit_light_groups(record: UnitRecord, manifest: Manifest) -> tuple[str, ...]:
    """The light groups a finished unit holds (a record that names none holds all of them)."""
    return manifest.light_groups if record.light_groups is None else record.light_groups


def _fewer_than_all(groups, manifest: Manifest) -> tuple[str, ...] | None:
    """``groups`` in the manifest's order, or None where they are all of its light groups
    (how records and the resolved manifest write them: a full render's bytes are as before)."""
    ordered = tuple(g for g in manifest.light_groups if g in set(groups))
    return None if ordered == manifest.light_groups else ordered


def requested_light_groups(manifest: Manifest, conditions=(), light_groups=()) -> tuple[str, ...] | None:
    """The light groups that ``conditions`` (the manifest's, or its illuminance sweep's) and
    ``light_groups`` need, in the manifest's order; None where neither names any (all of
    them). :class:`~metricscenes.manifest.ManifestError` (one line) for a name it lacks."""
    if not conditions and not light_groups:
        return None
    for group in light_groups:
        if group not in manifest.light_groups:
            raise ManifestError(f"light group {group!r} is not one of manifest {manifest.name}'s "
                                f"({', '.join(manifest.light_groups)})")
    wanted = set(light_groups).union(*(manifest.condition_light_groups(c) for c in conditions))
    return tuple(g for g in manifest.light_groups if g in wanted)


def light_groups_to_render(manifest: Manifest, light_groups, variant: str) -> tuple[str, ...]:
    """``light_groups`` and, on a JIT variant, every group rendered in one pass with one of
    them (:func:`metricscenes.lightgroups.passes`: the first sky with every lamp group), in
    the manifest's order. A pass's groups share their random numbers, so rendering part of
    one would give other bytes than a render of all groups; a whole pass gives the same."""
    from metricscenes.lightgroups import passes
    from metricscenes.render import is_jit_variant

    chosen = set(light_groups)
    if is_jit_variant(variant):
        chosen = chosen.union(*(p for p in passes(manifest.light_groups) if chosen & set(p)))
    return tuple(g for g in manifest.light_groups if g in chosen)


def _renders(lit_jobs: list, one_pass: bool) -> list:
    """The renders of a unit's lit jobs ``(index, (kind, group, film, spp, extent))``, as
    (job indices, (kind, film, spp, extent), groups): one per job, or on a JIT variant one
    per pass of :func:`metricscenes.lightgroups.passes` over the jobs sharing a film. A
    render's seed comes from its first job's index (one job each: the seeds of old)."""
    from metricscenes.lightgroups import passes

    if not one_pass:
        return [((i, ), (kind, film, spp, extent), (group, )) for i, (kind, group, film, spp, extent) in lit_jobs]
    by_film: dict = {}
    for i, (kind, group, film, spp, extent) in lit_jobs:
        by_film.setdefault((kind, film, spp, extent), {})[group] = i
    return [(tuple(index[g] for g in groups), target, groups)
            for target, index in by_film.items() for groups in passes(list(index))]


def scene_inset_window(manifest: Manifest, env: EnvironmentPlan, car_vertices_m: np.ndarray):
    """:func:`inset_window` of a scene's car: its projected box, and its shadows' where the
    manifest asks (``render.inset_shadow``)."""
    return inset_window(car_box_tan(car_vertices_m), manifest, shadow_box_tan(manifest, env, car_vertices_m))


def _inset_film(manifest: Manifest, car_vertices_m: np.ndarray, env: EnvironmentPlan):
    """The inset's film (a crop of a k-times finer reference film), its extent in tangent
    coordinates, the car's projected box (tangent coordinates) and k."""
    from metricscenes.render import Film

    ref_w, ref_h = manifest.reference_grid.width_px, manifest.reference_grid.height_px
    box = car_box_tan(car_vertices_m)
    k, cx, cy, cw, ch = scene_inset_window(manifest, env, car_vertices_m)
    e = manifest.reference_grid.field
    film = Film(ref_w * k, ref_h * k, cx, cy, cw, ch, field=e)
    extent = TanExtent(e.x0 + cx / film.width * e.width, e.y0 + cy / film.height * e.height,
                       e.x0 + (cx + cw) / film.width * e.width, e.y0 + (cy + ch) / film.height * e.height)
    return film, extent, box, k


def _instance_mask(manifest: Manifest, unit: Unit, env_parts, parts, film, extent):
    """The car's instance mask over the inset (the rays whose first hit moves when the car
    is added) and its tight box in tangent coordinates."""
    import mitsuba as mi

    from metricscenes import scene as scene_mod
    from metricscenes.lightgroups import depth_pass
    from metricscenes.render import RenderError, is_jit_variant, render_depth

    group = manifest.light_groups[0]
    if is_jit_variant(mi.variant()):  # one kernel for every inset
        depth_with, depth_without = (depth_pass(unit.environment, p, group, film, seed=unit.seed)
                                     for p in (parts, env_parts))
    else:
        depth_with, depth_without = (
            render_depth(scene_mod.scene_dict(unit.environment, p, group, film, spp=1, seed=unit.seed, max_depth=2),
                         film)
            for p in (parts, env_parts))
    mask = (depth_with > 0) & (depth_with != depth_without)
    mask_box = mask_box_tan(mask, extent)
    if mask_box is None:
        raise RenderError(f"{unit.key}: the car is not visible in its inset")
    return mask, mask_box


def _record_problem(root: Path, group, record: UnitRecord, manifest: Manifest) -> str | None:
    """Why a finished unit must be rendered again (an array missing, unreadable or not
    the bytes its record names; a mask that does not give the recorded box), or None:
    the progress record is a claim, not proof."""
    key = record.unit
    # (records written before attributes had a sha256 have none: _record_attributes checks them)
    attributes = {} if record.attributes is None else record.attributes
    fallback = None if record.attributes is None else ""
    try:
        for path, sha in sorted(record.arrays.items()):
            read_checked(root, group, path, sha, key, attributes.get(path, fallback))
        if record.inset is not None:  # the box goes into groundtruth.json: it must be the mask's
            path = f"masks/{key}"  # (records written before masks had a sha256 have none for it)
            mask, attrs = read_checked(root, group, path, record.arrays.get(path), key, attributes.get(path, fallback))
            box = mask_box_tan(mask.astype(bool), TanExtent(*attrs["extent_tan"]))
            grid = manifest.reference_grid
            xywh = None if box is None else tuple(box_tan_to_xywh(box, grid.width_px, grid.height_px, grid.field))
            if box is None or tuple(box) != record.inset.box_tan or xywh != record.inset.bbox_xywh:
                return f"{key}: masks/{key} does not give the recorded box"
    except CollectionError as exc:
        return str(exc)
    except (KeyError, TypeError, AttributeError, ValueError):
        return _incomplete(key)
    return None


def _incomplete(key: str) -> str:
    return f"{key}: its progress record is incomplete"


def _expected_attributes(manifest: Manifest, unit: Unit, path: str, stored: dict) -> dict:
    """The attributes :func:`render_unit` writes on ``path``, one of ``unit``'s arrays (its
    ``spectral_basis`` is taken as stored: it is under the array's sha256, which is of the
    values decoded through it)."""
    from metricscenes import scene as scene_mod
    from metricscenes.writer import mask_attributes, radiance_attributes

    kind = path.split("/")[0]
    extent = manifest.reference_grid.field
    if unit.kind != PLATE:
        pose = scene_mod.car_pose(unit.environment, unit.distance_m)
        extent = _inset_film(manifest, scene_mod.car_vertices(unit.environment, pose), unit.environment)[1]
    if kind == "masks":
        return mask_attributes(extent)
    if kind == "frames":
        extent = manifest.reference_grid.field
    store = manifest.store
    spp = manifest.render.inset_spp if kind == "insets" else manifest.render.plate_spp
    if kind in WIDE_KINDS:
        extent, spp = manifest.wide_plate.field, manifest.wide_plate.spp
    basis = stored.get("spectral_basis") if store and store.spectral_basis else None
    return radiance_attributes(path.split("/")[-1], extent, store.mantissa_bits if store else None, basis,
                               {"spp": spp, "seed": unit.seed})


def _attribute_difference(stored: dict, expected: dict) -> str | None:
    """The first attribute in which ``stored`` differs from ``expected``, or None (extents
    may differ by 1e-12, rounding of another machine)."""
    for name in sorted(set(stored) | set(expected)):
        a, b = stored.get(name), expected.get(name)
        if name == "extent_tan" and isinstance(a, list) and len(a) == 4 and b is not None:
            try:
                if np.allclose(np.asarray(a, dtype=np.float64), b, rtol=0.0, atol=1e-12):
                    continue
            except (TypeError, ValueError):
                pass
            return name
        if a != b:
            return name
    return None


def _record_attributes(group, record: UnitRecord, manifest: Manifest, unit: Unit) -> tuple[str | None, UnitRecord]:
    """A record written before attributes had a sha256, given them: each of its arrays'
    attributes, checked against what :func:`render_unit` writes, and hashed (metadata only:
    nothing is rendered). Returns (why the unit must be rendered again, the record as it
    was) or (None, the record with its ``attributes``)."""
    from metricscenes.store import attributes_sha256

    hashes = {}
    for path in sorted(record.arrays):
        try:
            stored = dict(group[path].attrs)
        except Exception:
            return f"{record.unit}: {path} is missing or unreadable", record
        different = _attribute_difference(stored, _expected_attributes(manifest, unit, path, stored))
        if different:
            return f"{record.unit}: {path} attribute {different!r} is not the one written", record
        hashes[path] = attributes_sha256(stored)
    return None, replace(record, attributes=hashes)


def _finished_units(writer: CollectionWriter, units: list[Unit], manifest: Manifest,
                    notice) -> dict[str, UnitRecord | None]:
    """The record of each unit, None for those to render (again): no record, or one whose
    arrays do not bear it out (``notice`` gets one line for each of these)."""
    import zarr

    group = zarr.open_group(str(writer.root / RADIANCE_STORE), mode="r")
    records = {}
    for u in units:
        try:
            record = writer.read_record(u.key)
            problem = None if record is None else _record_problem(writer.root, group, record, manifest)
        except RecordError:
            record, problem = None, _incomplete(u.key)
        if record is not None and not problem and record.attributes is None:  # written before they had a sha256
            problem, record = _record_attributes(group, record, manifest, u)
            if not problem:
                writer.write_record(record)
        if problem:
            record = None
            if notice:
                notice(f"rendering {u.key} again: {problem}")
        records[u.key] = record
    return records


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
    from metricscenes.scene_checks import farthest_scene_problems

    root = check_out_dir(out_dir)
    problems = farthest_scene_problems(manifest)
    if problems:
        more = f" (and {len(problems) - 1} more)" if len(problems) > 1 else ""
        raise ManifestError(f"manifest {manifest.name}: {problems[0]}{more}")
    check_scheduler(scheduler)
    if not is_remote(scheduler):  # a running cluster's workers have their own machines' memory
        check_memory(manifest, workers, source=f"manifest {manifest.name}")
    variant = render_variant(manifest, scheduler)  # an LLVM variant can abort the process, CUDA needs a GPU
    return root, variant


def generate(manifest: Manifest, out_dir: str | Path, *, workers: int = 1, threads: int | None = None,
             scheduler: str | None = None, progress=None, notice=None,
             light_groups: tuple[str, ...] | None = None) -> Path:
    """Render ``manifest`` into ``out_dir`` (resuming what is already done, repairing
    what is damaged).

    ``light_groups``: render only these of the manifest's (:func:`requested_light_groups`;
    on a JIT variant with those sharing their one-pass renders, :func:`light_groups_to_render`),
    besides those ``out_dir`` already holds; None: all of them. The collection records
    which it holds (:attr:`metricscenes.store.Collection.light_groups`), and a later run
    with more adds the missing groups to every unit.

    ``workers`` processes render units in parallel; each uses ``threads`` render
    threads (default: the CPU count divided by the workers). ``scheduler`` runs them on
    dask instead (:mod:`metricscenes.backends`): ``local`` starts a LocalCluster of
    ``workers`` processes, ``tcp://HOST:PORT`` uses that scheduler's cluster (whose
    workers must see ``out_dir`` at the same path; ``threads`` default: each worker's
    CPUs). The bytes do not depend on any of these. ``progress`` is an
    optional callable ``(done, total, unit_key)``; ``notice`` an optional callable that
    gets one line per finished unit found damaged (it is rendered again), one when a
    stale lock is taken over and one when a JIT variant renders more groups than asked.

    Before anything is created, :func:`check_before_writing` refuses a bad ``out_dir``, a
    scheduler that cannot be used, a render that would not fit in memory and a Mitsuba
    variant that cannot run here; while it writes, ``generate`` holds ``out_dir/generate.lock``
    (:mod:`metricscenes.lock`), so a second writer on the same folder is refused.
    """
    root, variant = _checked_root_and_variant(manifest, out_dir, workers, scheduler)
    with CollectionWriter(root).locked(notice=notice) as writer:  # one writer at a time; released on errors too
        _generate(manifest, writer, variant, workers, threads, scheduler, progress, notice, light_groups)
    return root


def _target_light_groups(manifest: Manifest, records: dict[str, UnitRecord | None], light_groups,
                         variant: str, notice) -> tuple[str, ...]:
    """The light groups every unit holds when this run ends: those asked for (None: all),
    with the groups sharing their one-pass renders, and every group a unit already holds
    (a run that was adding groups when it stopped is finished)."""
    asked = manifest.light_groups if light_groups is None else light_groups
    rendered = light_groups_to_render(manifest, asked, variant)
    held = {g for r in records.values() if r is not None for g in unit_light_groups(r, manifest)}
    brought = [g for g in rendered if g not in asked and g not in held]
    if brought and notice:
        notice(f"{variant} renders a sky with every lamp group in one pass: also rendering {', '.join(brought)}")
    return tuple(g for g in manifest.light_groups if g in held or g in rendered)


def _generate(manifest: Manifest, writer: CollectionWriter, variant: str, workers: int, threads: int | None,
              scheduler: str | None, progress, notice, light_groups: tuple[str, ...] | None) -> None:
    writer.prepare(manifest, variant)
    scenes = plan_collection(manifest)
    units = plan_units(scenes)
    records = _finished_units(writer, units, manifest, notice)
    target = _target_light_groups(manifest, records, light_groups, variant, notice)
    # A unit renders the target groups it lacks: all of them where it has no record (its mask too).
    missing = {key: [g for g in target if record is None or g not in unit_light_groups(record, manifest)]
               for key, record in records.items()}
    todo = [u for u in units if missing[u.key]]
    threads = threads_per_unit(threads, workers, scheduler)
    manifest_json = manifest.model_dump(mode="json")
    done = len(units) - len(todo)
    if progress:
        progress(done, len(units), None)
    # Units finish in any order; each record is written here, by the client, as it arrives.
    jobs = [(manifest_json, u, str(writer.root), threads, variant, tuple(missing[u.key]), records[u.key])
            for u in todo]
    with closing(map_units(render_unit, jobs, workers=workers, scheduler=scheduler)) as finished:
        for record in finished:
            writer.write_record(record)
            records[record.unit] = record
            done += 1
            if progress:
                progress(done, len(units), record.unit)
    writer.finish(manifest, scenes, records, variant, _fewer_than_all(target, manifest))
