"""The example notebook runs, as a reader would run it, on the smoke collection: its code
cells are executed in order in one namespace (plain script extraction: no Jupyter kernel
needed). A notebook that no longer runs against the API fails here."""

import json
from pathlib import Path

import pytest

from conftest import require_model

NOTEBOOK = Path(__file__).resolve().parents[1] / "examples" / "evaluate_your_camera.ipynb"
pytestmark = pytest.mark.slow


def test_the_notebook_runs_on_the_smoke_collection(smoke_collection, tmp_path, monkeypatch, capsys):
    require_model("yolov5n-dynamic.onnx")
    monkeypatch.setenv("METRICSCENES_COLLECTION", str(smoke_collection))
    monkeypatch.setenv("METRICSCENES_EXAMPLE_OUT", str(tmp_path / "runs"))
    monkeypatch.setenv("MPLBACKEND", "Agg")
    cells = [c for c in json.loads(NOTEBOOK.read_text())["cells"] if c["cell_type"] == "code"]
    assert all(c["outputs"] == [] for c in cells), "commit the notebook without outputs"
    namespace: dict = {"__name__": "__main__"}
    for i, cell in enumerate(cells):
        exec(compile("".join(cell["source"]), f"{NOTEBOOK.name}[cell {i}]", "exec"), namespace)
    printed = capsys.readouterr().out
    assert "field of view" in printed and "distortion k1 -0.05" in printed
    assert "mine-2.0um-f1.8-6mm  AP 25 m:" in printed and "cam12  AP 25 m:" in printed
    assert namespace["comparison"]["verdict"] in printed
    assert namespace["capture"].rgb8.shape == (900, 1600, 3)
    assert (tmp_path / "runs" / "cam12" / "results.json").is_file()
