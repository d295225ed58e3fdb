"""The first K environments of a collection, finished or still rendering, as a collection of
their own: its manifest with ``environments: K`` and ``-firstK`` after its name (the text a GPU
machine renders the same K environments from: benchmarks/studies/gpu_scored_environments.sh calls
:func:`first_manifest_text`), its finished units' arrays hard-linked (nothing is rendered or
copied but metadata), then ``generate`` checks every unit against its record and writes the
ground truth and resolved manifest.

So a collection another machine made of the same K environments can be scored beside this
one's (``benchmark compare``, ``benchmark publish backend-scores``; docs/performance.md, "On a
GPU") before the whole is done.

    python -m metricscenes.first_environments /work/collections/metric-300 \
        manifests/metric-300.yaml 8 /work/collections/metric-300-first8
"""

from __future__ import annotations

import argparse
import os
import re
import shutil
import sys
from pathlib import Path

from metricscenes.generate import generate, plan_units
from metricscenes.manifest import WIDE_KINDS, parse_manifest
from metricscenes.plan import plan_collection
from metricscenes.store import PROGRESS_DIR, RADIANCE_STORE
from metricscenes.writer import VARIANT_STAMP


def first_manifest_text(text: str, k: int) -> str:
    """The manifest's YAML with ``environments: k`` and ``-firstk`` after its name, every other
    line as it was (the GPU machine's manifest is this text: the same sha256)."""
    text = re.sub(r"(?m)^environments: .*$", f"environments: {k}", text)
    return re.sub(r"(?m)^name: (.*)$", rf"name: \1-first{k}", text)


def link_tree(src: Path, dst: Path) -> None:
    """Hard-link ``src``'s files into ``dst``; zarr's metadata (``zarr.json``) is copied, since
    ``generate`` rewrites the root's attributes and must not touch the source's."""
    for folder, _, files in os.walk(src):
        target = dst / Path(folder).relative_to(src)
        target.mkdir(parents=True, exist_ok=True)
        for name in files:
            if name == "zarr.json":
                shutil.copyfile(Path(folder) / name, target / name)
            else:
                os.link(Path(folder) / name, target / name)


def main(argv=None) -> int:
    ap = argparse.ArgumentParser(description=__doc__.split("\n\n")[0])
    ap.add_argument("source", type=Path, help="the collection (finished or still rendering)")
    ap.add_argument("manifest", type=Path, help="its manifest")
    ap.add_argument("k", type=int, help="how many environments")
    ap.add_argument("out", type=Path, help="a new folder")
    args = ap.parse_args(argv)
    import yaml

    text = first_manifest_text(args.manifest.read_text(), args.k)
    manifest = parse_manifest(yaml.safe_load(text), source=f"{args.manifest} (first {args.k})")
    units = plan_units(plan_collection(manifest))
    missing = [u.key for u in units if not (args.source / PROGRESS_DIR / f"{u.key}.json").is_file()]
    if missing:
        print(f"error: {args.source} has not finished {len(missing)} of the {len(units)} units "
              f"(first: {missing[0]})", file=sys.stderr)
        return 1
    if args.out.exists():
        print(f"error: {args.out} exists; choose a new folder", file=sys.stderr)
        return 1
    (args.out / PROGRESS_DIR).mkdir(parents=True)
    shutil.copyfile(args.source / PROGRESS_DIR / VARIANT_STAMP, args.out / PROGRESS_DIR / VARIANT_STAMP)
    store = args.source / RADIANCE_STORE
    for meta in [store / "zarr.json", *store.glob("*/zarr.json")]:
        (args.out / meta.relative_to(args.source)).parent.mkdir(parents=True, exist_ok=True)
        shutil.copyfile(meta, args.out / meta.relative_to(args.source))
    for u in units:
        for kind in ("plates", "insets", "frames", "masks", *WIDE_KINDS):
            if (store / kind / u.key).is_dir():
                link_tree(store / kind / u.key, args.out / RADIANCE_STORE / kind / u.key)
        shutil.copyfile(args.source / PROGRESS_DIR / f"{u.key}.json", args.out / PROGRESS_DIR / f"{u.key}.json")
    generate(manifest, args.out, notice=lambda line: print(line, file=sys.stderr))
    print(f"wrote {args.out}: the first {args.k} environments of {args.source} ({len(units)} units)")
    return 0


if __name__ == "__main__":
    sys.exit(main())
