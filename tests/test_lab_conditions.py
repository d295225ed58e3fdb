"""The paper's conditions as its lab made them (docs/scenes.md, "The paper's conditions as its
lab made them"): ``night_lab`` and ``day_lab`` in quick, first and metric-300, read-time
conditions that leave every hash that collections, results and submissions are keyed by as
it was."""

from __future__ import annotations

import json

import pytest

from conftest import REPO
from metricscenes.manifest import load_manifest, parse_manifest

PUBLISHED = {  # the published manifests' sha256 (tests/test_store.py pins them too)
    "smoke": "2b496a1a26819de6db01186453bfb52231475da05b2c558a5d153342fd8ee687",
    "first": "f3425e4e678e0da9494c7c9f7fc2a850a056687e4b6c37fb2d5dad06db76a701",
    "quick": "6ce3394e3129c2704092906ed6ae4d447610c48f19399a571be4319123edaf00",
    "metric-300": "fd9342ff7e065f1d172afca80942cb14e08ddd056981ee56f914a44a77d14db5",
}


@pytest.mark.parametrize("name", sorted(set(PUBLISHED) - {"smoke"}))
def test_the_lab_conditions_leave_every_published_hash_as_it_was(name):
    manifest = load_manifest(REPO / "manifests" / f"{name}.yaml")
    assert {"night_lab", "day_lab"} <= set(manifest.read_time_conditions)
    assert manifest.sha256() == PUBLISHED[name]
    bare = manifest.model_dump(mode="json")
    bare.pop("read_time_conditions")
    assert parse_manifest(bare).sha256() == PUBLISHED[name]  # (and the same without them)
    # The hashed conditions keep the JSON form they were hashed with: no knob added to them.
    night = manifest.model_dump(mode="json")["conditions"]["night"]
    assert manifest.conditions["night"].identity() == {k: v for k, v in night.items() if v is not None}


def test_the_reference_submissions_still_name_the_manifests_that_make_quick_and_metric300():
    from benchmark.leaderboard.protocols import load_protocols

    protocols = load_protocols()
    published = {**PUBLISHED, "adas-quick": load_manifest(REPO / "manifests" / "adas-quick.yaml").sha256()}
    for path in sorted((REPO / "leaderboard" / "submissions").glob("*.json")):
        submission = json.loads(path.read_text())
        collection = submission["collection"]
        assert collection["manifest_sha256"] == published[collection["name"]], path.name
        assert published[collection["name"]] in protocols[collection["protocol"]].manifests_sha256
        assert set(submission["conditions"]) <= {"day", "dusk", "night", "night_regulation"}  # the lab's: not ranked
    for name in ("quick", "metric-300"):
        assert not {"night_lab", "day_lab"} & set(protocols[name].conditions)


def test_quick_and_metric300_mix_the_labs_four_groups_without_ego_lamps():
    for name in ("quick", "metric-300", "first"):
        manifest = load_manifest(REPO / "manifests" / f"{name}.yaml")
        lab = manifest.read_time_conditions
        # isetauto: sky x 10 + headlights x 1 + other lamps x 1 + street lights x 0.5 (our car_lights: both lamps)
        assert lab["night_lab"].mix == {"sky_night": 10.0, "car_lights": 1.0, "street_lights": 0.5}
        assert lab["day_lab"].mix == {"sky_day": 10.0, "car_lights": 1.0, "street_lights": 0.5}
        for spec in lab.values():
            assert spec.scales_mix and spec.at_camera and "ego_lights" not in spec.mix
        assert lab["night_lab"].target_image_plane_lux == (0.1, 1.0)
        assert lab["day_lab"].target_image_plane_lux == (10.0, 200.0)
        # Paired with the physical conditions: the same target per environment.
        assert (lab["night_lab"].same_targets_as, lab["day_lab"].same_targets_as) == ("night", "day_paper")
        assert manifest.condition_names[-2:] == ["night_lab", "day_lab"]  # after every published condition


def test_the_whole_mix_keeps_the_labs_ratios_and_the_ambient_knob_does_not():
    from metricscenes.targets import solve_at_image_plane

    lab = load_manifest(REPO / "manifests" / "quick.yaml").read_time_conditions["night_lab"]
    w = solve_at_image_plane(lab, 0.5, {"mix": 0.2})
    assert w.mix_scale == pytest.approx(2.5, rel=1e-12)
    assert w.weights == pytest.approx({"sky_night": 25.0, "car_lights": 2.5, "street_lights": 1.25}, rel=1e-12)
    ours = load_manifest(REPO / "manifests" / "quick.yaml").conditions["night"]
    camera = ours.model_copy(update={"target_at": "camera", "f_number": None})
    w = solve_at_image_plane(camera, 0.5, {"ambient": 0.1, "lamps": 0.2})  # the lamps stay at their own
    assert w.weights == {"sky_night": pytest.approx(3.0), "car_lights": 1.0, "street_lights": 1.0, "ego_lights": 1.0}
    over = solve_at_image_plane(camera, 0.1, {"ambient": 0.1, "lamps": 0.2})
    assert over.over_target and over.ambient_weight == 0.0


def test_generate_again_records_new_read_time_conditions_and_renders_nothing(smoke_collection, tmp_path):
    """A collection made before a read-time condition was added gets it from `generate` run
    again with the manifest: the same hash, every unit found done, the arrays untouched."""
    import shutil

    import yaml

    from metricscenes.generate import generate
    from metricscenes.store import Collection

    copy = tmp_path / "smoke"
    shutil.copytree(smoke_collection, copy)
    before = yaml.safe_load((copy / "manifest.resolved.yaml").read_text())
    smoke = load_manifest(REPO / "manifests" / "smoke.yaml")
    assert smoke.read_time_conditions is None  # (smoke.yaml as it was: tests trim its groups)
    data = smoke.model_dump(mode="json")
    data["read_time_conditions"] = {"night_lab_bright": {
        "scales": "mix", "mix": {"sky_night": 10.0, "car_lights": 1.0}, "target_at": "camera",
        "target_image_plane_lux": [1.0, 10.0], "same_targets_as": "night"}}
    manifest = parse_manifest(data)
    assert manifest.sha256() == PUBLISHED["smoke"]
    rendered = []
    generate(manifest, copy, progress=lambda done, total, unit: unit and rendered.append(unit))
    after = yaml.safe_load((copy / "manifest.resolved.yaml").read_text())
    assert not rendered and after["arrays"] == before["arrays"] and after["manifest_sha256"] == PUBLISHED["smoke"]
    assert (copy / "groundtruth.json").read_bytes() == (smoke_collection / "groundtruth.json").read_bytes()
    assert "night_lab_bright" in Collection.open(copy).condition_names
