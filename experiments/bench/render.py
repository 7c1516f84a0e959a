"""Offscreen rendering speed (`playroom bench render`): frames per second, and the cost of a
filmed arm iteration against an unfilmed one. Needs an OpenGL backend: the CLI chooses it
before this module is imported (experiments/video/gl.py)."""

from __future__ import annotations

import math
import time
from collections.abc import Iterator

import numpy as np

from experiments.video.recording import DEFAULT_SIZE, FrameRecorder, parse_size
from models.layout import ARM_DIM
from sim import Playroom


def render_figures(
    size: tuple[int, int] = DEFAULT_SIZE,
    seed: int = 0,
    frames: int = 20,
    plain_repeats: int = 10,
    filmed_repeats: int = 2,
) -> Iterator[tuple[str, float, str]]:
    """(name, value, unit): offscreen frames per second at `size` (over `frames` renders), and
    the cost of a 50-step arm iteration filmed by a recorder (one frame per step) against an
    unfilmed one (best of `filmed_repeats` and `plain_repeats` random commands)."""
    width, height = parse_size(size)
    rng = np.random.default_rng(seed)
    room = Playroom(grasp="physical", seed=seed)
    with FrameRecorder(room, (width, height)) as recorder:
        for shadows, suffix in ((False, ""), (True, "_with_shadows")):
            recorder.shadows = shadows
            recorder.capture()  # the first frame of a style pays for its set-up
            start = time.perf_counter()
            for _ in range(frames):
                recorder.capture()
            fps = frames / (time.perf_counter() - start)
            recorder.take()
            yield f"render_fps_{width}x{height}{suffix}", fps, "frames/s"
        recorder.shadows = False

        def iteration_s(filmed: bool, repeats: int) -> float:
            best = math.inf
            for _ in range(repeats):
                m = rng.uniform(-1.0, 1.0, ARM_DIM)
                start = time.perf_counter()
                if filmed:
                    recorder.film("arm", m)
                    recorder.take()
                else:
                    room.act_arm(m)
                best = min(best, time.perf_counter() - start)
            return best

        plain = iteration_s(False, plain_repeats)
        filmed = iteration_s(True, filmed_repeats)
    yield "arm_iteration", plain * 1e3, "ms"
    yield f"arm_iteration_filmed_{width}x{height}", filmed * 1e3, "ms"
    yield "filmed_over_unfilmed_iteration", filmed / plain, "ratio"
