"""The camera pipeline: a spectral scene through optics, sensor, exposure and ISP.

``simulate(scene, camera, seed=...)`` is what ``benchmark run`` calls for every scene:

    radiance (resampled to the pixel grid) ──lens──▶ optical image ──sensor QE──▶
    electron rate per channel ──colour filter mosaic──▶ signal ──acquisition──▶ raw capture ──ISP──▶ sRGB 8-bit

The acquisition (:mod:`benchmark.camera.acquisition`) sets the exposure and reads the raw
frames: one exposure, the ``hdr`` policy's long and short raws merged before the ISP, or
an HDR pixel (``sensor.dcg``) merged and companded on the sensor; the ISP tone-maps an
HDR capture before the sRGB encoding.

Geometry: the camera sees its own field, 2·atan(width_px · pixel / 2f) ×
2·atan(height_px · pixel / 2f), a window of the scene's field centred on the optical
axis (:func:`camera_window`); a camera whose field exceeds the scene's is refused. The
13 registry cameras see exactly the reference field, so their window *is* the field.
A lens with radial distortion (``optics.distortion_k1``, ``distortion_k2``) sees the
undistorted window its sensor's border maps to, through :mod:`benchmark.camera.distortion`.
"""

from __future__ import annotations

from dataclasses import dataclass

import numpy as np

from benchmark.camera import acquisition as _acquisition
from benchmark.camera import distortion as _distortion
from benchmark.camera import isp as _isp
from benchmark.camera import optics as _optics
from benchmark.camera import sensor as _sensor
from benchmark.camera.calibration import calibrate
from benchmark.camera.spec import CameraSpec
from metricscenes.geometry import REFERENCE_EXTENT, TanExtent, centred_extent, extent_within, fov_deg
from metricscenes.radiance import SpectralScene


@dataclass(frozen=True)
class Capture:
    """One simulated image.

    Attributes:
        rgb8: (height, width, 3) uint8 sRGB.
        raw_dn: (height, width) uint16 mosaic (the sensor's colour filter tile), black level included.
        exposure_s: integration time, s.
        camera_name: the camera's registry name.
        width_px, height_px: image size.
        seed: the temporal-noise seed.
        camera_sha256: hash of the resolved camera spec.
        electrons: (height, width) float32 noise-free signal electrons of the mosaic.
        rgb_linear: (height, width, 3) float32 linear sRGB when ``isp.output`` is
            ``linear``, else None (``hdr``: before the tone curve, 1 = the reference
            exposure's white).
        exposure_short_s: ``hdr`` only: the short exposure, s (``exposure_s`` and
            ``raw_dn`` are then the long one's).
        raw_short_dn: ``hdr`` only: the short exposure's raw, uint16.
        merged_dn: HDR only: the merged linear raw (float32 DN on the first frame's scale,
            black level included) that the ISP processed (``hdr``: on the long exposure's;
            ``sensor.dcg``: the HCG readout's, decompanded from the output).
        raw: the acquisition (:class:`benchmark.camera.acquisition.RawCapture`) the fields
            above come from: every frame, the merged and companded words.

    With ``sensor.dcg``, ``raw_dn`` is the sensor's companded output (uint16, the
    ``companded_bits`` codes) and ``exposure_s`` the one exposure.
    """

    rgb8: np.ndarray
    raw_dn: np.ndarray
    exposure_s: float
    camera_name: str
    width_px: int
    height_px: int
    seed: int
    camera_sha256: str
    electrons: np.ndarray
    rgb_linear: np.ndarray | None = None
    exposure_short_s: float | None = None
    raw_short_dn: np.ndarray | None = None
    merged_dn: np.ndarray | None = None
    raw: _acquisition.RawCapture | None = None


class FieldOfViewError(ValueError):
    """A camera sees more than the collection's field (one-line message naming both)."""


def camera_extent(camera: CameraSpec, field: TanExtent = REFERENCE_EXTENT) -> TanExtent:
    """The camera's field in tangent coordinates, centred on the optical axis: ±half the
    pixel array over the focal length (with distortion, the undistorted window its
    border sees: :attr:`CameraSpec.seen_tan_half_extent`). Edges within 10⁻⁶ (relative)
    of ``field``'s are snapped onto them, so a camera of the reference geometry gets
    ``field`` itself. Not checked against ``field`` (:func:`camera_window` is)."""
    return centred_extent(*camera.seen_tan_half_extent, field)


def sensor_extent(camera: CameraSpec, field: TanExtent = REFERENCE_EXTENT) -> TanExtent:
    """The tangent extent the pixel grid spans in the lens's distorted coordinates,
    ±half the pixel array over the focal length (snapped as :func:`camera_extent`);
    without distortion, :func:`camera_extent` itself."""
    return centred_extent(camera.tan_half_width, camera.tan_half_height, field)


def camera_window(camera: CameraSpec, field: TanExtent = REFERENCE_EXTENT, widest: TanExtent | None = None) -> TanExtent:
    """The window of ``field`` (a collection's, or a scene's plate extent) that ``camera``
    samples: :func:`camera_extent`, refused (:class:`FieldOfViewError`) where it exceeds
    ``field`` in either axis, unless it lies inside ``widest`` (a collection's wide plate's
    field; None: none). The registry cameras get ``field`` itself."""
    window = camera_extent(camera, field)
    if extent_within(window, field):
        return window
    if widest is not None:
        window = camera_extent(camera, widest)
        if extent_within(window, widest):
            return window
    h, v = camera.hfov_deg, camera.vfov_deg
    fh, fv = fov_deg(field if widest is None else widest)
    raise FieldOfViewError(
        f"camera {camera.name!r} sees {h:.2f}° x {v:.2f}° (focal length {camera.optics.focal_length_mm:g} mm, "
        f"pixel array {camera.sensor.array_width_mm:.4g} x {camera.sensor.array_height_mm:.4g} mm), more than "
        f"the collection's {'widest ' if widest is not None else ''}field {fh:.2f}° x {fv:.2f}°: use a longer "
        "focal length or a smaller active area")


def lens_mapping(camera: CameraSpec, field: TanExtent = REFERENCE_EXTENT, widest: TanExtent | None = None):
    """What the camera's ground truth follows: (the extent its pixel grid spans, the
    lens's map from scene to sensor tangent coordinates or None for an ideal lens), as
    :func:`metricscenes.groundtruth.scale_groundtruth` takes them (``window``, ``to_sensor``).
    ``field`` is the ground truth's; ``widest`` as :func:`camera_window`'s."""
    camera_window(camera, field, widest)  # refused if it sees more than the field
    k = camera.optics.distortion
    return sensor_extent(camera, field), (None if k is None else lambda xy: _distortion.distort(xy, *k))


def electron_rate(
    scene: SpectralScene,
    camera: CameraSpec,
    *,
    shape_px: tuple[int, int] | None = None,
    extent: TanExtent | None = None,
    diffraction: bool = True,
) -> np.ndarray:
    """Noise-free signal, electrons·s⁻¹, per channel (3, rows, cols): the scene's optical
    image (:func:`optical_image`) through the sensor, which integrates its own QE
    (:func:`benchmark.camera.sensor.electron_rate`, the fast path).

    ``shape_px`` (rows, cols) and ``extent`` select a window of the sensor (default:
    the full frame: the camera's own field, :func:`camera_window` of the scene's
    field); the window must be sampled at the camera's pixel pitch. With lens
    distortion ``extent`` is in the sensor's (distorted) coordinates and the scene is
    sampled through the distortion (:func:`benchmark.camera.distortion.resample_distorted`).
    ``diffraction`` off: no lens blur (irradiance only).
    """
    oi = optical_image(scene, camera, shape_px=shape_px, extent=extent, diffraction=diffraction)
    return _sensor.electron_rate(oi, camera.sensor)


def sensor_radiance(scene: SpectralScene, camera: CameraSpec, *, shape_px: tuple[int, int] | None = None,
                    extent: TanExtent | None = None) -> np.ndarray:
    """The scene's radiance (rows, cols, bands) on the camera's pixel grid (or the window
    ``shape_px``, ``extent`` of it, as :func:`electron_rate`), through the lens's
    distortion where it has one; refused (ValueError) where it is not finite."""
    rows, cols = shape_px or (camera.height_px, camera.width_px)
    if extent is None:
        camera_window(camera, scene.extent, None if scene.surround is None else scene.widest_extent)  # or refuses it
        extent = sensor_extent(camera, scene.extent)
    if camera.optics.distortion is None:
        radiance = scene.resample(cols, rows, extent)
    else:
        radiance = _distortion.resample_distorted(scene, cols, rows, extent, *camera.optics.distortion)
    if not np.all(np.isfinite(radiance)):
        raise ValueError("scene radiance contains NaN or infinite values")
    return radiance


def optical_image(scene: SpectralScene, camera: CameraSpec, *, shape_px: tuple[int, int] | None = None,
                  extent: TanExtent | None = None, diffraction: bool = True) -> _optics.OpticalImage:
    """The scene through the camera's lens: the (lazy) optical image on its pixel grid, or
    the window ``shape_px``, ``extent`` of it (as :func:`electron_rate`): the radiance
    resampled there and the lens; its irradiance is computed when asked for."""
    return _optics.optical_image(sensor_radiance(scene, camera, shape_px=shape_px, extent=extent), scene.wavelengths_nm,
                                 camera.optics, camera.pixel_um, diffraction=diffraction)


def simulate(scene: SpectralScene, camera: CameraSpec, *, seed: int, noise: bool = True) -> Capture:
    """Simulate one capture of ``scene`` by ``camera``: its optical image
    (:func:`optical_image`) → the sensor's signal (electron rate per channel, on the colour
    filter mosaic) → the acquisition (:func:`benchmark.camera.acquisition.acquire`: one
    exposure, two-frame HDR or an HDR pixel) → the ISP (:func:`benchmark.camera.isp.render`).
    Each stage takes the previous one's value and never reaches back.

    Args:
        scene: spectral radiance, W·sr⁻¹·m⁻²·nm⁻¹, over a field at least the camera's
            (the camera samples its own window, :func:`camera_window`).
        camera: the camera spec.
        seed: temporal-noise seed (``np.random.default_rng(seed)``): same seed, same raw.
        noise: False switches every noise source off (shot, read, dark, PRNU, DSNU).
    """
    return simulate_on_grid(sensor_radiance(scene, camera), scene.wavelengths_nm, camera, seed=seed, noise=noise)


def simulate_on_grid(radiance: np.ndarray, wavelengths_nm: np.ndarray, camera: CameraSpec, *, seed: int,
                     noise: bool = True) -> Capture:
    """:func:`simulate` of a radiance already on the camera's pixel grid (:func:`sensor_radiance`):
    what a condition whose weights depend on the camera mixes there (:mod:`benchmark.camera.image_plane`)."""
    oi = _optics.optical_image(radiance, wavelengths_nm, camera.optics, camera.pixel_um)
    signal = _sensor.mosaic(_sensor.electron_rate(oi, camera.sensor), camera.sensor.cfa)
    raw = _acquisition.acquire(signal, camera, seed=seed, noise=noise)
    rgb_linear, rgb8 = _isp.render(raw, camera.sensor, camera.isp, calibrate(camera.sensor, camera.isp))
    two_frames = raw.strategy == "two_frame_hdr"
    return Capture(
        rgb8=rgb8,
        raw_dn=raw.frames[0].raw_dn if raw.output_dn is None else raw.output_dn,
        exposure_s=raw.exposure_s,
        camera_name=camera.name,
        width_px=camera.width_px,
        height_px=camera.height_px,
        seed=int(seed),
        camera_sha256=camera.sha256(),
        electrons=raw.electrons,
        rgb_linear=rgb_linear if camera.isp.output == "linear" else None,
        exposure_short_s=raw.frame("short").exposure_s if two_frames else None,
        raw_short_dn=raw.frame("short").raw_dn if two_frames else None,
        merged_dn=None if raw.strategy == "single" else raw.linear_dn,
        raw=raw,
    )
