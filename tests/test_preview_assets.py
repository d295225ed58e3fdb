"""Asset contact sheets: framing, a tiny rendered sheet, one-line errors."""

import numpy as np
import pytest
from PIL import Image

from metricscenes.assets import cars, skies
from metricscenes.geometry import REFERENCE_EXTENT
from metricscenes.groundtruth import car_box_tan
from metricscenes.preview_assets import (
    CAR_DISTANCE_M, AssetPreviewError, asset_contact_sheet, car_film, sky_view_azimuth_deg,
)


@pytest.mark.parametrize("car_id", [0, 9, 48])
def test_car_film_frames_the_whole_car(car_id):
    spec = cars.car_spec(car_id)
    box = car_box_tan(cars.car_vertices_world(spec, (CAR_DISTANCE_M, 0.0), np.pi - np.radians(35)))
    film = car_film(box, (160, 90))
    e = REFERENCE_EXTENT
    assert film.size == (160, 90) and film.height == round(film.width * 9 / 16)
    x0 = e.x0 + film.crop_x / film.width * e.width
    x1 = e.x0 + (film.crop_x + 160) / film.width * e.width
    y0 = e.y0 + film.crop_y / film.height * e.height
    y1 = e.y0 + (film.crop_y + 90) / film.height * e.height
    assert x0 <= box[0] and box[2] <= x1 and y0 <= box[1] and box[3] <= y1
    # the car fills the tile in at least one direction (margins only)
    assert max((box[2] - box[0]) / (x1 - x0), (box[3] - box[1]) / (y1 - y0)) > 0.7


def test_sky_tiles_look_at_the_sun_or_moon():
    assert sky_view_azimuth_deg(skies.sky_spec(3)) == skies.sky_spec(3).sun_azimuth_deg
    assert sky_view_azimuth_deg(skies.sky_spec(27)) == skies.sky_spec(27).moon_azimuth_deg
    assert sky_view_azimuth_deg(skies.sky_spec(21)) == 0.0


def test_bad_requests_are_one_line(tmp_path):
    with pytest.raises(AssetPreviewError, match="unknown asset kind 'boats'"):
        asset_contact_sheet("boats", tmp_path / "x.png")
    with pytest.raises(AssetPreviewError, match=r"0\.\.49"):
        asset_contact_sheet("cars", tmp_path / "x.png", ids=[50])
    assert not (tmp_path / "x.png").exists()


@pytest.mark.slow
@pytest.mark.parametrize("kind, ids", [("cars", [3, 9]), ("skies", [4, 25])])
def test_tiny_contact_sheet_renders(tmp_path, kind, ids):
    path = asset_contact_sheet(kind, tmp_path / f"{kind}.png", ids=ids, spp=2, tile_px=(64, 36))
    im = Image.open(path)
    assert im.size == (2 * 64, 36 + 16)  # two tiles side by side, a 16-px caption strip
    rgb = np.asarray(im.convert("RGB"), dtype=float)
    tiles = rgb[:36]
    assert tiles.std() > 5  # an image, not a blank
    assert tiles[:, :64].mean() > 10 and tiles[:, 64:].mean() > 10  # both tiles lit (auto exposure)
