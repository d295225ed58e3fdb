"""Bootstrap of OD50 over environments: the fast re-accumulation equals COCOeval, seeding, scaling."""

import numpy as np
import pytest

from benchmark.scoring import ap_by_distance, bootstrap_od50, resample_environments
from benchmark.scoring.bootstrap import _match_tables, weighted_ap
from synthetic_scoring import synthetic_collection


@pytest.mark.parametrize("seed", [0, 1])
def test_weighted_accumulate_equals_cocoeval_on_resamples(seed):
    gt, dets = synthetic_collection(8, seed=seed, empty_distance_m=200.0)
    envs = sorted({im["environment_id"] for im in gt["images"]})
    tables = _match_tables(gt, dets, 3, {e: k for k, e in enumerate(envs)})
    rng = np.random.default_rng(seed)
    for trial in range(4):
        sample = rng.integers(0, len(envs), len(envs)) if trial else np.arange(len(envs))
        rgt, rdets = resample_environments(gt, dets, [envs[k] for k in sample])
        assert len(rgt["images"]) == len(envs) * 6 and len({im["id"] for im in rgt["images"]}) == len(rgt["images"])
        oracle = ap_by_distance(rgt, rdets, backend="pycocotools")
        w = np.bincount(sample, minlength=len(envs))
        for row in oracle:
            ap, ap50 = weighted_ap(tables[row["distance_m"]], w)
            assert ap == pytest.approx(row["ap"], abs=1e-12)
            assert ap50 == pytest.approx(row["ap50"], abs=1e-12)


def test_same_seed_same_result_and_other_seed_differs():
    gt, dets = synthetic_collection(10, seed=4)
    a = bootstrap_od50(gt, dets, n_resamples=200, seed=7)
    b = bootstrap_od50(gt, dets, n_resamples=200, seed=7)
    c = bootstrap_od50(gt, dets, n_resamples=200, seed=8)
    assert a == b
    assert a.sd_m != c.sd_m
    assert a.n_resamples == 200 and a.n_environments == 10
    lo, hi = a.ci95_m
    assert lo < a.od50_m < hi
    assert 0 < a.sd_m < hi - lo


def test_sd_shrinks_with_more_environments():
    # SD of a mean-like statistic scales ~ 1/sqrt(n): 4x the environments ~ half the SD
    small = [bootstrap_od50(*synthetic_collection(10, seed=s), n_resamples=200, seed=0).sd_m for s in range(3)]
    large = [bootstrap_od50(*synthetic_collection(40, seed=s), n_resamples=200, seed=0).sd_m for s in range(3)]
    assert np.mean(large) < 0.75 * np.mean(small)


def test_point_estimate_is_od50_of_full_set_and_errors():
    gt, dets = synthetic_collection(6, seed=2)
    res = bootstrap_od50(gt, dets, n_resamples=50, seed=0, backend="pycocotools")
    from benchmark.scoring import od50

    rows = ap_by_distance(gt, dets)
    assert res.od50_m == pytest.approx(od50([r["distance_m"] for r in rows], [r["ap"] for r in rows]))
    with pytest.raises(ValueError, match="n_resamples"):
        bootstrap_od50(gt, dets, n_resamples=1)
    one_env = {**gt, "images": [im for im in gt["images"] if im["environment_id"] == 0]}
    with pytest.raises(ValueError, match="two or more environments"):
        bootstrap_od50(one_env, [], n_resamples=10)


def test_no_detections_bootstrap():
    gt, _ = synthetic_collection(4, seed=0)
    res = bootstrap_od50(gt, [], n_resamples=20)
    assert res.od50_m == 0.0 and res.sd_m == 0.0


def test_percentile_interval_with_unreachable_od50():
    import numpy as np

    from benchmark.scoring.bootstrap import percentile_interval

    values = np.r_[np.linspace(100.0, 199.0, 100), np.full(5, np.inf)]
    lo, hi = percentile_interval(values, 0.95)
    assert lo == 102.0 and hi == np.inf
    assert percentile_interval(np.linspace(0, 100, 101), 0.9) == (5.0, 95.0)


def test_one_runs_intervals_are_the_percentile_ones_widened_for_few_environments(monkeypatch):
    """OD50's and the AP range's intervals: the percentile interval stretched about its point by
    t_{n−1}(0.975)·√(n/(n − 1))/1.96 (1.22 on 10 environments); the SDs are the resamples' own."""
    import benchmark.scoring.bootstrap as bootstrap_module
    from benchmark.scoring.simultaneous import few_environments_scale, stretch

    gt, dets = synthetic_collection(10, seed=2, half_range_m=110.0)
    widened = bootstrap_od50(gt, dets, n_resamples=200)
    monkeypatch.setattr(bootstrap_module, "few_environments_scale", lambda n, level=0.95: 1.0)
    bare = bootstrap_od50(gt, dets, n_resamples=200)
    scale = few_environments_scale(10)
    assert widened.interval_scale == pytest.approx(scale) and 1.2 < scale < 1.23
    assert widened.ci95_m == pytest.approx(stretch(bare.od50_m, *bare.ci95_m, scale))
    assert widened.ap_range_ci95_m == pytest.approx(stretch(bare.ap_range_m, *bare.ap_range_ci95_m, scale))
    assert (widened.sd_m, widened.ap_range_sd_m) == (bare.sd_m, bare.ap_range_sd_m)
    assert widened.ci95_m[0] < bare.ci95_m[0] <= bare.od50_m <= bare.ci95_m[1] < widened.ci95_m[1]


def test_on_two_environments_the_widened_interval_stops_at_0_m():
    """× 9.2 on two environments: a distance's interval is cut at 0 m, not stretched below it."""
    gt, dets = synthetic_collection(2, seed=5, half_range_m=60.0)
    boot = bootstrap_od50(gt, dets, n_resamples=200)
    assert boot.interval_scale > 9.0
    assert boot.ci95_m[0] >= 0.0 and boot.ap_range_ci95_m[0] >= 0.0
    assert 0.0 in (boot.ci95_m[0], boot.ap_range_ci95_m[0])
