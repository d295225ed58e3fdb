"""Leaderboard validation: every kind of bad submission is refused with a one-line reason,
exit code 2, and the leaderboard folder left byte-identical."""

from __future__ import annotations

import copy
import hashlib
import json
import math
import re
from pathlib import Path

import pytest
from typer.testing import CliRunner

from benchmark.leaderboard import (
    build_submission,
    check_submission_file,
    dumps_submission,
    find_runs,
    load_protocols,
    save_submission,
    tree_sha256,
    write_submission,
)
from synthetic_leaderboard import write_synthetic_run
from benchmark.scoring import od50

from leaderboard_support import PROTOCOLS, leaderboard_app

REPO = Path(__file__).resolve().parents[1]
CREATED = "2025-01-02T03:04:05Z"


@pytest.fixture(scope="module")
def app():
    return leaderboard_app()


@pytest.fixture(scope="module")
def world(tmp_path_factory):
    """A leaderboard holding one submission, and a valid second submission (with its run) outside it."""
    from benchmark.camera import load_camera
    from metricscenes.manifest import load_manifest

    root = tmp_path_factory.mktemp("lb")
    manifest = load_manifest(REPO / "manifests" / "smoke.yaml")
    leaderboard = root / "leaderboard"
    (leaderboard / "submissions").mkdir(parents=True)
    # this leaderboard accepts the smoke manifest as it is now (the packaged list is checked in test_leaderboard_submit)
    (leaderboard / "protocols.yaml").write_text(PROTOCOLS.format(sha=manifest.sha256()))
    protocols = load_protocols(leaderboard)
    for cam, half_range in (("cam03", 70.0), ("cam07", 110.0)):
        for cond in ("day", "night"):
            write_synthetic_run(root / cam / cond, load_camera(cam), cond, manifest=manifest, half_range_m=half_range,
                                seed={"day": 1, "night": 2}[cond])  # fmt: skip
    existing = build_submission(find_runs(root / "cam03" / "day"), name="existing", submitter="a", created_at=CREATED,
                                n_resamples=20, measure_mtf=False, protocols=protocols)  # fmt: skip
    write_submission(existing, leaderboard)
    runs = find_runs(root / "cam07" / "day") + find_runs(root / "cam07" / "night")
    good = build_submission(runs, name="good", submitter="b", created_at=CREATED, n_resamples=20, measure_mtf=False, protocols=protocols)
    return {"root": root, "leaderboard": leaderboard, "good": good, "existing": existing}


def _fix_od50(sub: dict) -> dict:
    """Make every condition's OD50 follow from its (edited) AP curve again."""
    for cond in sub["conditions"].values():
        rows = sorted(cond["per_distance"], key=lambda r: r["distance_m"])
        value = od50([r["distance_m"] for r in rows], [r["ap"] for r in rows])
        cond["od50_m"] = round(value, 3) if math.isfinite(value) else None
    return sub


def _rehash(sub: dict) -> dict:
    sub["camera"]["spec_sha256"] = hashlib.sha256(
        json.dumps(sub["camera"]["spec"], sort_keys=True, separators=(",", ":")).encode()
    ).hexdigest()
    return sub


def _edit(fn):
    def make(good: dict) -> bytes:
        sub = copy.deepcopy(good)
        fn(sub)  # edits in place
        return dumps_submission(sub).encode()

    return make


def _text(fn):
    return lambda good: fn(dumps_submission(good)).encode()


def _set_ap(value):
    def fn(sub):
        sub["conditions"]["day"]["per_distance"][1]["ap"] = value

    return fn


def _drop_distance(sub):
    sub["conditions"]["day"]["per_distance"].pop(4)  # 150 m
    _fix_od50(sub)


def _extra_distance(sub):
    sub["conditions"]["day"]["per_distance"].append({"distance_m": 300.0, "ap": 0.0, "ap50": 0.0, "n_images": 4})
    _fix_od50(sub)


def _repeat_distance(sub):
    rows = sub["conditions"]["day"]["per_distance"]
    rows[5] = dict(rows[4])


def _pixel(sub):
    sub["camera"]["spec"]["sensor"]["pixel_um"] = 1.0


def _bad_spec_rehashed(sub):
    sub["camera"]["spec"]["sensor"]["pixel_um"] = 100.0
    _rehash(sub)


def _derived_width(sub):
    sub["camera"]["spec"]["sensor"]["width_px"] = 4000
    _rehash(sub)


def _only_night(sub):
    del sub["conditions"]["day"]


def _fog(sub):
    sub["conditions"]["fog"] = copy.deepcopy(sub["conditions"]["night"])


def _od50_off(sub):
    cond = sub["conditions"]["day"]
    cond["od50_m"] = 12.0 if cond["od50_m"] != 12.0 else 13.0


def _ap_above_ap50(sub):
    row = sub["conditions"]["day"]["per_distance"][0]  # 25 m: AP well above 0.05
    assert row["ap"] > 0.05
    row["ap50"] = round(row["ap"] - 0.05, 6)


def _day_od50(sub) -> float:
    value = sub["conditions"]["day"]["od50_m"]
    assert value is not None  # the synthetic day curve crosses 0.5 within the distances
    return value


def _ci_reversed(sub):
    od = _day_od50(sub)
    sub["conditions"]["day"]["od50_ci95_m"] = [od + 5.0, od - 5.0]


def _ci_lo_infinite(sub):
    sub["conditions"]["day"]["od50_ci95_m"] = [None, _day_od50(sub) + 5.0]


def _ci_excludes(sub):
    od = _day_od50(sub)
    sub["conditions"]["day"]["od50_ci95_m"] = [od + 5.0, od + 10.0]


def _sd_zero(sub):
    od = _day_od50(sub)
    sub["conditions"]["day"].update(od50_sd_m=0.0, od50_ci95_m=[od - 5.0, od + 5.0])


def _same_detections(sub):
    sub["conditions"]["night"]["detections_sha256"] = sub["conditions"]["day"]["detections_sha256"]


def _sub_number(pattern: str, replacement: str):
    return _text(lambda t: re.sub(pattern, replacement, t, count=1))


# (id, make bytes from the good submission, file name, expected piece of the message)
BAD = [
    ("not-json", lambda good: b"{this is not json", "good.json", "invalid JSON at line 1"),
    ("truncated", lambda good: dumps_submission(good).encode()[:700], "good.json", "invalid JSON"),
    ("empty", lambda good: b"", "good.json", "invalid JSON at line 1 column 1"),
    ("not-utf8", lambda good: b'{"name": "\xff"}', "good.json", "not UTF-8"),
    ("nan-literal", _text(lambda t: t.replace('"od50_sd_m": ', '"od50_sd_m": NaN, "x": ', 1)), "good.json", "non-standard literal NaN"),
    ("duplicate-key", _text(lambda t: t.replace('"submitter": "b"', '"submitter": "b", "submitter": "c"')), "good.json", "duplicate key 'submitter'"),
    ("top-level-array", lambda good: b"[1, 2]", "good.json", "schema: (top level): [1, 2] is not of type 'object'"),
    ("wrong-format", _edit(lambda s: s.update(format="metricscenes-submission/0")), "good.json", "schema: format:"),
    ("missing-field", _edit(lambda s: s.pop("submitter")), "good.json", "'submitter' is a required property"),
    ("unknown-field", _edit(lambda s: s.update(secret=1)), "good.json", "Additional properties are not allowed ('secret'"),
    ("ap-as-string", _edit(_set_ap("0.5")), "good.json", "schema: conditions.day.per_distance[1].ap: '0.5' is not of type 'number'"),
    ("n-images-float", _edit(lambda s: s["conditions"]["day"]["per_distance"][0].update(n_images=2.5)), "good.json",
     "per_distance[0].n_images: 2.5 is not of type 'integer'"),
    ("ap-above-1", _edit(_set_ap(1.5)), "good.json", "conditions.day.per_distance[1].ap: 1.5 is greater than the maximum of 1"),
    ("ap-below-0", _edit(_set_ap(-0.01)), "good.json", "conditions.day.per_distance[1].ap: -0.01 is less than the minimum of 0"),
    ("bad-sha-format", _edit(lambda s: s["detector"].update(sha256="XYZ")), "good.json", "detector.sha256: 'XYZ' does not match"),
    ("bad-date", _edit(lambda s: s.update(created_at="2025-13-01T00:00:00Z")), "good.json", "created_at '2025-13-01T00:00:00Z' is not a valid UTC date"),
    ("missing-distance", _edit(_drop_distance), "good.json", "conditions.day.per_distance: missing distance(s) 150 m"),
    ("extra-distance", _edit(_extra_distance), "good.json", "distance 300 m is not one of protocol 'smoke'"),
    ("repeated-distance", _edit(_repeat_distance), "good.json", "distance 150 m appears 2 times"),
    ("missing-day", _edit(_only_night), "good.json", "missing required condition 'day'"),
    ("unknown-condition", _edit(_fog), "good.json", "conditions.fog: not a condition of protocol 'smoke'"),
    ("od50-inconsistent", _edit(_od50_off), "good.json", "conditions.day.od50_m = 1"),
    ("spec-edited", _edit(_pixel), "good.json", "camera.spec_sha256"),
    ("spec-hash-edited", _edit(lambda s: s["camera"].update(spec_sha256="0" * 64)), "good.json", "does not match the spec's content"),
    ("spec-invalid", _edit(_bad_spec_rehashed), "good.json", "field 'sensor.pixel_um' = 100.0"),
    ("spec-derived-edited", _edit(_derived_width), "good.json", "camera.spec: sensor.width_px is not what the spec resolves to"),
    ("isp-differs", _edit(lambda s: s["isp"].update(demosaic="bilinear")), "good.json", "isp differs from camera.spec.isp"),
    ("unknown-protocol", _edit(lambda s: s["collection"].update(protocol="homebrew")), "good.json", "protocol 'homebrew' is not accepted"),
    ("manifest-not-accepted", _edit(lambda s: s["collection"].update(manifest_sha256="ab" * 32)), "good.json",
     "collection.manifest_sha256 abababababab... is not an accepted manifest of protocol 'smoke'"),
    ("name-mismatch", lambda good: dumps_submission(good).encode(), "other.json", "file name must be <name>.json"),
    ("unsafe-file-name", lambda good: dumps_submission(good).encode(), "bad name.json", "unsafe submission name 'bad name'"),
    ("unsafe-name-field", _edit(lambda s: s.update(name="../escape")), "good.json", "name is '../escape'"),
    ("not-dot-json", lambda good: dumps_submission(good).encode(), "good.txt", "must end in .json"),
    ("over-5-MB", lambda good: dumps_submission(good).encode() + b" " * (5 * 1024 * 1024), "good.json", "over the 5 MB limit"),
    ("duplicate-name", _edit(lambda s: s.update(name="existing")), "existing.json", "duplicate name"),
    # what used to pass --check (or break `benchmark leaderboard` later)
    ("name-trailing-newline", _edit(lambda s: s.update(name="good\n")), "good.json", "good.json: name: string holds a control character or line break U+000A"),
    ("submitter-carriage-return", _edit(lambda s: s.update(submitter="b\r")), "good.json", "submitter: string holds a control character or line break U+000D"),
    ("sha-trailing-newline", _edit(lambda s: s["detector"].update(sha256=s["detector"]["sha256"] + "\n")), "good.json",
     "detector.sha256: string holds a control character or line break U+000A"),
    ("overflow-to-infinity", _sub_number(r'"od50_sd_m": [0-9.]+', '"od50_sd_m": 1e400'), "good.json",
     "good.json: invalid JSON: number 1e400 overflows to infinity"),
    ("negative-overflow", _sub_number(r'"distance_m": 25(\.0)?', '"distance_m": -1E+999'), "good.json", "number -1E+999 overflows to infinity"),
    ("integer-too-large", _sub_number(r'"n_images": [0-9]+', '"n_images": 1' + "0" * 400), "good.json", "invalid JSON: integer 1000000000"),
    ("lone-surrogate", _text(lambda t: t.replace('"submitter": "b"', '"submitter": "b\\ud800"')), "good.json",
     "submitter: string holds a lone surrogate U+D800"),
    ("lone-surrogate-in-key", _text(lambda t: t.replace('"submitter": "b"', '"submitter": "b", "\\udfff": 1')), "good.json",
     "(top level): a key holds a lone surrogate U+DFFF"),
    ("nesting-100000", lambda good: b'{"notes": ' + b"[" * 100_000 + b"]" * 100_000 + b"}", "good.json", "invalid JSON: nested deeper than 32 levels"),
    ("nesting-200", _text(lambda t: t.replace('"submitter": "b"', '"submitter": "b", "x": ' + "[" * 200 + "]" * 200)), "good.json",
     "invalid JSON: nested deeper than 32 levels"),
    ("ap-above-ap50", _edit(_ap_above_ap50), "good.json", "conditions.day.per_distance: AP 0."),
    ("ci-reversed", _edit(_ci_reversed), "good.json", "is reversed (lo > hi)"),
    ("ci-lo-infinite", _edit(_ci_lo_infinite), "good.json", "conditions.day.od50_ci95_m = [null, "),
    ("n-environments", _edit(lambda s: s["conditions"]["night"].update(n_environments=999)), "good.json",
     "conditions.night.n_environments = 999, but protocol 'smoke' has 4 environments"),
    ("same-detections", _edit(_same_detections), "good.json", "conditions.day and conditions.night have the same detections_sha256"),
    ("created-in-the-future", _edit(lambda s: s.update(created_at="9999-12-31T23:59:59Z")), "good.json",
     "created_at 9999-12-31T23:59:59Z is in the future"),
    # inconsistent fields that passed --check
    ("n-images-not-one-per-environment", _edit(lambda s: s["conditions"]["day"]["per_distance"][0].update(n_images=99)),
     "good.json", "conditions.day.per_distance: n_images 99 at 25 m, but a collection of 4 environments has 4 images at each distance"),
    ("interval-excludes-od50", _edit(_ci_excludes), "good.json", "conditions.day.od50_m = "),
    ("sd-zero-with-a-wide-interval", _edit(_sd_zero), "good.json", "conditions.day.od50_sd_m = 0, but its od50_ci95_m"),
    ("detector-sha-not-the-models", _edit(lambda s: s["detector"].update(sha256="ab" * 32)), "good.json",
     "detector.sha256 abababababab... is not the sha256 of registry model 'yolov5n-dynamic'"),
    ("registry-model-under-another-name", _edit(lambda s: s["detector"].update(name="my-own-net")), "good.json",
     "is registry model 'yolov5n-dynamic', but detector.name is 'my-own-net'"),
    ("licence-not-the-models", _edit(lambda s: s["detector"].update(licence="MIT")), "good.json",
     "detector.licence 'MIT' is not registry model 'yolov5n-dynamic''s ('AGPL-3.0')"),
    ("family-not-the-models", _edit(lambda s: s["detector"].update(family="yolov8")), "good.json",
     "detector.family 'yolov8' is not registry model 'yolov5n-dynamic''s"),
    ("unknown-family", _edit(lambda s: s["detector"].update(name="my-own-net", sha256="ab" * 32, family="rcnn")),
     "good.json", "detector.family 'rcnn' is not a known family"),
    ("input-size-not-a-policy", _edit(lambda s: s["detector"].update(input_size=33)), "good.json",
     "detector.input_size must be 'native', 'multiscale' or a positive multiple of 32, got 33"),
    ("score-threshold-not-aps", _edit(lambda s: s["detector"].update(score_threshold=0.5)), "good.json",
     "detector.score_threshold 0.5 is not AP's 0.001"),
    ("single-label", _edit(lambda s: s["detector"].update(multi_label=False)), "good.json", "detector.multi_label is false"),
    ("rtl-override-in-a-name", _edit(lambda s: s.update(submitter="ref\u202emetricscenes")), "good.json",
     "submitter: string holds an invisible formatting character U+202E (right-to-left override)"),
    ("zero-width-space-in-notes", _edit(lambda s: s.update(notes="cam\u200b12")), "good.json",
     "notes: string holds an invisible formatting character U+200B (zero width space)"),
    ("blank-submitter", _edit(lambda s: s.update(submitter=" ")), "good.json", "submitter ' ' is blank or padded"),
    ("padded-detector-name", _edit(lambda s: s["detector"].update(name="yolov5n-dynamic ")), "good.json",
     "detector.name 'yolov5n-dynamic ' is blank or padded"),
    ("measured-mtf50-not-the-cameras", _edit(lambda s: s["camera"].update(mtf50_source="measured", mtf50_cy_per_mm=999.9)),
     "good.json", "camera.mtf50_cy_per_mm 999.9 (measured) is not the camera's: its spec gives"),
    ("no-mtf50-for-a-spec-with-a-group", _edit(lambda s: s["camera"].update(mtf50_source="none", mtf50_cy_per_mm=None)),
     "good.json", "camera.mtf50_source is 'none', but the spec has a published MTF50 group"),
    ("detections-of-another-entry", lambda good: b"", "good.json", "is the detections of existing.json"),  # made in the test
    # fields that passed --check where no duplicate answered first
    ("collection-name-of-another-protocol", _edit(lambda s: s["collection"].update(name="metric-300")), "good.json",
     "collection.name 'metric-300' is not the name of protocol 'smoke''s collection ('smoke')"),
    ("package-version-no-release-has", _edit(lambda s: s.update(package_version="999")), "good.json",
     "package_version 999 is newer than this checker's metricscenes"),
    ("package-version-not-a-version", _edit(lambda s: s.update(package_version="latest")), "good.json",
     "package_version 'latest' is not a version (PEP 440"),
    ("created-before-the-protocol", _edit(lambda s: s.update(created_at="1900-01-01T00:00:00Z")), "good.json",
     "created_at 1900-01-01T00:00:00Z is before 2023-01-01"),
    ("od50-sd-astronomical", _edit(lambda s: s["conditions"]["day"].update(od50_sd_m=1e300)), "good.json",
     "conditions.day.od50_sd_m = 1e+300 m is beyond any OD50 an AP curve gives"),
]  # fmt: skip


def _invoke(app, args):
    res = CliRunner().invoke(app, [str(a) for a in args])
    stderr = getattr(res, "stderr", None) or res.output
    return res, stderr


def _save(world, folder, sub=None):
    """``sub`` (default: the good submission) written into ``folder`` with the good one's detections beside it."""
    return save_submission(world["good"] if sub is None else sub, folder, packs=world["good"].packs)


@pytest.mark.parametrize("case", BAD, ids=[c[0] for c in BAD])
def test_bad_submission_refused(app, world, tmp_path, case):
    case_id, make, file_name, expected = case
    path = tmp_path / file_name
    if case_id == "detections-of-another-entry":  # copied detections: another entry's day run
        make = _edit(lambda s: s["conditions"]["day"].update(
            detections_sha256=world["existing"]["conditions"]["day"]["detections_sha256"]))
    path.write_bytes(make(world["good"]))
    before = tree_sha256(world["leaderboard"])
    res, stderr = _invoke(app, ["submit", "--check", path, "--leaderboard", world["leaderboard"]])
    assert res.exit_code == 2, res.output
    lines = stderr.strip().splitlines()
    assert len(lines) == 1 and lines[0].startswith("error: "), stderr
    assert expected in lines[0], lines[0]
    assert tree_sha256(world["leaderboard"]) == before


def test_good_submission_passes_and_touches_nothing(app, world, tmp_path):
    path = _save(world, tmp_path)
    before = tree_sha256(world["leaderboard"])
    root = world["root"]
    res, _ = _invoke(app, ["submit", "--check", path, "--leaderboard", world["leaderboard"],
                           "--detections", root / "cam07" / "day" / "detections.json",
                           "--groundtruth", root / "cam07" / "day" / "groundtruth.json"])  # fmt: skip
    assert res.exit_code == 0, res.output
    assert ("ok: good.json (protocol smoke, conditions day, night; AP recomputed from its shipped detections "
            "(2 condition(s)); AP recomputed from 1 detections file(s))") in res.output
    # (the synthetic runs draw a new ground truth per condition; real runs of one camera share it)
    res, _ = _invoke(app, ["submit", "--check", path, "--leaderboard", world["leaderboard"],
                           "--detections", root / "cam07" / "night" / "detections.json",
                           "--groundtruth", root / "cam07" / "night" / "groundtruth.json"])  # fmt: skip
    assert res.exit_code == 0, res.output
    assert tree_sha256(world["leaderboard"]) == before
    # a file already in the leaderboard is not its own duplicate
    check_submission_file(world["leaderboard"] / "submissions" / "existing.json", leaderboard_dir=world["leaderboard"])


def test_content_duplicate_under_another_name(app, world, tmp_path):
    sub = copy.deepcopy(world["existing"])
    sub["name"] = "renamed"
    path = tmp_path / "renamed.json"
    path.write_text(dumps_submission(sub))
    res, stderr = _invoke(app, ["submit", "--check", path, "--leaderboard", world["leaderboard"]])
    assert res.exit_code == 2 and "duplicate: existing.json already ranks the same camera spec, detector and collection" in stderr


def test_a_reproduction_of_an_entry_is_not_a_second_row(app, world, tmp_path):
    """The same camera spec, detector and collection run again (other detections: another
    seed or machine) under another name: refused as a duplicate, by `submit --check` and by
    `benchmark leaderboard` when such a file is dropped in by hand."""
    import shutil

    sub = copy.deepcopy(world["existing"])
    sub["name"] = "existing-again"
    for cond in sub["conditions"].values():
        cond["detections_sha256"] = hashlib.sha256(cond["detections_sha256"].encode()).hexdigest()
    path = save_submission(sub, tmp_path, packs=world["existing"].packs)
    before = tree_sha256(world["leaderboard"])
    res, stderr = _invoke(app, ["submit", "--check", path, "--leaderboard", world["leaderboard"]])
    assert res.exit_code == 2 and stderr.strip().splitlines() == [
        "error: duplicate: existing.json already ranks the same camera spec, detector and collection (a reproduction "
        "of it is not a second row; to replace it, remove existing.json first)"], stderr
    assert tree_sha256(world["leaderboard"]) == before
    lb = tmp_path / "lb"
    shutil.copytree(world["leaderboard"], lb)
    shutil.copy(path, lb / "submissions" / path.name)  # the JSON alone: a duplicate is named before missing files
    before = tree_sha256(lb)
    res, stderr = _invoke(app, ["leaderboard", "--dir", lb])
    assert res.exit_code == 2 and len(stderr.strip().splitlines()) == 1, stderr
    assert "submissions/existing.json: duplicate: existing-again.json already ranks the same camera spec" in stderr
    assert tree_sha256(lb) == before


@pytest.mark.parametrize("what", ["ap", "ap50"])
def test_ap_mismatch_with_detections(app, world, tmp_path, what):
    """An AP edited beyond float rounding (2e-6) is refused from the detections the submission ships,
    naming the field, the claimed and the recomputed value; from a run's files (--detections) too."""
    sub = copy.deepcopy(world["good"])
    row = sub["conditions"]["day"]["per_distance"][2]
    original = row[what]
    row[what] = round(row[what] + 2e-6, 9) if row[what] < 0.5 else row[what] - 2e-6  # beyond the 1e-6 tolerance
    _fix_od50(sub)
    path = _save(world, tmp_path, sub)
    day = world["root"] / "cam07" / "day"
    before = tree_sha256(world["leaderboard"])
    args = ["submit", "--check", path, "--leaderboard", world["leaderboard"]]
    res, stderr = _invoke(app, args)
    assert res.exit_code == 2 and stderr.strip().splitlines() == [
        f"error: good.json: conditions.day.per_distance[75 m].{what} is {row[what]:.6f}, but {original:.6f} recomputed "
        "from its shipped detections"], stderr
    res, stderr = _invoke(app, [*args, "--detections", day / "detections.json", "--groundtruth", day / "groundtruth.json"])
    assert res.exit_code == 2 and "recomputed from" in stderr, stderr
    assert tree_sha256(world["leaderboard"]) == before


def test_detections_of_another_system(app, world, tmp_path):
    path = _save(world, tmp_path)
    other = world["root"] / "cam03" / "day"
    res, stderr = _invoke(app, ["submit", "--check", path, "--leaderboard", world["leaderboard"],
                                "--detections", other / "detections.json", "--groundtruth", other / "groundtruth.json"])  # fmt: skip
    assert res.exit_code == 2 and "is not the file any condition was computed from" in stderr
    res, stderr = _invoke(app, ["submit", "--check", path, "--leaderboard", world["leaderboard"], "--detections", other / "detections.json"])
    assert res.exit_code == 2 and "--detections needs --groundtruth" in stderr


@pytest.mark.parametrize("name", ["../escape", "a/b", "a\\b", ".hidden", "sp ace", "naïve", "", "trailing\n"])
def test_unsafe_names_refused_when_building(app, world, name):
    before = tree_sha256(world["leaderboard"])
    res, stderr = _invoke(app, ["submit", world["root"] / "cam03" / "night", "--name", name, "--leaderboard", world["leaderboard"],
                                "--n-resamples", "5", "--no-mtf"])  # fmt: skip
    assert res.exit_code == 2
    assert stderr.strip().startswith("error: unsafe submission name"), stderr
    assert tree_sha256(world["leaderboard"]) == before


def test_build_refuses_changed_run_files(app, world, tmp_path):
    import shutil

    run = tmp_path / "run"
    shutil.copytree(world["root"] / "cam03" / "night", run)
    before = tree_sha256(world["leaderboard"])
    args = ["submit", run, "--name", "n1", "--leaderboard", world["leaderboard"], "--n-resamples", "5", "--no-mtf"]
    results = json.loads((run / "results.json").read_text())
    results["per_distance"][0]["ap"] = results["per_distance"][0]["ap"] / 2 + 0.01  # a results.json that lies
    (run / "results.json").write_text(json.dumps(results))
    res, stderr = _invoke(app, args)
    assert res.exit_code == 2 and "recomputed from detections.json" in stderr, stderr
    (run / "detections.json").write_text("[]")  # detections that are not the scored ones
    res, stderr = _invoke(app, args)
    assert res.exit_code == 2 and "sha256 differs from results.json's detections_sha256" in stderr, stderr
    assert tree_sha256(world["leaderboard"]) == before


def test_created_at_allows_one_day_of_clock_skew(world):
    from datetime import datetime, timedelta, timezone

    from benchmark.leaderboard import SubmissionError, validate_submission

    protocols = load_protocols(world["leaderboard"])
    now = datetime(2025, 1, 2, 3, 4, 5, tzinfo=timezone.utc)
    sub = copy.deepcopy(world["good"])
    for ahead, ok in ((timedelta(0), True), (timedelta(hours=23), True), (timedelta(days=1, seconds=1), False)):
        sub["created_at"] = (now + ahead).strftime("%Y-%m-%dT%H:%M:%SZ")
        if ok:
            validate_submission(sub, protocols=protocols, now=now)
        else:
            with pytest.raises(SubmissionError, match=r"^good: created_at 2025-01-03T03:04:06Z is in the future \(now 2025-01-02T03:04:05Z\)$"):
                validate_submission(sub, protocols=protocols, source="good", now=now)


@pytest.mark.parametrize(
    ("edit", "expected"),
    [
        (lambda s: s.update(submitter="\udcff"), "submitter: string holds a lone surrogate U+DCFF"),  # what a non-UTF-8 argv byte becomes
        (lambda s: s.update(submitter="a\u2028b"), "submitter: string holds a control character or line break U+2028"),
        (lambda s: s["conditions"]["day"].update(od50_sd_m=math.inf), "conditions.day.od50_sd_m: inf is not a finite number"),
        (lambda s: s["conditions"]["day"]["per_distance"][0].update(ap=math.nan), "per_distance[0].ap: nan is not a finite number"),
        (lambda s: s.update(notes="line one\n\tline two"), None),  # notes may hold line breaks and tabs
        (lambda s: s.update(notes="bell \x07"), "notes: string holds a control character or line break U+0007"),
    ],
    ids=["surrogate", "line-separator", "inf", "nan", "notes-multiline", "notes-control"],
)
def test_in_memory_submissions_checked_too(world, edit, expected):
    """`submit` validates what it built (e.g. a --submitter from argv) with the same rules as --check."""
    from benchmark.leaderboard import SubmissionError, validate_submission

    sub = copy.deepcopy(world["good"])
    edit(sub)
    protocols = load_protocols(world["leaderboard"])
    if expected is None:
        validate_submission(sub, protocols=protocols)
        return
    with pytest.raises(SubmissionError) as info:
        validate_submission(sub, protocols=protocols, source="good")
    assert str(info.value).startswith("good: ") and expected in str(info.value) and "\n" not in str(info.value)


def _laughs(levels: int) -> str:
    """A protocols.yaml whose description is 9**levels strings made of aliases of aliases."""
    lines = ["a0: &a0 [lol, lol, lol, lol, lol, lol, lol, lol, lol]"]
    lines += [f"a{i}: &a{i} [{', '.join([f'*a{i - 1}'] * 9)}]" for i in range(1, levels + 1)]
    return ("laughs:\n" + "".join(f"  {line}\n" for line in lines)
            + PROTOCOLS.format(sha="0" * 64).replace("description: smoke", f"description: *a{levels}"))


@pytest.mark.parametrize(("text", "expected"), [
    (_laughs(6), "invalid protocols file (an alias (*name): a protocols file holds none at line 3)"),
    (PROTOCOLS.format(sha="0" * 64) + "accepted_by: me\n",
     "invalid protocols file (unknown top-level key(s) accepted_by (it holds only 'labels', 'protocols'))"),
    (PROTOCOLS.format(sha="0" * 64).replace("n_environments", "n_environment"),
     "invalid protocols file (protocol 'smoke': unknown key(s) n_environment"),
    (PROTOCOLS.format(sha="0" * 64).replace("description: smoke", "description: [a, b]"),
     "invalid protocols file (protocol 'smoke': description must be a string, got list)"),
])
def test_a_protocols_file_a_pull_request_can_carry_is_read_as_untrusted(app, world, tmp_path, text, expected):
    """A leaderboard's own protocols.yaml: no aliases (a "billion laughs" grew to a MemoryError
    when its description was printed), no key that would be ignored, strings where strings
    are meant; each one line, at once."""
    import time

    lb = tmp_path / "lb"
    (lb / "submissions").mkdir(parents=True)
    (lb / "protocols.yaml").write_text(text)
    path = tmp_path / "good.json"
    path.write_text(dumps_submission(world["good"]))
    started = time.perf_counter()
    res, stderr = _invoke(app, ["submit", "--check", path, "--leaderboard", lb])
    assert res.exit_code == 2 and len(stderr.strip().splitlines()) == 1 and expected in stderr, stderr
    assert time.perf_counter() - started < 10


def test_check_name_is_anchored_at_the_very_end():
    from benchmark.leaderboard import SubmissionError, check_name

    assert check_name("good") == "good"
    for name in ("good\n", "good\r", "\ngood", "a" * 81):
        with pytest.raises(SubmissionError, match="unsafe submission name"):
            check_name(name)


def test_leaderboard_command_refuses_what_check_refuses(app, world, tmp_path):
    """A lone surrogate in a submission used to pass --check and then break `benchmark leaderboard`."""
    import shutil

    lb = tmp_path / "leaderboard"
    shutil.copytree(world["leaderboard"], lb)
    assert _invoke(app, ["leaderboard", "--dir", lb])[0].exit_code == 0
    text = dumps_submission(world["good"]).replace('"submitter": "b"', '"submitter": "b\\ud800"')
    (lb / "submissions" / "good.json").write_text(text, encoding="utf-8")
    before = tree_sha256(lb)
    res, stderr = _invoke(app, ["leaderboard", "--dir", lb])
    assert res.exit_code == 2
    assert stderr.strip().splitlines() == [
        "error: good.json: submitter: string holds a lone surrogate U+D800 (not valid Unicode; UTF-8 cannot encode it) (the table was not changed)"
    ]
    assert tree_sha256(lb) == before


HOSTILE = "<img src=x onerror=alert(1)> | [click](http://evil.example) ![i](x.png) *b* _i_ `c` \\ ~s~ &lt; {x} #1 !"


def _readme_row(text: str, name: str) -> str:
    return next(line for line in text.splitlines() if f"submissions/{name}.json" in line)


def test_markdown_escapes_free_text(world):
    """Free text reaches README.md as literal text, as html.escape makes it literal in index.html."""
    from benchmark.leaderboard import render_html, render_markdown
    from benchmark.leaderboard.render import columns

    protocols = load_protocols(world["leaderboard"])
    sub = copy.deepcopy(world["good"])
    sub["submitter"] = HOSTILE
    sub["name"] = "my_sys.v2"
    readme = render_markdown([sub], protocols)
    row = _readme_row(readme, "my_sys.v2")
    assert "\\<img src=x onerror=alert(1)\\> \\| \\[click\\](http://evil.example) \\!\\[i\\](x.png) \\*b\\* \\_i\\_ \\`c\\` \\\\ \\~s\\~ \\&lt; \\{x\\} \\#1 \\!" in row
    assert "[my\\_sys.v2](submissions/my_sys.v2.json)" in row  # the link target is the (safe) file name, unescaped
    keys = [c.key for c in columns(protocols["smoke"])]
    cells = re.split(r"(?<!\\)\|", row)[1:-1]  # unescaped pipes only: the hostile text is one cell
    assert len(cells) == len(keys) and cells[keys.index("submitter")].strip().startswith("\\<img")
    page = render_html([sub], protocols)
    assert "&lt;img src=x onerror=alert(1)&gt;" in page and "<img" not in page


def test_markdown_renders_free_text_literally(world):
    """Through a CommonMark renderer with GFM tables, the hostile submitter is one cell of plain text."""
    import html as html_lib

    from benchmark.leaderboard import render_markdown
    from benchmark.leaderboard.render import columns

    markdown_it = pytest.importorskip("markdown_it")  # installed with typer's rich; not a dependency of its own
    protocols = load_protocols(world["leaderboard"])
    sub = copy.deepcopy(world["good"])
    sub["submitter"] = HOSTILE
    rendered = markdown_it.MarkdownIt("commonmark").enable("table").render(render_markdown([sub], protocols))
    keys = [c.key for c in columns(protocols["smoke"])]
    cells = re.findall(r"<td[^>]*>(.*?)</td>", rendered)
    assert len(cells) == len(keys), cells
    assert html_lib.unescape(cells[keys.index("submitter")]) == HOSTILE  # shown exactly as submitted
    assert "<img" not in rendered and "<em>" not in rendered and "<code>" not in rendered and 'href="http://evil' not in rendered


def test_committed_readme_unchanged_by_escaping():
    """The escaping leaves today's table as it was: nothing in it needs escaping but the
    censored OD50 bounds ("\\> 200", "\\< 25"), escaped so that they show as themselves."""
    from benchmark.leaderboard.render import _md

    text = (REPO / "leaderboard" / "README.md").read_text()
    rows = [line for line in text.splitlines() if line.startswith("| ") and "submissions/" in line]
    assert len(rows) == 3 * 13  # the 13 reference cameras on quick, adas and metric-300
    for row in rows:
        for cell in row.strip("| ").split(" | ")[2:]:
            assert _md(cell.replace("\\>", ">").replace("\\<", "<")) == cell
