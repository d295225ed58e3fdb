"""A camera against itself with only the sensor-noise seed changed, on the real pipeline:
``compare`` calls no difference (docs/scoring.md, "Verdicts under a reseed")."""

from __future__ import annotations

import json

import pytest
import yaml
from conftest import SMOKE_MANIFEST, require_model
from typer.testing import CliRunner

# Six environments (above the minimum sample) at two near distances, where the detector finds
# the car, daylight only: 12 renders of about a second.
RESEED = {**yaml.safe_load(SMOKE_MANIFEST.read_text()), "name": "reseed", "environments": 6, "distances_m": [25, 50],
          "light_groups": ["sky_day"], "conditions": {"day": {"sky_day": 1.0}}}
del RESEED["illuminance_sweep"]


@pytest.fixture(scope="module")
def reseed_runs(tmp_path_factory):
    """The collection, and one small camera run with noise seeds 0 and 1."""
    from benchmark.cli.main import app
    from metricscenes.generate import generate
    from metricscenes.manifest import parse_manifest

    require_model("yolov5n-dynamic.onnx")
    work = tmp_path_factory.mktemp("reseed")
    collection = generate(parse_manifest(RESEED), work / "collection")
    spec = work / "small.yaml"
    spec.write_text("name: small\noptics: {f_number: 2.0}\nsensor: {pixel_um: 5.6}\n")
    runs = []
    for seed in (0, 1):
        out = work / f"seed{seed}"
        result = CliRunner().invoke(app, ["run", "--camera", str(spec), "--collection", str(collection),
                                          "--seed", str(seed), "--out", str(out)])
        assert result.exit_code == 0, result.output
        runs.append(out)
    return runs


@pytest.mark.slow
def test_a_camera_against_itself_reseeded_is_no_difference(reseed_runs, tmp_path):
    from benchmark.experiments.compare import compare_runs, load_side

    a, b = (load_side(run) for run in reseed_runs)
    assert a.detections != b.detections  # the noise did change the detections
    result = compare_runs(a, b)
    assert not result["sample_too_small"] and result["n_environments"] == 6
    assert result["family"]["members"] == 3  # two distances and the headline
    found = [r for r in result["per_distance"] if max(r["found_a"], r["found_b"]) >= r["cars_needed"]]
    assert found, "the detector found the car nowhere: the comparison would test nothing"
    assert not any(r["resolved"] for r in result["per_distance"])
    for row in result["per_distance"]:
        assert row["ci95"][0] <= 0 <= row["ci95"][1], row
    headline = result["delta_od50"] if result["delta_od50"]["delta_m"] is not None else result["delta_ap_range"]
    assert headline["ci95_m"][0] <= 0 <= headline["ci95_m"][1], headline
    assert result["verdict"].startswith("daylight: no difference resolved between"), result["verdict"]
    # the same through the command, which writes what it printed
    from benchmark.cli.main import app

    out = CliRunner().invoke(app, ["compare", str(reseed_runs[0]), str(reseed_runs[1]), "--out", str(tmp_path / "c")])
    assert out.exit_code == 0, out.output
    assert "no difference resolved" in out.output
