"""Golden bytes: smoke's arrays and ground truth, and a cam12 day run on it, hash as they did
on two other x86-64 AVX2 machines (tests/golden/smoke-avx2.json).

The README promises bit-reproducible results; this is the check that sees a machine or a
library version that breaks it. On an AVX-512 machine Mitsuba's ray tracer (Embree) and
onnxruntime take other kernels, which nothing in Python can pin, so the hashes are not
expected to match there (docs/performance.md, "Bytes across machines") and the test says so.
"""

from __future__ import annotations

import hashlib
import json
from pathlib import Path

import pytest
import yaml

from conftest import require_model
from metricscenes.numeric_pins import isa_class, package_versions, pins_hold

pytestmark = pytest.mark.slow

GOLDEN = json.loads((Path(__file__).parent / "golden" / "smoke-avx2.json").read_text())


def _sha256(path: Path) -> str:
    return hashlib.sha256(path.read_bytes()).hexdigest()


@pytest.fixture(scope="module", autouse=True)
def same_kind_of_machine():
    if isa_class() != GOLDEN["isa_class"]:
        pytest.skip(f"golden hashes are for x86-64 {GOLDEN['isa_class']} machines; this one is {isa_class()}, "
                    "where Embree and onnxruntime choose other kernels (docs/performance.md)")
    versions = package_versions()
    changed = {k: (v, versions.get(k)) for k, v in GOLDEN["versions"].items() if versions.get(k) != v}
    assert not changed, f"byte-deciding packages differ from constraints.txt (golden, installed): {changed}"
    assert pins_hold(), "numeric kernels not pinned: numpy was imported before metricscenes"


def test_smoke_arrays_and_groundtruth_are_golden(smoke_collection):
    resolved = yaml.safe_load((smoke_collection / "manifest.resolved.yaml").read_text())
    assert resolved["manifest_sha256"] == GOLDEN["manifest_sha256"]
    differ = sorted(k for k, v in GOLDEN["arrays"].items() if resolved["arrays"].get(k) != v)
    assert set(resolved["arrays"]) == set(GOLDEN["arrays"])
    assert not differ, f"{len(differ)} of {len(GOLDEN['arrays'])} arrays differ from the golden bytes, e.g. {differ[:3]}"
    assert _sha256(smoke_collection / "groundtruth.json") == GOLDEN["groundtruth_sha256"]


def test_cam12_day_run_is_golden(smoke_collection, tmp_path):
    from typer.testing import CliRunner

    from benchmark.cli.main import app

    require_model("yolov5n-dynamic.onnx")
    out = tmp_path / "cam12-day"
    result = CliRunner().invoke(app, ["run", "--camera", "cam12", "--collection", str(smoke_collection),
                                      "--out", str(out)])
    assert result.exit_code == 0, result.output
    got = {name: _sha256(out / name) for name in GOLDEN["cam12_day"]}
    differ = sorted(k for k, v in GOLDEN["cam12_day"].items() if got[k] != v)
    assert not differ, f"{len(differ)} of {len(got)} files of the cam12 run differ from the golden bytes: {differ}"
    numerics = json.loads((out / "results.json").read_text())["numerics"]
    assert numerics["pinned"] and numerics["isa_class"] == "avx2"
