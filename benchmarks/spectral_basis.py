"""A spectral basis per radiance array (ISETCam's hypercube basis, ``hcBasis``): how much
of the signal K basis spectra keep, against the render's own noise.

    PYTHONPATH=. python benchmarks/spectral_basis.py --manifest manifests/quick.yaml --units env000-d050m \\
        [--light-groups sky_day] [--ranks 3 4 6 8 10]

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

# A sibling in benchmarks/ (the script's folder is first on sys.path).
from store_codecs import noise_manifest, render_twice


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


def main() -> None:
    from metricscenes.manifest import load_manifest

    parser = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    parser.add_argument("--manifest", type=Path, required=True)
    parser.add_argument("--units", nargs="+", required=True, help="plates envNNN and insets envNNN-dDDDm")
    parser.add_argument("--light-groups", nargs="+", help="render only these light groups")
    parser.add_argument("--ranks", type=int, nargs="+", default=[3, 4, 6, 8, 10])
    parser.add_argument("--weightings", nargs="+", default=["norm", "energy"], choices=["norm", "energy", "blocks-norm", "blocks-energy"])
    parser.add_argument("--work", type=Path, default=Path("/tmp/basis-noise"), help="renders kept here")
    args = parser.parse_args()

    manifest = noise_manifest(load_manifest(args.manifest), args.light_groups)
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
