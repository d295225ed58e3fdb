"""The procedural car library: 50 seeded cars over 7 body styles, as Mitsuba scene parts.

Each car is a lofted, rounded, tapered body (``car_body``) with a dark-glass greenhouse,
wheel arches, four wheels showing under the body, head and tail lamps, licence plates,
grille, intakes and mirrors — the features that made procedural cars recognisable to a
COCO YOLOv5 in the feasibility study (``reference/car-detectability.md``).

Car frame: origin on the ground under the car's centre, x toward the front, y left, z up.
``car_parts(spec, (x, y), yaw)`` places it in the world (yaw = 0: front along +x, away from
the camera at the origin; yaw = pi: oncoming). Where asked, it also carries what a car carries
at night beyond its lamps (:func:`rear_fittings`): a lit rear plate (UN ECE R4) and two red
rear retro-reflectors (UN ECE R3, :mod:`metricscenes.assets.retroreflection`).
"""

from __future__ import annotations

from dataclasses import dataclass
from functools import lru_cache

import numpy as np

from metricscenes.assets import beams
from metricscenes.assets import lamps as lamp_photometry
from metricscenes.assets import ego_vehicle, materials, retroreflection
from metricscenes.assets.car_body import BodyShape
from metricscenes.assets.car_parts import (
    LampRect, MeshPart, conformal_patch, finish, lamp_rect, mirror_meshes, normals_for,
    split_greenhouse, wheel_meshes,
)
from metricscenes.assets.car_styles import PAINT_WEIGHTS, STYLE_SCHEDULE, STYLES
from metricscenes.assets.parts import Lamp, SceneParts, mesh_shape

CAR_IDS: list[int] = list(range(50))
BODY_STYLES: tuple[str, ...] = tuple(STYLES)
LIBRARY_SEED = 20230115  # fixed base seed of the library (any change re-draws every car)
LIGHT_MODES = ("auto", "on", "brake", "off")


@dataclass(frozen=True)
class CarSpec:
    """Main parameters of one library car (metres)."""

    car_id: int
    body_style: str
    length_m: float
    width_m: float
    height_m: float
    wheelbase_m: float
    paint: str
    tyre_radius_m: float
    tyre_width_m: float
    track_m: float
    front_overhang_m: float
    headlamp_kind: str  # 'led' or 'halogen'
    belt_scale: float  # multiplies the lower-body profile heights (0.97-1.03)
    greenhouse_shift: float  # shift of the greenhouse along u (-0.015..0.015)


def car_spec(car_id: int) -> CarSpec:
    """Deterministic spec of library car ``car_id`` (0..49), drawn from a seeded Generator."""
    if int(car_id) != car_id or not 0 <= car_id < len(CAR_IDS):
        raise ValueError(f"car_id must be an integer in 0..{len(CAR_IDS) - 1}, got {car_id!r}")
    rng = np.random.default_rng([LIBRARY_SEED, int(car_id)])
    style = STYLE_SCHEDULE[car_id % len(STYLE_SCHEDULE)]
    st = STYLES[style]

    def draw(key):
        lo, hi = st[key]
        return float(rng.uniform(lo, hi))

    length, width, height = draw("length"), draw("width"), draw("height")
    wheelbase = min(draw("wheelbase"), length - 1.25)
    tyre_r, tyre_w = draw("tyre_radius"), draw("tyre_width")
    names = list(PAINT_WEIGHTS)
    p = np.array([PAINT_WEIGHTS[n] for n in names])
    paint = names[int(rng.choice(len(names), p=p / p.sum()))]
    return CarSpec(
        car_id=int(car_id), body_style=style, length_m=round(length, 3), width_m=round(width, 3),
        height_m=round(height, 3), wheelbase_m=round(wheelbase, 3), paint=paint,
        tyre_radius_m=round(tyre_r, 3), tyre_width_m=round(tyre_w, 3),
        track_m=round(width - tyre_w - float(rng.uniform(0.07, 0.11)), 3),
        front_overhang_m=round((length - wheelbase) * st["front_overhang_frac"], 3),
        headlamp_kind="led" if rng.uniform() < 0.7 else "halogen",
        belt_scale=round(float(rng.uniform(0.97, 1.03)), 4),
        greenhouse_shift=round(float(rng.uniform(-0.015, 0.015)), 4),
    )


def car_library() -> list[CarSpec]:
    """All library cars, in id order."""
    return [car_spec(i) for i in CAR_IDS]


def body_shape(spec: CarSpec) -> BodyShape:
    """The lofted-body description of a spec."""
    st = STYLES[spec.body_style]
    top = tuple((u, z * spec.belt_scale) for u, z in st["top"])
    gh = tuple(float(np.clip(u + spec.greenhouse_shift, 0.005, 0.99)) for u in st["greenhouse"])
    return BodyShape(spec.length_m, spec.width_m, spec.height_m, top, tuple(st["bot"]), gh,
                     tumblehome=st["tumblehome"])


@dataclass(frozen=True)
class CarGeometry:
    meshes: tuple[MeshPart, ...]
    lamps: tuple[LampRect, ...]


@lru_cache(maxsize=64)
def car_geometry(spec: CarSpec) -> CarGeometry:
    """All meshes and lamp rectangles of a car in its own frame (cached per spec)."""
    body = body_shape(spec)
    pre = f"car_{spec.car_id:02d}"
    x_front_axle = 0.5 * spec.length_m - spec.front_overhang_m
    wheels_x = (x_front_axle, x_front_axle - spec.wheelbase_m)
    parts: list[MeshPart] = []
    v, f = body.lower_body(wheels_x, spec.tyre_radius_m, spec.track_m, spec.tyre_width_m)
    parts.append(MeshPart(f"{pre}_body", v, f, "paint"))
    gv, gf, s_v, env, h_v = body.greenhouse()
    glass_f, paint_f = split_greenhouse(body, gv, gf, s_v, env, h_v)
    parts += [MeshPart(f"{pre}_glass", gv, glass_f, "car_glass"), MeshPart(f"{pre}_roof", gv, paint_f, "paint")]
    for i, xw in enumerate(wheels_x):
        for side, sgn in (("l", 1.0), ("r", -1.0)):
            parts += wheel_meshes(f"{pre}_wheel{i}{side}", xw, sgn * 0.5 * spec.track_m,
                                  spec.tyre_radius_m, spec.tyre_width_m, sgn)
    parts += mirror_meshes(body, pre)
    lamps = _front_and_rear(body, spec, pre, parts)
    return CarGeometry(tuple(finish(parts)), tuple(lamps))


def _front_and_rear(body: BodyShape, spec: CarSpec, pre: str, parts: list[MeshPart]) -> list[LampRect]:
    """Grille, intakes, plates, bumper trim and the lamp rectangles (appends to ``parts``)."""
    style, W = spec.body_style, spec.width_m
    tall = style in ("suv", "pickup", "van")
    lamps: list[LampRect] = []
    # front face: from the bumper underside to the nose top
    zb, zt = float(body.z_bot(0.99)), float(body.z_top(0.975))
    span = zt - zb
    lw, lh = 0.15 * W / 1.8 + 0.02, (0.05 if not tall else 0.06)
    ly, lz = 0.5 * W - 0.09 - lw, zb + 0.80 * span
    for side, sgn in (("l", 1), ("r", -1)):
        hv, hf = conformal_patch(body, True, sgn * ly, lz, lw + 0.02, lh + 0.015, 0.004, 8.0)
        parts.append(MeshPart(f"{pre}_headhousing_{side}", hv, hf, "trim_black", smooth=False))
        lamps.append(lamp_rect(body, f"{pre}_headlamp_{side}", "head", True, sgn * ly, lz, (lw, lh), "lens_clear"))
    gy = ly - lw - 0.04
    gz = zb + (0.56 if tall else 0.60) * span
    gh = (0.16 if tall else 0.11) * span / 0.45
    gv, gf = conformal_patch(body, True, 0.0, gz, gy, gh, 0.004, 5.0)
    parts.append(MeshPart(f"{pre}_grille", gv, gf, "trim_black", smooth=False))
    iv, if_ = conformal_patch(body, True, 0.0, zb + 0.14 * span, 0.33 * W, 0.07 * span / 0.45 + 0.02, 0.004, 5.0)
    parts.append(MeshPart(f"{pre}_intake", iv, if_, "trim_black", smooth=False))
    parts += _plate(body, pre + "_plate_f", True, zb + 0.33 * span)
    # rear face
    zb, span = _rear_face(body)
    if style in ("pickup", "van"):
        tw, th = 0.07, 0.20 * span / 0.6
        ty, tz = 0.5 * W - 0.06 - tw, zb + 0.62 * span
    else:
        tw, th = 0.16 * W / 1.8 + 0.02, 0.06
        ty, tz = 0.5 * W - 0.07 - tw, zb + 0.76 * span
    for side, sgn in (("l", 1), ("r", -1)):
        hv, hf = conformal_patch(body, False, sgn * ty, tz, tw + 0.015, th + 0.015, 0.004, 8.0)
        parts.append(MeshPart(f"{pre}_tailhousing_{side}", hv, hf, "trim_black", smooth=False))
        lamps.append(lamp_rect(body, f"{pre}_taillamp_{side}", "tail", False, sgn * ty, tz, (tw, th), "lens_red"))
    bv, bf = conformal_patch(body, False, 0.0, zb + 0.10 * span, 0.40 * W, 0.08 * span, 0.004, 5.0)
    parts.append(MeshPart(f"{pre}_rearbumper", bv, bf, "trim_black", smooth=False))
    parts += _plate(body, pre + "_plate_r", False, _rear_plate_z(zb, span))
    if "bed" in STYLES[style]:
        u0, u1 = STYLES[style]["bed"]
        parts.append(_bed_floor(body, pre, u0, u1))
    return lamps


def _rear_face(body: BodyShape) -> tuple[float, float]:
    """(z of the rear face's bottom, its height): the frame the rear details are placed in."""
    zb, zt = float(body.z_bot(0.01)), float(body.z_top(0.03))
    return zb, zt - zb


def _rear_plate_z(zb: float, span: float) -> float:
    return zb + 0.45 * span


PLATE_HALF_M = (0.26, 0.055)
"""Half sizes (m) of an EU registration plate (520 x 110 mm)."""


def _plate(body: BodyShape, key: str, front: bool, z: float) -> list[MeshPart]:
    """EU plate 520 x 110 mm of retroreflective white sheeting (characters are sub-pixel at 25 m)."""
    pv, pf = conformal_patch(body, front, 0.0, z, *PLATE_HALF_M, 0.006, 12.0, n=(8, 4))
    return [MeshPart(key, pv, pf, "plate_white", smooth=False)]


PLATE_LAMP_ROLE = "plate"
REFLECTOR_ROLE = "reflector"
REFLECTOR_HEIGHT_SHARE = 0.25
"""Height of the rear reflectors' centres, as a share of the rear face above its bottom:
in the bumper, between its trim and the plate (0.45-0.62 m above the ground)."""
REFLECTOR_INSET_M = 0.25
"""How far in from the car's side a rear reflector's centre lies (its outer edge 200 mm in:
UN ECE R48 asks at most 400 mm; there the body faces within 20° of straight back)."""


@lru_cache(maxsize=64)
def rear_fittings(spec: CarSpec) -> tuple[LampRect, ...]:
    """The rear plate's lit face and the two rear retro-reflectors, in the car frame.

    - Plate (role ``'plate'``, UN ECE R4): a flat rectangle of the plate's size and
      material 10 mm proud of the body (4-7 mm before the plate, which stays behind it),
      the face the plate lamp lights.
    - Reflectors (role ``'reflector'``, red lens, :data:`retroreflection.REFLECTOR_HALF_M`):
      low in the bumper, near the sides, as UN ECE R48 §6.14 places them: outer edges
      within 400 mm of the car's sides, inner edges at least 600 mm apart, 250-900 mm above
      the ground (tested for every car).

    They are not in :func:`car_geometry` (nor in :func:`car_vertices_world`): a collection
    without them keeps its bytes, and they lie inside the rear face's outline.
    """
    body = body_shape(spec)
    pre = f"car_{spec.car_id:02d}"
    zb, span = _rear_face(body)
    plate = lamp_rect(body, f"{pre}_platelamp", PLATE_LAMP_ROLE, False, 0.0, _rear_plate_z(zb, span), PLATE_HALF_M,
                      "plate_white", offset_m=0.010)
    y = 0.5 * spec.width_m - REFLECTOR_INSET_M
    z = zb + REFLECTOR_HEIGHT_SHARE * span
    reflectors = tuple(lamp_rect(body, f"{pre}_reflector_{side}", REFLECTOR_ROLE, False, sgn * y, z,
                                 retroreflection.REFLECTOR_HALF_M, "lens_red")
                       for side, sgn in (("l", 1.0), ("r", -1.0)))
    return (plate,) + reflectors


def _bed_floor(body: BodyShape, pre: str, u0: float, u1: float) -> MeshPart:
    """Dark bed liner seen from above on a pickup's rear deck."""
    x0, x1 = body.x_of_u(u0), body.x_of_u(u1)
    w = 0.5 * body.width_m - 0.07
    z = float(body.z_top(0.5 * (u0 + u1))) + 0.004
    v = np.array([[x0, -w, z], [x1, -w, z], [x1, w, z], [x0, w, z]])
    return MeshPart(f"{pre}_bed", v, np.array([[0, 1, 2], [0, 2, 3]]), "trim_black", smooth=False)


def _world(position_m, yaw_rad) -> np.ndarray:
    c, s = np.cos(yaw_rad), np.sin(yaw_rad)
    m = np.eye(4)
    m[:2, :2] = [[c, -s], [s, c]]
    m[0, 3], m[1, 3] = float(position_m[0]), float(position_m[1])
    return m


def car_vertices_world(spec: CarSpec, position_m, yaw_rad) -> np.ndarray:
    """(N, 3) every mesh vertex and lamp corner of the car in world metres (for GT boxes)."""
    geo = car_geometry(spec)
    m = _world(position_m, yaw_rad)
    v = np.concatenate([p.vertices for p in geo.meshes] + [lamp.corners() for lamp in geo.lamps])
    return v @ m[:3, :3].T + m[:3, 3]


def car_parts(spec: CarSpec, position_m: tuple[float, float], yaw_rad: float, lights: str = "auto", *,
              plate_lamp: bool = False, rear_retroreflectors: bool = False) -> SceneParts:
    """Mitsuba shapes and lamps of a car placed in the world (its own lamps: group 'car_lights').

    ``lights``: 'auto'/'on' (low-beam head lamps with a road-lighting spot each, tail lamps),
    'brake' (as 'on' with stop-lamp intensity at the rear), 'off' (no emitters; lenses stay).
    ``plate_lamp``: the rear plate's lit face (UN ECE R4), a 'car_lights' lamp while the
    lights are on (a plain plate when 'off'). ``rear_retroreflectors``: the two red rear
    reflectors (UN ECE R3), lit by the camera car's low beams whatever ``lights`` says,
    lamps of group 'ego_lights' (:mod:`metricscenes.assets.retroreflection`); where they
    return nothing to the camera (a car facing it) they are lenses only.
    The variant (``scalar_spectral``) must be set by the caller.
    """
    if lights not in LIGHT_MODES:
        raise ValueError(f"lights must be one of {LIGHT_MODES}, got {lights!r}")
    geo = car_geometry(spec)
    m = _world(position_m, yaw_rad)
    rot = m[:3, :3]
    shapes: dict[str, object] = {}
    paint = materials.car_paint_bsdf(spec.paint)
    for p in geo.meshes:
        bsdf = paint if p.material == "paint" else materials.bsdf(p.material)
        n = normals_for(p)
        shapes[p.key] = mesh_shape(p.key, p.vertices @ rot.T + m[:3, 3], p.faces, bsdf,
                                   None if n is None else n @ rot.T)
    lamps: list[Lamp] = []
    for lr in geo.lamps:
        shape = _lamp_shape(lr, m)
        if lights == "off":
            shapes[lr.key] = shape
            continue
        if lr.role == "head":
            wl, rad = lamp_photometry.headlamp(spec.headlamp_kind, lens_area_m2=lr.area_m2)
        else:
            wl, rad = lamp_photometry.tail_lamp(brake=lights == "brake", lens_area_m2=lr.area_m2)
        lamps.append(Lamp(lr.key, "car_lights", shape, lamp_photometry.area_emitter(wl, rad)))
        if lr.role == "head":
            # The low beam (minus the lens's share) as a goniometric spot aimed along the car.
            origin = rot @ (lr.centre + 0.05 * lr.normal) + m[:3, 3]
            lamps.append(Lamp(lr.key + "_beam", "car_lights", None, beams.head_lamp_spot(
                "low", lamp_photometry.headlamp_spd(spec.headlamp_kind), origin, rot[:, 0],
                lens_cd=beams.HEADLAMP_LENS_CD)))
    for lr in rear_fittings(spec):
        if lr.role == PLATE_LAMP_ROLE and plate_lamp:
            lamp = None if lights == "off" else _plate_lamp(lr, m)
        elif lr.role == REFLECTOR_ROLE and rear_retroreflectors:
            lamp = _retroreflector(lr, m)
        else:
            continue
        if lamp is None:
            shapes[lr.key] = _lamp_shape(lr, m)
        else:
            lamps.append(lamp)
    return SceneParts(shapes=shapes, lamps=tuple(lamps))


def _lamp_shape(lr: LampRect, world: np.ndarray) -> dict:
    """Mitsuba ``rectangle`` of a lamp rectangle placed by the 4x4 ``world`` transform."""
    import mitsuba as mi

    return {"type": "rectangle", "to_world": mi.ScalarTransform4f((world @ lr.matrix()).tolist()),
            "bsdf": materials.bsdf(lr.material)}


def _plate_lamp(lr: LampRect, world: np.ndarray) -> Lamp:
    """The rear plate lit by its lamp: a 'car_lights' emitter of the plate's radiance (R4's
    minimum luminance on a perfect diffuser, times the plate's reflectance), never chosen
    by next-event estimation (its 0.1 cd barely lights anything else)."""
    wl, rad = lamp_photometry.plate_lamp(materials.reflectance(lr.material, lamp_photometry.LAMP_NM))
    return Lamp(lr.key, "car_lights", _lamp_shape(lr, world), lamp_photometry.area_emitter(wl, rad, sampled=False))


def _retroreflector(lr: LampRect, world: np.ndarray) -> Lamp | None:
    """A rear reflector returning the ego low beams to the camera: an 'ego_lights' emitter
    whose intensity towards the camera is :func:`retroreflection.returned_intensity_cd`,
    spread as a Lambertian lens does (L = I / (A cos θ)), or None where it returns nothing."""
    rot = world[:3, :3]
    centre, normal = rot @ lr.centre + world[:3, 3], rot @ lr.normal
    rearward = -rot[:, 0]  # R3's reference axis: straight back along the car
    to_camera = np.asarray(ego_vehicle.CAMERA_POSITION_M) - centre
    cos_camera = float(np.dot(normal, to_camera) / np.linalg.norm(to_camera))
    intensity = retroreflection.returned_intensity_cd(centre, rearward)
    if intensity <= 0.0 or cos_camera <= 0.0:
        return None
    wl, rad = lamp_photometry.retroreflected_red(ego_vehicle.LAMP_SPECTRUM, intensity / (lr.area_m2 * cos_camera))
    return Lamp(lr.key, retroreflection.EGO_GROUP, _lamp_shape(lr, world),
                lamp_photometry.area_emitter(wl, rad, sampled=False))
