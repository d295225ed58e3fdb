"""The car lamps' whole frame on a coarser grid (``render.frame_divisor``): the manifest
checks it, generate renders the frame on that grid, and the reader interpolates it onto
the plate's grid before adding it. One tiny night render."""

import numpy as np
import pytest

from metricscenes.manifest import ManifestError, parse_manifest
from metricscenes.radiance import RadianceLayer, SpectralScene

NIGHT = {
    "name": "frames", "protocol": "smoke", "seed": 11, "environments": 1, "distances_m": [25],
    "reference_grid": {"width_px": 96, "height_px": 54},
    "render": {"plate_spp": 4, "inset_spp": 4, "inset_pixel_mrad": 1.0, "inset_max_px": 64, "max_depth": 3,
               "frame_divisor": 2},
    "light_groups": ["sky_night", "car_lights"], "conditions": {"night": {"sky_night": 1.0, "car_lights": 1.0}},
}


def test_divisor_is_hashed_and_must_divide_the_grid():
    plain = {**NIGHT, "render": {k: v for k, v in NIGHT["render"].items() if k != "frame_divisor"}}
    assert parse_manifest(plain).frame_grid_px() == (96, 54)
    assert parse_manifest(NIGHT).frame_grid_px() == (48, 27)
    assert parse_manifest(plain).sha256() != parse_manifest(NIGHT).sha256()
    with pytest.raises(ManifestError, match="frame_divisor: 4 must divide the reference grid"):
        parse_manifest({**NIGHT, "render": {**NIGHT["render"], "frame_divisor": 4}})  # 54 / 4
    with pytest.raises(ManifestError, match="frame_divisor"):
        parse_manifest({**NIGHT, "render": {**NIGHT["render"], "frame_divisor": 1}})


@pytest.mark.slow
def test_a_coarse_frame_is_rendered_on_its_grid_and_added_on_the_plates(tmp_path):
    import zarr

    from metricscenes.generate import generate
    from metricscenes.store import Collection

    collection = Collection.open(generate(parse_manifest(NIGHT), tmp_path / "frames"))
    store = zarr.open_group(str(tmp_path / "frames" / "radiance.zarr"), mode="r")
    frame = store["frames/env000-d025m/car_lights"]
    plate_night = np.asarray(store["plates/env000/sky_night"][...])
    assert frame.shape == (27, 48, 31) and plate_night.shape == (54, 96, 31)
    assert np.asarray(frame[...]).max() > 0  # the beams light the road

    scene = collection.radiance("env000-d025m", "night")
    plate = scene.layers[0]
    assert plate.radiance.shape == (54, 96, 31)
    upsampled = SpectralScene(layers=(RadianceLayer(np.asarray(frame[...]), plate.extent),)).resample(
        96, 54, plate.extent)
    np.testing.assert_array_equal(plate.radiance, plate_night + upsampled)
    # Interpolation keeps the frame's light: the means over the field agree to a few per cent
    # (linear between pixel centres, clamped at the border).
    np.testing.assert_allclose(upsampled.mean(axis=(0, 1)), np.asarray(frame[...]).mean(axis=(0, 1)),
                               rtol=0.05, atol=1e-12)
    assert collection.verify() == []
