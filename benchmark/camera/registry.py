"""The camera registry: the paper's 13 cameras (``cam01`` ... ``cam13``) as packaged
YAML files, the packaged extra cameras beside them (automotive HDR sensors, ``auto-*``:
loaded by name, never part of the 13), plus user specs loaded from any YAML path.

Errors are one-line :class:`ValueError` s naming the field and its allowed range, so a
CLI can print them as they are. A spec file with a key twice is refused (YAML would keep
the last silently), and so is a user file whose ``name`` is a registry camera's (in any
case) unless it is that camera's very spec: results and submissions name a camera by it.
An unknown registry name gets a "did you mean" (``CAM12`` → ``cam12``), never a substitute.
"""

from __future__ import annotations

import re
from pathlib import Path
from typing import Any

import yaml
from pydantic import BaseModel, ValidationError

from benchmark.camera.spec import PACKAGE_DATA_DIR, CameraSpec
from benchmark.camera.spec_files import SPEC_DIR_CONTEXT
from benchmark.suggest import did_you_mean

DATA_DIR = PACKAGE_DATA_DIR


class _UniqueKeyLoader(yaml.SafeLoader):
    """YAML's safe loader, refusing a mapping that holds a key twice (the spec would
    silently keep the last one)."""

    def construct_mapping(self, node, deep=False):
        seen = set()
        for key_node, _ in node.value:
            key = self.construct_object(key_node, deep=deep)
            try:
                duplicate = key in seen
            except TypeError:  # an unhashable key: yaml's own error, below
                break
            if duplicate:
                raise yaml.constructor.ConstructorError(None, None, f"duplicate key {key!r}", key_node.start_mark)
            seen.add(key)
        return super().construct_mapping(node, deep=deep)


def camera_names() -> list[str]:
    """Names of the paper's 13 cameras, in the paper's order: the registry that ``--cameras
    all`` and the leaderboard mean (``benchmark cameras list`` shows them, then the extras)."""
    return sorted(p.stem for p in DATA_DIR.glob("cam*.yaml"))


def extra_camera_names() -> list[str]:
    """Names of the packaged cameras beside the paper's 13 (the automotive HDR cameras,
    ``auto-*``): loaded by name like a registry camera, never part of ``all``."""
    return sorted(p.stem for p in DATA_DIR.glob("*.yaml") if not p.stem.startswith("cam"))


def list_cameras() -> list[CameraSpec]:
    """The packaged cameras, in the paper's order."""
    return [load_camera(name) for name in camera_names()]


def load_camera(name_or_path: str | int | Path) -> CameraSpec:
    """A camera by registry name (``"cam12"``), number (``12`` or ``"12"``) or YAML path.

    Raises:
        ValueError: unknown name (the message lists the valid ones), unreadable YAML,
            or a field out of range (the message names the field and its range).
    """
    text = str(name_or_path).strip()
    path = Path(text)
    if text.isdigit():
        text = f"cam{int(text):02d}"
    registry = text in camera_names() or text in extra_camera_names()
    if registry:
        path = DATA_DIR / f"{text}.yaml"
    elif not (path.suffix.lower() in (".yaml", ".yml", ".json") or path.is_file()):
        known = camera_names() + extra_camera_names()
        raise ValueError(f"unknown camera {name_or_path!r} (valid names: {', '.join(camera_names())}; "
                         f"extra cameras: {', '.join(extra_camera_names())})"
                         f"{did_you_mean(text, known, guess=_registry_spelling(text))}")
    if not path.is_file():
        raise ValueError(f"camera file not found: {path}")
    try:
        data = yaml.load(path.read_text(encoding="utf-8"), Loader=_UniqueKeyLoader)  # noqa: S506 (a SafeLoader)
    except yaml.YAMLError as exc:
        mark = getattr(exc, "problem_mark", None)
        where = f" (line {mark.line + 1})" if mark is not None else ""
        raise ValueError(f"{path}: invalid YAML{where}: {getattr(exc, 'problem', exc)}") from None
    camera = camera_from_dict(data, source=str(path), spec_dir=path.parent)
    if not registry:
        check_not_a_registry_name(camera, source=str(path))
    return camera


def _registry_spelling(text: str) -> str:
    """``cam1``, ``CAM012`` → ``cam01``, ``cam12``: a registry number however it was padded
    (for the suggestion only); anything else as it is."""
    match = re.fullmatch(r"cam0*(\d{1,2})", text.strip(), flags=re.IGNORECASE)
    return f"cam{int(match.group(1)):02d}" if match else text


def check_not_a_registry_name(camera: CameraSpec, source: str = "camera spec") -> None:
    """One-line ValueError if a user spec calls itself by a registry camera's name (in any
    case) without being that camera's spec: its results would be read, compared and
    ranked as the registry camera's."""
    taken = next((n for n in camera_names() + extra_camera_names() if n.lower() == camera.name.lower()), None)
    if taken is None:
        return
    if camera.sha256() == load_camera(taken).sha256():  # the registry spec itself, copied
        return
    raise ValueError(f"{source}: name {camera.name!r} is the registry camera {taken}'s, and this spec differs from "
                     f"it: give the camera a name of its own (e.g. {camera.name}-mine)")


def camera_from_dict(data: Any, source: str = "camera spec", *, spec_dir: str | Path | None = None) -> CameraSpec:
    """Validate a mapping into a :class:`CameraSpec` (one-line ValueError on failure).

    ``spec_dir``: the folder of the spec file; a ``sensor.qe`` that is not a packaged
    file must then exist there (relative to it) and is read from there. Without it (a
    spec that comes from no file, e.g. a results.json dump) the file is looked up when
    it is first read: packaged, else relative to the working folder.
    """
    if not isinstance(data, dict):
        raise ValueError(f"{source}: expected a mapping of camera fields, got {type(data).__name__}")
    context = {SPEC_DIR_CONTEXT: Path(spec_dir)} if spec_dir is not None else None
    try:
        return CameraSpec.model_validate(data, context=context)
    except ValidationError as exc:
        err = exc.errors()[0]
        loc = ".".join(str(p) for p in err["loc"])
        allowed = _allowed(CameraSpec, err["loc"])
        msg = err["msg"]
        if err["type"] == "value_error":  # our own checks: the message says it all (range included)
            msg = msg.removeprefix("Value error, ")
            allowed = ""
        shown = err["type"] != "missing" and not isinstance(err.get("input"), (dict, list))
        value = f" = {err['input']!r}" if shown else ""
        where = f"field '{loc}'{value}" if loc else "the spec as a whole"
        raise ValueError(f"{source}: {where}: {msg}{allowed}") from None


def _allowed(model: type[BaseModel], loc: tuple) -> str:
    """``' (allowed: 0.2 <= pixel_um <= 20)'`` from the field's constraints, if any."""
    for i, key in enumerate(loc):
        field = model.model_fields.get(str(key))
        if field is None:
            return ""
        ann = field.annotation
        if isinstance(ann, type) and issubclass(ann, BaseModel) and i + 1 < len(loc):
            model = ann
            continue
        lo = hi = None
        for meta in field.metadata:
            for attr, sym in (("ge", "<="), ("gt", "<")):
                if getattr(meta, attr, None) is not None:
                    lo = f"{getattr(meta, attr)} {sym} "
            for attr, sym in (("le", "<="), ("lt", "<")):
                if getattr(meta, attr, None) is not None:
                    hi = f" {sym} {getattr(meta, attr)}"
        if lo or hi:
            return f" (allowed: {lo or ''}{key}{hi or ''})"
        if getattr(ann, "__args__", None) and all(isinstance(a, str) for a in ann.__args__):
            return f" (allowed: {', '.join(ann.__args__)})"
        return ""
    return ""
