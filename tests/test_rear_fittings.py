"""What a car carries at night: the rear plate lit by its lamp (UN ECE R4)
and two red rear retro-reflectors (UN ECE R3 class IA) returning the camera car's low beams.
Opt-in through the manifest (``render.plate_lamp``, ``render.rear_retroreflectors``); one
tiny render shows them where they belong."""

from __future__ import annotations

import colour
import numpy as np
import pytest
from scipy.ndimage import map_coordinates

from metricscenes.assets import beams, cars, ego_vehicle, lamps, materials
from metricscenes.assets import retroreflection as rr
from metricscenes.manifest import parse_manifest
from metricscenes.photometry import luminous_trapezoid

mi = pytest.importorskip("mitsuba")


@pytest.fixture(scope="module", autouse=True)
def _spectral_variant():
    mi.set_variant("scalar_spectral")


def _luminance(emitter: dict) -> float:
    spec = emitter["radiance"]
    wl, values = (np.array(spec[k].split(","), float) for k in ("wavelengths", "values"))
    return luminous_trapezoid(wl, values)


def _world_fittings(spec, position, yaw):
    """{key: (centre, normal, rect)} of a placed car's rear fittings, world m."""
    m = cars._world(position, yaw)
    return {lr.key: (m[:3, :3] @ lr.centre + m[:3, 3], m[:3, :3] @ lr.normal, lr) for lr in cars.rear_fittings(spec)}


# --- R3: the coefficient of luminous intensity ---------------------------------------------

def test_cil_hits_r3_table_and_is_log_linear_between_and_beyond():
    red = rr.RED_COLOUR_FACTOR
    assert red == 0.25
    assert rr.cil_red_cd_per_lx(20 / 60) == pytest.approx(red * 0.300, rel=1e-12)  # 300 mcd/lx at 20'
    assert rr.cil_red_cd_per_lx(1.5) == pytest.approx(red * 0.005, rel=1e-12)  # 5 mcd/lx at 1°30'
    # Held below 20' (R3 states nothing nearer the axis).
    np.testing.assert_allclose(rr.cil_red_cd_per_lx([0.0, 0.1, 0.3]), red * 0.3, rtol=1e-12)
    # Log-linear: the geometric mean half way; beyond 1°30' the same slope.
    mid = 0.5 * (20 / 60 + 1.5)
    assert rr.cil_red_cd_per_lx(mid) == pytest.approx(red * np.sqrt(0.3 * 0.005), rel=1e-12)
    step = 1.5 - 20 / 60
    assert rr.cil_red_cd_per_lx(1.5 + step) == pytest.approx(red * 0.005 * (0.005 / 0.3), rel=1e-12)
    alphas = np.linspace(0.0, 4.0, 81)
    assert np.all(np.diff(rr.cil_red_cd_per_lx(alphas)) <= 0)


def test_divergence_angle_and_facing():
    assert rr.divergence_angle_deg((0, 0, 0), (10, 0, 0), (0, 10, 0)) == pytest.approx(90.0)
    assert rr.divergence_angle_deg((100, 0, 0), (0, 0, 0), (0, 0, 100 * np.tan(np.radians(1.5)))) == pytest.approx(1.5)
    # Light from behind the reflector's face returns nothing.
    lamp = ego_vehicle.lamp_positions_m()[0]
    assert rr.perpendicular_illuminance_lux((50.0, 0.7, 0.5), (1.0, 0.0, 0.0), lamp) == 0.0
    assert rr.returned_intensity_cd((50.0, 0.7, 0.5), (1.0, 0.0, 0.0)) == 0.0


def test_beam_angles_are_those_the_ego_spot_projects():
    """(h, v) of a point, from the ego spot's own transform and the texture's angle formula
    (:func:`beams.beam_texture`), equal :func:`rr.beam_angles_deg`'s."""
    for lamp in ego_vehicle.lamp_positions_m():
        spot = beams.head_lamp_spot("low", ego_vehicle.LAMP_SPECTRUM, lamp, (1.0, 0.0, 0.0))
        to_local = np.linalg.inv(np.array(spot["to_world"].matrix, float))
        for point in ((25.0, 0.9, 0.5), (50.0, -1.3, 0.62), (120.0, 3.0, 0.4), (200.0, -0.2, 0.9)):
            x, y, z = (to_local @ np.r_[point, 1.0])[:3]
            h = np.degrees(np.arctan(-x / z))
            v = np.degrees(np.arctan(y / z * np.cos(np.radians(h))))
            np.testing.assert_allclose(rr.beam_angles_deg(lamp, point), (h, v), atol=1e-5)  # (float32 transform)


def _texture_illuminance_lux(point, lamp) -> float:
    """E⊥ from the ego spot's texture (what the renderer projects), bilinear as Mitsuba reads it."""
    texture = beams.beam_texture("low", 0.0)
    t = np.tan(np.radians(texture.cutoff_deg))
    rows, cols = texture.relative.shape
    dx, dy, dz = np.asarray(point, float) - np.asarray(lamp, float)
    col = ((dy / dx) / t + 1) / 2 * cols - 0.5  # column 0: the lamp's right (local -x = world -y)
    row = ((dz / dx) / t + 1) / 2 * rows - 0.5  # row 0: down
    rel = map_coordinates(texture.relative.astype(float), [[row], [col]], order=1, mode="nearest")[0]
    return texture.peak_cd * rel / (dx * dx + dy * dy + dz * dz)


def test_reflector_illuminance_matches_the_rendered_beam():
    """E⊥ on the reflectors of a car going away, 25-200 m, against the spot texture: equal
    where the beam is smooth, within 14 % near the cut-off's elbow (h = 0, where the
    texture's 0.39°-wide columns average the kink)."""
    spec = cars.car_spec(0)
    ratios = []
    for d in (25.0, 50.0, 100.0, 200.0):
        for key, (centre, _, lr) in _world_fittings(spec, (d, 0.0), 0.0).items():
            if lr.role != cars.REFLECTOR_ROLE:
                continue
            for lamp in ego_vehicle.lamp_positions_m():
                e = rr.perpendicular_illuminance_lux(centre, (-1.0, 0.0, 0.0), lamp)
                ratio = e / _texture_illuminance_lux(centre, lamp)
                ratios.append(ratio)
                if abs(rr.beam_angles_deg(lamp, centre)[0]) > 1.0:
                    assert ratio == pytest.approx(1.0, abs=0.025), (d, key, lamp)
    assert 0.86 < min(ratios) and max(ratios) < 1.02


def test_reflector_emitter_returns_cil_times_e_to_the_camera():
    spec = cars.car_spec(0)
    for d, yaw in ((25.0, 0.0), (50.0, 0.05), (100.0, -0.03), (200.0, 0.0)):
        parts = cars.car_parts(spec, (d, 0.4), yaw, rear_retroreflectors=True)
        placed = _world_fittings(spec, (d, 0.4), yaw)
        reflectors = [lamp for lamp in parts.lamps if lamp.light_group == "ego_lights"]
        assert {lamp.name for lamp in reflectors} == {k for k, v in placed.items() if v[2].role == "reflector"}
        for lamp in reflectors:
            centre, normal, lr = placed[lamp.name]
            rearward = -cars._world((d, 0.4), yaw)[:3, 0]
            # I = Σ CIL(α_i) E⊥,i, evaluated here term by term.
            expected = sum(rr.cil_red_cd_per_lx(rr.divergence_angle_deg(centre, l, ego_vehicle.CAMERA_POSITION_M))
                           * rr.perpendicular_illuminance_lux(centre, rearward, l)
                           for l in ego_vehicle.lamp_positions_m())
            assert expected > 0
            to_camera = np.asarray(ego_vehicle.CAMERA_POSITION_M) - centre
            cos = np.dot(normal, to_camera) / np.linalg.norm(to_camera)
            # Photometric round trip: the emitter's luminance x its area seen from the camera.
            assert _luminance(lamp.emitter) * lr.area_m2 * cos == pytest.approx(expected, rel=1e-6)
            assert lamp.emitter["sampling_weight"] == 0.0


def test_returned_light_is_ece_red():
    """The returned spectrum (beam x red filter) is inside the ECE red boundaries, and the
    filter passes about R3's red factor of illuminant A's light."""
    cmfs = colour.MSDS_CMFS["CIE 1931 2 Degree Standard Observer"]
    wl = lamps.LAMP_NM
    bar = np.stack([np.interp(wl, cmfs.wavelengths, cmfs.values[:, i]) for i in range(3)])
    for source in ("illuminant_a", ego_vehicle.LAMP_SPECTRUM, "halogen"):
        _, values = lamps.retroreflected_red(source, 1.0)
        xyz = np.trapezoid(values * bar, wl, axis=1)
        x, y, z = xyz / xyz.sum()
        assert y <= 0.335 and z <= 0.008, source
    a = lamps.relative_spd("illuminant_a")
    share = luminous_trapezoid(wl, a * lamps.red_reflector_transmission(wl)) / luminous_trapezoid(wl, a)
    assert share == pytest.approx(rr.RED_COLOUR_FACTOR, abs=0.015)


# --- R4: the plate lamp ---------------------------------------------------------------------

def test_plate_lamp_gives_r4_minimum_luminance_with_a_w5w_spectrum():
    rho = materials.reflectance("plate_white", lamps.LAMP_NM)
    wl, radiance = lamps.plate_lamp(rho)
    white = radiance / rho  # the lamp's light on a diffuser of reflection factor 1.0 (R4 §8)
    assert luminous_trapezoid(wl, white) == pytest.approx(2.5, rel=1e-9)
    a = colour.SDS_ILLUMINANTS["A"]
    np.testing.assert_allclose(white / white.max(), np.interp(wl, a.wavelengths, a.values) /
                               np.interp(wl, a.wavelengths, a.values).max(), rtol=1e-9)
    rho_v = luminous_trapezoid(wl, rho * white) / luminous_trapezoid(wl, white)
    assert 0.75 < rho_v < 0.8

    spec = cars.car_spec(3)
    parts = cars.car_parts(spec, (40.0, 0.0), 0.0, plate_lamp=True)
    (plate,) = [lamp for lamp in parts.lamps if lamp.name.endswith("_platelamp")]
    assert plate.light_group == "car_lights" and plate.emitter["sampling_weight"] == 0.0
    # One uniform radiance over the plate: every R4 measuring point gets the same luminance.
    assert _luminance(plate.emitter) == pytest.approx(rho_v * 2.5, rel=1e-6)
    assert plate.shape["bsdf"] == materials.bsdf("plate_white")


# --- placement (R48) and what each switch adds ----------------------------------------------

def test_fittings_sit_where_r48_puts_them_on_every_car():
    for spec in cars.car_library():
        fittings = {lr.role: lr for lr in cars.rear_fittings(spec) if lr.role != cars.REFLECTOR_ROLE}
        reflectors = [lr for lr in cars.rear_fittings(spec) if lr.role == cars.REFLECTOR_ROLE]
        assert len(reflectors) == 2 and set(fittings) == {cars.PLATE_LAMP_ROLE}
        for lr in reflectors:
            corners = lr.corners()
            assert 0.25 <= corners[:, 2].min() and corners[:, 2].max() <= 0.90, spec  # height
            assert 0.5 * spec.width_m - np.abs(corners[:, 1]).max() <= 0.40, spec  # near the sides
            assert np.abs(corners[:, 1]).min() >= 0.30, spec  # inner edges >= 600 mm apart
            assert lr.centre[0] < -0.45 * spec.length_m and lr.normal[0] < -0.93  # at the rear, facing back
        plate = fittings[cars.PLATE_LAMP_ROLE]
        (patch,) = [p for p in cars.car_geometry(spec).meshes if p.key.endswith("_plate_r")]
        # The plate stays behind its lit face: every vertex behind the rectangle's plane.
        assert np.max((patch.vertices - plate.centre) @ plate.normal) < 0.0, spec
        assert plate.area_m2 == pytest.approx(0.52 * 0.11)
        # Reflectors clear of the plate and the tail lamps.
        tails = [lr for lr in cars.car_geometry(spec).lamps if lr.role == "tail"]
        for lr in reflectors:
            for other in [plate, *tails]:
                apart_y = abs(lr.centre[1] - other.centre[1]) >= lr.half_m[0] + other.half_m[0]
                apart_z = abs(lr.centre[2] - other.centre[2]) >= lr.half_m[1] + other.half_m[1]
                assert apart_y or apart_z, (spec.car_id, other.key)


def test_switches_add_only_their_fittings_and_groups():
    spec = cars.car_spec(0)
    plain = cars.car_parts(spec, (50.0, 0.0), 0.0)
    both = cars.car_parts(spec, (50.0, 0.0), 0.0, plate_lamp=True, rear_retroreflectors=True)
    keys = {lr.key: lr.role for lr in cars.rear_fittings(spec)}
    assert not set(keys) & (set(plain.shapes) | {lamp.name for lamp in plain.lamps})
    assert set(both.shapes) == set(plain.shapes)
    assert [(lamp.name, lamp.light_group) for lamp in both.lamps[:len(plain.lamps)]] == \
        [(lamp.name, lamp.light_group) for lamp in plain.lamps]
    added = {lamp.name: lamp.light_group for lamp in both.lamps[len(plain.lamps):]}
    assert added == {k: ("car_lights" if role == "plate" else "ego_lights") for k, role in keys.items()}
    # Lights off: a plain plate, but the reflectors still return the ego beams.
    off = cars.car_parts(spec, (50.0, 0.0), 0.0, "off", plate_lamp=True, rear_retroreflectors=True)
    assert {lamp.light_group for lamp in off.lamps} == {"ego_lights"}
    assert sum(k.endswith("_platelamp") for k in off.shapes) == 1
    # An oncoming car's reflectors face away from the beams: lenses only; its plate lamp lights its rear.
    oncoming = cars.car_parts(spec, (50.0, -3.5), np.pi, plate_lamp=True, rear_retroreflectors=True)
    assert not [lamp for lamp in oncoming.lamps if lamp.light_group == "ego_lights"]
    assert sum("_reflector_" in k for k in oncoming.shapes) == 2
    for parts in (both, off, oncoming):  # they load
        for lamp in parts.lamps:
            mi.load_dict({**lamp.shape, "emitter": lamp.emitter} if lamp.shape else lamp.emitter)


TINY = {
    "name": "fittings", "protocol": "smoke", "seed": 12, "environments": 1, "distances_m": [100],
    "reference_grid": {"width_px": 96, "height_px": 54},
    "render": {"plate_spp": 4, "inset_spp": 4, "inset_pixel_mrad": 0.1, "inset_max_px": 320, "max_depth": 3,
               "plate_lamp": True, "rear_retroreflectors": True},
    "light_groups": ["sky_night", "car_lights", "ego_lights"],
    "conditions": {"night": {"sky_night": 1.0, "car_lights": 1.0, "ego_lights": 1.0}},
}


def test_switches_are_hashed_only_when_set():
    plain = {**TINY, "render": {k: v for k, v in TINY["render"].items()
                                if k not in ("plate_lamp", "rear_retroreflectors")}}
    hashes = {parse_manifest(plain).sha256()}
    for render in ({"plate_lamp": True}, {"rear_retroreflectors": True}, {"plate_lamp": False}):
        hashes.add(parse_manifest({**plain, "render": {**plain["render"], **render}}).sha256())
    assert len(hashes) == 4
    assert parse_manifest({**plain, "render": {**plain["render"], "plate_lamp": None}}).sha256() == \
        parse_manifest(plain).sha256()


@pytest.mark.slow
@pytest.mark.parametrize("variant", ["scalar_spectral", "llvm_ad_spectral"])
def test_the_reflectors_show_in_the_ego_lights_inset_and_the_plate_in_car_lights(tmp_path, variant):
    """A car going away at 100 m at night, insets at 0.1 mrad: at each reflector the
    ego_lights inset has the emitter's luminance (the red lens's own share of the beams is
    a few per cent) and is far brighter than the body above it; the plate shows R4's
    luminance in car_lights. Also with the one-pass light groups of a JIT variant (which
    never choose a zero-weight emitter for next-event estimation), rendered in worker
    processes (the variant is global to a process)."""
    import zarr

    from metricscenes import scene as scene_mod
    from metricscenes.generate import generate
    from metricscenes.geometry import TanExtent, tan_to_grid, world_to_tan
    from metricscenes.photometry import radiance_to_xyz
    from metricscenes.plan import plan_collection
    from metricscenes.render import RenderError, check_variant

    try:
        check_variant(variant)
    except RenderError as exc:
        pytest.skip(f"{variant} does not render here: {exc}")
    manifest = parse_manifest({**TINY, "render": {**TINY["render"], "variant": variant}})
    generate(manifest, tmp_path / "c", workers=1 if variant == "scalar_spectral" else 2)
    (scene,) = plan_collection(manifest)
    assert scene.environment.heading == "away"
    pose = scene_mod.car_pose(scene.environment, scene.distance_m)
    parts = scene_mod.car_parts(scene.environment, pose, plate_lamp=True, rear_retroreflectors=True)
    emitted = {lamp.name: _luminance(lamp.emitter) for lamp in parts.lamps if lamp.emitter["type"] == "area"}
    store = zarr.open_group(str(tmp_path / "c" / "radiance.zarr"), mode="r")
    spec = cars.car_spec(scene.environment.car_id)
    for group in ("ego_lights", "car_lights"):
        array = store[f"insets/{scene.scene_id}/{group}"]
        luminance = radiance_to_xyz(np.asarray(array[...]))[..., 1]
        extent = TanExtent(*array.attrs["extent_tan"])
        for key, (centre, _, lr) in _world_fittings(spec, (pose.x_m, pose.y_m), pose.yaw_rad).items():
            col, row = tan_to_grid(world_to_tan(centre[None]), extent, luminance.shape[1], luminance.shape[0])[0]
            i, j = int(row), int(col)
            seen = luminance[i - 1:i + 2, j - 1:j + 2].mean()
            if lr.role == cars.REFLECTOR_ROLE and group == "ego_lights":
                assert seen == pytest.approx(emitted[key], rel=0.25), key
                assert seen > 10 * luminance[i - 8:i - 5, j - 1:j + 2].mean(), key  # the body above it
            elif lr.role == cars.PLATE_LAMP_ROLE and group == "car_lights":
                assert seen == pytest.approx(emitted[key], rel=0.1), key
            elif lr.role == cars.REFLECTOR_ROLE:
                assert seen < 0.1 * emitted[key], key  # no reflector in the car's own lamps
