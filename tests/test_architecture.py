"""The house's walls, read from the source: ``metricscenes`` never imports ``benchmark``;
``benchmark`` reaches ``metricscenes`` only through the store API and the value and unit
modules, never through its render, generate, writer, scene or asset internals; the store's
read side never imports its write side; and inside ``benchmark`` every import goes down
the wings' layer order, but the exceptions declared here with their reasons."""

import ast
from pathlib import Path

REPO = Path(__file__).resolve().parents[1]

# What `benchmark` may import from `metricscenes`: the store API (collections, their
# ground truth on any grid), value types (manifests, tangent extents, spectral scenes), units
# (wavelength grid, photometry), small shared helpers (files, CLI, the process-pool and
# dask backends, where outputs may go, the one-writer lock its run and sweep folders take),
# the numeric-kernel pins and their provenance, and the version. Not the writer: benchmark
# only reads collections.
PUBLIC = {"metricscenes", "metricscenes.store", "metricscenes.manifest", "metricscenes.geometry", "metricscenes.radiance",
          "metricscenes.spectral", "metricscenes.photometry", "metricscenes.files", "metricscenes.cli_support",
          "metricscenes.backends", "metricscenes.outputs", "metricscenes.lock", "metricscenes.numeric_pins"}


def _imports(package: str) -> dict[str, set[str]]:
    """{module file: the modules it imports (absolute names)}, every import statement,
    at the top or inside functions; relative imports made absolute, and ``from P import M``
    names the module ``P.M`` too where M is one (``from benchmark.camera import dual_gain``)."""
    found = {}
    for path in sorted((REPO / package).rglob("*.py")):
        here = path.relative_to(REPO).with_suffix("").parts[:-1]  # the package the file is in
        names = set()
        for node in ast.walk(ast.parse(path.read_text(), str(path))):
            if isinstance(node, ast.Import):
                names.update(a.name for a in node.names)
            elif isinstance(node, ast.ImportFrom):
                base = here[:len(here) - node.level + 1] if node.level else ()
                module = ".".join((*base, *([node.module] if node.module else [])))
                names.add(module)
                names.update(f"{module}.{a.name}" for a in node.names if _is_module(f"{module}.{a.name}"))
        found[str(path.relative_to(REPO))] = names
    return found


def _is_module(name: str) -> bool:
    path = REPO.joinpath(*name.split("."))
    return path.with_suffix(".py").is_file() or (path / "__init__.py").is_file()


def test_metricscenes_never_imports_benchmark():
    offenders = {f: sorted(n for n in names if n.split(".")[0] == "benchmark")
                 for f, names in _imports("metricscenes").items()}
    assert {f: n for f, n in offenders.items() if n} == {}


def test_benchmark_uses_only_the_public_side_of_metricscenes():
    offenders = {f: sorted(n for n in names if n.split(".")[0] == "metricscenes" and n not in PUBLIC)
                 for f, names in _imports("benchmark").items()}
    assert {f: n for f, n in offenders.items() if n} == {}


def test_the_read_side_never_imports_the_write_side():
    """``Collection`` (store) and the record types both sides share never reach the
    writer, nor what drives it."""
    write_side = {"metricscenes.writer", "metricscenes.generate", "metricscenes.lock"}
    found = _imports("metricscenes")
    offenders = {f: sorted(found[f] & write_side) for f in ("metricscenes/store.py", "metricscenes/records.py",
                                                        "metricscenes/groundtruth_checks.py",
                                                        "metricscenes/checked_read.py",
                                                        "metricscenes/collection_files.py")}
    assert {f: n for f, n in offenders.items() if n} == {}


# ── Inside benchmark: the wings and their layer order ────────────────────────────────────
# A wing is a sub-package (benchmark/camera/) or a top-level module (benchmark/suggest.py).

# At the bottom, small shared modules that every wing may use; they import no wing.
SHARED = {
    "suggest": "'did you mean': the nearest valid name, for any wing that refuses one",
    "coco": "COCO's class names, category ids and box IoU: what the detectors speak and the scoring reads",
    "record_base": "the pydantic base, strict-JSON float and censoring mark every result record is made of",
}

# The wings above them, lowest first: each may import the shared modules and the wings it
# names, all of them earlier in this order, so no import runs back up.
WINGS = {
    "camera": ((), "a camera turns radiance into images, whatever then looks at them"),
    "detectors": ((), "a detector turns images into COCO detections, whichever camera made them"),
    "measure": (("camera",), "it measures a camera (MTF, photon transfer, the figures a spec implies) by running its stages"),
    "scoring": ((), "AP and OD50 come from ground truth and detections alone, whoever made them"),
    "result_files": (("scoring",), "the files runs and sweeps write hold what the scoring returns (od50.json: its bootstrap)"),
    "leaderboard": (("camera", "detectors", "scoring", "result_files"),
                    "it judges a submission from its records, spec and detector, and runs no experiment"),
    "experiments": (("camera", "detectors", "measure", "scoring", "result_files", "leaderboard"),
                    "a run chains camera, detector and scoring over a collection and writes result files; compare "
                    "and report put runs beside leaderboard submissions (their shipped detections, the references' "
                    "band) and name conditions by the protocols' labels"),
    "publish": (("camera", "detectors", "measure", "scoring", "result_files", "experiments"),
                "what the docs publish (tables, the results page, studies' CSVs) is made from runs and sweeps"),
    "cli": (("camera", "detectors", "measure", "scoring", "result_files", "experiments", "leaderboard", "publish"),
            "the commands sit on top: they call every wing and nothing imports them"),
}

# Imports that cross a wall on purpose: (file, module it imports) -> why.
DECLARED = {
    ("benchmark/leaderboard/validate.py", "benchmark.measure.mtf"):
        "a submission's measured or analytic MTF50 is re-measured from its spec by the one policy, "
        "not taken on trust",
    ("benchmark/leaderboard/submission.py", "benchmark.measure.mtf"):
        "submit records the camera's MTF50 by that same policy, so its check re-measures the same number",
}


def _wing(module: str) -> str | None:
    """The wing of ``benchmark.<wing>[...]``; None outside benchmark and for the package's
    face (benchmark/__init__.py, which holds no wing's code)."""
    parts = module.split(".")
    return parts[1] if parts[0] == "benchmark" and len(parts) > 1 and parts[1] != "__init__" else None


def _wing_breaks(imports: dict[str, set[str]], wings: dict, shared: dict, declared: dict) -> list[str]:
    """'file -> module' for every import from one wing into another that the wing may not
    import and that is not declared; a wing in neither table is a break too (it has no place
    in the order yet)."""
    breaks = []
    for file, modules in sorted(imports.items()):
        own = _wing(file.removesuffix(".py").replace("/", "."))
        if own is None:
            continue
        if own not in wings and own not in shared:
            breaks.append(f"{file}: wing {own!r} has no place in WINGS or SHARED")
            continue
        allowed = {own, *shared} if own in wings else {own}
        allowed |= set(wings.get(own, ((), ""))[0])
        for module in sorted(modules):
            target = _wing(module)
            if target is not None and target not in allowed and (file, module) not in declared:
                breaks.append(f"{file} -> {module}")
    return breaks


def test_every_import_inside_benchmark_goes_down_the_wings():
    breaks = _wing_breaks(_imports("benchmark"), WINGS, SHARED, DECLARED)
    assert not breaks, "imports across a wing's wall (move the code down, or declare it in DECLARED):\n" + "\n".join(breaks)


def test_the_wings_are_a_layer_order():
    """Each wing may import only wings below it, so the allowed imports have no loop."""
    seen = set()
    for wing, (below, why) in WINGS.items():
        assert set(below) <= seen, f"{wing} may import {sorted(set(below) - seen)}, not below it"
        assert why
        seen.add(wing)
    assert not set(WINGS) & set(SHARED)


def test_every_declared_exception_is_still_an_import():
    """A declared exception the code no longer makes is stale: the wall holds there again."""
    found = _imports("benchmark")
    assert [pair for pair in DECLARED if pair[1] not in found.get(pair[0], set())] == []


def test_the_checker_reports_a_deliberate_break():
    """A synthetic import graph with one bad edge in each way a wall breaks: the camera up
    into the experiments, a shared module into a wing, an undeclared leaderboard import of
    measure, and a wing the order does not place. The declared and downward edges pass."""
    graph = {
        "benchmark/camera/spec.py": {"benchmark.suggest", "benchmark.camera.lens", "benchmark.experiments.run", "numpy"},
        "benchmark/coco.py": {"benchmark.detectors.base"},
        "benchmark/leaderboard/render.py": {"benchmark.measure.mtf", "benchmark.scoring.od50"},
        "benchmark/leaderboard/validate.py": {"benchmark.measure.mtf"},
        "benchmark/newwing/thing.py": {"benchmark.camera"},
        "benchmark/__init__.py": {"metricscenes"},
    }
    assert _wing_breaks(graph, WINGS, SHARED, DECLARED) == [
        "benchmark/camera/spec.py -> benchmark.experiments.run",
        "benchmark/coco.py -> benchmark.detectors.base",
        "benchmark/leaderboard/render.py -> benchmark.measure.mtf",
        "benchmark/newwing/thing.py: wing 'newwing' has no place in WINGS or SHARED",
    ]
