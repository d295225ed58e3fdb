"""manifests/first.yaml, the README's first command, is quick's first two environments and
nothing else: the same plan, seeds and render settings, so the same arrays (measured byte for
byte in docs/performance.md, "The README's first command"), and no leaderboard protocol."""

from pathlib import Path

from benchmark.leaderboard.protocols import load_protocols
from metricscenes.manifest import load_manifest
from metricscenes.plan import plan_collection

REPO = Path(__file__).resolve().parents[1]


def test_first_is_quick_cut_to_its_first_two_environments():
    first = load_manifest(REPO / "manifests" / "first.yaml")
    quick = load_manifest(REPO / "manifests" / "quick.yaml")
    assert (first.name, first.protocol, first.environments) == ("first", "first", 2)
    own = {"name", "protocol", "description", "environments"}
    assert first.model_dump(exclude=own) == quick.model_dump(exclude=own)
    first_scenes = plan_collection(first)
    assert first_scenes == plan_collection(quick)[: len(first_scenes)]
    assert len(first_scenes) == 2 * len(quick.distances_m)


def test_first_is_no_leaderboard_protocol():
    """A first look rests on two cars per distance: submit refuses its protocol."""
    assert "first" not in load_protocols()
