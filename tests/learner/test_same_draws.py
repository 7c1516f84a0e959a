"""The learner's shortcuts draw what NumPy's own functions draw, from the same generator state."""

from __future__ import annotations

import numpy as np

from learner.interest import weighted_choice


def test_weighted_choice_is_generator_choice_draw_by_draw() -> None:
    """A changed NumPy that draws choice() differently fails here, not in a replication."""
    shapes = np.random.default_rng(0)
    ours, numpy = np.random.default_rng(7), np.random.default_rng(7)
    for _ in range(3000):
        progress = shapes.uniform(0.0, 1.0, 10) * (shapes.uniform(size=10) < 0.6)
        if progress.sum() == 0.0:
            progress[shapes.integers(10)] = 0.25  # a single model with progress, too
        p = progress / progress.sum()
        assert weighted_choice(ours, p) == numpy.choice(10, p=p)
    assert ours.bit_generator.state == numpy.bit_generator.state
