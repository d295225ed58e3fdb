"""The typed records of the result files (benchmark.result_files): every results.json,
od50.json and sweep.json parses and is written back byte for byte, and a malformed file is
one line naming it, from the functions and from the commands that read it."""

from __future__ import annotations

import json
import math
from pathlib import Path

import pytest
from typer.testing import CliRunner

from benchmark.result_files import (
    Od50Cache,
    Od50CacheKey,
    ResultsFileError,
    RunResults,
    read_od50_cache,
    read_results,
    read_sweep_record,
    read_sweep_table,
    write_od50_cache,
    write_results,
    write_sweep_record,
)
from benchmark.scoring.bootstrap import Od50Bootstrap

REPO = Path(__file__).resolve().parents[1]
SHA = "f" * 64

# A results.json with every optional field, in the order run.py writes them.
FULL = {
    "format": "metricscenes-results/1", "package_version": "0.1.0",
    "camera": {"name": "cam01", "pixel_um": 4.2, "f_number": 3.1, "width_px": 640, "height_px": 360,
               "spec_sha256": "a" * 64, "spec": {"name": "cam01", "sensor": {"pixel_um": 4.2}}},
    "condition": "day",
    "detector": {"name": "yolov5n-dynamic", "family": "yolov5", "sha256": "d" * 64, "input_size": 640,
                 "score_threshold": 0.001, "multi_label": True, "class_map": ["car", "-"]},
    "collection": {"name": "quick", "protocol": "quick", "manifest_sha256": SHA, "path": "collections/quick"},
    "seed": 0, "scoring_backend": "faster-coco-eval",
    "per_distance": [{"distance_m": 25.0, "ap": 0.8169, "ap50": 1.0, "n_images": 10},
                     {"distance_m": 50.0, "ap": float("nan"), "ap50": float("nan"), "n_images": 10}],
    "od50_m": None, "exposure_s": {"env000-d025m": 2.797e-05}, "detections_file": "detections.json",
    "detections_sha256": "e" * 64, "timing_s": {"camera": 1.5},
    "camera_geometry": {"hfov_deg": 30.0, "vfov_deg": 17.0, "window_tan": [-0.2, -0.1, 0.2, 0.1],
                        "collection_fov_deg": [34.3, 19.6]},
    "subset": {"environments": [0, 1], "distances_m": [25.0, 50.0]},
    "exposure_short_s": {"env000-d025m": 1.7e-06},
}


def _lines(text: str) -> list[str]:
    return [line for line in text.splitlines() if line.strip()]


def test_results_are_written_as_run_py_always_wrote_them(tmp_path):
    text = json.dumps(FULL, indent=1)
    (tmp_path / "in.json").write_text(text)
    results = read_results(tmp_path / "in.json")
    write_results(tmp_path / "out.json", results)
    assert (tmp_path / "out.json").read_text() == text
    # the optional fields a writer does not set stay out of the file
    plain = {k: v for k, v in FULL.items() if k not in ("camera_geometry", "subset", "exposure_short_s")}
    write_results(tmp_path / "plain.json", RunResults.model_validate(plain))
    assert (tmp_path / "plain.json").read_text() == json.dumps(plain, indent=1)


def test_results_read_as_typed_fields(tmp_path):
    (tmp_path / "results.json").write_text(json.dumps(FULL, indent=1))
    results = read_results(tmp_path / "results.json")
    assert results.camera.name == "cam01" and results.detector.input_size == 640
    assert results.ap_curve()[0] == [25.0, 50.0] and math.isnan(results.per_distance[1].ap)
    assert results.subset.environments == [0, 1] and results.detector.class_map == ["car", "-"]
    minimal = RunResults.model_validate({"camera": {"name": "c"}, "condition": "day", "collection": {"manifest_sha256": SHA}})
    assert (minimal.seed, minimal.scoring_backend, minimal.per_distance, minimal.detector) == (0, "faster-coco-eval", [], None)


def test_synthetic_run_round_trips(tmp_path):
    from benchmark.camera import load_camera
    from metricscenes.manifest import load_manifest
    from synthetic_leaderboard import write_synthetic_run

    write_synthetic_run(tmp_path, load_camera("cam03"), manifest=load_manifest(REPO / "manifests" / "smoke.yaml"))
    text = (tmp_path / "results.json").read_text()
    results = read_results(tmp_path / "results.json")
    write_results(tmp_path / "again.json", results)
    assert (tmp_path / "again.json").read_text() == text
    assert results.od50_censoring()[0] in ("", ">", "<")


def test_every_local_result_file_round_trips(tmp_path):
    """The result folders of this checkout (results/ is not in git: present where sweeps were run)."""
    runs = sorted(REPO.glob("results/*/runs/*/results.json"))
    if not runs:
        pytest.skip("no results/ folder in this checkout")
    out = tmp_path / "again.json"
    for path in runs:
        write_results(out, read_results(path))
        assert out.read_bytes() == path.read_bytes(), path
        if (od50 := path.with_name("od50.json")).is_file():
            write_od50_cache(out, read_od50_cache(od50))
            assert out.read_bytes() == od50.read_bytes(), od50
    for path in sorted(REPO.glob("results/*/sweep.json")):
        write_sweep_record(out, read_sweep_record(path))
        assert out.read_bytes() == path.read_bytes(), path


MALFORMED = [
    ("truncated", '{"camera": ', "not valid JSON"),
    ("not an object", "[1, 2]", "top level: Input should be a valid dictionary"),
    ("no condition", json.dumps({k: v for k, v in FULL.items() if k != "condition"}), "condition: Field required"),
    ("AP not a number", json.dumps({**FULL, "per_distance": [{**FULL["per_distance"][0], "ap": "high"}]}),
     "per_distance.0.ap: Input should be a valid number"),
    ("camera a string", json.dumps({**FULL, "camera": "cam01"}), "camera: Input should be a valid dictionary"),
]


@pytest.mark.parametrize("text, message", [c[1:] for c in MALFORMED], ids=[c[0] for c in MALFORMED])
def test_a_malformed_results_json_is_one_line_naming_it(tmp_path, text, message):
    path = tmp_path / "results.json"
    path.write_text(text)
    with pytest.raises(ResultsFileError) as info:
        read_results(path)
    line = str(info.value)
    assert "\n" not in line and line.startswith(f"{path}: ") and message in line, line


def test_many_problems_are_counted_not_listed(tmp_path):
    bad = {**FULL, "per_distance": [{"distance_m": "far", "ap": "high", "ap50": "low", "n_images": "ten"}] * 3}
    (tmp_path / "results.json").write_text(json.dumps(bad))
    with pytest.raises(ResultsFileError, match=r"and 9 more\)$"):
        read_results(tmp_path / "results.json")


@pytest.mark.parametrize("command", ["report", "compare", "submit"])
def test_commands_refuse_a_malformed_results_json_in_one_line(tmp_path, command):
    from benchmark.cli.main import app

    run = tmp_path / "run"
    run.mkdir()
    (run / "results.json").write_text(json.dumps({**FULL, "per_distance": "all of them"}))
    (run / "groundtruth.json").write_text('{"images": [], "annotations": []}')
    (run / "detections.json").write_text("[]")
    args = {"report": ["report", run], "compare": ["compare", run, run],
            "submit": ["submit", run, "--name", "x", "--leaderboard", tmp_path / "lb"]}[command]
    result = CliRunner().invoke(app, [str(a) for a in args])
    assert result.exit_code == 2, result.output
    lines = _lines(result.output)
    assert len(lines) == 1 and "Traceback" not in result.output, result.output
    assert "results.json" in lines[0] and "per_distance: Input should be a valid list" in " ".join(result.output.split())


def test_od50_cache_is_strict_json_and_reads_older_shapes(tmp_path):
    boot = Od50Bootstrap(od50_m=math.inf, sd_m=math.nan, ci95_m=(80.0, math.inf), n_resamples=20, n_environments=4,
                         n_infinite=3, censored=">", bound_m=200.0)
    cache = Od50Cache(key=Od50CacheKey(detections_sha256="e" * 64, n_resamples=20, seed=0), od50=boot)
    write_od50_cache(tmp_path / "od50.json", cache)
    stored = json.loads((tmp_path / "od50.json").read_text(), parse_constant=lambda c: pytest.fail(f"non-strict {c}"))
    assert stored["od50"] == {"od50_m": "inf", "sd_m": None, "ci95_m": [80.0, "inf"], "n_resamples": 20,
                              "n_environments": 4, "n_infinite": 3, "censored": ">", "bound_m": 200.0}
    back = read_od50_cache(tmp_path / "od50.json")
    assert back.key == cache.key and back.od50.od50_m == math.inf and math.isnan(back.od50.sd_m)
    # written before censoring was recorded, and by hand (no counts)
    older = {"key": stored["key"], "od50": {"od50_m": 89.7, "sd_m": 9.8, "ci95_m": [81.1, 118.6], "n_resamples": 20}}
    (tmp_path / "older.json").write_text(json.dumps(older))
    assert read_od50_cache(tmp_path / "older.json").od50.censored is None


def test_sweep_table_lacking_a_column_is_one_line(tmp_path):
    from benchmark.cli.main import app

    sweep = tmp_path / "sw"
    sweep.mkdir()
    (sweep / "sweep.csv").write_text("camera,condition,distance_m\ncam01,day,25.0\n")
    (sweep / "od50.csv").write_text("camera,condition,od50_m\ncam01,day,80.0\n")
    with pytest.raises(ResultsFileError, match=r"sweep.csv: not a sweep.csv table \(missing column\(s\) pixel_um, "):
        read_sweep_table(sweep / "sweep.csv")
    result = CliRunner().invoke(app, ["report", str(sweep)])
    assert result.exit_code == 2 and len(_lines(result.output)) == 1 and "missing column(s)" in result.output
