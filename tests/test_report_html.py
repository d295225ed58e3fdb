"""benchmark.experiments.report: self-contained HTML from a sweep folder and from a single run folder."""

from __future__ import annotations

import base64
import html
import io
import json
import re

import numpy as np
import pandas as pd
import pytest
from PIL import Image

from benchmark.experiments import report as report_module
from benchmark.leaderboard.protocols import condition_label as L  # tables and figures name a condition by what it is
from benchmark.scoring import MIN_ENVIRONMENTS
from benchmark.scoring.bootstrap import BOOTSTRAP_RESAMPLES
from test_sweep_cache import make_fake_sweep  # the fake runs (tests/ is on sys.path)

DATA_PNG = re.compile(r"src='data:image/png;base64,([A-Za-z0-9+/=]+)'")


@pytest.fixture(scope="module")
def sweep_dir(tmp_path_factory):
    monkeypatch = pytest.MonkeyPatch()
    out = tmp_path_factory.mktemp("report") / "sweep"
    try:
        make_fake_sweep(out, monkeypatch, cameras=("cam01", "cam05"), conditions=("day", "night", "day@1lux", "day@100lux"),
                        save_images=True, n_resamples=30)
    finally:
        monkeypatch.undo()
    return out


@pytest.fixture(scope="module")
def page(sweep_dir) -> str:
    return report_module.report(sweep_dir).read_text(encoding="utf-8")


def _html_table(fragment: str) -> pd.DataFrame:
    """The first HTML table of ``fragment`` (pandas.read_html would need lxml)."""
    body = fragment.split("<table", 1)[1].split("</table>", 1)[0]
    rows = [[html.unescape(c.strip()) for c in re.findall(r"<t[hd][^>]*>(.*?)</t[hd]>", r, re.S)]
            for r in re.findall(r"<tr[^>]*>(.*?)</tr>", body, re.S)]
    return pd.DataFrame(rows[1:], columns=rows[0])


def _pngs(page: str) -> list[Image.Image]:
    return [Image.open(io.BytesIO(base64.b64decode(b))) for b in DATA_PNG.findall(page)]


def test_sweep_report_is_self_contained(sweep_dir, page):
    assert (sweep_dir / "report.html").read_text(encoding="utf-8") == page
    assert "http://" not in page and "https://" not in page  # nothing loaded from elsewhere
    assert all(src.startswith("data:image/png;base64,") for src in re.findall(r"src='([^']*)'", page))
    assert '<link' not in page and "<script" not in page
    images = _pngs(page)
    figures = ["ap_vs_distance", "spm_mtf50", "od50_vs_mtf50", "spm_illuminance_cam01", "spm_illuminance_cam05"]
    thumbs = 2 * 2 * 6  # cameras × (day, night) × distances, first environment; none for the lux sweep
    assert len(images) == len(figures) + thumbs
    for name in figures:
        assert (sweep_dir / "figures" / f"{name}.png").is_file() and (sweep_dir / "figures" / f"{name}.svg").is_file()
    assert [h for h in re.findall(r"<h3>([^<]+)</h3>", page)][:2] == [f"25 m · {L('day')}", f"25 m · {L('night')}"]


def test_sweep_report_table_matches_od50_csv(sweep_dir, page):
    assert "<table" in page and "OD50 ± SD (m)" in page and "AP 200 m" in page
    od50 = pd.read_csv(sweep_dir / "od50.csv")
    assert len(od50) == 8
    table = _html_table(page.split("<h2>Results</h2>", 1)[1])
    assert len(table) == 8 and list(table.columns[:8]) == ["camera", "condition", "MTF50 (cy/mm)", "MTF50 (cy/mrad)",
                                                           "focal length (mm)", "FOV (°)", "OD50 ± SD (m)", "95 % interval (m)"]
    assert (od50.n_environments == 4).all() and MIN_ENVIRONMENTS > 4  # too few: every figure is marked
    for _, row in od50.iterrows():
        shown = table[(table.camera == row.camera) & (table.condition == L(row.condition))].iloc[0]
        assert shown["OD50 ± SD (m)"] == f"{row.od50_m:.1f} ± {row.sd_m:.1f}†" or not np.isfinite(row.od50_m)
        assert shown["AP range ± SD (m)"] == f"{row.ap_range_m:.1f} ± {row.ap_range_sd_m:.1f}†"
        assert shown["AP range 95 % (m)"] == f"[{row.ap_range_ci95_lo_m:.1f}, {row.ap_range_ci95_hi_m:.1f}]"
    results = page.split("<h2>Results</h2>", 1)[1]
    assert results.startswith("<p class='verdict'>sample too small: 4 environments per distance, at least "
                              f"{MIN_ENVIRONMENTS} needed for a verdict (docs/scoring.md)")
    assert f"† from fewer than {MIN_ENVIRONMENTS} environments per distance" in results
    ap = pd.read_csv(sweep_dir / "sweep.csv").query("camera == 'cam05' and condition == 'night' and distance_m == 50")
    shown = table.query("camera == 'cam05' and condition == @L('night')").iloc[0]["AP 50 m"]
    assert float(shown) == pytest.approx(ap.ap.iloc[0], abs=5e-4)


def test_thumbnails_carry_green_truth_and_red_detection(page):
    thumb = _pngs(page)[-1]  # a strip image
    assert thumb.width == report_module.THUMB_WIDTH_PX
    rgb = np.asarray(thumb.convert("RGB")).astype(int)
    green = (rgb[..., 1] > 150) & (rgb[..., 0] < 60) & (rgb[..., 2] < 60)
    assert green.sum() > 20
    assert re.search(r"cam0[15] · AP [0-9.]+ · (best car [0-9.]+|best car &lt; 0.01|no car detection)", page)


def test_crop_with_boxes_draws_at_the_right_place(tmp_path):
    img = Image.new("RGB", (640, 360), (50, 50, 50))
    img.save(tmp_path / "im.png")
    gt = [300.0, 170.0, 16.0, 8.0]  # tiny car (4 widths < 12 %): the crop is 12 % of the frame, centred on it
    thumb = report_module.crop_with_boxes(tmp_path / "im.png", gt, {"bbox": [302.0, 171.0, 20.0, 10.0], "score": 0.8},
                                          width_px=320)
    rgb = np.asarray(thumb).astype(int)
    scale = 320 / (0.12 * 640)
    x0 = 308 - 0.06 * 640  # crop's left edge in image pixels
    col = int(round((300 - x0) * scale))
    ys, xs = np.nonzero((rgb[..., 1] == 200) & (rgb[..., 0] == 0))
    assert abs(xs.min() - col) <= 1 and abs(ys.min() - round((170 - (174 - 0.06 * 360)) * scale)) <= 1
    assert thumb.size == (320, round(0.12 * 360 * scale))
    assert ((rgb[..., 0] == 230) & (rgb[..., 1] == 0)).any()


def test_single_run_report(sweep_dir):
    run = sweep_dir / "runs" / "cam01-day"
    page = report_module.report(run).read_text(encoding="utf-8")
    assert "http://" not in page and "https://" not in page
    assert "System Performance Maps" not in page and "OD50 vs MTF50" not in page  # one camera: curves only
    assert len(_pngs(page)) == 1 + 6  # the curves + one thumbnail per distance
    assert (run / "figures" / "ap_vs_distance.svg").is_file()
    assert "cam01" in page and "<table" in page and "AP 200 m" in page


def test_report_to_another_place_and_errors(sweep_dir, tmp_path):
    out = report_module.report(sweep_dir / "runs" / "cam05-night", tmp_path / "elsewhere" / "page.html")
    assert out.is_file() and (tmp_path / "elsewhere" / "figures" / "ap_vs_distance.png").is_file()
    with pytest.raises(ValueError, match="neither a sweep folder"):
        report_module.report(tmp_path)


def test_load_results_of_a_run_folder(sweep_dir):
    table, od50, runs, meta = report_module.load_results(sweep_dir / "runs" / "cam05-night")
    assert len(table) == 6 and set(table.condition) == {"night"}
    assert list(runs) == [("cam05", "night")]
    assert json.loads((sweep_dir / "runs" / "cam05-night" / "od50.json").read_text())["key"]["n_resamples"] == BOOTSTRAP_RESAMPLES  # one default everywhere
    assert meta["n_resamples"] == BOOTSTRAP_RESAMPLES  # printed with the result (the page's facts)


def test_miss_rate_and_false_positives_per_distance(sweep_dir, page):
    """Runs written before results.json held them: computed from their detections."""
    from benchmark.scoring import working_point

    section = page.split("<h2>Miss rate and false positives</h2>", 1)[1]
    table = _html_table(section)
    run = sweep_dir / "runs" / "cam01-day"
    expected = working_point(json.loads((run / "groundtruth.json").read_text()), json.loads((run / "detections.json").read_text()))
    shown = table.query("camera == 'cam01' and condition == @L('day')").iloc[0]  # named by what it is
    assert shown["25 m"] == f"{expected[25.0]['miss_rate']:.2f} / {expected[25.0]['false_positives_per_image']:.2f}"
    assert list(table.columns) == ["camera", "condition", "25 m", "50 m", "75 m", "100 m", "150 m", "200 m"]


def test_no_line_is_fitted_through_too_few_environments():
    from benchmark.experiments import spm
    from benchmark.scoring import MIN_ENVIRONMENTS

    def fitted_lines(n_environments):
        table = pd.DataFrame({"camera": ["a", "b", "c"], "condition": ["day"] * 3, "mtf50_cy_per_mm": [80.0, 120.0, 160.0],
                              "od50_m": [90.0, 120.0, 150.0], "sd_m": [5.0] * 3, "n_environments": [n_environments] * 3})
        fig = spm.od50_vs_mtf50(table)
        lines = [ln for ln in fig.axes[0].get_lines() if ln.get_linestyle() == "-" and len(ln.get_xdata()) == 2]
        legend = [t.get_text() for t in fig.axes[0].get_legend().get_texts()]
        return len(lines), legend

    assert fitted_lines(MIN_ENVIRONMENTS)[0] == 1
    n, legend = fitted_lines(MIN_ENVIRONMENTS - 1)
    assert n == 0 and legend == [f"{L('day')}: no fit (3 from too few environments: not fitted)"]
