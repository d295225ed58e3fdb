"""Reference camera geometry shared by the scenes and every camera (DESIGN §3).

All cameras have focal length 4.38 mm and an active area of 2.688 x 1.512 mm, so
they see the same field of view; only the sampling (pixel pitch) and the optics
(f-number) differ. Positions on the image plane are expressed as *tangent
coordinates* (x, y) = (tan of the angle right of the optical axis, tan of the angle
below it): a perspective image is uniformly sampled in them, so a pixel grid of any
camera maps onto them by a scale alone.
"""

from __future__ import annotations

from dataclasses import dataclass

import numpy as np

REFERENCE_FOCAL_LENGTH_MM = 4.38
REFERENCE_ACTIVE_WIDTH_MM = 2.688
REFERENCE_ACTIVE_HEIGHT_MM = 1.512
CAMERA_HEIGHT_M = 1.5

TAN_HALF_WIDTH = REFERENCE_ACTIVE_WIDTH_MM / 2 / REFERENCE_FOCAL_LENGTH_MM
TAN_HALF_HEIGHT = REFERENCE_ACTIVE_HEIGHT_MM / 2 / REFERENCE_FOCAL_LENGTH_MM
HORIZONTAL_FOV_DEG = float(np.degrees(2 * np.arctan(TAN_HALF_WIDTH)))
VERTICAL_FOV_DEG = float(np.degrees(2 * np.arctan(TAN_HALF_HEIGHT)))


@dataclass(frozen=True)
class TanExtent:
    """A rectangle on the image plane in tangent coordinates (x right, y down)."""

    x0: float
    y0: float
    x1: float
    y1: float

    @property
    def width(self) -> float:
        return self.x1 - self.x0

    @property
    def height(self) -> float:
        return self.y1 - self.y0

    def as_tuple(self) -> tuple[float, float, float, float]:
        return (self.x0, self.y0, self.x1, self.y1)


REFERENCE_EXTENT = TanExtent(-TAN_HALF_WIDTH, -TAN_HALF_HEIGHT, TAN_HALF_WIDTH, TAN_HALF_HEIGHT)


def world_to_tan(points_m: np.ndarray) -> np.ndarray:
    """Project world points (N, 3) in metres to tangent coordinates (N, 2).

    World frame: x forward along the road, y left, z up; camera at (0, 0, 1.5 m)
    looking along +x, level. Points must be in front of the camera (x > 0).
    """
    p = np.asarray(points_m, dtype=float)
    depth = p[:, 0]
    return np.stack([-p[:, 1] / depth, -(p[:, 2] - CAMERA_HEIGHT_M) / depth], axis=1)


def tan_to_pixels(tan_xy: np.ndarray, width_px: int, height_px: int) -> np.ndarray:
    """Map tangent coordinates to continuous pixel coordinates of a grid covering the
    reference field of view (pixel (0, 0)'s top-left corner is 0.0)."""
    t = np.asarray(tan_xy, dtype=float)
    e = REFERENCE_EXTENT
    return np.stack(
        [(t[..., 0] - e.x0) / e.width * width_px, (t[..., 1] - e.y0) / e.height * height_px], axis=-1
    )


def pixels_to_tan(px_xy: np.ndarray, width_px: int, height_px: int) -> np.ndarray:
    """Inverse of :func:`tan_to_pixels`."""
    p = np.asarray(px_xy, dtype=float)
    e = REFERENCE_EXTENT
    return np.stack(
        [e.x0 + p[..., 0] / width_px * e.width, e.y0 + p[..., 1] / height_px * e.height], axis=-1
    )
