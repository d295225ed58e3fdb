"""The house's walls, read from the source (issue 12): ``metricscenes`` never imports
``benchmark``; ``benchmark`` reaches ``metricscenes`` only through the store API and
the value and unit modules, never through its render, generate, writer, scene or asset
internals; the store's read side never imports its write side."""

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
    at the top or inside functions."""
    found = {}
    for path in sorted((REPO / package).rglob("*.py")):
        names = set()
        for node in ast.walk(ast.parse(path.read_text(), str(path))):
            if isinstance(node, ast.Import):
                names.update(a.name for a in node.names)
            elif isinstance(node, ast.ImportFrom) and node.module and node.level == 0:
                names.add(node.module)
        found[str(path.relative_to(REPO))] = names
    return found


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
    offenders = {f: sorted(found[f] & write_side) for f in ("metricscenes/store.py", "metricscenes/records.py")}
    assert {f: n for f, n in offenders.items() if n} == {}


def test_only_the_command_line_imports_the_publishing_layer():
    """``benchmark.publish`` (what the docs publish) sits on top of experiments, scoring and the
    cameras; below it nothing reaches up into it."""
    offenders = {f: sorted(n for n in names if n.split(".")[:2] == ["benchmark", "publish"])
                 for f, names in _imports("benchmark").items()
                 if not f.startswith(("benchmark/publish/", "benchmark/cli/"))}
    assert {f: n for f, n in offenders.items() if n} == {}
