"""The store's codecs: lossless by default (values and sha256 unchanged, older collections
still read), BitRound as a manifest option (the rounded values and their sha256 stored)."""

import json
import shutil

import numpy as np
import pytest
import yaml

from metricscenes.geometry import REFERENCE_EXTENT
from metricscenes.manifest import ManifestError, load_manifest, parse_manifest
from metricscenes.store import RADIANCE_STORE, Collection, array_sha256, verify_collection
from metricscenes.writer import RADIANCE_COMPRESSORS, UnitArrays, round_mantissa

from conftest import REPO, SMOKE_MANIFEST

# The published manifests' sha256: collections and leaderboard entries are keyed by them.
PUBLISHED_SHA256 = {
    "smoke": "2b496a1a26819de6db01186453bfb52231475da05b2c558a5d153342fd8ee687",
    "quick": "6ce3394e3129c2704092906ed6ae4d447610c48f19399a571be4319123edaf00",
    "metric-300": "fd9342ff7e065f1d172afca80942cb14e08ddd056981ee56f914a44a77d14db5",
}


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
    sha = UnitArrays(tmp_path, "env000").write_radiance("plates", "sky_day", cube, REFERENCE_EXTENT, {"spp": 4})
    back, attrs, codecs = _read(tmp_path, "plates/env000/sky_day")
    assert sha == array_sha256(cube) == array_sha256(back)
    assert back.dtype == np.float32 and np.array_equal(back.view(np.uint32), cube.view(np.uint32))
    assert [c["name"] for c in codecs] == ["bytes", "blosc"] and codecs[1] == dict(RADIANCE_COMPRESSORS[0])
    assert "mantissa_bits" not in attrs and attrs["spp"] == 4


def test_a_chunk_too_large_for_blosc_is_written_with_zstd(tmp_path, monkeypatch):
    from metricscenes import writer

    monkeypatch.setattr(writer, "BLOSC_MAX_BYTES", 1024)  # instead of a 2 GiB film
    cube = radiance_like()
    sha = UnitArrays(tmp_path, "env000-d025m").write_radiance("frames", "car_lights", cube, REFERENCE_EXTENT)
    back, _, codecs = _read(tmp_path, "frames/env000-d025m/car_lights")
    assert [c["name"] for c in codecs] == ["bytes", "zstd"]
    assert sha == array_sha256(back) == array_sha256(cube)


@pytest.mark.parametrize("bits", [7, 10])
def test_bitround_stores_the_rounded_values_and_their_sha256(tmp_path, bits):
    cube = radiance_like(seed=bits)
    arrays = UnitArrays(tmp_path, "env000-d025m", mantissa_bits=bits)
    sha = arrays.write_radiance("insets", "car_lights", cube, REFERENCE_EXTENT)
    back, attrs, _ = _read(tmp_path, "insets/env000-d025m/car_lights")
    rounded = round_mantissa(cube, bits)
    assert np.array_equal(back.view(np.uint32), rounded.view(np.uint32))
    assert sha == array_sha256(back) != array_sha256(cube)
    assert attrs["mantissa_bits"] == bits
    # Rounding is deterministic and idempotent: a rerun of generate writes the same sha256.
    assert arrays.write_radiance("insets", "car_lights", cube, REFERENCE_EXTENT) == sha
    assert np.array_equal(round_mantissa(rounded, bits).view(np.uint32), rounded.view(np.uint32))
    normal = cube >= np.finfo(np.float32).tiny
    relative = np.abs(rounded[normal].astype(np.float64) - cube[normal]) / cube[normal]
    assert relative.max() <= 2.0 ** -(bits + 1)
    assert np.all((rounded == 0) == (cube == 0)) and np.all(rounded >= 0)


@pytest.mark.parametrize("name", sorted(PUBLISHED_SHA256))
def test_published_manifests_keep_their_sha256(name):
    """``store`` is left out of the hash while it is unset; set, it is hashed."""
    manifest = load_manifest(REPO / "manifests" / f"{name}.yaml")
    assert manifest.sha256() == PUBLISHED_SHA256[name]
    data = yaml.safe_load((REPO / "manifests" / f"{name}.yaml").read_text())
    rounded = parse_manifest({**data, "store": {"mantissa_bits": 8 if manifest.store else 9}})
    assert rounded.sha256() != PUBLISHED_SHA256[name]


@pytest.mark.parametrize("store", [{"mantissa_bits": 0}, {"mantissa_bits": 23}, {"mantissa_bits": "9"},
                                   {}, {"mantissa_bits": 9, "codec": "zfp"}, {"spectral_basis": 3},
                                   {"spectral_basis": 8.5}])
def test_bad_store_settings_name_the_field(store):
    data = yaml.safe_load(SMOKE_MANIFEST.read_text())
    with pytest.raises(ManifestError, match=r"^m\.yaml: store(\.mantissa_bits|\.codec|\.spectral_basis)?: "):
        parse_manifest({**data, "store": store}, source="m.yaml")


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


@pytest.mark.slow
def test_generate_with_bitround_is_deterministic_and_verifies(smoke_collection, smoke_manifest, tmp_path):
    """The rounded collection holds exactly the lossless one's values rounded, records their
    sha256 (so it verifies), and keeps its store setting in the resolved manifest."""
    from metricscenes.generate import generate

    data = smoke_manifest.model_dump(mode="json", exclude={"store"})
    # One environment at the first two distances: the same plans and seeds as the smoke collection's.
    manifest = parse_manifest({**data, "environments": 1, "distances_m": [25.0, 50.0], "store": {"mantissa_bits": 8}})
    root = generate(manifest, tmp_path / "rounded")
    assert verify_collection(root) == []
    resolved = yaml.safe_load((root / "manifest.resolved.yaml").read_text())
    assert resolved["manifest"]["store"]["mantissa_bits"] == 8 and resolved["manifest_sha256"] == manifest.sha256()
    lossless = Collection.open(smoke_collection)
    for path, sha in resolved["arrays"].items():
        stored, attrs, _ = _read(root, path)
        if path.startswith("masks/"):
            assert sha == lossless.resolved.arrays[path]
            continue
        original, _, _ = _read(smoke_collection, path)
        assert np.array_equal(stored.view(np.uint32), round_mantissa(original, 8).view(np.uint32))
        assert sha == array_sha256(stored) and attrs["mantissa_bits"] == 8
    assert Collection.open(root).radiance("env000-d050m", "night").layers[0].radiance.dtype == np.float32
