"""Contact sheets of the procedural asset library: every car and every sky, rendered.

- **cars**: each library car alone on a grey ground (reflectance 0.2) 12 m in front of
  the reference camera (0, 0, 1.5 m, level, 34° field of view), turned 35° from facing
  the camera (a 3/4 front view), lamps off, under one fixed clear day sky (sun 35° high,
  behind the camera's left shoulder, turbidity 3). The film is cropped to a 16:9 window
  around the car's projected box, so every tile is framed the same way. One exposure
  for the whole sheet (the 97th percentile of luminance over all tiles), so paints can be
  compared.
- **skies**: each sky over a grey ground of the sky model's albedo (0.15), seen from
  1.5 m by a wide camera (100° horizontal) pitched up 20° and turned towards the sun
  (day, dusk) or the moon (moonlit nights; moonless nights look along +x), which shows
  the sky's brightest region and gradient. Each tile is exposed on its own (night skies
  are 10⁷ times darker than day skies); the label gives the median luminance of the
  tile's upper half (cd/m²).

Tiles are independent: ``workers`` processes render them in parallel, and each tile's
sampler seed is ``seed + id``, so a sheet is the same whatever the number of workers.
"""

from __future__ import annotations

import math
from concurrent.futures import ProcessPoolExecutor
from multiprocessing import get_context
from pathlib import Path

import numpy as np

from metricscenes.geometry import REFERENCE_EXTENT
from metricscenes.groundtruth import car_box_tan
from metricscenes.render import Film, render_radiance, sensor_dict, spectral_film_dict, use_variant

ASSET_KINDS = ("cars", "skies")
TILE_PX = (160, 90)
# Per-kind sheet defaults: a palette keeps the committed PNGs under ~300 KB (noisy renders
# compress badly as RGB); sky gradients need the full 256 colours, cars fewer and smaller tiles.
SHEET_DEFAULTS = {"cars": {"tile_px": (144, 81), "colors": 96}, "skies": {"tile_px": (160, 90), "colors": 256}}
CAR_DISTANCE_M = 12.0
CAR_TURN_DEG = 35.0
CAR_MARGIN = 0.12  # of the car box, on each side
SHEET_SUN = {"elevation_deg": 35.0, "azimuth_deg": 150.0, "turbidity": 3.0}
SKY_VIEW = {"hfov_deg": 100.0, "pitch_deg": 20.0}
GROUND_REFLECTANCE = {"cars": 0.2, "skies": 0.15}
MAX_DEPTH = 6


class AssetPreviewError(ValueError):
    """Bad contact-sheet request (one-line message)."""


def _ground(reflectance: float) -> dict:
    import mitsuba as mi

    return {"type": "rectangle", "to_world": mi.ScalarTransform4f().scale([1.0e4, 1.0e4, 1.0]),
            "bsdf": {"type": "diffuse", "reflectance": {"type": "uniform", "value": float(reflectance)}}}


def car_film(box_tan, tile_px: tuple[int, int] = TILE_PX) -> Film:
    """A reference-camera film scaled and cropped so that ``tile_px`` frames the car's box."""
    e = REFERENCE_EXTENT
    cols, rows = tile_px
    bw, bh = (box_tan[2] - box_tan[0]) * (1 + 2 * CAR_MARGIN), (box_tan[3] - box_tan[1]) * (1 + 2 * CAR_MARGIN)
    pitch = max(bw / cols, bh / rows)  # tangent units per tile pixel
    width = math.ceil(e.width / pitch)
    height = round(width * e.height / e.width)
    cx = 0.5 * (box_tan[0] + box_tan[2])
    cy = 0.5 * (box_tan[1] + box_tan[3])
    x0 = int(np.clip(round((cx - e.x0) / e.width * width - cols / 2), 0, width - cols))
    y0 = int(np.clip(round((cy - e.y0) / e.height * height - rows / 2), 0, height - rows))
    return Film(width, height, x0, y0, cols, rows)


def render_car_tile(car_id: int, spp: int, seed: int, tile_px: tuple[int, int] = TILE_PX) -> np.ndarray:
    """(rows, cols, 31) radiance of one library car, 3/4 front view (see module doc)."""
    from metricscenes.assets import cars, skies

    use_variant("scalar_spectral")
    spec = cars.car_spec(car_id)
    position, yaw = (CAR_DISTANCE_M, 0.0), math.pi - math.radians(CAR_TURN_DEG)
    parts = cars.car_parts(spec, position, yaw, lights="off")
    film = car_film(car_box_tan(cars.car_vertices_world(spec, position, yaw)), tile_px)
    sun = skies.SkySpec(-1, "day", SHEET_SUN["elevation_deg"], SHEET_SUN["azimuth_deg"], SHEET_SUN["turbidity"])
    scene = {"type": "scene", "integrator": {"type": "path", "max_depth": MAX_DEPTH},
             "sensor": sensor_dict(film, spp, seed + car_id), "ground": _ground(GROUND_REFLECTANCE["cars"]),
             **parts.shapes, **{f"sky_{k}": v for k, v in skies.sky_emitters(sun).items()}}
    return render_radiance(scene, spp)


def sky_view_azimuth_deg(spec) -> float:
    """Azimuth the sky tile looks at: the sun (day, dusk), the moon, or +x (moonless night)."""
    if spec.kind in ("day", "dusk"):
        return spec.sun_azimuth_deg
    return spec.moon_azimuth_deg if spec.moon_normal_illuminance_lux > 0 else 0.0


def render_sky_tile(sky_id: int, spp: int, seed: int, tile_px: tuple[int, int] = TILE_PX) -> np.ndarray:
    """(rows, cols, 31) radiance of one library sky over a grey ground (see module doc)."""
    import mitsuba as mi

    from metricscenes.assets import skies

    use_variant("scalar_spectral")
    spec = skies.sky_spec(sky_id)
    az, el = math.radians(sky_view_azimuth_deg(spec)), math.radians(SKY_VIEW["pitch_deg"])
    origin = np.array([0.0, 0.0, 1.5])
    target = origin + [math.cos(el) * math.cos(az), math.cos(el) * math.sin(az), math.sin(el)]
    sensor = {"type": "perspective", "fov": SKY_VIEW["hfov_deg"], "fov_axis": "x",
              "to_world": mi.ScalarTransform4f().look_at(origin=origin.tolist(), target=target.tolist(),
                                                         up=[0.0, 0.0, 1.0]),
              "sampler": {"type": "stratified", "sample_count": int(spp), "seed": int(seed + sky_id) % 2**31},
              "film": spectral_film_dict(Film(*tile_px))}
    scene = {"type": "scene", "integrator": {"type": "path", "max_depth": 3}, "sensor": sensor,
             "ground": _ground(GROUND_REFLECTANCE["skies"]),
             **{f"sky_{k}": v for k, v in skies.sky_emitters(spec).items()}}
    return render_radiance(scene, spp)


def _render(kind: str, asset_id: int, spp: int, seed: int, tile_px: tuple[int, int]) -> np.ndarray:
    render = render_car_tile if kind == "cars" else render_sky_tile
    return render(asset_id, spp, seed, tile_px)


def _labels(kind: str, ids: list[int], tiles: list[np.ndarray]) -> list[str]:
    from metricscenes.assets import cars, skies
    from metricscenes.photometry import radiance_to_xyz

    if kind == "cars":
        return [f"car {i:02d} {cars.car_spec(i).body_style} {cars.car_spec(i).paint}" for i in ids]
    labels = []
    for i, tile in zip(ids, tiles):
        s = skies.sky_spec(i)
        # median, not mean: a sun disk in view (~1e9 cd/m²) would dominate a mean
        sky_cd_m2 = float(np.median(radiance_to_xyz(tile[: tile.shape[0] // 2])[..., 1]))
        if s.kind == "night":
            what = f"moon{s.moon_elevation_deg:.0f}" if s.moon_normal_illuminance_lux > 0 else "no moon"
        else:
            what = f"sun{s.sun_elevation_deg:+.1f}"
        labels.append(f"sky {i:02d} {s.kind} {what} {_compact(sky_cd_m2)}cd")
    return labels


def _compact(value: float) -> str:
    """Two significant digits, short exponent: 48000 → '4.8e4', 0.00041 → '4.1e-4'."""
    text = f"{value:.2g}"
    return text.replace("e+0", "e").replace("e+", "e").replace("e-0", "e-")


def asset_contact_sheet(kind: str, out: str | Path, *, ids: list[int] | None = None, spp: int = 16,
                        seed: int = 0, workers: int = 1, columns: int | None = None,
                        tile_px: tuple[int, int] | None = None, colors: int | None = None) -> Path:
    """Render ``kind`` ('cars' or 'skies'; all of them unless ``ids``) and write a labelled
    PNG contact sheet with a ``colors`` palette to ``out``; return its path.
    ``tile_px`` and ``colors`` default to :data:`SHEET_DEFAULTS`."""
    from PIL import Image

    from metricscenes.assets import cars, skies
    from metricscenes.preview import contact_sheet, radiance_to_srgb8

    if kind not in ASSET_KINDS:
        raise AssetPreviewError(f"unknown asset kind {kind!r} (choose from: {', '.join(ASSET_KINDS)})")
    n = len(cars.CAR_IDS) if kind == "cars" else skies.N_SKIES
    ids = list(range(n)) if ids is None else [int(i) for i in ids]
    bad = [i for i in ids if not 0 <= i < n]
    if bad or not ids:
        raise AssetPreviewError(f"{kind} ids must be in 0..{n - 1}, got {bad or 'none'}")
    if spp < 1:
        raise AssetPreviewError(f"--spp must be >= 1, got {spp}")
    tile_px = tuple(tile_px or SHEET_DEFAULTS[kind]["tile_px"])
    colors = int(colors or SHEET_DEFAULTS[kind]["colors"])
    jobs = [(kind, i, spp, seed, tile_px) for i in ids]
    if workers <= 1:
        tiles = [_render(*job) for job in jobs]
    else:
        with ProcessPoolExecutor(workers, mp_context=get_context("spawn")) as pool:
            tiles = list(pool.map(_render, *zip(*jobs)))
    if kind == "cars":
        from metricscenes.photometry import radiance_to_xyz

        # 99.5th percentile: white paint in full sun must not clip (it is the brightest surface)
        white = float(np.percentile(np.concatenate([radiance_to_xyz(t)[..., 1].ravel() for t in tiles]), 99.5))
        rgb = [radiance_to_srgb8(t, white=white) for t in tiles]
    else:
        rgb = [radiance_to_srgb8(t, percentile=99.0) for t in tiles]
    columns = columns or 10
    path = contact_sheet(rgb, _labels(kind, ids, tiles), min(columns, len(ids)), Path(out), tile_width=tile_px[0])
    # A palette keeps the committed sheets small (noisy renders compress badly as RGB).
    Image.open(path).convert("RGB").quantize(colors, dither=Image.Dither.NONE).save(path, optimize=True)
    return path
