"""A condition's target met at the camera's own image plane, as the paper's lab met it.

ISETCam's ``oiAdjustIlluminance(oi, L)`` (and ``piOICreate(..., 'meanilluminance', L)``), which
the lab's isetauto scripts used to set a scene's condition, scale the optical image *after the
lens* to a mean illuminance L: every camera then gets the same mean image-plane illuminance
whatever its f-number or lens transmittance. A ``target_at: camera`` condition
(``metricscenes.manifest.TargetedCondition``) does the same per camera and scene:

1. each of the condition's parts (the whole mix at its fixed weights, or the ambient group and
   the lamps) is put on the camera's pixel grid (:func:`~benchmark.camera.pipeline.sensor_radiance`);
2. the camera measures each part's mean image-plane illuminance (:func:`image_plane_lux`);
3. the collection turns those into weights that meet the environment's target
   (``Collection.camera_weights``): the mix scaled by T / E, or the ambient group at
   (T − E_lamps) / E_ambient;
4. the parts, so weighted, are the radiance the camera captures
   (:func:`~benchmark.camera.pipeline.simulate_on_grid`).

Every step is linear and reads only the stored bytes, the seed and the camera spec, so the
weights are the same in every process; a run records them per scene (results.json
``condition_weights``, with the camera and each part's measured illuminance).
"""

from __future__ import annotations

from dataclasses import dataclass
from functools import lru_cache
from typing import Callable

import numpy as np

from benchmark.camera import optics as _optics
from benchmark.camera.pipeline import Capture, sensor_radiance, simulate_on_grid
from benchmark.camera.spec import CameraSpec
from metricscenes.photometry import MAX_LUMINOUS_EFFICACY_LM_W, cie_1931_cmfs
from metricscenes.radiance import SpectralScene
from metricscenes.spectral import BAND_WIDTH_NM


@lru_cache(maxsize=4)
def _lux_per_irradiance(wavelengths_nm: tuple[float, ...]) -> np.ndarray:
    """(1, bands): lux per W·m⁻²·nm⁻¹ in each band, K_m ȳ(λ) Δλ (the sum that gives the
    collection's luminances, ``metricscenes.photometry.radiance_to_xyz``)."""
    ybar = cie_1931_cmfs(np.asarray(wavelengths_nm, float))[:, 1]
    return (MAX_LUMINOUS_EFFICACY_LM_W * BAND_WIDTH_NM * ybar)[None, :]


def image_plane_lux(radiance: np.ndarray, wavelengths_nm: np.ndarray, camera: CameraSpec) -> float:
    """Mean illuminance (lux) of the camera's optical image of ``radiance`` (on its pixel grid)
    over its pixels: E = π T L / (1 + 4 N²) with the lens's relative illumination and veiling
    glare, what ISETCam reads as an optical image's mean illuminance. The lens's blur is left
    out: its OTF is 1 at zero frequency and the optics pad the image by reflection, so it moves
    the mean by less than the 1 % the tests hold it to (tests/test_image_plane_targets.py)."""
    oi = _optics.optical_image(radiance, wavelengths_nm, camera.optics, camera.pixel_um, diffraction=False)
    plane = oi.weighted_sum(_lux_per_irradiance(tuple(float(w) for w in wavelengths_nm)))
    if camera.optics.veiling_glare_fraction > 0.0:  # (the unblurred path skips it; it moves light off the frame)
        plane = _optics.veiling_glare(plane, camera.optics, camera.pixel_um)
    return float(np.mean(plane, dtype=np.float64))


@dataclass
class ImagePlaneParts:
    """One scene of a ``target_at: camera`` condition, read once for every camera: its parts'
    radiance (``{part: SpectralScene}``, ``Collection.condition_parts``) and ``weigh``, which
    turns a camera's measured ``{part: lux}`` and ``at`` (that camera) into the scene's
    ``TargetedWeights`` (``Collection.camera_weights``)."""

    parts: dict[str, SpectralScene]
    weigh: Callable[[dict[str, float], dict], object]

    def weights(self, camera: CameraSpec) -> tuple[object, dict[str, np.ndarray]]:
        """The camera's weights for this scene, and each part on its pixel grid."""
        grids = {name: sensor_radiance(scene, camera) for name, scene in self.parts.items()}
        wavelengths = next(iter(self.parts.values())).wavelengths_nm
        lux = {name: image_plane_lux(grid, wavelengths, camera) for name, grid in grids.items()}
        at = {"camera": camera.name, "f_number": camera.optics.f_number,
              "transmittance": camera.optics.transmittance, "part_image_plane_lux": lux}
        return self.weigh(lux, at), grids

    def simulate(self, camera: CameraSpec, *, seed: int, noise: bool = True) -> tuple[Capture, dict]:
        """The camera's capture of the scene at its own image plane, and the record of its weights."""
        weights, grids = self.weights(camera)
        radiance = None
        for name, coefficient in weights.part_coefficients().items():
            if name in grids and coefficient != 0.0:
                term = np.float32(coefficient) * grids[name]
                radiance = term if radiance is None else radiance + term
        if radiance is None:  # nothing lit (a target met by lamps that are off): a dark frame
            radiance = np.zeros_like(next(iter(grids.values())))
        wavelengths = next(iter(self.parts.values())).wavelengths_nm
        return simulate_on_grid(radiance, wavelengths, camera, seed=seed, noise=noise), weights.record()
