"""Environment assets: roads, trees, street lights and skies (metricscenes.assets)."""

from __future__ import annotations


import mitsuba as mi
import numpy as np
import pytest

mi.set_variant("scalar_spectral")

from metricscenes.render import Film, spectral_film_dict
from metricscenes.assets import roads, skies  # noqa: E402
from metricscenes.assets import beams  # noqa: E402
from metricscenes.assets.streetlights import FACE_SIZE_M, street_light_parts  # noqa: E402
from metricscenes.photometry import luminous_band_sum  # noqa: E402
from metricscenes.spectral import WAVELENGTHS_NM  # noqa: E402


def _scene(parts, emitters=None, lamps_on=False) -> dict:
    d = {"type": "scene", **parts.shapes}
    for lamp in parts.lamps:
        if lamp.shape is None:  # a goniometric spot: light only
            if lamps_on:
                d[lamp.name] = lamp.emitter
            continue
        d[lamp.name] = {**lamp.shape, "emitter": lamp.emitter} if lamps_on else dict(lamp.shape)
    d.update(emitters or {})
    return d


def test_road_library_deterministic_and_in_range():
    lib = roads.road_library()
    assert len(lib) == 20 and [r.road_id for r in lib] == list(range(20))
    assert lib == roads.road_library()
    for r in lib:
        assert 1 <= r.lanes_each_way <= 3
        assert 3.0 <= r.lane_width_m <= 3.75
        assert r.terrain in ("grass", "dirt") and r.centre_style in roads.CENTRE_STYLES
        assert 30.0 <= r.light_spacing_m <= 40.0 and r.lamp_kind in ("led_4000k", "hps")
    assert {r.lanes_each_way for r in lib} == {1, 2, 3}
    assert any(r.trees for r in lib) and not all(r.trees for r in lib)
    assert any(r.street_lights for r in lib) and not all(r.street_lights for r in lib)
    with pytest.raises(ValueError, match="road_id"):
        roads.road_spec(20)


def test_lane_centres():
    spec = roads.road_spec(17)  # three lanes each way
    assert spec.lanes_each_way == 3
    w = spec.lane_width_m
    assert roads.camera_lane_y_m(spec) == 0.0
    assert roads.lane_center_y_m(spec, 0, "same") == 0.0
    assert roads.lane_center_y_m(spec, 0, "oncoming") == pytest.approx(w)
    assert roads.lane_center_y_m(spec, 2, "same") == pytest.approx(-2 * w)
    assert roads.lane_center_y_m(spec, 0, "same", camera_lane=1) == pytest.approx(w)
    assert roads.camera_lane_y_m(spec, camera_lane=2) == pytest.approx(0.0)
    with pytest.raises(ValueError, match="direction"):
        roads.lane_center_y_m(spec, 0, "left")
    with pytest.raises(ValueError, match="lane"):
        roads.lane_center_y_m(roads.road_spec(0), 1, "same")


@pytest.mark.parametrize("road_id", [0, 2, 12, 19])
def test_road_parts_load_and_stay_off_the_corridor(road_id):
    spec = roads.road_spec(road_id)
    parts = roads.road_parts(spec, seed=7)
    scene = mi.load_dict(_scene(parts, lamps_on=True))
    assert all(k.startswith(("road_", "tree_", "streetlight_")) for k in parts.shapes)
    assert all(lamp.light_group == "street_lights" for lamp in parts.lamps)
    assert bool(parts.lamps) == spec.street_lights
    if spec.street_lights:
        assert len(scene.emitters()) == len(parts.lamps) >= 18  # a cover and a spot per luminaire
    yc = roads.centre_line_y_m(spec)
    for key, shape in parts.shapes.items():
        if key.startswith(("tree_", "streetlight_")):
            v = np.array(mi.traverse(shape)["vertex_positions"]).reshape(-1, 3)
            low = v[v[:, 2] < 7.0]  # poles and canopies below the luminaire arms
            assert np.all(np.abs(low[:, 1] - yc) > spec.half_paved_m), key
    # Markings: every white/yellow line lies on the paved road, 1 mm above it.
    for key in ("road_marking_white", "road_marking_yellow"):
        if key in parts.shapes:
            v = np.array(mi.traverse(parts.shapes[key])["vertex_positions"]).reshape(-1, 3)
            assert np.allclose(v[:, 2], roads.MARKING_Z_M)
            assert np.all(np.abs(v[:, 1] - yc) <= spec.half_paved_m)
    # The paved road spans x = -5..395 m and the whole paved width, at z = 0.
    v = np.concatenate([np.array(mi.traverse(s)["vertex_positions"]).reshape(-1, 3)
                        for k, s in parts.shapes.items() if k.startswith("road_asphalt_")])
    assert v[:, 0].min() == pytest.approx(-5.0) and v[:, 0].max() == pytest.approx(395.0)
    assert np.ptp(v[:, 1]) == pytest.approx(2 * spec.half_paved_m, rel=1e-5) and np.all(v[:, 2] == 0)
    # Same seed, same geometry.
    again = roads.road_parts(spec, seed=7).shapes["road_asphalt_0" if "road_asphalt_0" in parts.shapes else "road_far"]
    first = parts.shapes["road_asphalt_0" if "road_asphalt_0" in parts.shapes else "road_far"]
    assert np.array_equal(np.array(mi.traverse(again)["vertex_positions"]),
                          np.array(mi.traverse(first)["vertex_positions"]))


def test_ground_reaches_the_horizon():
    scene = mi.load_dict(_scene(roads.road_parts(roads.road_spec(3), seed=1)))
    for az in np.radians(np.arange(0, 360, 30)):
        d = mi.Vector3f(np.cos(az) * np.cos(1e-3), np.sin(az) * np.cos(1e-3), -np.sin(1e-3))
        assert scene.ray_test(mi.Ray3f(mi.Point3f(0, 0, 1.5), d)), np.degrees(az)


@pytest.mark.parametrize("closed", [False, True])
def test_ground_to_horizon_closes_the_strip_below_the_horizontal(closed):
    """Between the far ground's edge (20 km) and the camera's horizontal lies a strip 0.078 mrad
    tall where nothing is hit (sunsky is black there): ``ground_to_horizon`` closes it with a
    face towards the camera, and nothing rises above the horizontal."""
    scene = mi.load_dict(_scene(roads.road_parts(roads.road_spec(3), seed=1, ground_to_horizon=closed)))
    origin = mi.Point3f(0, 0, 1.5)
    for az in np.radians([-0.5, 0.0, 0.5]):
        for elevation_mrad, hit in ((-0.03, closed), (-0.07, closed), (-0.09, True), (0.01, False)):
            e = elevation_mrad * 1e-3
            d = mi.Vector3f(np.cos(az) * np.cos(e), np.sin(az) * np.cos(e), np.sin(e))
            si = scene.ray_intersect(mi.Ray3f(origin, d))
            assert bool(si.is_valid()) == hit, (np.degrees(az), elevation_mrad)
            if hit:
                assert np.dot(np.ravel(si.n), np.ravel(d)) < 0  # seen from its front: a one-sided diffuse face is lit there


def test_street_light_illuminance_follows_its_candela_table():
    """E = I cos(i) / d² from the luminaire's table (cover + spot), read as L = ρ E / π."""
    flux_lm, height_m, rho = 10_000.0, 9.0, 0.5
    parts = street_light_parts([0.0], pole_y_m=3.0, arm_y_m=0.0, height_m=height_m, flux_lm=flux_lm)
    scene = _scene(parts, lamps_on=True)
    del scene["streetlight_poles"]  # keep only the luminaire, so no shadowing of the measurement
    scene["plane"] = {"type": "rectangle", "to_world": mi.ScalarTransform4f().scale([80, 80, 1]),
                      "bsdf": {"type": "diffuse", "reflectance": {"type": "uniform", "value": rho}}}
    scene["integrator"] = {"type": "path", "max_depth": 2}
    lamp_z = height_m - 0.19
    for x, y in ((0.0, 0.0), (12.0, -1.0), (25.0, -3.0)):  # street side is -y here
        scene["sensor"] = {"type": "perspective", "fov": 0.5, "to_world": mi.ScalarTransform4f().look_at(
                               origin=[x, y + 0.2, 1], target=[x, y, 0], up=[1, 0, 0]),
                           "film": spectral_film_dict(Film(4, 4)), "sampler": {"type": "stratified", "sample_count": 64}}
        radiance = np.asarray(mi.render(mi.load_dict(scene))).reshape(-1, 31).mean(0)
        lux = luminous_band_sum(np.pi * radiance / rho)
        d = np.sqrt(x**2 + y**2 + lamp_z**2)
        table_cd = beams.road_luminaire_cd(flux_lm, x / lamp_z, -y / lamp_z)
        assert lux == pytest.approx(table_cd * lamp_z / d**3, rel=0.05), (x, y)
    assert FACE_SIZE_M[0] * FACE_SIZE_M[1] > 0


def test_sky_library_kinds_and_ranges():
    lib = skies.sky_library()
    assert len(lib) == 30 and lib == skies.sky_library()
    for kind in skies.SKY_KINDS:
        ids = skies.skies_for(kind)
        assert len(ids) == 10 and all(skies.sky_spec(i).kind == kind for i in ids)
        assert all(skies.sky_spec(i).light_group == f"sky_{kind}" for i in ids)
    day = [s for s in lib if s.kind == "day"]
    assert all(15 <= s.sun_elevation_deg <= 70 and 2 <= s.turbidity <= 6 for s in day)
    assert np.ptp([s.sun_azimuth_deg for s in day]) > 90
    assert all(-6 < s.sun_elevation_deg <= 0 for s in lib if s.kind == "dusk")
    night = [s for s in lib if s.kind == "night"]
    assert sum(s.moon_normal_illuminance_lux > 0 for s in night) == 5
    with pytest.raises(ValueError, match="kind"):
        skies.skies_for("noon")
    with pytest.raises(ValueError, match="sky_id"):
        skies.sky_spec(30)


def test_sky_emitters_use_physical_spectra():
    for spec in skies.sky_library():
        em = skies.sky_emitters(spec)
        assert em["sky"]["type"] in ("sunsky", "constant")
        for e in em.values():
            for key in ("radiance", "irradiance"):
                if key in e:
                    assert e[key]["type"] == "irregular"
        mi.load_dict({"type": "scene", **em})
    moon = skies.lunar_spectrum_w_m2_nm(0.2)
    assert luminous_band_sum(np.interp(WAVELENGTHS_NM, skies._GRID_NM, moon)) == pytest.approx(0.2, rel=0.02)


@pytest.mark.parametrize("sky_id", [0, 9, 12, 19, 21, 28])
def test_rendered_illuminance(sky_id):
    spec = skies.sky_spec(sky_id)
    lux = skies.measure_illuminance_lux(skies.sky_emitters(spec), size_px=8, spp=4)
    if spec.kind == "day":
        assert 10_000 < lux < 130_000
    else:
        assert lux == pytest.approx(skies.expected_illuminance_lux(spec), rel=0.05)
        lo, hi = (10.0, 1000.0) if spec.kind == "dusk" else (1e-3, 0.3)
        assert lo < lux < hi


def test_dusk_calibration_table():
    e = {"sky": {"type": "sunsky", "turbidity": 3.0, "albedo": 0.15, "sun_direction": skies._direction(0.5, 40.0),
                 "sun_scale": 0.0, "sky_scale": 1.0}}
    lux = skies.measure_illuminance_lux(e, size_px=8, spp=64)
    assert lux == pytest.approx(skies._DUSK_UNIT_SKY_LUX[3], rel=0.03)
    assert skies.twilight_illuminance_lux(-6.0) == pytest.approx(2.8)
    with pytest.raises(ValueError, match="sun_elevation_deg"):
        skies.twilight_illuminance_lux(3.0)
