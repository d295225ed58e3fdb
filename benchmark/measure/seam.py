"""Does the inset's window show in a camera's image? The seam figures of one scene (docs/scenes.md,
"The inset seam"; measured over a collection by ``benchmarks/studies/composite_fidelity.py --seam``).

The scene is captured noise-free (sensor noise off, D65 white balance: what is left is the
composite and the render's own noise) with the inset composited as the store gives it, and the
car-less plate alone at the same exposure; the CIELAB difference ΔE*ab per pixel of the two
sRGB images is zero outside the window, and away from the car it is what the window shows.
"""

from __future__ import annotations

import numpy as np

from metricscenes.store import Collection

SEAM_BAND_PX = 3  # band width, camera pixels
SEAM_GAP_PX = 1  # pixels left out inward of the feather ramp's end


def _srgb8_to_linear(rgb8: np.ndarray) -> np.ndarray:
    """Linear RGB of 8-bit sRGB (IEC 61966-2-1), float64 (..., 3)."""
    c = rgb8.astype(np.float64) / 255.0
    return np.where(c <= 0.04045, c / 12.92, ((c + 0.055) / 1.055) ** 2.4)


def srgb8_to_lab(rgb8: np.ndarray) -> np.ndarray:
    """CIELAB (D65 white) of 8-bit sRGB (IEC 61966-2-1), float64 (..., 3)."""
    lin = _srgb8_to_linear(rgb8)
    m = np.array([[0.4124, 0.3576, 0.1805], [0.2126, 0.7152, 0.0722], [0.0193, 0.1192, 0.9505]])
    xyz = lin @ m.T / np.array([0.95047, 1.0, 1.08883])
    f = np.where(xyz > (6 / 29) ** 3, np.cbrt(xyz), xyz / (3 * (6 / 29) ** 2) + 4 / 29)
    return np.stack([116 * f[..., 1] - 16, 500 * (f[..., 0] - f[..., 1]), 200 * (f[..., 1] - f[..., 2])], axis=-1)


def seam_check(collection: Collection, scene_id: str, condition: str, camera, inset_resolution: str) -> dict:
    """The seam figures of one scene in one camera's noise-free image: the per-pixel ΔE*ab
    between the composite's image and the car-less plate's (same exposure and white balance),
    which is zero outside the window, in bands along the window's edges just inward of its
    feather ramp (mean, and the worst line along an edge), and over the whole window's
    background (pixels farther from the car than :func:`metricscenes.radiance.car_sharpness`
    keeps sharp: mean and 99th percentile); and the detail ratio there, mean |∇L*| of the
    composite over the plate's (1: as sharp as the plate)."""
    from benchmark.camera.pipeline import sensor_extent
    from metricscenes.radiance import _overlap_matrix, car_sharpness

    if camera.optics.distortion is not None:
        raise ValueError(f"{camera.name}: the seam check maps the window without lens distortion; "
                         "choose another camera")
    scene = collection.radiance(scene_id, condition, inset_resolution=inset_resolution)
    plate, inset = scene.layers[0], scene.layers[1]
    composite, alone = _noise_free_pair(camera, scene, plate)
    lab_c, lab_p = srgb8_to_lab(composite.rgb8), srgb8_to_lab(alone.rgb8)
    de = np.linalg.norm(lab_c - lab_p, axis=-1)
    # The window on the camera's grid, and its background: wholly inside, away from the car.
    rows, cols = de.shape
    e = sensor_extent(camera, scene.extent)
    i = inset.extent
    ox = _overlap_matrix(i.x0, i.x1, inset.radiance.shape[1], e.x0, e.x1, cols)
    oy = _overlap_matrix(i.y0, i.y1, inset.radiance.shape[0], e.y0, e.y1, rows)
    mask, _ = collection.mask(scene_id)
    near_car = car_sharpness(mask, i, plate.pixel_tan).astype(np.float64)
    near_car = oy @ (ox @ near_car.T).T
    inside = np.outer(np.asarray(oy.sum(axis=1)).ravel(), np.asarray(ox.sum(axis=1)).ravel()) > 1 - 1e-6
    background = inside & (near_car == 0)
    sx, sy = cols / e.width, rows / e.height
    x0, x1 = (i.x0 - e.x0) * sx, (i.x1 - e.x0) * sx
    y0, y1 = (i.y0 - e.y0) * sy, (i.y1 - e.y0) * sy
    rx, ry = inset.feather * (x1 - x0), inset.feather * (y1 - y0)
    c0, c1 = int(np.ceil(x0 + rx)) + SEAM_GAP_PX, int(np.floor(x1 - rx)) - SEAM_GAP_PX
    r0, r1 = int(np.ceil(y0 + ry)) + SEAM_GAP_PX, int(np.floor(y1 - ry)) - SEAM_GAP_PX
    n = SEAM_BAND_PX
    bands = []  # (ΔE, background) over a band, lines along the edge first
    if x0 > 0:
        bands.append((de[r0:r1, c0:c0 + n], background[r0:r1, c0:c0 + n]))
    if x1 < cols:
        bands.append((de[r0:r1, c1 - n:c1], background[r0:r1, c1 - n:c1]))
    if y0 > 0:
        bands.append((de[r0:r0 + n, c0:c1].T, background[r0:r0 + n, c0:c1].T))
    if y1 < rows:
        bands.append((de[r1 - n:r1, c0:c1].T, background[r1 - n:r1, c0:c1].T))
    if not background.any():  # the window is all within the car's few plate pixels (e.g. smoke's far cars)
        raise ValueError(f"{scene_id}: no pixel of the window lies away from the car on {camera.name}'s grid")
    border = np.concatenate([d[b] for d, b in bands] + [np.zeros(0)])
    lines = [float(d[k][b[k]].mean()) for d, b in bands for k in range(d.shape[0]) if b[k].any()] or [np.nan]
    grad = [np.abs(np.diff(lab[..., 0], axis=a)) for lab in (lab_c, lab_p) for a in (0, 1)]

    def detail(along_rows: np.ndarray, along_cols: np.ndarray) -> float:
        return float(along_rows[background[1:] & background[:-1]].mean()
                     + along_cols[background[:, 1:] & background[:, :-1]].mean())

    return {"border_px": int(border.size), "border_de": float(border.mean()) if border.size else np.nan,
            "border_de_max_line": max(lines), "window_px": int(background.sum()),
            "window_de": float(de[background].mean()), "window_de_p99": float(np.percentile(de[background], 99)),
            "outside_de": float(de[~inside].mean()),
            "detail_ratio": detail(grad[0], grad[1]) / detail(grad[2], grad[3])}


def plate_seam_check(collection: Collection, scene_id: str, condition: str, camera) -> dict:
    """Does the reference plate's border show in a wide camera's image (a collection's
    ``wide_plate``: docs/scenes.md, "The wide plate")? The scene is captured noise-free as the
    store composites it, and its wide plate alone at the same exposure and white balance. Along
    each of the plate's four edges, the mean L* step from a band just outside the plate to a band
    just inside its feather ramp is measured on both images: the scene's own change across the
    edge is in both, so their difference (``step_l``, per edge, and the largest) is what the seam
    adds. ``inside_de``: the mean ΔE*ab between the two images over the inner bands (the two
    plates' sampling and render noise)."""
    from benchmark.camera.pipeline import sensor_extent
    from metricscenes.radiance import PLATE_SEAM_FEATHER

    if camera.optics.distortion is not None:
        raise ValueError(f"{camera.name}: the seam check maps the plate without lens distortion; choose another camera")
    scene = collection.radiance(scene_id, condition)
    if scene.surround is None:
        raise ValueError(f"{collection.root}: has no wide plate")
    composite, alone = _noise_free_pair(camera, scene, scene.surround_layer())
    lab_c, lab_s = srgb8_to_lab(composite.rgb8), srgb8_to_lab(alone.rgb8)
    rows, cols = lab_c.shape[:2]
    e, p = sensor_extent(camera, scene.extent), scene.extent  # the camera's grid, the plate's field
    sx, sy = cols / e.width, rows / e.height
    x0, x1, y0, y1 = (p.x0 - e.x0) * sx, (p.x1 - e.x0) * sx, (p.y0 - e.y0) * sy, (p.y1 - e.y0) * sy
    if x0 <= SEAM_BAND_PX or y0 <= SEAM_BAND_PX:
        raise ValueError(f"{camera.name}: sees no more than the reference plate's field on this collection")
    rx, ry = PLATE_SEAM_FEATHER * (x1 - x0), PLATE_SEAM_FEATHER * (y1 - y0)
    n = SEAM_BAND_PX
    out_x0, in_x0 = int(np.floor(x0)) - SEAM_GAP_PX - n, int(np.ceil(x0 + rx)) + SEAM_GAP_PX
    out_x1, in_x1 = int(np.ceil(x1)) + SEAM_GAP_PX, int(np.floor(x1 - rx)) - SEAM_GAP_PX - n
    out_y0, in_y0 = int(np.floor(y0)) - SEAM_GAP_PX - n, int(np.ceil(y0 + ry)) + SEAM_GAP_PX
    out_y1, in_y1 = int(np.ceil(y1)) + SEAM_GAP_PX, int(np.floor(y1 - ry)) - SEAM_GAP_PX - n
    r0, r1, c0, c1 = int(np.ceil(y0 + ry)), int(np.floor(y1 - ry)), int(np.ceil(x0 + rx)), int(np.floor(x1 - rx))
    edges = {  # (band outside, band inside), as index expressions
        "left": ((slice(r0, r1), slice(out_x0, out_x0 + n)), (slice(r0, r1), slice(in_x0, in_x0 + n))),
        "right": ((slice(r0, r1), slice(out_x1, out_x1 + n)), (slice(r0, r1), slice(in_x1, in_x1 + n))),
        "top": ((slice(out_y0, out_y0 + n), slice(c0, c1)), (slice(in_y0, in_y0 + n), slice(c0, c1))),
        "bottom": ((slice(out_y1, out_y1 + n), slice(c0, c1)), (slice(in_y1, in_y1 + n), slice(c0, c1))),
    }
    # Relative luminance (linear): where the two plates differ only in sharpness, their means agree in it.
    lum_c, lum_s = (_relative_luminance(image.rgb8) for image in (composite, alone))
    steps, relative, inner = {}, {}, []
    for edge, (outside, inside) in edges.items():
        step_c = lab_c[inside][..., 0].mean() - lab_c[outside][..., 0].mean()
        step_s = lab_s[inside][..., 0].mean() - lab_s[outside][..., 0].mean()
        steps[edge] = float(step_c - step_s)
        relative[edge] = float((lum_c[inside].mean() - lum_c[outside].mean() - lum_s[inside].mean()
                                + lum_s[outside].mean()) / lum_s[outside].mean())
        inner.append(np.linalg.norm(lab_c[inside] - lab_s[inside], axis=-1).ravel())
    return {"step_l": steps, "step_l_max": max(abs(v) for v in steps.values()),
            "step_luminance": relative, "step_luminance_max": max(abs(v) for v in relative.values()),
            "inside_de": float(np.concatenate(inner).mean())}


def _relative_luminance(rgb8: np.ndarray) -> np.ndarray:
    """Y of 8-bit sRGB (IEC 61966-2-1), linear, float64 (...)."""
    return _srgb8_to_linear(rgb8) @ np.array([0.2126, 0.7152, 0.0722])


def _noise_free_pair(camera, scene, alone):
    """The scene and its layer ``alone`` by itself, captured noise-free by ``camera`` with one white
    balance (the known illuminant: grey world would follow the car's few pixels) at the scene's
    exposure: (the scene's capture, the layer's capture)."""
    from benchmark.camera.exposure import with_exposure
    from benchmark.camera.pipeline import simulate
    from benchmark.camera.spec_exposure import ExposureSpec
    from metricscenes.radiance import SpectralScene

    isp = camera.isp.model_copy(update={"white_balance": "known_illuminant"})
    camera = camera.model_copy(update={"isp": isp})
    composite = simulate(scene, camera, seed=0, noise=False)
    fixed = with_exposure(camera, ExposureSpec(mode="fixed", exposure_s=composite.exposure_s))
    return composite, simulate(SpectralScene(layers=(alone,), wavelengths_nm=scene.wavelengths_nm), fixed, seed=0,
                               noise=False)
