"""One iteration of the study: a context in, one arm or voice command, 60D feedback out."""

from __future__ import annotations

from collections.abc import Callable
from typing import cast

import mujoco
import numpy as np

from models.layout import (
    ARM_DIM,
    N_ARTICULATORS,
    N_JOINTS,
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
from sim.grasping.base import ClosedForm
from sim.grasping.names import DEFAULT_GRASP
from sim.grasping.registry import load as backend_class
from sim.model_edits import ModelEdits
from sim.movement import MovementOutcome, closed_form_movement, stepped_movement
from sim.physics import CONTROL_SUBSTEPS, PlayroomPhysics
from sim.sensory import SAMPLE_STEPS, sensory_from
from sim.task import ARM, VOICE, MovementStepper, PlayroomTask
from sim.vocal.config import DEFAULT_VOICE, VoiceConfig
from sim.vocal.registry import make_tract

_SOUND = block_slice("sound")  # where her word goes in s
_PHYSICS_STATE = mujoco.mjtState.mjSTATE_INTEGRATION  # what get_state keeps of MuJoCo


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

    `task` and `physics` are the dm_control Task and Physics; `env` is the room's internal
    stepping (sim.task.MovementStepper), which acts only inside a movement `act` began and is
    never reset after the room is built. A room has no episodes: environments with `reset`,
    one command a step, are in sim/envs/.
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
        self.backend = backend(config, ModelEdits(self.physics))
        self._has_closed_form = isinstance(self.backend, ClosedForm)  # (an ABC check: 0.3 us)
        self.caregiver = Caregiver(self.backend, config, self.vocal_tract, self.rng)
        self.task = PlayroomTask(self.backend, self.caregiver, self.vocal_tract)
        # Internal stepping for observed movements (videos), reset once here: see its docstring.
        self.env = MovementStepper(self.physics, self.task, CONTROL_SUBSTEPS)
        self.experimenter = Experimenter(config, self.physics, self.backend)
        self.env.reset()
        self.iteration = 0
        # Called after every control step with (step, observation): renderers and recorders
        # watch a movement through this without changing it.
        self.step_observers: list[Callable[[int, dict], None]] = []
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
        at_samples = (
            None
            if self.step_observers
            else self.vocal_tract.frame_formants_at(frames, SAMPLE_STEPS)
        )
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
            "physics": self._physics_state(),
            "rng": self.rng.bit_generator.state,
            "words": [list(self.words.names), list(self.words.distractors)],
        }

    def set_state(self, state: dict) -> None:
        """Restore a state from `get_state` of a room with the same grasp backend."""
        if state["grasp"] != self.grasp:
            raise ValueError(f"state is of a {state['grasp']!r} room, this room is {self.grasp!r}")
        self._restore_physics(np.asarray(state["physics"]))
        self.iteration = int(state["iteration"])
        self.rng.bit_generator.state = state["rng"]
        names, distractors = state["words"]
        self.caregiver.words = WordAssignment(tuple(names), tuple(distractors))

    def _physics_state(self) -> np.ndarray:
        """MuJoCo's integration state (mjSTATE_INTEGRATION) of the room."""
        m, d = self.physics.model.ptr, self.physics.data.ptr
        state = np.empty(mujoco.mj_stateSize(m, _PHYSICS_STATE))
        mujoco.mj_getState(m, d, state, _PHYSICS_STATE)
        return state

    def _restore_physics(self, state: np.ndarray) -> None:
        m, d = self.physics.model.ptr, self.physics.data.ptr
        mujoco.mj_setState(m, d, state, _PHYSICS_STATE)
        mujoco.mj_forward(m, d)

    # The movement -------------------------------------------------------------------------
    def _closed_form(self) -> ClosedForm | None:
        """The backend, if its rules run a whole movement at once (the kinematic one) and no
        one watches each step (a video): the step-by-step path through the dm_control task
        gives the same result."""
        if self._has_closed_form and not self.step_observers:
            return cast(ClosedForm, self.backend)
        return None

    def _movement(self, movement: str, controls: np.ndarray, formants: np.ndarray) -> Feedback:
        """One movement of `controls` (N_STEPS, 3) joint targets or (N_STEPS, 7) articulators;
        formants: (N_STEPS, 2) log2 Hz of a vocal one (NaN where not computed), zeros for the
        arm. The caregiver hears the agent, one of the paths of sim/movement.py computes the
        movement, and `_finish` ends it, whichever path it took."""
        p = self.physics
        closed = self._closed_form()
        saved = None
        if closed is None:
            if self._has_closed_form:  # placed by kinematics alone (see above)
                mujoco.mj_forward(p.model.ptr, p.data.ptr)
            # Only the physics changes during the steps: what a divergence puts back.
            saved = self._physics_state()
        start = p.tracked_positions()
        voice = movement == VOICE
        if closed is None:
            self.task.begin_movement(p, movement, formants if voice else None)
        heard = self.caregiver.hear(p, formants) if voice else []
        if closed is not None:
            sound = self.task.normalised(formants) if voice else formants
            outcome = closed_form_movement(
                closed, p, self.caregiver, movement, controls, start, sound
            )
        else:
            assert saved is not None  # saved above on every stepped path
            actions = np.zeros((N_STEPS, N_JOINTS + N_ARTICULATORS))
            columns = slice(N_JOINTS, None) if voice else slice(N_JOINTS)
            actions[:, columns] = controls
            outcome = stepped_movement(
                p, self.task, self.env, self.step_observers, actions, start, saved
            )
        return self._finish(movement, outcome, heard)

    def _finish(self, movement: str, outcome: MovementOutcome, heard: list[ev.Event]) -> Feedback:
        """What follows every movement, whatever path computed it: which objects moved and by
        what, the caregiver's word after an arm movement, then everything put down (a diverged
        movement: the room put back as it was before it)."""
        p = self.physics
        if outcome.diverged_from is not None:
            self.task.end_movement(p)
            self._restore_physics(outcome.diverged_from)
            diverged = [ev.Event(ev.DIVERGED, 0)]
            return self._feedback(movement, outcome.positions, outcome.sound, diverged, None)
        events = heard + outcome.events
        brought = self.caregiver.bringing
        if not outcome.still:  # (movement_events finds nothing in still positions)
            brought_name = None if brought is None else TOYS[brought]
            events += ev.movement_events(outcome.positions, events, brought_name)
        said = self.caregiver.speak(outcome.holds, self.rng) if movement == ARM else None
        self.task.end_movement(p)
        return self._feedback(movement, outcome.positions, outcome.sound, events, said)

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
        m, d = self.physics.model.ptr, self.physics.data.ptr
        if self._has_closed_form:
            # Positions are all the closed form reads: the full mj_forward (contacts,
            # constraints, forces: 5 times the cost) runs when a stepped movement begins.
            mujoco.mj_kinematics(m, d)
        else:
            mujoco.mj_forward(m, d)
        return events

    @property
    def min_toy_gap(self) -> float:
        """Distance (m) between the centres of two toys placed side by side."""
        return self.experimenter.min_toy_gap


__all__ = ["Feedback", "Playroom"]
