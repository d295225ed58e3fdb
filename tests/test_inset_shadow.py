"""render.inset_shadow: the inset window also holds the car's shadow on the road (no rendering)."""

import hashlib
import json
import math

import numpy as np
import pytest

from conftest import REPO
from metricscenes import scene as scene_mod
from metricscenes.assets import skies
from metricscenes.generate import (_inset_film, inset_window, shadow_box_tan, shadow_light_directions,
                                   shadow_vertices)
from metricscenes.groundtruth import car_box_tan
from metricscenes.manifest import load_manifest
from metricscenes.plan import plan_collection


def _with(manifest, **render):
    return manifest.model_copy(update={"render": manifest.render.model_copy(update=render)})


def _window_extent(manifest, window):
    """(x0, y0, x1, y1) in tangent coordinates of an inset_window answer."""
    k, x, y, w, h = window
    g, e = manifest.reference_grid, manifest.reference_grid.field
    big_w, big_h = g.width_px * k, g.height_px * k
    return (e.x0 + x / big_w * e.width, e.y0 + y / big_h * e.height,
            e.x0 + (x + w) / big_w * e.width, e.y0 + (y + h) / big_h * e.height)


def _contains(outer, inner, tol=1e-12):
    return (outer[0] <= inner[0] + tol and outer[1] <= inner[1] + tol
            and outer[2] >= inner[2] - tol and outer[3] >= inner[3] - tol)


def _scenes(manifest):
    for s in plan_collection(manifest):
        pose = scene_mod.car_pose(s.environment, s.distance_m)
        yield s, scene_mod.car_vertices(s.environment, pose)


def test_a_sun_from_the_side_at_45_degrees_casts_a_shadow_as_long_as_the_car_is_high():
    car = np.array([[20.0, -0.9, 0.0], [24.5, 0.9, 0.0], [22.0, 0.5, 1.5], [21.0, -0.5, 1.2]])
    left_45 = (0.0, math.cos(math.radians(45.0)), math.sin(math.radians(45.0)))  # sun on the left (+y)
    shadow = shadow_vertices(car, left_45)
    np.testing.assert_allclose(shadow[:, 2], 0.0)
    np.testing.assert_allclose(shadow[:, 0], car[:, 0])  # straight sideways: nothing along the road
    np.testing.assert_allclose(shadow[:, 1], car[:, 1] - car[:, 2], atol=1e-12)  # as far right as it is high
    assert shadow[:, 1].min() == pytest.approx(-0.5 - 1.2)  # the 1.2 m high point, 1.2 m to its right


def test_the_window_holds_the_projected_shadow(smoke_manifest):
    manifest = _with(smoke_manifest, inset_shadow=True)
    s, vertices = next(_scenes(manifest))
    box = car_box_tan(vertices)
    sun = (0.0, -math.cos(math.radians(45.0)), math.sin(math.radians(45.0)))  # from the right: shadow to the left
    shadow = car_box_tan(shadow_vertices(vertices, sun))
    assert shadow[0] < box[0]  # it reaches beyond the car to the left
    plain = _window_extent(manifest, inset_window(box, manifest))
    grown = _window_extent(manifest, inset_window(box, manifest, shadow))
    assert _contains(grown, shadow) and _contains(grown, box) and _contains(grown, plain)
    # and beyond it the car's own margin (a share of the car's box) and, inside that, the feather ramp
    margin = 0.3 * (box[2] - box[0])
    assert grown[0] <= shadow[0] - margin + 1e-12


def test_every_scene_window_holds_its_skies_shadows():
    manifest = load_manifest(REPO / "manifests" / "quick.yaml")
    assert manifest.render.inset_shadow
    for s, vertices in list(_scenes(manifest))[:12]:
        film, extent = _inset_film(manifest, vertices, s.environment)[:2]
        window = (extent.x0, extent.y0, extent.x1, extent.y1)
        directions = shadow_light_directions(s.environment, manifest.light_groups)
        assert directions  # every environment has a day sky with its sun up
        e = manifest.reference_grid.field
        for d in directions:
            shadow = car_box_tan(shadow_vertices(vertices, d))
            in_field = (max(shadow[0], e.x0), max(shadow[1], e.y0), min(shadow[2], e.x1), min(shadow[3], e.y1))
            assert _contains(window, in_field), s.scene_id


def test_a_light_below_the_horizon_adds_nothing(smoke_manifest):
    dusk = next(i for i in skies.skies_for("dusk"))
    moonless = skies.skies_for("night")[0]
    assert skies.sky_spec(dusk).sun_elevation_deg <= 0.0 and skies.sky_spec(moonless).moon_normal_illuminance_lux == 0
    env = plan_collection(smoke_manifest)[0].environment
    from dataclasses import replace

    env = replace(env, sky_dusk_id=dusk, sky_night_id=moonless)
    assert shadow_light_directions(env, ("sky_dusk", "sky_night", "car_lights")) == []
    assert len(shadow_light_directions(env, ("sky_day",))) == 1
    with pytest.raises(ValueError, match="above the horizon"):
        shadow_vertices(np.zeros((1, 3)), (1.0, 0.0, -0.1))
    # a collection whose skies have no sun or moon up keeps its windows exactly
    manifest = _with(smoke_manifest, inset_shadow=True).model_copy(update={"light_groups": ("sky_dusk",),
                                                                           "conditions": {"dusk": {"sky_dusk": 1.0}},
                                                                           "illuminance_sweep": None})
    vertices = scene_mod.car_vertices(env, scene_mod.car_pose(env, 50.0))
    assert shadow_box_tan(manifest, env, vertices) is None
    assert _inset_film(manifest, vertices, env)[0] == _inset_film(_with(manifest, inset_shadow=None), vertices, env)[0]


# sha256 of the JSON list of every scene's (k, x, y, w, h) without render.inset_shadow, from
# inset_window as it was before the flag existed: unset, the windows (so the bytes) are today's.
# The windows of the manifests as they were before inset_shadow (quick's cap was then 320 px).
OLD_INSET_MAX_PX = {"smoke": 192, "quick": 320}
UNSET_WINDOWS_SHA256 = {
    "smoke": "0191d87a9cb29c8bd56978ff393f111d29541e70a4c24d03cec3e0befbea64c0",
    "quick": "3a240649500c4210cee7229a6b57d078d2d603300cf023ea6bf614d0071e8204",
}


@pytest.mark.parametrize("name", sorted(UNSET_WINDOWS_SHA256))
def test_unset_keeps_every_window(name):
    manifest = _with(load_manifest(REPO / "manifests" / f"{name}.yaml"), inset_shadow=None,
                     inset_max_px=OLD_INSET_MAX_PX[name])
    windows = []
    for s, vertices in _scenes(manifest):
        film = _inset_film(manifest, vertices, s.environment)[0]
        window = (film.width // manifest.reference_grid.width_px, film.crop_x, film.crop_y, *film.size)
        assert window == inset_window(car_box_tan(vertices), manifest)
        windows.append(list(window))
    assert hashlib.sha256(json.dumps(windows).encode()).hexdigest() == UNSET_WINDOWS_SHA256[name]


def test_inset_shadow_is_hashed_only_when_set(smoke_manifest):
    assert smoke_manifest.render.inset_shadow is None  # (smoke's sha256 is pinned in test_store)
    quick = load_manifest(REPO / "manifests" / "quick.yaml")
    before = "b16b81b117d8dce08404f5b2f17831ff43309760b4279f267196a36bddd003d8"  # quick before inset_shadow
    assert _with(quick, inset_shadow=None, inset_max_px=320).sha256() == before
    assert _with(smoke_manifest, inset_shadow=True).sha256() != smoke_manifest.sha256()
    assert _with(smoke_manifest, inset_shadow=False).sha256() != smoke_manifest.sha256()


def test_the_composite_keeps_a_shadow_far_from_the_car_in_a_wide_window():
    """The reader (inset_resolution="car") shows the inset at the plate's resolution away from
    the car's mask: a shadow there, inside a window widened for it, survives the composite."""
    from metricscenes.geometry import TanExtent
    from metricscenes.radiance import RadianceLayer, SpectralScene, car_sharpness

    field = TanExtent(-0.4, -0.2, 0.4, 0.2)
    plate = RadianceLayer(np.ones((40, 80, 2), np.float32), field)  # 0.01 per plate pixel, no car, no shadow
    window = TanExtent(-0.1, 0.0, 0.1, 0.06)  # 20 x 6 plate pixels, 3 times finer
    inset = np.ones((18, 60, 2), np.float32)
    mask = np.zeros((18, 60), bool)
    mask[3:15, 40:54] = True  # the car, on the right
    inset[mask] = 0.5
    inset[9:15, 8:30] = 0.2  # its shadow, far to its left (10-30 inset pixels from the window's edge)
    sharp = car_sharpness(mask, window, plate.pixel_tan)
    assert sharp[9:15, 8:30].max() == 0.0  # the shadow is shown at the plate's resolution
    scene = SpectralScene((plate, RadianceLayer(inset, window, feather=0.05, sharp=sharp)))
    out = scene.resample(320, 160)  # 4 times finer than the plate
    # tangent x -0.06..-0.04 (inset columns 12-18): deep inside the shadow and the ramp's far side
    cols = slice(int((-0.055 + 0.4) / 0.0025), int((-0.045 + 0.4) / 0.0025))
    rows = slice(int((0.036 + 0.2) / 0.0025), int((0.046 + 0.2) / 0.0025))
    np.testing.assert_allclose(out[rows, cols], 0.2, atol=0.02)
    assert out[:60].max() == pytest.approx(1.0) and out[:60].min() == pytest.approx(1.0)  # above the window
