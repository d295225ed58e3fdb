"""The wide plate and the long road (docs/scenes.md, "The wide plate" and "Distances beyond
200 m"): a collection may add a coarser plate around the reference field, which cameras up
to its field read and narrower cameras never do; the detailed road may reach farther; every
manifest is checked at its farthest distance before anything renders."""

from dataclasses import replace
from pathlib import Path

import numpy as np
import pytest
import yaml

from benchmark.camera import camera_from_dict, load_camera
from benchmark.camera.pipeline import FieldOfViewError, camera_window
from metricscenes.geometry import REFERENCE_EXTENT, TanExtent, field_extent
from metricscenes.manifest import ManifestError, load_manifest, parse_manifest
from metricscenes.plan import ScenePlan, plan_environment
from metricscenes.radiance import PLATE_SEAM_FEATHER, RadianceLayer, SpectralScene
from metricscenes.scene_checks import farthest_scene_problems, scene_problems
from conftest import model_dir, require_model

ROOT = Path(__file__).resolve().parents[1]
TINY = {
    "name": "wide-tiny", "protocol": "smoke", "seed": 5, "environments": 1, "distances_m": [25, 450],
    "reference_grid": {"width_px": 192, "height_px": 108},
    "render": {"plate_spp": 4, "inset_spp": 4, "inset_pixel_mrad": 0.5, "inset_max_px": 96, "max_depth": 3,
               "road_end_m": 500.0, "frame_divisor": 2},
    "light_groups": ["sky_day", "car_lights"],
    "conditions": {"day": {"sky_day": 1.0}, "day_lamps": {"sky_day": 1.0, "car_lights": 1.0}},
}
WIDE = {"width_px": 160, "height_px": 120, "hfov_deg": 120.0, "spp": 4}  # 4:3, 120° x 104.8°


def _camera(name: str, width_px: int, height_px: int, focal_mm: float, pixel_um: float = 2.1):
    spec = yaml.safe_load((ROOT / "cameras/tutorial-2.1um-f2.0-8mm.yaml").read_text())
    spec["name"], spec["label"], spec["mtf50_group_cy_per_mm"] = name, name, None
    spec["optics"]["focal_length_mm"] = focal_mm
    spec["sensor"].update(pixel_um=pixel_um, active_width_mm=width_px * pixel_um * 1e-3,
                          active_height_mm=height_px * pixel_um * 1e-3)
    return camera_from_dict(spec)


def test_earlier_manifests_keep_their_hash():
    # Pinned by the protocols; the new fields are hashed only once set.
    assert load_manifest(ROOT / "manifests/quick.yaml").sha256().startswith("6ce3394e")
    assert load_manifest(ROOT / "manifests/metric-300.yaml").sha256().startswith("fd9342ff")
    base = parse_manifest(TINY)
    assert base.sha256() != parse_manifest({**TINY, "wide_plate": WIDE}).sha256()
    assert base.sha256() != parse_manifest({**TINY, "render": {**TINY["render"], "road_end_m": 600.0}}).sha256()


@pytest.mark.parametrize("wide, words", [
    ({**WIDE, "hfov_deg": 30.0}, r"wide_plate: its field 30\.00° x 22\.73° must hold the reference grid's 34\.12° x 19\.59°"),
    ({**WIDE, "width_px": 100}, "aspect"),
    ({**WIDE, "spp": 5}, "square"),
    ({**WIDE, "width_px": 161}, "frame_divisor: 2 must divide the wide plate"),
])
def test_a_bad_wide_plate_is_refused_in_one_line(wide, words):
    with pytest.raises(ManifestError, match=words) as err:
        parse_manifest({**TINY, "wide_plate": wide})
    assert "\n" not in str(err.value)


def test_a_car_beyond_the_detailed_road_is_refused_in_one_line():
    with pytest.raises(ManifestError, match=r"a car at 490 m stands beyond the detailed road, which ends at 500 m"):
        parse_manifest({**TINY, "distances_m": [25, 490]})
    # The default road ends at 395 m: the paper's distances fit, 400 m does not.
    with pytest.raises(ManifestError, match="set render.road_end_m to at least 420"):
        parse_manifest({**TINY, "distances_m": [25, 400], "render": {**TINY["render"], "road_end_m": None}})


def test_the_adas_protocol_holds_at_its_farthest_distance():
    manifest = load_manifest(ROOT / "manifests/adas-quick.yaml")
    assert max(manifest.distances_m) == 600 and manifest.render.road_end_m == 700
    assert farthest_scene_problems(manifest) == []
    assert manifest.wide_plate.field.x1 == pytest.approx(np.tan(np.radians(60)))
    full = load_manifest(ROOT / "manifests/adas-300.yaml")  # the full size: metric-300's environments
    assert farthest_scene_problems(full) == [] and full.seed == load_manifest(ROOT / "manifests/metric-300.yaml").seed
    on_axis_mrad = 1e3 * full.wide_plate.field.width / full.wide_plate.width_px
    assert on_axis_mrad == pytest.approx(load_camera(ROOT / "cameras/adas-8mp-120deg.yaml").ifov_mrad, rel=0.01)


def test_the_scene_checks_catch_each_failure():
    manifest = parse_manifest({**TINY, "distances_m": [25, 1000], "render": {**TINY["render"], "road_end_m": 1100.0}})
    env = plan_environment(manifest, 0)
    far = ScenePlan(env, 1000.0, image_id=1, seed=1)
    problems = scene_problems(manifest, far)  # 192 px over 34°: a car at 1 km is under a pixel, on the horizon
    assert any("reference pixels below the horizontal" in p for p in problems)
    assert any("the car's box is" in p and "reference pixels" in p for p in problems)
    assert scene_problems(manifest, ScenePlan(env, 25.0, image_id=1, seed=1)) == []
    off_road = ScenePlan(replace(env, lateral_offset_m=12.0), 25.0, image_id=1, seed=1)
    assert any("leave the paved road" in p for p in scene_problems(manifest, off_road))
    from metricscenes.generate import generate

    with pytest.raises(ManifestError, match=r"env000-d1000m .* \(and 1 more\)"):
        generate(manifest, "/nonexistent/never-written")


def test_a_camera_wider_than_the_widest_plate_is_refused_naming_both_fields():
    wide = parse_manifest({**TINY, "wide_plate": WIDE}).wide_plate.field
    front = _camera("front-37", 1920, 1200, 6.0)  # 37.1° x 23.7°: wider than the reference field
    with pytest.raises(FieldOfViewError, match=r"sees 37\.1.° x 23\.7.°.* the collection's field 34\.12° x 19\.59°"):
        camera_window(front, REFERENCE_EXTENT)
    window = camera_window(front, REFERENCE_EXTENT, wide)
    assert window.x1 == pytest.approx(1920 * 2.1e-3 / 2 / 6.0)
    assert camera_window(load_camera("cam12"), REFERENCE_EXTENT, wide) is REFERENCE_EXTENT  # the same object
    camera_window(_camera("wide-94", 1600, 1200, 1.5, pixel_um=2.0), REFERENCE_EXTENT, wide)  # 93.7° x 77.3°
    too_wide = _camera("wider-140", 1600, 1200, 0.55, pixel_um=2.0)  # 142° horizontally
    with pytest.raises(FieldOfViewError, match=r"sees 142\.\d\d° x \d+\.\d\d°.* the collection's widest field "
                                               r"120\.00° x 104\.82°"):
        camera_window(too_wide, REFERENCE_EXTENT, wide)


def _field_scene(surround_px: tuple[int, int], plate_px: tuple[int, int], field):
    """Plate and surround sampled (cell means) from one smooth radiance field ``field(x, y)``:
    both estimate the same radiance, as two renders of one scene do."""
    def layer(extent: TanExtent, cols: int, rows: int, k: int = 8) -> RadianceLayer:
        xs = extent.x0 + (np.arange(cols * k) + 0.5) * extent.width / (cols * k)
        ys = extent.y0 + (np.arange(rows * k) + 0.5) * extent.height / (rows * k)
        fine = field(xs[None, :], ys[:, None])
        cells = fine.reshape(rows, k, cols, k).mean(axis=(1, 3))
        return RadianceLayer(np.repeat(cells[:, :, None], 2, axis=2).astype(np.float32), extent)

    wide = field_extent(120.0, *surround_px)
    return SpectralScene(layers=(layer(REFERENCE_EXTENT, *plate_px),), surround=layer(wide, *surround_px),
                         wavelengths_nm=np.array([500.0, 600.0]))


def test_a_grid_inside_the_plate_never_reads_the_surround():
    scene = _field_scene((160, 120), (96, 54), lambda x, y: 1.0 + x + 0.5 * y)
    without = SpectralScene(layers=scene.layers, wavelengths_nm=scene.wavelengths_nm)
    for cols, rows, extent in ((192, 108, None), (64, 36, None), (50, 20, TanExtent(-0.1, -0.05, 0.2, 0.1))):
        assert np.array_equal(scene.resample(cols, rows, extent), without.resample(cols, rows, extent))


@pytest.mark.parametrize("cols, rows", [(600, 400), (1200, 800)])  # coarser and finer than the plate
def test_the_plate_seam_leaves_no_step(cols, rows):
    """The same kind of check as the inset seam's: across the plate's border in a wide grid, the
    composite follows the field; its step there is no larger than the field's own."""
    field = lambda x, y: 2.0 + np.sin(3.0 * x) + 0.5 * np.cos(2.0 * y)  # noqa: E731
    scene = _field_scene((320, 240), (192, 108), field)
    extent = field_extent(90.0, cols, rows)
    image = scene.resample(cols, rows, extent)[..., 0].astype(np.float64)
    xs = extent.x0 + (np.arange(cols) + 0.5) * extent.width / cols
    ys = extent.y0 + (np.arange(rows) + 0.5) * extent.height / rows
    truth = field(xs[None, :], ys[:, None])
    surround_alone = SpectralScene(layers=(scene.surround,), wavelengths_nm=scene.wavelengths_nm)
    alone = surround_alone.resample(cols, rows, extent)[..., 0].astype(np.float64)
    error, error_alone = np.abs(image - truth), np.abs(alone - truth)
    # Both layers are registered on one field: the composite follows it everywhere to 1e-3 (of values
    # 1-3.5; a surround shifted by half its pixel errs by 0.015, the plate alone outside its field by 3).
    assert error.max() < 1e-3
    # Along the plate's border the blend adds no error of its own: within twice the surround's there.
    border = (np.abs(np.abs(xs[None, :]) - REFERENCE_EXTENT.x1) < 0.02) & (np.abs(ys[:, None]) < REFERENCE_EXTENT.y1)
    assert error[border].mean() < 2 * error_alone[border].mean()


@pytest.mark.slow
def test_a_wide_collection_leaves_the_narrow_cameras_bytes_and_runs_wide_cameras_whole(tmp_path):
    from PIL import Image

    from benchmark.detectors import load_detector
    from benchmark.experiments.run import run_camera
    from benchmark.measure.seam import plate_seam_check
    from metricscenes.generate import generate
    from metricscenes.store import Collection

    require_model("yolov5n-dynamic.onnx")
    detector = load_detector("yolov5n-dynamic", input_size="native", model_dir=model_dir())
    narrow = Collection.open(generate(parse_manifest(TINY), tmp_path / "narrow"))
    wide = Collection.open(generate(parse_manifest({**TINY, "wide_plate": WIDE}), tmp_path / "wide"))
    extra = {p for p in wide.resolved.arrays if p.startswith(("wide_plates/", "wide_frames/"))}
    assert extra == {"wide_plates/env000/sky_day", "wide_frames/env000-d025m/car_lights",
                     "wide_frames/env000-d450m/car_lights"}
    # Every array the narrow collection has, the wide one has with the same bytes (seeds by job, not by manifest).
    assert {p: s for p, s in wide.resolved.arrays.items() if p not in extra} == narrow.resolved.arrays
    assert wide.resolved.illuminance_lux == narrow.resolved.illuminance_lux
    for scene in ("env000-d025m", "env000-d450m"):
        a, b = (c.radiance(scene, "day_lamps") for c in (narrow, wide))
        assert np.array_equal(a.resample(192, 108), b.resample(192, 108))
    # A narrow camera: the same images and AP; a 37° x 24° (16:10), a 120° (16:9) and a 100° (4:3) camera run uncropped.
    cam12 = load_camera("cam12")
    runs = {name: run_camera(c, cam12, "day_lamps", detector, tmp_path / name) for name, c in (("n", narrow), ("w", wide))}
    assert (tmp_path / "n/images.sha256").read_bytes() == (tmp_path / "w/images.sha256").read_bytes()
    assert [r.ap for r in runs["n"].per_distance] == [r.ap for r in runs["w"].per_distance]
    for camera in (_camera("front-37", 960, 600, 3.0, pixel_um=4.2), _camera("wide-120", 1280, 720, 1.552),
                   _camera("wide-100-4x3", 640, 480, 1.128, pixel_um=4.2)):
        with pytest.raises(FieldOfViewError):
            run_camera(narrow, camera, "day", detector, tmp_path / f"{camera.name}-refused")
        result = run_camera(wide, camera, "day", detector, tmp_path / camera.name)
        with Image.open(tmp_path / camera.name / "images/env000-d025m.png") as image:
            assert image.size == (camera.width_px, camera.height_px)
        assert result.camera_geometry.window_tan[2] == pytest.approx(camera.tan_half_width)
        # The plate's border in its image (docs/scenes.md, "The wide plate"): the relative luminance step across
        # it is the surround's and the plate's render noise at 4 spp (0.07; a surround 1.3 x too bright: 0.24).
        seam = plate_seam_check(wide, "env000-d025m", "day_lamps", camera)
        assert seam["step_luminance_max"] < 0.15, seam


def test_a_longer_road_is_the_default_road_and_more():
    """The road beyond the default's end draws from its own stream: up to 395 m a long road has
    the default road's paving, tiles, trees and lamps, draw for draw."""
    import mitsuba as mi

    from metricscenes.assets import roads
    from metricscenes.render import use_variant

    use_variant("scalar_spectral")

    def vertices(parts, name):
        return np.array(mi.traverse(parts.shapes[name])["vertex_positions"]).reshape(-1, 3)

    for road_id in (3, 12):
        short = roads.road_parts(roads.road_spec(road_id), seed=11)
        long = roads.road_parts(roads.road_spec(road_id), seed=11, road_end_m=700.0)
        assert set(short.shapes) < set(long.shapes) and "tree_far_more_trunks" in long.shapes
        assert np.array_equal(vertices(short, "tree_far_trunks"), vertices(long, "tree_far_trunks"))
        for name in [n for n in short.shapes if n.startswith(("road_asphalt_", "road_terrain_"))]:
            short_rows = {tuple(v) for v in vertices(short, name)}
            long_rows = {tuple(v) for v in vertices(long, name)}
            assert short_rows <= long_rows, name
            assert {v for v in long_rows if v[0] < 395.0 - 1e-3} <= short_rows, name
        assert long.lamps[:len(short.lamps)] == short.lamps and len(long.lamps) >= len(short.lamps)
        assert vertices(long, "road_terrain_0")[:, 0].max() >= 700.0  # (10 m tiles: to 705 m)
    with pytest.raises(ValueError, match="road_end_m must be at least 395"):
        roads.road_parts(roads.road_spec(3), road_end_m=300.0)
