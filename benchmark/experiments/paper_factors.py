"""From our night to the paper's, factor by factor: ``benchmark paper-factors``.

Our physical night (``night``: every lamp at its photometric intensity, the night sky raised
until an ideal f/2.4 lens gets 0.1–1 lux) ranks cameras by the light each pixel collects
(p²/N²); the paper's ranks them by MTF50. The paper's lab made its night differently
(../shared/reference/isetcam-lab-procedure.md). This experiment applies the lab's choices to
our night one at a time, and cumulatively, each a documented procedure of the lab or of the
paper, none a value fitted to a score (:data:`FACTORS`):

1. the target met at each camera's own image plane (ISETCam ``oiAdjustIlluminance``);
2. the whole mix scaled, lamps included, at the lab's weights (sky × 10, car lamps × 1, street
   lights × 0.5: isetauto ``iaLightsGroup.m``);
3. the ego vehicle's lamps off (the lab had no such group);
4. YOLOv5s, the paper's detector;
5. auto-exposure at the strict maximum of the central region (ISETCam ``autoExposure``);
6. that region the central 20 % × 20 % (the lab's ``piOI2IP``, 2022);
7. 1 e⁻ of read noise (the lab's ``piRadiance2RGB``, 2022-09);
8. no noise at all (``'noisefree'``, the January 2023 set).

Every row is scored as a run is (the same noise seeds, multiscale input, multi-label decoding,
COCO AP of `car` per distance: the first row is ``benchmark run --condition night``'s AP), and
says, over the cameras: mean AP per distance, Spearman ρ between a camera's mean AP over the
distances and p²/N² (pixel pitch² / f-number²) and MTF50, and the mean AP at the nearest
distance of the fast and the slow cameras (f-number below and above the cameras' median).

Work is split in units of one camera and one environment (every row, every distance), run on
``workers`` processes; each unit's detections are kept in ``OUT/units/`` under a key of what
made them, so a run stopped midway resumes, and a unit is never taken for another's. A
capture several rows share (a change of detector only) is simulated once.
"""

from __future__ import annotations

import hashlib
import json
import math
from dataclasses import dataclass
from pathlib import Path
from typing import Annotated, Optional

import numpy as np
import typer

from benchmark.experiments.keys import PAPER_FACTORS_FORMAT

UNITS_DIR = "units"


@dataclass(frozen=True)
class Factor:
    key: str
    label: str
    source: str


FACTORS = (
    Factor("image_plane", "target at each camera's image plane",
           "ISETCam oiAdjustIlluminance / piOICreate 'meanilluminance' (isetauto s_metricScenes.m @0ba30b5)"),
    Factor("whole_mix", "whole mix scaled (sky x10, car lamps x1, street lights x0.5)",
           "isetauto utility/illumination/iaLightsGroup.m; scripts/s_sensorImageGenerate.m @dc77cea"),
    Factor("no_ego", "ego lamps off", "isetauto has no ego-vehicle lamp group"),
    Factor("yolov5s", "YOLOv5s", "Liu et al. 2023 (the paper's detector)"),
    Factor("strict_max", "AE at the strict maximum", "ISETCam sensor/simulation/autoExposure.m"),
    Factor("centre_20", "AE region central 20 %", "isetauto piOI2IP (2022)"),
    Factor("read_noise_1e", "read noise 1 e-", "isetauto utility/piRadiance2RGB.m @69a45f7"),
    Factor("noise_free", "no noise", "isetauto January 2023 night set: 'noisefree', true"),
)
FACTOR_KEYS = tuple(f.key for f in FACTORS)
LAB_AMBIENT_WEIGHT = 10.0
LAB_LAMP_WEIGHTS = {"car_lights": 1.0, "street_lights": 0.5}  # isetauto: headlights x1, other lamps x1, streetlights x0.5
EGO_GROUPS = ("ego_lights", "ego_high_beam")
BASELINE_DETECTOR = "yolov5n-dynamic"
PAPER_DETECTOR = "yolov5s-dynamic"


@dataclass(frozen=True)
class Row:
    """One row of the table: the factors applied to the physical night."""

    name: str
    factors: tuple[str, ...]
    kind: str  # "baseline" | "alone" | "cumulative"


def factor_rows(which: str = "both") -> list[Row]:
    """The rows: the physical night, then each factor alone and/or cumulatively (a
    configuration listed once: the first factor alone is the first cumulative row)."""
    if which not in ("both", "alone", "cumulative"):
        raise ValueError(f"--rows {which!r}: expected both, alone or cumulative")
    rows = [Row("physical night", (), "baseline")]
    seen = {()}
    for i, factor in enumerate(FACTORS):
        candidates = []
        if which in ("both", "cumulative"):
            candidates.append(Row(("+ " if i else "") + factor.label, FACTOR_KEYS[: i + 1], "cumulative"))
        if which in ("both", "alone"):
            candidates.append(Row(f"{factor.label} only", (factor.key,), "alone"))
        for row in candidates:
            if row.factors not in seen:
                seen.add(row.factors)
                rows.append(row)
    return rows


def row_condition(base: dict, base_name: str, factors) -> dict | None:
    """The condition a row reads (the JSON form of a targeted condition), or None where no
    scene factor applies (the base condition itself). ``base``: the physical night's
    definition (``ambient`` under ``lamps``), every row paired with its targets."""
    factors = set(factors)
    if not factors & {"image_plane", "whole_mix", "no_ego"}:
        return None
    lamps = {g: w for g, w in base.get("lamps", {}).items() if not ("no_ego" in factors and g in EGO_GROUPS)}
    spec = {"target_image_plane_lux": list(base["target_image_plane_lux"]), "same_targets_as": base_name}
    if "whole_mix" in factors:  # the lab's weights where it had the group, ours (1) where it had none
        spec["scales"] = "mix"
        spec["mix"] = {base["ambient"]: LAB_AMBIENT_WEIGHT, **{g: LAB_LAMP_WEIGHTS.get(g, w) for g, w in lamps.items()}}
    else:
        spec["ambient"], spec["lamps"] = base["ambient"], lamps
    if "image_plane" in factors:
        spec["target_at"] = "camera"
    else:
        spec["f_number"] = base.get("f_number", 2.4)
    return spec


def row_camera(camera, factors):
    """The camera a row uses (its spec changed where the row says), and whether it adds noise."""
    factors = set(factors)
    exposure, sensor = {}, {}
    if "strict_max" in factors:
        exposure["peak_percentile"] = 100.0
    if "centre_20" in factors:
        exposure["region_fraction"] = 0.2
    if "read_noise_1e" in factors:
        sensor["read_noise_e"] = 1.0
    if exposure:
        camera = camera.model_copy(update={"exposure": camera.exposure.model_copy(update=exposure)})
    if sensor:
        camera = camera.model_copy(update={"sensor": camera.sensor.model_copy(update=sensor)})
    return camera, "noise_free" not in factors


def condition_name(spec: dict | None, base_name: str) -> str:
    """A row's condition's name: the base's, or ``factors-<sha256[:10]>`` of its definition."""
    if spec is None:
        return base_name
    return "factors-" + hashlib.sha256(json.dumps(spec, sort_keys=True).encode()).hexdigest()[:10]


def plan(collection, cameras, base_name: str = "night", which: str = "both", model_dir=None) -> dict:
    """What a run of the table needs: rows, the read-time conditions they add, and per row
    its condition, detector and the key of each camera's capture. Refuses (ValueError, one
    line) a base that is not a targeted condition scaling an ambient group."""
    from metricscenes.manifest import TargetedCondition

    spec = collection.conditions.get(base_name)
    if not isinstance(spec, TargetedCondition) or spec.scales_mix or spec.at_camera:
        raise ValueError(f"condition {base_name!r}: the table starts from a physical night, a targeted condition that "
                         "scales its ambient group at a reference lens (as `night`)")
    base = spec.identity()
    rows = factor_rows(which)
    conditions = {}
    for row in rows:
        c = row_condition(base, base_name, row.factors)
        if c is not None:
            conditions[condition_name(c, base_name)] = c
    return {"base": base_name, "base_spec": base, "rows": rows, "conditions": conditions}


def _rows_config(rows, base_name: str, base: dict, camera, detector_sha: dict) -> list[dict]:
    out = []
    for row in rows:
        cond = row_condition(base, base_name, row.factors)
        cam, noise = row_camera(camera, row.factors)
        detector = PAPER_DETECTOR if "yolov5s" in row.factors else BASELINE_DETECTOR
        out.append({"row": row.name, "condition": condition_name(cond, base_name), "condition_spec": cond,
                    "camera_sha256": cam.sha256(), "noise": noise, "detector": detector,
                    "detector_sha256": detector_sha[detector]})
    return out


def run_unit(collection_path: str, conditions: dict, camera, env: int, scene_ids: list[str],
             rows_config: list[dict], factor_sets: list[list[str]], seed: int, model_dir: str | None,
             threads: int | None, out_path: str, key: dict) -> str:
    """One camera and one environment through every row: detections per row, written to
    ``out_path`` (with ``key``). A top-level function, so a worker process can run it."""
    from benchmark.camera.image_plane import ImagePlaneParts
    from benchmark.camera.pipeline import simulate
    from benchmark.coco import coco_category_id
    from benchmark.detectors import load_detector
    from benchmark.experiments.run import read_scene, scene_seed
    from benchmark.scoring.ap import AP_SCORE_THRESHOLD
    from metricscenes.files import write_atomic
    from metricscenes.store import Collection

    collection = Collection.open(collection_path).with_read_time_conditions(conditions)
    detectors: dict = {}
    images = {s.scene_id: s.image_id for s in collection.scenes()}
    rows_out = [{"detections": [], "exposure_s": {}, "condition_weights": {}} for _ in rows_config]
    for scene_id in scene_ids:
        read: dict = {}  # the scene under each condition, read once
        captured: dict = {}  # (condition, camera spec, noise) -> (rgb8, exposure, weights)
        found: dict = {}  # (capture, detector) -> detections
        for config, factors, out in zip(rows_config, factor_sets, rows_out):
            name = config["condition"]
            if name not in read:
                read[name] = read_scene(collection, scene_id, name)
            cam, noise = row_camera(camera, factors)
            capture_key = (name, config["camera_sha256"], noise)
            if capture_key not in captured:
                scene, weights = read[name], None
                seed_here = scene_seed(seed, images[scene_id])
                if isinstance(scene, ImagePlaneParts):
                    capture, weights = scene.simulate(cam, seed=seed_here, noise=noise)
                else:
                    capture = simulate(scene, cam, seed=seed_here, noise=noise)
                    weights = collection.condition_record(scene_id, name)
                captured[capture_key] = (capture.rgb8, capture.exposure_s, weights)
            rgb8, exposure_s, weights = captured[capture_key]
            detector_name = config["detector"]
            if (capture_key, detector_name) not in found:
                if detector_name not in detectors:
                    detectors[detector_name] = load_detector(detector_name, model_dir=model_dir, threads=threads)
                (dets,) = detectors[detector_name].detect([rgb8], conf_threshold=AP_SCORE_THRESHOLD, multi_label=True)
                found[(capture_key, detector_name)] = [
                    {"image_id": images[scene_id], "category_id": coco_category_id(d.class_id),
                     "bbox": [round(float(d.box_xyxy[0]), 3), round(float(d.box_xyxy[1]), 3),
                              round(float(d.box_xyxy[2] - d.box_xyxy[0]), 3),
                              round(float(d.box_xyxy[3] - d.box_xyxy[1]), 3)],
                     "score": round(float(d.score), 6)} for d in dets]
            out["detections"].extend(found[(capture_key, detector_name)])
            out["exposure_s"][scene_id] = exposure_s
            if weights is not None:
                out["condition_weights"][scene_id] = weights
    write_atomic(Path(out_path), json.dumps({"key": key, "rows": rows_out}, sort_keys=True))
    return out_path


def run_factors(collection, cameras, out_dir, *, base_name: str = "night", which: str = "both",
                environments=None, distances=None, seed: int = 0, workers: int = 1, model_dir=None,
                mtf_source: str = "measured", progress=None) -> dict:
    """Run (or resume) the table on ``collection`` for ``cameras``; write and return it.
    ``environments``, ``distances``: a subset, as ``benchmark run --environments/--distances``."""
    from benchmark.camera.pipeline import lens_mapping
    from benchmark.detectors.registry import resolve_model, verify_sha256
    from benchmark.experiments.keys import factor_unit_key
    from benchmark.experiments.collection_view import collection_field, collection_widest_field
    from benchmark.experiments.subset import parse_subset
    from metricscenes.backends import map_units, threads_per_unit
    from metricscenes.store import scale_groundtruth

    out_dir = Path(out_dir)
    p = plan(collection, cameras, base_name, which)
    view = collection.with_read_time_conditions(p["conditions"])
    for name in [base_name, *p["conditions"]]:
        view.check_condition(name)  # its light groups held: one line naming what is missing
    detector_sha = {}
    for name in (BASELINE_DETECTOR, PAPER_DETECTOR):
        path, entry = resolve_model(name, None if model_dir is None else Path(model_dir))
        detector_sha[name] = verify_sha256(path, entry)
    subset = parse_subset(collection, environments, distances) or {}
    envs = subset.get("environments") or sorted({s.environment_id for s in collection.scenes()})
    dists = subset.get("distances_m") or sorted({s.distance_m for s in collection.scenes()})
    scenes = [s for s in collection.scenes() if s.environment_id in envs and any(abs(s.distance_m - d) < 1e-6
                                                                                   for d in dists)]
    units_dir = out_dir / UNITS_DIR
    units_dir.mkdir(parents=True, exist_ok=True)
    threads = threads_per_unit(None, workers, None)
    factor_sets = [list(row.factors) for row in p["rows"]]
    jobs, paths = [], {}
    for camera in cameras:
        configs = _rows_config(p["rows"], base_name, p["base_spec"], camera, detector_sha)
        for env in envs:
            ids = [s.scene_id for s in scenes if s.environment_id == env]
            key = factor_unit_key(collection.manifest_sha256, camera, env, ids, configs, seed)
            path = units_dir / f"{camera.name}-env{env:03d}.json"
            paths[(camera.name, env)] = path
            try:
                if json.loads(path.read_text())["key"] == json.loads(json.dumps(key)):
                    continue  # done before, with the same key
            except (OSError, ValueError, KeyError, TypeError):
                pass
            jobs.append((str(collection.root), p["conditions"], camera, env, ids, configs,
                         factor_sets, seed, None if model_dir is None else str(model_dir), threads, str(path), key))
    total, done = len(cameras) * len(envs), len(cameras) * len(envs) - len(jobs)
    if progress:
        progress(done, total)
    for _ in map_units(run_unit, jobs, workers=workers):
        done += 1
        if progress:
            progress(done, total)
    # Scored per row and camera over all its scenes, as a run scores them.
    field = collection_field(collection)
    kept = {s.image_id for s in scenes}
    per_camera = {}
    for camera in cameras:
        window, to_sensor = lens_mapping(camera, field, collection_widest_field(collection))
        gt = scale_groundtruth(collection.groundtruth(), camera.width_px, camera.height_px, field=field,
                               window=window, to_sensor=to_sensor)
        gt["images"] = [im for im in gt["images"] if im["id"] in kept]
        gt["annotations"] = [a for a in gt["annotations"] if a["image_id"] in kept]
        units = [json.loads(paths[(camera.name, env)].read_text())["rows"] for env in envs]
        per_camera[camera.name] = {"camera": camera, "gt": gt, "rows": [
            {"detections": [d for u in units for d in u[k]["detections"]],
             "condition_weights": {s: w for u in units for s, w in u[k]["condition_weights"].items()}}
            for k in range(len(p["rows"]))]}
    table = score_table(p, per_camera, mtf_source=mtf_source)
    table.update({"collection": {"name": collection.name, "manifest_sha256": collection.manifest_sha256},
                  "subset": subset or None, "seed": seed})
    write_table(out_dir, table)
    return table


def _spearman(x, y) -> float | None:
    from scipy.stats import spearmanr

    x, y = np.asarray(x, float), np.asarray(y, float)
    if len(x) < 2 or np.all(x == x[0]) or np.all(y == y[0]):
        return None  # undefined: too few cameras, or one side constant
    rho = float(spearmanr(x, y).statistic)
    return None if math.isnan(rho) else round(rho, 3)


def score_table(p: dict, per_camera: dict, *, mtf_source: str = "measured") -> dict:
    """The table from every camera's detections per row (see the module's docstring)."""
    from benchmark.measure.mtf import camera_mtf50
    from benchmark.scoring import ap_by_distance

    names = list(per_camera)
    cameras = [per_camera[n]["camera"] for n in names]
    light = {c.name: c.pixel_um**2 / c.f_number**2 for c in cameras}
    mtf50 = {c.name: camera_mtf50(c, mtf_source)[0] for c in cameras}
    f_numbers = np.array([c.f_number for c in cameras])
    median = float(np.median(f_numbers))
    fast = [c.name for c in cameras if c.f_number < median]
    slow = [c.name for c in cameras if c.f_number > median]
    rows = []
    for k, row in enumerate(p["rows"]):
        ap = {n: {r["distance_m"]: float(r["ap"]) for r in ap_by_distance(per_camera[n]["gt"],
                                                                          per_camera[n]["rows"][k]["detections"])}
              for n in names}
        distances = sorted(next(iter(ap.values())))
        mean_ap = {n: float(np.nanmean([ap[n][d] for d in distances])) for n in names}
        near = distances[0]
        entry = {"row": row.name, "kind": row.kind, "factors": list(row.factors),
                 "mean_ap": {f"{d:g}": round(float(np.nanmean([ap[n][d] for n in names])), 3) for d in distances},
                 "rho_ap_light": _spearman([mean_ap[n] for n in names], [light[n] for n in names]),
                 "rho_ap_mtf50": _spearman([mean_ap[n] for n in names], [mtf50[n] for n in names]),
                 f"ap_{near:g}m_fast": round(float(np.mean([ap[n][near] for n in fast])), 3) if fast else None,
                 f"ap_{near:g}m_slow": round(float(np.mean([ap[n][near] for n in slow])), 3) if slow else None,
                 "ap": {n: {f"{d:g}": round(ap[n][d], 3) for d in distances} for n in names}}
        rows.append(entry)
    return {"format": PAPER_FACTORS_FORMAT, "base": p["base"], "base_spec": p["base_spec"],
            "factors": [f.__dict__ for f in FACTORS], "conditions": p["conditions"],
            "cameras": {c.name: {"pixel_um": c.pixel_um, "f_number": c.f_number, "p2_over_n2": round(light[c.name], 5),
                                 "mtf50_cy_per_mm": None if mtf50[c.name] is None else round(mtf50[c.name], 2)}
                        for c in cameras},
            "fast": fast, "slow": slow, "mtf50_source": mtf_source, "rows": rows}


def table_markdown(table: dict) -> str:
    """The table as Markdown: one line per row."""
    rows = table["rows"]
    distances = list(rows[0]["mean_ap"])
    near = distances[0]
    head = (["row"] + [f"AP {d} m" for d in distances] + ["ρ(AP, p²/N²)", "ρ(AP, MTF50)", f"AP {near} m fast",
                                                          f"AP {near} m slow"])
    lines = ["| " + " | ".join(head) + " |", "|" + "---|" * len(head)]

    def cell(v):
        return "—" if v is None else f"{v:.3f}" if isinstance(v, float) else str(v)

    for r in rows:
        lines.append("| " + " | ".join([r["row"]] + [cell(r["mean_ap"][d]) for d in distances]
                                       + [cell(r["rho_ap_light"]), cell(r["rho_ap_mtf50"]),
                                          cell(r[f"ap_{near}m_fast"]), cell(r[f"ap_{near}m_slow"])]) + " |")
    return "\n".join(lines) + "\n"


def write_table(out_dir: Path, table: dict) -> None:
    """``factors.json`` (everything) and ``factors.md`` (the table)."""
    from metricscenes.files import write_atomic

    write_atomic(out_dir / "factors.json", json.dumps(table, indent=1, sort_keys=True))
    fast = ", ".join(table["fast"]) or "none"
    slow = ", ".join(table["slow"]) or "none"
    write_atomic(out_dir / "factors.md", table_markdown(table) + f"\nfast: {fast}; slow: {slow}; MTF50 "
                 f"{table['mtf50_source']}; base condition {table['base']}.\n")


def register(app) -> None:
    """``benchmark paper-factors`` on the CLI app."""
    from rich.console import Console

    from metricscenes.cli_support import fail, progress_bar

    @app.command("paper-factors")
    def paper_factors(
        collection: Annotated[Path, typer.Option(help="collection folder (quick or metric-300: a night with street lights)")],
        out: Annotated[Path, typer.Option(help="folder for factors.json, factors.md and the units (resumable)")],
        cameras: Annotated[str, typer.Option(help="'all' (the 13) or a comma list of names or spec files")] = "all",
        condition: Annotated[str, typer.Option(help="the physical night the rows start from")] = "night",
        rows: Annotated[str, typer.Option(help="both | alone | cumulative")] = "both",
        environments: Annotated[Optional[str], typer.Option(help="some environments only: 0-9,12")] = None,
        distances: Annotated[Optional[str], typer.Option(help="some distances only, in metres: 25,50,100")] = None,
        seed: Annotated[int, typer.Option(help="sensor noise seed (a run's)")] = 0,
        workers: Annotated[int, typer.Option(min=1, help="processes, one camera and environment each")] = 1,
        mtf_source: Annotated[str, typer.Option(help="measured | analytic | group")] = "measured",
        model_dir: Annotated[Optional[Path], typer.Option(help="folder of the registry's models")] = None,
    ) -> None:
        """From our night to the paper's, factor by factor (docs/results.md)."""
        from benchmark.camera import load_camera
        from benchmark.camera.registry import camera_names
        from benchmark.experiments.run import check_out_dir
        from metricscenes.store import Collection

        try:
            names = camera_names() if cameras == "all" else [c.strip() for c in cameras.split(",") if c.strip()]
            specs = [load_camera(name) for name in names]
            if len({c.name for c in specs}) != len(specs):
                raise ValueError("--cameras: two cameras of one name")
            check_out_dir(out)
            col = Collection.open(collection)
            with progress_bar(Console(stderr=True)) as bar:
                task = bar.add_task("paper-factors (camera x environment)", total=None)
                table = run_factors(col, specs, out, base_name=condition, which=rows, environments=environments,
                                    distances=distances, seed=seed, workers=workers, model_dir=model_dir,
                                    mtf_source=mtf_source,
                                    progress=lambda done, total: bar.update(task, completed=done, total=total))
        except (ValueError, OSError) as exc:
            fail(str(exc).splitlines()[0] if str(exc) else type(exc).__name__)
        print(table_markdown(table), end="")
        print(f"fast: {', '.join(table['fast']) or 'none'}; slow: {', '.join(table['slow']) or 'none'}")
        print(f"wrote {out / 'factors.json'}, {out / 'factors.md'}")
