"""One iteration of the study: a context in, one arm or voice command, 60D feedback out."""

from __future__ import annotations

from collections.abc import Callable
from dataclasses import dataclass, field

import mujoco
import numpy as np
from dm_control.rl import control

from sim import events as ev
from sim.caregiver import Caregiver
from sim.config import ARM_DIM, CONTEXT_DIM, DEFAULT_WORLD, SENSORY_DIM, VOICE_DIM, WorldConfig
from sim.dmp import arm_trajectory, voice_trajectory
from sim.grasp import BACKENDS, make_backend
from sim.physics import CONTROL_SUBSTEPS, TOYS, KinematicPhysics, PlayroomPhysics
from sim.task import ARM, N_ARTICULATORS, N_JOINTS, VOICE, PlayroomTask
from sim.vocal.tract import VocalTract
from sim.vocal.words import WordAssignment, assign_words, word_features

# An object counts as moved once it is this far from where it started (m). Contacts of
# resting objects jitter by far less.
MOVE_TOLERANCE = 1e-3
# Commands may exceed [-1, 1] by this much (float round-off) before they are refused.
RANGE_TOLERANCE = 1e-9
# Rows of the recorded trajectory: the 5 tracked objects of the sensory space.
TRACKED = ("hand", "stick", *TOYS)
# Toys placed in the physical backend keep this clearance from each other and the stick (m):
# two solid toys cannot share a place, and overlapping geoms would be pushed apart violently.
PLACEMENT_CLEARANCE = 0.01


@dataclass
class Feedback:
    """What the agent perceives of one movement.

    s: (60,) hand, stick handle, toy1, toy2, toy3 (each 5 x then 5 y at the sample steps) and
    sound (5 normalised log2 F1 then 5 log2 F2).
    events: what happened, in step order.
    positions: (50, 5, 2) the tracked objects after every control step.
    sound: (50, 2) the sound sensor after every control step.
    """

    motor_space: str
    s: np.ndarray
    events: list[ev.Event] = field(default_factory=list)
    positions: np.ndarray | None = None
    sound: np.ndarray | None = None

    def kinds(self) -> list[str]:
        return [e.kind for e in self.events]


class Playroom:
    """The playroom world the learner talks to, built on the dm_control task.

    grasp: 'kinematic' (the study's distance rules) or 'physical' (MuJoCo contacts).
    seed: seeds every random choice of the world (placements, the caregiver's words).
    exact_voice: formants through VocalTractLab's area function and the tube model (about 5 ms
    a frame) instead of the fitted formant map (microseconds); for audio checks.
    """

    def __init__(
        self,
        grasp: str = "physical",
        seed: int = 0,
        config: WorldConfig = DEFAULT_WORLD,
        exact_voice: bool = False,
    ) -> None:
        if grasp not in BACKENDS:
            raise ValueError(f"unknown grasp backend {grasp!r}: choose one of {sorted(BACKENDS)}")
        if isinstance(seed, bool) or not isinstance(seed, int | np.integer) or seed < 0:
            raise ValueError(f"seed must be a non-negative integer, got {seed!r}")
        self.grasp = grasp
        self.seed = int(seed)
        self.config = config
        self.rng = np.random.default_rng(self.seed)
        self.vocal_tract = VocalTract(exact=exact_voice)
        self.words = assign_words(self.rng, self.vocal_tract.config)
        physics_class = KinematicPhysics if grasp == "kinematic" else PlayroomPhysics
        self.physics: PlayroomPhysics = physics_class.load()
        self.caregiver = Caregiver(physical=grasp == "physical", config=config)
        self.task = PlayroomTask(make_backend(grasp, config), self.caregiver, self.vocal_tract)
        self.env = control.Environment(
            self.physics, self.task, n_sub_steps=CONTROL_SUBSTEPS, time_limit=float("inf")
        )
        self.env.reset()
        self.iteration = 0
        # Called after every control step with (step, observation): renderers and recorders
        # watch a movement through this without changing it.
        self.step_observers: list[Callable[[int, dict], None]] = []
        self._place_for_iteration()

    # What the agent sees ------------------------------------------------------------------
    def context(self) -> np.ndarray:
        """(10,) stick handle x, y; toy1 x, y; toy2 x, y; toy3 x, y; caregiver x, y."""
        p = self.physics
        return np.concatenate([p.stick_handle(), p.toy_positions().ravel(), p.caregiver_position()])

    # What the agent does ------------------------------------------------------------------
    def act_arm(self, m: np.ndarray) -> Feedback:
        """Execute 21 arm parameters in [-1, 1] (protocol.md) and return the feedback.

        Afterwards the caregiver says the name of the toy in the hand, or else a random
        distractor: her word is the sound block s[50:60].
        """
        m = _checked_command(m, ARM_DIM, "arm command")
        actions = np.zeros((self.config.n_steps, N_JOINTS + N_ARTICULATORS))
        actions[:, :N_JOINTS] = arm_trajectory(m, self.config).T
        return self._run(ARM, actions)

    def act_voice(self, m: np.ndarray) -> Feedback:
        """Execute 28 vocal parameters in [-1, 1] (protocol.md) and return the feedback.

        The sound block s[50:60] is the agent's own sound. If the caregiver recognises a toy's
        name in it, she brings that toy toward the midpoint between her and the arm's base
        during the same 50 steps, as in the study.
        """
        m = _checked_command(m, VOICE_DIM, "voice command")
        articulators = voice_trajectory(m, self.config)  # (7, n_steps)
        actions = np.zeros((self.config.n_steps, N_JOINTS + N_ARTICULATORS))
        actions[:, N_JOINTS:] = articulators.T
        fallbacks = self.vocal_tract.n_fallbacks
        formants = self.vocal_tract.trajectory_formants(articulators)
        feedback = self._run(VOICE, actions, formants)
        if self.vocal_tract.n_fallbacks > fallbacks:  # the exact path found no formant
            feedback.events.append(ev.Event(ev.FORMANT_FALLBACK, 0))
        return feedback

    def _hear(self, voice_formants: np.ndarray) -> list[ev.Event]:
        """The caregiver listens to the coming sound, (n_steps, 2) log2 Hz; she fetches the toy
        it names."""
        word = self.vocal_tract.recognise(self.vocal_tract.features_from_formants(voice_formants))
        if word is None:
            return []
        toy = self.words.toy_of(word)
        if toy is not None:
            self.caregiver.start_bringing(self.physics, toy)
        return [ev.Event(ev.WORD_RECOGNISED, 1, obj=None if toy is None else TOYS[toy], word=word)]

    def _speak(self) -> tuple[np.ndarray, ev.Event]:
        """After an arm movement: the name of the toy in the hand, else a random distractor."""
        held = self.task.grasp.hand_holds
        if held in TOYS:
            word, obj = self.words.names[TOYS.index(held)], held
        else:
            word, obj = self.words.distractors[self.rng.integers(len(self.words.distractors))], None
        features = word_features(word, config=self.vocal_tract.config)
        return features, ev.Event(ev.CAREGIVER_SAID, self.config.n_steps, obj=obj, word=word)

    def arrange(
        self,
        stick: tuple[float, float, float] | None = None,
        toys: np.ndarray | None = None,
        caregiver: tuple[float, float] | None = None,
    ) -> None:
        """Put objects at chosen places, for scripted scenes.

        stick: handle x, y (m) and angle (rad); toys: (3, 2) positions (m); caregiver: x, y (m).
        Whatever is None stays where it is. The random placements go on as before afterwards.
        """
        checked = {
            name: _checked_array(value, shape, name)
            for name, value, shape in (
                ("stick", stick, (3,)),
                ("toys", toys, (len(TOYS), 2)),
                ("caregiver", caregiver, (2,)),
            )
            if value is not None
        }
        p = self.physics
        poses = p.object_poses()
        if "stick" in checked:
            poses[0] = checked["stick"]
        if "toys" in checked:
            poses[1:, :2] = checked["toys"]
        p.set_object_poses(poses)
        if "caregiver" in checked:
            d = p.data.ptr
            d.mocap_pos[[p.caregiver_mocap, p.caregiver_hand_mocap], :2] = checked["caregiver"]
        mujoco.mj_forward(p.model.ptr, p.data.ptr)

    # Checkpoints --------------------------------------------------------------------------
    def get_state(self) -> dict:
        """Everything that decides what happens next, as plain values and arrays."""
        m, d = self.physics.model.ptr, self.physics.data.ptr
        spec = mujoco.mjtState.mjSTATE_INTEGRATION
        physics_state = np.empty(mujoco.mj_stateSize(m, spec))
        mujoco.mj_getState(m, d, physics_state, spec)
        return {
            "grasp": self.grasp,
            "seed": self.seed,
            "iteration": self.iteration,
            "physics": physics_state,
            "rng": self.rng.bit_generator.state,
            "words": [list(self.words.names), list(self.words.distractors)],
        }

    def set_state(self, state: dict) -> None:
        """Restore a state from `get_state` of a room with the same grasp backend."""
        if state["grasp"] != self.grasp:
            raise ValueError(f"state is of a {state['grasp']!r} room, this room is {self.grasp!r}")
        m, d = self.physics.model.ptr, self.physics.data.ptr
        mujoco.mj_setState(m, d, np.asarray(state["physics"]), mujoco.mjtState.mjSTATE_INTEGRATION)
        mujoco.mj_forward(m, d)
        self.iteration = int(state["iteration"])
        self.rng.bit_generator.state = state["rng"]
        names, distractors = state["words"]
        self.words = WordAssignment(tuple(names), tuple(distractors))

    # The movement -------------------------------------------------------------------------
    def _run(
        self, movement: str, actions: np.ndarray, voice_formants: np.ndarray | None = None
    ) -> Feedback:
        p = self.physics
        saved = self.get_state()
        n = self.config.n_steps
        positions = np.empty((n + 1, len(TRACKED), 2))
        sound = np.zeros((n, 2))
        positions[0] = p.tracked_positions()
        self.task.begin_movement(p, movement, voice_formants)
        events = self._hear(voice_formants) if movement == VOICE else []
        try:
            for k in range(n):
                obs = self.env.step(actions[k]).observation
                positions[k + 1, 0] = obs["hand"]
                positions[k + 1, 1] = obs["stick_handle"]
                positions[k + 1, 2:] = obs["toys"]
                sound[k] = obs["sound"]
                events += self.task.step_events
                for observer in self.step_observers:
                    observer(k + 1, obs)
            if not np.isfinite(positions).all():
                raise control.PhysicsError("non-finite positions")
        except control.PhysicsError:
            # Divergence: put everything back where it was and report it; the room goes on.
            self.task.end_movement(p)
            self.set_state(saved)
            positions[1:] = positions[0]
            events = [ev.Event(ev.DIVERGED, 0)]
            said = None
        else:
            brought = self.caregiver.bringing
            events += _movement_events(
                positions, events, None if brought is None else TOYS[brought]
            )
            said = self._speak() if movement == ARM else None
            self.task.end_movement(p)
        s = self._sensory(positions[1:], sound)
        if said is not None:
            s[50:], event = said
            events.append(event)
        self.iteration += 1
        self._place_for_iteration()
        return Feedback(movement, s, events, positions[1:], sound)

    def _sensory(self, positions: np.ndarray, sound: np.ndarray) -> np.ndarray:
        """(60,) from (50, 5, 2) positions and (50, 2) sound, sampled at the 5 steps."""
        idx = list(self.config.sample_indices)
        objects = positions[idx].transpose(1, 2, 0).reshape(len(TRACKED), 10)  # 5 x then 5 y
        s = np.empty(SENSORY_DIM)
        s[:50] = objects.ravel()
        s[50:] = sound[idx].T.ravel()
        return s

    # Placements ---------------------------------------------------------------------------
    def _place_for_iteration(self) -> None:
        """The caregiver moves every iteration; the toys every `toy_replace_period`."""
        if self.iteration % self.config.toy_replace_period == 0:
            self._place_toys()
        self.caregiver.place(self.physics, self.rng)
        mujoco.mj_forward(self.physics.model.ptr, self.physics.data.ptr)

    def _place_toys(self) -> None:
        """Each toy picks one of the 3 rings with equal chance and a uniform angle."""
        p = self.physics
        poses = p.object_poses()
        for i in range(len(TOYS)):
            while True:
                position = self._random_ring_position()
                if self.grasp == "kinematic" or self._clear_of_others(position, poses, i):
                    break
            poses[1 + i] = (*position, 0.0)
        p.set_object_poses(poses)

    def _random_ring_position(self) -> np.ndarray:
        rings = self.config.toy_rings
        low, high = rings[self.rng.integers(len(rings))]
        radius = self.rng.uniform(low, high)
        angle = self.rng.uniform(0.0, 2.0 * np.pi)
        return radius * np.array([np.cos(angle), np.sin(angle)])

    def _clear_of_others(self, position: np.ndarray, poses: np.ndarray, toy: int) -> bool:
        """Whether a toy at `position` would keep clear of the toys placed before it and the
        stick."""
        p = self.physics
        m = p.model.ptr
        toy_radius = m.geom_size[p.toy_geoms[0], 0]
        # The thickest part of the stick (its tip sphere), measured from the handle-tip line.
        stick_radius = m.geom_size[p.stick_geoms, 0].max()
        for j in range(toy):
            if np.linalg.norm(position - poses[1 + j, :2]) < 2 * toy_radius + PLACEMENT_CLEARANCE:
                return False
        handle, tip = p.stick_handle(), p.stick_tip()
        return _segment_distance(position, handle, tip) >= (
            toy_radius + stick_radius + PLACEMENT_CLEARANCE
        )


def _segment_distance(point: np.ndarray, a: np.ndarray, b: np.ndarray) -> float:
    ab = b - a
    t = np.clip(np.dot(point - a, ab) / np.dot(ab, ab), 0.0, 1.0)
    return float(np.linalg.norm(point - (a + t * ab)))


def _movement_events(
    positions: np.ndarray, step_events: list[ev.Event], brought: str | None
) -> list[ev.Event]:
    """Which objects moved, when first, and by what, from (51, 5, 2) positions (row 0 = start)."""
    grasped = {e.obj for e in step_events if e.kind in (ev.TOY_GRASPED, ev.STICK_GRASPED)}
    caught = {e.obj for e in step_events if e.kind == ev.TOY_CAUGHT}
    moved: list[ev.Event] = []
    displacement = np.linalg.norm(positions - positions[0], axis=2)  # (51, 5)
    for row, name in enumerate(TRACKED[1:], start=1):
        steps = np.flatnonzero(displacement[:, row] > MOVE_TOLERANCE)
        if steps.size == 0:
            continue
        if name == "stick":
            by = "hand" if "stick" in grasped else "push"
            moved.append(ev.Event(ev.STICK_MOVED, int(steps[0]), obj="stick", by=by))
            continue
        if name == brought:
            by = "caregiver"
        else:
            by = "hand" if name in grasped else "stick" if name in caught else "push"
        moved.append(ev.Event(ev.TOY_MOVED, int(steps[0]), obj=name, by=by))
    return moved


def _checked_array(value, shape: tuple[int, ...], what: str) -> np.ndarray:
    """`value` as a finite float array of `shape`, or ValueError naming what is wrong."""
    try:
        arr = np.asarray(value, dtype=float)
    except (TypeError, ValueError) as exc:
        raise ValueError(f"{what} must be numbers: {exc}") from None
    if arr.shape != shape:
        raise ValueError(f"{what} must have shape {shape}, got {arr.shape}")
    if not np.isfinite(arr).all():
        bad = np.flatnonzero(~np.isfinite(arr.ravel()))
        raise ValueError(f"{what} contains NaN or inf at flat indices {bad.tolist()}")
    return arr


def _checked_command(m, dim: int, what: str) -> np.ndarray:
    """The command as a float array of shape (dim,) in [-1, 1], or ValueError naming what is
    wrong."""
    arr = _checked_array(m, (dim,), what)
    if np.abs(arr).max() > 1.0 + RANGE_TOLERANCE:
        raise ValueError(f"{what} must lie in [-1, 1], max |value| is {np.abs(arr).max():.6g}")
    return np.clip(arr, -1.0, 1.0)


__all__ = ["CONTEXT_DIM", "Feedback", "Playroom"]
