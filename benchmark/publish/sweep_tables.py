"""Sweep folders laid out as ``docs/data``: each sweep's ``sweep.csv`` and ``od50.csv`` under the
names the docs and tests/test_results_findings.py read (``benchmark publish sweeps``).

The sweep folders of a collection are ``COLLECTION``, ``COLLECTION-640``, ``-native``, ``-lux``,
``-day-paper`` and ``-policy-…``; in ``docs/data`` they become ``sweep.csv``, ``sweep-640.csv``,
``-native``, ``-illuminance``, ``-day-paper`` and ``-policies`` (the policy tables gain an
``exposure`` column, the reference policy's rows coming from the reference sweep).
"""

from __future__ import annotations

from pathlib import Path

import pandas as pd

REFERENCE_POLICY = "auto_peak (reference)"
POLICIES = {"percentile:99": "-policy-percentile-99", "mean_level@0.18": "-policy-mean_level-0.18",
            "hdr:16": "-policy-hdr-16"}  # the sweep folders' names after the collection's
SWEEPS = {"": "", "-640": "-640", "-native": "-native", "-illuminance": "-lux", "-day-paper": "-day-paper"}
POLICY_CONDITIONS = ("dusk", "night")  # the acquisition policies: dusk and the paper's night


def publish(results: Path, out: Path, collection: str = "quick", say=print) -> None:
    """docs/data's CSVs from the sweep folders of ``collection`` under ``results``; ``say``
    gets a line for each table left as it is."""
    out.mkdir(parents=True, exist_ok=True)
    for suffix, folder_suffix in SWEEPS.items():
        folder = collection + folder_suffix
        if not (results / folder / "sweep.csv").is_file():  # absent, or a sweep still under way
            say(f"no {results / folder}/sweep.csv: {out}/sweep{suffix}.csv and od50{suffix}.csv left as they are")
            continue
        for name in ("sweep", "od50"):
            (out / f"{name}{suffix}.csv").write_bytes((results / folder / f"{name}.csv").read_bytes())
    policies = {policy: collection + folder_suffix for policy, folder_suffix in POLICIES.items()}
    if not all((results / folder / "sweep.csv").exists() for folder in policies.values()):
        say(f"no policy sweeps under {results}: {out}/sweep-policies.csv and od50-policies.csv left as they are")
        return
    reference_cameras = set(pd.read_csv(results / next(iter(policies.values())) / "sweep.csv")["camera"])
    for name in ("sweep", "od50"):
        parts = []
        reference = pd.read_csv(results / collection / f"{name}.csv")
        reference = reference[reference["camera"].isin(reference_cameras)
                              & reference["condition"].isin(POLICY_CONDITIONS)]
        parts.append(reference.assign(exposure=REFERENCE_POLICY))
        parts += [pd.read_csv(results / folder / f"{name}.csv").assign(exposure=policy)
                  for policy, folder in policies.items()]
        pd.concat(parts, ignore_index=True).to_csv(out / f"{name}-policies.csv", index=False)
