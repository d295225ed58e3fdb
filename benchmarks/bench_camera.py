"""Time the camera simulation, stage by stage, on a 1920x1080 31-band scene.

    PYTHONPATH=. python benchmarks/bench_camera.py [--camera cam10] [--repeat 3]

Compares the fast optics path (31 forward rFFTs, spectra summed per colour channel in
the frequency domain, 3 inverse) with two baselines measured in the same run:
per-band irradiance (31 forward + 31 inverse FFTs, then spectral integration) and a
naive per-band spatial convolution with the PSF (scipy.ndimage.convolve; timed on a
few bands and scaled to 31, because all 31 take minutes).
"""

from __future__ import annotations

import argparse
import os
import platform
import time

import numpy as np
import scipy.ndimage
import scipy.fft as sfft

from benchmark import exposure, isp, optics, sensor
from benchmark.cameras import load_camera
from metricscenes.geometry import REFERENCE_EXTENT
from metricscenes.radiance import RadianceLayer, SpectralScene
from metricscenes.spectral import WAVELENGTHS_NM


def _scene(rows: int, cols: int, seed: int = 0) -> SpectralScene:
    """A smooth random 31-band radiance field at the camera's own sampling."""
    rng = np.random.default_rng(seed)
    base = scipy.ndimage.gaussian_filter(rng.random((rows, cols, 3), dtype=np.float32), (3, 3, 0))
    basis = np.stack([np.exp(-0.5 * ((WAVELENGTHS_NM - c) / 40.0) ** 2) for c in (450, 550, 630)])
    cube = (base @ basis.astype(np.float32)) * np.float32(0.02)
    return SpectralScene(layers=(RadianceLayer(cube.astype(np.float32), REFERENCE_EXTENT),))


def _psf_kernel(wavelength_nm: float, f_number: float, pixel_um: float, radius_px: int) -> np.ndarray:
    """Pixel-sampled diffraction PSF (inverse FFT of the OTF), normalised to sum 1."""
    size = sfft.next_fast_len(8 * radius_px + 1)
    psf = np.fft.fftshift(sfft.irfft2(optics.otf_grid((size, size), pixel_um, wavelength_nm, f_number), s=(size, size)))
    c = size // 2
    k = psf[c - radius_px : c + radius_px + 1, c - radius_px : c + radius_px + 1]
    return (k / k.sum()).astype(np.float32)


def _best(fn, repeat: int) -> tuple[float, object]:
    best, out = np.inf, None
    for _ in range(repeat):
        t0 = time.perf_counter()
        out = fn()
        best = min(best, time.perf_counter() - t0)
    return best, out


def main() -> None:
    parser = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    parser.add_argument("--camera", default="cam10")
    parser.add_argument("--repeat", type=int, default=3)
    parser.add_argument("--naive-bands", type=int, default=2)
    args = parser.parse_args()

    cam = load_camera(args.camera)
    rows, cols = cam.height_px, cam.width_px
    scene = _scene(rows, cols)
    resp = sensor.channel_responsivity(cam.sensor)
    times: dict[str, float] = {}

    times["resample"], radiance = _best(lambda: scene.resample(cols, rows), args.repeat)
    times["optics (fast path)"], chans = _best(
        lambda: optics.channel_signal(radiance, WAVELENGTHS_NM, cam.optics, cam.pixel_um, resp), args.repeat
    )
    rate = sensor.mosaic(chans)
    times["mosaic + exposure"], t_exp = _best(
        lambda: exposure.exposure_time_s(sensor.mosaic(chans), cam.sensor, cam.exposure), args.repeat
    )
    times["sensor (noise, ADC)"], raw = _best(
        lambda: sensor.capture_dn(rate, t_exp, cam.sensor, np.random.default_rng(0)), args.repeat
    )
    times["isp (wb, demosaic, matrix)"], lin = _best(lambda: isp.process(raw, cam.sensor, cam.isp), args.repeat)
    times["srgb encode"], _ = _best(lambda: isp.encode_srgb8(lin), args.repeat)
    total = sum(times.values())

    per_band_s, _ = _best(
        lambda: np.einsum("hwb,cb->chw", optics.irradiance(radiance, WAVELENGTHS_NM, cam.optics, cam.pixel_um),
                          resp.astype(np.float32), optimize=True),
        1,
    )
    radius = optics.pad_px(cam.pixel_um, cam.f_number)
    bands = np.linspace(0, 30, args.naive_bands).astype(int)
    t0 = time.perf_counter()
    for b in bands:
        kernel = _psf_kernel(float(WAVELENGTHS_NM[b]), cam.f_number, cam.pixel_um, radius)
        scipy.ndimage.convolve(radiance[:, :, b], kernel, mode="reflect")
    naive_s = (time.perf_counter() - t0) / len(bands) * 31

    fast = times["optics (fast path)"]
    print(f"camera {cam.name}: {cols}x{rows} px, 31 bands, f/{cam.f_number}, pixel {cam.pixel_um} um")
    print(f"machine: {platform.processor() or platform.machine()}, {os.cpu_count()} cores, numpy {np.__version__}")
    print(f"{'stage':<30}{'seconds':>10}")
    for name, t in times.items():
        print(f"{name:<30}{t:>10.3f}")
    print(f"{'total simulate()':<30}{total:>10.3f}")
    print(f"{'baseline: per-band FFT irradiance + integration':<50}{per_band_s:>8.3f} s  ({per_band_s / fast:.1f}x the fast path)")
    print(f"{f'baseline: naive spatial convolution ({2 * radius + 1}x{2 * radius + 1} PSF)':<50}{naive_s:>8.3f} s  "
          f"({naive_s / fast:.1f}x the fast path; {len(bands)} bands timed, scaled to 31)")


if __name__ == "__main__":
    main()
