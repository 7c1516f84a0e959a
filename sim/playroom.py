"""One iteration of the study: a context in, one arm or voice command, 60D feedback out."""

from __future__ import annotations

import numpy as np

from models.layout import (
    ARM_DIM,
    N_STEPS,
    TOYS,
    VOICE_DIM,
    block_slice,
)
from models.presets import DEFAULT_PRESET
from models.world import Feedback
from sim import events as ev
from sim.caregiver import Caregiver, WordAssignment
from sim.commands import checked_array, checked_command
from sim.config import WorldConfig, world_preset
from sim.dmp import arm_trajectory, voice_trajectory
from sim.experimenter import Experimenter
from sim.grasping.base import GraspBackend
from sim.grasping.names import DEFAULT_GRASP
from sim.grasping.registry import load as backend_class
from sim.model_edits import ModelEdits
from sim.movement import ARM, VOICE, Movement, MovementOutcome, MovementTrace
from sim.mujoco_import import mujoco
from sim.physics import PlayroomPhysics
from sim.sensory import SAMPLE_STEPS, sensory_from
from sim.task import PlayroomTask
from sim.vocal.config import DEFAULT_VOICE, VoiceConfig
from sim.vocal.registry import make_tract

_SOUND = block_slice("sound")  # where her word goes in s


class Playroom:
    """The playroom world the learner talks to, built on the dm_control task.

    grasp: a backend of sim/grasping/: 'kinematic' (the study's distance rules, the default)
    or 'physical' (MuJoCo contacts).
    seed: seeds every random choice of the world (placements, the caregiver's words).
    config, voice: the world's and the voice's numbers (config: the default preset's world,
    `world_preset(DEFAULT_PRESET)`, when None); the MJCF model is checked against `config`
    when it loads. The vocal tract is the one `config.voice` names (sim/vocal/registry.py).
    exact_voice: formants through VocalTractLab's area function and the tube model (about 5 ms
    a frame) instead of the fitted formant map (microseconds); for audio checks.

    `task` and `physics` are the dm_control Task and Physics. Each movement is computed whole
    by the backend (`GraspBackend.simulate`); with `tracing` on, `last_trace` is where
    everything was after each of its control steps (sim/movement.py), from which videos, the
    viewer and Gymnasium's frames are drawn. A room has no episodes: environments with
    `reset`, one command a step, are in sim/envs/.
    """

    def __init__(
        self,
        grasp: str = DEFAULT_GRASP,
        seed: int = 0,
        config: WorldConfig | None = None,
        voice: VoiceConfig = DEFAULT_VOICE,
        exact_voice: bool = False,
    ) -> None:
        backend = backend_class(grasp)  # ValueError naming the backends
        if isinstance(seed, bool) or not isinstance(seed, int | np.integer) or seed < 0:
            raise ValueError(f"seed must be a non-negative integer, got {seed!r}")
        config = world_preset(DEFAULT_PRESET) if config is None else config
        self.grasp = grasp
        self.seed = int(seed)
        self.config = config
        self.rng = np.random.default_rng(self.seed)
        self.vocal_tract = make_tract(config.voice, exact_voice, voice, config)
        self.physics: PlayroomPhysics = backend.physics_class.load(config)
        self.backend = compose_backend(backend, config, self.physics)
        self.caregiver = Caregiver(self.backend.carrying, config, self.vocal_tract, self.rng)
        self.task = PlayroomTask(self.vocal_tract)
        self.experimenter = Experimenter(config, self.physics, self.backend)
        with self.physics.reset_context():  # as dm_control's Environment.reset starts one
            self.task.initialize_episode(self.physics)
        self.iteration = 0
        # Whether each movement keeps its trace (`last_trace`): videos and frames read it.
        self.tracing = False
        self.last_trace: MovementTrace | None = None
        self._place_for_iteration()

    # What the agent sees ------------------------------------------------------------------
    def context(self) -> np.ndarray:
        """(10,) stick handle x, y; toy1 x, y; toy2 x, y; toy3 x, y; caregiver x, y."""
        return self.physics.context_positions()

    # What the agent does ------------------------------------------------------------------
    def act(self, motor_space: str, m: np.ndarray) -> Feedback:
        """Execute command m in `motor_space` ('arm' or 'voice'): the `World` interface
        (models/world.py) through which every caller acts."""
        if motor_space == ARM:
            return self.act_arm(m)
        if motor_space == VOICE:
            return self.act_voice(m)
        raise ValueError(f"unknown motor space {motor_space!r}: 'arm' or 'voice'")

    def act_arm(self, m: np.ndarray) -> Feedback:
        """Execute 21 arm parameters in [-1, 1] (docs/protocol.md §2) and return the feedback.

        Afterwards the caregiver says the name of the toy in the hand, or else a random
        distractor: her word is the sound block s[50:60].
        """
        m = checked_command(m, ARM_DIM, "arm command")
        targets = arm_trajectory(m, self.config)  # (3, N_STEPS)
        return self._movement(ARM, targets.T, np.zeros((N_STEPS, 2)))

    def act_voice(self, m: np.ndarray) -> Feedback:
        """Execute 28 vocal parameters in [-1, 1] (docs/protocol.md §2) and return the feedback.

        The sound block s[50:60] is the agent's own sound. If the caregiver recognises a toy's
        name in it, she brings that toy toward the midpoint between her and the arm's base
        during the same 50 steps, as in the study.
        """
        m = checked_command(m, VOICE_DIM, "voice command")
        articulators = voice_trajectory(m, self.config)  # (7, n_steps)
        fallbacks = self.vocal_tract.n_fallbacks
        # The trajectory is finite and clipped to [-1, 1]: the tract's input checks
        # (trajectory_formants) would only repeat that.
        frames = articulators.T
        # Unobserved, the sound is no step's input (it is not physical): only what the learner
        # and the caregiver hear, the 5 sample steps, is computed now, the other steps when the
        # feedback's `sound` is read.
        at_samples = self.vocal_tract.frame_formants_at(frames, SAMPLE_STEPS)
        if at_samples is not None:  # (None: the tract computes every step anyway)
            formants = np.empty((N_STEPS, 2))
            formants.fill(np.nan)  # np.full's array, without its Python wrapper
            formants[SAMPLE_STEPS] = at_samples
            feedback = self._movement(VOICE, frames, formants)
            feedback.sound = lambda: self.task.normalised(self.vocal_tract.frame_formants(frames))
            return feedback
        feedback = self._movement(VOICE, frames, self.vocal_tract.frame_formants(frames))
        if self.vocal_tract.n_fallbacks > fallbacks:  # the exact path found no formant
            feedback.events.append(ev.Event(ev.FORMANT_FALLBACK, 0))
        return feedback

    @property
    def words(self) -> WordAssignment:
        """The caregiver's words of this room: which names which toy."""
        return self.caregiver.words

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
            name: checked_array(value, shape, name)
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
        return {
            "grasp": self.grasp,
            "seed": self.seed,
            "iteration": self.iteration,
            "physics": self.physics.integration_state(),
            "rng": self.rng.bit_generator.state,
            "words": [list(self.words.names), list(self.words.distractors)],
        }

    def set_state(self, state: dict) -> None:
        """Restore a state from `get_state` of a room with the same grasp backend."""
        if state["grasp"] != self.grasp:
            raise ValueError(f"state is of a {state['grasp']!r} room, this room is {self.grasp!r}")
        self.physics.restore_integration_state(np.asarray(state["physics"]))
        self.iteration = int(state["iteration"])
        self.rng.bit_generator.state = state["rng"]
        names, distractors = state["words"]
        self.caregiver.words = WordAssignment(tuple(names), tuple(distractors))

    def _movement(self, movement: str, controls: np.ndarray, formants: np.ndarray) -> Feedback:
        """One movement of `controls` (N_STEPS, 3) joint targets or (N_STEPS, 7) articulators;
        formants: (N_STEPS, 2) log2 Hz of a vocal one (NaN where not computed), zeros for the
        arm. The caregiver hears the agent, the backend computes the movement, and `_finish`
        ends it."""
        p = self.physics
        start = p.tracked_positions()
        voice = movement == VOICE
        self.backend.begin(p)
        heard = self.caregiver.hear(p, formants) if voice else []
        sound = self.task.normalised(formants) if voice else formants
        asked = Movement(movement, controls, start, sound, self.caregiver.brought)
        trace = MovementTrace.starting_at(p.data.ptr) if self.tracing else None
        outcome = self.backend.simulate(p, asked, trace)
        self.last_trace = trace
        return self._finish(movement, outcome, heard)

    def _finish(self, movement: str, outcome: MovementOutcome, heard: list[ev.Event]) -> Feedback:
        """What follows every movement, whatever path computed it: which objects moved and by
        what, the caregiver's word after an arm movement, then everything put down (a diverged
        movement: the room put back as it was before it)."""
        p = self.physics
        if outcome.diverged_from is not None:
            self._end_movement()
            p.restore_integration_state(outcome.diverged_from)
            diverged = [ev.Event(ev.DIVERGED, 0)]
            return self._feedback(movement, outcome.positions, outcome.sound, diverged, None)
        events = heard + outcome.events
        brought = self.caregiver.bringing
        if not outcome.still:  # (movement_events finds nothing in still positions)
            brought_name = None if brought is None else TOYS[brought]
            events += ev.movement_events(outcome.positions, events, brought_name)
        said = self.caregiver.speak(outcome.holds, self.rng) if movement == ARM else None
        self._end_movement()
        return self._feedback(movement, outcome.positions, outcome.sound, events, said)

    def _end_movement(self) -> None:
        """Everything dropped where it is, the arm back at rest, the toy she carried put down,
        and (where the world says so) the room left to settle."""
        p = self.physics
        self.backend.release(p)
        self.caregiver.stop(p)
        self.backend.settle(p)

    def _feedback(
        self,
        movement: str,
        positions: np.ndarray,
        sound: np.ndarray,
        events: list[ev.Event],
        said: tuple[np.ndarray, ev.Event] | None,
    ) -> Feedback:
        """The movement's feedback from (N_STEPS + 1, 5, 2) positions (row 0: the start) and
        (N_STEPS, 2) sound; then the room moves on to the next iteration."""
        s = sensory_from(positions[1:], sound)
        if said is not None:
            s[_SOUND], event = said
            events.append(event)
        self.iteration += 1
        events += self._place_for_iteration()
        return Feedback(movement, s, events, positions[1:], sound)

    # Placements ---------------------------------------------------------------------------
    def _place_for_iteration(self) -> list[ev.Event]:
        """Between iterations: the experimenter returns a lost stick (if the config says so)
        and places the toys every `toy_replace_period`; the caregiver moves every iteration.
        Returns what the experimenter did."""
        events = self.experimenter.return_stick_if_lost()
        if self.iteration % self.config.toy_replace_period == 0:
            self.experimenter.place_toys(self.rng)
        self.caregiver.place(self.physics, self.rng)
        self.backend.after_placements(self.physics)
        return events

    @property
    def min_toy_gap(self) -> float:
        """Distance (m) between the centres of two toys placed side by side."""
        return self.experimenter.min_toy_gap


__all__ = ["Feedback", "Playroom"]


def compose_backend(
    backend: type[GraspBackend], config: WorldConfig, physics: PlayroomPhysics
) -> GraspBackend:
    """A backend of the room, made of the parts it declares (sim/grasping/base.py), built here
    on the room's physics (loaded as the backend's `physics_class`): the caregiver's carrying,
    and the grasp rule where it is a part of its own; all edit the model through one
    ModelEdits."""
    edits = ModelEdits(physics)
    carrying = backend.carrying_for(config)(edits)
    rule = None if backend.rule_class is None else backend.rule_class(config, edits, backend.name)
    return backend(config, edits, carrying, rule)
