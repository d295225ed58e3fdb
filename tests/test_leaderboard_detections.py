"""Submissions ship their detections: `submit` writes them, `submit --check` recomputes every AP from
them and refuses an edited AP, a corrupted file or a new submission without them (the references
made before detections shipped are accepted with a warning); condition labels come from protocols.yaml."""

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
def manifest():
    from metricscenes.manifest import load_manifest

    return load_manifest(REPO / "manifests" / "smoke.yaml")


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
    path = COMMITTED / "submissions" / "ref-cam12-yolov5n-quick.json"
    res, stderr = _invoke(app, ["submit", "--check", path])
    assert res.exit_code == 0, stderr
    assert "ok: ref-cam12-yolov5n-quick.json (protocol quick, conditions day, dusk, night, night_regulation)" in res.output
    assert ("warning: ref-cam12-yolov5n-quick.json was made before detections shipped (protocol 'quick', "
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
        "error: ref-cam12-yolov5n-quick.json: carries no detections: its AP cannot be recomputed (and it is not the file "
        "pinned as made before detections shipped: edited?); `benchmark submit` writes them beside the file"], stderr


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
