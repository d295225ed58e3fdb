"""--environments / --distances: a quick try on part of a collection, marked as a subset run
everywhere (results.json, the sweep cache key and folder) and refused by `benchmark submit`."""

from __future__ import annotations

import json

import pytest
from typer.testing import CliRunner

from benchmark.camera import load_camera
from benchmark.cli.main import app
from benchmark.experiments.run import run_camera
from benchmark.experiments.subset import CollectionSubset, parse_subset, subset_collection
from test_sweep_cache import N_ENV, FakeCollection, FakeDetector, fake_run_camera, patch_runs


def _lines(output: str) -> list[str]:
    return [line for line in output.splitlines() if line.strip()]


def test_parse_subset_ranges_and_errors(tmp_path):
    col = FakeCollection(tmp_path)
    distances = sorted({s.distance_m for s in col.scenes()})
    assert parse_subset(col) is None
    sub = parse_subset(col, "0-1,3", f"{distances[0]:g},{distances[1]:g}")
    assert sub == {"environments": [0, 1, 3], "distances_m": distances[:2]}
    assert parse_subset(col, f"0-{N_ENV - 1}", None) is None  # every scene: the full run, not a subset
    view = CollectionSubset(col, sub)
    assert {(s.environment_id, s.distance_m) for s in view.scenes()} <= {(e, d) for e in (0, 1, 3) for d in distances[:2]}
    gt = view.groundtruth()
    assert len(gt["images"]) == len(view.scenes()) > 0
    assert {a["image_id"] for a in gt["annotations"]} == {im["id"] for im in gt["images"]}
    assert view.name == col.name and view.manifest_sha256 == col.manifest_sha256  # the rest is the collection's
    for envs, dists, message in [("0-2,9", None, "unknown environment id(s) 9 (this collection has 0-3)"),
                                 ("a", None, "'a' is neither an environment id nor a range"),
                                 ("2-1", None, "empty range"),
                                 (None, "30", "unknown distance 30 m"),
                                 (None, "far", "'far' is not a distance"),
                                 (None, f"{distances[0]:g}", "a run needs two or more distances")]:
        with pytest.raises(ValueError, match=message.replace("(", r"\(").replace(")", r"\)")):
            subset_collection(col, envs, dists)


def test_run_camera_records_the_subset(tmp_path, monkeypatch):
    """The real run_camera on a subset: only the chosen scenes, ground truth to match, results.json marked."""
    import benchmark.camera.pipeline
    from test_sweep_cache import BlankCapture, BlankCollection, BlindDetector as Detector

    monkeypatch.setattr(benchmark.camera.pipeline, "simulate", lambda radiance, camera, seed: BlankCapture())
    col = BlankCollection(tmp_path)
    view = subset_collection(col, "1", None)
    results = run_camera(view, load_camera("cam01"), "day", Detector(), tmp_path / "run", save_images=False)
    assert results.subset.environments == [1]
    assert set(results.exposure_s) == {s.scene_id for s in col.scenes() if s.environment_id == 1}
    gt = json.loads((tmp_path / "run" / "groundtruth.json").read_text())
    assert {im["environment_id"] for im in gt["images"]} == {1}
    assert json.loads((tmp_path / "run" / "results.json").read_text())["subset"] == results.subset.model_dump()
    full = run_camera(col, load_camera("cam01"), "day", Detector(), tmp_path / "full", save_images=False)
    assert full.subset is None and "subset" not in (tmp_path / "full" / "results.json").read_text()  # full runs keep their bytes


@pytest.fixture
def fakes(monkeypatch, tmp_path):
    import benchmark.detectors
    import metricscenes.store

    def run(collection, *args, **kwargs):  # the fake writes what run_camera writes, with its subset mark
        from benchmark.result_files import Subset, write_results

        results = fake_run_camera(collection, *args, **kwargs)
        if getattr(collection, "subset", None):
            results.subset = Subset(**collection.subset)
            write_results(args[3] / "results.json", results)
        return results

    patch_runs(monkeypatch, run)
    monkeypatch.setattr(metricscenes.store.Collection, "open", classmethod(lambda cls, path: FakeCollection(tmp_path)))
    monkeypatch.setattr(benchmark.detectors, "load_detector", lambda model, **kw: FakeDetector(name=model))
    return tmp_path


def test_subset_sweep_is_marked_and_never_reused_as_full(fakes):
    out = fakes / "sw"
    base = ["sweep", "--collection", str(fakes), "--cameras", "cam01", "--conditions", "day", "--out", str(out),
            "--resamples", "20", "--mtf-source", "published_group"]
    quick = CliRunner().invoke(app, [*base, "--environments", "0-1"])
    assert quick.exit_code == 0, quick.output
    assert "subset run (environments 0,1" in quick.output
    meta = json.loads((out / "sweep.json").read_text())
    assert meta["subset"]["environments"] == [0, 1]
    subset_dir = out / meta["runs"][0]["path"]
    assert subset_dir.name.startswith("cam01-day+subset-")
    assert json.loads((subset_dir / "results.json").read_text())["subset"]["environments"] == [0, 1]
    again = CliRunner().invoke(app, [*base, "--environments", "0-1"])  # the same subset: reused
    assert again.exit_code == 0 and json.loads((out / "sweep.json").read_text())["runs"][0]["reused"]
    full = CliRunner().invoke(app, base)  # the full sweep: its own folder, computed, not the subset's
    assert full.exit_code == 0, full.output
    meta = json.loads((out / "sweep.json").read_text())
    assert meta["runs"][0] == {"camera": "cam01", "condition": "day", "path": "runs/cam01-day", "reused": False}
    assert "subset" not in meta and "subset run" not in full.output


def test_subset_cache_key(tmp_path):
    from benchmark.experiments.keys import results_key, run_key
    from benchmark.result_files import RunResults

    col = FakeCollection(tmp_path)
    cam = load_camera("cam01")
    full_key = run_key(cam, "day", FakeDetector(), col, 0)
    sub_key = run_key(cam, "day", FakeDetector(), subset_collection(col, "0", None), 0)
    assert "subset" not in full_key and sub_key["subset"] == {"environments": [0],
                                                              "distances_m": sorted({s.distance_m for s in col.scenes()})}
    results = {"camera": {"name": "cam01", "spec_sha256": cam.sha256()}, "condition": "day",
               "detector": {"name": "fake", "sha256": "d" * 64, "input_size": "multiscale"},
               "collection": {"manifest_sha256": "f" * 64}, "seed": 0, "subset": sub_key["subset"], "composite": "car"}
    assert results_key(RunResults.model_validate(results)) == sub_key != full_key


@pytest.mark.parametrize("command", ["run", "sweep"])
@pytest.mark.parametrize("extra, message", [
    (["--environments", "0-2,7"], "unknown environment id(s) 7"),
    (["--distances", "33"], "unknown distance 33 m"),
])
def test_unknown_subset_is_one_line_before_any_output(fakes, command, extra, message):
    args = [command, "--collection", str(fakes), "--out", str(fakes / "o"), *extra]
    args += ["--camera", "cam01"] if command == "run" else ["--cameras", "cam01"]
    result = CliRunner().invoke(app, args)
    assert result.exit_code == 2 and message in result.output
    assert len(_lines(result.output)) == 1 and not (fakes / "o").exists()


def test_submit_refuses_a_subset_run(tmp_path):
    from benchmark.leaderboard.schema import SubmissionError
    from benchmark.leaderboard.submission import RESULTS_FORMAT, find_runs

    subset = {"environments": [0], "distances_m": [25.0, 50.0]}
    (tmp_path / "results.json").write_text(json.dumps({"format": RESULTS_FORMAT, "camera": {"name": "cam01"}, "condition": "day",
                                                       "collection": {"manifest_sha256": "f" * 64}, "subset": subset}))
    with pytest.raises(SubmissionError, match="a subset run"):
        find_runs(tmp_path)
    result = CliRunner().invoke(app, ["submit", str(tmp_path), "--name", "quick"])
    assert result.exit_code != 0 and "a subset run" in result.output and len(_lines(result.output)) == 1


def test_run_command_says_it_is_a_subset(fakes):
    out = fakes / "r"
    result = CliRunner().invoke(app, ["run", "--camera", "cam01", "--collection", str(fakes), "--out", str(out),
                                      "--environments", "2", "--distances", "25,50"])
    assert result.exit_code == 0, result.output
    assert "subset run (environments 2; distances 25,50 m)" in result.output and "benchmark submit" in result.output
    assert json.loads((out / "results.json").read_text())["subset"] == {"environments": [2], "distances_m": [25.0, 50.0]}


def test_a_subset_reaches_a_sweeps_worker_processes(smoke_collection):
    """A sweep's workers receive the collection pickled: a subset must survive the trip
    (unpickling looked its attributes up before it had any, and recursed)."""
    import pickle

    from metricscenes.store import Collection

    subset = subset_collection(Collection.open(smoke_collection), distances="25,50")
    copy = pickle.loads(pickle.dumps(subset))
    assert copy.subset == subset.subset and [s.scene_id for s in copy.scenes()] == [s.scene_id for s in subset.scenes()]
