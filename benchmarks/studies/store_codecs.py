"""Store codecs: bytes and write/read time of a collection's radiance arrays under lossless
chains and BitRound, and BitRound's rounding error against the render's own Monte Carlo
noise (results in docs/performance.md, "Store size").

    python benchmarks/studies/store_codecs.py [--collection collections/quick] [--environments 0 7] [--slow]
    python benchmarks/studies/store_codecs.py --noise-units env000 env007 env007-d050m
    python benchmarks/studies/store_codecs.py --noise-units env000 --noise-manifest manifests/metric-300.yaml \
        --noise-light-groups sky_day sky_night ego_lights
    python benchmarks/studies/store_codecs.py --whole --mantissa-bits 8 9

Codec study (default): every radiance array of the chosen environments (their plates, and
the insets and car-lamp frames of their six scenes; every light group: day, dusk, night,
lamps) is written to a scratch store under each chain, then read back and compared with
the original bits (BitRound chains: with :func:`metricscenes.writer.round_mantissa`'s
values). Bytes are the chunk files'; ratios are against zarr's default chain (bytes + zstd
level 0), what collections were written with before, measured in the same run. Speeds are
MB of raw float32 per second (these machines are shared: compare within a run).

``--noise-units``: renders those units (plates ``envNNN``, insets ``envNNN-dDDDm``) twice
with metricscenes' own render path (``generate.render_unit``), with the manifest's seed
(from the collection's manifest, the arrays must equal the collection's: that is checked)
and with another. The difference of two renders that differ only in seed is the Monte
Carlo noise itself; a local estimate from one render (neighbouring pixels or bands) would
take texture, edges and the spectrum's slope for noise. Compared per value (31 bands) and
after the band sum a camera makes (luminance): see :func:`noise_and_rounding`. Renders are
kept under ``--work`` and reused.

``--whole``: rewrites every array of the collection with the store's writer
(``UnitArrays.write_radiance`` / ``write_mask``: the lossless default, and BitRound at each
``--mantissa-bits``) into scratch copies, checks that the lossless copy verifies against the
collection's recorded sha256, prints the store sizes, and extrapolates them to one
environment of metric-300 (its plates, frames and insets sized by its own plan); the copies
are deleted at the end.
"""

from __future__ import annotations

import argparse
import json
import math
import os
import shutil
import time
import warnings
from dataclasses import replace
from pathlib import Path
from typing import NamedTuple

import numpy as np

from metricscenes.geometry import TanExtent
from metricscenes.store import (
    GROUNDTRUTH_FILE, RADIANCE_STORE, RESOLVED_MANIFEST_FILE, Collection, array_sha256, read_checked, verify_collection,
)
from metricscenes.writer import RADIANCE_COMPRESSORS, CollectionWriter, round_mantissa

MB = 1e6
ZARR_DEFAULT = "zstd 0 (zarr default: collections so far)"
LIGHT_GROUP_CONDITION = {"sky_day": "day", "sky_dusk": "dusk", "sky_night": "night"}  # any other group: lamps
FLOAT32_TINY = float(np.finfo(np.float32).tiny)  # smallest normal float32
# Pixels darker than this fraction of an array's brightest (99.9th percentile) are left out of
# the noise comparison: far below any camera's dynamic range (1e4-1e5), and where both renders
# are exactly zero or equal (the edge of a lamp's footprint) the noise estimate is zero.
DARK = 1e-6
ONE_BLOCK = 2**30  # a Blosc block size above any chunk's: Blosc caps it, so the chunk is one block


def blosc(cname: str, clevel: int, shuffle: str, blocksize: int = 0) -> dict:
    """A zarr v3 core Blosc codec over float32, in the form of RADIANCE_COMPRESSORS
    (blocksize 0: Blosc's automatic size, 32-256 KiB blocks compressed apart)."""
    return {"name": "blosc", "configuration": {"cname": cname, "clevel": clevel, "shuffle": shuffle,
                                               "typesize": 4, "blocksize": blocksize}}


def lossless_chains(slow: bool) -> dict[str, dict]:
    """name -> zarr.create_array codec arguments. ``[numcodecs]``: codecs outside the zarr v3
    specification (zarr-python reads them through numcodecs; other readers may not)."""
    import zarr.codecs.numcodecs as bridge
    from zarr.codecs import TransposeCodec, ZstdCodec

    chains = {
        ZARR_DEFAULT: {},
        "zstd 1": {"compressors": [ZstdCodec(level=1)]},
        "zstd 9": {"compressors": [ZstdCodec(level=9)]},
        **{f"blosc zstd {level} shuffle": {"compressors": [blosc("zstd", level, "shuffle")]} for level in (1, 3, 5)},
        **{f"blosc zstd {level} shuffle, one block": {"compressors": [blosc("zstd", level, "shuffle", ONE_BLOCK)]}
           for level in (1, 3, 5)},
        "blosc zstd 5 bitshuffle": {"compressors": [blosc("zstd", 5, "bitshuffle")]},
        "blosc lz4 5 shuffle": {"compressors": [blosc("lz4", 5, "shuffle")]},
        "transpose (bands first) + blosc zstd 1 shuffle, one block": {
            "filters": [TransposeCodec(order=(2, 0, 1))], "compressors": [blosc("zstd", 1, "shuffle", ONE_BLOCK)]},
        "[numcodecs] shuffle + zstd 3": {"compressors": [bridge.Shuffle(elementsize=4), ZstdCodec(level=3)]},
    }
    if slow:
        chains["blosc zstd 9 shuffle, one block"] = {"compressors": [blosc("zstd", 9, "shuffle", ONE_BLOCK)]}
        chains["[numcodecs] shuffle + zstd 19"] = {"compressors": [bridge.Shuffle(elementsize=4), ZstdCodec(level=19)]}
    try:
        import pcodec  # noqa: F401  (optional: not a dependency of metricscenes)

        chains["[numcodecs] pcodec 8 (needs pcodec)"] = {"serializer": bridge.PCodec(level=8), "compressors": []}
    except ImportError:
        pass
    return chains


def bitround_chains(widths: list[int]) -> dict[str, tuple[int, dict]]:
    """name -> (kept mantissa bits, codec arguments): numcodecs' BitRound through zarr's
    numcodecs bridge, then the store's lossless chain."""
    import zarr.codecs.numcodecs as bridge

    return {f"BitRound {m} + store chain": (m, {"filters": [bridge.BitRound(keepbits=m)],
                                                "compressors": list(RADIANCE_COMPRESSORS)}) for m in widths}


def store_chain_name(chains: dict[str, dict]) -> str:
    """Which lossless chain is the store's (RADIANCE_COMPRESSORS); added if none is."""
    name = next((n for n, kw in chains.items() if kw.get("compressors") == list(RADIANCE_COMPRESSORS)
                 and not kw.get("filters")), None)
    if name is None:
        name = "the store's chain"
        chains[name] = {"compressors": list(RADIANCE_COMPRESSORS)}
    return name


def chunk_bytes(folder: Path) -> int:
    """Bytes of an array's (or a store's) chunk files: everything but zarr.json metadata."""
    return sum(p.stat().st_size for p in folder.rglob("*") if p.is_file() and p.name != "zarr.json")


def file_bytes(folder: Path) -> int:
    return sum(p.stat().st_size for p in folder.rglob("*") if p.is_file())


def same_bits(a: np.ndarray, b: np.ndarray) -> bool:
    return a.shape == b.shape and np.array_equal(a.view(np.uint32), b.view(np.uint32))


def write_read(scratch: Path, cube: np.ndarray, codecs: dict) -> tuple[int, float, float, np.ndarray]:
    """(chunk bytes, write s, read s, values read back) of one single-chunk array."""
    import zarr

    shutil.rmtree(scratch, ignore_errors=True)
    started = time.perf_counter()
    arr = zarr.create_array(store=str(scratch), shape=cube.shape, dtype="float32", chunks=cube.shape,
                            config={"write_empty_chunks": True}, **codecs)
    arr[...] = cube
    written = time.perf_counter()
    back = zarr.open_array(str(scratch), mode="r")[...]
    read = time.perf_counter()
    size = chunk_bytes(scratch)
    shutil.rmtree(scratch)
    return size, written - started, read - written, back


def subset_arrays(collection: Collection, environments: list[int]) -> list[str]:
    """The radiance arrays of these environments: plates, and their scenes' insets and frames."""
    scenes = {s.scene_id for s in collection.scenes() if s.environment_id in environments}
    units = scenes | {f"env{e:03d}" for e in environments}
    return [p for p in sorted(collection.resolved.arrays) if not p.startswith("masks/")
            and p.split("/")[1] in units]


def radiance_group(collection: Collection):
    import zarr

    return zarr.open_group(str(collection.root / RADIANCE_STORE), mode="r")


def condition_of(path: str) -> str:
    return LIGHT_GROUP_CONDITION.get(path.split("/")[2], "lamps")


def rounding_error(cube: np.ndarray, mantissa_bits: int) -> dict:
    """Relative rounding error over the normal non-zero values; subnormals apart."""
    a = cube.astype(np.float64)
    err = np.abs(round_mantissa(cube, mantissa_bits).astype(np.float64) - a)
    normal = np.abs(a) >= FLOAT32_TINY
    rel = err[normal] / np.abs(a[normal])
    subnormal = (a != 0) & ~normal
    return {"max": float(rel.max(initial=0.0)), "sum_sq": float(np.sum(rel**2)), "n": int(rel.size),
            "subnormal": int(subnormal.sum()), "subnormal_abs": float(err[subnormal].max(initial=0.0))}


def codec_study(collection: Collection, environments: list[int], widths: list[int], slow: bool, work: Path) -> None:
    lossless = lossless_chains(slow)
    store_chain = store_chain_name(lossless)
    rounded = bitround_chains(widths)
    chains = {**{n: (None, kw) for n, kw in lossless.items()}, **rounded}
    paths = subset_arrays(collection, environments)
    n_scenes = sum(s.environment_id in environments for s in collection.scenes())
    size = {n: {} for n in chains}  # chain -> path -> bytes
    seconds = {n: [0.0, 0.0] for n in chains}
    exact = {n: True for n in chains}
    errors = {m: [] for m in widths}
    raw = {}
    group = radiance_group(collection)
    print(f"codec study: {collection.root}, environments {environments}: {len(paths)} arrays, {n_scenes} scenes; "
          f"{os.cpu_count()} CPUs, load {os.getloadavg()[0]:.1f}", flush=True)
    for path in paths:
        cube, _ = read_checked(collection.root, group, path, collection.resolved.arrays[path], path)
        cube = np.ascontiguousarray(cube, dtype=np.float32)
        raw[path] = cube.nbytes
        for name, (bits, codecs) in chains.items():
            nbytes, t_write, t_read, back = write_read(work / "array", cube, codecs)
            size[name][path] = nbytes
            seconds[name][0] += t_write
            seconds[name][1] += t_read
            exact[name] &= same_bits(back, cube if bits is None else round_mantissa(cube, bits))
        for m in widths:
            errors[m].append(rounding_error(cube, m))
    total_raw = sum(raw.values())
    base = sum(size[ZARR_DEFAULT].values())
    print(f"\nraw float32: {total_raw / MB:.0f} MB ({total_raw / n_scenes / MB:.1f} MB per scene); "
          f"ratios against '{ZARR_DEFAULT}' ({base / n_scenes / MB:.2f} MB per scene); * = the store's lossless chain\n")
    print(f"| chain | MB per scene | size vs {ZARR_DEFAULT.split(' (')[0]} | compression | write MB/s | read MB/s | "
          "values read back |")
    print("|---|---|---|---|---|---|---|")
    for name, (bits, _) in chains.items():
        total = sum(size[name].values())
        check = ("bit-identical" if bits is None else f"= round_mantissa(·, {bits})") if exact[name] else "DIFFER"
        print(f"| {name}{' *' if name == store_chain else ''} | {total / n_scenes / MB:.2f} | {total / base:.3f} | "
              f"{total_raw / total:.2f}x | {total_raw / MB / seconds[name][0]:.0f} | "
              f"{total_raw / MB / seconds[name][1]:.0f} | {check} |")
    subsets = {kind: [p for p in paths if p.split("/")[0] == kind] for kind in sorted({p.split("/")[0] for p in paths})}
    subsets |= {c: [p for p in paths if condition_of(p) == c] for c in ("day", "dusk", "night", "lamps")}
    print("\nsize against the zarr default, by kind and by light group (day, dusk, night: sky; lamps: car, street, ego)\n")
    print("| chain | " + " | ".join(subsets) + " |")
    print("|---|" + "---|" * len(subsets))
    for name in [store_chain, *rounded]:
        print(f"| {name} | " + " | ".join(
            f"{sum(size[name][p] for p in chosen) / max(1, sum(size[ZARR_DEFAULT][p] for p in chosen)):.3f}"
            for chosen in subsets.values()) + " |")
    print("\nrounding error relative to the value (normal non-zero values of the same arrays)\n")
    print("| kept mantissa bits | max | bound 2^-(m+1) | RMS | subnormal values (max absolute error, W sr-1 m-2 nm-1) |")
    print("|---|---|---|---|---|")
    for m in widths:
        e = errors[m]
        print(f"| {m} | {max(x['max'] for x in e):.3g} | {2.0 ** -(m + 1):.3g} | "
              f"{math.sqrt(sum(x['sum_sq'] for x in e) / sum(x['n'] for x in e)):.3g} | "
              f"{sum(x['subnormal'] for x in e)} ({max(x['subnormal_abs'] for x in e):.1e}) |")


class Renders(NamedTuple):
    """One radiance array rendered with the unit's own seed (``a``) and with another (``b``),
    and the extent (tangent coordinates) its grid covers."""

    a: np.ndarray
    b: np.ndarray
    extent: TanExtent


def render_twice(manifest, unit_key: str, work: Path) -> dict[str, Renders]:
    """The unit's radiance arrays rendered with its own seed and with another: path ->
    :class:`Renders`. Renders are kept in ``work`` and reused by later runs."""
    import zarr

    from metricscenes.generate import plan_units, render_unit
    from metricscenes.plan import plan_collection
    from metricscenes.render import resolve_variant

    unit = next((u for u in plan_units(plan_collection(manifest)) if u.key == unit_key), None)
    if unit is None:
        raise SystemExit(f"{unit_key}: no such unit in {manifest.name}")
    records = []
    for name, seed in (("own_seed", unit.seed), ("other_seed", unit.seed + 1)):
        root = work / name
        record_file = root / f"{unit_key}.json"
        if not record_file.is_file():
            root.mkdir(parents=True, exist_ok=True)
            started = time.perf_counter()
            record = render_unit(manifest.model_dump(mode="json"), replace(unit, seed=seed), str(root), None,
                                 resolve_variant(manifest.render.variant))
            record_file.write_text(record.to_json())
            print(f"  rendered {unit_key} with seed {seed} in {time.perf_counter() - started:.0f} s", flush=True)
        records.append((root, json.loads(record_file.read_text())))
    pairs = {}
    for path in records[0][1]["arrays"]:
        if not path.startswith("masks/"):
            arrays = [zarr.open_group(str(root / RADIANCE_STORE), mode="r")[path] for root, _ in records]
            pairs[path] = Renders(*(np.asarray(arr[...]) for arr in arrays),
                                  TanExtent(*arrays[0].attrs["extent_tan"]))
    return pairs


def noise_and_rounding(a: np.ndarray, b: np.ndarray, widths: list[int]) -> dict:
    """Render noise and rounding error of one array, per value and after the band sum a
    camera makes (luminance Y), from two renders ``a``, ``b`` that differ only in seed.

    Per band: per pixel, noise = RMS over the 31 bands of (a - b) / sqrt(2), rounding error =
    RMS over the bands of round(a) - a, signal = RMS over the bands of (a + b) / 2.
    Luminance: the same for Y (photometry.radiance_to_xyz), squares pooled over 5 x 5 pixels
    (one pixel's difference is a one-sample estimate of its noise).
    """
    from scipy.ndimage import uniform_filter

    from metricscenes.photometry import radiance_to_xyz

    a64, b64 = a.astype(np.float64), b.astype(np.float64)
    rounded = {m: round_mantissa(a, m).astype(np.float64) for m in widths}
    out = {}
    band_noise = np.sqrt(np.mean((a64 - b64) ** 2 / 2, axis=-1))
    band_signal = np.sqrt(np.mean(((a64 + b64) / 2) ** 2, axis=-1))
    band_error = {m: np.sqrt(np.mean((r - a64) ** 2, axis=-1)) for m, r in rounded.items()}
    y_a, y_b = radiance_to_xyz(a64)[..., 1], radiance_to_xyz(b64)[..., 1]

    def pool(squares):  # root of the 5 x 5 mean (clipped at 0: the filter's round-off)
        return np.sqrt(np.maximum(uniform_filter(squares, 5, mode="nearest"), 0.0))

    y_noise, y_signal = pool((y_a - y_b) ** 2 / 2), pool(((y_a + y_b) / 2) ** 2)
    y_error = {m: pool((radiance_to_xyz(r)[..., 1] - y_a) ** 2) for m, r in rounded.items()}
    for name, noise, signal, error in (("band", band_noise, band_signal, band_error),
                                       ("luminance", y_noise, y_signal, y_error)):
        lit = signal > DARK * np.percentile(signal, 99.9)
        rel = noise[lit] / signal[lit]
        out[name] = {"lit": float(lit.mean()), "rel_noise_p5": float(np.percentile(rel, 5)),
                     "rel_noise_median": float(np.median(rel)),
                     "ok": {m: float(np.mean(e[lit] < noise[lit] / 10)) for m, e in error.items()},
                     "ratio": {m: math.sqrt(np.sum(e**2) / np.sum(noise**2)) for m, e in error.items()}}
    return out


def noise_manifest(manifest, light_groups: list[str] | None):
    """The manifest the noise units are rendered with: ``manifest`` (the collection's, or
    another, e.g. metric-300: its grid and spp) with only ``light_groups`` rendered (they
    cost the time)."""
    from metricscenes.manifest import parse_manifest

    if not light_groups:
        return manifest
    data = manifest.model_dump(mode="json", exclude={"store", "illuminance_sweep"})
    return parse_manifest({**data, "light_groups": light_groups, "conditions": {"any": {light_groups[0]: 1.0}}})


def noise_study(collection: Collection, manifest, units: list[str], widths: list[int], work: Path) -> None:
    work = work / "noise" / manifest.sha256()[:12]
    print(f"\nrender noise: {', '.join(units)} of {manifest.name} ({', '.join(manifest.light_groups)}) "
          f"rendered with their own seed and another "
          f"({manifest.render.plate_spp} spp plates, {manifest.render.inset_spp} spp insets); per kept mantissa "
          "width: lit pixels whose rounding error is under a tenth of their noise / RMS rounding error : RMS noise",
          flush=True)
    rows = []
    for unit in units:
        for path, (a, b, _) in render_twice(manifest, unit, work / unit).items():
            same = (array_sha256(a) == collection.resolved.arrays.get(path)
                    if manifest.sha256() == collection.manifest_sha256 else None)  # None: another manifest
            rows.append((path, same, noise_and_rounding(a, b, widths)))
    for name in ("band", "luminance"):
        print(f"\n{name}: {'each of the 31 values of a pixel' if name == 'band' else 'Y = the band sum, 5 x 5 px'}\n")
        print("| array | own seed = collection | lit px | relative noise: 5 % / median | "
              + " | ".join(f"{m} bits" for m in widths) + " |")
        print("|---|---|---|---|" + "---|" * len(widths))
        for path, same, stats in rows:
            st = stats[name]
            print(f"| {path} | {'n/a' if same is None else 'yes' if same else 'NO'} | {100 * st['lit']:.0f} % | "
                  f"{st['rel_noise_p5']:.3f} / {st['rel_noise_median']:.3f} | "
                  + " | ".join(f"{100 * st['ok'][m]:.2f} % / {st['ratio'][m]:.4f}" for m in widths) + " |")
        worst = {m: (min(st[name]["ok"][m] for *_, st in rows), max(st[name]["ratio"][m] for *_, st in rows))
                 for m in widths}
        print("| worst | | | | " + " | ".join(f"{100 * ok:.2f} % / {r:.4f}" for ok, r in worst.values()) + " |")


def rewrite_collection(collection: Collection, out: Path, mantissa_bits: int | None,
                       spectral_basis: int | None = None) -> tuple[Path, dict[str, str]]:
    """A copy of the collection's store written by the store's writer (with ``store``
    settings ``mantissa_bits``, ``spectral_basis``); the sha256 it returns per array."""
    shutil.rmtree(out, ignore_errors=True)
    (out / RADIANCE_STORE).mkdir(parents=True)
    shutil.copy(collection.root / RADIANCE_STORE / "zarr.json", out / RADIANCE_STORE / "zarr.json")  # root attributes
    group = radiance_group(collection)
    arrays = collection.resolved.arrays
    # every scene's mask (collections written before masks had a sha256 do not list them)
    paths = sorted({*arrays, *(f"masks/{s.scene_id}" for s in collection.scenes())})
    written = {}
    for path in paths:
        data, attrs = read_checked(collection.root, group, path, arrays.get(path), path)
        extent = TanExtent(*attrs["extent_tan"])
        if path.startswith("masks/"):
            written[path] = CollectionWriter(out).unit_arrays(path.split("/")[1]).write_mask(data, extent)
        else:
            kind, unit, light_group = path.split("/")
            extra = {k: v for k, v in attrs.items() if k in ("spp", "seed")}
            unit_arrays = CollectionWriter(out).unit_arrays(unit, mantissa_bits, spectral_basis)
            written[path] = unit_arrays.write_radiance(kind, light_group, data, extent, extra)
    return out, written


def metric300_pixels(manifest_path: Path) -> dict[str, float]:
    """Pixels of the units of one metric-300 environment, by kind (each unit counted once,
    whatever its light groups): plate on its reference grid, frames on theirs
    (``render.frame_divisor``), insets sized by
    its plan (``inset_window``, mean over its environments); and its number of environments."""
    from metricscenes import scene as scene_mod
    from metricscenes.generate import scene_inset_window
    from metricscenes.manifest import load_manifest
    from metricscenes.plan import plan_collection

    m = load_manifest(manifest_path)
    scenes = plan_collection(m)
    inset_px = 0
    for s in scenes:
        pose = scene_mod.car_pose(s.environment, s.distance_m)
        _, _, _, w, h = scene_inset_window(m, s.environment, scene_mod.car_vertices(s.environment, pose))
        inset_px += w * h
    grid = m.reference_grid.width_px * m.reference_grid.height_px
    frame_w, frame_h = m.frame_grid_px()
    return {"plates": grid, "frames": frame_w * frame_h * len(m.distances_m), "insets": inset_px / m.environments,
            "environments": m.environments}


def whole_store(collection: Collection, widths: list[int], work: Path, metric300: Path, keep: bool,
                spectral_basis: int | None = None) -> None:
    """Sizes of the whole store: as it is, rewritten lossless, rewritten with BitRound (and,
    with ``spectral_basis`` K, with BitRound on the coefficients of a K-spectra basis)."""
    envs = len({s.environment_id for s in collection.scenes()})
    n_scenes = len(collection.scenes())
    variants: dict[str, Path] = {"as stored (zarr default: zstd 0)": collection.root}
    print(f"\nwhole store: {collection.root} ({envs} environments, {n_scenes} scenes); "
          f"load {os.getloadavg()[0]:.1f}; writing copies under {work}", flush=True)
    settings = [(None, None), *((bits, None) for bits in widths)]
    settings += [(bits, spectral_basis) for bits in widths] if spectral_basis else []
    for bits, basis in settings:
        name = "store chain, lossless" if bits is None else f"BitRound {bits} + store chain"
        name = name if basis is None else f"spectral basis {basis}, {name}"
        started = time.perf_counter()
        out, written = rewrite_collection(collection, work / f"whole-{bits or 'lossless'}-{basis or 31}", bits, basis)
        seconds = time.perf_counter() - started
        if bits is None:  # the lossless copy is the same collection: every recorded sha256 must hold
            for name_ in (RESOLVED_MANIFEST_FILE, GROUNDTRUTH_FILE):
                shutil.copy(collection.root / name_, out / name_)
            same = all(written[path] == sha for path, sha in collection.resolved.arrays.items())
            problems = verify_collection(out)
            print(f"  lossless copy: every sha256 equals the recorded one: {same}; verify: "
                  f"{'no problems' if not problems else problems[:3]}", flush=True)
        print(f"  {name}: written in {seconds:.0f} s", flush=True)
        variants[name] = out
    # Bytes per kind, and per pixel of a unit (summed over its light groups), for the extrapolation.
    pixels = {}
    group = radiance_group(collection)
    for path in collection.resolved.arrays:
        kind, unit = path.split("/")[:2]
        if kind != "masks":
            pixels[(kind, unit)] = math.prod(group[path].shape[:2])
    unit_px = {k: sum(v for (kind, _), v in pixels.items() if kind == k) for k in ("plates", "insets", "frames")}
    target = metric300_pixels(metric300)
    print("\n| store | GB (all files) | MB per environment | MB per scene | size vs as stored | "
          "metric-300, extrapolated: MB per environment | GB for its 50 |")
    print("|---|---|---|---|---|---|---|")
    base = file_bytes(collection.root / RADIANCE_STORE)
    for name, root in variants.items():
        store = root / RADIANCE_STORE
        total = file_bytes(store)
        per_px = {k: chunk_bytes(store / k) / unit_px[k] for k in unit_px}
        metric = sum(per_px[k] * target[k] for k in unit_px) + chunk_bytes(store / "masks") / envs
        print(f"| {name} | {total / 1e9:.2f} | {total / envs / MB:.0f} | {total / n_scenes / MB:.1f} | "
              f"{total / base:.3f} | {metric / MB:.0f} | {metric * target['environments'] / 1e9:.1f} |")
    print(f"\nmetric-300 per environment: plate {target['plates']:.0f} px, frames {target['frames']:.0f} px, "
          f"insets {target['insets']:.0f} px (its plan, mean over its {target['environments']} environments), "
          "times the bytes per unit pixel (all its light groups) measured here, per kind")
    if not keep:
        for name, root in variants.items():
            if root != collection.root:
                shutil.rmtree(root)


def main() -> None:
    parser = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    parser.add_argument("--collection", type=Path, default=Path("collections/quick"))
    parser.add_argument("--environments", type=int, nargs="+", default=[0, 7],
                        help="codec study subset (default: env000, and env007 which has street lights)")
    parser.add_argument("--mantissa-bits", type=int, nargs="+", default=[4, 5, 6, 7, 8, 9, 10, 12])
    parser.add_argument("--slow", action="store_true", help="also blosc zstd 9 and zstd 19 (tens of times slower)")
    parser.add_argument("--noise-units", nargs="+", default=[], help="render these units twice (e.g. env000 env000-d100m)")
    parser.add_argument("--noise-manifest", type=Path, help="render them from this manifest (default: the collection's)")
    parser.add_argument("--noise-light-groups", nargs="+", help="render only these light groups")
    parser.add_argument("--whole", action="store_true", help="rewrite the whole store (lossless, BitRound)")
    parser.add_argument("--metric300", type=Path, default=Path("manifests/metric-300.yaml"))
    parser.add_argument("--work", type=Path, default=Path("/tmp/store-codecs"), help="scratch folder")
    parser.add_argument("--keep", action="store_true", help="keep the --whole copies")
    parser.add_argument("--spectral-basis", type=int, help="--whole: also each width on a basis of this many spectra")
    args = parser.parse_args()
    # The numcodecs bridge warns that its codecs are outside the zarr v3 specification: said in the table.
    warnings.filterwarnings("ignore", message=".*not in the Zarr version 3 specification.*")
    collection = Collection.open(args.collection)
    args.work.mkdir(parents=True, exist_ok=True)
    if args.whole:
        whole_store(collection, args.mantissa_bits, args.work, args.metric300, args.keep, args.spectral_basis)
    elif args.noise_units:
        from metricscenes.manifest import load_manifest

        base = load_manifest(args.noise_manifest) if args.noise_manifest else collection.manifest
        manifest = noise_manifest(base, args.noise_light_groups)
        noise_study(collection, manifest, args.noise_units, args.mantissa_bits, args.work)
    else:
        codec_study(collection, args.environments, args.mantissa_bits, args.slow, args.work)


if __name__ == "__main__":
    main()
