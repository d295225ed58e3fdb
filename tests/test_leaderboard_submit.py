"""Leaderboard: building submissions from run and sweep folders, the packaged protocols and
schema, deterministic and atomic rendering, and the round trip on the smoke collection."""

from __future__ import annotations

import json
import math
import shutil
import warnings
from pathlib import Path

import jsonschema
import pytest
from typer.testing import CliRunner

from conftest import require_model

from benchmark.leaderboard import (
    SubmissionError,
    build_submission,
    check_submission_file,
    find_runs,
    load_protocols,
    load_submissions,
    rank_key,
    schema_text,
    tree_sha256,
)
from synthetic_leaderboard import write_synthetic_run

from leaderboard_support import PROTOCOLS, leaderboard_app

REPO = Path(__file__).resolve().parents[1]


@pytest.fixture(scope="module")
def app():
    return leaderboard_app()


@pytest.fixture(scope="module")
def manifest(smoke_manifest):
    return smoke_manifest


@pytest.fixture()
def leaderboard(tmp_path, manifest):
    """An empty leaderboard accepting the current smoke manifest."""
    lb = tmp_path / "leaderboard"
    (lb / "submissions").mkdir(parents=True)
    (lb / "protocols.yaml").write_text(PROTOCOLS.format(sha=manifest.sha256()))
    return lb


@pytest.fixture(scope="module")
def sweep(tmp_path_factory, manifest):
    """A sweep folder: cam03 day+night, cam07 day (+ a day@100lux run the leaderboard does not rank)."""
    from benchmark.camera import load_camera

    root = tmp_path_factory.mktemp("sweep")
    for cam, cond, half in (("cam03", "day", 120.0), ("cam03", "night", 60.0), ("cam07", "day", 80.0), ("cam07", "day@100lux", 70.0)):
        write_synthetic_run(root / "runs" / f"{cam}-{cond}", load_camera(cam), cond, manifest=manifest, half_range_m=half)
    return root


def _invoke(app, args, **kw):
    res = CliRunner().invoke(app, [str(a) for a in args], **kw)
    return res, (getattr(res, "stderr", None) or res.output)


def test_packaged_protocols_accept_the_packaged_manifests():
    """The accepted hashes are those of manifests/*.yaml (update data/protocols.yaml when a manifest changes)."""
    from metricscenes.manifest import load_manifest

    protocols = load_protocols()
    assert list(protocols) == ["metric-300", "quick", "adas", "smoke"]
    for name, protocol in protocols.items():
        (collection,) = protocol.collection_names or (name,)  # the manifest that names the collection
        m = load_manifest(REPO / "manifests" / f"{collection}.yaml")
        assert m.protocol == name and m.name == collection
        assert m.sha256() in protocol.manifests_sha256, f"{name}: manifest sha256 is now {m.sha256()}"
        assert protocol.distances_m == tuple(m.distances_m)
        assert protocol.n_environments == m.environments
        assert set(protocol.conditions) <= set(m.conditions) and "day" in protocol.required_conditions


def test_schema_command_prints_the_packaged_schema(app):
    res, _ = _invoke(app, ["schema", "submission"])
    assert res.exit_code == 0
    schema = json.loads(res.stdout)
    jsonschema.Draft202012Validator.check_schema(schema)
    assert res.stdout == schema_text() and schema["properties"]["format"]["const"] == "metricscenes-submission/1"
    res, stderr = _invoke(app, ["schema", "results"])
    assert res.exit_code == 2 and "unknown schema 'results'" in stderr


def test_submit_a_run_folder(app, sweep, leaderboard, monkeypatch):
    from benchmark.scoring import bootstrap_od50, od50

    run = sweep / "runs" / "cam03-day"
    monkeypatch.setenv("SOURCE_DATE_EPOCH", "1700000000")
    res, _ = _invoke(app, ["submit", run, "--name", "c3", "--submitter", "Ada <ada@example.org>", "--leaderboard", leaderboard,
                           "--n-resamples", "30"])  # fmt: skip
    assert res.exit_code == 0, res.output
    sub = json.loads((leaderboard / "submissions" / "c3.json").read_text())
    results = json.loads((run / "results.json").read_text())
    gt, dets = (json.loads((run / f).read_text()) for f in ("groundtruth.json", "detections.json"))
    day = sub["conditions"]["day"]
    assert sub["created_at"] == "2023-11-14T22:13:20Z" and sub["submitter"] == "Ada <ada@example.org>"
    assert day["per_distance"] == results["per_distance"] and day["detections_sha256"] == results["detections_sha256"]
    curve = od50([r["distance_m"] for r in day["per_distance"]], [r["ap"] for r in day["per_distance"]])
    assert day["od50_m"] == pytest.approx(curve, abs=5e-4) and 50 < curve < 200
    boot = bootstrap_od50(gt, dets, n_resamples=30, seed=0)  # the SD is the scorer's bootstrap, same settings
    assert day["od50_sd_m"] == pytest.approx(boot.sd_m, abs=5e-4) and day["od50_sd_m"] > 0
    assert day["n_environments"] == 4
    assert sub["detector"]["licence"] == "AGPL-3.0" and sub["camera"]["mtf50_source"] == "measured"
    from benchmark.camera import load_camera
    from benchmark.measure.mtf import measure_mtf50, mtf50_analytic_cy_per_mm

    spec_mtf = measure_mtf50(load_camera("cam03"))["mtf50_cy_per_mm"]
    assert sub["camera"]["mtf50_cy_per_mm"] == pytest.approx(spec_mtf, abs=0.06)
    assert sub["camera"]["mtf50_cy_per_mm"] == pytest.approx(mtf50_analytic_cy_per_mm(2.8, 9.1), rel=0.15)
    assert sub["isp"] == sub["camera"]["spec"]["isp"] and sub["package_version"]
    check_submission_file(leaderboard / "submissions" / "c3.json", leaderboard_dir=leaderboard,
                          detections=[run / "detections.json"], groundtruth=run / "groundtruth.json")  # fmt: skip
    # the same system again under another name, or the same name again: refused, nothing written
    before = tree_sha256(leaderboard)
    for name, message in (("c3", "duplicate name"), ("c3-again", "duplicate: c3.json")):
        res, stderr = _invoke(app, ["submit", run, "--name", name, "--leaderboard", leaderboard, "--n-resamples", "30"])
        assert res.exit_code == 2 and message in stderr, stderr
    assert tree_sha256(leaderboard) == before


def test_submit_a_sweep(app, sweep, leaderboard):
    args = ["--leaderboard", leaderboard, "--n-resamples", "20", "--no-mtf", "--created-at", "2025-01-01T00:00:00Z"]
    res, stderr = _invoke(app, ["submit", sweep, "--name", "ref", *args])
    assert res.exit_code == 2 and "holds 2 cameras (cam03, cam07): put {camera} in --name" in stderr
    assert tree_sha256(leaderboard / "submissions") == {}
    res, _ = _invoke(app, ["submit", sweep, "--name", "ref-{camera}", *args])
    assert res.exit_code == 0, res.output
    assert "not ranked, left out: day@100lux" in res.output
    subs = {s["name"]: s for s in load_submissions(leaderboard)}
    assert sorted(subs) == ["ref-cam03", "ref-cam07"]
    assert sorted(subs["ref-cam03"]["conditions"]) == ["day", "night"] and sorted(subs["ref-cam07"]["conditions"]) == ["day"]
    assert subs["ref-cam07"]["camera"]["mtf50_source"] == "published_group"
    assert subs["ref-cam07"]["camera"]["mtf50_cy_per_mm"] == subs["ref-cam07"]["camera"]["spec"]["mtf50_group_cy_per_mm"]
    res, stderr = _invoke(app, ["submit", sweep, "--name", "x", "--camera", "cam99", *args])
    assert res.exit_code == 2 and "camera 'cam99' is not in" in stderr


def test_sweep_bootstrap_cache_is_used(tmp_path, sweep, leaderboard):
    """A sweep's per-run od50.json (benchmark.experiments.sweep.run_od50) with the same settings is reused, not recomputed."""
    run = tmp_path / "run"
    shutil.copytree(sweep / "runs" / "cam07-day", run)
    sha = json.loads((run / "results.json").read_text())["detections_sha256"]
    # a stored interval must hold the run's OD50 (68.3 m here), or validation refuses it
    cache = {"key": {"detections_sha256": sha, "n_resamples": 20, "seed": 0},
             "od50": {"od50_m": 80.0, "sd_m": 12.345, "ci95_m": [50.0, "inf"], "n_resamples": 20}}  # fmt: skip
    (run / "od50.json").write_text(json.dumps(cache))
    protocols = load_protocols(leaderboard)
    day = build_submission(find_runs(run), name="c", submitter="s", n_resamples=20, measure_mtf=False, protocols=protocols)["conditions"]["day"]
    assert day["od50_sd_m"] == 12.345 and day["od50_ci95_m"] == [50.0, None]
    day = build_submission(find_runs(run), name="c", submitter="s", n_resamples=21, measure_mtf=False, protocols=protocols)["conditions"]["day"]
    assert day["od50_sd_m"] != 12.345  # other settings: recomputed


def test_one_submission_is_one_system(tmp_path, sweep, leaderboard):
    for cond in ("day", "night"):
        shutil.copytree(sweep / "runs" / f"cam03-{cond}", tmp_path / "s" / "runs" / f"cam03-{cond}")
    night = tmp_path / "s" / "runs" / "cam03-night" / "results.json"
    results = json.loads(night.read_text())
    results["detector"]["sha256"] = "0" * 64
    night.write_text(json.dumps(results))
    with pytest.raises(SubmissionError, match="detector differs"):
        build_submission(find_runs(tmp_path / "s"), name="c", submitter="s", n_resamples=5, measure_mtf=False,
                         protocols=load_protocols(leaderboard))  # fmt: skip
    shutil.copytree(sweep / "runs" / "cam03-night", tmp_path / "s" / "runs" / "cam03-night-2")
    with pytest.raises(SubmissionError, match="2 runs under condition 'night'"):
        from benchmark.leaderboard import group_by_camera

        group_by_camera(find_runs(tmp_path / "s"))
    with pytest.raises(SubmissionError, match="neither a run folder"):
        find_runs(tmp_path)


def _fake(name: str, day: float | None, night: float | None = -1.0) -> dict:
    conditions = {"day": {"od50_m": day}}
    if night != -1.0:
        conditions["night"] = {"od50_m": night}
    return {"name": name, "conditions": conditions}


def test_rank_order():
    subs = [_fake("a", 80.0, 20.0), _fake("b", 120.0), _fake("c", None, 10.0), _fake("d", 80.0, 30.0), _fake("e", 80.0, None), _fake("f", 80.0)]
    # day OD50 descending (null = +inf first), then night descending (null = +inf; absent last), then name
    assert [s["name"] for s in sorted(subs, key=rank_key)] == ["c", "b", "e", "d", "a", "f"]


@pytest.fixture()
def populated(app, sweep, leaderboard):
    res, _ = _invoke(app, ["submit", sweep, "--name", "ref-{camera}", "--leaderboard", leaderboard, "--n-resamples", "20",
                           "--no-mtf", "--created-at", "2025-01-01T00:00:00Z"])  # fmt: skip
    assert res.exit_code == 0, res.output
    return leaderboard


def test_render_deterministic_and_ranked(app, populated, tmp_path):
    res, _ = _invoke(app, ["leaderboard", "--dir", populated])
    assert res.exit_code == 0, res.output
    readme, page = (populated / "README.md").read_bytes(), (populated / "index.html").read_bytes()
    subs = {s["name"]: s for s in load_submissions(populated)}
    order = sorted(subs, key=lambda n: -subs[n]["conditions"]["day"]["od50_m"])
    assert subs[order[0]]["conditions"]["day"]["od50_m"] > subs[order[1]]["conditions"]["day"]["od50_m"]
    text = readme.decode()
    rows = [line for line in text.splitlines() if line.startswith("| 1 ") or line.startswith("| 2 ")]
    assert [r.split("[")[1].split("]")[0] for r in rows] == order
    for name in order:
        day = subs[name]["conditions"]["day"]
        assert f"[{name}](submissions/{name}.json)" in text
        assert f"{day['od50_m']:.1f} ± {day['od50_sd_m']:.1f}" in text
    assert 'benchmark submit sweeps/$c --name "ref-{camera}-yolov5n-$c"' in text and 'for c in quick adas-quick metric-300' in text
    assert "http://" not in page.decode() and "https://" not in page.decode() and "src=" not in page.decode()
    # same inputs, same bytes: again, and in another folder
    other = tmp_path / "copy"
    shutil.copytree(populated, other)
    for folder in (populated, other):
        res, _ = _invoke(app, ["leaderboard", "--dir", folder])
        assert res.exit_code == 0
        assert (folder / "README.md").read_bytes() == readme and (folder / "index.html").read_bytes() == page


def test_render_refuses_a_bad_submission_and_keeps_the_table(app, populated):
    assert _invoke(app, ["leaderboard", "--dir", populated])[0].exit_code == 0
    bad = populated / "submissions" / "ref-cam03.json"
    sub = json.loads(bad.read_text())
    sub["conditions"]["day"]["per_distance"][0]["ap"] = 2.0
    bad.write_text(json.dumps(sub))
    before = tree_sha256(populated)
    res, stderr = _invoke(app, ["leaderboard", "--dir", populated])
    assert res.exit_code == 2
    assert stderr.strip().splitlines() == [
        "error: submissions/ref-cam03.json: schema: conditions.day.per_distance[0].ap: 2.0 is greater than the maximum of 1 "
        "(the table was not changed)"
    ]  # fmt: skip
    assert tree_sha256(populated) == before


def test_interrupted_render_leaves_the_old_table(app, populated, monkeypatch):
    import metricscenes.files as files

    assert _invoke(app, ["leaderboard", "--dir", populated])[0].exit_code == 0
    (populated / "submissions" / "ref-cam07.json").unlink()  # the next render would differ
    before = tree_sha256(populated)

    def interrupted(src, dst):
        raise KeyboardInterrupt

    monkeypatch.setattr(files.os, "replace", interrupted)
    with pytest.raises(KeyboardInterrupt):
        from benchmark.leaderboard import render_leaderboard

        render_leaderboard(populated)
    assert tree_sha256(populated) == before  # old files intact, no temporary files left
    monkeypatch.undo()
    assert _invoke(app, ["leaderboard", "--dir", populated])[0].exit_code == 0
    assert tree_sha256(populated) != before and "ref-cam07" not in (populated / "README.md").read_text()


@pytest.mark.slow
def test_round_trip_on_the_smoke_collection(app, smoke_collection, tmp_path):
    """Run a camera on the smoke collection, submit, check, render: the table shows its OD50."""
    model_dir = require_model("yolov5n-dynamic.onnx").parent
    from benchmark.camera import load_camera
    from benchmark.detectors import load_detector
    from benchmark.experiments.run import run_camera
    from metricscenes.store import Collection

    collection = Collection.open(smoke_collection)
    detector = load_detector("yolov5n-dynamic", model_dir=model_dir)
    run = tmp_path / "run-cam01-day"
    results = run_camera(collection, load_camera("cam01"), "day", detector, run, save_images=False)
    lb = tmp_path / "leaderboard"  # the packaged protocols: the smoke manifest's hash must be accepted
    res, _ = _invoke(app, ["submit", run, "--name", "cam01-yolov5n-smoke", "--submitter", "tests", "--leaderboard", lb,
                           "--n-resamples", "50", "--created-at", "2025-06-01T12:00:00Z"])  # fmt: skip
    assert res.exit_code == 0, res.output
    path = lb / "submissions" / "cam01-yolov5n-smoke.json"
    res, _ = _invoke(app, ["submit", "--check", path, "--leaderboard", lb,
                           "--detections", run / "detections.json", "--groundtruth", run / "groundtruth.json"])  # fmt: skip
    assert res.exit_code == 0, res.output
    res, _ = _invoke(app, ["leaderboard", "--dir", lb])
    assert res.exit_code == 0, res.output
    sub = json.loads(path.read_text())
    day = sub["conditions"]["day"]
    # (a submission holds AP per distance; results.json also the miss rate and false positives at the working threshold)
    assert day["per_distance"] == [r.model_dump(include={"distance_m", "ap", "ap50", "n_images"}) for r in results.per_distance]
    assert all(r.miss_rate is not None and r.false_positives_per_image is not None for r in results.per_distance)
    assert day["od50_m"] == results.od50_m  # both None (inf) or the same metres
    expected = "∞" if day["od50_m"] is None else f"{day['od50_m']:.1f}"
    lines = (lb / "README.md").read_text().splitlines()
    row = next(line for line in lines if "cam01-yolov5n-smoke" in line)
    header = next(line for line in lines if line.startswith("| # |"))
    cells = dict(zip([c.strip() for c in header.strip("|").split("|")], [c.strip() for c in row.strip("|").split("|")]))
    assert cells["#"] == "1" and cells["Camera"] == "cam01" and cells["Daylight OD50 (m)"].split(" ±")[0] == expected
    html = (lb / "index.html").read_text()
    assert 'href="submissions/cam01-yolov5n-smoke.json"' in html and f">{expected}" in html
    assert math.isclose(float(cells["Pixel (µm)"]), 4.2) and math.isclose(float(cells["f-number"]), 3.1)
    assert cells["Focal (mm)"] == "4.38" and cells["FOV (°)"] == "34.1 × 19.6"
    assert math.isclose(float(cells["MTF50 (cy/mrad)"]), float(cells["MTF50 (cy/mm)"]) * 4.38 / 1000, abs_tol=0.01)


def test_committed_reference_submissions_are_valid_and_rendered():
    """The reference submissions in leaderboard/ still pass every check against the
    packaged protocols (a manifest change must come with new references; metric-300's, made
    before detections shipped, each with its warning; quick's recomputed from the detections
    they ship, silently), and the committed table and band figures are what `benchmark
    leaderboard` renders from them."""
    from benchmark.leaderboard import (
        NoDetectionsWarning, check_submission_file, load_protocols, load_submissions, render_html, render_markdown,
    )
    from benchmark.leaderboard.render import band_figures

    folder = REPO / "leaderboard"
    subs = sorted((folder / "submissions").glob("*.json"))
    assert len(subs) >= 13
    for path in subs:
        if path.name.endswith("-metric-300.json"):
            with pytest.warns(NoDetectionsWarning, match="made before detections shipped"):
                data = check_submission_file(path)
        else:
            with warnings.catch_warnings():
                warnings.simplefilter("error", NoDetectionsWarning)
                data = check_submission_file(path)
            assert all(c["shipped_detections_sha256"] for c in data["conditions"].values())
        assert data["collection"]["protocol"] in {"quick", "metric-300", "adas"}
    protocols = load_protocols(folder)
    submissions = load_submissions(folder, protocols)
    assert render_markdown(submissions, protocols) == (folder / "README.md").read_text()
    assert render_html(submissions, protocols) == (folder / "index.html").read_text()
    figures = band_figures(submissions, protocols)
    assert sorted(figures) == ["adas", "metric-300", "quick"]
    for name, svg in figures.items():
        assert (folder / f"references-{name}.svg").read_text() == svg


def test_tree_hash_of_a_missing_folder_is_empty(tmp_path):
    assert tree_sha256(tmp_path / "absent") == {}
    (tmp_path / "a").mkdir()
    (tmp_path / "a" / "x.json").write_text("{}")
    assert list(tree_sha256(tmp_path)) == ["a/x.json"]


def test_an_od50_spread_beyond_any_distance_is_written_as_infinite():
    """A nearly flat AP curve's resamples extrapolate OD50 to 1e16 m (quick's cam13 by day): the
    spread and interval ends beyond the validator's limit are written as null (+inf)."""
    from benchmark.leaderboard.submission import _none_if_beyond_reach
    from benchmark.leaderboard.validate import MAX_OD50_M

    assert _none_if_beyond_reach(7.9e15) is None and _none_if_beyond_reach(math.inf) is None
    assert _none_if_beyond_reach(MAX_OD50_M) == MAX_OD50_M and _none_if_beyond_reach(12.34567) == 12.346
