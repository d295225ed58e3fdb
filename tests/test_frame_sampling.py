"""benchmarks/frame_sampling.py swaps a scene's car-lamp frame as the store's reader would
add it: the same frame gives the same scene, a coarser uniform one adds uniformly."""

from __future__ import annotations

import numpy as np
import pytest

from metricscenes.geometry import REFERENCE_EXTENT
from metricscenes.radiance import RadianceLayer, SpectralScene


@pytest.fixture(scope="module")
def frame_sampling(load_benchmark):
    return load_benchmark("frame_sampling")


def test_with_frame_replaces_the_frame_on_the_plates_grid(frame_sampling):
    rng = np.random.default_rng(3)
    plate_only = rng.uniform(0.0, 1.0, (54, 96, 31)).astype(np.float32)
    frame = rng.uniform(0.0, 0.1, (54, 96, 31)).astype(np.float32)
    weight = 2.0
    scene = SpectralScene(layers=(RadianceLayer(plate_only + np.float32(weight) * frame, REFERENCE_EXTENT),))
    same = frame_sampling.with_frame(scene, frame, frame, weight)
    np.testing.assert_allclose(same.layers[0].radiance, scene.layers[0].radiance, rtol=1e-6)
    coarse = np.full((27, 48, 31), 0.05, np.float32)  # a uniform frame stays uniform on the finer grid
    swapped = frame_sampling.with_frame(scene, frame, coarse, weight)
    np.testing.assert_allclose(swapped.layers[0].radiance, plate_only + np.float32(weight * 0.05), rtol=1e-5)
