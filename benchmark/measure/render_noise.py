"""Render noise as a camera sees it: the Monte Carlo noise of two renders that differ only in
seed, against the camera's own photon shot noise, on noise-free captures of both.

Per pixel, the difference of two independent renders has variance 2 sigma_r^2, so one
render's noise is sigma_r^2 = (e_A - e_B)^2 / 2 (one sample: pooled over pixels), and the
camera's shot noise is sigma_s^2 = e = (e_A + e_B) / 2 (Poisson). The ratio sigma_r / sigma_s
is pooled over the used pixels of a region and over square windows of it. The spp of every
manifest rest on it (render noise under a third of the shot noise: docs/scenes.md, "Samples per
pixel"); the studies that measure it are benchmarks/studies/render_noise.py, frame_sampling.py
and spectral_basis.py.
"""

from __future__ import annotations

import numpy as np

TARGET = 1.0 / 3.0  # render noise below a third of the shot noise
MIN_USED = 0.5  # a window counts when at least this fraction of its pixels is used


def pooled_ratio(e_a: np.ndarray, e_b: np.ndarray, used: np.ndarray, window: int) -> dict:
    """Render noise over shot noise of two noise-free captures ``e_a``, ``e_b`` (electrons)
    of two renders that differ only in seed, over the ``used`` pixels:

    overall: sqrt(sum (e_a - e_b)^2 / 2 / sum (e_a + e_b) / 2);
    windows: the same per ``window`` x ``window`` block (the region cut to whole blocks),
    over the blocks with at least ``MIN_USED`` of their pixels used: median, 90th
    percentile, fraction above :data:`TARGET`; used: the fraction of pixels used.
    """
    a, b = np.asarray(e_a, np.float64), np.asarray(e_b, np.float64)
    u = np.asarray(used, bool) & np.isfinite(a) & np.isfinite(b)
    noise = np.where(u, (a - b) ** 2 / 2, 0.0)
    shot = np.where(u, (a + b) / 2, 0.0)
    total = float(shot.sum())
    out = {"used": float(u.mean()) if u.size else 0.0,
           "overall": float(np.sqrt(noise.sum() / total)) if total > 0 else float("nan")}
    rows, cols = (n // window * window for n in u.shape)

    def blocks(x):
        return x[:rows, :cols].reshape(rows // window, window, cols // window, window).sum(axis=(1, 3))

    count, noise_w, shot_w = blocks(u.astype(np.float64)), blocks(noise), blocks(shot)
    keep = (count >= MIN_USED * window * window) & (shot_w > 0)
    ratios = np.sqrt(noise_w[keep] / shot_w[keep])
    out["windows"] = int(ratios.size)
    if ratios.size:
        out |= {"median": float(np.median(ratios)), "p90": float(np.percentile(ratios, 90)),
                "above": float(np.mean(ratios > TARGET))}
    else:
        out |= {"median": float("nan"), "p90": float("nan"), "above": float("nan")}
    return out


def spp_needed(spp: int, ratio: float) -> float:
    """The spp at which a ratio measured at ``spp`` falls to :data:`TARGET` (noise ~ 1/sqrt(spp))."""
    return spp * (ratio / TARGET) ** 2


def fitted_spp(points: list[tuple[int, float]]) -> tuple[float, float]:
    """From ratios measured at two or more spp, ``(spp, ratio)``: the exponent alpha of
    ratio ~ spp^-alpha (least squares in log-log) and the spp at which the fitted line
    reaches :data:`TARGET` (nan where the ratio does not fall with spp)."""
    x, y = np.log([p[0] for p in points]), np.log([p[1] for p in points])
    slope, intercept = np.polyfit(x, y, 1)
    alpha = -float(slope)
    return alpha, float(np.exp((intercept - np.log(TARGET)) / alpha)) if alpha > 0 else float("nan")


def used_pixels(e_a: np.ndarray, e_b: np.ndarray, saturation_e: float, dark_e: float) -> tuple[np.ndarray, dict]:
    """Pixels below saturation in both captures and at least ``dark_e`` on average; and
    the fractions left out for each reason."""
    saturated = np.maximum(e_a, e_b) >= saturation_e
    dark = (e_a.astype(np.float64) + e_b) / 2 < dark_e
    return ~saturated & ~dark, {"saturated": float(saturated.mean()), "dark": float((dark & ~saturated).mean())}


def capture_pair(scene_a, scene_b, camera):
    """Noise-free captures of both renders: A with the camera's exposure policy, B with
    A's exposure time. Returns (e_A, e_B, exposure s, B's own auto exposure s)."""
    from benchmark.camera import ExposureSpec
    from benchmark.camera.exposure import exposure_time_s, with_exposure
    from benchmark.camera.pipeline import simulate

    if camera.exposure.mode == "hdr":
        raise ValueError(f"{camera.name}: the hdr policy takes two exposures; choose a one-frame policy")
    cap_a = simulate(scene_a, camera, seed=0, noise=False)
    fixed = with_exposure(camera, ExposureSpec(mode="fixed", exposure_s=cap_a.exposure_s))
    cap_b = simulate(scene_b, fixed, seed=0, noise=False)
    own_b = exposure_time_s(cap_b.electrons / np.float32(cap_a.exposure_s), camera.sensor, camera.exposure)
    return cap_a.electrons, cap_b.electrons, cap_a.exposure_s, own_b


def channel_ratios(e_a, e_b, used, cfa: str) -> str:
    """Overall ratio per colour channel of the mosaic, 'R / G / B'."""
    from benchmark.camera.sensor import cfa_index

    channel = cfa_index(*e_a.shape, cfa)
    return " / ".join(f"{pooled_ratio(e_a, e_b, used & (channel == c), 1)['overall']:.3f}" for c in range(3))
