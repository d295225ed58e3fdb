"""The typed records of a collection (progress records, the resolved manifest) keep the
bytes their dicts had: what is read back is written again identically, so collections made
before resume and verify unchanged."""

import json

import pytest
import yaml

from metricscenes.records import RecordError, ResolvedManifest, UnitRecord

PLATE = {"arrays": {"plates/env000/sky_day": "d8" * 32}, "illuminance_lux": {"sky_day": 101645.025126306},
         "kind": "plate", "seconds": 0.816, "unit": "env000"}
INSET = {"arrays": {"insets/env000-d025m/sky_day": "0f" * 32, "masks/env000-d025m": "0e" * 32},
         "bbox_xywh": [44.25, 52, 26.25, 22.0], "box_tan": [-0.165, -0.006, -0.081, 0.063], "inset_scale": 4,
         "kind": "inset", "mask_iou": 0.9884, "pose": {"x_m": 25.0, "y_m": 3.017, "yaw_rad": 3.185},
         "projected_box_tan": [-0.165, -0.006, -0.081, 0.063], "seconds": 3.896, "unit": "env000-d025m"}


@pytest.mark.parametrize("data", [PLATE, INSET, {**PLATE, "arrays": {}, "illuminance_lux": None}])
def test_a_unit_record_is_written_as_its_dict_was(data):
    data = {k: v for k, v in data.items() if v is not None}  # a plate no group lights has no illuminance_lux
    text = json.dumps(data, indent=1, sort_keys=True)
    record = UnitRecord.from_dict(json.loads(text))
    assert record.to_json() == text
    assert record.kind != "inset" or record.inset.bbox_xywh == (44.25, 52, 26.25, 22.0)  # the int stays an int


@pytest.mark.parametrize("change", [{"kind": "film"}, {"seconds": "1"}, {"arrays": ["x"]}, {"box_tan": [0.0, 1.0]},
                                    {"bbox_xywh": None}, {"mask_iou": True}, {"inset_scale": 4.0}])
def test_an_incomplete_record_is_refused(change):
    with pytest.raises(RecordError):
        UnitRecord.from_dict({**INSET, **change})


def test_a_resolved_manifest_written_before_its_newer_fields_keeps_their_absence():
    old = {"package_version": "0.1.0", "manifest_sha256": "c6" * 32, "manifest": {"name": "quick"},
           "arrays": {"plates/env000/sky_day": "6f" * 32}, "illuminance_lux": {"env000": {"sky_day": 1.5}},
           "plan": [{"scene_id": "env000-d025m"}]}
    resolved = ResolvedManifest.from_dict(old)
    assert resolved.render_variant is resolved.groundtruth_sha256 is resolved.content_sha256 is None
    assert list(resolved.as_dict().items()) == list(old.items())


@pytest.mark.slow
def test_the_smoke_collections_records_read_back_write_the_same_bytes(smoke_collection):
    for path in sorted((smoke_collection / "progress").glob("*.json")):
        text = path.read_text()
        assert UnitRecord.from_dict(json.loads(text)).to_json() == text, path.name
    text = (smoke_collection / "manifest.resolved.yaml").read_text()
    assert ResolvedManifest.from_dict(yaml.safe_load(text)).to_yaml() == text
