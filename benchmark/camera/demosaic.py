"""Malvar–He–Cutler demosaicking in float32, one Bayer phase at a time.

H. S. Malvar, L. He and R. Cutler, "High-quality linear interpolation for demosaicing
of Bayer-patterned color images", ICASSP 2004: bilinear interpolation corrected by the
Laplacian of the channel known at the pixel, as four 5×5 kernels (×1/8):

    G at R or B     [ 0  0 -1  0  0;  0  0  2  0  0; -1  2  4  2 -1; ... ]
    R|B at G, same-row neighbours (K1)
                    [ 0  0 ½  0  0;  0 -1  0 -1  0; -1  4  5  4 -1; ... ]
    R|B at G, same-column neighbours (K2 = K1ᵀ)
    R at B, B at R  [ 0  0 -3⁄2 0 0;  0  2  0  2  0; -3⁄2 0  6  0 -3⁄2; ... ]

The same kernels and the same border handling (symmetric reflection, ``scipy.ndimage``'s
``reflect``) as colour-demosaicing's ``demosaicing_CFA_Bayer_Malvar2004``, but each
kernel is evaluated only on the pixels that need it, from shared neighbour sums of
float32 planes, instead of four full-frame float64 convolutions: the same result up to
float32 rounding (``tests/test_camera_speed_paths.py``), several times faster.
"""

from __future__ import annotations

import numpy as np

from benchmark.camera.sensor import bayer_sites

_PAD = 2  # the kernels' radius


def _phase_sums(padded: np.ndarray, dy: int, dx: int, h: int, w: int):
    """Neighbour sums on the sub-grid of pixels (dy + 2i, dx + 2j) of the unpadded image."""

    def at(oy: int, ox: int) -> np.ndarray:
        y, x = _PAD + dy + oy, _PAD + dx + ox
        return padded[y : y + 2 * h - 1 : 2, x : x + 2 * w - 1 : 2]

    centre = at(0, 0)
    vert1 = at(-1, 0) + at(1, 0)
    horiz1 = at(0, -1) + at(0, 1)
    vert2 = at(-2, 0) + at(2, 0)
    horiz2 = at(0, -2) + at(0, 2)
    diag = at(-1, -1) + at(-1, 1)
    diag += at(1, -1)
    diag += at(1, 1)
    return centre, vert1, horiz1, vert2, horiz2, diag


def malvar2004(mosaic: np.ndarray, cfa: str = "RGGB") -> np.ndarray:
    """Demosaic a (rows, cols) Bayer mosaic to (rows, cols, 3) float32 RGB.

    Args:
        mosaic: the raw mosaic (any real dtype; computed in float32).
        cfa: the 2×2 pattern, row by row: ``RGGB``, ``BGGR``, ``GRBG`` or ``GBRG``.
    """
    if cfa not in ("RGGB", "BGGR", "GRBG", "GBRG"):
        raise ValueError(f"sensor.cfa: unsupported Bayer pattern {cfa!r} (RGGB, BGGR, GRBG, GBRG)")
    mosaic = np.asarray(mosaic, dtype=np.float32)
    if mosaic.ndim != 2:
        raise ValueError(f"mosaic: expected a 2-D Bayer mosaic, got shape {mosaic.shape}")
    rows, cols = mosaic.shape
    padded = np.pad(mosaic, _PAD, mode="symmetric")
    out = np.empty((rows, cols, 3), dtype=np.float32)
    f = np.float32
    for dy, dx, channel in bayer_sites(cfa):
        h, w = len(range(dy, rows, 2)), len(range(dx, cols, 2))
        if h == 0 or w == 0:
            continue
        c, v1, h1, v2, h2, diag = _phase_sums(padded, dy, dx, h, w)
        site = out[dy::2, dx::2]
        colour = "RGB"[channel]
        if colour == "G":
            # K1: the colour whose pixels are this row's neighbours; K2: the column's.
            k1 = f(5) * c + f(4) * h1 - h2 - diag + f(0.5) * v2
            k2 = f(5) * c + f(4) * v1 - v2 - diag + f(0.5) * h2
            k1 *= f(0.125)
            k2 *= f(0.125)
            row_colour = "R" if "R" in cfa[2 * dy : 2 * dy + 2] else "B"
            site[..., 1] = c
            site[..., 0] = k1 if row_colour == "R" else k2
            site[..., 2] = k2 if row_colour == "R" else k1
        else:
            g = f(4) * c + f(2) * (v1 + h1) - (v2 + h2)
            g *= f(0.125)
            other = f(6) * c + f(2) * diag - f(1.5) * (v2 + h2)
            other *= f(0.125)
            site[..., 1] = g
            site[..., channel] = c
            site[..., 2 if colour == "R" else 0] = other
    return out
