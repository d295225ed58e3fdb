"""Do two Mitsuba variants render the same collection? Luminance of every array, block by block.

Two renders of one unit by different variants (``llvm_ad_spectral`` on a CPU,
``cuda_ad_spectral`` on a GPU) share the seed but not the floating point (Embree against
OptiX, FMA contraction), so their bytes differ and only their Monte Carlo estimates can be
compared. ``stats`` reduces each radiance array of the chosen units to its luminance (cd/m²,
CIE 1924 V(λ)) averaged over square blocks of 4, 16 and 64 pixels, and keeps each unit's
render seconds; it reads a store whole or half-written (a collection still generating) and
writes a small ``.npz`` that travels back from a GPU machine. ``compare`` sets two such files
side by side, per array: the ratio of mean luminances, and the RMS relative difference of the
blocks at each size. Where the two differ only by render noise the RMS falls as 1/block
(×4 from 4 to 16 px); a bias (a missing light, a wrong spectrum) does not fall.

    python benchmarks/studies/backend_agreement.py stats COLLECTION --units env000 env000-d025m ... --out a.npz
    python benchmarks/studies/backend_agreement.py compare a.npz b.npz
"""

from __future__ import annotations

import argparse
import json
from pathlib import Path

import numpy as np

BLOCKS = (4, 16, 64)


def block_means(image: np.ndarray, block: int) -> np.ndarray:
    rows, cols = (image.shape[0] // block) * block, (image.shape[1] // block) * block
    return image[:rows, :cols].reshape(rows // block, block, cols // block, block).mean(axis=(1, 3))


def luminance(cube: np.ndarray, wavelengths_nm: np.ndarray) -> np.ndarray:
    from metricscenes.photometry import MAX_LUMINOUS_EFFICACY_LM_W, photopic_v

    step = float(np.mean(np.diff(wavelengths_nm)))
    return MAX_LUMINOUS_EFFICACY_LM_W * step * (cube @ photopic_v(wavelengths_nm))


def unit_arrays(store, unit: str) -> list[str]:
    """Paths of a unit's radiance arrays: ``plates/envNNN/<group>`` for a plate, the inset and
    the car lamps' frame (``insets/...``, ``frames/...``) for a scene."""
    kinds = ("plates",) if "-d" not in unit else ("insets", "frames")
    paths = []
    for kind in kinds:
        try:
            node = store[f"{kind}/{unit}"]
        except KeyError:
            continue
        paths += [f"{kind}/{unit}/{name}" for name in sorted(node.array_keys())]
    return paths


def stats(collection: Path, units: list[str]) -> dict[str, np.ndarray]:
    import zarr

    from metricscenes.spectral_basis import decode

    store = zarr.open_group(str(collection / "radiance.zarr"), mode="r")
    out: dict[str, np.ndarray] = {}
    for unit in units:
        record = collection / "progress" / f"{unit}.json"
        if not record.exists():
            raise SystemExit(f"{collection}: unit {unit} is not done yet")
        out[f"seconds/{unit}"] = np.array(json.loads(record.read_text())["seconds"])
        for path in unit_arrays(store, unit):
            arr = store[path]
            attrs = dict(arr.attrs)
            data = np.asarray(arr[...], dtype=np.float64)
            if "spectral_basis" in attrs:
                data = decode(data, np.asarray(attrs["spectral_basis"], dtype=np.float64).T)
            lum = luminance(data, np.asarray(attrs["wavelengths_nm"], dtype=np.float64))
            for block in BLOCKS:
                out[f"{path}@{block}"] = block_means(lum, block).astype(np.float32)
            out[f"{path}@mean"] = np.array(lum.mean())
    return out


def compare(a: dict[str, np.ndarray], b: dict[str, np.ndarray]) -> list[dict]:
    rows = []
    paths = sorted({k.rsplit("@", 1)[0] for k in a if "@" in k} & {k.rsplit("@", 1)[0] for k in b if "@" in k})
    for path in paths:
        row = {"array": path, "mean ratio": float(a[f"{path}@mean"] / b[f"{path}@mean"])}
        for block in BLOCKS:
            x, y = a[f"{path}@{block}"].astype(np.float64), b[f"{path}@{block}"].astype(np.float64)
            mid = 0.5 * (x + y)
            lit = mid > 0.05 * mid.mean()  # dark blocks: relative differences of nothing
            row[f"rms rel diff @{block}px"] = float(np.sqrt(np.mean(((x - y)[lit] / mid[lit]) ** 2))) if lit.any() else np.nan
        rows.append(row)
    return rows


def main() -> None:
    parser = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    sub = parser.add_subparsers(dest="command", required=True)
    s = sub.add_parser("stats", help="block luminances of some units of a collection (finished or not)")
    s.add_argument("collection", type=Path)
    s.add_argument("--units", nargs="+", required=True)
    s.add_argument("--out", type=Path, required=True)
    c = sub.add_parser("compare", help="two stats files side by side")
    c.add_argument("a", type=Path)
    c.add_argument("b", type=Path)
    args = parser.parse_args()
    if args.command == "stats":
        np.savez_compressed(args.out, **stats(args.collection, args.units))
        return
    a, b = dict(np.load(args.a)), dict(np.load(args.b))
    rows = compare(a, b)
    units = sorted({k.split("/", 1)[1] for k in a if k.startswith("seconds/")} & {k.split("/", 1)[1] for k in b if k.startswith("seconds/")})
    print(f"{'unit':<16} {args.a.stem + ' s':>12} {args.b.stem + ' s':>12}")
    for unit in units:
        print(f"{unit:<16} {float(a['seconds/' + unit]):>12.1f} {float(b['seconds/' + unit]):>12.1f}")
    print(f"\n{'array':<36} {'mean a/b':>9} " + " ".join(f"{'rms @' + str(k) + 'px':>10}" for k in BLOCKS))
    for row in rows:
        print(f"{row['array']:<36} {row['mean ratio']:>9.4f} "
              + " ".join(f"{row[f'rms rel diff @{k}px']:>10.4f}" for k in BLOCKS))


if __name__ == "__main__":
    main()
