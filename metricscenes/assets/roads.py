"""Twenty seeded rural roads (DESIGN.md §2): asphalt, lane markings, shoulders, terrain, trees, lights.

World frame: x forward along the road, y left, z up. Traffic keeps right, and the camera
drives in same-direction lane ``camera_lane`` (0 = next to the centre line), whose centre
line is y = 0; every y here is in that frame. The paved road runs x = -5..395 m at z = 0,
lane markings lie 1 mm above it, terrain 200 m wide 2 cm below it, and a 40 km ground
plane (and the road's continuation) reaches the horizon, since ``sunsky`` is zero below
the horizon. Dash patterns follow common rural practice: 3 m / 9 m (US MUTCD 10 ft / 30 ft),
4.5 m / 7.5 m and 6 m / 12 m (European); line widths 0.10-0.15 m.
"""

from __future__ import annotations

from dataclasses import dataclass

import numpy as np

from metricscenes.assets import meshes
from metricscenes.assets.lamps import STREET_LIGHT_FLUX_LM
from metricscenes.assets.parts import SceneParts, mesh_shape
from metricscenes.assets.streetlights import street_light_parts
from metricscenes.assets.vegetation import diffuse_bsdf, tree_parts
from metricscenes.geometry import CAMERA_HEIGHT_M

N_ROADS = 20
ROAD_X_RANGE_M = (-5.0, 395.0)
TERRAIN_HALF_WIDTH_M = 100.0
FAR_GROUND_HALF_SIZE_M = 20000.0
MARKING_Z_M = 0.001
PATCH_Z_M = 0.0005
TERRAIN_Z_M = -0.02
FAR_GROUND_Z_M = -0.05
CENTRE_STYLES = ("yellow_double_solid", "yellow_dashed", "yellow_solid_dashed", "white_dashed", "white_solid")
DASH_PATTERNS_M = ((3.0, 9.0), (4.5, 7.5), (6.0, 12.0))
_TONES = 5  # asphalt / terrain reflectance classes, one mesh each
_SALT = 0x20AD


@dataclass(frozen=True)
class RoadSpec:
    """Parameters of one road (lengths in metres)."""

    road_id: int
    lanes_each_way: int
    lane_width_m: float
    centre_style: str
    edge_lines: bool
    marking_width_m: float
    dash_m: float
    gap_m: float
    shoulder_width_m: float
    terrain: str  # 'grass' | 'dirt'
    asphalt_brightness: float  # multiplies the asphalt reflectance (aged asphalt is greyer)
    asphalt_variation: float  # relative reflectance spread between paving segments
    patch_count: int  # darker repair patches
    trees: bool
    tree_spacing_m: float
    street_lights: bool
    light_spacing_m: float
    light_side: str  # 'left' | 'right'
    lamp_kind: str  # 'led_4000k' | 'hps'
    lamp_flux_lm: float

    @property
    def half_paved_m(self) -> float:
        """Centre line to the outer edge of the paved shoulder."""
        return self.lanes_each_way * self.lane_width_m + self.shoulder_width_m


def road_spec(road_id: int) -> RoadSpec:
    """The road ``road_id`` (0-19), deterministic."""
    if not isinstance(road_id, (int, np.integer)) or not 0 <= road_id < N_ROADS:
        raise ValueError(f"road_id must be an integer in [0, {N_ROADS}), got {road_id!r}")
    r = int(road_id)
    rng = np.random.default_rng([_SALT, r])
    dash, gap = DASH_PATTERNS_M[int(rng.integers(len(DASH_PATTERNS_M)))]
    return RoadSpec(
        road_id=r,
        lanes_each_way=1 if r < 10 else (2 if r < 16 else 3),
        lane_width_m=round(float(rng.uniform(3.0, 3.75)), 2),
        centre_style=CENTRE_STYLES[int(rng.integers(len(CENTRE_STYLES)))],
        edge_lines=bool(rng.uniform() < 0.8),
        marking_width_m=round(float(rng.uniform(0.10, 0.15)), 3),
        dash_m=dash,
        gap_m=gap,
        shoulder_width_m=round(float(rng.uniform(0.3, 2.5)), 2),
        terrain="dirt" if rng.uniform() < 0.3 else "grass",
        asphalt_brightness=round(float(rng.uniform(0.8, 1.5)), 3),
        asphalt_variation=round(float(rng.uniform(0.04, 0.15)), 3),
        patch_count=int(rng.integers(0, 9)),
        trees=r % 4 != 3,
        tree_spacing_m=round(float(rng.uniform(8.0, 40.0)), 1),
        street_lights=r % 5 in (0, 2),
        light_spacing_m=round(float(rng.uniform(30.0, 40.0)), 1),
        light_side="left" if rng.uniform() < 0.5 else "right",
        lamp_kind="hps" if rng.uniform() < 0.4 else "led_4000k",
        lamp_flux_lm=round(float(rng.uniform(*STREET_LIGHT_FLUX_LM[::2])), -1),
    )


def road_library() -> list[RoadSpec]:
    """All 20 roads, ordered by ``road_id``."""
    return [road_spec(i) for i in range(N_ROADS)]


def centre_line_y_m(spec: RoadSpec, camera_lane: int = 0) -> float:
    """y of the centre line when the camera is centred in same-direction lane ``camera_lane``."""
    if not 0 <= camera_lane < spec.lanes_each_way:
        raise ValueError(f"camera_lane must be in [0, {spec.lanes_each_way}), got {camera_lane}")
    return (camera_lane + 0.5) * spec.lane_width_m


def lane_center_y_m(spec: RoadSpec, lane: int, direction: str, camera_lane: int = 0) -> float:
    """y of a lane centre; ``direction`` 'same' (driving away, right of centre) or 'oncoming'."""
    if direction not in ("same", "oncoming"):
        raise ValueError(f"direction must be 'same' or 'oncoming', got {direction!r}")
    if not 0 <= lane < spec.lanes_each_way:
        raise ValueError(f"lane must be in [0, {spec.lanes_each_way}), got {lane}")
    sign = -1.0 if direction == "same" else 1.0
    return centre_line_y_m(spec, camera_lane) + sign * (lane + 0.5) * spec.lane_width_m


def camera_lane_y_m(spec: RoadSpec, camera_lane: int = 0) -> float:
    """y of the camera's lane centre: 0 by construction of the frame."""
    return lane_center_y_m(spec, camera_lane, "same", camera_lane)


def _line_rects(y: float, width: float, dashed: bool, dash: float, gap: float, phase: float,
                x_range: tuple[float, float] = ROAD_X_RANGE_M) -> np.ndarray:
    x0, x1 = x_range
    if not dashed:
        return np.array([[x0, x1, y - width / 2, y + width / 2, MARKING_Z_M]])
    starts = np.arange(x0 - phase, x1, dash + gap)
    a, b = np.clip(starts, x0, x1), np.clip(starts + dash, x0, x1)
    keep = b - a > 0.05
    return np.stack([a[keep], b[keep], np.full(keep.sum(), y - width / 2),
                     np.full(keep.sum(), y + width / 2), np.full(keep.sum(), MARKING_Z_M)], 1)


def _markings(spec: RoadSpec, yc: float, rng: np.random.Generator,
              x_range: tuple[float, float] = ROAD_X_RANGE_M) -> dict[str, list[np.ndarray]]:
    """Marking rectangles grouped by colour ('white', 'yellow')."""
    w, lw = spec.marking_width_m, spec.lane_width_m
    phase = rng.uniform(0, spec.dash_m + spec.gap_m)
    colour, pattern = spec.centre_style.split("_", 1)
    out: dict[str, list[np.ndarray]] = {"white": [], "yellow": []}
    line = lambda y, dashed: _line_rects(y, w, dashed, spec.dash_m, spec.gap_m, phase, x_range)  # noqa: E731
    if pattern == "double_solid":
        out[colour] += [line(yc - 1.5 * w, False), line(yc + 1.5 * w, False)]
    elif pattern == "solid_dashed":  # passing allowed from the camera's side
        out[colour] += [line(yc - 1.5 * w, True), line(yc + 1.5 * w, False)]
    else:
        out[colour].append(line(yc, pattern == "dashed"))
    for k in range(1, spec.lanes_each_way):  # lane lines between same-direction lanes
        out["white"] += [line(yc - k * lw, True), line(yc + k * lw, True)]
    if spec.edge_lines:
        edge = spec.lanes_each_way * lw - w / 2
        out["white"] += [line(yc - edge, False), line(yc + edge, False)]
    return out


def _segments(rng: np.random.Generator, y0: float, y1: float, z: float, mean_m: float,
              x_range: tuple[float, float] = ROAD_X_RANGE_M) -> list[np.ndarray]:
    """Paving segments along x with random lengths, as (rect, tone) rows."""
    x, rows = x_range[0], []
    while x < x_range[1]:
        x_end = min(x + rng.uniform(0.5, 1.5) * mean_m, x_range[1])
        rows.append(np.array([x, x_end, y0, y1, z, rng.integers(_TONES)], float))
        x = x_end
    return rows


def _toned_meshes(prefix: str, rows: list[np.ndarray], material: str, brightness: float,
                  variation: float) -> dict[str, object]:
    """One mesh per reflectance tone class (scale = brightness × (1 + variation × (k-2)/2))."""
    table = np.array(rows)
    shapes = {}
    for k in range(_TONES):
        sel = table[table[:, 5] == k, :5]
        if len(sel):
            v, f = meshes.quads_z(sel)
            scale = brightness * (1.0 + variation * (k - (_TONES - 1) / 2) / ((_TONES - 1) / 2))
            shapes[f"{prefix}_{k}"] = mesh_shape(f"{prefix}_{k}", v, f, diffuse_bsdf(material, scale))
    return shapes


def horizon_edge() -> meshes.Mesh:
    """A vertical face along the far ground's edge ahead, from the ground up to the camera's
    height, facing the camera. Without it the camera sees, between the ground's edge and its
    own horizontal, a strip 1.55 m / 20 km = 0.078 mrad tall where ``sunsky`` is zero: a black
    line along the horizon once a render samples finer than about 0.3 mrad (an inset does).
    On the real Earth the ground reaches the horizon, 0.69 mrad below the horizontal from
    1.5 m (dip ≈ √(2h/R)); a flat world cannot place it there, so the ground is closed up
    to the horizontal instead, with the far ground's material."""
    g = FAR_GROUND_HALF_SIZE_M
    v = np.array([[g, -g, FAR_GROUND_Z_M], [g, -g, CAMERA_HEIGHT_M], [g, g, CAMERA_HEIGHT_M], [g, g, FAR_GROUND_Z_M]])
    return v, np.array([[0, 1, 2], [0, 2, 3]])  # counter-clockwise seen from the camera (-x)


def road_parts(spec: RoadSpec, seed: int = 0, camera_lane: int = 0, ground_to_horizon: bool = False,
               road_end_m: float | None = None) -> SceneParts:
    """All shapes and lamps of a road (keys 'road_*', 'tree_*', 'streetlight_*'), seeded.

    ``ground_to_horizon`` closes the strip between the far ground's edge and the camera's
    horizontal (see :func:`horizon_edge`). ``road_end_m``: where the detailed road (paving,
    markings, terrain tiles, trees, street lights) ends ahead, beyond it the plain far road and
    ground (None: ``ROAD_X_RANGE_M``'s end, the same shapes and draws as ever)."""
    rng = np.random.default_rng([_SALT, spec.road_id, int(seed)])
    # The road beyond the default's end draws from a stream of its own, so that a longer road is the
    # default road, draw for draw, and more road (docs/scenes.md, "Distances beyond 200 m").
    more_rng = np.random.default_rng([_SALT, spec.road_id, int(seed), 1])
    yc = centre_line_y_m(spec, camera_lane)
    half_lanes, half_paved = spec.lanes_each_way * spec.lane_width_m, spec.half_paved_m
    x0, x_default = ROAD_X_RANGE_M
    x1 = x_default if road_end_m is None else float(road_end_m)
    if x1 < x_default:
        raise ValueError(f"road_end_m must be at least {x_default:g} m (the default road's end), got {x1:g}")
    spans = [(rng, (x0, x_default))] + ([(more_rng, (x_default, x1))] if x1 > x_default else [])
    # Asphalt: lanes of each direction and the shoulders are paved in separate segments.
    rows = []
    for draw, span in spans:
        rows += _segments(draw, yc - half_lanes, yc, 0.0, 40.0, span) + _segments(draw, yc, yc + half_lanes, 0.0, 40.0, span)
        rows += _segments(draw, yc - half_paved, yc - half_lanes, 0.0, 60.0, span)
        rows += _segments(draw, yc + half_lanes, yc + half_paved, 0.0, 60.0, span)
    shapes = _toned_meshes("road_asphalt", rows, "asphalt", spec.asphalt_brightness, spec.asphalt_variation)
    if spec.patch_count:
        px = rng.uniform(8.0, 300.0, spec.patch_count)
        py = rng.uniform(yc - half_lanes + 1.0, yc + half_lanes - 1.0, spec.patch_count)
        lx, ly = rng.uniform(1.5, 6.0, spec.patch_count), rng.uniform(0.8, 2.5, spec.patch_count)
        v, f = meshes.quads_z(np.stack([px, px + lx, py - ly / 2, py + ly / 2, np.full_like(px, PATCH_Z_M)], 1))
        patch_bsdf = diffuse_bsdf("asphalt", 0.75 * spec.asphalt_brightness)
        shapes["road_patches"] = mesh_shape("road_patches", v, f, patch_bsdf)
    for colour, rects in _markings(spec, yc, rng, (x0, x1)).items():  # (dashes follow from one phase)
        if rects:
            v, f = meshes.quads_z(np.concatenate(rects))
            name = f"road_marking_{colour}"
            shapes[name] = mesh_shape(name, v, f, diffuse_bsdf(f"lane_{colour}", 0.9))
    v, f = meshes.quads_z([[x1, FAR_GROUND_HALF_SIZE_M, yc - half_paved, yc + half_paved, 0.0]])
    shapes["road_far"] = mesh_shape("road_far", v, f, diffuse_bsdf("asphalt", spec.asphalt_brightness))
    # Terrain: 10 m x 10 m tiles in tone classes, a dirt verge strip, and the far ground.
    ys = np.arange(yc - TERRAIN_HALF_WIDTH_M, yc + TERRAIN_HALF_WIDTH_M, 10.0)
    tiles = [np.array([x, x + 10.0, y, y + 10.0, TERRAIN_Z_M, draw.integers(_TONES)])
             for draw, (a, b) in spans for x in np.arange(a, b, 10.0) for y in ys]
    shapes.update(_toned_meshes("road_terrain", tiles, spec.terrain, 1.0, 0.12))
    verge = rng.uniform(0.4, 1.2)
    v, f = meshes.quads_z([[x0, x1, yc - half_paved - verge, yc - half_paved, TERRAIN_Z_M / 2],
                           [x0, x1, yc + half_paved, yc + half_paved + verge, TERRAIN_Z_M / 2]])
    shapes["road_verge"] = mesh_shape("road_verge", v, f, diffuse_bsdf("dirt", 0.8))
    g = FAR_GROUND_HALF_SIZE_M
    v, f = meshes.quads_z([[-g, g, -g, g, FAR_GROUND_Z_M]])
    shapes["road_ground_far"] = mesh_shape("road_ground_far", v, f, diffuse_bsdf(spec.terrain, 0.9))
    if ground_to_horizon:
        shapes["road_ground_edge"] = mesh_shape("road_ground_edge", *horizon_edge(), diffuse_bsdf(spec.terrain, 0.9))
    parts = SceneParts(shapes=shapes)
    margin = 1.5 + verge
    far_rows = [(yc + 45.0, 1, 40.0), (yc - 45.0, -1, 40.0)]
    if spec.trees:
        rows_t = [(yc + half_paved + margin, 1, 20.0), (yc - half_paved - margin, -1, 20.0)]
        parts = parts.merged(tree_parts(rng, rows_t, spec.tree_spacing_m))
    # A distant tree line on both sides gives the horizon some structure on every road.
    parts = parts.merged(tree_parts(rng, far_rows, 12.0, x_range_m=(20.0, x_default), prefix="tree_far"))
    if x1 > x_default:  # the trees of the road beyond, from its own stream
        if spec.trees:
            parts = parts.merged(tree_parts(more_rng, rows_t, spec.tree_spacing_m, x_range_m=(390.0, x1 - 5.0),
                                            prefix="tree_more"))
        parts = parts.merged(tree_parts(more_rng, far_rows, 12.0, x_range_m=(x_default, x1), prefix="tree_far_more"))
    if spec.street_lights:
        side = 1.0 if spec.light_side == "left" else -1.0
        pole_y = yc + side * (half_paved + verge + 1.0)
        arm_y = pole_y - side * min(2.0 + spec.shoulder_width_m, half_paved)
        xs = np.arange(rng.uniform(8.0, 8.0 + spec.light_spacing_m), x1 - 5.0, spec.light_spacing_m)
        parts = parts.merged(street_light_parts(xs, pole_y, arm_y, height_m=float(rng.uniform(8.0, 10.0)),
                                                kind=spec.lamp_kind, flux_lm=spec.lamp_flux_lm))
    return parts
