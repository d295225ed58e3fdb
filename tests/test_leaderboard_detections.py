"""Submissions ship their detections: `submit` writes them, `submit --check` recomputes every AP from
them and refuses an edited AP, a corrupted file or a new submission without them (the references
made before detections shipped are accepted with a warning); `compare --reference` pairs a run with
a submission by scene, and `report --references` draws a run over the references' band."""

from __future__ import annotations

import copy
import gzip
import hashlib
import json
import math
import shutil
from pathlib import Path

import pytest
from typer.testing import CliRunner

from conftest import require_model
from benchmark.leaderboard import (
    NoDetectionsWarning, SubmissionError, check_submission_file, dumps_submission, load_protocols, pack_path,
    read_pack, save_submission, tree_sha256, write_submission,
)
from benchmark.leaderboard.protocols import condition_label
from benchmark.scoring import ap_by_distance, od50
from synthetic_leaderboard import write_synthetic_run

from leaderboard_support import PROTOCOLS, leaderboard_app

REPO = Path(__file__).resolve().parents[1]
COMMITTED = REPO / "leaderboard"
CREATED = "2025-01-01T00:00:00Z"


@pytest.fixture(scope="module")
def app():
    return leaderboard_app()


@pytest.fixture(scope="module")
def manifest(smoke_manifest):
    return smoke_manifest


@pytest.fixture(scope="module")
def runs(tmp_path_factory, manifest):
    """Synthetic runs on the smoke manifest (4 environments): cam03 day and night, cam07 day."""
    from benchmark.camera import load_camera

    root = tmp_path_factory.mktemp("runs")
    for cam, cond, half in (("cam03", "day", 120.0), ("cam03", "night", 60.0), ("cam07", "day", 80.0)):
        write_synthetic_run(root / "runs" / f"{cam}-{cond}", load_camera(cam), cond, manifest=manifest, half_range_m=half)
    return root


def _invoke(app, args):
    res = CliRunner().invoke(app, [str(a) for a in args])
    return res, (getattr(res, "stderr", None) or res.output)


def _leaderboard(path: Path, manifest, extra: str = "") -> Path:
    (path / "submissions").mkdir(parents=True)
    (path / "protocols.yaml").write_text(PROTOCOLS.format(sha=manifest.sha256()) + extra)
    return path


@pytest.fixture(scope="module")
def board(app, runs, manifest, tmp_path_factory):
    """A leaderboard holding ref-cam03 (day, night) and ref-cam07 (day), built by `benchmark submit`."""
    lb = _leaderboard(tmp_path_factory.mktemp("lb") / "leaderboard", manifest, "    references: ref-*\n")
    res, _ = _invoke(app, ["submit", runs, "--name", "ref-{camera}", "--leaderboard", lb, "--n-resamples", "20",
                           "--no-mtf", "--created-at", CREATED])
    assert res.exit_code == 0, res.output
    return lb


def _copy(board: Path, tmp_path: Path) -> Path:
    out = tmp_path / "leaderboard"
    shutil.copytree(board, out)
    return out


def _fix_od50(sub: dict) -> dict:
    for cond in sub["conditions"].values():
        rows = sorted(cond["per_distance"], key=lambda r: r["distance_m"])
        value = od50([r["distance_m"] for r in rows], [r["ap"] for r in rows])
        cond["od50_m"] = round(value, 3) if math.isfinite(value) else None
        cond["od50_ci95_m"] = [None if cond["od50_m"] is None else 0.0, None]  # holds any OD50
    return sub


# ── shipping and recomputing ─────────────────────────────────────────────────────────────────

def test_a_submission_ships_its_detections_and_check_recomputes_them(app, board, runs, manifest, tmp_path):
    path = board / "submissions" / "ref-cam03.json"
    sub = json.loads(path.read_text())
    for cond in ("day", "night"):
        gz = pack_path(path, cond)
        assert gz == board / "submissions" / "ref-cam03.detections" / f"{cond}.json.gz"
        data = gz.read_bytes()
        assert sub["conditions"][cond]["shipped_detections_sha256"] == hashlib.sha256(data).hexdigest()
        assert data[:2] == b"\x1f\x8b" and data[4:8] == b"\0\0\0\0"  # gzip, mtime 0: the same content, the same bytes
        body = json.loads(gzip.decompress(data))
        assert body["format"] == "metricscenes-detections/1" and body["condition"] == cond
        assert {d["category_id"] for d in body["detections"]} == {3} and min(d["score"] for d in body["detections"]) >= 0.001
        assert {a["category_id"] for a in body["groundtruth"]["annotations"]} == {3}
        run = runs / "runs" / f"cam03-{cond}"  # AP from the pack is the run's AP, exactly
        full = ap_by_distance(json.loads((run / "groundtruth.json").read_text()), json.loads((run / "detections.json").read_text()))
        assert ap_by_distance(body["groundtruth"], body["detections"]) == full
        assert len(body["detections"]) < len(json.loads((run / "detections.json").read_text()))  # other classes left out
    before = tree_sha256(board)
    res, stderr = _invoke(app, ["submit", "--check", path, "--leaderboard", board])
    assert res.exit_code == 0, res.output
    assert "ok: ref-cam03.json (protocol smoke, conditions day, night; AP recomputed from its shipped detections (2 condition(s)))" in res.output
    assert "warning" not in stderr and tree_sha256(board) == before
    # built again elsewhere: byte-identical files
    other = _leaderboard(tmp_path / "again", manifest, "    references: ref-*\n")
    res, _ = _invoke(app, ["submit", runs, "--name", "ref-{camera}", "--leaderboard", other, "--n-resamples", "20",
                           "--no-mtf", "--created-at", CREATED])
    assert res.exit_code == 0, res.output
    assert tree_sha256(other / "submissions") == tree_sha256(board / "submissions")


def test_an_edited_ap_is_refused(app, board, tmp_path):
    lb = _copy(board, tmp_path)
    path = lb / "submissions" / "ref-cam03.json"
    sub = json.loads(path.read_text())
    row = sub["conditions"]["day"]["per_distance"][0]  # 25 m
    claimed = round(row["ap"] - 0.01, 6)
    recomputed, row["ap"] = row["ap"], claimed
    path.write_text(dumps_submission(_fix_od50(sub)))
    before = tree_sha256(lb)
    res, stderr = _invoke(app, ["submit", "--check", path, "--leaderboard", lb])
    assert res.exit_code == 2
    assert stderr.strip().splitlines() == [f"error: ref-cam03.json: conditions.day.per_distance[25 m].ap is {claimed:.6f}, "
                                           f"but {recomputed:.6f} recomputed from its shipped detections"]
    assert tree_sha256(lb) == before


def _swap_night_for_day(lb: Path) -> None:
    """ref-cam03's day pack replaced by its night pack, the sha256 in the JSON updated to match."""
    path = lb / "submissions" / "ref-cam03.json"
    sub = json.loads(path.read_text())
    shutil.copy(pack_path(path, "night"), pack_path(path, "day"))
    sub["conditions"]["day"]["shipped_detections_sha256"] = sub["conditions"]["night"]["shipped_detections_sha256"]
    path.write_text(dumps_submission(sub))


def _not_gzip(lb: Path) -> None:
    path = lb / "submissions" / "ref-cam03.json"
    sub = json.loads(path.read_text())
    pack_path(path, "day").write_bytes(b"not a gzip file")
    sub["conditions"]["day"]["shipped_detections_sha256"] = hashlib.sha256(b"not a gzip file").hexdigest()
    path.write_text(dumps_submission(sub))


def _flip_a_byte(lb: Path) -> None:
    gz = lb / "submissions" / "ref-cam03.detections" / "day.json.gz"
    data = bytearray(gz.read_bytes())
    data[len(data) // 2] ^= 0xFF
    gz.write_bytes(bytes(data))


@pytest.mark.parametrize(("corrupt", "expected"), [
    (_flip_a_byte, "error: ref-cam03.detections/day.json.gz: sha256 "),
    (lambda lb: (lb / "submissions" / "ref-cam03.detections" / "day.json.gz").unlink(),
     "error: ref-cam03.detections/day.json.gz: no such file (the submission's detections are missing)"),
    (_not_gzip, "error: ref-cam03.detections/day.json.gz: not a gzip file"),
    (_swap_night_for_day, "error: ref-cam03.json: conditions.day: its pack is of condition 'night'"),
], ids=["flipped-byte", "missing", "not-gzip", "another-conditions-pack"])
def test_a_corrupted_detections_file_is_refused(app, board, tmp_path, corrupt, expected):
    lb = _copy(board, tmp_path)
    corrupt(lb)
    before = tree_sha256(lb)
    res, stderr = _invoke(app, ["submit", "--check", lb / "submissions" / "ref-cam03.json", "--leaderboard", lb])
    lines = stderr.strip().splitlines()
    assert res.exit_code == 2 and len(lines) == 1 and lines[0].startswith(expected), stderr
    assert tree_sha256(lb) == before
    if corrupt is _flip_a_byte:  # the render checks the checksums too, and leaves the table as it was
        res, stderr = _invoke(app, ["leaderboard", "--dir", lb])
        assert res.exit_code == 2 and "sha256" in stderr and "(the file changed)" in stderr and tree_sha256(lb) == before


def test_a_new_submission_without_detections_is_refused(app, board, manifest, tmp_path):
    lb = _copy(board, tmp_path)
    path = lb / "submissions" / "ref-cam03.json"
    sub = json.loads(path.read_text())
    for cond in sub["conditions"].values():
        cond.pop("shipped_detections_sha256")
    path.write_text(dumps_submission(sub))
    res, stderr = _invoke(app, ["submit", "--check", path, "--leaderboard", lb])
    assert res.exit_code == 2 and stderr.strip().splitlines() == [
        "error: ref-cam03.json: carries no detections: its AP cannot be recomputed; `benchmark submit` writes them "
        "beside the file"], stderr
    sub = json.loads((board / "submissions" / "ref-cam03.json").read_text())
    del sub["conditions"]["night"]["shipped_detections_sha256"]
    path.write_text(dumps_submission(sub))
    res, stderr = _invoke(app, ["submit", "--check", path, "--leaderboard", lb])
    assert res.exit_code == 2 and "conditions.night carries no detections" in stderr, stderr
    # nor can one be written without them
    sub["name"] = "plain"
    with pytest.raises(SubmissionError, match="conditions.day: no detections file with its shipped_detections_sha256"):
        write_submission(sub, _leaderboard(tmp_path / "elsewhere", manifest))


def test_a_reference_made_before_detections_shipped_is_accepted_with_its_warning(app, tmp_path):
    path = COMMITTED / "submissions" / "ref-cam12-yolov5n-metric-300.json"
    res, stderr = _invoke(app, ["submit", "--check", path])
    assert res.exit_code == 0, stderr
    assert "ok: ref-cam12-yolov5n-metric-300.json (protocol metric-300, conditions day, dusk, night, night_regulation)" in res.output
    assert ("warning: ref-cam12-yolov5n-metric-300.json was made before detections shipped (protocol 'metric-300', "
            "made_before_detections): its AP is accepted as published, not recomputed") in stderr
    with pytest.warns(NoDetectionsWarning):
        check_submission_file(path)
    # the pin is of the file's content: the same reference with an AP edited is a submission without detections
    sub = _fix_od50(json.loads(path.read_text()))
    sub["conditions"]["day"]["per_distance"][0]["ap"] = round(sub["conditions"]["day"]["per_distance"][0]["ap"] - 0.01, 6)
    _fix_od50(sub)
    edited = tmp_path / path.name
    edited.write_text(dumps_submission(sub))
    res, stderr = _invoke(app, ["submit", "--check", edited, "--leaderboard", tmp_path / "none"])
    assert res.exit_code == 2 and stderr.strip().splitlines() == [
        "error: ref-cam12-yolov5n-metric-300.json: carries no detections: its AP cannot be recomputed (and it is not the file "
        "pinned as made before detections shipped: edited?); `benchmark submit` writes them beside the file"], stderr


# ── compare with a reference ────────────────────────────────────────────────────────────────

def test_compare_with_a_reference_pairs_it_by_scene(board, runs):
    """A run against a submission's shipped detections is the comparison with the run it was
    made from: the same AP, ΔAP, intervals and verdict, B named by the submission."""
    from benchmark.experiments.compare import compare_paths

    mine = runs / "runs" / "cam07-day"
    by_reference = compare_paths(mine, reference="ref-cam03", leaderboard_dir=board, n_resamples=100)
    by_run = compare_paths(mine, runs / "runs" / "cam03-day", n_resamples=100)
    assert by_reference["b"]["label"] == "ref-cam03" and by_run["b"]["label"] == "cam03"
    assert by_reference["per_distance"] == by_run["per_distance"]
    assert by_reference["delta_ap_range"] == by_run["delta_ap_range"] and by_reference["delta_od50"] == by_run["delta_od50"]
    assert by_reference["verdict"] == by_run["verdict"].replace("cam03", "ref-cam03")
    path = compare_paths(mine, reference=board / "submissions" / "ref-cam03.json", n_resamples=100)  # or a path
    assert path["per_distance"] == by_run["per_distance"]


def test_compare_with_a_reference_from_the_cli_and_its_refusals(board, runs, tmp_path):
    from benchmark.cli.main import app as main_app

    def compare(*args):
        res = CliRunner().invoke(main_app, ["compare", *map(str, args), "--resamples", "50"])
        return res, (getattr(res, "stderr", None) or res.output)

    mine = runs / "runs" / "cam07-day"
    res, _ = compare(mine, "--reference", "ref-cam03", "--leaderboard", board)
    assert res.exit_code == 0, res.output
    assert "cam07 − ref-cam03" in " ".join(res.output.split())  # (4 environments: no verdict, the table all the same)
    for args, expected in (
        ((mine, "--reference", "ref-cam12-yolov5n-metric-300", "--leaderboard", COMMITTED),
         "error: ref-cam12-yolov5n-metric-300 carries no detections (made before detections shipped): it cannot be paired by scene"),
        ((runs / "runs" / "cam03-night", "--reference", "ref-cam07", "--leaderboard", board),
         "error: ref-cam07 has no condition 'night' (it has: day)"),
        ((mine, runs / "runs" / "cam03-day", "--reference", "ref-cam03", "--leaderboard", board),
         "error: give B (a run or sweep folder) or --reference"),
        ((mine, "--reference", "ref-cam3", "--leaderboard", board), "error: --reference ref-cam3: no such submission ("),
    ):
        res, stderr = compare(*args)
        assert res.exit_code == 2 and len(stderr.strip().splitlines()) == 1 and stderr.startswith(expected), stderr
    lb = _copy(board, tmp_path)
    _flip_a_byte(lb)
    res, stderr = compare(mine, "--reference", "ref-cam03", "--leaderboard", lb)
    assert res.exit_code == 2 and "ref-cam03.detections/day.json.gz: sha256" in stderr, stderr


@pytest.mark.slow
def test_a_smoke_run_compared_with_a_submission_that_ships_its_detections(smoke_collection, tmp_path):
    """Two cameras run on the smoke collection; one is submitted (with its detections) and --check
    recomputes its AP; the other compared with that submission is its comparison with the run."""
    model_dir = require_model("yolov5n-dynamic.onnx").parent
    from benchmark.camera import load_camera
    from benchmark.detectors import load_detector
    from benchmark.experiments.compare import compare_paths
    from benchmark.experiments.run import run_camera
    from metricscenes.store import Collection

    collection = Collection.open(smoke_collection)
    detector = load_detector("yolov5n-dynamic", model_dir=model_dir)
    for cam in ("cam01", "cam12"):
        run_camera(collection, load_camera(cam), "day", detector, tmp_path / f"run-{cam}", save_images=False)
    lb = tmp_path / "leaderboard"  # the packaged protocols accept the smoke manifest
    res, _ = _invoke(leaderboard_app(), ["submit", tmp_path / "run-cam12", "--name", "cam12-smoke", "--submitter", "tests",
                                         "--leaderboard", lb, "--n-resamples", "50", "--created-at", CREATED])
    assert res.exit_code == 0, res.output
    res, _ = _invoke(leaderboard_app(), ["submit", "--check", lb / "submissions" / "cam12-smoke.json", "--leaderboard", lb])
    assert res.exit_code == 0 and "AP recomputed from its shipped detections (1 condition(s))" in res.output, res.output
    by_reference = compare_paths(tmp_path / "run-cam01", reference="cam12-smoke", leaderboard_dir=lb, n_resamples=100)
    by_run = compare_paths(tmp_path / "run-cam01", tmp_path / "run-cam12", n_resamples=100)
    assert by_reference["per_distance"] == by_run["per_distance"] and by_reference["b"]["label"] == "cam12-smoke"


# ── the references' band ────────────────────────────────────────────────────────────────────

def test_the_band_of_the_committed_references():
    """Lowest, median and highest AP per distance of the 13 committed references of each protocol,
    from their submitted AP alone (they ship no detections), drawn as the page's SVG."""
    import statistics

    from benchmark.leaderboard import load_submissions
    from benchmark.leaderboard.band import band_svg, reference_band

    protocols = load_protocols(COMMITTED)
    subs = load_submissions(COMMITTED, protocols)
    for name in ("quick", "metric-300"):
        protocol = protocols[name]
        band = reference_band(subs, protocol)
        assert [b.condition for b in band] == ["day", "dusk", "night", "night_regulation"] and {b.n for b in band} == {13}
        files = sorted((COMMITTED / "submissions").glob(f"ref-cam*-yolov5n-{name}.json"))
        assert len(files) == 13
        for b in band:
            curves = [{r["distance_m"]: r["ap"] for r in json.loads(f.read_text())["conditions"][b.condition]["per_distance"]}
                      for f in files]
            assert b.distances_m == protocol.distances_m
            for k, d in enumerate(b.distances_m):
                values = [c[d] for c in curves]
                assert (b.lo[k], b.median[k], b.hi[k]) == (min(values), statistics.median(values), max(values))
        svg = band_svg(band, protocol)
        assert svg == band_svg(band, protocol) and svg.count("<polygon") == 4 and 'style="' not in svg
        for b in band:
            assert f">{protocol.label(b.condition)}</text>" in svg


def _quick_stand_in():
    """The quick manifest the committed references were made on, as write_synthetic_run reads a manifest."""
    from metricscenes.manifest import load_manifest

    quick = load_manifest(REPO / "manifests" / "quick.yaml")
    sha = json.loads((COMMITTED / "submissions" / "ref-cam12-yolov5n-quick.json").read_text())["collection"]["manifest_sha256"]

    class StandIn:
        name, protocol, distances_m = quick.name, quick.protocol, quick.distances_m

        @staticmethod
        def sha256():
            return sha

    return StandIn()


def test_report_draws_a_run_over_the_references_band(tmp_path, runs):
    """One command, one figure: a run of the quick collection over the 13 references' band, nothing rendered."""
    from benchmark.camera import load_camera
    from benchmark.cli.main import app as main_app

    run = tmp_path / "mine-day"
    write_synthetic_run(run, load_camera("cam05"), "day", manifest=_quick_stand_in(), n_environments=10, half_range_m=120.0)
    page = tmp_path / "report" / "mine.html"
    res = CliRunner().invoke(main_app, ["report", str(run), "--references", "quick", "--leaderboard", str(COMMITTED),
                                        "--out", str(page)])
    assert res.exit_code == 0, res.output
    text = page.read_text()
    assert "<h2>Beside the references</h2>" in text and "13 reference submissions of quick" in text
    assert (page.parent / "figures" / "references_quick.png").is_file()
    # the figure itself: the band's median and the run's curve, in a panel named by what the condition is
    from benchmark.experiments.report import load_results, plot_over_band
    from benchmark.leaderboard.band import references_of

    protocol, band = references_of("quick", COMMITTED)
    table = load_results(run)[0]
    fig = plot_over_band(table, band, protocol)
    (ax,) = fig.axes
    assert ax.get_title() == condition_label("day")
    median, mine = (line for line in ax.get_lines() if len(line.get_xdata()) == 6)
    assert list(median.get_ydata()) == list(band[0].median) and list(mine.get_ydata()) == list(table.sort_values("distance_m")["ap"])
    # a run on another collection has no reference to stand beside
    res = CliRunner().invoke(main_app, ["report", str(runs / "runs" / "cam07-day"), "--references", "quick", "--leaderboard",
                                        str(COMMITTED), "--out", str(tmp_path / "other.html")])
    out = getattr(res, "stderr", None) or res.output
    assert res.exit_code == 2 and "--references quick: no reference submission (ref-*-yolov5n-quick) on manifest" in out


# ── condition labels ────────────────────────────────────────────────────────────────────────

def test_condition_labels_come_from_protocols_yaml(tmp_path, manifest, board):
    import yaml

    from benchmark.leaderboard import render_markdown
    from benchmark.leaderboard.render import columns

    packaged = yaml.safe_load((REPO / "benchmark" / "leaderboard" / "data" / "protocols.yaml").read_text(encoding="utf-8"))
    labels = packaged["labels"]
    assert labels["night"] == "0.1–1 lux image plane, sky raised" and labels["night_regulation"] != "night_regulation"
    for condition, label in labels.items():
        assert condition_label(condition) == label
    for name, protocol in load_protocols().items():  # every packaged condition is named by what it is
        assert set(protocol.conditions) <= set(labels), name
    assert condition_label("day@100lux") == "day@100lux"  # none given: the key
    headers = [c.header for c in columns(load_protocols()["quick"])]
    assert "Daylight OD50 (m)" in headers and "0.1–1 lux image plane, sky raised AP range (m)" in headers
    # a leaderboard's own protocols.yaml: its labels, else the key; without a 'labels' key, the packaged ones
    lb = _copy(board, tmp_path)
    (lb / "protocols.yaml").write_text('labels:\n  day: "sunlit test road"\n' + PROTOCOLS.format(sha=manifest.sha256()))
    protocols = load_protocols(lb)
    assert [c.header for c in columns(protocols["smoke"])][3:5] == ["Sunlit test road OD50 (m)", "Night OD50 (m)"]
    from benchmark.leaderboard import load_submissions

    assert "| Sunlit test road OD50 (m) |" in render_markdown(load_submissions(lb, protocols), protocols)
    (lb / "protocols.yaml").write_text(PROTOCOLS.format(sha=manifest.sha256()))
    assert load_protocols(lb)["smoke"].label("night") == labels["night"]
    (lb / "protocols.yaml").write_text('labels:\n  day: "sun\\u202elit"\n' + PROTOCOLS.format(sha=manifest.sha256()))
    with pytest.raises(ValueError, match=r"invalid protocols file \(labels.day must be 1-80 printable characters"):
        load_protocols(lb)


def test_save_submission_writes_detections_before_the_json(board, tmp_path):
    """An interrupted save never leaves a JSON naming detections that are not there."""
    from benchmark.leaderboard import read_submission_file

    sub = read_submission_file(board / "submissions" / "ref-cam03.json")
    packs = {c: pack_path(board / "submissions" / "ref-cam03.json", c).read_bytes() for c in sub["conditions"]}
    order = []
    import metricscenes.files as files

    real = files.os.replace
    try:
        files.os.replace = lambda src, dst: (order.append(Path(dst).name), real(src, dst))[1]
        path = save_submission(copy.deepcopy(sub), tmp_path, packs=packs)
    finally:
        files.os.replace = real
    assert order == ["day.json.gz", "night.json.gz", "ref-cam03.json"]
    body = read_pack(pack_path(path, "day"), expected_sha256=sub["conditions"]["day"]["shipped_detections_sha256"])
    assert body["condition"] == "day"


def test_the_quick_references_ship_their_detections_and_a_run_is_compared_with_them(tmp_path):
    """quick's 13 references carry a checksummed pack per condition: `submit --check` recomputes
    their AP from it, and a run on quick is paired with a reference scene by scene, nothing
    rendered (here the run is cam05's, written from its reference's pack)."""
    from test_compare import _write_run

    from benchmark.cli.main import app as main_app
    from benchmark.experiments.compare import load_reference

    files = sorted((COMMITTED / "submissions").glob("ref-cam*-yolov5n-quick.json"))
    assert len(files) == 13
    for path in files:
        conditions = json.loads(path.read_text())["conditions"]
        assert all(c["shipped_detections_sha256"] for c in conditions.values()), path.name
    res = CliRunner().invoke(main_app, ["submit", "--check", str(COMMITTED / "submissions" / "ref-cam12-yolov5n-quick.json"),
                                        "--leaderboard", str(COMMITTED)])
    assert res.exit_code == 0 and "AP recomputed from its shipped detections (4 condition(s))" in res.output, res.output
    mine = load_reference("ref-cam05-yolov5n-quick", "day", COMMITTED)
    run = tmp_path / "mine-day"
    _write_run(run, "mine", "day", mine.groundtruth, mine.detections, mine.manifest_sha256)
    res = CliRunner().invoke(main_app, ["compare", str(run), "--reference", "ref-cam12-yolov5n-quick",
                                        "--leaderboard", str(COMMITTED), "--out", str(tmp_path / "c")])
    assert res.exit_code == 0, res.output
    result = json.loads((tmp_path / "c" / "compare.json").read_text())
    assert result["n_environments"] == 10 and not result["sample_too_small"]
    assert result["verdict"].startswith("daylight: ref-cam12-yolov5n-quick detects cars farther than mine"), result["verdict"]
    assert (tmp_path / "c" / "compare.png").is_file()
