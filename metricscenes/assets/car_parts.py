"""Car geometry assembly in the car frame (x front, y left, z up, origin on the ground).

Turns a :class:`~metricscenes.assets.car_body.BodyShape` plus wheel/lamp parameters into
plain numpy meshes tagged with a material name, and flat lamp rectangles. Mitsuba objects
are made later (``cars.car_parts``) so that geometry stays testable without a renderer.
"""

from __future__ import annotations

from dataclasses import dataclass

import numpy as np

from metricscenes.assets.car_body import BodyShape, lathe, orient_faces, superellipsoid, vertex_normals


@dataclass(frozen=True)
class MeshPart:
    key: str
    vertices: np.ndarray
    faces: np.ndarray
    material: str  # 'paint' or a materials.bsdf name
    smooth: bool = True


@dataclass(frozen=True)
class LampRect:
    """A flat lamp lens: centre, unit axes (e1 horizontal, e2 up-ish, normal), half sizes (m)."""

    key: str
    role: str  # 'head' or 'tail'
    centre: np.ndarray
    e1: np.ndarray
    e2: np.ndarray
    normal: np.ndarray
    half_m: tuple[float, float]
    material: str

    @property
    def area_m2(self) -> float:
        return 4.0 * self.half_m[0] * self.half_m[1]

    def corners(self) -> np.ndarray:
        a, b = self.half_m
        return np.array([self.centre + sa * a * self.e1 + sb * b * self.e2 for sa in (-1, 1) for sb in (-1, 1)])

    def matrix(self) -> np.ndarray:
        """4x4 car-frame transform of Mitsuba's unit ``rectangle`` ([-1,1]², normal +z)."""
        m = np.eye(4)
        m[:3, 0] = self.e1 * self.half_m[0]
        m[:3, 1] = self.e2 * self.half_m[1]
        m[:3, 2] = self.normal
        m[:3, 3] = self.centre
        return m


def _surface_frame(body: BodyShape, y: float, z: float, front: bool, offset_m: float):
    """Point on the front/rear surface at (y, z) pushed out by offset, and its frame."""
    d = 0.01
    xs = body.surface_x(np.array([y, y + d, y - d, y, y]), np.array([z, z, z, z + d, z - d]), front)
    x0 = float(xs[0])
    gy = float(xs[1] - xs[2]) / (2 * d)
    gz = float(xs[3] - xs[4]) / (2 * d)
    n = np.array([1.0, -0.5 * gy, -gz]) * (1.0 if front else -1.0)  # half the wrap: lamps sit flush
    n /= np.linalg.norm(n)
    p = np.array([x0, y, z]) + offset_m * n
    e1 = np.cross([0.0, 0.0, 1.0], n)
    e1 /= np.linalg.norm(e1)
    e2 = np.cross(n, e1)
    return p, e1, e2, n


def conformal_patch(body: BodyShape, front: bool, yc, zc, half_y, half_z, offset_m=0.004,
                    roundness=6.0, n=(10, 6)) -> tuple[np.ndarray, np.ndarray]:
    """Rounded-rectangle patch following the front/rear surface (grilles, plates, housings)."""
    ny, nz = n
    t = np.linspace(-1, 1, nz)
    scale = (1 - np.abs(0.97 * t) ** roundness) ** (1 / roundness)  # 0.97: keep the end rows wide
    s = np.linspace(-1, 1, ny)
    zz = np.broadcast_to((zc + half_z * t)[:, None], (nz, ny))
    yy = yc + half_y * scale[:, None] * s[None]
    xx = body.surface_x(yy, zz, front)
    sign = 1.0 if front else -1.0
    v = np.stack([xx + sign * offset_m, yy, zz], -1).reshape(-1, 3)
    from metricscenes.assets.car_body import grid_faces

    f = grid_faces(nz, ny)
    out = np.tile([sign, 0.0, 0.0], (len(f), 1))
    return v, orient_faces(v, f, out)


def wheel_meshes(prefix: str, x_m: float, y_m: float, radius_m: float, width_m: float, outward: float):
    """Tyre (rubber) and rim (two materials: spokes and dark gaps) at axle centre (x, y, r)."""
    r, hw = radius_m, 0.5 * width_m
    rr = 0.66 * r
    prof = np.array([
        (rr, -hw + 0.01), (r - 0.055, -hw), (r - 0.02, -hw + 0.012), (r, -hw + 0.045),
        (r, hw - 0.045), (r - 0.02, hw - 0.012), (r - 0.055, hw), (rr, hw - 0.01),
    ])
    v, f = lathe(prof, 48)
    core = v.copy()
    rad = np.linalg.norm(v[:, [0, 2]], axis=1, keepdims=True)
    core[:, [0, 2]] = v[:, [0, 2]] / np.maximum(rad, 1e-9) * (0.5 * (r + rr))
    core[:, 1] = 0.0
    f = orient_faces(v, f, v[f].mean(1) - core[f].mean(1))
    centre = np.array([x_m, y_m, r])
    tyre = MeshPart(f"{prefix}_tyre", v + centre, f, "rubber")
    # rim dish on the outer face: lathe + angular spoke/gap split
    yo = outward * (hw - 0.02)
    rim_prof = np.array([(0.0, yo + outward * 0.01), (0.18 * rr, yo + outward * 0.01), (0.3 * rr, yo),
                         (0.85 * rr, yo - outward * 0.01), (rr, yo - outward * 0.025)])
    rv, rf = lathe(rim_prof, 40)
    rf = orient_faces(rv, rf, np.tile([0.0, outward, 0.0], (len(rf), 1)))
    cen = rv[rf].mean(1)
    ang = np.arctan2(cen[:, 2], cen[:, 0])
    rad_c = np.linalg.norm(cen[:, [0, 2]], axis=1)
    gap = (np.mod(ang * 5 / (2 * np.pi), 1.0) > 0.45) & (rad_c > 0.3 * rr) & (rad_c < 0.85 * rr)
    spokes = MeshPart(f"{prefix}_rim", rv + centre, rf[~gap], "aluminium")
    gaps = MeshPart(f"{prefix}_rimgap", rv + centre, rf[gap], "trim_black", smooth=False)
    return [tyre, spokes, gaps]


def split_greenhouse(body: BodyShape, v, f, s_v, env, h_v, pillar_m=0.075, b_pillar_m=0.045, rail_m=0.055):
    """Split greenhouse faces into glass and painted (roof, pillars) by position and normal.

    Windshield/rear window: faces facing fore/aft inside the A/C pillars. Side windows: faces
    facing sideways between the beltline and a roof rail, so their edges follow the A- and
    C-pillar slopes, minus a B-pillar band.
    """
    urb, urr, urf, uws = body.greenhouse_u
    x_rr, x_rf = body.x_of_u(urr), body.x_of_u(urf)
    a, b, c = (v[f[:, k]] for k in range(3))
    nrm = np.cross(b - a, c - a)
    nrm /= np.maximum(np.linalg.norm(nrm, axis=1, keepdims=True), 1e-12)
    cen = (a + b + c) / 3
    s_c, env_c, h_c = s_v[f].mean(1), env[f].mean(1), h_v[f].mean(1)
    x, y = cen[:, 0], np.abs(cen[:, 1])
    side = np.abs(nrm[:, 1]) > 0.6
    in_front = x > x_rf + 0.03
    in_rear = x < x_rr - 0.03
    pillar = np.where(in_rear, 1.6 * pillar_m, pillar_m)  # C/D pillars are wider than A pillars
    in_rear &= x < x_rr - 0.07  # painted header / spoiler band above the rear window
    screen = (in_front | in_rear) & ~side & (y < env_c - pillar) & (s_c > 0.12)
    x_b = 0.5 * (x_rr + x_rf) + 0.05 * (x_rf - x_rr)
    side_glass = (side & (h_c * (1 - s_c) > rail_m) & (h_c * s_c > 0.025) & (h_c > 0.2)
                  & (np.abs(x - x_b) > b_pillar_m))
    glass = screen | side_glass
    return f[glass], f[~glass]


def finish(parts: list[MeshPart]) -> list[MeshPart]:
    """Drop unused vertices of each part (compact index space)."""
    out = []
    for p in parts:
        if len(p.faces) == 0:
            continue
        used, inv = np.unique(p.faces.ravel(), return_inverse=True)
        out.append(MeshPart(p.key, p.vertices[used], inv.reshape(-1, 3), p.material, p.smooth))
    return out


def normals_for(part: MeshPart) -> np.ndarray | None:
    return vertex_normals(part.vertices, part.faces) if part.smooth else None


def mirror_meshes(body: BodyShape, prefix: str):
    urb, urr, urf, uws = body.greenhouse_u
    u = uws - 0.03
    w = float(body.half_width(u)) * 0.86
    z = float(body.z_top(u)) + 0.09
    x = float(body.x_of_u(u)) - 0.05
    out = []
    for side, sgn in (("l", 1), ("r", -1)):
        v, f = superellipsoid((x, sgn * (w + 0.07), z), (0.08, 0.1, 0.06), exponent=3.0)
        out.append(MeshPart(f"{prefix}_mirror_{side}", v, f, "paint"))
        gv, gf = conformal_like_box((x - 0.082, sgn * (w + 0.08), z), (0.08, 0.048))
        out.append(MeshPart(f"{prefix}_mirrorglass_{side}", gv, gf, "car_glass", smooth=False))
    return out


def conformal_like_box(centre, half_yz):
    """A rear-facing (-x) flat quad centred at ``centre`` with half sizes (y, z)."""
    cx, cy, cz = centre
    hy, hz = half_yz
    v = np.array([[cx, cy - hy, cz - hz], [cx, cy + hy, cz - hz], [cx, cy + hy, cz + hz], [cx, cy - hy, cz + hz]])
    f = np.array([[0, 1, 2], [0, 2, 3]])
    return v, orient_faces(v, f, np.tile([-1.0, 0, 0], (2, 1)))


def lamp_rect(body: BodyShape, key: str, role: str, front: bool, y, z, half, material, offset_m=0.008):
    p, e1, e2, n = _surface_frame(body, y, z, front, offset_m)
    return LampRect(key, role, p, e1, e2, n, half, material)
