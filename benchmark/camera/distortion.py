"""Radial lens distortion (Brown–Conrady, radial terms k1, k2).

A lens maps the undistorted normalised image point (x, y) = tangent coordinates of the
scene direction (:mod:`metricscenes.geometry`) to the distorted point the sensor sees,

    (x_d, y_d) = (x, y) · (1 + k1·r² + k2·r⁴),   r² = x² + y²

(D. C. Brown, "Decentering distortion of lenses", Photogramm. Eng. 32 (1966) 444–462;
A. E. Conrady, MNRAS 79 (1919) 384–390; the radial part of OpenCV's camera model).
k1 < 0 is barrel distortion (a wide-angle lens's), k1 > 0 pincushion. The sensor's
pixel grid is uniform in distorted coordinates: ``pixel position · pitch / f``.

The camera images a distorted scene by sampling, at every pixel centre, the scene at
the undistorted point that the lens sends there (:func:`undistort`, Newton's method
on the radius, exact to 1e-12): :func:`resample_distorted`. A mapping must be
monotonic over the sensor (a lens never folds the image onto itself):
:func:`check_monotonic` refuses k1, k2 that fold before the sensor's corner.
"""

from __future__ import annotations

import functools

import numpy as np

from metricscenes.geometry import TanExtent, extent_border


def distort(xy: np.ndarray, k1: float, k2: float) -> np.ndarray:
    """Undistorted tangent coordinates (..., 2) → distorted ones (the sensor's)."""
    xy = np.asarray(xy, dtype=float)
    r2 = (xy**2).sum(axis=-1, keepdims=True)
    return xy * (1.0 + k1 * r2 + k2 * r2**2)


def undistort(xy_d: np.ndarray, k1: float, k2: float, iterations: int = 30) -> np.ndarray:
    """Inverse of :func:`distort` on its monotonic range: Newton's method on the radius
    r_d = r·(1 + k1·r² + k2·r⁴), started at r = r_d (quadratic convergence; 30 steps
    is far more than a monotonic mapping needs to reach 1e-12)."""
    xy_d = np.asarray(xy_d, dtype=float)
    rd = np.sqrt((xy_d**2).sum(axis=-1, keepdims=True))
    r = rd.copy()
    for _ in range(iterations):
        r2 = r * r
        step = (r * (1.0 + k1 * r2 + k2 * r2 * r2) - rd) / (1.0 + 3.0 * k1 * r2 + 5.0 * k2 * r2 * r2)
        r = r - step
        if np.all(np.abs(step) <= 1e-15 * np.maximum(r, 1.0)):
            break
    scale = np.divide(r, rd, out=np.ones_like(rd), where=rd > 0)
    return xy_d * scale


def check_monotonic(k1: float, k2: float, corner_radius: float) -> None:
    """Refuse (ValueError, one line) a distortion that folds the image before the
    sensor's corner (``corner_radius``: the corner's distorted radius, tangent units):
    the radial mapping r → r·(1 + k1·r² + k2·r⁴) must keep increasing (slope
    1 + 3·k1·r² + 5·k2·r⁴ > 0) until it has reached the corner."""
    r = np.linspace(0.0, 10.0, 20001)
    r2 = r * r
    folds = np.flatnonzero(1.0 + 3.0 * k1 * r2 + 5.0 * k2 * r2 * r2 <= 0.0)
    if folds.size:
        r_fold = float(r[folds[0]])
        reach = r_fold * (1.0 + k1 * r_fold**2 + k2 * r_fold**4)
        if reach <= corner_radius:
            raise ValueError(f"distortion k1 {k1:g}, k2 {k2:g} folds the image at a distorted radius of {reach:.3g} "
                             f"(tangent units), inside the sensor's corner at {corner_radius:.3g}: "
                             "reduce |k1| or |k2|")


def undistorted_bounds(extent: TanExtent, k1: float, k2: float, points_per_edge: int = 513) -> TanExtent:
    """The smallest box holding what the sensor region ``extent`` (distorted
    coordinates) sees: the bounds of the undistorted image of its border (a monotonic
    radial mapping sends a region's border onto its image's border)."""
    seen = undistort(extent_border(extent, points_per_edge), k1, k2)
    return TanExtent(float(seen[:, 0].min()), float(seen[:, 1].min()), float(seen[:, 0].max()), float(seen[:, 1].max()))


def pixel_centres(extent: TanExtent, cols: int, rows: int) -> np.ndarray:
    """(rows, cols, 2) tangent coordinates of the centres of a grid over ``extent``."""
    x = extent.x0 + (np.arange(cols) + 0.5) * extent.width / cols
    y = extent.y0 + (np.arange(rows) + 0.5) * extent.height / rows
    return np.stack(np.meshgrid(x, y), axis=-1)


def resample_distorted(scene, cols: int, rows: int, sensor_extent: TanExtent, k1: float, k2: float) -> np.ndarray:
    """The scene's radiance (rows, cols, bands) float32 on a sensor grid over
    ``sensor_extent`` (distorted coordinates) through the lens's distortion.

    The scene is first area-averaged (``SpectralScene.resample``) over the undistorted
    window the grid sees (:func:`undistorted_bounds`) at the sensor's pitch on the axis, where
    the mapping's scale is 1; each pixel then takes that image bilinearly at the
    undistorted point of its centre. Off axis a barrel lens's pixel covers more of the
    scene than one axial pitch: there the image is point-sampled at the axial pitch
    (slightly sharper and more aliased than a full area integral would give).
    """
    from scipy.ndimage import map_coordinates

    scene_window, cols_u, rows_u, v, u = _sampling_map(sensor_extent, cols, rows, k1, k2)
    fine = scene.resample(cols_u, rows_u, scene_window)  # (rows_u, cols_u, bands), band planes contiguous
    bands = fine.shape[2]
    out = np.empty((bands, rows, cols), dtype=np.float32)
    for b in range(bands):
        out[b] = map_coordinates(fine[:, :, b], [v, u], order=1, mode="nearest")
    return out.transpose(1, 2, 0)


@functools.lru_cache(maxsize=8)  # a sweep's cameras, scene by scene (≤ 64 MB each at 2688 x 1512)
def _sampling_map(sensor_extent: TanExtent, cols: int, rows: int, k1: float, k2: float):
    """Where :func:`resample_distorted` samples: the undistorted window the grid sees, the
    axial-pitch grid over it (cols_u, rows_u), and the continuous (row, col) index in that
    grid of each pixel centre's undistorted point, read-only. The same for every capture
    of a camera, so cached (the inverse map of a 1600 × 900 sensor takes ~0.25 s)."""
    scene_window = undistorted_bounds(sensor_extent, k1, k2)
    pitch_x, pitch_y = sensor_extent.width / cols, sensor_extent.height / rows
    cols_u = max(2, int(np.ceil(scene_window.width / pitch_x - 1e-9)))
    rows_u = max(2, int(np.ceil(scene_window.height / pitch_y - 1e-9)))
    seen = undistort(pixel_centres(sensor_extent, cols, rows), k1, k2)
    # Continuous index of each undistorted point in the fine grid (index i = centre of pixel i).
    u = (seen[..., 0] - scene_window.x0) / scene_window.width * cols_u - 0.5
    v = (seen[..., 1] - scene_window.y0) / scene_window.height * rows_u - 0.5
    u.setflags(write=False)
    v.setflags(write=False)
    return scene_window, cols_u, rows_u, v, u
