"""Quick-look sRGB renderings of spectral radiance (for people, not for cameras).

Radiance → CIE 1931 XYZ (2° observer, 683 lm/W) → linear sRGB, scaled so that a
chosen percentile of luminance maps to 0.8 (of one image, or pooled over a whole contact
sheet so that every tile of a condition shares one exposure), → sRGB transfer curve → 8 bit. This is a
display rendering only; cameras model their own sensor and ISP (``benchmark``).
"""

from __future__ import annotations

from pathlib import Path

import numpy as np

from metricscenes.photometry import radiance_to_xyz

def radiance_to_srgb8(radiance: np.ndarray, percentile: float = 99.0, white: float | None = None) -> np.ndarray:
    """Display rendering: (rows, cols, 31) radiance → (rows, cols, 3) uint8 sRGB.

    ``white``: the luminance (cd/m²) drawn at 0.8 of full scale; by default the
    ``percentile`` of the image's own luminance (auto exposure).
    """
    xyz = radiance_to_xyz(radiance)
    return xyz_to_srgb8(xyz, white if white is not None else white_luminance([xyz], percentile))


def white_luminance(xyz_tiles: list[np.ndarray], percentile: float = 99.0) -> float:
    """The ``percentile`` of luminance Y (cd/m²) pooled over every pixel of ``xyz_tiles``:
    one exposure for a whole contact sheet, so a dark condition looks dark."""
    pooled = np.concatenate([np.ravel(xyz[..., 1]) for xyz in xyz_tiles])
    return float(np.percentile(pooled, percentile)) or 1.0


def xyz_to_srgb8(xyz: np.ndarray, white: float) -> np.ndarray:
    """(rows, cols, 3) CIE XYZ (Y in cd/m²) → uint8 sRGB with luminance ``white`` at 0.8 of full scale."""
    import colour

    rgb = colour.XYZ_to_RGB(xyz * (0.8 / white), colour.RGB_COLOURSPACES["sRGB"], apply_cctf_encoding=False)
    encoded = colour.cctf_encoding(np.clip(rgb, 0.0, 1.0), function="sRGB")
    return np.round(encoded * 255).astype(np.uint8)


def contact_sheet(tiles: list[np.ndarray], labels: list[str], columns: int, path: Path, tile_width: int = 320) -> Path:
    """Lay out uint8 RGB tiles in a grid with a caption under each; write a PNG."""
    from PIL import Image, ImageDraw

    thumbs = []
    for tile in tiles:
        im = Image.fromarray(tile)
        h = max(1, round(im.height * tile_width / im.width))
        thumbs.append(im.resize((tile_width, h), Image.Resampling.LANCZOS))
    tile_h = max(t.height for t in thumbs) + 16
    rows = -(-len(thumbs) // columns)
    sheet = Image.new("RGB", (columns * tile_width, rows * tile_h), (24, 24, 24))
    draw = ImageDraw.Draw(sheet)
    for i, (thumb, label) in enumerate(zip(thumbs, labels, strict=True)):
        x, y = (i % columns) * tile_width, (i // columns) * tile_h
        sheet.paste(thumb, (x, y))
        draw.text((x + 4, y + thumb.height + 2), label, fill=(230, 230, 230))
    path = Path(path)
    path.parent.mkdir(parents=True, exist_ok=True)
    sheet.save(path)
    return path
