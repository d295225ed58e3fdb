"""``store: {spectral_basis: K}``: radiance stored as K coefficients per pixel on basis spectra
that hold the IMX363's channels and CIE Y exactly; readers get 31 bands back, the same bytes
whatever the worker count, and a damaged basis is a one-line error."""

import json

import numpy as np
import pytest

from metricscenes.manifest import ManifestError, parse_manifest
from metricscenes.spectral_basis import basis_for, decode, encode, held_spectra

TINY = {
    "name": "basis", "protocol": "smoke", "seed": 12, "environments": 1, "distances_m": [25, 100],
    "reference_grid": {"width_px": 96, "height_px": 54},
    "render": {"plate_spp": 4, "inset_spp": 4, "inset_pixel_mrad": 1.0, "inset_max_px": 64, "max_depth": 3},
    "light_groups": ["sky_day", "sky_night", "car_lights"],
    "conditions": {"day": {"sky_day": 1.0}, "night": {"sky_night": 1.0, "car_lights": 1.0}},
    "store": {"mantissa_bits": 8, "spectral_basis": 8},
}


def test_the_basis_holds_the_sensor_channels_and_y_of_any_spectrum():
    rng = np.random.default_rng(0)
    cube = rng.gamma(2.0, 1.0, (40, 48, 31)).astype(np.float32)
    basis = basis_for(cube, 8)
    np.testing.assert_allclose(basis.T @ basis, np.eye(8), atol=1e-12)
    held = held_spectra()
    back = decode(encode(cube, basis), basis)
    # The held channels come back to float32 precision; the bands do not (8 of 31 directions).
    np.testing.assert_allclose(back.astype(np.float64) @ held, cube.astype(np.float64) @ held, rtol=2e-6)
    assert np.abs(back - cube).max() > 0.1
    with pytest.raises(ValueError, match="must exceed the 4 held spectra"):
        basis_for(cube, 4)


def test_the_setting_is_hashed_only_when_set_and_checked():
    plain = {**TINY, "store": {"mantissa_bits": 8}}
    assert parse_manifest(plain).sha256() != parse_manifest(TINY).sha256()
    assert "spectral_basis" not in json.dumps(parse_manifest(plain).model_dump(mode="json", exclude_none=True))
    with pytest.raises(ManifestError, match="spectral_basis"):
        parse_manifest({**TINY, "store": {"spectral_basis": 4}})
    with pytest.raises(ManifestError, match="spectral_basis"):
        parse_manifest({**TINY, "store": {"spectral_basis": 32}})


@pytest.mark.slow
def test_a_collection_through_a_basis_reads_31_bands_identically_with_one_or_two_workers(tmp_path):
    import zarr

    from metricscenes.generate import generate
    from metricscenes.store import Collection, CollectionError

    # Two render threads against one: the 100 m inset (30 x 34 px) has fewer 32 px blocks than
    # threads, where Mitsuba's own block size would change with the thread count (render.BLOCK_SIZE_PX).
    one = generate(parse_manifest(TINY), tmp_path / "one", workers=1)
    two = generate(parse_manifest(TINY), tmp_path / "two", workers=2)
    files = sorted(p.relative_to(one) for p in one.rglob("*") if p.is_file() and "progress" not in p.parts)
    assert files and all((one / f).read_bytes() == (two / f).read_bytes() for f in files)

    store = zarr.open_group(str(one / "radiance.zarr"), mode="r")
    stored = store["plates/env000/sky_day"]
    assert stored.shape == (54, 96, 8) and len(stored.attrs["spectral_basis"]) == 8
    collection = Collection.open(one)
    assert collection.verify() == []
    scene = collection.radiance("env000-d025m", "night")
    assert [layer.radiance.shape[-1] for layer in scene.layers] == [31, 31]
    assert scene.layers[0].radiance.max() > 0
    assert collection.angular_sampling("env000-d025m")[0]["shape"] == (54, 96, 31)

    basis = np.asarray(stored.attrs["spectral_basis"])
    attrs = dict(stored.attrs) | {"spectral_basis": (basis[:, :30]).tolist()}  # a damaged basis
    zarr.open_array(str(one / "radiance.zarr" / "plates/env000/sky_day"), mode="r+").attrs.put(attrs)
    problems = Collection.open(one).verify()
    assert len(problems) == 1 and "plates/env000/sky_day" in problems[0] and "spectral_basis" in problems[0]
    with pytest.raises(CollectionError, match="spectral_basis does not fit"):
        Collection.open(one).radiance("env000-d025m", "day")


@pytest.mark.slow
def test_a_camera_cannot_tell_a_collection_through_the_basis_from_its_31_bands(tmp_path):
    """The same renders stored in 31 bands and through the basis: the bands differ by tens of
    per cent (4 spp of noise the basis projects away), the cameras' noise-free signal by
    under a per cent (measured: 0.05-0.5 % RMS for cam12 and cam08, day and night)."""
    from benchmark.camera import load_camera
    from benchmark.camera.pipeline import electron_rate
    from metricscenes.generate import generate
    from metricscenes.store import Collection

    bands = Collection.open(generate(parse_manifest({**TINY, "store": {"mantissa_bits": 8}}), tmp_path / "bands"))
    basis = Collection.open(generate(parse_manifest(TINY), tmp_path / "basis"))
    for condition in ("day", "night"):
        a, b = (c.radiance("env000-d100m", condition) for c in (bands, basis))
        plate_a, plate_b = a.layers[0].radiance.astype(np.float64), b.layers[0].radiance.astype(np.float64)
        assert np.abs(plate_a - plate_b).max() > 0.1 * np.abs(plate_a).max()
        for name in ("cam12", "cam08"):
            e_a, e_b = (electron_rate(s, load_camera(name)).astype(np.float64) for s in (a, b))
            lit = e_a > 1e-3 * e_a.max()
            assert np.sqrt(np.mean((e_a - e_b)[lit] ** 2) / np.mean(e_a[lit] ** 2)) < 0.01, (name, condition)
