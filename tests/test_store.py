"""The store's codecs: lossless (values and sha256 unchanged, older collections still read)."""

import json
import shutil

import numpy as np
import pytest
import yaml

from metricscenes.geometry import REFERENCE_EXTENT
from metricscenes.store import (
    RADIANCE_COMPRESSORS, RADIANCE_STORE, Collection, array_sha256, verify_collection, write_radiance,
)


def radiance_like(shape=(27, 48, 31), seed=0) -> np.ndarray:
    """Path-traced-like float32 radiance: noisy values over decades, zeros (unlit pixels),
    subnormals (far lamp tails) and a few bright ones."""
    rng = np.random.default_rng(seed)
    cube = (rng.lognormal(-12.0, 4.0, shape) * rng.gamma(2.0, 0.5, shape)).astype(np.float32)
    cube[rng.random(shape) < 0.3] = 0.0
    cube.flat[:5] = [1e-40, 5.6e-39, np.finfo(np.float32).tiny, 3.0, 0.5]
    return cube


def _read(root, path):
    import zarr

    node = zarr.open_group(str(root / RADIANCE_STORE), mode="r")[path]
    return node[...], dict(node.attrs), node.metadata.to_dict()["codecs"]


def test_lossless_default_reads_back_bit_identical_with_the_same_sha256(tmp_path):
    cube = radiance_like()
    sha = write_radiance(tmp_path, "plates", "env000", "sky_day", cube, REFERENCE_EXTENT, {"spp": 4})
    back, attrs, codecs = _read(tmp_path, "plates/env000/sky_day")
    assert sha == array_sha256(cube) == array_sha256(back)
    assert back.dtype == np.float32 and np.array_equal(back.view(np.uint32), cube.view(np.uint32))
    assert [c["name"] for c in codecs] == ["bytes", "blosc"] and codecs[1] == dict(RADIANCE_COMPRESSORS[0])
    assert "mantissa_bits" not in attrs and attrs["spp"] == 4


def test_a_chunk_too_large_for_blosc_is_written_with_zstd(tmp_path, monkeypatch):
    from metricscenes import store

    monkeypatch.setattr(store, "BLOSC_MAX_BYTES", 1024)  # instead of a 2 GiB film
    cube = radiance_like()
    sha = write_radiance(tmp_path, "frames", "env000-d025m", "car_lights", cube, REFERENCE_EXTENT)
    back, _, codecs = _read(tmp_path, "frames/env000-d025m/car_lights")
    assert [c["name"] for c in codecs] == ["bytes", "zstd"]
    assert sha == array_sha256(back) == array_sha256(cube)


def rewrite_with_zarr_default_codecs(root) -> None:
    """Every array of a collection written again as collections were before (zarr's default
    chain: bytes + zstd level 0), same values and attributes."""
    import zarr

    group = zarr.open_group(str(root / RADIANCE_STORE), mode="r")
    paths = yaml.safe_load((root / "manifest.resolved.yaml").read_text())["arrays"]
    for path in paths:
        node = group[path]
        data, attrs = node[...], dict(node.attrs)
        arr = zarr.create_array(store=str(root / RADIANCE_STORE), name=path, shape=data.shape, dtype=data.dtype,
                                chunks=data.shape, dimension_names=node.metadata.dimension_names,
                                attributes=attrs, overwrite=True, config={"write_empty_chunks": True})
        arr[...] = data


@pytest.mark.slow
def test_collections_written_with_the_old_codec_still_read(smoke_collection, tmp_path):
    old = tmp_path / "old"
    shutil.copytree(smoke_collection, old)
    rewrite_with_zarr_default_codecs(old)
    codecs = json.loads((old / RADIANCE_STORE / "plates" / "env000" / "sky_day" / "zarr.json").read_text())["codecs"]
    assert [c["name"] for c in codecs] == ["bytes", "zstd"]
    assert verify_collection(old) == []
    new, before = Collection.open(smoke_collection), Collection.open(old)
    for scene in ("env000-d025m", "env001-d200m"):
        a, b = new.radiance(scene, "night"), before.radiance(scene, "night")
        assert all(np.array_equal(x.radiance, y.radiance) for x, y in zip(a.layers, b.layers))
