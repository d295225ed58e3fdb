"""The detector registry (``data/models.yaml``) and model-file resolution.

A model is given by registry name (looked up in ``model_dir``, default env
``METRICSCENES_MODEL_DIR``) or by path. A file whose name matches a registry entry is
checked against that entry's sha256, so a corrupted or substituted file is refused.
"""

from __future__ import annotations

import os
from dataclasses import dataclass
from functools import lru_cache
from importlib import resources
from pathlib import Path

import yaml

from benchmark.detectors.base import DetectorError
from metricscenes.files import sha256_file

MODEL_DIR_ENV = "METRICSCENES_MODEL_DIR"


@dataclass(frozen=True)
class ModelEntry:
    name: str
    family: str
    file: str
    input_size: str | int  # fixed square size in px, or 'dynamic'
    sha256: str
    licence: str
    url: str
    notes: str = ""


@lru_cache(maxsize=1)
def registry() -> dict[str, ModelEntry]:
    """All registry entries by name."""
    text = resources.files("benchmark.detectors").joinpath("data/models.yaml").read_text()
    return {m["name"]: ModelEntry(**m) for m in yaml.safe_load(text)["models"]}


def entry_for_file(path: Path) -> ModelEntry | None:
    """The registry entry whose file name is ``path``'s name, if any."""
    return next((e for e in registry().values() if e.file == Path(path).name), None)


def default_model_dir() -> Path | None:
    """``METRICSCENES_MODEL_DIR`` resolved against the working directory (absolute)."""
    value = os.environ.get(MODEL_DIR_ENV)
    return Path(value).expanduser().resolve() if value else None


def resolve_model(model: str | Path, model_dir: Path | None = None) -> tuple[Path, ModelEntry | None]:
    """Path of a registry name or file path, and its registry entry (None for unknown files)."""
    entries = registry()
    if isinstance(model, str) and model in entries:
        entry = entries[model]
        folder = model_dir or default_model_dir()
        if folder is None:
            raise DetectorError(f"model '{model}' is a registry name; set {MODEL_DIR_ENV} or pass --model-dir (model_dir in Python) to locate {entry.file}")
        path = Path(folder) / entry.file
    else:
        path = Path(model)
        if not path.exists() and model_dir is not None and (Path(model_dir) / path).exists():
            path = Path(model_dir) / path
        entry = entry_for_file(path)
    if not path.is_file():
        known = ", ".join(entries)
        raise DetectorError(f"model file not found: {path} (registry names: {known})")
    return path, entry


def verify_sha256(path: Path, entry: ModelEntry | None) -> str:
    """sha256 of ``path``; DetectorError if it differs from the registry entry's."""
    digest = sha256_file(path)
    if entry is not None and digest != entry.sha256:
        raise DetectorError(f"sha256 mismatch for {path}: got {digest}, registry '{entry.name}' expects {entry.sha256}")
    return digest
