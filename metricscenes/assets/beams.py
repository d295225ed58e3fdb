"""Luminous intensity distributions of head lamps and road luminaires, and their emitters.

A lamp's light is a luminous intensity distribution I (cd) over directions. Mitsuba's
``spot`` emitter multiplies its intensity by a texture projected through its cone
(``uv = 1/2 + x / (2 z tan(cutoff))`` in the spot's frame: x = left, y = up, z = axis),
so a distribution sampled on that gnomonic grid is a goniometric lamp (a "photometric
web"). The texture is normalised to its peak; the spectrum carries the peak intensity.

**Low beam** (dipped beam, right-hand traffic): an analytic distribution with the cut-off
and the kerb-side asymmetry of a regulation beam, checked against every test point of
SAE J1383 (1996), Table 1, low beam (:data:`SAE_J1383_LOW_BEAM`; the same table is
FMVSS 108's lower-beam photometry): a hot spot right of and below H-V, a wide foreground
spread, a flat cut-off 0.6° below the horizon on the oncoming side that rises at 15° on
the kerb side (the ECE R112 "elbow", capped at 0.5° up), a logistic edge 0.1° wide
(ECE R112 Annex 9 asks a gradient G = log E(β) - log E(β + 0.1°) >= 0.13; this gives
0.27), and a glare floor above the cut-off (J1383: >= 64-125 cd for signs, <= 125 cd
above 10U). Angles: h right of the lamp axis, v above it, in degrees.

**High beam**: a Gaussian hot spot at H-V checked against SAE J1383 Table 2.

**Road luminaire**: IES (ANSI/IES RP-8-18; IES LM-31) lateral Type II, vertical "medium"
distribution with a full cut-off (CIE 140 / EN 13201-2 glare class G3: I(80°) <= 100 cd
per 1000 lm, I(90°) <= 20 cd/klm): a batwing whose maximum lies along the road at 3 mounting
heights (Medium: 2.25-3.75 MH) and 0.5 MH towards the street, whose half-maximum trace
reaches 1-1.75 MH on the street side (Type II), and which is scaled to the luminaire's
rated flux. It is synthesised for this class (no manufacturer's file), and the tests
check it against each criterion of the class.

What a camera sees of a lamp is its lens, a Lambertian ``area`` emitter
(I_lens(θ) = I_lens(0) cos θ); the textured spot carries the distribution minus the lens,
so lens + spot equal the distribution wherever it exceeds the lens (no light counted
twice), and the tests check the sum against the regulation. A head-lamp lens carries
:data:`HEADLAMP_LENS_CD` (the most that keeps the sum under J1383's 125 cd above 10U;
the regulation allows 350 cd towards an oncoming driver at B50L); a luminaire's
diffusing cover carries :data:`LUMINAIRE_LENS_FRACTION` of its nadir intensity (the sum
stays inside glare class G3).
"""

from __future__ import annotations

from dataclasses import dataclass
from functools import lru_cache

import numpy as np

from metricscenes.assets.lamps import HEADLAMP_LENS_CD, scaled_to_luminous  # noqa: F401 (HEADLAMP_LENS_CD: the lens share)

# --- head lamps -----------------------------------------------------------------

LOW_BEAM_CUTOFF_DEG = -0.6
"""Cut-off on the oncoming side (v, degrees): ECE R112/R149 aim the horizontal part 0.57°
(1 %) below H; J1383's 0.5D-1.5L-to-L maximum (3000 cd) needs the edge below 0.5D."""
LOW_BEAM_ELBOW_SLOPE = np.tan(np.radians(15.0))
"""Rise of the kerb-side cut-off per degree right of V (ECE R112: 15°)."""
LOW_BEAM_SHOULDER_DEG = 0.5
LOW_BEAM_EDGE_DEG = 0.1
LOW_BEAM_HOT_SPOT_CD = 20_000.0
"""Typical of halogen and LED low beams (ECE R112 Class B: Imax <= 44 100 cd; J1383
1.5D-2R >= 15 000 cd)."""
LOW_BEAM_SPREAD_CD = 3_000.0
"""Wide foreground light (J1383: >= 700-750 cd at 9-15° left and right, 1.5-2° down)."""
GLARE_FLOOR_CD = 350.0
"""Above the cut-off at H: the ECE B50L limit (350 cd) and J1383's sign-lighting minima."""
HIGH_BEAM_PEAK_CD = 40_000.0
"""SAE J1383 high beam: H-V 20 000-75 000 cd."""


@dataclass(frozen=True)
class TestPoint:
    """A photometric test point or zone: h (right +) and v (up +) in degrees, limits in cd.

    ``h_deg``/``v_deg`` are ranges (lo, hi); a zone is checked at every grid point in it.
    """

    name: str
    h_deg: tuple[float, float]
    v_deg: tuple[float, float]
    min_cd: float | None = None
    max_cd: float | None = None


def _pt(name, h, v, lo=None, hi=None) -> TestPoint:
    h = (h, h) if np.isscalar(h) else h
    v = (v, v) if np.isscalar(v) else v
    return TestPoint(name, tuple(map(float, h)), tuple(map(float, v)), lo, hi)


SAE_J1383_LOW_BEAM: tuple[TestPoint, ...] = (
    _pt("10U-90U, 45L-45R", (-45, 45), (10, 90), hi=125),
    _pt("4U 8L", -8, 4, lo=64), _pt("4U 8R", 8, 4, lo=64),
    _pt("2U 4L", -4, 2, lo=125), _pt("2U 4R", 4, 2, lo=125),
    _pt("1U 1.5L to L", (-45, -1.5), 1, hi=700),
    _pt("0.5U 1.5L to L", (-45, -1.5), 0.5, hi=1000),
    _pt("0.5D 1.5L to L", (-45, -1.5), -0.5, hi=3000),
    _pt("1.5U 1R to R", (1, 45), 1.5, hi=1400),
    _pt("0.5U 1R", 1, 0.5, hi=2700), _pt("0.5U 2R", 2, 0.5, hi=2700), _pt("0.5U 3R", 3, 0.5, hi=2700),
    _pt("0.5D 1.5R", 1.5, -0.5, lo=8000, hi=20000),
    _pt("1D 6L", -6, -1, lo=750),
    _pt("1.5D 2R", 2, -1.5, lo=15000),
    _pt("1.5D 9L", -9, -1.5, lo=750), _pt("1.5D 9R", 9, -1.5, lo=750),
    _pt("2D 15L", -15, -2, lo=700), _pt("2D 15R", 15, -2, lo=700),
    _pt("4D 4R", 4, -4, hi=8000),
)
"""SAE J1383 (1996) Table 1, low beam, as cited in US patent literature quoting the standard
(min/max luminous intensity, cd)."""

ECE_R112_CLASS_B_LOW_BEAM: tuple[TestPoint, ...] = (
    _pt("B50L", -3.43, 0.57, hi=350),
    _pt("75R", 1.15, -0.57, lo=10100),
    _pt("75L", -3.43, -0.57, hi=10600),
    _pt("50L", -3.43, -0.86, hi=13200),
    _pt("50R", 1.72, -0.86, lo=10100),
    _pt("50V", 0, -0.86, lo=5100),
    _pt("25L", -9, -1.72, lo=1700), _pt("25R", 9, -1.72, lo=1700),
    _pt("Imax", (-45, 45), (-10, 10), hi=44100),
)
"""UN ECE Regulation No. 112 (01 series), Annex 3, Class B passing beam for right-hand
traffic, in cd (the 25/50/75 points are where the beam meets the road at 25, 50 and 75 m
from a lamp 0.75 m high)."""

SAE_J1383_HIGH_BEAM: tuple[TestPoint, ...] = (
    _pt("2U V", 0, 2, lo=1500),
    _pt("1U 3L", -3, 1, lo=5000), _pt("1U 3R", 3, 1, lo=5000),
    _pt("H V", 0, 0, lo=20000, hi=75000),
    _pt("H 3L", -3, 0, lo=10000), _pt("H 3R", 3, 0, lo=10000),
    _pt("H 6L", -6, 0, lo=3250), _pt("H 6R", 6, 0, lo=3250),
    _pt("H 9L", -9, 0, lo=2000), _pt("H 9R", 9, 0, lo=2000),
    _pt("H 12L", -12, 0, lo=500), _pt("H 12R", 12, 0, lo=500),
    _pt("1.5D V", 0, -1.5, lo=5000),
    _pt("1.5D 9L", -9, -1.5, lo=1500), _pt("1.5D 9R", 9, -1.5, lo=1500),
    _pt("2.5D V", 0, -2.5, lo=2000),
    _pt("2.5D 12L", -12, -2.5, lo=750), _pt("2.5D 12R", 12, -2.5, lo=750),
    _pt("4D V", 0, -4, hi=12500),
    _pt("maximum", (-45, 45), (-10, 10), hi=75000),
)
"""SAE J1383 (1996) Table 2, high beam (same source as :data:`SAE_J1383_LOW_BEAM`)."""


def low_beam_cutoff_deg(h_deg) -> np.ndarray:
    """Vertical angle of the cut-off at horizontal angle ``h_deg`` (right +)."""
    h = np.asarray(h_deg, float)
    rise = LOW_BEAM_CUTOFF_DEG + LOW_BEAM_ELBOW_SLOPE * np.clip(h, 0.0, None)
    return np.minimum(rise, LOW_BEAM_SHOULDER_DEG)


def low_beam_cd(h_deg, v_deg) -> np.ndarray:
    """Low-beam luminous intensity (cd) of one lamp, right-hand traffic."""
    h, v = np.broadcast_arrays(np.asarray(h_deg, float), np.asarray(v_deg, float))
    below = 1.0 / (1.0 + np.exp(np.clip((v - low_beam_cutoff_deg(h)) / LOW_BEAM_EDGE_DEG, -60, 60)))
    # Hot spot right of and below H-V, falling slower towards the foreground than upwards.
    sigma_v = np.where(v < -1.5, 1.5, 1.0)
    hot = LOW_BEAM_HOT_SPOT_CD * np.exp(-0.5 * ((h - 2.0) / 3.0) ** 2 - 0.5 * ((v + 1.5) / sigma_v) ** 2)
    spread = LOW_BEAM_SPREAD_CD * np.exp(-0.5 * (h / 12.0) ** 2 - 0.5 * ((v + 2.0) / 2.0) ** 2)
    # Glare floor above the cut-off: signs and overhead, fading upwards and sideways.
    floor = GLARE_FLOOR_CD * np.exp(-np.clip(v, 0.0, None) / 4.0 - 0.5 * (h / 25.0) ** 2)
    return (hot + spread) * below + floor * (1.0 - below)


def high_beam_cd(h_deg, v_deg) -> np.ndarray:
    """High-beam (driving beam) luminous intensity (cd) of one lamp."""
    h, v = np.broadcast_arrays(np.asarray(h_deg, float), np.asarray(v_deg, float))
    return HIGH_BEAM_PEAK_CD * np.exp(-0.5 * (h / 5.0) ** 2 - 0.5 * (v / 2.5) ** 2)


BEAMS = {"low": low_beam_cd, "high": high_beam_cd}


def check_test_points(intensity, points: tuple[TestPoint, ...], step_deg: float = 0.25) -> list[str]:
    """Every test point or zone that ``intensity(h, v)`` fails, as 'name: value' strings."""
    failures = []
    for p in points:
        hs = np.arange(p.h_deg[0], p.h_deg[1] + 1e-9, step_deg) if p.h_deg[1] > p.h_deg[0] else np.array([p.h_deg[0]])
        vs = np.arange(p.v_deg[0], p.v_deg[1] + 1e-9, step_deg) if p.v_deg[1] > p.v_deg[0] else np.array([p.v_deg[0]])
        values = intensity(*np.meshgrid(hs, vs))
        if p.min_cd is not None and values.min() < p.min_cd:
            failures.append(f"{p.name}: {values.min():.0f} cd < {p.min_cd:.0f}")
        if p.max_cd is not None and values.max() > p.max_cd:
            failures.append(f"{p.name}: {values.max():.0f} cd > {p.max_cd:.0f}")
    return failures


# --- road luminaires ---------------------------------------------------------------

LUMINAIRE_LENS_FRACTION = 0.1
"""Share of the nadir intensity a road luminaire's diffusing cover carries (a modelling
choice: lens + spot stay inside glare class G3, tested)."""
ROAD_LUMINAIRE_PEAK_RATIO = 3.0
"""Peak over nadir intensity of the batwing (typical of IES Type II medium optics)."""


def road_luminaire_relative(along_mh, across_mh) -> np.ndarray:
    """Relative intensity (nadir = 1) towards the road point (``along_mh``, ``across_mh``)
    in mounting heights from the foot of the luminaire (across: + towards the street)."""
    x, y = np.broadcast_arrays(np.asarray(along_mh, float), np.asarray(across_mh, float))
    gamma = np.degrees(np.arctan(np.hypot(x, y)))
    bat = np.exp(-0.5 * ((np.abs(x) - 3.0) / 1.2) ** 2 - 0.5 * ((y - 0.5) / 0.7) ** 2)
    lobe = 1.0 + (ROAD_LUMINAIRE_PEAK_RATIO - 1.0) * bat
    # Street side: the distribution ends between 1 and 1.75 MH; house side: it ends near the pole.
    lateral = np.where(y >= 0.0, np.exp(-0.5 * (np.clip(y - 0.5, 0, None) / 0.75) ** 2),
                       np.exp(-0.5 * (y / 0.6) ** 2))
    # Full cut-off: nothing at and above the horizontal, a steep fall beyond 70°.
    cutoff = np.clip((90.0 - gamma) / 20.0, 0.0, 1.0) ** 2
    return lobe * lateral * cutoff


def road_luminaire_cd(flux_lm: float, along_mh, across_mh) -> np.ndarray:
    """Luminous intensity (cd) of a luminaire of rated ``flux_lm`` towards a road point."""
    return road_luminaire_nadir_cd(flux_lm) * road_luminaire_relative(along_mh, across_mh)


def road_luminaire_nadir_cd(flux_lm: float) -> float:
    """Nadir intensity (cd) of the class distribution emitting ``flux_lm`` into the lower
    half space: Φ = ∫ I dω, integrated on a fine (γ, C) grid."""
    return float(flux_lm) / _relative_flux_sr()


@lru_cache(maxsize=1)
def _relative_flux_sr() -> float:
    gamma = np.radians(np.linspace(0.0, 90.0, 721))
    c = np.radians(np.linspace(0.0, 360.0, 1441)[:-1])
    g, cc = np.meshgrid(gamma, c, indexing="ij")
    t = np.tan(np.minimum(g, np.radians(89.99)))
    rel = road_luminaire_relative(t * np.cos(cc), t * np.sin(cc))
    per_gamma = rel.mean(axis=1) * 2 * np.pi * np.sin(gamma)
    return float(np.trapezoid(per_gamma, gamma))


# --- emitters ----------------------------------------------------------------------


@dataclass(frozen=True)
class SpotTexture:
    """A distribution sampled on a spot emitter's gnomonic grid.

    ``relative`` (rows, cols) is normalised to the peak ``peak_cd``; row 0 is the bottom
    (local -y), column 0 the right (local -x), as Mitsuba's ``uv`` lookup reads it.
    """

    relative: np.ndarray
    peak_cd: float
    cutoff_deg: float


def _grid(cutoff_deg: float, cols: int, rows: int) -> tuple[np.ndarray, np.ndarray]:
    """Local tangents (x/z, y/z) at texel centres: x left +, y up +."""
    t = np.tan(np.radians(cutoff_deg))
    u = (np.arange(cols) + 0.5) / cols
    v = (np.arange(rows) + 0.5) / rows
    return np.meshgrid((2 * u - 1) * t, (2 * v - 1) * t)


@lru_cache(maxsize=8)
def beam_texture(beam: str, lens_cd: float, cutoff_deg: float = 60.0, cols: int = 512,
                 rows: int = 2048) -> SpotTexture:
    """Texture of a head lamp's beam minus its Lambertian lens share (see module doc)."""
    tx, ty = _grid(cutoff_deg, cols, rows)
    h = np.degrees(np.arctan(-tx))  # local x is left; h is right of the axis
    v = np.degrees(np.arctan(ty * np.cos(np.radians(h))))
    cos_axis = 1.0 / np.sqrt(1.0 + tx**2 + ty**2)
    spot = np.clip(BEAMS[beam](h, v) - lens_cd * cos_axis, 0.0, None)
    return _normalised(spot, cutoff_deg)


@lru_cache(maxsize=64)
def luminaire_texture(flux_lm: float, lens_cd: float, cutoff_deg: float = 85.0, size: int = 1024) -> SpotTexture:
    """Texture of a road luminaire pointing down, local x towards the street, local y
    along the road; minus its lens share."""
    tx, ty = _grid(cutoff_deg, size, size)
    cos_axis = 1.0 / np.sqrt(1.0 + tx**2 + ty**2)
    spot = np.clip(road_luminaire_cd(flux_lm, ty, tx) - lens_cd * cos_axis, 0.0, None)
    return _normalised(spot, cutoff_deg)


def _normalised(cd: np.ndarray, cutoff_deg: float) -> SpotTexture:
    peak = float(cd.max())
    rel = (cd / peak).astype(np.float32) if peak > 0 else np.zeros_like(cd, np.float32)
    rel.setflags(write=False)
    return SpotTexture(rel, peak, float(cutoff_deg))


def textured_spot(texture: SpotTexture, wavelengths_nm, intensity_per_cd, origin_m, target_m, up) -> dict:
    """Mitsuba ``spot`` dict: spectrum ``intensity_per_cd`` (W·sr⁻¹·nm⁻¹ for 1 cd) times the
    texture's peak, shaped by the texture; no falloff inside the cone."""
    import mitsuba as mi

    from metricscenes.assets.parts import spectrum

    return {
        "type": "spot",
        "intensity": spectrum(wavelengths_nm, np.asarray(intensity_per_cd) * texture.peak_cd),
        "cutoff_angle": texture.cutoff_deg,
        "beam_width": texture.cutoff_deg - 1e-3,
        "texture": {"type": "bitmap", "bitmap": mi.Bitmap(np.array(texture.relative[..., None])), "raw": True},
        "to_world": mi.ScalarTransform4f().look_at(
            origin=[float(c) for c in origin_m], target=[float(c) for c in target_m],
            up=[float(c) for c in up]),
    }


def head_lamp_spot(beam: str, spd_kind: str, origin_m, forward, lens_cd: float = 0.0) -> dict:
    """Spot emitter of a head lamp at ``origin_m`` aimed along the horizontal ``forward``
    (the vehicle's +x), carrying ``beam`` ('low' or 'high') minus a lens of ``lens_cd``."""
    wl, per_cd = scaled_to_luminous(spd_kind, 1.0)
    f = np.asarray(forward, float)
    return textured_spot(beam_texture(beam, float(lens_cd)), wl, per_cd, origin_m,
                         np.asarray(origin_m, float) + f, (0.0, 0.0, 1.0))


def luminaire_spot(flux_lm: float, spd_kind: str, origin_m, street_side_y: float, lens_cd: float) -> dict:
    """Spot emitter of a road luminaire at ``origin_m`` pointing down, its street side
    towards world ``street_side_y`` (+1: +y, -1: -y), carrying the distribution minus a
    lens of ``lens_cd``."""
    wl, per_cd = scaled_to_luminous(spd_kind, 1.0)
    # look_at down with up = +x gives local x = +y (left); up = -x gives local x = -y.
    up = (1.0, 0.0, 0.0) if street_side_y > 0 else (-1.0, 0.0, 0.0)
    o = np.asarray(origin_m, float)
    return textured_spot(luminaire_texture(round(float(flux_lm), 3), float(lens_cd)), wl, per_cd, o,
                         o - np.array([0.0, 0.0, 1.0]), up)
