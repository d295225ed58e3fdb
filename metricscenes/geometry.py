"""Reference camera geometry shared by the scenes and every camera (DESIGN §3).

The collections are rendered over the reference field: focal length 4.38 mm over an
active area of 2.688 x 1.512 mm (the paper's 13 cameras, which all see that field and
differ only in sampling and f-number). Positions on the image plane are expressed as
*tangent coordinates* (x, y) = (tan of the angle right of the optical axis, tan of the
angle below it): a perspective image is uniformly sampled in them, so a pixel grid of
any camera maps onto them by a scale and an offset. A camera with another focal length
or active area samples its own window of the collection's field, centred on the
optical axis (:func:`centred_extent`, ``benchmark.camera.pipeline.camera_window``).
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
    return tan_to_grid(tan_xy, REFERENCE_EXTENT, width_px, height_px)


def pixels_to_tan(px_xy: np.ndarray, width_px: int, height_px: int) -> np.ndarray:
    """Inverse of :func:`tan_to_pixels`."""
    return grid_to_tan(px_xy, REFERENCE_EXTENT, width_px, height_px)


def field_extent(hfov_deg: float | None, width_px: int, height_px: int) -> TanExtent:
    """A collection's field: ``hfov_deg`` horizontally, centred on the optical axis, with
    the grid's aspect (square pixels in tangent coordinates, as a perspective film has);
    ``None`` is the reference field (:data:`REFERENCE_EXTENT` itself)."""
    if hfov_deg is None:
        return REFERENCE_EXTENT
    half_w = float(np.tan(np.radians(hfov_deg) / 2))
    half_h = half_w * height_px / width_px
    return TanExtent(-half_w, -half_h, half_w, half_h)


def horizontal_fov_deg(field: TanExtent) -> float:
    """A centred field's horizontal field of view, degrees, written as the reference's
    is (:data:`HORIZONTAL_FOV_DEG`), so the reference field gives that very float."""
    return float(np.degrees(2 * np.arctan(field.x1)))


def fov_deg(extent: TanExtent) -> tuple[float, float]:
    """(horizontal, vertical) field of view of ``extent``, degrees."""
    return (float(np.degrees(np.arctan(extent.x1) - np.arctan(extent.x0))),
            float(np.degrees(np.arctan(extent.y1) - np.arctan(extent.y0))))


def centred_extent(tan_half_width: float, tan_half_height: float, field: TanExtent,
                   rtol: float = 1e-6) -> TanExtent:
    """The window ±``tan_half_width`` × ±``tan_half_height`` around the optical axis, each
    edge snapped onto ``field``'s where it is within ``rtol`` of the field's size (a
    camera of the reference geometry gets exactly ``field``: same object, same floats).
    Not checked against ``field``: see :func:`extent_within`."""
    def snap(value: float, edge: float, size: float) -> float:
        return edge if abs(value - edge) <= rtol * size else value

    window = TanExtent(snap(-tan_half_width, field.x0, field.width), snap(-tan_half_height, field.y0, field.height),
                       snap(tan_half_width, field.x1, field.width), snap(tan_half_height, field.y1, field.height))
    return field if window == field else window


def extent_within(window: TanExtent, field: TanExtent) -> bool:
    """True if ``window`` lies inside ``field`` (edges may coincide)."""
    return field.x0 <= window.x0 and window.x1 <= field.x1 and field.y0 <= window.y0 and window.y1 <= field.y1


def tan_to_grid(tan_xy: np.ndarray, extent: TanExtent, width_px: int, height_px: int) -> np.ndarray:
    """Tangent coordinates → continuous pixel coordinates of a ``width_px`` × ``height_px``
    grid covering ``extent`` (pixel (0, 0)'s top-left corner is 0.0)."""
    t = np.asarray(tan_xy, dtype=float)
    return np.stack([(t[..., 0] - extent.x0) / extent.width * width_px,
                     (t[..., 1] - extent.y0) / extent.height * height_px], axis=-1)


def grid_to_tan(px_xy: np.ndarray, extent: TanExtent, width_px: int, height_px: int) -> np.ndarray:
    """Inverse of :func:`tan_to_grid`."""
    p = np.asarray(px_xy, dtype=float)
    return np.stack([extent.x0 + p[..., 0] / width_px * extent.width,
                     extent.y0 + p[..., 1] / height_px * extent.height], axis=-1)


def extent_border(extent: TanExtent, points_per_edge: int = 513) -> np.ndarray:
    """(4·points_per_edge, 2) tangent coordinates along the border of ``extent`` (what a
    monotonic radial lens mapping needs to bound the image of the whole rectangle)."""
    s = np.linspace(0.0, 1.0, points_per_edge)
    xs, ys = extent.x0 + s * extent.width, extent.y0 + s * extent.height
    return np.concatenate([np.stack([xs, np.full_like(s, extent.y0)], axis=1),
                           np.stack([xs, np.full_like(s, extent.y1)], axis=1),
                           np.stack([np.full_like(s, extent.x0), ys], axis=1),
                           np.stack([np.full_like(s, extent.x1), ys], axis=1)])
