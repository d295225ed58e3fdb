"""Test targets: the ISO 12233 slanted edge as a spectral scene, and synthetic edge
images of known MTF for checking the e-SFR algorithm itself.

The edge is near-vertical, tilted by ``angle_deg`` (5° by default, ISO 12233:2017
recommends a few degrees), bright on the right. Each pixel's value is the exact
fraction of its square covered by the bright side (the projection of a unit square on
the edge normal is a trapezoid distribution), so no rendering blur is added.
"""

from __future__ import annotations

import math

import numpy as np

from metricscenes.geometry import REFERENCE_EXTENT, grid_to_tan, pixels_to_tan, TanExtent
from metricscenes.radiance import RadianceLayer, SpectralScene


def _ramp2(x: np.ndarray) -> np.ndarray:
    return 0.5 * np.maximum(x, 0.0) ** 2


def square_coverage(distance_px: np.ndarray, angle_deg: float) -> np.ndarray:
    """Fraction of a unit pixel on the positive side of a line whose normal makes
    ``angle_deg`` with the x axis, given the signed distance of the pixel centre."""
    w1, w2 = abs(math.cos(math.radians(angle_deg))), abs(math.sin(math.radians(angle_deg)))
    if w2 < 1e-9:
        return np.clip(np.asarray(distance_px) + 0.5, 0.0, 1.0)
    # CDF of U(0, w1) + U(0, w2), evaluated at d + (w1 + w2) / 2
    x = np.asarray(distance_px, dtype=float) + 0.5 * (w1 + w2)
    return (_ramp2(x) - _ramp2(x - w1) - _ramp2(x - w2) + _ramp2(x - w1 - w2)) / (w1 * w2)


def edge_distance_px(shape: tuple[int, int], angle_deg: float) -> np.ndarray:
    """Signed distance (pixels) of every pixel centre from a slanted edge through the
    centre of a (rows, cols) window; positive on the bright (right) side."""
    rows, cols = shape
    y = np.arange(rows) - (rows - 1) / 2.0
    x = np.arange(cols) - (cols - 1) / 2.0
    a = math.radians(angle_deg)
    return x[None, :] * math.cos(a) - y[:, None] * math.sin(a)


def slanted_edge_scene(
    width_px: int,
    height_px: int,
    spectrum: np.ndarray,
    *,
    roi_px: tuple[int, int] = (96, 96),
    angle_deg: float = 5.0,
    low: float = 0.1,
    high: float = 0.9,
    field: TanExtent | None = None,
) -> tuple[SpectralScene, TanExtent]:
    """A slanted-edge target in the centre of a camera's field of view.

    The edge lives in an inset aligned with the camera's pixel grid (``width_px`` ×
    ``height_px`` over ``field``, the camera's own field; default the reference field)
    over the central ``roi_px`` (rows, cols) window; the plate around it is uniform at
    the mean level. Radiance = ``spectrum`` (bands,) × reflectance.

    Returns:
        The scene and the window's extent (resample it at ``roi_px`` for the camera).
    """
    rows, cols = roi_px
    r0, c0 = (height_px - rows) // 2, (width_px - cols) // 2
    px = np.array([[c0, r0], [c0 + cols, r0 + rows]], float)
    if field is None or field == REFERENCE_EXTENT:
        corners = pixels_to_tan(px, width_px, height_px)
    else:
        corners = grid_to_tan(px, field, width_px, height_px)
    extent = TanExtent(corners[0, 0], corners[0, 1], corners[1, 0], corners[1, 1])
    frac = square_coverage(edge_distance_px(roi_px, angle_deg), angle_deg)
    spectrum = np.asarray(spectrum, dtype=np.float32)
    inset = ((low + (high - low) * frac)[..., None] * spectrum).astype(np.float32)
    plate = SpectralScene.uniform(0.5 * (low + high) * spectrum).layers[0]
    scene = SpectralScene(layers=(plate, RadianceLayer(inset, extent)), metadata={"target": "slanted_edge"})
    return scene, extent


def synthetic_edge_image(
    shape: tuple[int, int],
    mtf: callable,
    cutoff_cy_per_px: float,
    *,
    angle_deg: float = 5.0,
    low: float = 0.1,
    high: float = 0.9,
    n_freq: int = 4096,
) -> np.ndarray:
    """A noise-free slanted-edge image whose system MTF is ``mtf(f_cy_per_px)``
    (real, even, zero beyond ``cutoff_cy_per_px``), sampled at pixel centres:

        ESF(d) = 1/2 + (1/π) ∫₀^fc MTF(f) sin(2π f d) / f df.

    ``mtf`` must include the pixel aperture if the image is meant to have one.
    """
    d = edge_distance_px(shape, angle_deg).ravel()
    f = (np.arange(n_freq) + 0.5) * (cutoff_cy_per_px / n_freq)  # midpoint rule
    weights = mtf(f) / f * (cutoff_cy_per_px / n_freq) / math.pi
    esf = np.empty_like(d)
    for s in range(0, d.size, 2048):
        esf[s : s + 2048] = 0.5 + np.sin(2 * math.pi * np.outer(d[s : s + 2048], f)) @ weights
    return (low + (high - low) * esf).reshape(shape)
