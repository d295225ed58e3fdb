"""Lofted car body geometry from side-profile curves and superellipse cross-sections.

Car frame: x toward the front, y left, z up, origin on the ground under the car's centre.
A body is described along u in [0, 1] (0 = rear tip, 1 = front tip):
- ``z_top(u)``/``z_bot(u)``: side-profile curves of the lower body (trunk deck, beltline,
  hood, bumpers; ground clearance), monotone cubic (PCHIP) through control points;
- ``half_width(u)``: plan-view superellipse, so the ends taper and round off;
- cross-sections: superellipses, rounder above the widest line than below;
- a greenhouse lofted on the beltline with inward-leaning sides (tumblehome), whose roof
  profile gives windshield rake, roof and rear window/hatch;
- wheel arches cut by lifting the outer underside of sections above the tyres.
The superellipse body is the classic parametric-car construction (e.g. Barr 1981,
"Superquadrics and angle-preserving transformations", IEEE CG&A 1(1)).
"""

from __future__ import annotations

from dataclasses import dataclass
from functools import cached_property

import numpy as np
from scipy.interpolate import PchipInterpolator


def _spow(x: np.ndarray, p: float) -> np.ndarray:
    return np.sign(x) * np.abs(x) ** p


def orient_faces(vertices: np.ndarray, faces: np.ndarray, outward: np.ndarray) -> np.ndarray:
    """Flip triangles whose normal points against ``outward`` (one vector per face)."""
    a, b, c = (vertices[faces[:, k]] for k in range(3))
    n = np.cross(b - a, c - a)
    flip = np.einsum("ij,ij->i", n, outward) < 0
    out = faces.copy()
    out[flip] = out[flip][:, [0, 2, 1]]
    return out


def vertex_normals(vertices: np.ndarray, faces: np.ndarray) -> np.ndarray:
    """Area-weighted vertex normals (unit; +z where a vertex has no area)."""
    a, b, c = (vertices[faces[:, k]] for k in range(3))
    fn = np.cross(b - a, c - a)
    vn = np.zeros_like(vertices)
    for k in range(3):
        np.add.at(vn, faces[:, k], fn)
    norm = np.linalg.norm(vn, axis=1, keepdims=True)
    vn = np.where(norm > 1e-12, vn / np.maximum(norm, 1e-12), [0.0, 0.0, 1.0])
    return vn


def grid_faces(n_rows: int, n_cols: int, wrap_cols: bool = False) -> np.ndarray:
    """Two triangles per quad of an (n_rows x n_cols) vertex grid (row-major indices)."""
    cols = n_cols if wrap_cols else n_cols - 1
    i, j = np.meshgrid(np.arange(n_rows - 1), np.arange(cols), indexing="ij")
    i, j = i.ravel(), j.ravel()
    j1 = (j + 1) % n_cols
    v00, v01 = i * n_cols + j, i * n_cols + j1
    v10, v11 = (i + 1) * n_cols + j, (i + 1) * n_cols + j1
    return np.concatenate([np.stack([v00, v10, v11], 1), np.stack([v00, v11, v01], 1)])


@dataclass(frozen=True)
class BodyShape:
    """Parametric body: dimensions (m), profile control points (u, z/height) and greenhouse."""

    length_m: float
    width_m: float
    height_m: float
    top_pts: tuple[tuple[float, float], ...]  # lower-body top (deck, belt, hood), z as fraction of height
    bot_pts: tuple[tuple[float, float], ...]  # underside, z as fraction of height
    greenhouse_u: tuple[float, float, float, float]  # rear-window base, roof rear, roof front, windshield base
    tumblehome: float = 0.78  # roof half-width / beltline half-width
    plan_exponent: float = 7.0  # plan-view superellipse exponent (higher = squarer corners)
    section_exponent_up: float = 3.2
    section_exponent_down: float = 4.0
    widest_frac: float = 0.55  # height of the widest line between underside and top

    def x_of_u(self, u):
        return (np.asarray(u, float) - 0.5) * self.length_m

    def u_of_x(self, x):
        return np.asarray(x, float) / self.length_m + 0.5

    @cached_property
    def _top_curve(self) -> PchipInterpolator:
        p = np.array(self.top_pts)
        return PchipInterpolator(p[:, 0], p[:, 1] * self.height_m)

    @cached_property
    def _bot_curve(self) -> PchipInterpolator:
        p = np.array(self.bot_pts)
        return PchipInterpolator(p[:, 0], p[:, 1] * self.height_m)

    def z_top(self, u):
        return self._top_curve(np.clip(u, 0, 1))

    def z_bot(self, u):
        return self._bot_curve(np.clip(u, 0, 1))

    def half_width(self, u):
        t = np.clip(np.abs(2.0 * np.asarray(u, float) - 1.0), 0.0, 1.0)
        return 0.5 * self.width_m * (1.0 - t**self.plan_exponent) ** (1.0 / self.plan_exponent)

    def section(self, u):
        """(zc, h_up, h_down, half_width) of the lower-body section at u."""
        zt, zb = self.z_top(u), self.z_bot(u)
        zc = zb + self.widest_frac * (zt - zb)
        return zc, zt - zc, zc - zb, self.half_width(u)

    def inside(self, u, y, z):
        """True where (y, z) lies inside the lower-body section at u (arches ignored)."""
        zc, hu, hd, w = self.section(u)
        dz = np.asarray(z, float) - zc
        n = np.where(dz > 0, self.section_exponent_up, self.section_exponent_down)
        h = np.where(dz > 0, hu, hd)
        return (np.abs(y) / np.maximum(w, 1e-9)) ** n + (np.abs(dz) / np.maximum(h, 1e-9)) ** n <= 1.0

    def surface_x(self, y, z, front: bool, iterations: int = 30):
        """x of the body surface at the front (or rear) end for lateral y and height z."""
        y, z = np.broadcast_arrays(np.asarray(y, float), np.asarray(z, float))
        lo = np.full(y.shape, 0.5)  # inside at mid-body by construction
        hi = np.full(y.shape, 1.0 if front else 0.0)
        for _ in range(iterations):
            mid = 0.5 * (lo + hi)
            ins = self.inside(mid, y, z)
            lo = np.where(ins, mid, lo)
            hi = np.where(ins, hi, mid)
        return self.x_of_u(lo)

    def shoulder_z(self, u, y):
        """Height of the lower-body top surface at lateral offset y (|y| < half width)."""
        zc, hu, _, w = self.section(u)
        r = np.clip(np.abs(y) / np.maximum(w, 1e-9), 0, 1)
        return zc + hu * (1.0 - r**self.section_exponent_up) ** (1.0 / self.section_exponent_up)

    # --- meshes -------------------------------------------------------------------------
    def lower_body(self, wheels_x, tyre_radius_m, track_m, tyre_width_m, n_stations=96, n_around=56):
        """(vertices, faces) of the lower body with wheel arches over the wheels at ``wheels_x``."""
        t = np.linspace(0.0, 1.0, n_stations)
        u = 0.65 * (0.5 - 0.5 * np.cos(np.pi * t)) + 0.35 * t  # denser near the bumpers
        zc, hu, hd, w = self.section(u)
        th = np.linspace(0, 2 * np.pi, n_around, endpoint=False)
        c, s = np.cos(th), np.sin(th)
        y = w[:, None] * _spow(c, 2 / self.section_exponent_up)[None]
        up = s >= 0
        ez = np.where(up, 2 / self.section_exponent_up, 2 / self.section_exponent_down)
        z = zc[:, None] + np.where(up, hu[:, None], hd[:, None]) * _spow(s, ez)[None]
        # lower half sides use the flatter exponent in y too
        y = np.where(up[None], y, w[:, None] * _spow(c, 2 / self.section_exponent_down)[None])
        x = np.broadcast_to(self.x_of_u(u)[:, None], y.shape).copy()
        # wheel arches: lift the outer underside above each tyre
        r_arch = 1.12 * tyre_radius_m
        y_in = 0.5 * track_m - 0.5 * tyre_width_m - 0.03
        for xw in wheels_x:
            dx = x - xw
            inside = np.abs(dx) < r_arch
            z_arch = tyre_radius_m + np.sqrt(np.clip(r_arch**2 - dx**2, 0, None))
            lift = inside & (np.abs(y) > y_in) & (z < z_arch)
            z = np.where(lift, np.minimum(z_arch, zc[:, None] + 0.8 * hu[:, None]), z)
        v = np.stack([x, y, z], -1).reshape(-1, 3)
        f = grid_faces(n_stations, n_around, wrap_cols=True)
        centre = np.stack([x, np.zeros_like(x), np.broadcast_to(zc[:, None], x.shape)], -1).reshape(-1, 3)
        out = v[f].mean(1) - centre[f[:, 0]]
        return v, orient_faces(v, f, out)

    def greenhouse_profile(self):
        """(u_nodes, z_nodes) of the greenhouse top (windshield, roof, rear window)."""
        urb, urr, urf, uws = self.greenhouse_u
        h = self.height_m
        zr = float(self.z_top(urb))
        zf = float(self.z_top(uws))
        um = 0.5 * (urr + urf)
        return np.array([urb, urr, um, urf, uws]), np.array([zr, 0.985 * h, h, 0.985 * h, zf])

    def greenhouse(self, n_stations=64, n_around=36, exponent=5.0):
        """(vertices, faces, s, envelope, h) of the greenhouse, per vertex: s = normalised height in
        its section, envelope = section half-width at that height, h = section height (m)."""
        urb, urr, urf, uws = self.greenhouse_u
        t = np.linspace(0, 1, n_stations)
        u = urb + (uws - urb) * t
        un, zn = self.greenhouse_profile()
        z_roof = PchipInterpolator(un, zn)(u)
        wb = 0.86 * self.half_width(u)
        z_base = self.shoulder_z(u, wb) - 0.012
        h = np.clip(z_roof - z_base, 0, None)
        th = np.linspace(0, np.pi, n_around)
        cy = _spow(np.cos(th), 2 / exponent)
        ss = np.abs(np.sin(th)) ** (2 / exponent)
        y = cy[None] * wb[:, None] * (1 - (1 - self.tumblehome) * ss[None])
        z = z_base[:, None] + h[:, None] * ss[None]
        x = np.broadcast_to(self.x_of_u(u)[:, None], y.shape)
        v = np.stack([x, y, z], -1).reshape(-1, 3)
        f = grid_faces(n_stations, n_around)
        ref = np.stack([x, np.zeros_like(y), np.broadcast_to(z_base[:, None] - 0.4, y.shape)], -1).reshape(-1, 3)
        f = orient_faces(v, f, v[f].mean(1) - ref[f[:, 0]])
        s_v = np.broadcast_to(ss[None], y.shape).ravel()
        env = (wb[:, None] * (1 - (1 - self.tumblehome) * ss[None])).ravel()
        h_v = np.broadcast_to(h[:, None], y.shape).ravel()
        return v, f, s_v, env, h_v


def lathe(profile_ry: np.ndarray, n_segments: int = 40) -> tuple[np.ndarray, np.ndarray]:
    """Revolve a (radius, y) polyline about the y axis: (vertices, faces)."""
    phi = np.linspace(0, 2 * np.pi, n_segments, endpoint=False)
    r, yy = profile_ry[:, 0], profile_ry[:, 1]
    x = r[:, None] * np.cos(phi)[None]
    z = r[:, None] * np.sin(phi)[None]
    y = np.broadcast_to(yy[:, None], x.shape)
    v = np.stack([x, y, z], -1).reshape(-1, 3)
    f = grid_faces(len(profile_ry), n_segments, wrap_cols=True)
    return v, f


def superellipsoid(center, half_m, exponent=4.0, n_u=16, n_v=12) -> tuple[np.ndarray, np.ndarray]:
    """Rounded box (superellipsoid) mesh: (vertices, faces), outward-oriented."""
    th = np.linspace(-np.pi / 2, np.pi / 2, n_v)
    ph = np.linspace(0, 2 * np.pi, n_u, endpoint=False)
    e = 2.0 / exponent
    ct, st = _spow(np.cos(th), e), _spow(np.sin(th), e)
    cp, sp = _spow(np.cos(ph), e), _spow(np.sin(ph), e)
    x = half_m[0] * ct[:, None] * cp[None]
    y = half_m[1] * ct[:, None] * sp[None]
    z = half_m[2] * np.broadcast_to(st[:, None], x.shape)
    v = np.stack([x, y, z], -1).reshape(-1, 3)
    f = grid_faces(n_v, n_u, wrap_cols=True)
    f = orient_faces(v, f, v[f].mean(1))
    return v + np.asarray(center, float), f
