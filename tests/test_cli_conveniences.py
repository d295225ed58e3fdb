"""Command-line conveniences: `--model-dir` on every command that loads a model,
"did you mean" for conditions (never taken silently), help that uses the terminal's width, and
`benchmark report` over several run and sweep folders. Each refusal: exit code 2, one line,
nothing created."""

from __future__ import annotations

import hashlib
import json
import shutil
from pathlib import Path

import click
import pytest
import typer
from typer.testing import CliRunner

from benchmark.camera import load_camera
from benchmark.cli.main import app
from benchmark.suggest import closest_name, did_you_mean
from test_sweep_cache import make_fake_sweep  # the fake runs (tests/ is on sys.path)

runner = CliRunner()


def _snapshot(root: Path) -> dict[str, str]:
    return {str(p.relative_to(root)): hashlib.sha256(p.read_bytes()).hexdigest() if p.is_file() else "dir"
            for p in sorted(root.rglob("*"))}


def _refused(args: list, root: Path, **env) -> str:
    """``benchmark ARGS``: exit 2, one line on stderr, nothing created under ``root``."""
    before = _snapshot(root)
    res = runner.invoke(app, [str(a) for a in args], env=env or None)
    assert res.exit_code == 2, res.output
    lines = [line for line in res.stderr.splitlines() if line.strip()]
    assert len(lines) == 1 and lines[0].startswith("error: ") and "Traceback" not in res.output, res.output
    assert _snapshot(root) == before
    return lines[0]


def test_suggestions():
    names = ["day", "dusk", "night", "night_regulation", "day@1lux"]
    assert did_you_mean("nite", names) == "; did you mean 'night'?"
    assert did_you_mean("Night", names) == "; did you mean 'night'?"  # case: suggested, not taken
    assert did_you_mean("DAY", names) == "; did you mean 'day'?"
    assert did_you_mean("sunrise", names) == "" and did_you_mean("day", names) == ""
    assert closest_name("cam1", ["cam01", "cam13"], guess="cam01") == "cam01"


def _commands(group: click.Group, prefix=()):
    for name, command in group.commands.items():
        if isinstance(command, click.Group):
            yield from _commands(command, (*prefix, name))
        else:
            yield (*prefix, name), command


def test_every_command_that_loads_a_model_takes_model_dir():
    root = typer.main.get_command(app)
    loading = {path: cmd for path, cmd in _commands(root) if any(p.name == "model" for p in cmd.params)}
    assert {("run",), ("sweep",), ("detect",)} <= set(loading)
    for path, command in loading.items():
        assert any(p.name == "model_dir" and "--model-dir" in p.opts for p in command.params), path


@pytest.fixture(scope="module")
def smoke(smoke_collection, tmp_path_factory) -> Path:
    """A copy of the session's smoke collection (the original stays untouched)."""
    copy = tmp_path_factory.mktemp("conveniences") / "smoke"
    shutil.copytree(smoke_collection, copy)
    return copy


def test_run_and_sweep_take_model_dir(smoke, tmp_path):
    line = _refused(["run", "--camera", "cam01", "--collection", smoke, "--out", tmp_path / "out",
                     "--model-dir", tmp_path / "no-models"], tmp_path)
    assert f"model file not found: {tmp_path / 'no-models' / 'yolov5n-dynamic.onnx'}" in line
    line = _refused(["sweep", "--cameras", "cam01", "--conditions", "day", "--collection", smoke,
                     "--out", tmp_path / "sw", "--model-dir", tmp_path / "no-models"], tmp_path)
    assert "model file not found" in line and "no-models" in line


def test_without_a_model_folder_the_error_names_the_option(smoke, tmp_path, monkeypatch):
    monkeypatch.delenv("METRICSCENES_MODEL_DIR", raising=False)
    line = _refused(["run", "--camera", "cam01", "--collection", smoke, "--out", tmp_path / "out"], tmp_path)
    assert "set METRICSCENES_MODEL_DIR or pass --model-dir" in line


@pytest.mark.parametrize(("typed", "suggested"), [("nite", "night"), ("Day", "day"), ("NIGHT", "night")])
def test_unknown_conditions_get_a_suggestion_not_a_substitute(smoke, tmp_path, typed, suggested):
    line = _refused(["run", "--camera", "cam01", "--collection", smoke, "--out", tmp_path / "out",
                     "--condition", typed], tmp_path)
    assert f"unknown condition {typed!r} (this collection has: day, " in line
    assert line.endswith(f"did you mean {suggested!r}?")
    line = _refused(["sweep", "--cameras", "cam01", "--conditions", f"day,{typed}", "--collection", smoke,
                     "--out", tmp_path / "sw"], tmp_path)
    assert line.endswith(f"did you mean {suggested!r}?")


def _option_help_lines(text: str, option: str) -> list[str]:
    """The lines of ``option``'s entry in a click help page (up to the next option)."""
    lines = text.splitlines()
    start = next(i for i, line in enumerate(lines) if line.lstrip().startswith(option + " "))
    end = next((i for i in range(start + 1, len(lines)) if lines[i].lstrip().startswith("-")), len(lines))
    return lines[start:end]


def test_help_uses_the_terminal_width():
    narrow = runner.invoke(app, ["run", "--help"], terminal_width=80)
    assert narrow.exit_code == 0 and all(len(line) <= 80 for line in narrow.output.splitlines())
    entry = _option_help_lines(narrow.output, "--exposure")
    assert len(entry) <= 6, entry  # (rich's panels gave it 14 lines of one or two words)
    assert sum(len(line.split()) for line in entry) / len(entry) >= 5, entry
    wide = runner.invoke(app, ["run", "--help"], terminal_width=160)
    assert len(_option_help_lines(wide.output, "--exposure")) <= 3
    assert max(len(line) for line in wide.output.splitlines()) > 100  # the width is used
    cameras = runner.invoke(app, ["cameras", "mtf", "--help"], terminal_width=160)
    assert cameras.exit_code == 0 and len(_option_help_lines(cameras.output, "--isp")) <= 2


@pytest.fixture(scope="module")
def two_runs(tmp_path_factory):
    monkeypatch = pytest.MonkeyPatch()
    root = tmp_path_factory.mktemp("multi")
    try:
        make_fake_sweep(root / "sweep", monkeypatch, n_resamples=20, save_images=True)
    finally:
        monkeypatch.undo()
    runs = root / "runs"
    for camera in ("cam01", "cam12"):  # as `benchmark run` writes them: the spec in results.json
        shutil.copytree(root / "sweep" / "runs" / f"{camera}-day", runs / f"{camera}-day")
        results = json.loads((runs / f"{camera}-day" / "results.json").read_text())
        results["camera"]["spec"] = load_camera(camera).model_dump(mode="json")
        (runs / f"{camera}-day" / "results.json").write_text(json.dumps(results, indent=1))
    return runs


def test_report_over_several_run_folders(two_runs, tmp_path):
    page = tmp_path / "reports" / "day.html"
    res = runner.invoke(app, ["report", str(two_runs / "cam01-day"), str(two_runs / "cam12-day"), "--out", str(page)])
    assert res.exit_code == 0, res.output
    text = page.read_text(encoding="utf-8")
    assert "cam01" in text and "cam12" in text and "OD50 vs MTF50" in text and "System Performance Maps" in text
    assert (tmp_path / "reports" / "figures" / "od50_vs_mtf50.png").is_file()
    assert not (two_runs / "cam01-day" / "report.html").exists()  # nothing written into the runs


def test_report_over_several_folders_refusals(two_runs, tmp_path):
    a, b = two_runs / "cam01-day", two_runs / "cam12-day"
    line = _refused(["report", a, b], two_runs)
    assert "2 results folders: name the page with --out" in line
    line = _refused(["report", a, a, "--out", tmp_path / "x" / "r.html"], tmp_path)
    assert f"camera cam01 under day is in both {a} and {a}: keep one" in line
    other = tmp_path / "other-collection"
    shutil.copytree(b, other)
    results = json.loads((other / "results.json").read_text())
    results["collection"]["manifest_sha256"] = "0" * 64
    (other / "results.json").write_text(json.dumps(results))
    line = _refused(["report", a, other, "--out", tmp_path / "x" / "r.html"], tmp_path)
    assert "come from different collections: one report compares cameras on one collection with one detector" in line
