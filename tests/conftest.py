"""Shared fixtures: the smoke collection is rendered once per test session."""

from __future__ import annotations

import os
from pathlib import Path

import metricscenes  # noqa: F401  (before numpy: it pins the numeric kernels, as the commands do)
import pytest

REPO = Path(__file__).resolve().parents[1]
SMOKE_MANIFEST = REPO / "manifests" / "smoke.yaml"


def model_dir() -> Path:
    # Resolved once against the working directory, as the README's relative path needs.
    return Path(os.environ.get("METRICSCENES_MODEL_DIR", REPO.parent / "shared" / "models")).expanduser().resolve()


# Registry names resolve in METRICSCENES_MODEL_DIR: default it to the shared folder beside
# the checkout, so tests that use a registry name skip or pass the same way as the rest.
os.environ["METRICSCENES_MODEL_DIR"] = str(model_dir())


def require_model(name: str) -> Path:
    path = model_dir() / name
    if not path.is_file():
        pytest.skip(f"{name} not found in METRICSCENES_MODEL_DIR={model_dir()} (set it to the shared models folder)")
    return path


@pytest.fixture(scope="session")
def smoke_manifest():
    from metricscenes.manifest import load_manifest

    return load_manifest(SMOKE_MANIFEST)


@pytest.fixture(scope="session")
def smoke_collection(tmp_path_factory, smoke_manifest) -> Path:
    from metricscenes.generate import generate

    out = tmp_path_factory.mktemp("smoke") / "collection"
    generate(smoke_manifest, out)
    return out

