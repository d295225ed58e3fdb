"""Read-only outside one's own output, and the last bad inputs:
no command writes into a collection, the leaderboard or another command's folder; two
writers to one folder are refused; a killed run's staging folder is cleaned; range
arguments are bounded before anything is listed; five tracebacks became one line.

Every refusal: exit code 2, one line naming the input and the problem, and the files of
the collection, the run, the sweep and the leaderboard byte-identical, nothing created."""

from __future__ import annotations

import hashlib
import json
import shutil
import subprocess
import sys
import time
from pathlib import Path

import numpy as np
import pytest
from typer.testing import CliRunner

from cli_output import error_lines
from conftest import REPO, require_model

BENCHMARK, METRICSCENES = "benchmark", "metricscenes"


def _app(which: str):
    if which == BENCHMARK:
        from benchmark.cli.main import app
    else:
        from metricscenes.cli import app
    return app


def _snapshot(root: Path) -> dict[str, str]:
    """Every file and folder under ``root`` by relative path: sha256 of a file's bytes."""
    return {str(p.relative_to(root)): hashlib.sha256(p.read_bytes()).hexdigest() if p.is_file() else "dir"
            for p in sorted(root.rglob("*"))}


def _refused(which: str, args: list, *words: str) -> str:
    """Invoke a command in this process; assert exit code 2 and one `error:` line holding
    ``words``; return the line."""
    result = CliRunner().invoke(_app(which), [str(a) for a in args])
    assert result.exit_code == 2, (result.output, result.exception)
    assert result.exception is None or isinstance(result.exception, SystemExit), repr(result.exception)
    lines = [line for line in result.output.splitlines() if line.strip()]
    assert len(lines) == 1 and lines[0].startswith("error: "), result.output
    for word in words:
        assert word in lines[0], lines[0]
    return lines[0]


@pytest.fixture(scope="module")
def world(smoke_collection, tmp_path_factory):
    """A folder holding a copy of the smoke collection (col), a run folder (run), a sweep
    folder (sweep), a leaderboard (lb) and an image outside all of them (photo.png)."""
    from PIL import Image

    from benchmark.camera import load_camera
    from metricscenes.manifest import load_manifest
    from synthetic_leaderboard import write_synthetic_run

    root = tmp_path_factory.mktemp("world")
    shutil.copytree(smoke_collection, root / "col")
    write_synthetic_run(root / "run", load_camera("cam12"), "day", manifest=load_manifest(REPO / "manifests" / "smoke.yaml"))
    (root / "run" / "images").mkdir()
    Image.fromarray(np.zeros((64, 64, 3), np.uint8)).save(root / "run" / "images" / "env000-d025m.png")
    (root / "sweep" / "runs").mkdir(parents=True)
    (root / "sweep" / "sweep.csv").write_text("camera,condition\n")
    (root / "lb" / "submissions").mkdir(parents=True)
    shutil.copy(REPO / "leaderboard" / "submissions" / "ref-cam12-yolov5n-quick.json", root / "lb" / "submissions")
    (root / "lb" / "README.md").write_text("# leaderboard\n")
    Image.fromarray(np.zeros((64, 64, 3), np.uint8)).save(root / "photo.png")
    return root


def _col_run(world, out):
    return ["run", "--camera", "cam12", "--collection", world / "col", "--out", out]


# (id, which CLI, arguments from the world folder, words of the one line)
OUT_OF_BOUNDS = [
    # a file where a folder or an image belongs
    ("export-over-groundtruth", METRICSCENES, lambda w: ["export", w / "col", w / "col" / "groundtruth.json", "--scene", "env000-d100m"],
     ["OUT", "groundtruth.json: the file name must end in .h5 or .hdf5"]),
    ("export-into-the-collection", METRICSCENES, lambda w: ["export", w / "col", w / "col" / "scene.h5", "--scene", "env000-d100m"],
     ["scene.h5 is inside the collection", "collections are written only by `metricscenes generate`"]),
    ("report-over-groundtruth", BENCHMARK, lambda w: ["report", w / "run", "--out", w / "col" / "groundtruth.json"],
     ["groundtruth.json: the report is an HTML page"]),
    ("report-into-the-collection", BENCHMARK, lambda w: ["report", w / "run", "--out", w / "col" / "report.html"],
     ["report.html is inside the collection"]),
    ("report-over-a-submission", BENCHMARK, lambda w: ["report", w / "run", "--out", w / "lb" / "submissions" / "ref-cam12-yolov5n-quick.json"],
     ["the report is an HTML page"]),
    ("report-into-the-leaderboard", BENCHMARK, lambda w: ["report", w / "run", "--out", w / "lb" / "submissions" / "r.html"],
     ["r.html is inside the leaderboard", "written only by `benchmark submit` and `benchmark leaderboard`"]),
    ("report-into-a-sweep", BENCHMARK, lambda w: ["report", w / "run", "--out", w / "sweep" / "report.html"],
     ["report.html is inside the sweep folder"]),
    ("report-of-a-collection", BENCHMARK, lambda w: ["report", w / "col"], ["col is neither a sweep folder (sweep.csv) nor a run folder (results.json)"]),
    ("run-into-the-leaderboard", BENCHMARK, lambda w: _col_run(w, w / "lb" / "submissions"), ["submissions is inside the leaderboard"]),
    ("run-inside-another-run", BENCHMARK, lambda w: _col_run(w, w / "run" / "again"), ["again is inside the run folder", "another run's results"]),
    ("run-over-a-sweep", BENCHMARK, lambda w: _col_run(w, w / "sweep"), ["--out", "sweep is the sweep folder"]),
    ("run-into-the-collection", BENCHMARK, lambda w: _col_run(w, w / "col"), ["read-only"]),
    ("sweep-over-a-run", BENCHMARK, lambda w: ["sweep", "--collection", w / "col", "--cameras", "cam12", "--out", w / "run"],
     ["run is the run folder"]),
    ("sweep-into-the-leaderboard", BENCHMARK, lambda w: ["sweep", "--collection", w / "col", "--cameras", "cam12", "--out", w / "lb" / "s"],
     ["s is inside the leaderboard"]),
    ("preview-into-the-collection", METRICSCENES, lambda w: ["preview", w / "col", "--out", w / "col" / "sheet.png"],
     ["sheet.png is inside the collection"]),
    ("preview-assets-into-the-leaderboard", METRICSCENES, lambda w: ["preview-assets", "cars", "--out", w / "lb" / "cars.png"],
     ["cars.png is inside the leaderboard"]),
    ("generate-inside-a-run", METRICSCENES, lambda w: ["generate", "--manifest", REPO / "manifests" / "smoke.yaml", "--out", w / "run" / "c"],
     ["c is inside the run folder"]),
    ("detect-over-a-runs-image", BENCHMARK, lambda w: ["detect", w / "photo.png", "--save", w / "run" / "images" / "env000-d025m.png"],
     ["env000-d025m.png is inside the run folder"]),
    ("submit-into-a-collection", BENCHMARK, lambda w: ["submit", w / "run", "--name", "x", "--leaderboard", w / "col"],
     ["--leaderboard", "col is the collection"]),
    ("leaderboard-over-a-run", BENCHMARK, lambda w: ["leaderboard", "--dir", w / "run"], ["--dir", "run is the run folder"]),
    ("compare-into-a-run", BENCHMARK, lambda w: ["compare", w / "run", w / "run", "--out", w / "run" / "cmp"],
     ["cmp is inside the run folder"]),
    # point 4: the five tracebacks (the fifth, the huge range, below)
    ("preview-out-json", METRICSCENES, lambda w: ["preview", w / "col", "--out", w / "x.json"], ["x.json: the file name must end in .png"]),
    ("preview-assets-out-json", METRICSCENES, lambda w: ["preview-assets", "cars", "--out", w / "x.json"],
     ["x.json: the file name must end in .png"]),
    ("submit-leaderboard-file", BENCHMARK, lambda w: ["submit", w / "run", "--name", "x", "--leaderboard", w / "photo.png"],
     ["--leaderboard", "photo.png is a file, not a leaderboard folder"]),
    ("run-environments-huge-range", BENCHMARK, lambda w: [*_col_run(w, w / "new"), "--environments", "0-999999999"],
     ["--environments 0-999999999: unknown environment id(s) 2-999999999 (this collection has 0-1)"]),
    ("sweep-environments-huge-range", BENCHMARK,
     lambda w: ["sweep", "--collection", w / "col", "--cameras", "cam12", "--out", w / "new", "--environments", "1,3-999999999,5"],
     ["unknown environment id(s) 3-999999999, 5 (this collection has 0-1)"]),
]  # fmt: skip


@pytest.mark.parametrize("case", OUT_OF_BOUNDS, ids=[c[0] for c in OUT_OF_BOUNDS])
def test_nothing_is_written_outside_a_commands_own_output(world, case, monkeypatch):
    _, which, args, words = case
    monkeypatch.chdir(world)
    before = _snapshot(world)
    started = time.perf_counter()
    _refused(which, args(world), *words)
    assert _snapshot(world) == before
    assert time.perf_counter() - started < 60  # refused before any work (a range is not listed)


def test_info_photometry_on_a_damaged_collection_is_one_line(smoke_collection, tmp_path):
    root = tmp_path / "col"
    shutil.copytree(smoke_collection, root)
    chunk = next(p for p in (root / "radiance.zarr" / "insets" / "env001-d150m" / "sky_day").rglob("*")
                 if p.is_file() and p.name != "zarr.json")
    chunk.write_bytes(chunk.read_bytes()[:1000])
    before = _snapshot(tmp_path)
    _refused(METRICSCENES, ["info", root, "--photometry"], "scene env001-d150m: insets/env001-d150m/sky_day",
             "rerun `metricscenes generate`")
    assert _snapshot(tmp_path) == before


def test_preview_writes_beside_the_user_not_into_the_collection(world, tmp_path, monkeypatch):
    monkeypatch.chdir(tmp_path)
    before = _snapshot(world)
    result = CliRunner().invoke(_app(METRICSCENES), ["preview", str(world / "col"), "--condition", "day", "--white", "5000"])
    assert result.exit_code == 0, result.output
    assert sorted(p.name for p in tmp_path.iterdir()) == ["preview-smoke-day.png"]
    assert _snapshot(world) == before


# --- one writer per output folder; a killed run's stage -----------------------------------

def _fake_run(out: Path, monkeypatch):
    """The real run_camera on a synthetic collection with a blank camera and a detector
    that finds nothing (fast): what matters here is where it writes."""
    import benchmark.camera.pipeline
    from benchmark.camera import load_camera
    from benchmark.experiments.run import run_camera
    from test_sweep_cache import BlankCapture, BlankCollection, BlindDetector

    monkeypatch.setattr(benchmark.camera.pipeline, "simulate", lambda radiance, camera, seed: BlankCapture())
    return run_camera(BlankCollection(out.parent), load_camera("cam01"), "day", BlindDetector(), out, save_images=False)


def test_a_second_writer_of_a_run_folder_is_refused_naming_the_first(tmp_path, monkeypatch):
    import os

    from metricscenes.lock import LockError, output_lock

    out = tmp_path / "run"
    out.mkdir()
    (out / "notes.txt").write_text("kept\n")
    before = _snapshot(tmp_path)
    with output_lock(out, "benchmark run", "run folder"):
        held = _snapshot(tmp_path)
        with pytest.raises(LockError) as info:
            _fake_run(out, monkeypatch)
        assert _snapshot(tmp_path) == held
    message = str(info.value)
    assert "\n" not in message and f"{out}: another `benchmark run` is writing this run folder (PID {os.getpid()}" in message
    assert _snapshot(tmp_path) == before  # the lock is gone with its holder
    _fake_run(out, monkeypatch)
    assert (out / "results.json").is_file() and not (out / "benchmark.lock").exists()


def test_a_second_sweep_on_one_folder_is_refused(tmp_path, monkeypatch):
    import os

    from metricscenes.lock import output_lock

    import benchmark.detectors
    import metricscenes.store
    from test_sweep_cache import FakeCollection, FakeDetector

    monkeypatch.setattr(metricscenes.store.Collection, "open", classmethod(lambda cls, path: FakeCollection(tmp_path)))
    monkeypatch.setattr(benchmark.detectors, "load_detector", lambda model, **kw: FakeDetector(name=model))
    out = tmp_path / "sweep"
    out.mkdir()
    before = _snapshot(tmp_path)
    with output_lock(out, "benchmark sweep", "sweep folder"):
        line = _refused(BENCHMARK, ["sweep", "--collection", tmp_path, "--cameras", "cam01", "--conditions", "day",
                                    "--out", out, "--resamples", "20", "--mtf-source", "published_group"],
                        f"{out}: another `benchmark sweep` is writing this sweep folder (PID {os.getpid()}")
    assert "wait for it or stop it" in line
    assert _snapshot(tmp_path) == before


@pytest.mark.slow
def test_two_runs_on_one_out_and_a_killed_runs_stage(smoke_collection, tmp_path, monkeypatch):
    """Two `benchmark run` on one --out: without the lock both exited 0 and one result was
    lost; the second is refused naming the first; the first, killed, leaves its stage
    and lock, and the next run on the folder takes the lock over and removes the stage."""
    require_model("yolov5n-dynamic.onnx")
    out = tmp_path / "run"
    command = [sys.executable, "-m", "benchmark.cli.main", "run", "--camera", "cam12", "--collection",
               str(smoke_collection), "--out", str(out)]
    first = subprocess.Popen(command, cwd=REPO, stdout=subprocess.DEVNULL, stderr=subprocess.DEVNULL)
    try:
        deadline = time.monotonic() + 240
        while not ((out / "benchmark.lock").exists() and list(out.glob(".partial-*"))):
            assert first.poll() is None, "the first run ended before the second started"
            assert time.monotonic() < deadline, "the first run never started writing"
            time.sleep(0.2)
        second = subprocess.run(command, cwd=REPO, capture_output=True, text=True, timeout=300)
        assert first.poll() is None, "the first run ended before the second was refused"
        assert second.returncode == 2 and "Traceback" not in second.stderr
        lines = error_lines(second.stderr)
        assert len(lines) == 1, second.stderr
        assert f"another `benchmark run` is writing this run folder (PID {first.pid}" in lines[0], lines[0]
    finally:
        first.kill()
        first.wait()
    stages = sorted(out.glob(".partial-*"))
    assert stages and (out / "benchmark.lock").exists() and not (out / "results.json").exists()
    _fake_run(out, monkeypatch)
    assert not list(out.glob(".partial-*")) and not (out / "benchmark.lock").exists()
    assert json.loads((out / "results.json").read_text())["camera"]["name"] == "cam01"
