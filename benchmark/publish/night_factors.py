"""What separates our night from the paper's, factor by factor, at equal image-plane illuminance:
docs/data/night-factors.csv (``benchmark publish night-factors``).

One camera, one set of scenes, one change at a time; every row is scored like a run (same
detector, multiscale input, COCO AP of the car per distance) and says what the camera
collected. The rows, each a documented scene or camera choice, not a value fitted to a score:

- **scene**: the paper's night as `quick` makes it (`night`: the night sky scaled so that,
  with every lamp on, the mean image-plane illuminance at f/2.4 meets a target of 0.1–1 lux);
  the daylight sky scaled to the *same* mean image-plane illuminance per scene (the paper's
  luminance sweep darkens a day scene); the same with every lamp on (the paper: "varying
  the scene luminance and adding headlights").
- **exposure**: the 16 ms cap raised to a 30 fps frame period (33 ms); the mean-level policy
  (18 % of full scale on the central region's mean) instead of 90 % of its 99.9th percentile.
- **sensor**: shot noise only (read noise, PRNU and DSNU off), then no noise at all: bounds
  of what any sensor with these pixels could give.
- **ISP**: white balance for a known D65 illuminant instead of grey world.
- **detector input**: the same linear image ×4 and ×16 before the sRGB encoding (a brighter
  rendering of the same raw data).

Per row: mean image-plane illuminance (f/2.4) of the scenes, median exposure, median
noise-free electrons on the car's green pixels and on the whole frame, AP per distance.
"""

from __future__ import annotations

from dataclasses import dataclass, field

import numpy as np

from benchmark.camera import load_camera
from benchmark.camera.exposure import parse_exposure, with_exposure
from benchmark.camera.isp import encode_srgb8
from benchmark.camera.pipeline import lens_mapping, simulate
from benchmark.coco import coco_category_id
from benchmark.experiments.collection_view import collection_field, collection_widest_field
from benchmark.experiments.run import scene_seed
from benchmark.experiments.subset import subset_collection
from benchmark.publish.night_exposure import green_sites
from benchmark.scoring import AP_SCORE_THRESHOLD, ap_by_distance
from metricscenes.photometry import image_plane_illuminance_lux
from metricscenes.store import Collection, scale_groundtruth

LAMPS = ("car_lights", "street_lights", "ego_lights")


@dataclass
class Variant:
    factor: str
    name: str
    scene: str = "night"  # night | day_matched | day_lamps_matched
    camera: dict = field(default_factory=dict)  # {"exposure": "percentile:99"} or {"sensor": {...}, "isp": {...}}
    gain: float = 1.0  # on the linear image before the sRGB encoding
    noise: bool = True


VARIANTS = [
    Variant("scene", "paper's night as quick makes it (night sky + every lamp, 0.1-1 lux)"),
    Variant("scene", "daylight sky at the same image-plane lux", scene="day_matched"),
    Variant("scene", "daylight sky + every lamp at the same image-plane lux", scene="day_lamps_matched"),
    Variant("exposure", "cap 16 ms -> 33 ms (30 fps frame period)", camera={"exposure": {"max_exposure_s": 1 / 30}}),
    Variant("exposure", "mean-level policy (18 % on the central mean)", camera={"exposure": "mean_level@0.18"}),
    Variant("sensor", "shot noise only (read noise, PRNU, DSNU off)",
            camera={"sensor": {"read_noise_e": 0.0, "prnu_fraction": 0.0, "dsnu_v": 0.0}}),
    Variant("sensor", "no noise at all (bound)", noise=False),
    Variant("ISP", "white balance for D65 instead of grey world", camera={"isp": {"white_balance": "known_illuminant"}}),
    Variant("detector input", "linear image x4 before sRGB", gain=4.0),
    Variant("detector input", "linear image x16 before sRGB", gain=16.0),
    Variant("combined", "daylight + lamps, 33 ms cap, x4", scene="day_lamps_matched",
            camera={"exposure": {"max_exposure_s": 1 / 30}}, gain=4.0),
]


def variant_camera(base, variant: Variant):
    camera = base
    for block, change in variant.camera.items():
        if block == "exposure" and isinstance(change, str):
            camera = with_exposure(camera, parse_exposure(change))
        else:
            spec = getattr(camera, block)
            camera = camera.model_copy(update={block: spec.model_copy(update=change)})
    if variant.gain != 1.0:  # the ISP's linear output, to apply the gain before the 8-bit encoding
        camera = camera.model_copy(update={"isp": camera.isp.model_copy(update={"output": "linear"})})
    return camera


class SceneWeights:
    """Light-group weights per scene for the three scenes, all at the mean image-plane
    illuminance the paper's night (``night``) has in that scene."""

    def __init__(self, collection: Collection, condition: str = "night"):
        self.collection, self.condition = collection, condition

    def luminance(self, scene_id: str, weights: dict[str, float]) -> float:
        """Mean luminance of a mix, from the collection's cached per-group luminances (a mix is linear)."""
        return sum(w * self.collection.group_luminance(scene_id, g) for g, w in weights.items() if w)

    def weights(self, scene_id: str, scene: str) -> dict[str, float]:
        night = self.collection.targeted_weights(scene_id, self.condition).weights
        if scene == "night":
            return dict(night)
        target = self.luminance(scene_id, night)
        lamps = {g: 1.0 for g in LAMPS} if scene == "day_lamps_matched" else {}
        ambient = max(0.0, target - self.luminance(scene_id, lamps)) / self.collection.group_luminance(scene_id, "sky_day")
        return {"sky_day": ambient, **lamps}


def run_variant(collection, scenes, weights: SceneWeights, base_camera, variant: Variant, detector, seed: int) -> dict:
    camera = variant_camera(base_camera, variant)
    field_ = collection_field(collection)
    sensor_window, to_sensor = lens_mapping(camera, field_, collection_widest_field(collection))
    groundtruth = scale_groundtruth(collection.groundtruth(), camera.width_px, camera.height_px,
                                    field=field_, window=sensor_window, to_sensor=to_sensor)
    boxes = {a["image_id"]: a["bbox"] for a in groundtruth["annotations"]}
    detections, lux, exposure_ms, car_e, frame_e = [], [], [], [], []
    for scene in scenes:
        w = weights.weights(scene.scene_id, variant.scene)
        lux.append(image_plane_illuminance_lux(weights.luminance(scene.scene_id, w), 2.4))
        capture = simulate(collection.radiance(scene.scene_id, w), camera,
                           seed=scene_seed(seed, scene.image_id), noise=variant.noise)
        rgb8 = capture.rgb8 if variant.gain == 1.0 else encode_srgb8(capture.rgb_linear * np.float32(variant.gain))
        x, y, bw, bh = boxes[scene.image_id]
        car_e.append(float(np.median(green_sites(capture.electrons, slice(int(y), int(np.ceil(y + bh))),
                                                 slice(int(x), int(np.ceil(x + bw)))))))
        frame_e.append(float(np.mean(capture.electrons)))
        exposure_ms.append(1e3 * capture.exposure_s)
        (found,) = detector.detect([rgb8], conf_threshold=AP_SCORE_THRESHOLD, multi_label=True)
        for d in found:
            x1, y1, x2, y2 = (float(v) for v in d.box_xyxy)
            detections.append({"image_id": scene.image_id, "category_id": coco_category_id(d.class_id),
                               "bbox": [x1, y1, x2 - x1, y2 - y1], "score": float(d.score)})
    row = {"camera": base_camera.name, "factor": variant.factor, "variant": variant.name,
           "image_plane_lux": round(float(np.mean(lux)), 3), "exposure_ms": round(float(np.median(exposure_ms)), 2),
           "car_median_e": round(float(np.median(car_e)), 2), "frame_mean_e": round(float(np.median(frame_e)), 2)}
    for r in ap_by_distance(groundtruth, detections):
        row[f"ap_{r['distance_m']:g}m"] = round(float(r["ap"]), 3)
    return row


def night_factors(collection: Collection, cameras: list[str], detector, condition: str = "night",
                  distances: str | None = "25,50,100", seed: int = 0, variants: list[Variant] = VARIANTS,
                  say=print) -> list[dict]:
    """A row per camera and variant on the scenes at ``distances`` (metres, as ``benchmark run
    --distances``), all at the image-plane illuminance of ``condition`` (a targeted condition of the
    collection); ``say`` gets each row as it is made."""
    subset = subset_collection(collection, distances=distances)
    scenes = subset.scenes()
    weights = SceneWeights(collection, condition)
    rows = []
    for name in cameras:
        base = load_camera(name)
        for variant in variants:
            row = run_variant(subset, scenes, weights, base, variant, detector, seed)
            rows.append(row)
            say(" | ".join(str(v) for v in row.values()))
    return rows
