"""Rear retro-reflectors lit by the camera car's low beams (UN ECE R3 class IA, red).

Every M1 car carries two red rear retro-reflectors (UN ECE R48 §6.14: non-triangular,
R3 class IA or IB; near the outer edges, 250-900 mm above the ground). A retro-reflector
sends the light it receives back towards its source, in a cone of a degree or two; the
camera, 0.8 m above and 0.7 m beside each of the ego vehicle's head lamps
(:mod:`metricscenes.assets.ego_vehicle`), sees the part of that cone its divergence
angle reaches. Mitsuba has no retroreflective BSDF, so a reflector is an area emitter
whose luminous intensity towards the camera is what R3's photometry says it returns:

    I = Σ_lamps CIL(α_i) · E⊥,i,    E⊥,i = I_beam,i / r_i²

- E⊥,i: the illuminance head lamp i puts on the reflector, on a plane perpendicular to the
  incident light (R3 §2's definition of the coefficient of luminous intensity), from the
  very low-beam distribution the renderer projects (:func:`metricscenes.assets.beams.low_beam_cd`)
  at the ego lamps' positions; zero when the light arrives from behind the reflector.
- α_i: the divergence (observation) angle at the reflector between the direction to lamp i
  and the direction to the camera.
- CIL(α): R3 Annex 7 §3.1, class IA/IB, illumination angle V = H = 0°: 300 mcd/lx at
  α = 20′ and 5 mcd/lx at α = 1°30′ for a colourless (white) device; red devices × 0.25
  (R3's colour factor). These are the regulation's minima. Between the two angles CIL is
  interpolated log-linearly in α (retroreflection falls off roughly exponentially with the
  divergence angle over this range); below 20′ it is held at the 20′ value (R3 states
  nothing nearer the axis, and a reflector's return flattens there); above 1°30′ it follows
  the same log-slope (1.52 decades per degree: at 2.5°, 0.15 mcd/lx white). In our scenes
  α is about 2.5° for a car at 25 m, 1.3° at 50 m, 0.6° at 100 m and 0.3° at 200 m.
- The illumination angle: R3's 0° column stands for every direction in front of the
  reflector (our cars are yawed by at most 4° and stand in or beside the camera's lane;
  R3 asks 2/3 of the 0° value at V = ±10° and 1/3 at V = ±5°, H = ±20°).

The returned light is group ``ego_lights`` (it scales with the ego beams' weight in a
condition) and red: the beam's spectrum through a red filter
(:func:`metricscenes.assets.lamps.retroreflected_red`). Left out: the optional high beam
(group ``ego_high_beam``) does not light the reflectors, and other cars' lamps, the street
lights and the sky return nothing.
"""

from __future__ import annotations

import numpy as np

from metricscenes.assets import beams, ego_vehicle

CLASS_IA_WHITE_CIL_MCD_PER_LX: tuple[tuple[float, float], ...] = ((20.0 / 60.0, 300.0), (1.5, 5.0))
"""(divergence angle α in degrees, CIL in mcd/lx) of a colourless class IA/IB device at
illumination angle V = H = 0°: UN ECE R3 Annex 7 §3.1."""
RED_COLOUR_FACTOR = 0.25
"""UN ECE R3 Annex 7: the CIL of a red device is the colourless one × 0.25 (amber × 0.625)."""
REFLECTOR_HALF_M = (0.05, 0.02)
"""Half sizes (m) of a rear reflector's illuminating surface: 100 x 40 mm, a typical
bumper reflector (the light it returns does not depend on its size, only its radiance)."""
EGO_GROUP = "ego_lights"
"""The light group whose lamps the reflectors return: the ego vehicle's low beams."""


def cil_red_cd_per_lx(divergence_deg) -> np.ndarray:
    """Coefficient of luminous intensity (cd/lx) of a red class IA reflector at divergence
    angle ``divergence_deg``: R3's table, log-linear in α, held below 20′ and extrapolated
    with the same log-slope beyond 1°30′ (see the module doc)."""
    (a0, c0), (a1, c1) = CLASS_IA_WHITE_CIL_MCD_PER_LX
    alpha = np.asarray(divergence_deg, float)
    slope = (np.log(c1) - np.log(c0)) / (a1 - a0)
    white_mcd = c0 * np.exp(slope * (np.maximum(alpha, a0) - a0))
    return RED_COLOUR_FACTOR * 1e-3 * white_mcd


def divergence_angle_deg(reflector_m, source_m, observer_m) -> float:
    """Angle (degrees) at ``reflector_m`` between the directions to ``source_m`` and to ``observer_m``."""
    p = np.asarray(reflector_m, float)
    a, b = np.asarray(source_m, float) - p, np.asarray(observer_m, float) - p
    cos = np.dot(a, b) / (np.linalg.norm(a) * np.linalg.norm(b))
    return float(np.degrees(np.arccos(np.clip(cos, -1.0, 1.0))))


def beam_angles_deg(lamp_m, point_m) -> tuple[float, float]:
    """(h right of the axis, v above it), degrees, of ``point_m`` seen from an ego head lamp
    at ``lamp_m`` aimed along +x: the angles of :func:`metricscenes.assets.beams.low_beam_cd`."""
    dx, dy, dz = np.asarray(point_m, float) - np.asarray(lamp_m, float)
    return float(np.degrees(np.arctan2(-dy, dx))), float(np.degrees(np.arctan2(dz, np.hypot(dx, dy))))


def perpendicular_illuminance_lux(reflector_m, facing, lamp_m, beam: str = "low") -> float:
    """Illuminance (lux) an ego head lamp at ``lamp_m`` puts on a plane at ``reflector_m``
    perpendicular to its light: I(h, v) / r², or 0 where the light arrives from behind the
    reflector (``facing``: the direction its face looks, its reference axis)."""
    to_lamp = np.asarray(lamp_m, float) - np.asarray(reflector_m, float)
    r = float(np.linalg.norm(to_lamp))
    if np.dot(to_lamp, np.asarray(facing, float)) <= 0.0:
        return 0.0
    return float(beams.BEAMS[beam](*beam_angles_deg(lamp_m, reflector_m))) / r**2


def returned_intensity_cd(reflector_m, facing, lamps_m=None, observer_m=None,
                          beam: str | None = None) -> float:
    """Luminous intensity (cd) a red class IA reflector at ``reflector_m`` facing ``facing``
    sends to ``observer_m`` (default: the camera) of the head lamps at ``lamps_m`` (default:
    the ego vehicle's, with their ``beam``, default the low beam of :data:`EGO_GROUP`):
    Σ CIL(α_i) E⊥,i."""
    lamps_m = ego_vehicle.lamp_positions_m() if lamps_m is None else lamps_m
    observer_m = ego_vehicle.CAMERA_POSITION_M if observer_m is None else observer_m
    beam = ego_vehicle.GROUPS[EGO_GROUP] if beam is None else beam
    return float(sum(cil_red_cd_per_lx(divergence_angle_deg(reflector_m, lamp, observer_m))
                     * perpendicular_illuminance_lux(reflector_m, facing, lamp, beam) for lamp in lamps_m))
