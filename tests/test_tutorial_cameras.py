"""The tutorial's cameras (cameras/tutorial-*.yaml) load, and the 8 mm one makes the tutorial's
point: lower MTF50 on the sensor than cam12, finer in object space (docs/tutorial.md, step 2)."""

from pathlib import Path

from benchmark.camera import load_camera
from benchmark.measure.mtf import camera_mtf50

CAMERAS = Path(__file__).resolve().parents[1] / "cameras"


def test_a_longer_lens_resolves_finer_angles_with_a_lower_sensor_mtf50():
    cam12, long_lens = load_camera("cam12"), load_camera(CAMERAS / "tutorial-2.1um-f2.0-8mm.yaml")
    (mm12, _), (mm8, _) = camera_mtf50(cam12, "analytic"), camera_mtf50(long_lens, "analytic")
    assert long_lens.optics.focal_length_mm == 8.0 and long_lens.hfov_deg < cam12.hfov_deg
    assert mm8 < mm12 and long_lens.cy_per_mrad(mm8) > 1.2 * cam12.cy_per_mrad(mm12)


def test_every_tutorial_camera_loads():
    for path in sorted(CAMERAS.glob("tutorial-*.yaml")):
        assert load_camera(path).name == path.stem
