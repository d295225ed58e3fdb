"""``benchmark cameras list`` shows the packaged extra cameras after the paper's 13, marked
extra; ``--cameras all`` stays the 13."""

from __future__ import annotations

import json

import pytest
from typer.testing import CliRunner

from benchmark.camera import camera_names, extra_camera_names
from benchmark.cli.main import app
from test_sweep_cli import fakes  # noqa: F401  (fixture)

runner = CliRunner()
PAPER = [f"cam{i:02d}" for i in range(1, 14)]


def test_list_json_puts_the_extras_after_the_13_marked_extra():
    result = runner.invoke(app, ["cameras", "list", "--json"])
    assert result.exit_code == 0, result.output
    rows = json.loads(result.stdout)
    assert extra_camera_names()  # the packaged auto-* cameras: else this test checks nothing
    assert [r["name"] for r in rows] == PAPER + extra_camera_names()
    assert [r["extra"] for r in rows] == [False] * 13 + [True] * len(extra_camera_names())
    assert all(set(r) == set(rows[0]) for r in rows)  # the same fields for every camera
    for r in rows[13:]:
        assert r["mtf50_group"] is None and r["mtf50_group_cy_per_mrad"] is None  # no paper group for an extra
        assert r["pixel_um"] > 0 and r["focal_length_mm"] > 0 and len(r["sha256"]) == 64


def test_list_table_shows_the_extras_after_the_13_marked_extra():
    result = runner.invoke(app, ["cameras", "list"])
    assert result.exit_code == 0, result.output
    lines = result.output.splitlines()
    first_cell = [line.split("│")[1].strip() if line.count("│") > 2 else None for line in lines]
    row = {name: first_cell.index(name) for name in PAPER + extra_camera_names()}  # each name whole, on its row
    assert max(row[name] for name in PAPER) < min(row[name] for name in extra_camera_names())
    for name in PAPER:
        assert lines[row[name]].split("│")[2].strip() == "paper"
    for name in extra_camera_names():
        assert lines[row[name]].split("│")[2].strip() == "extra"
    assert "not in --cameras all" in " ".join(result.output.split())


def test_cameras_all_stays_the_13(fakes, monkeypatch):  # noqa: F811
    seen = []

    def sweep(collection, cameras, *args, **kw):
        seen.extend(c.name for c in cameras)
        raise ValueError("stopped: the cameras are what this test reads")

    monkeypatch.setattr("benchmark.experiments.sweep.sweep", sweep)
    result = runner.invoke(app, ["sweep", "--collection", str(fakes), "--out", str(fakes / "sw"), "--cameras", "all",
                                 "--conditions", "day"])
    assert "stopped" in result.output
    assert seen == PAPER == camera_names()
    assert not set(seen) & set(extra_camera_names())


@pytest.mark.parametrize("name", ["auto-imx490-like", "auto-imx490-rccb-like"])
def test_an_extra_camera_from_the_list_loads_by_its_name(name):
    listed = json.loads(runner.invoke(app, ["cameras", "list", "--json"]).stdout)
    shown = json.loads(runner.invoke(app, ["cameras", "show", name, "--json"]).stdout)
    assert next(r for r in listed if r["name"] == name)["sha256"] == shown["sha256"]
