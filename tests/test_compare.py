"""`benchmark compare`: paired bootstrap of ΔAP per distance and ΔOD50 over the same environments."""

from __future__ import annotations

import json

import numpy as np
import pytest
from typer.testing import CliRunner

from benchmark.experiments.compare import CompareError, Side, compare_runs, load_side, verdict
from benchmark.leaderboard.protocols import condition_label
from synthetic_scoring import synthetic_collection

SHA = "f" * 64
NIGHT = condition_label("night")  # verdicts open with what the condition physically is


def _write_run(folder, camera: str, condition: str, gt: dict, detections: list, manifest_sha256: str = SHA):
    """A minimal run folder ``compare`` reads: results.json, groundtruth.json, detections.json."""
    folder.mkdir()
    results = {"camera": {"name": camera}, "condition": condition, "collection": {"manifest_sha256": manifest_sha256}}
    (folder / "results.json").write_text(json.dumps(results))
    (folder / "groundtruth.json").write_text(json.dumps(gt))
    (folder / "detections.json").write_text(json.dumps(detections))


def side(gt, dets, name="camA", condition="day", sha=SHA, folder="run") -> Side:
    from pathlib import Path

    from benchmark.result_files import RunResults

    results = RunResults.model_validate({"camera": {"name": name}, "condition": condition,
                                         "collection": {"manifest_sha256": sha}, "scoring_backend": "faster-coco-eval"})
    return Side(Path(folder), results, gt, dets)


def degraded(gt, dets, *, drop=0.5, from_m=25.0, seed=1):
    """The same run with car detections at ``from_m`` and beyond dropped with probability ``drop``."""
    rng = np.random.default_rng(seed)
    distance = {im["id"]: im["distance_m"] for im in gt["images"]}
    return [d for d in dets if not (d["category_id"] == 3 and distance[d["image_id"]] >= from_m and rng.uniform() < drop)]


@pytest.fixture(scope="module")
def run20():
    return synthetic_collection(20, seed=3, half_range_m=110.0)


def test_identical_runs_give_zero_and_no_difference(run20):
    gt, dets = run20
    res = compare_runs(side(gt, dets), side(gt, dets, name="camB"), n_resamples=50)
    assert res["delta_od50"]["delta_m"] == 0.0
    assert res["delta_od50"]["ci95_m"] == [0.0, 0.0]
    assert all(r["delta_ap"] == 0.0 and r["ci95"] == [0.0, 0.0] for r in res["per_distance"])
    assert res["verdict"].startswith("daylight: no difference resolved between camA and camB: ΔOD50")


def test_shifted_run_has_the_known_sign(run20):
    gt, dets = run20
    worse = degraded(gt, dets)
    res = compare_runs(side(gt, dets, name="good"), side(gt, worse, name="bad"), n_resamples=200)
    od = res["delta_od50"]
    assert od["delta_m"] > 0 and od["ci95_m"][0] > 0, od
    assert res["verdict"].startswith("daylight: good detects cars ") and "farther than bad (95 %" in res["verdict"]
    assert sum(r["delta_ap"] for r in res["per_distance"]) > 0
    flipped = compare_runs(side(gt, worse, name="bad"), side(gt, dets, name="good"), n_resamples=200)
    assert flipped["delta_od50"]["delta_m"] == pytest.approx(-od["delta_m"])
    assert flipped["verdict"].startswith("daylight: good detects cars ")  # the farther one is named first


def test_mismatched_collections_are_refused(run20):
    gt, dets = run20
    with pytest.raises(CompareError, match="different collections"):
        compare_runs(side(gt, dets), side(gt, dets, sha="0" * 64), n_resamples=10)
    other_gt, other_dets = synthetic_collection(12, seed=3)
    with pytest.raises(CompareError, match="different environments"):
        compare_runs(side(gt, dets), side(other_gt, other_dets), n_resamples=10)


def test_paired_interval_is_narrower_than_unpaired(run20):
    gt, dets = run20
    worse = degraded(gt, dets, drop=0.3)
    kw = {"n_resamples": 300, "seed": 5}
    paired = compare_runs(side(gt, dets), side(gt, worse, name="camB"), paired=True, **kw)
    unpaired = compare_runs(side(gt, dets), side(gt, worse, name="camB"), paired=False, **kw)

    def width(res):
        lo, hi = res["delta_od50"]["ci95_m"]
        return hi - lo

    # both intervals are multiplier x bootstrap SD (every resample finite): the ratio is the SDs'
    assert width(paired) == pytest.approx(2 * paired["family"]["sd_multiplier"] * paired["delta_od50"]["sd_m"])
    assert width(paired) < 0.85 * width(unpaired)
    ap_w = [r["ci95"][1] - r["ci95"][0] for r in paired["per_distance"]]
    ap_w_un = [r["ci95"][1] - r["ci95"][0] for r in unpaired["per_distance"]]
    assert sum(ap_w) < sum(ap_w_un)


def test_censored_od50_is_not_a_difference():
    res = {"a": {"label": "cam12", "condition": "day", "od50_m": 281.3, "censored": ">", "bound_m": 200.0},
           "b": {"label": "cam01", "condition": "day", "od50_m": 89.7, "censored": "", "bound_m": None},
           "confidence_level": 0.95, "delta_od50": {"delta_m": None, "sd_m": None, "ci95_m": [None, None]},
           "per_distance": [{"distance_m": 100.0, "ci95": [0.3, 0.6]}, {"distance_m": 25.0, "ci95": [-0.01, 0.04]}]}
    text = verdict(res)
    assert text.startswith("daylight: cam12 detects cars farther than cam01, by at least 110 m (OD50 > 200 m vs 89.7 m")
    assert "AP differs at 100 m" in text and "281" not in text


def test_cli_runs_and_refuses_in_one_line(tmp_path, run20):
    from benchmark.cli.main import app

    gt, dets = run20
    for name, d, sha in (("a", dets, SHA), ("b", degraded(gt, dets), SHA), ("c", dets, "0" * 64)):
        _write_run(tmp_path / name, f"cam-{name}", "day", gt, d, sha)
    runner = CliRunner()
    out = tmp_path / "cmp"
    res = runner.invoke(app, ["compare", str(tmp_path / "a"), str(tmp_path / "b"), "--resamples", "50", "--out", str(out)])
    assert res.exit_code == 0, res.output
    assert "cam-a detects cars" in res.output and "50 resamples" in res.output
    assert (out / "compare.png").stat().st_size > 1000
    assert json.loads((out / "compare.json").read_text())["paired"] is True
    assert load_side(tmp_path / "a").camera == "cam-a"
    bad = runner.invoke(app, ["compare", str(tmp_path / "a"), str(tmp_path / "c"), "--resamples", "10"])
    assert bad.exit_code == 2 and "different collections" in bad.output
    assert "Traceback" not in bad.output


def _blind_beyond_25m(gt, *, low_score_hits_at=200.0):
    """A night pair: both cameras find every car at 25 m (score 0.9) and none farther; B also puts a
    box of score 0.02 on the car at ``low_score_hits_at`` in 6 of 10 environments (AP > 0 from noise)."""
    a, b = [], []
    for im in gt["images"]:
        box = next(x["bbox"] for x in gt["annotations"] if x["image_id"] == im["id"])
        if im["distance_m"] == 25.0:
            hit = {"image_id": im["id"], "category_id": 3, "bbox": list(box), "score": 0.9}
            a.append(hit)
            b.append(dict(hit))
        elif im["distance_m"] == low_score_hits_at and im["environment_id"] < 6:
            b.append({"image_id": im["id"], "category_id": 3, "bbox": list(box), "score": 0.02})
    return a, b


def test_both_blind_beyond_25m_is_said_plainly_not_called_a_difference():
    gt, _ = synthetic_collection(10, seed=7)
    dets_a, dets_b = _blind_beyond_25m(gt)
    res = compare_runs(side(gt, dets_a, name="camA", condition="night"), side(gt, dets_b, name="camB", condition="night"),
                       n_resamples=200)
    far = next(r for r in res["per_distance"] if r["distance_m"] == 200.0)
    assert far["ap_b"] > 0.1 and far["ci95"][1] < 0  # the interval alone would call B better at 200 m ...
    assert far["found_b"] == 0 and far["cars_needed"] == 3 and not far["resolved"] and far["blind"]  # ... on noise
    near = next(r for r in res["per_distance"] if r["distance_m"] == 25.0)
    assert near["found_a"] == near["found_b"] == 10 and not near["blind"]
    assert res["verdict"].startswith(f"{NIGHT}: ") and "both blind beyond 25 m" in res["verdict"]
    assert "AP differs at" not in res["verdict"] and "\n" not in res["verdict"]


def test_both_blind_everywhere_is_no_difference():
    gt, _ = synthetic_collection(10, seed=7)
    noise = [{"image_id": im["id"], "category_id": 3, "bbox": [10.0, 10.0, 30.0, 20.0], "score": 0.05}
             for im in gt["images"]]
    res = compare_runs(side(gt, noise, condition="night"), side(gt, noise[:5], name="camB", condition="night"),
                       n_resamples=50)
    assert res["verdict"] == (f"{NIGHT}: camA and camB are both blind at every measured distance (25 to 200 m: neither "
                              "camera found 3 of the 10 cars: a car detection of score >= 0.25 on the car at IoU >= 0.5): "
                              "no difference is called")


def test_cli_says_both_blind(tmp_path):
    from benchmark.cli.main import app

    gt, _ = synthetic_collection(10, seed=7)
    for name, dets in zip(("a", "b"), _blind_beyond_25m(gt)):
        _write_run(tmp_path / name, f"cam-{name}", "night", gt, dets, SHA)
    before = sorted(p.name for p in tmp_path.rglob("*"))
    res = CliRunner().invoke(app, ["compare", str(tmp_path / "a"), str(tmp_path / "b"), "--resamples", "100"])
    assert res.exit_code == 0, res.output
    text = " ".join(res.output.split())
    assert f"{NIGHT}: " in text and "both blind beyond 25 m" in text and "AP differs at" not in text
    assert "0/10" in text and "10/10" in text and "blind" in text
    assert sorted(p.name for p in tmp_path.rglob("*")) == before  # no --out: nothing written


def test_too_few_cars_to_call_anything_is_said_not_taken_for_blindness(monkeypatch):
    monkeypatch.setattr("benchmark.scoring.sample.MIN_ENVIRONMENTS", 2)  # (the found-cars rule alone, below the minimum sample)
    gt, _ = synthetic_collection(2, seed=7)  # two environments: two cars a distance, as on smoke
    perfect = [{"image_id": a["image_id"], "category_id": 3, "bbox": list(a["bbox"]), "score": 0.9}
               for a in gt["annotations"]]
    res = compare_runs(side(gt, perfect), side(gt, perfect[::2], name="camB"), n_resamples=50)
    assert not any(r["blind"] or r["resolved"] for r in res["per_distance"])
    assert res["verdict"].endswith("; with 2 cars per distance no difference at a distance can be called "
                                   "(3 found cars needed)")
    assert "blind" not in res["verdict"]


def _perfect(gt, up_to_m=1e9):
    """Exact car boxes of score 0.9 up to ``up_to_m``, none beyond."""
    distance = {im["id"]: im["distance_m"] for im in gt["images"]}
    return [{"image_id": a["image_id"], "category_id": 3, "bbox": list(a["bbox"]), "score": 0.9}
            for a in gt["annotations"] if distance[a["image_id"]] <= up_to_m]


def test_two_environments_refuse_in_one_line_naming_the_minimum():
    """As on `first`: a camera that finds every car against one that finds none beyond 50 m. The
    interval alone would call it; the verdict is the one line, the table is still there."""
    from benchmark.scoring import MIN_ENVIRONMENTS

    gt, _ = synthetic_collection(2, seed=7)
    res = compare_runs(side(gt, _perfect(gt)), side(gt, _perfect(gt, 50.0), name="camB"), n_resamples=100)
    assert res["verdict"] == (f"sample too small: 2 environments per distance, at least {MIN_ENVIRONMENTS} needed for a "
                              "verdict (docs/scoring.md)")
    assert res["sample_too_small"] and res["environments_per_distance"] == 2 and res["min_environments"] == MIN_ENVIRONMENTS
    assert len(res["per_distance"]) == 6 and not any(r["resolved"] for r in res["per_distance"])
    assert not res["delta_ap_range"]["resolved"] and res["delta_ap_range"]["ci95_m"][0] > 0  # excluded 0, not called


def test_cli_refuses_on_two_environments_and_prints_the_table(tmp_path):
    from benchmark.cli.main import app

    gt, _ = synthetic_collection(2, seed=7)
    for name, dets in (("a", _perfect(gt)), ("b", _perfect(gt, 50.0))):
        _write_run(tmp_path / name, f"cam-{name}", "day", gt, dets, SHA)
    res = CliRunner().invoke(app, ["compare", str(tmp_path / "a"), str(tmp_path / "b"), "--resamples", "50"],
                             env={"COLUMNS": "250"})
    assert res.exit_code == 0, res.output
    lines = res.output.splitlines()
    assert lines[-1].startswith("sample too small: 2 environments per distance, at least ")
    assert "2/2" in res.output and "0/2" in res.output and "FP/image" in res.output and "AP range" in res.output


def test_censored_od50_is_compared_by_ap_range():
    """A finds every car to 200 m (OD50 > 200 m), B none beyond 100 m: ΔOD50 is not measured, the
    ΔAP range is (200 vs 125 m) and carries the verdict."""
    gt, _ = synthetic_collection(10, seed=7)
    res = compare_runs(side(gt, _perfect(gt), name="camA"), side(gt, _perfect(gt, 100.0), name="camB"), n_resamples=100)
    assert res["delta_od50"]["delta_m"] is None and res["a"]["censored"] == ">" and res["b"]["censored"] == ""
    rng = res["delta_ap_range"]
    assert (res["a"]["ap_range_m"], res["b"]["ap_range_m"]) == pytest.approx((200.0, 125.0))
    assert rng["delta_m"] == pytest.approx(75.0) and rng["resolved"]
    assert res["verdict"].startswith("daylight: camA detects cars farther than camB: AP range 200 vs 125 m, 75 ± 0 m more "
                                     "(95 %: 75–75 m; OD50 > 200 m vs 125.0 m: outside the measured distances")
    same = compare_runs(side(gt, _perfect(gt), name="camA"), side(gt, _perfect(gt), name="camB"), n_resamples=50)
    assert same["verdict"].startswith("daylight: no difference resolved between camA and camB: ΔAP range = +0 ± 0 m")


def test_rows_carry_miss_rate_false_positives_and_hold_their_points(run20):
    gt, dets = run20
    res = compare_runs(side(gt, dets), side(gt, degraded(gt, dets), name="camB"), n_resamples=100)
    for r in res["per_distance"]:
        assert r["ci95"][0] <= r["delta_ap"] <= r["ci95"][1]
        assert r["miss_rate_a"] == pytest.approx(1 - r["found_a"] / r["n_cars"]) and r["fp_per_image_a"] >= 0
        assert r["miss_rate_b"] >= r["miss_rate_a"]  # B lost half its car boxes
    for block in (res["delta_od50"], res["delta_ap_range"]):
        assert block["ci95_m"][0] <= block["delta_m"] <= block["ci95_m"][1]


def test_a_camera_against_itself_reseeded_is_within_its_interval():
    """Capture noise is inside the interval: environments are resampled with their one capture
    each, so the spread of the paired bootstrap covers a reseed (docs/scoring.md, "What is
    resampled"). On 12 environments of a synthetic camera, pairs of sensor-noise seeds: the
    bootstrap SD of ΔAP range is the reseeds' own spread (√2 × their SD) within 40 %, and the
    95 % intervals hold 0 in most pairs."""
    from benchmark.scoring import ap_by_distance, ap_range

    gt, _ = synthetic_collection(12, seed=1, noise_seed=0, half_range_m=110.0)
    runs = [synthetic_collection(12, seed=1, noise_seed=k, half_range_m=110.0)[1] for k in range(12)]
    ranges = []
    for dets in runs:
        rows = ap_by_distance(gt, dets)
        ranges.append(ap_range([r["distance_m"] for r in rows], [r["ap"] for r in rows]))
    pairs = [compare_runs(side(gt, runs[k]), side(gt, runs[k + 1], name="reseeded"), n_resamples=200, seed=k)
             for k in range(0, 12, 2)]
    spread = np.sqrt(2) * np.std(ranges, ddof=1)
    assert 0.6 * spread < np.mean([p["delta_ap_range"]["sd_m"] for p in pairs]) < 1.4 * spread
    held = [p["delta_ap_range"]["ci95_m"][0] <= 0 <= p["delta_ap_range"]["ci95_m"][1] for p in pairs]
    assert sum(held) >= 5, held
