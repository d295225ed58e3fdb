"""Small numpy mesh primitives (vertices in metres, triangle faces) for the environment assets.

Each function returns ``(vertices_m (N, 3), faces (M, 3))``; :func:`concat` joins many
primitives into one mesh so a whole row of trees or lane dashes costs one Mitsuba shape.
Faces are wound counter-clockwise seen from outside (normals point outwards / up).
"""

from __future__ import annotations

from functools import lru_cache

import numpy as np

Mesh = tuple[np.ndarray, np.ndarray]


def quads_z(rects: np.ndarray) -> Mesh:
    """Horizontal rectangles facing +z; ``rects`` rows are (x0, x1, y0, y1, z) in metres."""
    r = np.asarray(rects, dtype=float).reshape(-1, 5)
    x0, x1, y0, y1, z = r.T
    v = np.stack([np.stack([x0, y0, z], 1), np.stack([x1, y0, z], 1),
                  np.stack([x1, y1, z], 1), np.stack([x0, y1, z], 1)], axis=1).reshape(-1, 3)
    base = 4 * np.arange(len(r))[:, None]
    f = np.concatenate([base + [0, 1, 2], base + [0, 2, 3]], axis=0)
    return v, f


def box(center_m, size_m) -> Mesh:
    """Axis-aligned box (12 triangles, outward winding)."""
    c, h = np.asarray(center_m, float), np.asarray(size_m, float) / 2
    corners = np.array([[sx, sy, sz] for sz in (-1, 1) for sy in (-1, 1) for sx in (-1, 1)], float)
    v = c + corners * h
    f = np.array([[0, 2, 1], [1, 2, 3], [4, 5, 6], [5, 7, 6], [0, 1, 4], [1, 5, 4],
                  [2, 6, 3], [3, 6, 7], [0, 4, 2], [2, 4, 6], [1, 3, 5], [3, 7, 5]])
    return v, f


def prism(base_m, radius_m: float, height_m: float, sides: int = 8, top_radius_m: float | None = None) -> Mesh:
    """Vertical n-sided prism (or frustum / cone with ``top_radius_m``) standing on ``base_m``."""
    top = radius_m if top_radius_m is None else top_radius_m
    a = 2 * np.pi * np.arange(sides) / sides
    ring = np.stack([np.cos(a), np.sin(a), np.zeros(sides)], 1)
    b = np.asarray(base_m, float)
    v = np.concatenate([b + ring * radius_m, b + ring * top + [0, 0, height_m], [b + [0, 0, height_m]]])
    i = np.arange(sides)
    j = (i + 1) % sides
    f = np.concatenate([np.stack([i, j, j + sides], 1), np.stack([i, j + sides, i + sides], 1),
                        np.stack([i + sides, j + sides, np.full(sides, 2 * sides)], 1)])
    return v, f


@lru_cache(maxsize=4)
def _unit_icosphere(subdivisions: int) -> Mesh:
    t = (1 + 5**0.5) / 2
    v = np.array([[-1, t, 0], [1, t, 0], [-1, -t, 0], [1, -t, 0], [0, -1, t], [0, 1, t],
                  [0, -1, -t], [0, 1, -t], [t, 0, -1], [t, 0, 1], [-t, 0, -1], [-t, 0, 1]], float)
    f = np.array([[0, 11, 5], [0, 5, 1], [0, 1, 7], [0, 7, 10], [0, 10, 11], [1, 5, 9], [5, 11, 4],
                  [11, 10, 2], [10, 7, 6], [7, 1, 8], [3, 9, 4], [3, 4, 2], [3, 2, 6], [3, 6, 8],
                  [3, 8, 9], [4, 9, 5], [2, 4, 11], [6, 2, 10], [8, 6, 7], [9, 8, 1]])
    verts = list(v)
    for _ in range(subdivisions):
        cache: dict[tuple[int, int], int] = {}

        def mid(a: int, b: int) -> int:
            key = (min(a, b), max(a, b))
            if key not in cache:
                verts.append((verts[a] + verts[b]) / 2)
                cache[key] = len(verts) - 1
            return cache[key]

        new = []
        for a, b, c in f:
            ab, bc, ca = mid(a, b), mid(b, c), mid(c, a)
            new += [[a, ab, ca], [b, bc, ab], [c, ca, bc], [ab, bc, ca]]
        f = np.array(new)
    v = np.array(verts)
    return v / np.linalg.norm(v, axis=1, keepdims=True), f


def ellipsoid(center_m, radii_m, subdivisions: int = 1, jitter: np.ndarray | None = None) -> Mesh:
    """Icosphere scaled to ``radii_m``; ``jitter`` (N,) multiplies vertex radii (lumpy blobs)."""
    v, f = _unit_icosphere(subdivisions)
    scale = np.asarray(radii_m, float)
    if jitter is not None:
        v = v * np.asarray(jitter, float)[:, None]
    return np.asarray(center_m, float) + v * scale, f.copy()


def icosphere_vertex_count(subdivisions: int = 1) -> int:
    """Number of vertices of :func:`ellipsoid` at ``subdivisions`` (to size a jitter array)."""
    return len(_unit_icosphere(subdivisions)[0])


def concat(meshes: list[Mesh]) -> Mesh:
    """Join meshes into one (faces re-indexed)."""
    if not meshes:
        raise ValueError("concat needs at least one mesh")
    verts, faces, offset = [], [], 0
    for v, f in meshes:
        verts.append(v)
        faces.append(f + offset)
        offset += len(v)
    return np.concatenate(verts), np.concatenate(faces)
