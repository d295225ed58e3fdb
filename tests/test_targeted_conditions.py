"""Conditions set by a photometric target (metricscenes.targets): smoke's ``night`` is the
paper's night, 0.1-1 lux mean image-plane illuminance at f/2.4, reached by scaling the night
sky under the lamps."""

from __future__ import annotations

import json
import math
import subprocess
import sys

import numpy as np
import pytest
from scipy import stats

from metricscenes.manifest import ManifestError, load_manifest, parse_manifest
from metricscenes.photometry import image_plane_illuminance_lux
from metricscenes.store import Collection
from metricscenes.targets import ambient_weight, draw_target_lux


def test_draw_is_seeded_and_log_uniform():
    draws = [draw_target_lux(7, env, "night", (0.1, 1.0)) for env in range(4000)]
    assert draws[:5] == [draw_target_lux(7, env, "night", (0.1, 1.0)) for env in range(5)]
    assert all(0.1 <= d <= 1.0 for d in draws)
    assert stats.kstest(np.log10(draws), stats.uniform(loc=-1.0, scale=1.0).cdf).pvalue > 0.01
    assert draw_target_lux(8, 0, "night", (0.1, 1.0)) != draws[0]  # another seed
    assert draw_target_lux(7, 0, "dusk", (0.1, 1.0)) != draws[0]  # another condition's draw
    assert draw_target_lux(7, 3, "x", (0.5, 0.5)) == pytest.approx(0.5)


def test_ambient_weight_meets_the_target_or_says_the_lamps_exceed_it():
    needed = (1.0 + 4.0 * 2.4**2) / math.pi  # cd/m^2 for 1 lux at f/2.4: E = pi L / (1 + 4 N^2)
    w = ambient_weight(1.0, 2.4, 2.0, {"car": 1.0}, {"car": 1.0}, "sky")
    assert not w.over_target and w.weights == {"sky": pytest.approx((needed - 1.0) / 2.0, rel=1e-9), "car": 1.0}
    over = ambient_weight(0.1, 2.4, 2.0, {"car": 10.0}, {"car": 1.0}, "sky")
    assert over.over_target and over.ambient_weight == 0.0 and over.lamps_lux > 0.1
    with pytest.raises(ValueError, match="adds no luminance"):
        ambient_weight(1.0, 2.4, 0.0, {}, {}, "sky")


def test_every_smoke_scene_meets_its_target(smoke_collection):
    c = Collection.open(smoke_collection)
    for scene in c.scenes():
        rec = c.targeted_weights(scene.scene_id, "night")
        lux = image_plane_illuminance_lux(c.mean_luminance(scene.scene_id, "night"), 2.4)  # the mix, measured
        if rec.over_target:
            assert rec.lamps_lux > rec.target_lux and lux == pytest.approx(rec.lamps_lux, rel=1e-3)
        else:
            assert lux == pytest.approx(rec.target_lux, rel=0.01), scene.scene_id
        assert 0.1 <= rec.target_lux <= 1.0 and set(rec.weights) == {"sky_night", "car_lights", "ego_lights"}
    # One target per environment, shared by its six distances.
    targets = {(s.environment_id, c.targeted_weights(s.scene_id, "night").target_lux) for s in c.scenes()}
    assert len(targets) == 2


def test_weights_are_the_same_in_another_process(smoke_collection):
    c = Collection.open(smoke_collection)
    here = {s.scene_id: c.condition_record(s.scene_id, "night") for s in c.scenes()}
    code = ("import json, sys; from metricscenes.store import Collection; c = Collection.open(sys.argv[1]); "
            "print(json.dumps({s.scene_id: c.condition_record(s.scene_id, 'night') for s in c.scenes()}))")
    there = json.loads(subprocess.run([sys.executable, "-c", code, str(smoke_collection)], check=True,
                                      capture_output=True, text=True).stdout)
    assert there == json.loads(json.dumps(here))


def test_a_fixed_condition_has_no_targeted_record(smoke_collection):
    c = Collection.open(smoke_collection)
    scene = c.scenes()[0].scene_id
    assert c.condition_record(scene, "night_regulation") is None and c.condition_record(scene, "day") is None


def _night(**changes) -> dict:
    base = load_manifest("manifests/smoke.yaml").model_dump(mode="json")
    base["conditions"]["night"] = {**base["conditions"]["night"], **changes}
    return base


@pytest.mark.parametrize("changes, message", [
    ({"target_image_plane_lux": [0.0, 1.0]}, "0 < low <= high"),
    ({"target_image_plane_lux": [-1.0, 1.0]}, "0 < low <= high"),
    ({"target_image_plane_lux": [1.0, 0.1]}, "0 < low <= high"),
    ({"ambient": "sky_dusk"}, "light group 'sky_dusk' is not rendered"),
    ({"lamps": {"street_lights": 1.0}}, "light group 'street_lights' is not rendered"),
    ({"ambient": "car_lights"}, "conditions.night.ambient"),
    ({"ambient": None}, "conditions.night.ambient"),
])
def test_bad_targets_are_refused_in_one_line(changes, message):
    with pytest.raises(ManifestError) as err:
        parse_manifest(_night(**changes), "smoke.yaml")
    assert message in str(err.value) and "\n" not in str(err.value)


def test_a_target_without_an_ambient_group_is_refused_before_anything_runs(tmp_path):
    data = _night()
    del data["conditions"]["night"]["ambient"]
    path = tmp_path / "m.json"
    path.write_text(json.dumps(data))
    proc = subprocess.run([sys.executable, "-m", "metricscenes.cli", "generate", "--manifest", str(path),
                           "--out", str(tmp_path / "c")], capture_output=True, text=True)
    lines = [line for line in proc.stderr.splitlines() + proc.stdout.splitlines() if line.strip()]
    assert proc.returncode != 0 and any("needs an ambient group" in line for line in lines), proc.stderr
    assert not (tmp_path / "c").exists()
