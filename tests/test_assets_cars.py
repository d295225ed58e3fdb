"""Tests of the procedural car library, spectral materials and lamp photometry."""

from __future__ import annotations

from collections import Counter

import colour
import numpy as np
import pytest

from metricscenes.assets import beams  # noqa: E402
from metricscenes.assets import cars, lamps, materials
from metricscenes.assets.parts import Lamp, SceneParts, spectrum
from metricscenes.photometry import luminous_trapezoid, photopic_v
from metricscenes.spectral import WAVELENGTHS_NM

mi = pytest.importorskip("mitsuba")


@pytest.fixture(scope="module", autouse=True)
def _spectral_variant():
    mi.set_variant("scalar_spectral")


# --- library ---------------------------------------------------------------------------

def test_library_has_50_cars_over_at_least_6_styles():
    lib = cars.car_library()
    assert [s.car_id for s in lib] == list(range(50)) == cars.CAR_IDS
    styles = Counter(s.body_style for s in lib)
    assert len(styles) >= 6
    assert set(styles) <= set(cars.BODY_STYLES)
    assert len({s.paint for s in lib}) >= 5


def test_dimensions_in_real_car_ranges():
    for s in cars.car_library():
        assert 3.6 <= s.length_m <= 5.5, s
        assert 1.65 <= s.width_m <= 2.05, s
        assert 1.3 <= s.height_m <= 2.0, s
        assert 0.5 * s.length_m < s.wheelbase_m < s.length_m - 1.2, s
        assert s.track_m + s.tyre_width_m < s.width_m


def test_mesh_extents_match_spec():
    for cid in (0, 1, 2, 4, 6, 8, 9):
        s = cars.car_spec(cid)
        v = cars.car_vertices_world(s, (0.0, 0.0), 0.0)
        assert s.length_m <= np.ptp(v[:, 0]) <= s.length_m + 0.08  # lamps/plates stand proud
        assert v[:, 2].max() == pytest.approx(s.height_m, abs=0.03)
        assert v[:, 2].min() == pytest.approx(0.0, abs=1e-6)  # tyres touch the ground
        body = next(p for p in cars.car_geometry(s).meshes if p.key.endswith("_body"))
        assert np.ptp(body.vertices[:, 0]) == pytest.approx(s.length_m, abs=0.005)
        assert np.ptp(body.vertices[:, 1]) == pytest.approx(s.width_m, abs=0.01)


def test_deterministic_and_seeded():
    a = cars.car_vertices_world(cars.car_spec(3), (40.0, 1.5), 0.3)
    cars.car_geometry.cache_clear()
    b = cars.car_vertices_world(cars.car_spec(3), (40.0, 1.5), 0.3)
    np.testing.assert_array_equal(a, b)
    assert cars.car_spec(3) == cars.car_spec(3)
    assert cars.car_spec(3) != cars.car_spec(13)


def test_world_placement_and_yaw():
    s = cars.car_spec(0)
    local = cars.car_vertices_world(s, (0.0, 0.0), 0.0)
    world = cars.car_vertices_world(s, (25.0, -2.0), np.pi)
    np.testing.assert_allclose(world[:, 0], 25.0 - local[:, 0], atol=1e-9)
    np.testing.assert_allclose(world[:, 1], -2.0 - local[:, 1], atol=1e-9)
    np.testing.assert_allclose(world[:, 2], local[:, 2])
    heads = [lr for lr in cars.car_geometry(s).lamps if lr.role == "head"]
    assert all(lr.centre[0] > 0.4 * s.length_m for lr in heads)  # head lamps at the front (+x)


def test_library_meshes_have_plausible_triangle_counts():
    # (Their build time is not a test's business: the timed assert failed under load.)
    cars.car_geometry.cache_clear()
    geos = [cars.car_geometry(s) for s in cars.car_library()]
    for g in geos:
        n_tri = sum(len(p.faces) for p in g.meshes)
        assert 3000 < n_tri < 40000


def test_bad_input_is_refused():
    with pytest.raises(ValueError, match="car_id"):
        cars.car_spec(50)
    with pytest.raises(ValueError, match="lights"):
        cars.car_parts(cars.car_spec(0), (25.0, 0.0), 0.0, lights="party")


# --- Mitsuba scene parts ---------------------------------------------------------------

def _scene(parts: SceneParts, with_lamps: bool) -> dict:
    d = {
        "type": "scene",
        "integrator": {"type": "path", "max_depth": 4},
        "sky": {"type": "sunsky", "sun_direction": [0.5, 0.5, 0.7]},
        "sensor": {
            "type": "perspective", "fov": 34.3,
            "to_world": mi.ScalarTransform4f().look_at(origin=[0, 0, 1.5], target=[1, 0, 1.5], up=[0, 0, 1]),
            "film": {"type": "hdrfilm", "width": 16, "height": 16, "rfilter": {"type": "box"}},
            "sampler": {"type": "independent", "sample_count": 4},
        },
        "ground": {"type": "rectangle", "to_world": mi.ScalarTransform4f().scale([500, 500, 1]),
                   "bsdf": materials.bsdf("asphalt")},
    }
    d.update(parts.shapes)
    for lamp in parts.lamps:
        if lamp.shape is None:
            if with_lamps:
                d[lamp.name] = lamp.emitter
        else:
            d[lamp.name] = {**lamp.shape, "emitter": lamp.emitter} if with_lamps else lamp.shape
    return d


@pytest.mark.parametrize("car_id,yaw", [(0, 0.0), (8, np.pi)])
def test_parts_load_and_render(car_id, yaw):
    parts = cars.car_parts(cars.car_spec(car_id), (10.0, 0.0), yaw)
    assert all(k.startswith("car_") for k in parts.shapes)
    assert len({lamp.name for lamp in parts.lamps} | set(parts.shapes)) == len(parts.lamps) + len(parts.shapes)
    assert {lamp.light_group for lamp in parts.lamps} == {"car_lights"}
    roles = Counter("head" if "head" in lamp.name else "tail" for lamp in parts.lamps if lamp.shape)
    assert roles == {"head": 2, "tail": 2}
    for with_lamps in (False, True):
        img = np.array(mi.render(mi.load_dict(_scene(parts, with_lamps)), spp=4))
        assert np.all(np.isfinite(img)) and img.mean() > 0


def test_lights_off_keeps_lenses_without_emitters():
    parts = cars.car_parts(cars.car_spec(1), (25.0, 0.0), 0.0, lights="off")
    assert parts.lamps == ()
    assert sum("lamp" in k for k in parts.shapes) == 4


def test_car_lamp_intensities_in_documented_ranges():
    spec = cars.car_spec(0)
    geo = {lr.key: lr for lr in cars.car_geometry(spec).lamps}
    for mode, tail_key in (("auto", "tail"), ("brake", "brake")):
        for lamp in cars.car_parts(spec, (25.0, 0.0), 0.0, lights=mode).lamps:
            spec_dict = lamp.emitter["radiance" if lamp.emitter["type"] == "area" else "intensity"]
            wl = np.array(spec_dict["wavelengths"].split(","), float)
            val = np.array(spec_dict["values"].split(","), float)
            if lamp.emitter["type"] == "spot":  # the low beam's peak, minus the lens
                beam = beams.beam_texture("low", beams.HEADLAMP_LENS_CD)
                assert luminous_trapezoid(wl, val) == pytest.approx(beam.peak_cd, rel=1e-3)
                continue
            cd = luminous_trapezoid(wl, val) * geo[lamp.name].area_m2
            if "head" in lamp.name:
                assert cd == pytest.approx(beams.HEADLAMP_LENS_CD, rel=1e-3)
                continue
            lo, typ, hi = lamps.INTENSITY_RANGES_CD[tail_key]
            assert lo <= cd <= hi, (lamp.name, cd)
            assert cd == pytest.approx(typ, rel=1e-3)


# --- lamps -------------------------------------------------------------------------------

def test_photopic_and_scaling_oracles():
    assert photopic_v(np.array([555.0]))[0] == pytest.approx(1.0, abs=1e-3)
    # 1/683 W/sr of 555 nm light is 1 cd: narrow band of 1 nm width
    wl = np.array([554.0, 555.0, 556.0])
    assert luminous_trapezoid(wl, [0.0, 1.0 / 683.0, 0.0]) == pytest.approx(1.0, rel=1e-3)
    for kind in lamps.SPD_KINDS:
        wl, val = lamps.scaled_to_luminous(kind, 1234.0)
        assert luminous_trapezoid(wl, val) == pytest.approx(1234.0, rel=1e-9)
        assert np.all(val >= 0)


def test_lamp_spectra_have_the_right_colour():
    def peak(kind):
        return lamps.LAMP_NM[np.argmax(lamps.relative_spd(kind))]

    assert 620 <= peak("red_led") <= 640
    assert 580 <= peak("hps") <= 600  # sodium D lines region
    led = lamps.relative_spd("led_4000k")
    assert 440 <= lamps.LAMP_NM[np.argmax(led[lamps.LAMP_NM < 500])] <= 465  # blue pump
    halo = lamps.relative_spd("halogen")
    assert halo[-1] == pytest.approx(1.0)  # rising towards the red


def test_lamp_input_checks():
    with pytest.raises(ValueError):
        lamps.headlamp("xenon")
    with pytest.raises(ValueError):
        lamps.tail_lamp(lens_area_m2=0.0)
    with pytest.raises(ValueError):
        lamps.relative_spd("candle")


# --- materials -----------------------------------------------------------------------------

def test_all_material_bsdfs_load():
    for name in ("asphalt", "lane_white", "lane_yellow", "grass", "dirt", "bark", "leaves",
                 "concrete", "rubber", "chrome", "glass"):
        assert name in materials.MATERIALS
    for name in materials.MATERIALS:
        mi.load_dict(materials.bsdf(name))
    for paint in materials.PAINTS:
        mi.load_dict(materials.car_paint_bsdf(paint))
    with pytest.raises(ValueError):
        materials.bsdf("unobtainium")


def test_paint_spectra_reproduce_their_target_colours():
    shape = colour.SpectralShape(360, 780, 5)
    cmfs = colour.MSDS_CMFS["CIE 1931 2 Degree Standard Observer"].copy().align(shape)
    d65 = colour.SDS_ILLUMINANTS["D65"].copy().align(shape)
    for paint, target in materials.PAINT_LINEAR_SRGB.items():
        r = materials.paint_reflectance(paint, shape.wavelengths)
        assert np.all((r >= 0) & (r <= 1))
        sd = colour.SpectralDistribution(r, shape.wavelengths)
        xyz = colour.sd_to_XYZ(sd, cmfs, d65) / 100.0
        rgb = colour.XYZ_to_RGB(xyz, colour.RGB_COLOURSPACES["sRGB"], apply_cctf_encoding=False)
        np.testing.assert_allclose(rgb, target, atol=0.03, err_msg=paint)


def test_natural_reflectances_are_plausible():
    g = materials.reflectance("grass")
    wl = WAVELENGTHS_NM
    assert g[wl == 550] > g[wl == 450] and g[wl == 550] > g[wl == 670]  # green peak, chlorophyll trough
    assert np.all(materials.reflectance("asphalt") < 0.15)
    assert materials.reflectance("lane_white").mean() > 0.6
    y = materials.reflectance("lane_yellow")
    assert y[wl == 600] > 4 * y[wl == 450]


# --- parts ---------------------------------------------------------------------------------

def test_scene_parts_merge_and_spectrum_checks():
    a = SceneParts({"car_a": {"type": "sphere"}}, (Lamp("l1", "car_lights", None, {"type": "point"}),))
    b = SceneParts({"road": {"type": "rectangle"}})
    m = a.merged(b)
    assert set(m.shapes) == {"car_a", "road"} and len(m.lamps) == 1
    with pytest.raises(ValueError, match="duplicate"):
        m.merged(a)
    with pytest.raises(ValueError):
        Lamp("x", "sky_day", None, {})
    with pytest.raises(ValueError):
        spectrum([500, 400], [1, 1])
    d = spectrum([400, 700], [0.25, 0.5])
    assert d["type"] == "irregular"
