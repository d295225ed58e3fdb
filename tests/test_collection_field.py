"""A collection's own field of view: a manifest may set
``reference_grid.hfov_deg``; the renders, the stored extents, the ground truth and the
cameras all follow it, and every earlier manifest keeps its sha256. One tiny render."""

import math
from pathlib import Path

import numpy as np
import pytest

from benchmark.camera.pipeline import FieldOfViewError, camera_window
from benchmark.camera import camera_from_dict
from benchmark.experiments.collection_view import collection_field
from metricscenes.geometry import REFERENCE_EXTENT, field_extent, fov_deg
from metricscenes.groundtruth import box_tan_to_xywh, car_box_tan
from metricscenes.manifest import ManifestError, canonical_sha256, load_manifest, parse_manifest

MANIFESTS = Path(__file__).resolve().parents[1] / "manifests"
WIDE = {
    "name": "wide60", "protocol": "smoke", "seed": 5, "environments": 1, "distances_m": [25, 50],
    "reference_grid": {"width_px": 128, "height_px": 96, "hfov_deg": 60.0},  # 4:3, 60° x 46.8°
    "render": {"plate_spp": 4, "inset_spp": 4, "inset_pixel_mrad": 1.0, "inset_max_px": 96, "max_depth": 3},
    "light_groups": ["sky_day"], "conditions": {"day": {"sky_day": 1.0}},
}


def test_earlier_manifests_keep_their_hash():
    m = load_manifest(MANIFESTS / "smoke.yaml")  # its hash is pinned in test_store.PUBLISHED_SHA256
    assert m.reference_grid.hfov_deg is None and m.reference_grid.field is REFERENCE_EXTENT
    dumped = m.model_dump(mode="json")
    # Fields added later are hashed only once set.
    del dumped["reference_grid"]["hfov_deg"], dumped["store"]
    del dumped["render"]["inset_feather"], dumped["render"]["ground_to_horizon"], dumped["render"]["frame_divisor"]
    del dumped["render"]["plate_lamp"], dumped["render"]["rear_retroreflectors"], dumped["render"]["inset_shadow"]
    del dumped["render"]["road_end_m"], dumped["wide_plate"]
    del dumped["read_time_conditions"]  # never hashed: conditions made at read time
    for condition in dumped["conditions"].values():  # a targeted condition's later knobs, unset
        for knob in ("scales", "mix", "target_at", "same_targets_as"):
            if knob in condition and condition[knob] is None:
                del condition[knob]
    assert m.sha256() == canonical_sha256(dumped)
    assert parse_manifest(WIDE).sha256() != parse_manifest({**WIDE, "reference_grid": {
        **WIDE["reference_grid"], "hfov_deg": 61.0}}).sha256()
    for render in ({"inset_feather": 0.1}, {"ground_to_horizon": False}):
        assert parse_manifest(WIDE).sha256() != parse_manifest({**WIDE, "render": {**WIDE["render"], **render}}).sha256()


@pytest.mark.parametrize("grid, words", [
    ({"width_px": 128, "height_px": 96}, "16:9"),  # another aspect needs hfov_deg
    ({"width_px": 128, "height_px": 72, "hfov_deg": 170.0}, "hfov_deg"),
    ({"width_px": 64, "height_px": 96, "hfov_deg": 60.0}, "aspect"),
])
def test_bad_fields_are_refused(grid, words):
    with pytest.raises(ManifestError, match=words):
        parse_manifest({**WIDE, "reference_grid": grid})
    with pytest.raises(ManifestError, match="render.inset_feather"):  # past the inset's margins
        parse_manifest({**WIDE, "render": {**WIDE["render"], "inset_feather": 0.3}})


def test_field_follows_hfov_and_aspect():
    field = parse_manifest(WIDE).reference_grid.field
    h, v = fov_deg(field)
    assert h == pytest.approx(60.0, abs=1e-9)
    assert v == pytest.approx(math.degrees(2 * math.atan(math.tan(math.radians(30)) * 0.75)), abs=1e-9)


@pytest.mark.slow
def test_a_wide_collection_renders_and_maps_its_own_field(tmp_path):
    from metricscenes.generate import generate
    from metricscenes.plan import plan_collection
    from metricscenes.scene import car_pose, car_vertices
    from metricscenes.store import Collection

    # With this session's fidelity settings too: the skirt renders, and the reader feathers the inset.
    manifest = parse_manifest({**WIDE, "render": {**WIDE["render"], "inset_feather": 0.05, "ground_to_horizon": True}})
    collection = Collection.open(generate(manifest, tmp_path / "wide"))
    assert [layer.feather for layer in collection.radiance("env000-d025m", "day").layers] == [0.0, 0.05]
    field = field_extent(60.0, 128, 96)
    assert collection.field == field and collection_field(collection) == field
    (plate,) = [layer for layer in collection.angular_sampling("env000-d025m") if layer["layer"] == "plate"]
    np.testing.assert_allclose(plate["extent_tan"], field.as_tuple(), rtol=1e-12)
    assert plate["shape"][:2] == (96, 128)
    assert collection.verify() == []

    # The stored box is the mask's on the 60° grid, and agrees with the car's mesh
    # projected through that field (not through the reference one).
    gt = collection.groundtruth()
    env = next(s.environment for s in plan_collection(manifest) if s.distance_m == 25)
    projected = box_tan_to_xywh(car_box_tan(car_vertices(env, car_pose(env, 25.0))), 128, 96, field)
    ann = next(a for a in gt["annotations"]
               if next(i for i in gt["images"] if i["id"] == a["image_id"])["distance_m"] == 25)
    assert np.abs(np.array(ann["bbox"]) - projected).max() < 1.5  # pixels of the 128-px grid
    as_if_reference = box_tan_to_xywh(car_box_tan(car_vertices(env, car_pose(env, 25.0))), 128, 96)
    assert ann["bbox"][2] < 0.7 * as_if_reference[2]  # 60° spreads 128 px wider than 34.3°

    # A camera sees its window of the collection's field; one wider than it is refused.
    def camera(focal_mm):
        return camera_from_dict({"name": f"f{focal_mm}", "optics": {"f_number": 2.0, "focal_length_mm": focal_mm},
                                 "sensor": {"pixel_um": 2.8, "active_width_mm": 3.584, "active_height_mm": 2.688}})
    window = camera_window(camera(4.0), collection.field)  # 48.2° x 37.1°
    assert fov_deg(window)[0] == pytest.approx(2 * math.degrees(math.atan(1.792 / 4.0)), rel=1e-9)
    with pytest.raises(FieldOfViewError, match=r"60\.00° x 46\.83°"):
        camera_window(camera(2.5), collection.field)  # 71.3° wide
