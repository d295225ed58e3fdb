"""Generation: structure of the store, determinism, seeds, resume, corruption."""

import json
import shutil
import subprocess
import sys
import time
from pathlib import Path

import numpy as np
import pytest
import yaml

from metricscenes.generate import generate
from metricscenes.store import Collection, CollectionError

pytestmark = pytest.mark.slow
SMOKE = Path(__file__).resolve().parents[1] / "manifests" / "smoke.yaml"


def _resolved(path):
    return yaml.safe_load((path / "manifest.resolved.yaml").read_text())


def test_store_carries_names_units_and_wavelengths(smoke_collection):
    import zarr

    root = zarr.open_group(str(smoke_collection / "radiance.zarr"), mode="r")
    arrays = _resolved(smoke_collection)["arrays"]
    assert {p.split("/")[0] for p in arrays} == {"plates", "insets", "frames", "masks"}
    for path in (p for p in arrays if not p.startswith("masks/")):
        arr = root[path]
        assert arr.metadata.dimension_names == ("y", "x", "wavelength")
        assert arr.attrs["units"] == "W sr-1 m-2 nm-1"
        np.testing.assert_array_equal(arr.attrs["wavelengths_nm"], np.arange(400, 701, 10))
        assert arr.shape[2] == 31 and arr.dtype == np.float32
        assert len(arr.attrs["extent_tan"]) == 4


def test_groundtruth_is_valid_coco_with_boxes_inside(smoke_collection, smoke_manifest):
    from pycocotools.coco import COCO

    coco = COCO(str(smoke_collection / "groundtruth.json"))
    n = smoke_manifest.environments * len(smoke_manifest.distances_m)
    assert len(coco.getImgIds()) == n and len(coco.getAnnIds(catIds=[3])) == n
    for img in coco.dataset["images"]:
        assert {"distance_m", "environment_id", "scene_id"} <= set(img)
        (ann,) = coco.loadAnns(coco.getAnnIds(imgIds=[img["id"]]))
        x, y, w, h = ann["bbox"]
        assert ann["category_id"] == 3 and w > 0 and h > 0
        assert 0 <= x and 0 <= y and x + w <= img["width"] and y + h <= img["height"]
    # Farther cars are smaller within each environment (paired design).
    for env in {i["environment_id"] for i in coco.dataset["images"]}:
        imgs = sorted((i for i in coco.dataset["images"] if i["environment_id"] == env), key=lambda i: i["distance_m"])
        widths = [coco.loadAnns(coco.getAnnIds(imgIds=[i["id"]]))[0]["bbox"][2] for i in imgs]
        assert widths == sorted(widths, reverse=True)


def test_same_seed_same_bytes_other_seed_different(smoke_collection, smoke_manifest, tmp_path):
    again = generate(smoke_manifest, tmp_path / "again")
    assert _resolved(again)["arrays"] == _resolved(smoke_collection)["arrays"]
    assert (again / "groundtruth.json").read_bytes() == (smoke_collection / "groundtruth.json").read_bytes()
    assert Collection.open(again).verify() == []
    reseeded = smoke_manifest.model_copy(update={"seed": smoke_manifest.seed + 1, "environments": 1})
    other = generate(reseeded, tmp_path / "other")
    other_hashes = set(_resolved(other)["arrays"].values())
    assert not other_hashes & set(_resolved(smoke_collection)["arrays"].values())


@pytest.mark.parametrize("fraction", [0.3, 0.7])
def test_killed_run_resumes_bit_identical_with_more_workers(smoke_collection, smoke_manifest, tmp_path, fraction):
    """Interrupted after about 30 % and 70 % of its units, resumed with two workers: the
    same arrays and ground truth as the uninterrupted collection."""
    out = tmp_path / "resumed"
    stopped_at = []

    def stop_part_way(done, total, key):
        if key is not None and done >= max(1, round(fraction * total)):
            stopped_at.append((done, total))
            raise KeyboardInterrupt

    with pytest.raises(KeyboardInterrupt):
        generate(smoke_manifest, out, progress=stop_part_way)
    done, total = stopped_at[0]
    assert 0 < done < total and abs(done / total - fraction) <= 1 / total
    assert not (out / "manifest.resolved.yaml").exists()
    with pytest.raises(CollectionError, match="generation has not finished"):
        Collection.open(out)
    # A torn progress record is redone, not trusted.
    records = sorted((out / "progress").glob("env*.json"))
    records[0].write_text("{ torn")
    generate(smoke_manifest, out, workers=2, threads=1)
    assert _resolved(out)["arrays"] == _resolved(smoke_collection)["arrays"]
    assert (out / "groundtruth.json").read_bytes() == (smoke_collection / "groundtruth.json").read_bytes()


@pytest.mark.skipif(not sys.platform.startswith("linux"), reason="PR_SET_PDEATHSIG is Linux-only")
def test_workers_die_with_a_killed_parent(tmp_path):
    """SIGKILL of `generate --workers 2` takes its render workers with it."""
    proc = subprocess.Popen([sys.executable, "-m", "metricscenes.cli", "generate", "--manifest", str(SMOKE),
                             "--out", str(tmp_path / "killed"), "--workers", "2"],
                            stdout=subprocess.DEVNULL, stderr=subprocess.DEVNULL)
    deadline = time.monotonic() + 60
    while time.monotonic() < deadline and len(_children(proc.pid)) < 2:
        time.sleep(0.2)
    workers = _children(proc.pid)
    assert len(workers) >= 2, "the workers never started"
    proc.kill()
    proc.wait()
    deadline = time.monotonic() + 20
    while time.monotonic() < deadline and any(_alive(pid) for pid in workers):
        time.sleep(0.2)
    assert not any(_alive(pid) for pid in workers)


def _children(pid: int) -> list[int]:
    found = []
    for stat in Path("/proc").glob("[0-9]*/stat"):
        try:
            fields = stat.read_text().rsplit(")", 1)[1].split()
        except OSError:
            continue
        if int(fields[1]) == pid and "multiprocessing" in (stat.parent / "cmdline").read_bytes().decode(errors="ignore"):
            found.append(int(stat.parent.name))
    return found


def _alive(pid: int) -> bool:
    try:
        state = Path(f"/proc/{pid}/stat").read_text().rsplit(")", 1)[1].split()[0]
    except OSError:
        return False
    return state != "Z"


def test_refuses_to_mix_manifests(smoke_collection, smoke_manifest, tmp_path):
    out = tmp_path / "mixed"
    shutil.copytree(smoke_collection, out)
    with pytest.raises(CollectionError, match="another manifest"):
        generate(smoke_manifest.model_copy(update={"seed": 1}), out)


def test_verify_finds_a_corrupted_chunk(smoke_collection, tmp_path):
    out = tmp_path / "corrupt"
    shutil.copytree(smoke_collection, out)
    path = next(iter(_resolved(out)["arrays"]))
    chunk = next(p for p in (out / "radiance.zarr" / path).rglob("*") if p.is_file() and p.name != "zarr.json")
    data = bytearray(chunk.read_bytes())
    data[len(data) // 2] ^= 0xFF
    chunk.write_bytes(bytes(data))
    assert any(path in problem for problem in Collection.open(out).verify())


def test_conditions_are_linear_mixes_of_light_groups(smoke_collection):
    c = Collection.open(smoke_collection)
    scene = c.scenes()[0].scene_id
    day, night = c.radiance(scene, "day"), c.radiance(scene, "night_regulation")
    both = c.radiance(scene, {"sky_day": 1.0, **c.conditions["night_regulation"]})
    for a, b, ab in zip(day.layers, night.layers, both.layers):
        np.testing.assert_allclose(a.radiance + b.radiance, ab.radiance, rtol=1e-5, atol=1e-12)
    assert len(day.layers) == 2 and day.layers[1].extent.width < day.layers[0].extent.width
    # The inset is finer than the plate, and angular_sampling reports the layers' grids.
    assert day.layers[1].pixel_tan[0] < day.layers[0].pixel_tan[0]
    for reported, layer in zip(c.angular_sampling(scene), day.layers, strict=True):
        assert reported["extent_tan"] == layer.extent.as_tuple() and reported["shape"] == layer.radiance.shape
        assert reported["mrad_per_px"] == pytest.approx((1e3 * layer.pixel_tan[0], 1e3 * layer.pixel_tan[1]))
    with pytest.raises(CollectionError, match="unknown condition"):
        c.radiance(scene, "dawn")


def test_open_refuses_incomplete_folders(tmp_path):
    with pytest.raises(CollectionError, match="no such"):
        Collection.open(tmp_path / "nothing")
    (tmp_path / "half").mkdir()
    with pytest.raises(CollectionError, match="missing"):
        Collection.open(tmp_path / "half")
    (tmp_path / "half" / "manifest.resolved.yaml").write_text(": not yaml : [")
    (tmp_path / "half" / "groundtruth.json").write_text("{}")
    (tmp_path / "half" / "radiance.zarr").mkdir()
    with pytest.raises(CollectionError, match="corrupted"):
        Collection.open(tmp_path / "half")


def test_photometry_and_illuminance_sweep(smoke_collection):
    c = Collection.open(smoke_collection)
    assert c.condition_names == ["day", "night", "night_regulation", "day@1lux", "day@100lux"]
    scene = c.scenes()[0].scene_id
    day, night = c.photometry(scene, "day"), c.photometry(scene, "night")
    # Daylight is tens of kilolux at the camera; night is below one lux.
    assert day["illuminance_at_camera_lux"] > 1e4 and night["illuminance_at_camera_lux"] < 1.0
    assert day["image_plane_illuminance_lux"] > 10.0
    for level in (1.0, 100.0):
        p = c.photometry(scene, f"day@{level:g}lux")
        assert p["illuminance_at_camera_lux"] == pytest.approx(level, rel=1e-9)
        # Scaling the only light group scales the luminance by the same factor.
        assert p["mean_luminance_cd_m2"] == pytest.approx(
            day["mean_luminance_cd_m2"] * level / day["illuminance_at_camera_lux"], rel=1e-4)
    # E = pi L / (1 + 4 N^2) for an ideal f/2.4 lens.
    assert day["image_plane_illuminance_lux"] == pytest.approx(np.pi * day["mean_luminance_cd_m2"] / (1 + 4 * 2.4**2))


def test_photometry_sums_the_groups_as_the_mix_measures(smoke_collection):
    """photometry() adds the light groups' luminances; the mix's own, measured, agrees (linear
    to the rounding) in every scene under every condition, targeted ones included."""
    c = Collection.open(smoke_collection)
    for scene in c.scenes()[::5]:
        for condition in c.held_condition_names:
            summed = c.photometry(scene.scene_id, condition)["mean_luminance_cd_m2"]
            assert summed == pytest.approx(c.mean_luminance(scene.scene_id, condition), rel=1e-5), (scene, condition)


def test_illuminance_sweep_keeps_lamps_on(smoke_collection):
    """``lamps_on`` groups join every sweep level at weight 1, the ambient group is scaled."""
    c = Collection.open(smoke_collection)
    sweep = c.manifest.illuminance_sweep.model_copy(update={"lamps_on": ("car_lights", "ego_lights")})
    c.manifest = c.manifest.model_copy(update={"illuminance_sweep": sweep})
    weights = c._weights("day@1lux", "env000-d025m")
    measured = c.resolved.illuminance_lux["env000"]["sky_day"]
    assert weights == pytest.approx({"sky_day": 1.0 / measured, "car_lights": 1.0, "ego_lights": 1.0})


def test_boxes_come_from_the_instance_mask_and_agree_with_the_projection(smoke_collection):
    import zarr

    from metricscenes.geometry import TanExtent
    from metricscenes.groundtruth import box_tan_to_xywh, mask_box_tan

    gt = json.loads((smoke_collection / "groundtruth.json").read_text())
    root = zarr.open_group(str(smoke_collection / "radiance.zarr"), mode="r")
    boxes = {a["image_id"]: a["bbox"] for a in gt["annotations"]}
    for img in gt["images"]:
        # The mask box and the projected mesh box agree (no occlusion, fine sampling).
        assert img["mask_vs_projection_iou"] >= 0.9, img["scene_id"]
        arr = root[f"masks/{img['scene_id']}"]
        mask = np.asarray(arr[...])
        assert mask.dtype == bool and 0 < mask.mean() < 1
        box = mask_box_tan(mask, TanExtent(*arr.attrs["extent_tan"]))
        np.testing.assert_allclose(box_tan_to_xywh(box, img["width"], img["height"]), boxes[img["id"]], atol=1e-3)


def test_feathered_inset_window_holds_the_ramp_outside_the_margins(smoke_manifest):
    from metricscenes.generate import inset_window
    from metricscenes.manifest import parse_manifest

    data = smoke_manifest.model_dump(mode="json")
    data["render"].update(inset_max_px=4096)  # the same scale k for both windows
    hard = parse_manifest(data)
    data["render"].update(inset_feather=0.1)
    feathered = parse_manifest(data)
    box = (-0.01, 0.0, 0.01, 0.012)  # tangent units, in the middle of the field
    k, x, y, w, h = inset_window(box, hard)
    k2, x2, y2, w2, h2 = inset_window(box, feathered)
    assert k2 == k
    # W' (1 - 2 f) = W: the full-weight middle is the hard window (to a pixel of rounding per edge).
    assert abs(w2 * 0.8 - w) <= 2 and abs(h2 * 0.8 - h) <= 2
    assert abs((x2 + w2 / 2) - (x + w / 2)) <= 1 and abs((y2 + h2 / 2) - (y + h / 2)) <= 1
