"""A submission says what decided its bytes (versions, the CPU's kernel class), and
``submit --check`` warns where this machine differs."""

from __future__ import annotations

import json
from pathlib import Path

from typer.testing import CliRunner

from benchmark.cli.main import app
from benchmark.leaderboard.submission import software_differences
from benchmark.leaderboard.validate import validate_submission
from metricscenes.numeric_pins import isa_class, package_versions

REPO = Path(__file__).resolve().parents[1]
REFERENCE = REPO / "leaderboard" / "submissions" / "ref-cam12-yolov5n-quick.json"


def _with_software(versions: dict, isa: str) -> dict:
    sub = json.loads(REFERENCE.read_text())
    sub["software"] = {"versions": versions, "isa_class": isa}
    return sub


def test_the_same_software_is_no_difference_and_validates():
    sub = _with_software(package_versions(), isa_class())
    assert validate_submission(sub, source="s") is sub and software_differences(sub) == []
    assert software_differences(json.loads(REFERENCE.read_text())) == []  # made before it was recorded: silent


def test_check_warns_about_other_versions_and_another_kernel_class(tmp_path):
    other_isa = "avx512" if isa_class() != "avx512" else "avx2"
    sub = _with_software({**package_versions(), "numpy": "1.0.0"}, other_isa)
    assert software_differences(sub) == [f"numpy 1.0.0 (here {package_versions()['numpy']})",
                                         f"made on an x86-64 {other_isa} machine (here {isa_class()})"]
    path = tmp_path / "ref-cam12-yolov5n-quick.json"
    path.write_text(json.dumps(sub))
    res = CliRunner().invoke(app, ["submit", "--check", str(path), "--leaderboard", str(tmp_path / "lb")])
    assert res.exit_code == 0, res.output
    assert "warning: ref-cam12-yolov5n-quick.json was made with numpy 1.0.0" in res.output
