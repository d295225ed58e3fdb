"""Experiments over a collection: a camera run, sweeps, SPMs, reports, acceptance checks, comparisons."""
