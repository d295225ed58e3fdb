"""The command lines: user errors end in one line and a non-zero exit, never a traceback."""

import json
import subprocess
import sys

import pytest

from cli_output import error_lines
from conftest import REPO, SMOKE_MANIFEST


def _run(module, *args):
    return subprocess.run([sys.executable, "-m", module, *map(str, args)], capture_output=True, text=True,
                          cwd=REPO, timeout=300)


def _one_line_error(proc):
    assert proc.returncode != 0
    assert "Traceback" not in proc.stderr + proc.stdout
    lines = error_lines(proc.stderr)
    assert len(lines) == 1, proc.stderr
    return lines[0]


def test_malformed_manifest_is_one_line(tmp_path):
    bad = tmp_path / "bad.yaml"
    bad.write_text(SMOKE_MANIFEST.read_text().replace("environments: 2", "environments: -3"))
    line = _one_line_error(_run("metricscenes.cli", "generate", "--manifest", bad, "--out", tmp_path / "c"))
    assert "environments" in line
    assert not (tmp_path / "c").exists()


def test_dry_run_prints_the_plan():
    proc = _run("metricscenes.cli", "generate", "--manifest", SMOKE_MANIFEST, "--dry-run", "--json")
    assert proc.returncode == 0, proc.stderr
    plan = json.loads(proc.stdout)
    assert len(plan["scenes"]) == 12
    assert {"scene_id", "environment_id", "distance_m", "car_id", "road_id", "sky_day_id"} <= set(plan["scenes"][0])


@pytest.mark.slow
def test_missing_model_file_is_one_line(smoke_collection, tmp_path):
    line = _one_line_error(_run("benchmark.cli.main", "run", "--camera", "cam12", "--collection", smoke_collection,
                                "--model", tmp_path / "nope.onnx", "--out", tmp_path / "r"))
    assert "nope.onnx" in line


def test_unknown_camera_and_collection_are_one_line(tmp_path):
    line = _one_line_error(_run("benchmark.cli.main", "run", "--camera", "cam99", "--collection", tmp_path,
                                "--out", tmp_path / "r"))
    assert "cam99" in line
    line = _one_line_error(_run("metricscenes.cli", "info", tmp_path / "absent"))
    assert "absent" in line


def test_score_rescores_a_run_folder(tmp_path):
    from typer.testing import CliRunner

    from benchmark.cli.main import app
    from synthetic_scoring import synthetic_collection

    gt, dets = synthetic_collection(n_environments=4, seed=3)
    (tmp_path / "groundtruth.json").write_text(json.dumps(gt))
    (tmp_path / "detections.json").write_text(json.dumps(dets))
    runner = CliRunner()
    fast = json.loads(runner.invoke(app, ["score", str(tmp_path), "--json"]).output)
    ref = json.loads(runner.invoke(app, ["score", str(tmp_path), "--json", "--backend", "pycocotools"]).output)
    assert [r["ap"] for r in fast["per_distance"]] == pytest.approx([r["ap"] for r in ref["per_distance"]], abs=1e-12)
    assert all(0 <= r["rate"] <= 1 for r in fast["per_distance"])
    line = _one_line_error(_run("benchmark.cli.main", "score", tmp_path / "absent"))
    assert "not a run folder" in line


def test_llvm_variant_never_aborts_the_process(tmp_path):
    """With a libLLVM < 17 the LLVM variants abort the process on the first render; the
    generator probes them in a child process and reports one line instead."""
    import yaml

    data = yaml.safe_load(SMOKE_MANIFEST.read_text())
    data.update(environments=1, distances_m=[25], light_groups=["sky_day"], conditions={"day": {"sky_day": 1.0}})
    data.pop("illuminance_sweep")
    data["render"]["variant"] = "llvm_ad_spectral"
    manifest = tmp_path / "llvm.yaml"
    manifest.write_text(yaml.safe_dump(data))
    proc = _run("metricscenes.cli", "generate", "--manifest", manifest, "--out", tmp_path / "c")
    if proc.returncode != 0:  # the image's libLLVM 15: a clear error, not an abort
        line = _one_line_error(proc)
        assert "llvm_ad_spectral" in line and "scalar_spectral" in line
        assert proc.returncode == 2
    else:  # a libLLVM >= 17 is installed: it renders
        assert (tmp_path / "c" / "groundtruth.json").exists()


def test_variant_probe_renders_with_a_variant_that_works():
    """The probe script must itself be a valid render: with the always-working CPU variant it
    exits 0 (it once lacked an integrator, so every LLVM and CUDA variant was refused)."""
    import subprocess
    import sys

    from metricscenes.render import _LLVM_PROBE

    probe = subprocess.run([sys.executable, "-c", _LLVM_PROBE.format(variant="scalar_spectral")],
                           capture_output=True, text=True, timeout=300)
    assert probe.returncode == 0, probe.stderr[-300:]


def test_preview_exposes_the_whole_sheet_once(smoke_collection, tmp_path):
    """One white for every tile of a condition (a dark scene stays dark next to a lit one);
    --white fixes it across conditions, so night is darker than day on the same scale."""
    import numpy as np
    from PIL import Image
    from typer.testing import CliRunner

    from metricscenes.cli import app
    from metricscenes.preview import white_luminance, xyz_to_srgb8

    runner = CliRunner()
    result = runner.invoke(app, ["preview", str(smoke_collection), "--condition", "night", "--out", str(tmp_path / "n.png")])
    assert result.exit_code == 0 and "cd/m² for every tile" in result.output
    mean = {}
    for condition in ("day", "night"):
        out = tmp_path / f"{condition}-fixed.png"
        result = runner.invoke(app, ["preview", str(smoke_collection), "--condition", condition, "--white", "5000",
                                     "--out", str(out)])
        assert result.exit_code == 0 and "white = 5000 cd/m²" in result.output
        mean[condition] = np.asarray(Image.open(out), float).mean()
    assert mean["night"] < 0.5 * mean["day"]
    # The rule itself: a tile ten times darker than its neighbour stays darker on a shared white.
    bright, dark = np.full((4, 4, 3), 10.0), np.full((4, 4, 3), 1.0)
    white = white_luminance([bright, dark])
    assert xyz_to_srgb8(dark, white).mean() < xyz_to_srgb8(bright, white).mean()
    assert xyz_to_srgb8(dark, white_luminance([dark])).mean() == xyz_to_srgb8(bright, white_luminance([bright])).mean()
