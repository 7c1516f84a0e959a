"""The speed-ups of the learning loop give the numbers of the plain computation, to the last bit:
the formant map's sample rows, a feedback's sound computed when read, the context read at once."""

from __future__ import annotations

import numpy as np
import pytest

from models.layout import N_STEPS, SAMPLE_INDICES, VOICE_DIM
from models.world import Feedback
from sim import Playroom
from sim.dmp import voice_trajectory
from sim.vocal.vtl.formant_map import FormantMap


def test_the_map_at_the_sample_rows_is_the_whole_map_s_rows() -> None:
    formant_map = FormantMap.load()
    rows = np.array(SAMPLE_INDICES)
    rng = np.random.default_rng(3)
    for _ in range(300):
        frames = rng.uniform(-1.0, 1.0, (N_STEPS, 7))
        np.testing.assert_array_equal(formant_map.at_rows(frames, rows), formant_map(frames)[rows])


def test_a_sound_given_as_a_function_is_computed_once_when_read() -> None:
    calls = []

    def sound() -> np.ndarray:
        calls.append(1)
        return np.ones((N_STEPS, 2))

    feedback = Feedback("voice", np.zeros(60), sound=sound)
    assert calls == []
    assert feedback.sound.shape == (N_STEPS, 2)
    assert feedback.sound is feedback.sound and calls == [1]
    assert Feedback("arm", np.zeros(60)).sound is None


def test_a_vocal_movement_s_sound_is_the_tract_s_at_every_step() -> None:
    room = Playroom("kinematic", seed=2)
    for m in np.random.default_rng(4).uniform(-1.0, 1.0, (20, VOICE_DIM)):
        feedback = room.act_voice(m)
        frames = voice_trajectory(m, room.config).T
        expected = room.task.normalised(room.vocal_tract.formants(frames))
        np.testing.assert_array_equal(feedback.sound, expected)
        np.testing.assert_array_equal(feedback.s[50:55], expected[list(SAMPLE_INDICES), 0])


def test_the_context_is_the_objects_positions_read_one_by_one() -> None:
    for grasp in ("kinematic", "physical"):
        room = Playroom(grasp, seed=5)
        for m in np.random.default_rng(6).uniform(-1.0, 1.0, (15, 21)):
            p = room.physics
            expected = [p.stick_handle(), p.toy_positions().ravel(), p.caregiver_position()]
            np.testing.assert_array_equal(room.context(), np.concatenate(expected))
            room.act_arm(m)


def test_compiled_kernels_measure_distances_as_numpy_does() -> None:
    """The compiled kinematic rules (sim/grasping/kinematic_kernel.py) take math.hypot for
    NumPy's np.hypot: both must be the C library's, to the last bit, or a grasp at the
    threshold could differ between the closed form and the step-by-step rules."""
    import math

    from sim.compiled import compiled

    def hypots(dx: np.ndarray, dy: np.ndarray, out: np.ndarray) -> None:
        for i in range(dx.size):
            out[i] = math.hypot(dx[i], dy[i])

    rng = np.random.default_rng(8)
    dx, dy = rng.uniform(-2.0, 2.0, (2, 200000)) * rng.choice([1e-8, 1.0, 1e3], (2, 200000))
    out = np.empty_like(dx)
    compiled(hypots)(dx, dy, out)
    np.testing.assert_array_equal(out, np.hypot(dx, dy))


def test_which_objects_moved_and_when_as_numpy_finds_it() -> None:
    """sim/moved_kernel.py's first step beyond MOVED_DISTANCE, object by object, is the NumPy
    expression's, at every scale and with offsets placed on the threshold itself."""
    from models.layout import MOVED_DISTANCE
    from sim.moved_kernel import NOT_MOVED, first_moved_steps

    rng = np.random.default_rng(10)
    for trial in range(3000):
        scale = rng.choice([1e-4, MOVED_DISTANCE, 0.1])
        positions = rng.uniform(-1, 1, (N_STEPS + 1, 5, 2))
        positions[1:] = positions[0] + rng.normal(0, scale, (N_STEPS, 5, 2)) * (trial % 3 > 0)
        if trial % 5 == 0:  # an offset of exactly the threshold along x: not beyond it
            positions[7, 2] = positions[0, 2] + (MOVED_DISTANCE, 0.0)
        offsets = positions[:, 1:] - positions[0, 1:]
        beyond = np.linalg.norm(offsets, axis=2) > MOVED_DISTANCE
        want = np.where(beyond.any(axis=0), beyond.argmax(axis=0), NOT_MOVED)
        first = np.empty(4, dtype=np.int64)
        assert first_moved_steps(positions, MOVED_DISTANCE, first) == beyond.any(axis=0).sum()
        np.testing.assert_array_equal(first, want)


@pytest.mark.parametrize("grasp", ["kinematic", "physical"])
def test_the_compiled_rules_work_where_numba_cannot_cache(run_without_numba_cache, grasp) -> None:
    """A read-only install without a writable home: the kinematic rules and the physical
    control steps are compiled in the process (no cache directory numba may use) and move the
    room as the cached ones do."""
    code = (
        "import numpy as np\n"
        "from sim import Playroom\n"
        f"room = Playroom({grasp!r}, seed=3)\n"
        "commands = np.random.default_rng(9).uniform(-1.0, 1.0, (40, 21))\n"
        "print(np.concatenate([room.act_arm(m).s for m in commands]).tobytes().hex())\n"
    )
    printed = run_without_numba_cache(code)
    room = Playroom(grasp, seed=3)
    commands = np.random.default_rng(9).uniform(-1.0, 1.0, (40, 21))
    here = np.concatenate([room.act_arm(m).s for m in commands]).tobytes().hex()
    assert printed == here
