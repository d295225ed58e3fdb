import pytest
import yaml

from metricscenes.manifest import ManifestError, load_manifest, parse_manifest
from metricscenes.plan import plan_collection, plan_environment

from conftest import REPO, SMOKE_MANIFEST


def _smoke_dict():
    return yaml.safe_load(SMOKE_MANIFEST.read_text())


@pytest.mark.parametrize("name", ["smoke", "quick", "metric-300"])
def test_packaged_manifests_validate(name):
    m = load_manifest(REPO / "manifests" / f"{name}.yaml")
    assert m.name == name
    assert m.distances_m == (25, 50, 75, 100, 150, 200)


@pytest.mark.parametrize(
    "change, field",
    [
        (lambda d: d.update(environments=0), "environments"),
        (lambda d: d.update(distances_m=[50, 25]), "distances_m"),
        (lambda d: d["render"].update(plate_spp="many"), "render.plate_spp"),
        (lambda d: d["render"].update(inset_spp=32), "render.inset_spp"),  # not a square: 36 would be rendered
        (lambda d: d["reference_grid"].update(height_px=200), "reference_grid"),
        (lambda d: d["conditions"].update(dusk={"sky_dusk": 1.0}), "conditions.dusk.sky_dusk"),
        (lambda d: d.update(colour="blue"), "colour"),
        (lambda d: d.pop("seed"), "seed"),
        (lambda d: d.update(light_groups=["moonlight"]), "light_groups"),
        (lambda d: d["illuminance_sweep"].update(lamps_on=["street_lights"]), "illuminance_sweep"),
        (lambda d: d["illuminance_sweep"].update(lamps_on=["sky_day"]), "illuminance_sweep"),
    ],
)
def test_bad_manifest_names_the_field(change, field):
    data = _smoke_dict()
    change(data)
    with pytest.raises(ManifestError) as info:
        parse_manifest(data, source="m.yaml")
    message = str(info.value)
    assert "\n" not in message
    assert message.startswith(f"m.yaml: {field}")


def test_unreadable_and_non_yaml(tmp_path):
    with pytest.raises(ManifestError, match="cannot read"):
        load_manifest(tmp_path / "absent.yaml")
    bad = tmp_path / "bad.yaml"
    bad.write_text("name: [unclosed\n")
    with pytest.raises(ManifestError, match="not valid YAML"):
        load_manifest(bad)
    bad.write_text("- a list\n")
    with pytest.raises(ManifestError, match="mapping"):
        load_manifest(bad)


def test_plan_is_seeded_paired_and_prefix_stable(smoke_manifest):
    a, b = plan_collection(smoke_manifest), plan_collection(smoke_manifest)
    assert a == b
    assert len(a) == smoke_manifest.environments * len(smoke_manifest.distances_m)
    # Paired design: an environment keeps everything but the distance.
    envs = {s.environment for s in a}
    assert len(envs) == smoke_manifest.environments
    # Environment e does not depend on how many environments there are.
    bigger = smoke_manifest.model_copy(update={"environments": 5})
    assert plan_environment(bigger, 1) == plan_environment(smoke_manifest, 1)
    other = smoke_manifest.model_copy(update={"seed": smoke_manifest.seed + 1})
    assert plan_collection(other) != a
    assert len({s.scene_id for s in a}) == len(a)


def test_plan_draws_from_the_whole_asset_library():
    from metricscenes import plan
    from metricscenes.assets import cars, roads, skies

    assert plan.N_CARS == len(cars.car_library())
    assert plan.N_ROADS == len(roads.road_library())
    for kind, ids in plan.SKY_IDS.items():
        assert list(ids) == skies.skies_for(kind)
