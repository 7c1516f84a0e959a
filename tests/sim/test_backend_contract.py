"""The contract every registered grasp backend keeps, run for each name in
sim/grasping/registry.py's `REGISTRY` (a backend added there is tested here without editing
this file), and for one more that only this file registers: a copy of the kinematic backend
with twice the grasp distance, the extension the registry is for, whose trials must
be reported at its own reach, not at the one its config.json's grasp distance suggests.

Each backend is loaded by name and built into a room; it acts (an arm and a voice command, with
feedback of the room's shape); its unobserved path (the closed form, or compiled steps) gives
what the observed, stepped dm_control path gives, to the bit; a short trial with it records what
it declares (backend.json), which for the two backends of before the record equals what old
trials are read with (experiments/trial_dir/backend_record.py `recorded_before`); the comparison's
grasp-rate row and the stick-reach figure show it under its own name and reach.
"""

from __future__ import annotations

import dataclasses
import subprocess
import sys
from collections.abc import Iterator
from pathlib import Path
from types import SimpleNamespace

import numpy as np
import pandas as pd
import pytest
from scripted import Waypoint, arm_command_through

from experiments.analysis.room_measures import RoomMeasures
from experiments.measure.stick import grasp_rates
from experiments.report import stick_reach
from experiments.report.comparison import _grasp_rate_row
from experiments.run.settings import TrialSettings
from experiments.run.trial import Trial, run_trial
from experiments.trial_dir import backend_record, storage
from experiments.trial_dir.layout import BACKEND_FILE, CONFIG_FILE
from models.layout import ARM_DIM, N_STEPS, SENSORY_DIM, TRACKED_OBJECTS, VOICE_DIM
from sim import Playroom
from sim import events as ev
from sim.grasping.base import GraspBackend
from sim.grasping.kinematic import KinematicGrasp
from sim.grasping.names import DEFAULT_GRASP, GRASPS
from sim.grasping.registry import REGISTRY, load

DOUBLED = "kinematic_doubled"
# The backends of before trials recorded theirs: old trials are read by their config.
RECORDED_BEFORE = ("kinematic", "physical")


class DoubledGrasp(KinematicGrasp):
    """The kinematic rules with twice the world's grasp distance; config.json still records
    the world's."""

    name = DOUBLED

    def __init__(self, config, edits, carrying, rule=None):
        doubled = dataclasses.replace(config, grasp_distance=2 * config.grasp_distance)
        super().__init__(doubled, edits, carrying, rule)


@pytest.fixture(scope="module", params=[*REGISTRY, DOUBLED])
def grasp(request: pytest.FixtureRequest) -> Iterator[str]:
    """A backend's name, with the doubled copy registered (as one line of the registry would
    register it) while the module's tests run."""
    with pytest.MonkeyPatch.context() as patch:
        patch.setitem(REGISTRY, DOUBLED, f"{__name__}:{DoubledGrasp.__name__}")
        yield request.param


@pytest.fixture(scope="module")
def trial(grasp: str, tmp_path_factory: pytest.TempPathFactory) -> Trial:
    """A short trial with the backend, in a batch folder of its own."""
    settings = TrialSettings(grasp=grasp, iterations=30, checkpoint_every=30, seed=1)
    out = tmp_path_factory.mktemp("batch") / f"{grasp}-random-seed0001"
    return run_trial(out, settings, progress=False)


# The registry ---------------------------------------------------------------------------------
def test_the_names_the_command_line_reads_cost_no_backend() -> None:
    """The table is lazy: its names (the command line's choices, the default among them) are
    read without importing a backend's module or MuJoCo; an unknown name is refused, naming
    the registered ones."""
    assert GRASPS == tuple(REGISTRY) and DEFAULT_GRASP in GRASPS
    heavy = sorted({entry.split(":")[0] for entry in REGISTRY.values()} | {"mujoco"})
    code = f"import sys, sim.grasping.names; print([m for m in {heavy!r} if m in sys.modules])"
    found = subprocess.run([sys.executable, "-c", code], capture_output=True, text=True, check=True)
    assert found.stdout.strip() == "[]"
    with pytest.raises(ValueError, match="'kinematic', 'physical'"):
        load("magnetic")


def test_a_backend_is_registered_under_its_own_name(grasp: str) -> None:
    cls = load(grasp)
    assert issubclass(cls, GraspBackend) and cls.name == grasp
    assert f"{cls.__module__}:{cls.__qualname__}" == REGISTRY[grasp]


# The room ---------------------------------------------------------------------------------
def test_the_room_builds_with_the_backend_and_acts(grasp: str) -> None:
    room = Playroom(grasp, seed=0)
    assert type(room.backend) is load(grasp) and room.grasp == grasp
    rng = np.random.default_rng(0)
    for space, dim in (("arm", ARM_DIM), ("voice", VOICE_DIM)):
        feedback = room.act(space, rng.uniform(-1, 1, dim))
        assert feedback.motor_space == space and feedback.s.shape == (SENSORY_DIM,)
        assert np.all(np.isfinite(feedback.s))
        assert feedback.positions.shape == (N_STEPS, len(TRACKED_OBJECTS), 2)
        assert feedback.sound.shape == (N_STEPS, 2)
        assert all(isinstance(e, ev.Event) for e in feedback.events)
        steps = [e.step for e in feedback.events]
        assert steps == sorted(steps)
    assert room.context().shape == (10,)


def _commands(rng: np.random.Generator) -> Iterator[tuple[str, np.ndarray, tuple | None]]:
    """(motor space, command, stick pose to arrange first or None): random arm and voice
    commands, and arm commands that sweep the hand through the handle (grasps)."""
    for k in range(24):
        if k % 3 == 2:
            handle = rng.uniform(-0.3, 0.3, 2)
            angle = float(rng.uniform(-np.pi, np.pi))
            sweep = [Waypoint(15, tuple(handle), angle), Waypoint(50, tuple(0.8 * handle))]
            yield "arm", arm_command_through(sweep)[0], (*handle, angle)
        else:
            space, dim = ("arm", ARM_DIM) if k % 3 == 0 else ("voice", VOICE_DIM)
            yield space, rng.uniform(-1, 1, dim), None


def test_a_movements_trace_shows_what_its_feedback_says(grasp: str) -> None:
    """Frames are drawn from the trace (videos, the viewer, Gymnasium's rgb_array): posed at
    each step, the room's tracked objects are where the feedback says they were; and tracing
    changes nothing of the world."""
    traced, plain = Playroom(grasp, seed=3), Playroom(grasp, seed=3)
    traced.tracing = True
    kinds: set[str] = set()
    for space, m, stick in _commands(np.random.default_rng(3)):
        if stick is not None:
            for room in (traced, plain):
                room.arrange(stick=stick)
        a, b = traced.act(space, m), plain.act(space, m)
        np.testing.assert_array_equal(a.s, b.s)
        assert a.events == b.events
        trace = traced.last_trace
        assert trace is not None and plain.last_trace is None
        for step, posed in trace.replayed(traced.physics):
            np.testing.assert_allclose(posed.tracked_positions(), a.positions[step - 1], atol=1e-12)
        kinds.update(a.kinds())
    np.testing.assert_array_equal(traced.get_state()["physics"], plain.get_state()["physics"])
    assert ev.STICK_GRASPED in kinds  # the comparison covered a grasp


# The trial's record and the reports -----------------------------------------------------------
def test_a_trial_records_what_its_backend_declares(grasp: str, trial: Trial) -> None:
    record = storage.read_json(trial.dir / BACKEND_FILE)
    backend = trial.room.backend
    assert record == backend_record.make_record(grasp, backend.reach(), backend.capabilities())
    config = storage.read_json(trial.dir / CONFIG_FILE)
    assert backend_record.read_record(trial.dir, config) == record
    if grasp in RECORDED_BEFORE:
        # An old trial, read without its record, is read as the backend would record it.
        assert backend_record.recorded_before(config) == record
    if grasp == DOUBLED:
        # Its config.json records the world's grasp distance; its record, the one it used.
        world = config["world"]
        assert record["reach"] == pytest.approx(sum(world["segment_lengths"]) + 0.2)
        assert record["reach"] > backend_record.study_reach(world)


def test_the_stick_reach_figure_draws_the_backend_at_its_recorded_reach(trial: Trial) -> None:
    record = storage.read_json(trial.dir / BACKEND_FILE)
    batch = stick_reach.batch_rates(Path(trial.dir).parent)
    assert set(batch.rates) == {record["grasp"]}
    lines = stick_reach.distance_lines(batch)
    drawn = [(x, label.split(":")[0]) for x, _, style, label in lines if style == "--"]
    assert drawn == [(record["reach"], record["grasp"])]


def test_the_comparison_shows_the_backends_grasp_rate_beside_another(grasp: str) -> None:
    other = next(n for n in (DEFAULT_GRASP, *REGISTRY) if n != grasp)
    # The row reads a side's backend from its trials table only.
    sides = [SimpleNamespace(trials=pd.DataFrame({"grasp": [g]})) for g in (grasp, other)]
    measures = RoomMeasures(study_numbers=lambda results: {}, grasp_rates=grasp_rates)
    rows = _grasp_rate_row(sides[0], sides[1], 3, measures)  # type: ignore[arg-type]
    assert len(rows) == 1 and rows[0][1].endswith("of 3") and rows[0][2].endswith("of 3")
    # Beside itself a backend has no row: both sides would show the same share.
    assert _grasp_rate_row(sides[0], sides[0], 3, measures) == []  # type: ignore[arg-type]
