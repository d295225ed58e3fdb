"""Procedural trees beside the road: a trunk frustum and a few lumpy canopy blobs (or cones).

Geometry is deliberately coarse (about 250 triangles per tree): at 25-400 m a tree covers
tens of pixels, and all trunks and all canopies of a road are merged into a handful of
meshes so scene loading stays fast. Canopies use the ``leaves`` reflectance (green leaf,
chlorophyll dip and red edge; see materials.py) in three tones, trunks ``bark``.
"""

from __future__ import annotations

import numpy as np

from metricscenes.assets import meshes
from metricscenes.assets.materials import reflectance
from metricscenes.assets.parts import SceneParts, mesh_shape, spectrum
from metricscenes.spectral import WAVELENGTHS_NM

CANOPY_TONES = (0.75, 1.0, 1.3)
_PAD_NM = np.concatenate([[380.0], WAVELENGTHS_NM, [720.0]])


def diffuse_bsdf(material: str, scale: float = 1.0) -> dict:
    """Lambertian BSDF of a materials.py reflectance × ``scale``, edge-padded to 380-720 nm.

    The padding keeps the 400 nm and 700 nm bands (395-405, 695-705 nm) fully covered.
    """
    r = np.clip(reflectance(material) * scale, 0.0, 0.98)
    return {"type": "diffuse", "reflectance": spectrum(_PAD_NM, np.concatenate([[r[0]], r, [r[-1]]]))}


def tree(rng: np.random.Generator, base_m, height_m: float, conifer: bool) -> tuple[meshes.Mesh, meshes.Mesh]:
    """One tree standing at ``base_m``: (trunk mesh, canopy mesh); reaches at most 0.4 height sideways."""
    base = np.asarray(base_m, float)
    crown_r = height_m * rng.uniform(0.22, 0.32)
    if conifer:
        trunk = meshes.prism(base, 0.12 * height_m / 10, 0.3 * height_m, sides=6)
        z0 = 0.2 * height_m
        canopy = meshes.concat([
            meshes.prism(base + [0, 0, z0 + k * 0.22 * height_m], crown_r * (1 - 0.25 * k), 0.45 * height_m,
                         sides=9, top_radius_m=0.02)
            for k in range(3)])
        return trunk, canopy
    crown_z = height_m * rng.uniform(0.28, 0.36)  # vertical semi-axis: crown ~ 2/3 of the height
    radius = 0.15 * height_m / 10 + 0.05
    trunk = meshes.prism(base, radius, height_m - crown_z, sides=6, top_radius_m=0.6 * radius)
    centre = base + [0, 0, height_m - crown_z]
    n = meshes.icosphere_vertex_count(1)
    blobs = []
    for _ in range(int(rng.integers(2, 5))):
        offset = np.clip(rng.normal(0, 0.2 * crown_r, 3), -0.3 * crown_r, 0.3 * crown_r) * [1, 1, 0.6]
        radii = rng.uniform(0.6, 0.85, 3) * [crown_r, crown_r, crown_z]
        blobs.append(meshes.ellipsoid(centre + offset, radii, 1, rng.uniform(0.85, 1.12, n)))
    return trunk, meshes.concat(blobs)


def tree_parts(
    rng: np.random.Generator,
    rows: list[tuple[float, int, float]],
    spacing_m: float,
    x_range_m: tuple[float, float] = (5.0, 390.0),
    height_range_m: tuple[float, float] = (6.0, 16.0),
    prefix: str = "tree",
) -> SceneParts:
    """Trees along the road, one row per ``(y_near_m, side, depth_m)``; mean spacing ``spacing_m``.

    ``side`` is +1 for a row left of the road (y grows away from it) and -1 for the right.
    Each trunk stands ``0.4 height + 0.5 m + U(0, depth_m)`` beyond ``y_near_m``, so no canopy
    crosses ``y_near_m`` (the road edge plus a margin): trees never overhang the corridor.
    Returns shapes '{prefix}_trunks' and '{prefix}_canopy_{k}' (three leaf tones).
    """
    if spacing_m <= 0:
        raise ValueError(f"tree spacing_m must be > 0, got {spacing_m}")
    trunks, canopies = [], [[] for _ in CANOPY_TONES]
    for y_near, side, depth in rows:
        if side not in (-1, 1):
            raise ValueError(f"tree row side must be +1 or -1, got {side}")
        x = x_range_m[0] + rng.uniform(0, spacing_m)
        while x < x_range_m[1]:
            height = rng.uniform(*height_range_m)
            y = y_near + side * (0.4 * height + 0.5 + rng.uniform(0, depth))
            t, c = tree(rng, [x, y, -0.02], height, conifer=bool(rng.uniform() < 0.3))
            trunks.append(t)
            canopies[int(rng.integers(len(CANOPY_TONES)))].append(c)
            x += spacing_m * rng.uniform(0.4, 1.6)
    shapes: dict[str, object] = {}
    if trunks:
        v, f = meshes.concat(trunks)
        shapes[f"{prefix}_trunks"] = mesh_shape(f"{prefix}_trunks", v, f, diffuse_bsdf("bark"))
    for k, group in enumerate(canopies):
        if group:
            v, f = meshes.concat(group)
            name = f"{prefix}_canopy_{k}"
            shapes[name] = mesh_shape(name, v, f, diffuse_bsdf("leaves", CANOPY_TONES[k]))
    return SceneParts(shapes=shapes)
