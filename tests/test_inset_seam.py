"""The inset's window leaves no seam in an image finer than the plate (docs/scenes.md, "The
inset seam"): outside a few plate pixels around the car, the inset is shown at the plate's
resolution, so its border has nothing to show; the car keeps the inset's own."""

from dataclasses import replace

import numpy as np
import pytest

from metricscenes.geometry import REFERENCE_EXTENT, TanExtent
from metricscenes.radiance import (SHARP_CORE_PLATE_PX, SHARP_RAMP_PLATE_PX, RadianceLayer, SpectralScene,
                                   _overlap_matrix, car_sharpness)

K = 4  # inset pixels per plate pixel
PLATE_ROWS, PLATE_COLS = 18, 32
CELLS = (3, 15, 8, 24)  # the inset window in plate cells: rows r0:r1, cols c0:c1
CAR = (32, 40, 56, 68)  # the car in fine pixels (rows, cols), 4 plate pixels or more from the edges
WAVES = np.array([500.0, 600.0])


def _truth(car: bool) -> np.ndarray:
    """The scene on a grid K times finer than the plate: a horizon that the plate's cells cut
    (bright sky above fine row 33, ground below), a slanted lane marking and, if ``car``, a car."""
    rows, cols = PLATE_ROWS * K, PLATE_COLS * K
    y, x = np.mgrid[0:rows, 0:cols]
    f = np.where(y < 33, 10.0, 1.0)
    f = np.where((y >= 33) & (np.abs((x - 20) - 0.8 * (y - 33)) < 1.5), 6.0, f)
    f = np.stack([f, 0.5 * f + (x % 7 == 0)], axis=-1).astype(np.float32)  # two bands, a little texture
    if car:
        f[CAR[0]:CAR[1], CAR[2]:CAR[3]] = (3.0, 0.2)
    return f


def _layers(feather: float = 0.1):
    """The plate (the car-less truth averaged over its cells, as a render estimates it), the
    inset with the car (the truth over the window), the same inset without it, and the car's mask."""
    e = REFERENCE_EXTENT
    px, py = e.width / PLATE_COLS, e.height / PLATE_ROWS
    plate_cells = _truth(car=False).reshape(PLATE_ROWS, K, PLATE_COLS, K, 2).mean(axis=(1, 3))
    plate = RadianceLayer(plate_cells, e)
    r0, r1, c0, c1 = CELLS
    extent = TanExtent(e.x0 + c0 * px, e.y0 + r0 * py, e.x0 + c1 * px, e.y0 + r1 * py)
    window = (slice(r0 * K, r1 * K), slice(c0 * K, c1 * K))
    with_car, without = (RadianceLayer(_truth(car)[window], extent, feather=feather) for car in (True, False))
    mask = np.zeros(with_car.radiance.shape[:2], bool)
    mask[CAR[0] - r0 * K:CAR[1] - r0 * K, CAR[2] - c0 * K:CAR[3] - c0 * K] = True
    return plate, with_car, without, mask


def _scene(plate, inset, sharp=None):
    return SpectralScene(layers=(plate, replace(inset, sharp=sharp)), wavelengths_nm=WAVES)


def _sharp_on_grid(inset, sharp, cols, rows):
    i = inset.extent
    ox = _overlap_matrix(i.x0, i.x1, sharp.shape[1], REFERENCE_EXTENT.x0, REFERENCE_EXTENT.x1, cols)
    oy = _overlap_matrix(i.y0, i.y1, sharp.shape[0], REFERENCE_EXTENT.y0, REFERENCE_EXTENT.y1, rows)
    return oy @ (ox @ sharp.astype(np.float64).T).T


@pytest.mark.parametrize("cols, rows", [(96, 54), (80, 45), (71, 40)])  # 3x, 2.5x, 2.2x finer than the plate
def test_the_window_shows_nothing_but_the_car_on_a_grid_finer_than_the_plate(cols, rows):
    plate, with_car, without, mask = _layers()
    sharp = car_sharpness(mask, with_car.extent, plate.pixel_tan)
    plate_only = SpectralScene(layers=(plate,), wavelengths_nm=WAVES).resample(cols, rows)
    old = _scene(plate, without).resample(cols, rows)
    new = _scene(plate, without, sharp).resample(cols, rows)
    away = _sharp_on_grid(without, sharp, cols, rows) == 0  # every pixel beyond the car's few plate pixels
    # The composite of old shows the window: its horizon and lane marking sharper than the plate's.
    assert np.abs(old - plate_only)[away].max() > 1.0
    # Now, where the car is not, the car-less inset composites to the plate's own image: no border
    # to see, in the window or across its edges.
    np.testing.assert_allclose(new[away], plate_only[away], rtol=1e-5, atol=1e-5)
    r0, r1, c0, c1 = (int(v) for v in np.array(CELLS) * ([rows / PLATE_ROWS] * 2 + [cols / PLATE_COLS] * 2))
    border = np.zeros_like(away)
    border[r0 - 1:r1 + 1, c0 - 1:c1 + 1] = True
    border[r0 + 1:r1 - 1, c0 + 1:c1 - 1] = False
    assert away[border].all()  # the window's edges, inside and out, are all shown at the plate's resolution


def test_the_car_keeps_the_insets_own_resolution():
    plate, with_car, _, mask = _layers()
    sharp = car_sharpness(mask, with_car.extent, plate.pixel_tan)
    cols, rows = 96, 54
    old = _scene(plate, with_car).resample(cols, rows)
    new = _scene(plate, with_car, sharp).resample(cols, rows)
    s = _sharp_on_grid(with_car, sharp, cols, rows)
    keep = s > 1 - 1e-9
    assert keep.sum() >= 60  # the car's 6 x 9 pixels and a plate pixel and a half around them
    np.testing.assert_allclose(new[keep], old[keep], rtol=1e-6, atol=1e-6)
    # The car's radiance reaches the image only where the inset keeps its own resolution (no halo
    # of a blurred car around the sharp one): pixels shown at the plate's resolution see the road.
    plate_only = SpectralScene(layers=(plate,), wavelengths_nm=WAVES).resample(cols, rows)
    np.testing.assert_allclose(new[s == 0], plate_only[s == 0], rtol=1e-5, atol=1e-5)


def test_nothing_changes_away_from_the_window_nor_on_a_grid_no_finer_than_the_plate():
    plate, with_car, _, mask = _layers()
    sharp = car_sharpness(mask, with_car.extent, plate.pixel_tan)
    for cols, rows in ((32, 18), (24, 13), (16, 9)):  # the plate's grid and coarser: bit for bit the old composite
        np.testing.assert_array_equal(_scene(plate, with_car, sharp).resample(cols, rows),
                                      _scene(plate, with_car).resample(cols, rows))
    cols, rows = 96, 54
    old, new = _scene(plate, with_car).resample(cols, rows), _scene(plate, with_car, sharp).resample(cols, rows)
    r0, r1, c0, c1 = (3 * v for v in CELLS)  # the window on this grid (3 pixels a plate cell)
    far = np.ones((rows, cols), bool)
    far[r0 - 5:r1 + 5, c0 - 5:c1 + 5] = False  # beyond a plate cell and a half of the window
    np.testing.assert_array_equal(new[far], old[far])
    # A camera window of the field (a narrower lens) composites as the whole field does.
    e = REFERENCE_EXTENT
    half = TanExtent(e.x0 / 2, e.y0 / 2, e.x1 / 2, e.y1 / 2)
    whole = _scene(plate, with_car, sharp).resample(192, 108)
    np.testing.assert_allclose(_scene(plate, with_car, sharp).resample(96, 54, half), whole[27:81, 48:144],
                               rtol=1e-5, atol=1e-6)


def test_car_sharpness_is_one_near_the_car_and_falls_to_zero_over_the_ramp():
    e = TanExtent(0.0, 0.0, 0.04, 0.01)  # 40 x 10 inset pixels of 1e-3; plate pixels of 4e-3 (4 inset pixels)
    mask = np.zeros((10, 40), bool)
    mask[:, 0] = True
    s = car_sharpness(mask, e, (4e-3, 4e-3))
    assert s.dtype == np.float32 and s.shape == (10, 40)
    distance = np.arange(40) / 4  # plate pixels from the car's column
    expected = np.clip((SHARP_CORE_PLATE_PX + SHARP_RAMP_PLATE_PX - distance) / SHARP_RAMP_PLATE_PX, 0, 1)
    np.testing.assert_allclose(s[5], expected, atol=1e-6)
    assert s[5, 6] == 1.0 and s[5, 14] == 0.0 and s[5, 10] == pytest.approx(0.5)
    assert not car_sharpness(np.zeros((3, 4), bool), e, (4e-3, 4e-3)).any()


def test_collection_gives_the_inset_its_car_map_unless_asked_for_the_whole_window(smoke_collection):
    from metricscenes.store import Collection

    c = Collection.open(smoke_collection)
    scene = c.radiance("env000-d100m", "day")
    plate, inset = scene.layers
    mask, _ = c.mask("env000-d100m")
    assert inset.sharp is not None and inset.sharp.shape == inset.radiance.shape[:2]
    np.testing.assert_array_equal(inset.sharp, car_sharpness(mask, inset.extent, plate.pixel_tan))
    assert np.all(inset.sharp[mask] == 1.0) and inset.sharp.min() == 0.0
    window = c.radiance("env000-d100m", "day", inset_resolution="window")
    assert window.layers[1].sharp is None
    np.testing.assert_array_equal(window.layers[1].radiance, inset.radiance)
    # On smoke's own grid (and coarser) both give the same image; on a camera's finer grid they differ.
    np.testing.assert_array_equal(scene.resample(192, 108), window.resample(192, 108))
    assert not np.array_equal(scene.resample(960, 540), window.resample(960, 540))
    with pytest.raises(ValueError, match="inset_resolution"):
        c.radiance("env000-d100m", "day", inset_resolution="sharp")


def test_seam_check_sees_the_window_and_not_the_fix(smoke_collection):
    import yaml

    from benchmark.camera.registry import DATA_DIR, camera_from_dict
    from benchmark.measure.seam import seam_check
    from metricscenes.store import Collection

    small = yaml.safe_load((DATA_DIR / "cam12.yaml").read_text())  # cam12 with 4x its pixel: 480 x 270,
    small["sensor"].update(pixel_um=5.6)                           # 2.4x finer than smoke's plate
    small.update(name="cam12-5.6um", mtf50_group_cy_per_mm=None)
    camera = camera_from_dict(small)
    c = Collection.open(smoke_collection)
    before, after = (seam_check(c, "env000-d025m", "day", camera, mode) for mode in ("window", "car"))
    assert before["outside_de"] < 0.05 and after["outside_de"] < 0.05
    # (smoke's 4-spp plate is noisy: what is left after the fix is its render noise against the inset's)
    assert before["window_de_p99"] > 2 * after["window_de_p99"]
    assert before["border_de_max_line"] > 2 * after["border_de_max_line"]
    assert before["detail_ratio"] > 1.1 > after["detail_ratio"]


def test_a_scene_resampled_onto_several_grids_gives_each_what_a_fresh_scene_gives():
    """What does not depend on the grid (the plate and the feathered inset band by band, the
    inset pasted onto the plate's cells) is made once per scene and kept for its next grids
    (a sweep's six pixel grids): each grid's composite is, bit for bit, a fresh scene's."""
    plate, with_car, _, mask = _layers()
    sharp = car_sharpness(mask, with_car.extent, plate.pixel_tan)
    scene = _scene(plate, with_car, sharp)
    grids = [(96, 54), (71, 40), (16, 9), (96, 54)]  # finer, finer, coarser than the plate, and back
    for cols, rows in grids:
        again = scene.resample(cols, rows)
        np.testing.assert_array_equal(again, _scene(plate, with_car, sharp).resample(cols, rows))
    kept = {key[0] for key in scene._grid_free}
    assert kept == {"plate", "feathered", "inset", "cells"}
    assert all(not a.flags.writeable for key, a in scene._grid_free.items() if key[0] == "cells")
