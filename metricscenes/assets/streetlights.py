"""Street lights: a pole, an arm over the road and a road luminaire (light group 'street_lights').

Each luminaire is an IES Type II medium, full cut-off road distribution scaled to its
rated flux (:mod:`metricscenes.assets.beams`): a goniometric ``spot`` pointing down, its
street side over the road, plus the glowing cover a camera sees, a small Lambertian
``area`` emitter carrying a tenth of the nadir intensity (the spot carries the rest).
Spectrum: a 4000 K LED (CIE LED-B3) or high-pressure sodium (CIE HP1). Poles are 8-10 m high, 30-40 m apart, on one side of the road, standing
1 m beyond the paved edge so they never enter the road corridor; the arm and head hang
at least 7.5 m above the road, far above any sight line from the camera to a car.
"""

from __future__ import annotations

import numpy as np

from metricscenes.assets import beams, lamps, meshes
from metricscenes.assets.parts import Lamp, SceneParts, mesh_shape
from metricscenes.assets.vegetation import diffuse_bsdf

LIGHT_GROUP = "street_lights"
FACE_SIZE_M = (0.6, 0.25)


def _face_dict(center_m, bsdf: dict) -> dict:
    """Downward-facing luminaire face (a ``rectangle``: +z normal flipped to -z)."""
    import mitsuba as mi

    half = [FACE_SIZE_M[0] / 2, FACE_SIZE_M[1] / 2, 1.0]
    to_world = (mi.ScalarTransform4f().translate([float(c) for c in center_m])
                @ mi.ScalarTransform4f().rotate([1, 0, 0], 180.0) @ mi.ScalarTransform4f().scale(half))
    return {"type": "rectangle", "to_world": to_world, "bsdf": bsdf}


def street_light_parts(
    x_positions_m: np.ndarray,
    pole_y_m: float,
    arm_y_m: float,
    height_m: float = 9.0,
    kind: str = "led_4000k",
    flux_lm: float = 9000.0,
    prefix: str = "streetlight",
) -> SceneParts:
    """Street lights at ``x_positions_m``: poles at ``pole_y_m``, heads at ``arm_y_m``.

    Returns shapes '{prefix}_poles' (one mesh: poles, arms, heads) and one :class:`Lamp`
    per luminaire named '{prefix}_{i:02d}' in light group 'street_lights'.
    """
    if height_m < 7.5:
        raise ValueError(f"street light height_m must be >= 7.5 m (above the car corridor), got {height_m}")
    if not flux_lm > 0:
        raise ValueError(f"street light flux_lm must be > 0, got {flux_lm}")
    xs = np.asarray(x_positions_m, dtype=float).ravel()
    if xs.size == 0:
        return SceneParts()
    spd = lamps.street_light_spd(kind)
    lens_cd = beams.LUMINAIRE_LENS_FRACTION * beams.road_luminaire_nadir_cd(flux_lm)
    wl, radiance = lamps.scaled_to_luminous(spd, lens_cd / (FACE_SIZE_M[0] * FACE_SIZE_M[1]))
    emitter = lamps.area_emitter(wl, radiance)
    street_side = 1.0 if arm_y_m > pole_y_m else -1.0
    lens = diffuse_bsdf("lens_clear")
    parts, lamp_list = [], []
    arm_len = abs(arm_y_m - pole_y_m)
    arm_mid = (arm_y_m + pole_y_m) / 2
    for i, x in enumerate(xs):
        parts.append(meshes.prism([x, pole_y_m, -0.02], 0.09, height_m + 0.02, sides=8, top_radius_m=0.06))
        parts.append(meshes.box([x, arm_mid, height_m - 0.05], [0.08, arm_len + 0.1, 0.08]))
        parts.append(meshes.box([x, arm_y_m, height_m - 0.1], [FACE_SIZE_M[0] + 0.1, FACE_SIZE_M[1] + 0.1, 0.15]))
        face = _face_dict([x, arm_y_m, height_m - 0.18], lens)
        lamp_list.append(Lamp(name=f"{prefix}_{i:02d}", light_group=LIGHT_GROUP, shape=face, emitter=emitter))
        spot = beams.luminaire_spot(flux_lm, spd, [x, arm_y_m, height_m - 0.19], street_side, lens_cd)
        lamp_list.append(Lamp(name=f"{prefix}_{i:02d}_beam", light_group=LIGHT_GROUP, shape=None, emitter=spot))
    v, f = meshes.concat(parts)
    poles = mesh_shape(f"{prefix}_poles", v, f, diffuse_bsdf("concrete", 1.3))
    return SceneParts(shapes={f"{prefix}_poles": poles}, lamps=tuple(lamp_list))
