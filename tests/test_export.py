"""HDF5 export for ISETCam: units, photon conversion, grid, box, one-line errors."""

import subprocess
import sys

import h5py
import numpy as np
import pytest

from conftest import REPO
from metricscenes.export import (
    MAX_DEFAULT_WIDTH_PX, PHOTON_UNITS, ExportError, default_width_px, export_scene, grid_for_width,
    radiance_to_photons,
)
from metricscenes.geometry import HORIZONTAL_FOV_DEG, REFERENCE_EXTENT, TanExtent
from metricscenes.radiance import RadianceLayer, SpectralScene
from metricscenes.spectral import WAVELENGTHS_NM
from metricscenes.store import Collection

H_J_S, C_M_S = 6.62607015e-34, 299792458.0  # SI exact values (oracle, not the package's constants)


def test_photons_at_555nm_match_the_textbook_value():
    # One W at 555 nm is 1 / (h c / 555 nm) = 2.7940e18 photons per second.
    q = radiance_to_photons(np.ones((1, 1, 1), np.float32), np.array([555.0]))
    assert q[0, 0, 0] == pytest.approx(2.7940e18, rel=1e-4)


def _scene(inset_pitch_tan: float | None) -> SpectralScene:
    layers = [RadianceLayer(np.ones((108, 192, 31), np.float32), REFERENCE_EXTENT)]
    if inset_pitch_tan is not None:
        cols = 50
        layers.append(RadianceLayer(np.ones((40, cols, 31), np.float32),
                                    TanExtent(0.0, 0.0, cols * inset_pitch_tan, 40 * inset_pitch_tan)))
    return SpectralScene(layers=tuple(layers))


def test_default_width_keeps_the_inset_sampling_capped_at_2688():
    field = REFERENCE_EXTENT.width
    assert default_width_px(_scene(field / 1000), 192) == 1000
    assert default_width_px(_scene(field / 5000), 192) == MAX_DEFAULT_WIDTH_PX
    assert default_width_px(_scene(None), 192) == 192
    assert grid_for_width(384, (192, 108)) == (384, 216)
    with pytest.raises(ExportError, match="width-px"):
        grid_for_width(8, (192, 108))


def test_unknown_format_is_refused_before_reading(tmp_path):
    with pytest.raises(ExportError, match="unknown export format 'mat'"):
        export_scene(tmp_path / "nowhere", "env000-d100m", "day", "mat", tmp_path / "x.h5")


@pytest.mark.slow
def test_export_reads_back_for_isetcam(smoke_collection, tmp_path):
    out = export_scene(smoke_collection, "env000-d100m", "day", "hdf5", tmp_path / "s.h5", width_px=384)
    collection = Collection.open(smoke_collection)
    with h5py.File(out, "r") as f:
        photons, radiance, wave = f["photons"][...], f["radiance"][...], f["wave"][...]
        assert photons.shape == radiance.shape == (216, 384, 31)
        np.testing.assert_array_equal(wave, WAVELENGTHS_NM)
        assert f["photons"].attrs["units"] == PHOTON_UNITS
        assert f["radiance"].attrs["units"] == "W sr-1 m-2 nm-1"
        assert "permute" in f["photons"].attrs["dimension_order"]
        assert f["photons"].dims[2][0].name == "/wave"
        assert f.attrs["hfov_deg"] == pytest.approx(HORIZONTAL_FOV_DEG)
        assert f.attrs["hfov_deg"] == pytest.approx(2 * np.degrees(np.arctan(1.344 / 4.38)))
        assert f.attrs["distance_m"] == 100.0
        assert f.attrs["mrad_per_px"][0] == pytest.approx(1e3 * REFERENCE_EXTENT.width / 384)
        box = f["groundtruth/bbox_xywh"][...]
        x_tan, y_tan = f["x_tan"][...], f["y_tan"][...]
    # q = L λ / (h c), band by band
    per_band = WAVELENGTHS_NM * 1e-9 / (H_J_S * C_M_S)
    np.testing.assert_allclose(photons, radiance * per_band, rtol=2e-6)
    # the composite is the store's own resampling onto the export grid
    np.testing.assert_allclose(radiance, collection.radiance("env000-d100m", "day").resample(384, 216), rtol=1e-6)
    assert radiance.min() >= 0 and radiance.mean() > 0
    # the COCO box is the reference box scaled by 2 and lies inside the grid
    ref_box = next(a["bbox"] for a in collection.groundtruth()["annotations"] if a["image_id"] == 4)
    np.testing.assert_allclose(box, np.array(ref_box) * 2.0)
    assert box[0] >= 0 and box[1] >= 0 and box[0] + box[2] <= 384 and box[1] + box[3] <= 216 and box[2] > 0
    assert x_tan[0] == pytest.approx(REFERENCE_EXTENT.x0 + REFERENCE_EXTENT.width / 768)
    assert y_tan[0] == pytest.approx(REFERENCE_EXTENT.y0 + REFERENCE_EXTENT.height / 432)


def _cli(*args):
    return subprocess.run([sys.executable, "-m", "metricscenes.cli", "export", *map(str, args)],
                          capture_output=True, text=True, cwd=REPO, timeout=120)


@pytest.mark.slow
@pytest.mark.parametrize("extra, words", [
    (["--scene", "env099-d100m"], "unknown scene 'env099-d100m'"),
    (["--scene", "env000-d100m", "--condition", "dusk"], "unknown condition 'dusk'"),
    (["--scene", "env000-d100m", "--format", "exr"], "unknown export format 'exr'"),
    (["--scene", "env000-d100m", "--width-px", "5"], "--width-px"),
])
def test_cli_errors_are_one_line(smoke_collection, tmp_path, extra, words):
    proc = _cli(smoke_collection, tmp_path / "x.h5", *extra)
    assert proc.returncode != 0
    lines = [line for line in proc.stderr.splitlines() if line.strip()]
    assert len(lines) == 1 and words in lines[0], proc.stderr
    assert "Traceback" not in proc.stderr and not (tmp_path / "x.h5").exists()


@pytest.mark.slow
def test_cli_export_writes_the_file(smoke_collection, tmp_path):
    proc = _cli(smoke_collection, tmp_path / "y.h5", "--scene", "env001-d200m", "--condition", "night",
                "--width-px", "192")
    assert proc.returncode == 0, proc.stderr
    with h5py.File(tmp_path / "y.h5", "r") as f:
        assert f["photons"].shape == (108, 192, 31) and f.attrs["condition"] == "night"


def test_composite_in_band_passes_keeps_the_feather():
    from metricscenes.export import composite

    rng = np.random.default_rng(3)
    inset = RadianceLayer(rng.random((40, 64, 31), dtype=np.float32), TanExtent(-0.05, -0.03, 0.07, 0.05), feather=0.1)
    scene = SpectralScene(layers=(RadianceLayer(rng.random((27, 48, 31), dtype=np.float32), REFERENCE_EXTENT), inset))
    np.testing.assert_array_equal(composite(scene, 192, 108), scene.resample(192, 108))
