"""benchmark.experiments.spm on synthetic tables: files written, the surface passes through the
measured points and is linear between them, OD50-vs-MTF50 slope."""

from __future__ import annotations

import matplotlib.pyplot as plt
import numpy as np
import pandas as pd
import pytest

from benchmark.experiments import spm
from benchmark.leaderboard.protocols import condition_label as L  # figures name a condition by what it is

DISTANCES = (25.0, 50.0, 75.0, 100.0, 150.0, 200.0)


def synthetic_sweep(mtf50s=(55.0, 75.0, 100.0, 150.0)) -> pd.DataFrame:
    """AP falls with distance, faster for low MTF50 and at night (a logistic in d / range)."""
    rows = []
    for k, m in enumerate(mtf50s):
        for condition, scale in (("day", 1.0), ("night", 0.4)):
            od = 0.9 * m * scale + 20
            for d in DISTANCES:
                rows.append({"camera": f"cam{k + 1:02d}", "mtf50_cy_per_mm": m, "condition": condition, "distance_m": d,
                             "ap": 0.95 / (1 + np.exp((d - od) / 20))})
    return pd.DataFrame(rows)


def test_interpolation_passes_through_points_and_is_linear():
    table = synthetic_sweep()
    day = table[table.condition == "day"]
    gx, gy, gz = spm.interpolate_map(day.distance_m, day.mtf50_cy_per_mm, day.ap, n=37)
    assert gz.shape == (gy.size, gx.size)
    for _, r in day.iterrows():
        j, i = np.searchsorted(gx, r.distance_m), np.searchsorted(gy, r.mtf50_cy_per_mm)
        assert gx[j] == r.distance_m and gy[i] == r.mtf50_cy_per_mm
        assert gz[i, j] == pytest.approx(r.ap, abs=1e-12)
    # a plane is reproduced exactly everywhere inside the hull (linear interpolation)
    plane = 0.3 + 0.002 * day.distance_m - 0.001 * day.mtf50_cy_per_mm
    gx, gy, gz = spm.interpolate_map(day.distance_m, day.mtf50_cy_per_mm, plane, n=21)
    mx, my = np.meshgrid(gx, gy)
    np.testing.assert_allclose(gz, 0.3 + 0.002 * mx - 0.001 * my, atol=1e-12)


def test_interpolation_averages_repeats_and_rejects_degenerate_input():
    x, y = [1.0, 1.0, 2.0, 2.0, 1.0], [0.0, 1.0, 0.0, 1.0, 0.0]
    gx, gy, gz = spm.interpolate_map(x, y, [0.2, 0.5, 0.5, 0.5, 0.4], n=2)
    assert gz[0, 0] == pytest.approx(0.3)
    with pytest.raises(ValueError, match="two or more distinct"):
        spm.interpolate_map([1, 1, 1], [0, 1, 2], [0.1, 0.2, 0.3])
    with pytest.raises(ValueError, match="log_x"):
        spm.interpolate_map([0, 1, 2], [0, 1, 2], [0.1, 0.2, 0.3], log_x=True)


def test_spm_mtf50_writes_png_and_svg(tmp_path):
    fig = spm.spm_mtf50(synthetic_sweep(), tmp_path / "spm_mtf50", mark_mtf50=100)
    assert len(fig.axes) == 3  # day, night, colourbar
    assert [a.get_title() for a in fig.axes[:2]] == [L("day"), L("night")]
    png, svg = tmp_path / "spm_mtf50.png", tmp_path / "spm_mtf50.svg"
    assert png.read_bytes()[:8] == b"\x89PNG\r\n\x1a\n" and png.stat().st_size > 10_000
    text = svg.read_text()
    assert text.lstrip().startswith("<?xml") and "<svg" in text and 'href="http' not in text
    guide = [l for l in fig.axes[0].get_lines() if l.get_linestyle() == "--"]
    assert guide, "the OD50 guide at MTF50 100 is drawn"
    # MTF50 100 is a measured row: the guide ends at that camera's OD50 (linear between distances)
    from benchmark.scoring import od50

    row = synthetic_sweep().query("condition == 'day' and mtf50_cy_per_mm == 100")
    assert guide[0].get_xdata()[1] == pytest.approx(od50(row.distance_m, row.ap))
    plt.close(fig)
    with pytest.raises(ValueError, match="condition 'dusk'"):
        spm.spm_mtf50(synthetic_sweep(), conditions=["dusk"])
    with pytest.raises(ValueError, match="lacks column"):
        spm.spm_mtf50(synthetic_sweep().drop(columns="ap"))


def test_spm_illuminance_on_synthetic_sweep(tmp_path):
    lux = [0.25, 1.0, 5.0, 10.0, 50.0, 500.0]
    rows = [{"camera": "cam12", "illuminance_lux": e, "distance_m": d,
             "ap": min(0.9, 0.2 * np.log10(e * 10)) * np.exp(-d / 300)} for e in lux for d in DISTANCES]
    table = pd.DataFrame(rows)
    fig = spm.spm_illuminance(table, tmp_path / "spm_lux")
    ax = fig.axes[0]
    assert ax.get_yscale() == "log" and ax.get_xlabel() == "distance (m)"
    assert (tmp_path / "spm_lux.png").is_file() and (tmp_path / "spm_lux.svg").is_file()
    gy, gx, gz = spm.interpolate_map(table.illuminance_lux, table.distance_m, table.ap, log_x=True)
    for r in rows:  # exact at the measured points, the illuminance axis in log space
        i = np.argmin(abs(np.log10(gy) - np.log10(r["illuminance_lux"])))
        j = np.searchsorted(gx, r["distance_m"])
        assert gz[j, i] == pytest.approx(r["ap"], abs=1e-12)
    plt.close(fig)
    with pytest.raises(ValueError, match="one camera"):
        spm.spm_illuminance(pd.concat([table, table.assign(camera="cam01")]))


def test_od50_vs_mtf50_slope_in_legend(tmp_path):
    mtf = np.array([55.0, 75.0, 100.0, 150.0])
    od = pd.DataFrame({"camera": [f"c{i}" for i in range(4)] * 2, "condition": ["day"] * 4 + ["night"] * 4,
                       "mtf50_cy_per_mm": np.r_[mtf, mtf], "od50_m": np.r_[0.8 * mtf + 10, 0.3 * mtf + 5],
                       "sd_m": [3.0] * 8})
    od.loc[7, "od50_m"] = np.inf  # never falls to 0.5: left out of the fit
    fig = spm.od50_vs_mtf50(od, tmp_path / "od50")
    labels = [t.get_text() for t in fig.axes[0].get_legend().get_texts()]
    assert labels == [f"{L('day')}: slope 0.80 m per cy/mm", f"{L('night')}: slope 0.30 m per cy/mm"]
    assert (tmp_path / "od50.png").is_file() and (tmp_path / "od50.svg").is_file()
    # an OD50 outside the measured distances is an extrapolation: drawn, not fitted
    od.loc[3, "od50_m"] = 5000.0
    od.loc[4, "od50_m"] = 0.0
    plt.close(fig)
    fig = spm.od50_vs_mtf50(od, tmp_path / "od50", measured_range_m=(25.0, 200.0))
    labels = [t.get_text() for t in fig.axes[0].get_legend().get_texts()]
    assert labels == [f"{L('day')}: slope 0.80 m per cy/mm (1 extrapolated: hollow, not fitted)",
                      f"{L('night')}: slope 0.30 m per cy/mm (1 extrapolated: hollow, not fitted)"]
    assert fig.axes[0].get_ylim()[1] < 5000.0  # the extrapolation does not squash the axes
    assert spm.fit_line([1, 2, 3], [2, 4, 6]) == pytest.approx((2.0, 0.0))
    assert np.isnan(spm.fit_line([1, 1], [2, 3])[0])
    plt.close(fig)
