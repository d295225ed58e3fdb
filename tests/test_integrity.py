"""Integrity: a damaged collection is refused when read, listed whole by `verify`,
repaired by rerunning `generate`; benchmark never writes into a collection."""

import json
import shutil
import subprocess
import sys
from pathlib import Path

import pytest
import yaml

from cli_output import error_lines
from metricscenes.store import Collection, CollectionError

pytestmark = pytest.mark.slow
REPO = Path(__file__).resolve().parents[1]


def _copy(smoke_collection, tmp_path, name="copy") -> Path:
    out = tmp_path / name
    shutil.copytree(smoke_collection, out)
    return out


def _chunk(root: Path, path: str) -> Path:
    return next(p for p in (root / "radiance.zarr" / path).rglob("*") if p.is_file() and p.name != "zarr.json")


def flip_a_byte(root):
    chunk = _chunk(root, "insets/env000-d025m/sky_day")
    data = bytearray(chunk.read_bytes())
    data[len(data) // 2] ^= 0xFF
    chunk.write_bytes(bytes(data))
    return "env000-d025m", "insets/env000-d025m/sky_day"


def truncate_a_chunk(root):
    chunk = _chunk(root, "insets/env000-d050m/sky_night")
    chunk.write_bytes(chunk.read_bytes()[: chunk.stat().st_size // 2])
    return "env000-d050m", "insets/env000-d050m/sky_night"


def delete_a_chunk(root):
    _chunk(root, "plates/env001/sky_day").unlink()  # the plate of all six env001 scenes
    return "env001-d025m", "plates/env001/sky_day"


def delete_a_mask(root):
    shutil.rmtree(root / "radiance.zarr" / "masks" / "env000-d075m")
    return "env000-d075m", "masks/env000-d075m"


def move_a_box(root):
    gt = json.loads((root / "groundtruth.json").read_text())
    image_id = next(i["id"] for i in gt["images"] if i["scene_id"] == "env001-d100m")
    ann = next(a for a in gt["annotations"] if a["image_id"] == image_id)
    ann["bbox"][0] += 30.0
    (root / "groundtruth.json").write_text(json.dumps(gt, indent=1))
    return "env001-d100m", "groundtruth.json"


def empty_the_resolved_manifest(root):
    (root / "manifest.resolved.yaml").write_text("")
    return None, "manifest.resolved.yaml"


DAMAGES = [flip_a_byte, truncate_a_chunk, delete_a_chunk, delete_a_mask, move_a_box, empty_the_resolved_manifest]


def _read_scene(root: Path, scene_id: str | None) -> None:
    c = Collection.open(root)
    for condition in c.condition_names:
        c.radiance(scene_id, condition)


@pytest.mark.parametrize("damage", DAMAGES, ids=lambda d: d.__name__)
def test_reading_refuses_damage_in_one_line_naming_the_scene(smoke_collection, tmp_path, damage):
    root = _copy(smoke_collection, tmp_path)
    _read_scene(root, "env000-d025m")  # intact: reads (and caches its checks in this process)
    scene, item = damage(root)
    with pytest.raises(CollectionError) as info:
        _read_scene(root, scene or "env000-d025m")
    message = str(info.value)
    assert "\n" not in message and item in message
    if scene is not None:
        assert f"scene {scene}" in message


def test_a_missing_chunk_is_never_read_as_zeros(smoke_collection, tmp_path):
    root = _copy(smoke_collection, tmp_path)
    delete_a_chunk(root)
    c = Collection.open(root)
    with pytest.raises(CollectionError, match=r"plates/env001/sky_day does not match its sha256 \(its chunk is missing\)"):
        c.radiance("env001-d200m", "day")
    assert c.radiance("env000-d025m", "day")  # the other environment is intact


def test_verify_lists_every_problem_with_its_scene(smoke_collection, tmp_path):
    root = _copy(smoke_collection, tmp_path)
    from metricscenes.store import verify_collection

    damaged = [damage(root) for damage in DAMAGES]
    problems = verify_collection(root)  # Collection.open refuses it: the resolved manifest is empty
    for scene, item in damaged:
        matching = [p for p in problems if item in p]
        assert matching, (item, problems)
        if scene is not None and item.startswith("plates/"):
            assert any("environment env001" in p for p in matching)
        elif scene is not None:
            assert any(f"scene {scene}" in p for p in matching), (scene, problems)
    assert len(problems) == len(DAMAGES), problems
    # The command line lists them all and exits non-zero.
    proc = subprocess.run([sys.executable, "-m", "metricscenes.cli", "verify", str(root)], capture_output=True,
                          text=True, cwd=REPO, timeout=300)
    assert proc.returncode == 1 and "Traceback" not in proc.stdout + proc.stderr
    listed = [line for line in proc.stdout.splitlines() if line.startswith("bad: ")]
    assert len(listed) == len(DAMAGES), proc.stdout
    assert f"{len(DAMAGES)} problem(s)" in proc.stderr


def test_verify_passes_an_intact_collection(smoke_collection):
    assert Collection.open(smoke_collection).verify() == []


def test_generate_repairs_a_damaged_collection_bit_identically(smoke_collection, smoke_manifest, tmp_path):
    from metricscenes.generate import generate

    root = _copy(smoke_collection, tmp_path)
    for damage in DAMAGES:
        damage(root)
    notices = []
    generate(smoke_manifest, root, notice=notices.append)
    rerendered = {line.split()[1] for line in notices}
    assert rerendered == {"env000-d025m", "env000-d050m", "env001", "env000-d075m"}, notices
    for name in ("manifest.resolved.yaml", "groundtruth.json"):
        assert (root / name).read_bytes() == (smoke_collection / name).read_bytes(), name
    resolved = yaml.safe_load((root / "manifest.resolved.yaml").read_text())
    assert resolved["arrays"] == yaml.safe_load((smoke_collection / "manifest.resolved.yaml").read_text())["arrays"]
    assert Collection.open(root).verify() == []
    # Nothing left to repair: a second rerun renders nothing.
    notices.clear()
    generate(smoke_manifest, root, notice=notices.append, progress=lambda d, t, k: notices.append(k) if k else None)
    assert notices == []


def test_edited_resolved_manifest_is_refused(smoke_collection, tmp_path):
    root = _copy(smoke_collection, tmp_path)
    path = root / "manifest.resolved.yaml"
    resolved = yaml.safe_load(path.read_text())
    resolved["illuminance_lux"]["env000"]["sky_day"] *= 2  # would silently rescale day@1lux
    path.write_text(yaml.safe_dump(resolved, sort_keys=False))
    with pytest.raises(CollectionError, match="content_sha256"):
        Collection.open(root)
    resolved["manifest"]["conditions"]["night_regulation"]["car_lights"] = 2.0
    path.write_text(yaml.safe_dump(resolved, sort_keys=False))
    with pytest.raises(CollectionError, match="manifest_sha256"):
        Collection.open(root)


def test_collections_without_mask_and_groundtruth_hashes_are_still_read_and_checked(smoke_collection, tmp_path):
    """A collection written before masks and groundtruth.json had a sha256: boxes are
    recomputed from the masks instead."""
    root = _copy(smoke_collection, tmp_path)
    path = root / "manifest.resolved.yaml"
    resolved = yaml.safe_load(path.read_text())
    for key in ("groundtruth_sha256", "content_sha256"):
        del resolved[key]
    resolved["arrays"] = {k: v for k, v in resolved["arrays"].items() if not k.startswith("masks/")}
    path.write_text(yaml.safe_dump(resolved, sort_keys=False))
    assert Collection.open(root).verify() == []
    _read_scene(root, "env001-d100m")
    move_a_box(root)
    with pytest.raises(CollectionError, match="scene env001-d100m: its groundtruth.json box"):
        Collection.open(root)


# --- benchmark never writes into a collection; names that become paths ------------------

def test_out_inside_a_collection_is_refused(smoke_collection, tmp_path):
    from benchmark.experiments.run import check_out_dir, run_camera

    for out in (smoke_collection, smoke_collection / "results", smoke_collection / "radiance.zarr" / "x"):
        with pytest.raises(ValueError, match="read-only"):
            check_out_dir(out)
    assert check_out_dir(tmp_path / "results" / "run") == tmp_path / "results" / "run"
    with pytest.raises(ValueError, match="read-only"):  # the library refuses before it writes anything
        run_camera(Collection.open(smoke_collection), None, "day", None, smoke_collection / "r")
    assert not (smoke_collection / "r").exists()


@pytest.mark.parametrize("command", ["run", "sweep"])
def test_cli_out_inside_a_collection_is_one_line(smoke_collection, command):
    extra = ["--camera", "cam12"] if command == "run" else ["--cameras", "cam12", "--conditions", "day"]
    proc = subprocess.run([sys.executable, "-m", "benchmark.cli.main", command, "--collection", str(smoke_collection),
                           "--out", str(smoke_collection / "results"), *extra],
                          capture_output=True, text=True, cwd=REPO, timeout=300)
    assert proc.returncode != 0 and "Traceback" not in proc.stdout + proc.stderr
    lines = error_lines(proc.stderr)
    assert len(lines) == 1 and "read-only" in lines[0], proc.stderr
    assert not (smoke_collection / "results").exists()


@pytest.mark.parametrize("name", ["", "..", "a..b", "a/b", "a\\b", "a\0b", "a\nb", "a\rb"])
def test_path_name_rule_rejects(name):
    from benchmark.experiments.run import check_path_name
    from benchmark.experiments.sweep import run_name

    with pytest.raises(ValueError, match="cannot name a folder"):
        check_path_name(name, "name")
    with pytest.raises(ValueError, match="condition"):
        run_name("cam01", name)
    with pytest.raises(ValueError, match="camera name"):
        run_name(name, "day")


@pytest.mark.parametrize("name", ["day", "day@0.25lux", "cam01", "hdr-16", "percentile-99.9-level0.18"])
def test_path_name_rule_accepts(name):
    from benchmark.experiments.run import check_path_name

    assert check_path_name(name, "name") == name


def test_out_folder_name_follows_the_rule(tmp_path):
    from benchmark.experiments.run import check_out_dir

    for out in (tmp_path / "x" / "..", Path("."), Path("")):
        with pytest.raises(ValueError, match="cannot name a folder"):
            check_out_dir(out)


def test_sweep_refuses_a_condition_that_is_not_a_folder_name(tmp_path):
    """A collection whose manifest names a condition '../escape': no run folder is made."""
    from benchmark.camera import load_camera
    from benchmark.experiments.sweep import sweep

    class Collectionish:
        root, name, manifest_sha256 = tmp_path, "fake", "f" * 64
        condition_names = ["../escape"]

        def scenes(self):
            return []

    with pytest.raises(ValueError, match="condition '../escape' cannot name a folder"):
        sweep(Collectionish(), [load_camera("cam12")], ["../escape"], None, tmp_path / "sweep")
    assert not (tmp_path / "sweep").exists() and not (tmp_path / "escape").exists()


def test_generate_does_not_trust_a_progress_record_box(smoke_collection, smoke_manifest, tmp_path):
    from metricscenes.generate import generate

    root = _copy(smoke_collection, tmp_path)
    record_path = root / "progress" / "env000-d100m.json"
    record = json.loads(record_path.read_text())
    record["bbox_xywh"][0] += 30.0
    record_path.write_text(json.dumps(record))
    notices = []
    generate(smoke_manifest, root, notice=notices.append)
    assert [line.split()[1] for line in notices] == ["env000-d100m"], notices
    assert (root / "groundtruth.json").read_bytes() == (smoke_collection / "groundtruth.json").read_bytes()


def test_a_plate_is_mixed_once_for_its_scenes_and_read_again_once_changed(smoke_collection, tmp_path):
    import numpy as np

    root = _copy(smoke_collection, tmp_path)
    c = Collection.open(root)
    first = c.radiance("env000-d025m", "day").layers[0].radiance
    again = c.radiance("env000-d050m", "day").layers[0].radiance  # the same environment and condition
    assert again is first and not first.flags.writeable  # shared, so no reader may write into it
    np.testing.assert_array_equal(first, Collection.open(root).radiance("env000-d050m", "day").layers[0].radiance)
    night = c.radiance("env000-d050m", "night").layers[0].radiance  # other weights (and the car's lamps)
    assert night is not first
    np.testing.assert_array_equal(night, Collection.open(root).radiance("env000-d050m", "night").layers[0].radiance)
    c.radiance("env001-d025m", "day")  # env001's day plate is now the one kept
    chunk = _chunk(root, "plates/env001/sky_day")
    data = bytearray(chunk.read_bytes())
    data[len(data) // 2] ^= 0xFF
    chunk.write_bytes(bytes(data))
    with pytest.raises(CollectionError, match="plates/env001/sky_day does not match its sha256"):
        c.radiance("env001-d050m", "day")  # its file changed: read again, and checked


# --- array attributes under the checksum ------------------------------------------------

def _set_attribute(root: Path, path: str, name: str, change) -> None:
    """Edit one attribute in an array's zarr.json, as a hand or a tool would."""
    meta_path = root / "radiance.zarr" / path / "zarr.json"
    meta = json.loads(meta_path.read_text())
    meta["attributes"][name] = change(meta["attributes"].get(name))
    meta_path.write_text(json.dumps(meta, indent=2))


def _moved(extent):
    return [extent[0] + 0.001, extent[1], extent[2] + 0.001, extent[3]]


# (array, attribute, change): every kind of attribute a reader takes from an array's zarr.json
ATTRIBUTE_EDITS = [
    ("insets/env000-d025m/sky_day", "extent_tan", _moved),  # the car's placement
    ("masks/env000-d025m", "extent_tan", _moved),
    ("frames/env000-d025m/car_lights", "extent_tan", _moved),
    ("plates/env001/sky_day", "extent_tan", _moved),
    ("plates/env001/sky_night", "units", lambda _: "W sr-1 m-2 um-1"),
    ("insets/env000-d025m/sky_night", "wavelengths_nm", lambda w: [v + 5.0 for v in w]),
    ("insets/env000-d025m/car_lights", "light_group", lambda _: "sky_day"),
    ("plates/env001/ego_lights", "spp", lambda v: v + 1),
    # an attribute added: an identity basis decodes to the same values, so only this hash sees it
    ("insets/env000-d025m/ego_lights", "spectral_basis", lambda _: [[float(i == j) for j in range(31)] for i in range(31)]),
]


def _scene_of(path: str) -> str:
    unit = path.split("/")[1]
    return unit if "-" in unit else f"{unit}-d025m"


@pytest.mark.parametrize("path, name, change", ATTRIBUTE_EDITS, ids=[f"{p}:{n}" for p, n, _ in ATTRIBUTE_EDITS])
def test_an_edited_attribute_is_refused_on_read_naming_the_array(smoke_collection, tmp_path, path, name, change):
    root = _copy(smoke_collection, tmp_path)
    _set_attribute(root, path, name, change)
    c = Collection.open(root)  # opening reads no array
    with pytest.raises(CollectionError) as info:
        for condition in c.condition_names:
            c.radiance(_scene_of(path), condition)
            c.angular_sampling(_scene_of(path))
    message = str(info.value)
    assert "\n" not in message and f"{path} attributes do not match their sha256" in message, message
    assert "rerun `metricscenes generate`" in message


def test_verify_lists_edited_attributes_and_generate_repairs_them(smoke_collection, smoke_manifest, tmp_path):
    from metricscenes.generate import generate
    from metricscenes.store import verify_collection

    root = _copy(smoke_collection, tmp_path)
    for path, name, change in ATTRIBUTE_EDITS:
        _set_attribute(root, path, name, change)
    problems = verify_collection(root)
    assert len(problems) == len(ATTRIBUTE_EDITS), problems
    for path, _, _ in ATTRIBUTE_EDITS:
        assert any(f"{path} attributes do not match their sha256" in p for p in problems), (path, problems)
    before = {str(p.relative_to(root)): p.read_bytes() for p in root.rglob("*") if p.is_file()}
    proc = subprocess.run([sys.executable, "-m", "metricscenes.cli", "verify", str(root)], capture_output=True,
                          text=True, cwd=REPO, timeout=300)
    assert proc.returncode == 1 and "Traceback" not in proc.stdout + proc.stderr
    assert len([line for line in proc.stdout.splitlines() if line.startswith("bad: ")]) == len(ATTRIBUTE_EDITS)
    assert error_lines(proc.stderr) == [
        f"error: {root}: {len(ATTRIBUTE_EDITS)} problem(s); rerun `metricscenes generate` with its manifest to repair it"]
    assert {str(p.relative_to(root)): p.read_bytes() for p in root.rglob("*") if p.is_file()} == before
    notices = []
    generate(smoke_manifest, root, notice=notices.append)
    assert {line.split()[1] for line in notices} == {"env000-d025m", "env001"}, notices  # the two units, rendered again
    assert verify_collection(root) == []
    for path, _, _ in ATTRIBUTE_EDITS:
        meta = "radiance.zarr/" + path + "/zarr.json"
        assert (root / meta).read_bytes() == (smoke_collection / meta).read_bytes(), path
    for name in ("manifest.resolved.yaml", "groundtruth.json"):
        assert (root / name).read_bytes() == (smoke_collection / name).read_bytes(), name


def test_benchmark_run_refuses_a_moved_car_in_one_line_and_writes_nothing(smoke_collection, tmp_path):
    """The car's placement moved in the insets' zarr.json: unchecked, `benchmark run` exited 0
    with AP 0.000 at every distance; it stops at the first such scene."""
    root = _copy(smoke_collection, tmp_path)
    for scene in ("env000-d025m", "env001-d100m"):
        for group in ("sky_day", "sky_night", "car_lights", "ego_lights"):
            _set_attribute(root, f"insets/{scene}/{group}", "extent_tan", _moved)
    before = {str(p.relative_to(root)): p.read_bytes() for p in root.rglob("*") if p.is_file()}
    out = tmp_path / "run"
    proc = subprocess.run([sys.executable, "-m", "benchmark.cli.main", "run", "--camera", "cam12", "--collection",
                           str(root), "--out", str(out)], capture_output=True, text=True, cwd=REPO, timeout=300)
    assert proc.returncode == 2 and "Traceback" not in proc.stdout + proc.stderr
    lines = error_lines(proc.stderr)  # (a loaded machine can take 30 s to reach the first scene)
    assert len(lines) == 1 and "scene env000-d025m: insets/env000-d025m/" in lines[0], proc.stderr
    assert "attributes do not match their sha256" in lines[0]
    assert not out.exists()
    assert {str(p.relative_to(root)): p.read_bytes() for p in root.rglob("*") if p.is_file()} == before


def _as_written_before_attribute_hashes(root: Path) -> None:
    """Make a copy look like a collection written before attributes had a sha256: no
    attributes in its records, none in its resolved manifest (whose content hash is redone)."""
    from metricscenes.records import resolved_content_sha256

    for record_path in (root / "progress").glob("*.json"):
        record = json.loads(record_path.read_text())
        del record["attributes"]
        record_path.write_text(json.dumps(record, indent=1, sort_keys=True))
    path = root / "manifest.resolved.yaml"
    resolved = yaml.safe_load(path.read_text())
    del resolved["attributes_sha256"]
    resolved["content_sha256"] = resolved_content_sha256(resolved)
    path.write_text(yaml.safe_dump(resolved, sort_keys=False))


def test_an_older_collection_verifies_and_generate_records_its_attributes_without_rendering(
        smoke_collection, smoke_manifest, tmp_path):
    from metricscenes.generate import generate

    root = _copy(smoke_collection, tmp_path)
    _as_written_before_attribute_hashes(root)
    assert Collection.open(root).verify() == []
    _read_scene(root, "env000-d025m")  # read as before: unchecked attributes
    proc = subprocess.run([sys.executable, "-m", "metricscenes.cli", "verify", str(root)], capture_output=True,
                          text=True, cwd=REPO, timeout=300)
    assert proc.returncode == 0, proc.stderr
    notes = [line for line in proc.stdout.splitlines() if line.startswith("note: ")]
    assert len(notes) == 1 and "rerun `metricscenes generate` with its manifest to record them" in notes[0], proc.stdout
    rendered = []
    generate(smoke_manifest, root, notice=rendered.append,
             progress=lambda d, t, k: rendered.append(k) if k else None)
    assert rendered == []  # metadata only
    for path in [*(root / "progress").glob("*.json"), root / "manifest.resolved.yaml", root / "groundtruth.json"]:
        rel = path.relative_to(root)
        assert path.read_bytes() == (smoke_collection / rel).read_bytes(), rel
    proc = subprocess.run([sys.executable, "-m", "metricscenes.cli", "verify", str(root)], capture_output=True,
                          text=True, cwd=REPO, timeout=300)
    assert proc.returncode == 0 and "note:" not in proc.stdout


def test_an_older_collection_with_a_moved_car_is_rendered_again_not_blessed(smoke_collection, smoke_manifest, tmp_path):
    from metricscenes.generate import generate

    root = _copy(smoke_collection, tmp_path)
    _as_written_before_attribute_hashes(root)
    _set_attribute(root, "insets/env001-d100m/car_lights", "extent_tan", _moved)
    notices = []
    generate(smoke_manifest, root, notice=notices.append)
    assert notices == ["rendering env001-d100m again: env001-d100m: insets/env001-d100m/car_lights attribute "
                       "'extent_tan' is not the one written"]
    assert (root / "manifest.resolved.yaml").read_bytes() == (smoke_collection / "manifest.resolved.yaml").read_bytes()
    assert Collection.open(root).verify() == []


def test_attributes_of_every_store_setting_are_hashed_as_read_back(tmp_path):
    """The writer's attribute hashes are those of the zarr.json a reader sees, with a
    spectral basis and rounded mantissas too; an edited basis or rounding width is refused."""
    import numpy as np
    import zarr

    from metricscenes.geometry import REFERENCE_EXTENT
    from metricscenes.store import RADIANCE_STORE, attributes_sha256, read_checked
    from metricscenes.writer import UnitArrays

    cube = np.random.default_rng(0).random((9, 16, 31), dtype=np.float32)
    arrays = UnitArrays(tmp_path, "env000", mantissa_bits=8, spectral_basis=6)
    arrays.write_radiance("plates", "sky_day", cube, REFERENCE_EXTENT, {"spp": 4, "seed": 1})
    path = "plates/env000/sky_day"
    group = zarr.open_group(str(tmp_path / RADIANCE_STORE), mode="r")
    assert arrays.attributes_sha256[path] == attributes_sha256(dict(group[path].attrs))
    read_checked(tmp_path, group, path, arrays.sha256[path], "environment env000", arrays.attributes_sha256[path])
    for name, change in (("spectral_basis", lambda b: [[v * 1.0000001 for v in row] for row in b]),
                         ("mantissa_bits", lambda v: v + 1)):
        _set_attribute(tmp_path, path, name, change)
        group = zarr.open_group(str(tmp_path / RADIANCE_STORE), mode="r")
        with pytest.raises(CollectionError, match=f"{path} attributes do not match their sha256"):
            read_checked(tmp_path, group, path, arrays.sha256[path], "environment env000",
                         arrays.attributes_sha256[path])
        arrays.write_radiance("plates", "sky_day", cube, REFERENCE_EXTENT, {"spp": 4, "seed": 1})  # as it was
