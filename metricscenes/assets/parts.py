"""Shared containers and helpers for procedural scene parts (Mitsuba 3 dicts and meshes).

Every asset builder (cars, roads, vegetation, street lights) returns a :class:`SceneParts`:
non-emissive shapes that are always in the scene, plus :class:`Lamp` objects whose emitters
are switched on per light group (DESIGN.md §2, light groups). Spectra are always given as
Mitsuba ``irregular`` spectra in nm so that ``scalar_spectral`` uses physical values
(an RGB or float value would be upsampled and multiplied by D65; see mitsuba-notes.md).
"""

from __future__ import annotations

from dataclasses import dataclass, field

import numpy as np

LIGHT_GROUPS = ("car_lights", "street_lights", "ego_lights", "ego_high_beam")
SPECTRUM_PAD_NM = (380.0, 720.0)


@dataclass(frozen=True)
class Lamp:
    """One switchable light source.

    ``shape`` is a Mitsuba shape dict without an emitter (it stays in the scene in every
    light group, so it occludes and reflects); ``emitter`` is attached to it as its
    ``'emitter'`` (an ``area`` emitter) when ``light_group`` is rendered. When ``shape`` is
    None the emitter is a point/spot light added at the scene's top level.
    """

    name: str
    light_group: str
    shape: dict | None
    emitter: dict

    def __post_init__(self) -> None:
        if self.light_group not in LIGHT_GROUPS:
            raise ValueError(f"Lamp.light_group must be one of {LIGHT_GROUPS}, got {self.light_group!r}")


@dataclass(frozen=True)
class SceneParts:
    """Non-emissive shapes (unique key -> Mitsuba shape dict or ``mi.Mesh``) and lamps."""

    shapes: dict[str, object] = field(default_factory=dict)
    lamps: tuple[Lamp, ...] = ()

    def merged(self, other: "SceneParts") -> "SceneParts":
        """Union of two part sets; raises ValueError on a repeated shape key or lamp name."""
        clash = set(self.shapes) & set(other.shapes)
        if clash:
            raise ValueError(f"duplicate shape keys when merging SceneParts: {sorted(clash)[:5]}")
        names = {lamp.name for lamp in self.lamps}
        lamp_clash = names & {lamp.name for lamp in other.lamps}
        if lamp_clash:
            raise ValueError(f"duplicate lamp names when merging SceneParts: {sorted(lamp_clash)[:5]}")
        return SceneParts(shapes={**self.shapes, **other.shapes}, lamps=self.lamps + other.lamps)


def spectrum(wavelengths_nm, values, hold_ends: bool = True) -> dict:
    """Mitsuba ``irregular`` spectrum dict from wavelengths (nm, increasing) and values.

    With ``hold_ends`` (reflectances, emission), a table that stops inside 380-720 nm
    is held constant out to those ends; a band-pass filter passes ``hold_ends=False``.
    """
    wl = np.asarray(wavelengths_nm, dtype=float).ravel()
    val = np.asarray(values, dtype=float).ravel()
    if wl.shape != val.shape or wl.size < 2:
        raise ValueError(f"spectrum needs >= 2 matching wavelengths and values, got {wl.size} and {val.size}")
    if np.any(np.diff(wl) <= 0):
        raise ValueError("spectrum wavelengths_nm must be strictly increasing")
    # Mitsuba reads an irregular spectrum as zero outside its table, and the end bands
    # span 395-405 and 695-705 nm: hold the end values out to 380 and 720 nm.
    if hold_ends and wl[0] > SPECTRUM_PAD_NM[0]:
        wl, val = np.r_[SPECTRUM_PAD_NM[0], wl], np.r_[val[0], val]
    if hold_ends and wl[-1] < SPECTRUM_PAD_NM[1]:
        wl, val = np.r_[wl, SPECTRUM_PAD_NM[1]], np.r_[val, val[-1]]
    return {
        "type": "irregular",
        "wavelengths": ", ".join(f"{w:.6g}" for w in wl),
        "values": ", ".join(f"{v:.9g}" for v in val),
    }


def mesh_shape(
    name: str,
    vertices_m: np.ndarray,
    faces: np.ndarray,
    bsdf: dict,
    normals: np.ndarray | None = None,
    to_world=None,
):
    """Build a ``mi.Mesh`` from numpy arrays (the caller has already set the Mitsuba variant).

    ``vertices_m`` (N, 3) in metres, ``faces`` (M, 3) vertex indices, optional per-vertex
    ``normals`` (N, 3) for smooth shading, optional ``to_world`` (``mi.ScalarTransform4f``
    or 4x4 array) applied to the vertices here.
    """
    import mitsuba as mi

    v = np.asarray(vertices_m, dtype=np.float64).reshape(-1, 3)
    f = np.asarray(faces, dtype=np.int64).reshape(-1, 3)
    if v.size == 0 or f.size == 0:
        raise ValueError(f"mesh {name!r} has no vertices or faces")
    if f.min() < 0 or f.max() >= len(v):
        raise ValueError(f"mesh {name!r} face index out of range [0, {len(v)})")
    n = None if normals is None else np.asarray(normals, dtype=np.float64).reshape(-1, 3)
    if to_world is not None:
        m = np.asarray(to_world.matrix if hasattr(to_world, "matrix") else to_world, dtype=np.float64)
        m = np.array(m).reshape(4, 4)
        v = v @ m[:3, :3].T + m[:3, 3]
        if n is not None:
            n = n @ np.linalg.inv(m[:3, :3])
    if n is not None:
        n = n / np.maximum(np.linalg.norm(n, axis=1, keepdims=True), 1e-12)
    mesh = mi.Mesh(
        name,
        vertex_count=len(v),
        face_count=len(f),
        has_vertex_normals=n is not None,
        has_vertex_texcoords=False,
    )
    params = mi.traverse(mesh)
    params["vertex_positions"] = v.astype(np.float32).ravel()
    params["faces"] = f.astype(np.uint32).ravel()
    if n is not None:
        params["vertex_normals"] = n.astype(np.float32).ravel()
    params.update()
    mesh.set_bsdf(_loaded_bsdf(mi.variant(), repr(bsdf), bsdf))
    return mesh


_BSDF_CACHE: dict[tuple[str, str], object] = {}


def _loaded_bsdf(variant: str, key: str, bsdf: dict):
    """Load a BSDF dict once per variant (``mi.load_dict`` of a spectral BSDF costs ~20 ms)."""
    import mitsuba as mi

    if (variant, key) not in _BSDF_CACHE:
        if len(_BSDF_CACHE) > 512:
            _BSDF_CACHE.clear()
        _BSDF_CACHE[(variant, key)] = mi.load_dict(bsdf)
    return _BSDF_CACHE[(variant, key)]
