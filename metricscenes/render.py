"""Mitsuba rendering of 31-band spectral radiance (W·sr⁻¹·m⁻²·nm⁻¹).

Uses a ``specfilm`` with one 10 nm box band per ISET wavelength, so each channel is
the band-averaged radiance in the emitters' units, a ``box`` reconstruction filter
(bit-identical results whatever the thread count) and a ``stratified`` sampler (less
per-band noise). ``scalar_spectral`` needs no libLLVM; ``llvm_ad_spectral`` renders a unit's
light groups in one pass (:mod:`metricscenes.lightgroups`), about twice as fast on 2 cores,
but needs a libLLVM >= 17 (Debian's libllvm15 aborts the process), so it is probed in a
child process first. ``render.variant: auto`` renders with ``cuda_ad_spectral`` where a
CUDA device is usable, else with ``llvm_ad_spectral`` where it renders, else with
``scalar_spectral`` (:func:`resolve_variant`; docs/performance.md).
"""

from __future__ import annotations

from dataclasses import dataclass
from functools import lru_cache

import numpy as np

from metricscenes.geometry import CAMERA_HEIGHT_M, REFERENCE_EXTENT, TanExtent, horizontal_fov_deg
from metricscenes.spectral import BAND_WIDTH_NM, WAVELENGTHS_NM

_active_variant: str | None = None
CPU_VARIANT = "scalar_spectral"
CPU_JIT_VARIANT = "llvm_ad_spectral"
GPU_VARIANT = "cuda_ad_spectral"
BLOCK_SIZE_PX = 32
"""The scalar renderer's image block, fixed (Mitsuba's default). Left unset, Mitsuba halves it
until a film has a block per render thread, and a pixel's random numbers follow its block:
a small film (a far car's inset) then rendered other bytes with another thread count, i.e.
another worker count or machine. 32 is what every film of more blocks than threads already
got, so collections made before keep their bytes."""


class RenderError(RuntimeError):
    """Mitsuba could not be set up or a render failed (one-line message)."""


def use_variant(variant: str = "scalar_spectral", threads: int | None = None):
    """Select the Mitsuba variant once per process and return the ``mitsuba`` module."""
    global _active_variant
    import drjit as dr
    import mitsuba as mi

    if _active_variant != variant:
        check_variant(variant)
        mi.set_variant(variant)
        _active_variant = variant
    if threads is not None:
        dr.set_thread_count(max(1, int(threads)))
    return mi


_LLVM_PROBE = """
import mitsuba as mi
mi.set_variant({variant!r})
scene = mi.load_dict({{"type": "scene", "integrator": {{"type": "path"}}, "sensor": {{"type": "perspective",
    "film": {{"type": "hdrfilm", "width": 2, "height": 2}}}}, "light": {{"type": "constant"}}}})
mi.render(scene, spp=1)
"""


def check_variant(variant: str) -> None:
    """Raise :class:`RenderError` unless ``variant`` can render in this process."""
    import mitsuba as mi

    if variant not in mi.variants():
        raise RenderError(f"Mitsuba variant {variant!r} is not available (have: {', '.join(mi.variants())})")
    if is_jit_variant(variant):
        _probe_jit(variant)


def is_jit_variant(variant: str) -> bool:
    """Whether a Mitsuba variant compiles kernels (LLVM, CUDA) rather than running scalar code."""
    return variant.startswith(("llvm", "cuda"))


def resolve_variant(setting: str) -> str:
    """The Mitsuba variant a ``render.variant`` setting means on this machine, checked
    (:class:`RenderError` if it cannot render here): ``auto`` is ``cuda_ad_spectral`` where a
    CUDA device renders 2x2 pixels, else ``llvm_ad_spectral`` where a libLLVM renders them,
    else ``scalar_spectral``; any other setting is itself."""
    from metricscenes.manifest import AUTO_VARIANT

    if setting != AUTO_VARIANT:
        check_variant(setting)
        return setting
    if _cuda_driver_present():
        try:
            check_variant(GPU_VARIANT)
            return GPU_VARIANT
        except RenderError:
            pass  # a driver without a usable device (or a Mitsuba without CUDA variants)
    try:
        check_variant(CPU_JIT_VARIANT)
        return CPU_JIT_VARIANT
    except RenderError:
        return CPU_VARIANT  # no libLLVM, or one older than 17


def _cuda_driver_present() -> bool:
    """Whether the CUDA driver library loads (spares the probe's child process, ~2 s, on
    machines without an NVIDIA driver)."""
    import ctypes
    import sys

    if not sys.platform.startswith("linux"):
        return True  # (other systems: let the probe decide)
    try:
        ctypes.CDLL("libcuda.so.1")
    except OSError:
        return False
    return True


@lru_cache(maxsize=None)
def _probe_jit(variant: str) -> None:
    """Render 2x2 pixels with an LLVM or CUDA variant in a child process first. With a
    libLLVM older than 17 (Debian 12's default is 15) the first LLVM render aborts the
    whole process (``LLVM ERROR: Cannot select ... fminimum``), which no exception can
    catch; a CUDA variant is listed on machines without a GPU and fails only when used."""
    import subprocess
    import sys

    try:
        probe = subprocess.run([sys.executable, "-c", _LLVM_PROBE.format(variant=variant)],
                               capture_output=True, text=True, timeout=300)
    except subprocess.TimeoutExpired:
        raise RenderError(f"Mitsuba variant {variant!r} did not render 2x2 pixels in 300 s; "
                          "use render.variant: scalar_spectral") from None
    if probe.returncode == 0:
        return
    if variant.startswith("llvm"):
        raise RenderError(
            f"Mitsuba variant {variant!r} crashes here (libLLVM < 17?); install libllvm19 "
            f"or use render.variant: scalar_spectral")
    lines = [line.strip() for line in probe.stderr.splitlines() if line.strip()]
    why = lines[-1][:160] if lines else f"exit status {probe.returncode}"
    raise RenderError(f"Mitsuba variant {variant!r} cannot run here (no usable CUDA GPU: {why}); "
                      "use render.variant: scalar_spectral")


@dataclass(frozen=True)
class Film:
    """A perspective film covering ``field`` (centred on the optical axis; default the
    reference field of view) at ``width x height`` pixels, of which only the crop window
    is rendered (crop = whole film by default)."""

    width: int
    height: int
    crop_x: int = 0
    crop_y: int = 0
    crop_width: int | None = None
    crop_height: int | None = None
    field: TanExtent = REFERENCE_EXTENT

    @property
    def size(self) -> tuple[int, int]:
        return (self.crop_width or self.width, self.crop_height or self.height)


def spectral_film_dict(film: Film) -> dict:
    cols, rows = film.size
    d = {
        "type": "specfilm",
        "width": film.width,
        "height": film.height,
        "crop_offset_x": film.crop_x,
        "crop_offset_y": film.crop_y,
        "crop_width": cols,
        "crop_height": rows,
        "rfilter": {"type": "box"},
    }
    half = BAND_WIDTH_NM / 2
    for w in WAVELENGTHS_NM:
        # Zero-padded names: specfilm orders channels alphabetically by name.
        d[f"b{int(w):04d}"] = {
            "type": "irregular",
            "wavelengths": f"{w - half}, {w + half}",
            "values": f"{1 / BAND_WIDTH_NM}, {1 / BAND_WIDTH_NM}",
        }
    return d


def sensor_dict(film: Film, spp: int, seed: int) -> dict:
    import mitsuba as mi

    return {
        "type": "perspective",
        "fov": horizontal_fov_deg(film.field),
        "fov_axis": "x",
        "near_clip": 0.05,
        "far_clip": 1.0e5,
        "to_world": mi.ScalarTransform4f().look_at(
            origin=[0.0, 0.0, CAMERA_HEIGHT_M], target=[1.0, 0.0, CAMERA_HEIGHT_M], up=[0.0, 0.0, 1.0]
        ),
        "sampler": {"type": "stratified", "sample_count": int(spp), "seed": int(seed) % 2**31},
        "film": spectral_film_dict(film),
    }


def _first_line(exc: Exception) -> str:
    """The first line of an exception's message (Mitsuba raises plain RuntimeErrors with long ones)."""
    text = str(exc).strip()
    return text.splitlines()[0] if text else type(exc).__name__


def load_scene(scene_dict: dict):
    """``mi.load_dict`` of a scene dict, a :class:`RenderError` in one line if it fails."""
    import mitsuba as mi

    try:
        return mi.load_dict(scene_dict)
    except Exception as exc:
        raise RenderError(f"scene load failed: {_first_line(exc)}") from exc


def render_radiance(scene_dict: dict, spp: int) -> np.ndarray:
    """Render a scene dict (with its sensor) to a (rows, cols, 31) float32 radiance cube."""
    import mitsuba as mi

    try:
        scene = mi.load_dict(scene_dict)
        image = np.array(mi.render(scene, spp=int(spp)), dtype=np.float32)
    except Exception as exc:
        raise RenderError(f"render failed: {_first_line(exc)}") from exc
    if image.ndim != 3 or image.shape[2] != WAVELENGTHS_NM.size:
        raise RenderError(f"unexpected film output shape {image.shape}")
    # Negative values cannot occur in radiance; NaN would poison every later stage.
    if not np.all(np.isfinite(image)):
        raise RenderError("render produced non-finite radiance")
    return image


ILLUMINANCE_METER_SPP = 1024


def with_illuminance_patch(scene_dict: dict, height_m: float = CAMERA_HEIGHT_M,
                           at_xy_m: tuple[float, float] = (0.0, 0.0)) -> dict:
    """``scene_dict`` with the illuminance meter's target: a 2 cm white Lambertian square
    (reflectance 1) facing up at (x, y, height_m)."""
    import mitsuba as mi

    return {**scene_dict, "illuminance_patch": {
        "type": "rectangle",
        "to_world": mi.ScalarTransform4f().translate([*map(float, at_xy_m), height_m]).scale(0.01),
        "bsdf": {"type": "diffuse", "reflectance": {"type": "uniform", "value": 1.0}},
    }}


def illuminance_meter(scene_dict: dict, height_m: float = CAMERA_HEIGHT_M, seed: int = 0,
                      at_xy_m: tuple[float, float] = (0.0, 0.0)) -> np.ndarray:
    """Horizontal spectral irradiance (31,) W·m⁻²·nm⁻¹ at (x, y, height_m) in a scene dict.

    A 2 cm white Lambertian patch (reflectance 1) is placed there and a radiance meter
    looks down at it: E = π L. Unlike Mitsuba's ``irradiancemeter``, this catches
    delta lights (the moon as a directional emitter) through emitter sampling. The
    scene's own sensor is replaced.
    """
    scene = with_illuminance_patch({k: v for k, v in scene_dict.items() if k != "sensor"}, height_m, at_xy_m)
    scene["sensor"] = {
        "type": "radiancemeter", "origin": [*map(float, at_xy_m), height_m + 0.1], "direction": [0.0, 0.0, -1.0],
        "film": spectral_film_dict(Film(1, 1)),
        "sampler": {"type": "stratified", "sample_count": ILLUMINANCE_METER_SPP, "seed": int(seed) % 2**31},
    }
    return np.pi * render_radiance(scene, ILLUMINANCE_METER_SPP).reshape(-1)


def render_depth(scene_dict: dict, film: Film) -> np.ndarray:
    """Distance (m) along each pixel's ray to the first surface, 0 where it escapes.

    One sample per pixel at positions fixed by the sensor's seed, so two scenes
    rendered with the same film and seed are probed along the same rays.
    """
    import mitsuba as mi

    cols, rows = film.size
    scene = dict(scene_dict)
    scene["integrator"] = {"type": "aov", "aovs": "dd:depth", "block_size": BLOCK_SIZE_PX}
    sensor = dict(scene["sensor"])
    sensor["film"] = {
        "type": "hdrfilm", "width": film.width, "height": film.height, "crop_offset_x": film.crop_x,
        "crop_offset_y": film.crop_y, "crop_width": cols, "crop_height": rows, "rfilter": {"type": "box"},
        "pixel_format": "luminance",
    }
    sensor["sampler"] = {"type": "independent", "sample_count": 1, "seed": sensor["sampler"]["seed"]}
    scene["sensor"] = sensor
    try:
        image = np.array(mi.render(mi.load_dict(scene), spp=1))
    except Exception as exc:
        raise RenderError(f"depth render failed: {_first_line(exc)}") from exc
    return image[..., -1].astype(np.float32)
