"""MTF10/30/50 read off a curve, and the MTF plot: Nyquist markers and a cycles/pixel axis."""

from __future__ import annotations

import json

import numpy as np
import pytest
from typer.testing import CliRunner

from benchmark.measure.mtf import mtf50, mtf_crossing, mtf_figure, mtf_readings


def _gauss_curve(pixel_um: float, sigma_cy_per_px: float = 0.3):
    per_px = np.linspace(0.0, 1.0, 201)
    return per_px / (pixel_um * 1e-3), np.exp(-0.5 * (per_px / sigma_cy_per_px) ** 2)


def test_crossings_match_the_closed_form():
    sigma = 0.3
    freq, mtf = _gauss_curve(2.0, sigma)
    read = mtf_readings(freq, mtf, 2.0)
    for level in (0.5, 0.3, 0.1):
        exact = sigma * np.sqrt(-2.0 * np.log(level))  # cycles/pixel
        assert read[f"mtf{round(level * 100)}_cy_per_px"] == pytest.approx(exact, rel=2e-3)
        assert read[f"mtf{round(level * 100)}_cy_per_mm"] == pytest.approx(exact / 2e-3, rel=2e-3)
    assert read["nyquist_cy_per_mm"] == 250.0
    assert mtf_crossing(freq, mtf, 0.5) == mtf50(freq, mtf)
    assert np.isnan(mtf_crossing(freq, mtf, 0.001))  # never reached within the band
    assert np.isnan(mtf_crossing(freq, np.full_like(mtf, 0.05), 0.1))  # starts below


def _lines_at_x(ax, x):
    return [line for line in ax.get_lines() if np.allclose(line.get_xdata(), x) and len(line.get_xdata()) == 2]


def test_figure_one_pitch_has_a_cycles_per_pixel_axis_on_top():
    import matplotlib.pyplot as plt

    fig = mtf_figure([{"name": "mine", "pixel_um": 2.0, "freq_cy_per_mm": _gauss_curve(2.0)[0], "mtf": _gauss_curve(2.0)[1]}])
    try:
        ax = fig.axes[0]
        assert ax.get_xlabel() == "cycles/mm on the sensor"
        assert _lines_at_x(ax, 250.0)  # Nyquist of a 2 µm pixel
        texts = {t.get_text() for t in ax.texts}
        assert {"MTF50", "MTF30", "MTF10"} <= texts
        tops = [a for a in ax.child_axes if "cycles/pixel" in a.get_xlabel()]
        assert len(tops) == 1
        forward = getattr(tops[0], "_functions", (None,))[0]  # the secondary axis: 250 c/mm ↔ 0.5 cy/px
        assert forward is None or forward(250.0) == pytest.approx(0.5)
    finally:
        plt.close(fig)


def test_figure_mixed_pitches_has_a_cycles_per_pixel_panel():
    import matplotlib.pyplot as plt

    curves = [{"name": n, "pixel_um": p, "freq_cy_per_mm": _gauss_curve(p)[0], "mtf": _gauss_curve(p)[1]}
              for n, p in (("a", 1.0), ("b", 4.0))]
    fig = mtf_figure(curves)
    try:
        top, bottom = fig.axes[:2]
        assert _lines_at_x(top, 500.0) and _lines_at_x(top, 125.0)  # each camera's Nyquist
        assert len(_lines_at_x(bottom, 0.5)) == 2 and "cycles/pixel" in bottom.get_xlabel()
    finally:
        plt.close(fig)


def test_cameras_mtf_prints_and_returns_the_readings(tmp_path, monkeypatch):
    import benchmark.measure.mtf
    from benchmark.cli.cameras import app

    def fake_measure(camera, esfr="iso"):
        freq, mtf = _gauss_curve(camera.pixel_um)
        return {"freq_cy_per_mm": freq, "mtf": mtf, "mtf50_cy_per_mm": mtf50(freq, mtf),
                "mtf50_cy_per_px": mtf50(freq, mtf) * camera.pixel_um * 1e-3}

    monkeypatch.setattr(benchmark.measure.mtf, "measure_mtf50", fake_measure)
    res = CliRunner().invoke(app, ["mtf", "cam13", "--json", "--plot", str(tmp_path / "mtf.png")])
    assert res.exit_code == 0, res.output
    (row,) = json.loads(res.stdout)
    assert row["mtf10_cy_per_px"] == pytest.approx(0.3 * np.sqrt(-2 * np.log(0.1)), rel=2e-3)
    assert row["mtf30_cy_per_mm"] == pytest.approx(row["mtf30_cy_per_px"] / 1e-3, rel=1e-3)
    assert (tmp_path / "mtf.png").stat().st_size > 1000
    res = CliRunner().invoke(app, ["mtf", "cam13"])
    assert res.exit_code == 0 and "MTF30" in res.output and "MTF10" in res.output
    assert "cam13 in cycles/pixel (Nyquist 0.5): MTF50 0.353, MTF30 0.466, MTF10 0.644" in res.output
