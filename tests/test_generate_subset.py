"""Rendering some light groups only (``generate --conditions``), adding the others later.

A group's bytes must not depend on which groups were rendered with it: {sky_day} first and
the rest added later give the arrays, records and resolved manifest of a render of all in
one run. A collection that lacks a condition's groups refuses it in one line that names
them and the command that renders them; ``verify`` takes their absence for no damage."""

import json

import pytest
import yaml
from typer.testing import CliRunner

from metricscenes.generate import generate, requested_light_groups
from metricscenes.manifest import ManifestError, parse_manifest
from metricscenes.store import Collection, CollectionError, verify_collection

pytestmark = pytest.mark.slow

# One environment at one distance on a 96 x 54 grid, quick's switches, three skies and two lamp
# groups: two units of a fraction of a second each.
TINY = {
    "name": "tiny-groups", "protocol": "smoke", "seed": 20230116, "environments": 1, "distances_m": [50],
    "reference_grid": {"width_px": 96, "height_px": 54},
    "render": {"plate_spp": 4, "inset_spp": 4, "inset_pixel_mrad": 0.5, "inset_max_px": 64, "max_depth": 3,
               "inset_feather": 0.05, "ground_to_horizon": True, "frame_divisor": 2, "plate_lamp": True,
               "rear_retroreflectors": True, "inset_shadow": True},
    "light_groups": ["sky_day", "sky_dusk", "sky_night", "car_lights", "ego_lights"],
    "conditions": {"day": {"sky_day": 1.0}, "dusk": {"sky_dusk": 1.0, "car_lights": 1.0, "ego_lights": 1.0},
                   "night": {"ambient": "sky_night", "lamps": {"car_lights": 1.0, "ego_lights": 1.0},
                             "target_image_plane_lux": [0.1, 1.0]}},
    "illuminance_sweep": {"base": "day", "ambient_group": "sky_day", "levels_lux": [10]},
}


def _manifest(variant: str = "scalar_spectral"):
    return parse_manifest({**TINY, "render": {**TINY["render"], "variant": variant}})


def _resolved(root):
    return yaml.safe_load((root / "manifest.resolved.yaml").read_text())


def _records(root) -> dict:
    """The progress records, less the seconds each unit took (the one field that differs between runs)."""
    out = {}
    for path in sorted((root / "progress").glob("*.json")):
        record = json.loads(path.read_text())
        record.pop("seconds")
        out[path.name] = record
    return out


@pytest.fixture(scope="module")
def full(tmp_path_factory):
    return generate(_manifest(), tmp_path_factory.mktemp("full") / "c")


def test_conditions_name_their_light_groups():
    m = _manifest()
    assert requested_light_groups(m) is None  # nothing named: all of them
    assert requested_light_groups(m, ["day"]) == ("sky_day",)
    assert requested_light_groups(m, ["night"]) == ("sky_night", "car_lights", "ego_lights")  # targeted
    assert requested_light_groups(m, ["day@10lux"], ["ego_lights"]) == ("sky_day", "ego_lights")
    with pytest.raises(ManifestError, match="unknown condition 'dawn'"):
        requested_light_groups(m, ["dawn"])
    with pytest.raises(ManifestError, match="light group 'street_lights' is not one of"):
        requested_light_groups(m, (), ["street_lights"])


def test_day_first_then_the_rest_gives_the_bytes_of_one_full_render(full, tmp_path):
    m = _manifest()
    part = generate(m, tmp_path / "part", light_groups=requested_light_groups(m, ["day"]))
    day = Collection.open(part)
    assert day.light_groups == ("sky_day",) and day.held_condition_names == ["day", "day@10lux"]
    assert _resolved(part)["light_groups"] == ["sky_day"]
    assert verify_collection(part) == []  # the absent groups are no damage
    held = _resolved(part)["arrays"]
    assert {p.split("/")[-1] for p in held if not p.startswith("masks/")} == {"sky_day"}
    assert held == {p: sha for p, sha in _resolved(full)["arrays"].items() if p in held}
    scene = day.scenes()[0].scene_id
    assert day.radiance(scene, "day").layers[0].radiance.any()

    generate(m, part, light_groups=requested_light_groups(m, ["dusk"]))  # adds sky_dusk and the lamps
    assert Collection.open(part).light_groups == ("sky_day", "sky_dusk", "car_lights", "ego_lights")
    generate(m, part)  # no conditions: all of them
    assert _resolved(part)["arrays"] == _resolved(full)["arrays"]
    for name in ("manifest.resolved.yaml", "groundtruth.json"):
        assert (part / name).read_bytes() == (full / name).read_bytes(), name
    assert _records(part) == _records(full)
    assert "light_groups" not in _resolved(full) and Collection.open(full).light_groups == _manifest().light_groups


def test_a_condition_whose_groups_are_missing_is_refused_in_one_line(tmp_path):
    m = _manifest()
    part = generate(m, tmp_path / "part", light_groups=requested_light_groups(m, ["day"]))
    c = Collection.open(part)
    scene = c.scenes()[0].scene_id
    line = (f"{part} holds no sky_dusk, car_lights, ego_lights (rendered: sky_day); add them with: metricscenes "
            f"generate --manifest <its manifest> --out {part} --conditions dusk")
    with pytest.raises(CollectionError) as dusk:
        c.radiance(scene, "dusk")
    assert str(dusk.value) == line
    for read in (lambda: c.photometry(scene, "night"), lambda: c.targeted_weights(scene, "night"),
                 lambda: c.illuminance_lux(scene, "night")):
        with pytest.raises(CollectionError, match="holds no sky_night, car_lights, ego_lights .* --conditions night$"):
            read()
    with pytest.raises(CollectionError, match=r"holds no sky_night \(rendered: sky_day\); add it with: .* "
                                              "--light-groups sky_night$"):
        c.radiance(scene, {"sky_night": 1.0})


def test_the_command_line_renders_day_only_and_says_what_it_holds(tmp_path):
    from benchmark.cli.main import app as benchmark_app
    from metricscenes.cli import app

    manifest = tmp_path / "tiny.yaml"
    manifest.write_text(yaml.safe_dump(TINY))
    out = tmp_path / "c"
    made = CliRunner().invoke(app, ["generate", "--manifest", str(manifest), "--out", str(out), "--conditions", "day"])
    assert made.exit_code == 0, made.output
    assert "it holds sky_day: run again with more --conditions" in made.output
    info = CliRunner().invoke(app, ["info", str(out), "--json", "--photometry"])
    assert info.exit_code == 0, info.output
    summary = json.loads(info.output)
    assert summary["light_groups"] == ["sky_day"] and summary["conditions_held"] == ["day", "day@10lux"]
    assert {row["condition"] for row in summary["photometry"]} == {"day", "day@10lux"}
    table = CliRunner().invoke(app, ["info", str(out)])
    assert table.exit_code == 0 and "holds 1 of its 5 light groups; add the others with: metricscenes generate" \
        in " ".join(table.output.split())
    refused = CliRunner().invoke(app, ["generate", "--manifest", str(manifest), "--out", str(out),
                                       "--conditions", "day,dawn"])
    assert refused.exit_code == 2 and "unknown condition 'dawn'" in refused.output
    verified = CliRunner().invoke(app, ["verify", str(out)])
    assert verified.exit_code == 0, verified.output

    run = CliRunner().invoke(benchmark_app, ["run", "--camera", "cam12", "--collection", str(out),
                                             "--condition", "dusk", "--out", str(tmp_path / "run")])
    lines = [line for line in run.output.splitlines() if line.strip()]
    assert run.exit_code == 2 and len(lines) == 1, run.output
    assert f"holds no sky_dusk, car_lights, ego_lights (rendered: sky_day); add them with: metricscenes generate " \
           f"--manifest <its manifest> --out {out} --conditions dusk" in " ".join(run.output.split())
    assert not (tmp_path / "run").exists()


def _one_pass_run(root) -> dict:
    """Run in a child process (the Mitsuba variant is global to a process, and the other tests
    render with scalar_spectral): a full llvm_ad_spectral render, then day first and the rest
    added, all in this process so that the kernels compile once."""
    from pathlib import Path

    m = _manifest("llvm_ad_spectral")
    full = generate(m, Path(root) / "full")
    notices = []
    part = generate(m, Path(root) / "part", light_groups=requested_light_groups(m, ["day"]), notice=notices.append)
    first = list(Collection.open(part).light_groups)
    generate(m, part)
    resolved = [(root / "manifest.resolved.yaml").read_bytes() for root in (part, full)]
    return {"notices": notices, "first": first, "same_arrays": _resolved(part)["arrays"] == _resolved(full)["arrays"],
            "same_resolved": resolved[0] == resolved[1]}


def test_a_one_pass_variant_renders_a_sky_with_its_lamps_and_keeps_the_bytes(tmp_path):
    """On a JIT variant the first sky and every lamp group are one pass: asking for day renders the
    lamps too (said in a notice), and the rest added later gives the bytes of one full render."""
    import subprocess
    import sys

    from metricscenes.render import RenderError, check_variant

    try:
        check_variant("llvm_ad_spectral")
    except RenderError as exc:
        pytest.skip(f"llvm_ad_spectral does not render here: {exc}")
    proc = subprocess.run([sys.executable, __file__, str(tmp_path)], capture_output=True, text=True, timeout=1200)
    assert proc.returncode == 0, proc.stderr[-2000:]
    got = json.loads(proc.stdout.strip().splitlines()[-1])
    assert got["notices"] == ["llvm_ad_spectral renders a sky with every lamp group in one pass: also rendering "
                              "car_lights, ego_lights"]
    assert got["first"] == ["sky_day", "car_lights", "ego_lights"]
    assert got["same_arrays"] and got["same_resolved"]


if __name__ == "__main__":
    import sys

    print(json.dumps(_one_pass_run(sys.argv[1])))
