"""A spectral basis per radiance array (ISETCam's hypercube basis, ``hcBasis``): how much
of the signal K basis spectra keep, against the render's own noise.

    PYTHONPATH=. python benchmarks/studies/spectral_basis.py --manifest manifests/quick.yaml --units env000-d050m \\
        [--light-groups sky_day] [--ranks 3 4 6 8 10]
    PYTHONPATH=. python benchmarks/studies/spectral_basis.py --manifest manifests/quick.yaml --units env000-d050m \\
        --ranks 6 8 10 --held day night [--hold imx363+y|xyz|none]

``--held``: the store's basis (``store.spectral_basis``: the sensor's channels and Y held,
:mod:`metricscenes.spectral_basis`) judged by cameras instead of Y: the scene under each
condition from render A, from render B and from A stored through the basis (coefficients
rounded as the store does), captured noise-free by cam12, cam01 and cam08 at A's exposure;
the table gives the render noise (A against B) and the basis's loss (A against P A) over
the shot noise, as ``render_noise.py`` does. ``--hold`` swaps the held spectra for CIE
x-bar, y-bar, z-bar or none (the principal spectra alone), to see what holding them buys.

A basis stores a (rows, cols, 31) array as (rows, cols, K) coefficients and 31 x K basis
spectra: K/31 of the values (before the codecs). Here the basis of an array is the K
leading principal directions (uncentred) of its spectra, each pixel's spectrum either
scaled to unit length first (``norm``: every pixel's shape counts alike, dark or bright)
or as it is (``energy``: bright pixels dominate, as ISETCam's ``hcBasis`` does), and an
array is stored as its projection P A onto them.

A projection also removes render noise (the part of it outside the K spectra), so its
difference from the render is not the criterion. Two renders A, B of the unit that differ
only in seed (``store_codecs.render_twice``) separate the two: with Y the band sum a camera
makes (luminance), per pixel, E (Y(PA) - Y(B))^2 = bias^2 + E Y(P n)^2 + sigma^2, where
bias = Y(P T) - Y(T) is the signal the basis loses, sigma^2 = E (Y(A) - Y(B))^2 / 2 the
render noise and E Y(P n)^2 = E Y(P(A - B))^2 / 2 the noise the projection keeps. The
table gives sqrt(sum bias^2 / sum sigma^2) over the lit pixels (the basis's loss against
the render noise: the store's rounding is held under a tenth of it),
sum (Y(PA) - Y(B))^2 / sum (Y(A) - Y(B))^2 (below 1: P A is nearer the noise-free
radiance than A is), and sqrt(E Y(P n)^2 / E Y(n)^2), the render noise in Y after the
projection over before (Mitsuba's stratified wavelengths make a pixel's band errors
cancel in the band sum; a projection can undo that, and then a camera sees more noise).
"""

from __future__ import annotations

import argparse
from pathlib import Path

import numpy as np

# store_codecs: this script's sibling (the script's folder is first on sys.path).
from store_codecs import noise_manifest, render_twice

HELD_CAMERAS = ["cam12", "cam01", "cam08"]  # the reference; the largest pixels; the slowest lens (most blur per band)


def basis(cube: np.ndarray, rank: int, weighting: str) -> np.ndarray:
    """(31, rank) orthonormal basis spectra of ``cube`` (rows, cols, 31): the leading
    eigenvectors of the uncentred second moment of its spectra (``norm``: each scaled to
    unit length; ``energy``: as they are), over the pixels that are not black."""
    if weighting.startswith("blocks"):  # learnt from 8 x 8-pixel means: an eighth of the noise, the spectra kept
        rows, cols = (n // 8 * 8 for n in cube.shape[:2])
        cube = cube[:rows, :cols].astype(np.float64).reshape(rows // 8, 8, cols // 8, 8, -1).mean(axis=(1, 3))
    x = cube.reshape(-1, cube.shape[-1]).astype(np.float64)
    length = np.linalg.norm(x, axis=1)
    lit = length > 1e-6 * length.max()
    u = x[lit] / length[lit, None] if weighting.endswith("norm") else x[lit]
    _, vectors = np.linalg.eigh(u.T @ u)
    return vectors[:, ::-1][:, :rank]


def held_spectra(wavelengths_nm: np.ndarray, hold: str = "imx363+y") -> np.ndarray:
    """(bands, h): the spectra a basis holds exactly. ``imx363+y``: the store's
    (:func:`metricscenes.spectral_basis.held_spectra`: the IMX363's R, G, B responsivities and
    CIE 1931 y-bar); ``xyz``: CIE 1931 x-bar, y-bar, z-bar (no camera's data); ``none``:
    nothing (the data's principal spectra only)."""
    import colour

    from metricscenes import spectral_basis

    if hold == "imx363+y":
        return spectral_basis.held_spectra(wavelengths_nm)
    if hold == "none":
        return np.zeros((len(wavelengths_nm), 0))
    cmfs = colour.MSDS_CMFS["CIE 1931 2 Degree Standard Observer"]
    return np.column_stack([cmfs.signals[name][np.asarray(wavelengths_nm, float)] for name in ("x_bar", "y_bar", "z_bar")])


def stored_projection(cube: np.ndarray, v: np.ndarray, mantissa_bits: int | None) -> tuple[np.ndarray, int, int]:
    """(the cube as a reader gets it back from K coefficients rounded to ``mantissa_bits``
    (BitRound) on the basis ``v``, bytes of the coefficients, bytes of the cube rounded
    alike): both compressed with the store's radiance codecs (as ``UnitArrays.write_radiance``)."""
    from numcodecs import Blosc

    from metricscenes.spectral_basis import decode, encode
    from metricscenes.writer import round_mantissa

    def rounded(a):
        a = np.ascontiguousarray(a, np.float32)
        return a if mantissa_bits is None else round_mantissa(a, mantissa_bits)

    coefficients = rounded(encode(cube, v))
    blosc = Blosc(cname="zstd", clevel=1, shuffle=Blosc.SHUFFLE, blocksize=2**30)  # the store's chain
    return decode(coefficients, v), len(blosc.encode(coefficients)), len(blosc.encode(rounded(cube)))


def basis_loss(a: np.ndarray, b: np.ndarray, rank: int, weighting: str) -> tuple[float, float, float]:
    """(bias / render noise, sum (Y(PA) - Y(B))^2 / sum (Y(A) - Y(B))^2, render noise in Y
    after the projection / before) in luminance Y, over the pixels whose Y is not black,
    for the rank-``rank`` basis of ``a``."""
    from metricscenes.photometry import radiance_to_xyz

    def y(cube):
        return radiance_to_xyz(cube)[..., 1]

    a64, b64 = a.astype(np.float64), b.astype(np.float64)
    v = basis(a, rank, weighting)
    project = v @ v.T
    y_a, y_b, y_pa, y_pd = y(a64), y(b64), y(a64 @ project), y((a64 - b64) @ project)
    signal = np.abs(y_a + y_b) / 2
    lit = signal > 1e-6 * np.percentile(signal, 99.9)
    noise2 = (y_a - y_b)[lit] ** 2 / 2
    bias2 = (y_pa - y_b)[lit] ** 2 - noise2 - y_pd[lit] ** 2 / 2
    nearer = np.sum((y_pa - y_b)[lit] ** 2) / np.sum((y_a - y_b)[lit] ** 2)
    kept = np.sqrt(np.sum(y_pd[lit] ** 2) / np.sum((y_a - y_b)[lit] ** 2))
    return float(np.sqrt(max(bias2.sum(), 0.0) / noise2.sum())), float(nearer), float(kept)


def judged_scenes(arrays: dict, weights: dict[str, float], feather: float):
    """The SpectralScene a camera is handed under a condition (``weights`` per light group), as
    ``Collection.radiance`` builds it, from ``arrays``: path -> (radiance, TanExtent) of a
    unit's plate, inset and frame light groups."""
    from metricscenes.radiance import RadianceLayer, SpectralScene, on_grid_of

    def weighted(kind: str) -> list[tuple[np.float32, np.ndarray, object]]:
        return [(np.float32(weights[group]), a, e) for p, (a, e) in arrays.items()
                if p.startswith(kind) and weights.get(group := p.rsplit("/", 1)[1], 0.0)]

    plates = weighted("plates/")
    plate = RadianceLayer(sum(w * a for w, a, _ in plates), plates[0][2])
    for w, a, e in weighted("frames/"):
        plate = RadianceLayer(plate.radiance + w * on_grid_of(RadianceLayer(a, e), plate), plate.extent)
    insets = weighted("insets/")
    if not insets:
        return SpectralScene(layers=(plate,))
    return SpectralScene(layers=(plate, RadianceLayer(sum(w * a for w, a, _ in insets), insets[0][2], feather=feather)))


def camera_judge(manifest, units: list[str], ranks: list[int], conditions: list[str], work: Path, hold: str) -> None:
    """Per unit, condition, rank and camera: the render noise (A against B) and what the
    held basis loses (A against A stored through it), both over the shot noise of
    noise-free captures (:func:`benchmark.measure.render_noise.pooled_ratio`), and the bytes it stores."""
    from benchmark.camera import load_camera
    from benchmark.camera.sensor import saturation_electrons
    from benchmark.measure.render_noise import capture_pair, pooled_ratio, used_pixels
    from metricscenes.spectral import WAVELENGTHS_NM
    from metricscenes.spectral_basis import basis_for

    held = held_spectra(np.asarray(WAVELENGTHS_NM, float), hold)
    bits = manifest.store.mantissa_bits if manifest.store else None
    print(f"{manifest.name}: {manifest.reference_grid.width_px} x {manifest.reference_grid.height_px} plates, "
          f"{manifest.render.plate_spp} spp, BitRound {bits}; held: {hold}; noise-free captures at A's exposure; lit: at least the "
          "read noise squared in e-, below saturation; ratios to the shot noise (sqrt(sum d^2 / 2 / sum e))\n")
    print("| unit | condition | camera | render noise (A vs B) | " + " | ".join(f"basis K = {k} (A vs PA)" for k in ranks) + " |")
    print("|---|---|---|---|" + "---|" * len(ranks))
    for unit in units:
        pairs = render_twice(manifest, unit.split("-")[0], work / unit.split("-")[0])
        if "-" in unit:
            pairs |= {p: r for p, r in render_twice(manifest, unit, work / unit).items() if not p.startswith("plates/")}
        a = {p: (r.a, r.extent) for p, r in pairs.items()}
        b = {p: (r.b, r.extent) for p, r in pairs.items()}
        stored, sizes = {}, {}
        for k in ranks:
            stored[k] = {}
            for p, r in pairs.items():
                back, coefficient_bytes, band_bytes = stored_projection(r.a, basis_for(r.a, k, held), bits)
                stored[k][p] = (back, r.extent)
                sizes[k] = np.add(sizes.get(k, (0, 0)), (coefficient_bytes, band_bytes))
        for condition in conditions:
            weights = manifest.conditions[condition]
            scene_a, scene_b = (judged_scenes(x, weights, manifest.render.inset_feather or 0.0) for x in (a, b))
            for name in HELD_CAMERAS:
                camera = load_camera(name)
                e_a, e_b, _, _ = capture_pair(scene_a, scene_b, camera)
                used, _ = used_pixels(e_a, e_b, saturation_electrons(camera.sensor), camera.sensor.read_noise_e ** 2)
                cells = []
                for k in ranks:
                    scene_pa = judged_scenes(stored[k], weights, manifest.render.inset_feather or 0.0)
                    _, e_pa, _, _ = capture_pair(scene_a, scene_pa, camera)
                    cells.append(f"{pooled_ratio(e_a, e_pa, used, 32)['overall']:.4f}")
                print(f"| {unit} | {condition} | {name} | {pooled_ratio(e_a, e_b, used, 32)['overall']:.3f} | "
                      + " | ".join(cells) + " |", flush=True)
        print("bytes, coefficients / 31 bands (all arrays of the unit): "
              + ", ".join(f"K = {k}: {c / 1e6:.1f} / {t / 1e6:.1f} MB ({c / t:.2f})" for k, (c, t) in sizes.items()), flush=True)


def main() -> None:
    from metricscenes.manifest import load_manifest

    parser = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    parser.add_argument("--manifest", type=Path, required=True)
    parser.add_argument("--units", nargs="+", required=True, help="plates envNNN and insets envNNN-dDDDm")
    parser.add_argument("--light-groups", nargs="+", help="render only these light groups")
    parser.add_argument("--ranks", type=int, nargs="+", default=[3, 4, 6, 8, 10])
    parser.add_argument("--weightings", nargs="+", default=["norm", "energy"], choices=["norm", "energy", "blocks-norm", "blocks-energy"])
    parser.add_argument("--work", type=Path, default=Path("/tmp/basis-noise"), help="renders kept here")
    parser.add_argument("--held", nargs="+", metavar="CONDITION",
                        help="judge the basis that holds the sensor's channels and Y through cameras, under these conditions")
    parser.add_argument("--hold", default="imx363+y", choices=["imx363+y", "xyz", "none"], help="with --held: the spectra held")
    args = parser.parse_args()

    manifest = noise_manifest(load_manifest(args.manifest), args.light_groups)
    if args.held:
        return camera_judge(manifest, args.units, args.ranks, args.held, args.work / manifest.sha256()[:12], args.hold)
    print(f"{manifest.name}: {manifest.render.plate_spp} spp plates, {manifest.render.inset_spp} spp insets; "
          "per rank K: bias / render noise in Y ; sum (Y(PA) - Y(B))^2 / sum (Y(A) - Y(B))^2 ; "
          "render noise in Y after the projection / before\n")
    print("| array | weighting | " + " | ".join(f"K = {k} ({k / 31:.2f} of the values)" for k in args.ranks) + " |")
    print("|---|---|" + "---|" * len(args.ranks))
    for unit in args.units:
        for path, (a, b, _) in render_twice(manifest, unit, args.work / manifest.sha256()[:12] / unit).items():
            for weighting in args.weightings:
                cells = [basis_loss(a, b, k, weighting) for k in args.ranks]
                print(f"| {path} | {weighting} | " + " | ".join(f"{bias:.2f} ; {nearer:.2f} ; {kept:.2f}" for bias, nearer, kept in cells)
                      + " |", flush=True)


if __name__ == "__main__":
    main()
