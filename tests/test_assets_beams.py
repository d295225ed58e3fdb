"""Lamp photometry: head-lamp beams against SAE J1383 and ECE R112, the ego vehicle's road
illuminance, and road luminaires against their IES/CIE class (metricscenes.assets.beams)."""

from __future__ import annotations

import numpy as np
import pytest

from metricscenes.render import illuminance_meter, use_variant

mi = use_variant("scalar_spectral")

from metricscenes.assets import beams, ego_vehicle  # noqa: E402
from metricscenes.photometry import radiance_to_xyz  # noqa: E402


def _low_beam_with_lens(h, v):
    """What leaves a car's head lamp: the spot (beam minus lens, clipped) plus the lens."""
    lens = beams.HEADLAMP_LENS_CD * np.cos(np.radians(h)) * np.cos(np.radians(v))
    return np.maximum(beams.low_beam_cd(h, v), lens)


@pytest.mark.parametrize("intensity", [beams.low_beam_cd, _low_beam_with_lens])
@pytest.mark.parametrize("table", [beams.SAE_J1383_LOW_BEAM, beams.ECE_R112_CLASS_B_LOW_BEAM])
def test_low_beam_meets_every_test_point(intensity, table):
    assert beams.check_test_points(intensity, table) == []


def test_high_beam_meets_sae_j1383():
    assert beams.check_test_points(beams.high_beam_cd, beams.SAE_J1383_HIGH_BEAM) == []


def test_test_point_check_can_fail():
    assert beams.check_test_points(lambda h, v: 0.5 * beams.low_beam_cd(h, v), beams.ECE_R112_CLASS_B_LOW_BEAM)
    assert beams.check_test_points(beams.high_beam_cd, beams.ECE_R112_CLASS_B_LOW_BEAM)  # glare at B50L


def test_low_beam_cutoff_is_sharp_and_asymmetric():
    # ECE R112 Annex 9: gradient G = log10 I(β) - log10 I(β + 0.1°) >= 0.13 across the cut-off.
    v_c = beams.LOW_BEAM_CUTOFF_DEG
    gradient = np.log10(beams.low_beam_cd(-3.0, v_c) / beams.low_beam_cd(-3.0, v_c + 0.1))
    assert gradient >= 0.13
    # Kerb side (right) is lit higher than the oncoming side at the same angle off axis.
    assert beams.low_beam_cd(4.0, 0.2) > 10 * beams.low_beam_cd(-4.0, 0.2)


def _ego_scene(group: str) -> dict:
    scene = {"type": "scene", "integrator": {"type": "path", "max_depth": 2}}
    for lamp in ego_vehicle.ego_lamp_parts().lamps:
        if lamp.light_group == group:
            scene[lamp.name] = mi.load_dict(lamp.emitter)
    return scene


def _road_lux(scene: dict, x: float, y: float) -> float:
    return float(radiance_to_xyz(illuminance_meter(scene, height_m=0.0, at_xy_m=(x, y)))[1])


def _analytic_road_lux(beam: str, x: float, y: float) -> float:
    total = 0.0
    for lx, ly, lz in ego_vehicle.lamp_positions_m():
        dx, dy = x - lx, y - ly
        d = np.sqrt(dx**2 + dy**2 + lz**2)
        h = np.degrees(np.arctan2(-dy, dx))
        v = np.degrees(np.arctan2(-lz, np.hypot(dx, dy)))
        total += float(beams.BEAMS[beam](h, v)) * lz / d**3
    return total


@pytest.mark.parametrize("group", ["ego_lights", "ego_high_beam"])
def test_ego_beam_renders_its_distribution(group):
    scene = _ego_scene(group)
    beam = ego_vehicle.GROUPS[group]
    for x, y in ((10.0, 0.0), (25.0, 0.0), (50.0, 0.0), (25.0, -3.0), (25.0, 3.0)):
        assert _road_lux(scene, x, y) == pytest.approx(_analytic_road_lux(beam, x, y), rel=0.02), (x, y)


def test_ego_low_beam_road_illuminance_inside_the_regulation():
    """Horizontal illuminance on the lane axis, E = Σ I h / d³, must lie where ECE R112's
    limits put it: at 25 m the lamps reach the road 1.6° down (25L/25R: >= 1700 cd), at 50 m
    0.8° down (50V: >= 5100 cd); no point may exceed Imax = 44 100 cd."""
    scene = _ego_scene("ego_lights")
    h = ego_vehicle.LAMP_HEIGHT_M
    for x, i_min in ((25.0, 1700.0), (50.0, 5100.0)):
        d3 = sum(((x - lx) ** 2 + ly**2 + lz**2) ** 1.5 for lx, ly, lz in ego_vehicle.lamp_positions_m()) / 2
        lo, hi = 2 * i_min * h / d3, 2 * 44_100.0 * h / d3
        assert lo <= _road_lux(scene, x, 0.0) <= hi, x
    # Kerb-side asymmetry on the road: brighter 3 m right of the lane axis than 3 m left.
    assert _road_lux(scene, 25.0, -3.0) > 1.5 * _road_lux(scene, 25.0, 3.0)
    # Towards an oncoming driver's eyes (B50L) the lamp stays under 350 cd.
    assert beams.low_beam_cd(-3.43, 0.57) <= 350.0


def test_ego_lamps_only_light_their_groups():
    parts = ego_vehicle.ego_lamp_parts()
    assert {lamp.light_group for lamp in parts.lamps} == set(ego_vehicle.GROUPS)
    assert all(lamp.shape is None for lamp in parts.lamps) and not parts.shapes


def test_road_luminaire_is_an_ies_type_ii_medium_full_cutoff():
    along, across = np.meshgrid(np.linspace(-6, 6, 601), np.linspace(-4, 4, 401))
    rel = beams.road_luminaire_relative(along, across)
    peak = np.unravel_index(rel.argmax(), rel.shape)
    assert 2.25 <= abs(along[peak]) <= 3.75  # vertical: medium (IES RP-8)
    street = across[rel >= 0.5 * rel.max()].max()
    assert 1.0 <= street <= 1.75  # lateral: Type II (half-max trace on the street side)
    flux = 10_000.0
    lens = beams.LUMINAIRE_LENS_FRACTION * beams.road_luminaire_nadir_cd(flux)
    for gamma_deg, limit_cd_per_klm in ((80.0, 100.0), (90.0, 20.0)):  # glare class G3 (EN 13201-2)
        c = np.radians(np.linspace(0, 360, 721))
        t = np.tan(np.radians(min(gamma_deg, 89.999)))
        total = np.maximum(beams.road_luminaire_cd(flux, t * np.cos(c), t * np.sin(c)),
                           lens * np.cos(np.radians(gamma_deg)))
        assert total.max() / (flux / 1000.0) <= limit_cd_per_klm, gamma_deg


def test_road_luminaire_emits_its_rated_flux():
    gamma = np.radians(np.linspace(0, 89.99, 2001))
    c = np.radians(np.linspace(0, 360, 2001)[:-1])
    g, cc = np.meshgrid(gamma, c, indexing="ij")
    cd = beams.road_luminaire_cd(8000.0, np.tan(g) * np.cos(cc), np.tan(g) * np.sin(cc))
    flux = np.trapezoid(cd.mean(axis=1) * 2 * np.pi * np.sin(gamma), gamma)
    assert flux == pytest.approx(8000.0, rel=0.01)
