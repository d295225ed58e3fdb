"""metricscenes.first_environments: a collection's first K environments as a collection of
their own, for scoring beside the same K rendered elsewhere (docs/performance.md, "On a GPU")."""

import json
import shutil

import pytest

from conftest import REPO, SMOKE_MANIFEST
from metricscenes import first_environments


def test_manifest_text_changes_the_count_and_the_name_only():
    """The GPU machine renders from this text too, so both machines' collections carry one
    manifest sha256 and `benchmark compare` pairs their runs."""
    import yaml

    from metricscenes.manifest import load_manifest, parse_manifest

    source = (REPO / "manifests" / "metric-300.yaml").read_text()
    text = first_environments.first_manifest_text(source, 8)
    changed = [(a, b) for a, b in zip(source.splitlines(), text.splitlines()) if a != b]
    assert changed == [("name: metric-300", "name: metric-300-first8"), ("environments: 50", "environments: 8")]
    assert len(text.splitlines()) == len(source.splitlines())
    first = parse_manifest(yaml.safe_load(text), source="first 8")
    whole = load_manifest(REPO / "manifests" / "metric-300.yaml")
    assert first.environments == 8 and first.seed == whole.seed and first.render == whole.render


@pytest.mark.slow
def test_first_environment_of_smoke(smoke_collection, tmp_path):
    from metricscenes.store import Collection, verify_collection

    root_meta = (smoke_collection / "radiance.zarr" / "zarr.json").read_bytes()
    out = tmp_path / "first1"
    assert first_environments.main([str(smoke_collection), str(SMOKE_MANIFEST), "1", str(out)]) == 0
    assert verify_collection(out) == []
    first = Collection.open(out)
    assert first.manifest.environments == 1 and first.manifest.name == "smoke-first1"
    gt = json.loads((out / "groundtruth.json").read_text())
    whole = json.loads((smoke_collection / "groundtruth.json").read_text())
    assert gt["images"] == [i for i in whole["images"] if i["environment_id"] == 0]
    # the source is untouched (its root's attributes name its own manifest) and the arrays are shared, not copied
    assert (smoke_collection / "radiance.zarr" / "zarr.json").read_bytes() == root_meta
    chunk = next(p for p in (out / "radiance.zarr" / "plates").rglob("*") if p.is_file() and p.name != "zarr.json")
    assert chunk.stat().st_nlink >= 2


def test_refuses_an_unfinished_source_and_an_existing_folder(smoke_collection, tmp_path, capsys):
    partial = tmp_path / "partial"
    shutil.copytree(smoke_collection / "progress", partial / "progress")
    (partial / "progress" / "env000-d200m.json").unlink()
    assert first_environments.main([str(partial), str(SMOKE_MANIFEST), "1", str(tmp_path / "out")]) == 1
    assert "has not finished 1 of the 7 units (first: env000-d200m)" in capsys.readouterr().err
    assert not (tmp_path / "out").exists()
    assert first_environments.main([str(smoke_collection), str(SMOKE_MANIFEST), "1", str(tmp_path)]) == 1
    assert "exists; choose a new folder" in capsys.readouterr().err
