"""The playroom as a Gymnasium environment (`PlayroomGymEnv`, its docstring says everything a user
needs), registered by `import sim.envs` under the ids of sim/envs/versions.py: the dm_env
environment of sim/envs/dm_env_movement.py, with flat Box spaces for the libraries that need
them, and frames of the room (sim/envs/rendering.py).
"""

from __future__ import annotations

from typing import Any

import gymnasium
import numpy as np
from gymnasium import logger, spaces

from models.layout import ARM_DIM, VOICE_DIM
from sim import events as ev
from sim.config import WorldConfig
from sim.envs.actions import checked_numbers
from sim.envs.dm_env_movement import PlayroomMovementEnv
from sim.envs.rendering import (
    DEFAULT_SIZE,
    MovementEnd,
    OffscreenRenderer,
    RenderError,
    Viewer,
    checked_view,
    display_missing,
)
from sim.envs.versions import STUDY_ITERATIONS
from sim.envs.world import SEED_BOUND, checked_seed, event_dicts
from sim.grasping.names import DEFAULT_GRASP
from sim.movement import posed_as
from sim.mujoco_import import mujoco
from sim.physics import CONTROL_SUBSTEPS
from sim.task import ARM, VOICE
from sim.vocal.config import DEFAULT_VOICE, VoiceConfig

# Where each part of the flat action lies.
SELECTOR = 0
ARM_PART = slice(1, 1 + ARM_DIM)
VOICE_PART = slice(ARM_PART.stop, ARM_PART.stop + VOICE_DIM)
ACTION_DIM = VOICE_PART.stop  # 50
# What the spaces hold: what learning libraries expect (stable-baselines3 warns of float64).
# The room computes in float64; actions are read into float64, observations rounded at the end.
SPACE_DTYPE = np.float32
RENDER_MODES = ("human", "rgb_array", "rgb_array_list")
# "rgb_array_list" (Gymnasium's name): every frame since the last render, one after a reset and
# one after each control step of a movement.
FRAME_LIST = "rgb_array_list"


class PlayroomGymEnv(gymnasium.Env[np.ndarray, np.ndarray]):
    """## Description

    The playroom of the study (docs/protocol.md): a planar 3-joint arm on a table with a stick,
    three toys and a caregiver, and a vocal tract. One step is one of the study's iterations:
    one arm command (a DMP of 50 control steps of 20 ms, a second of the room) or one voice
    command, never both. Between steps the room places the toys and moves the caregiver as the
    study's experimenter did (`Playroom.act`). The caregiver names the toy in the hand after an
    arm movement, and brings a toy whose name she recognises in the agent's sound.

    ## Action Space

    Box(-1, 1, (50,), float32). `a[0]` chooses the motor space; the command not chosen moves
    nothing but is checked as the chosen one is (real, finite, within [-1, 1]).

    | Num   | Action                                                       | Min | Max |
    |-------|--------------------------------------------------------------|-----|-----|
    | 0     | motor space: the arm if below 0, else the voice              | -1  | 1   |
    | 1-6   | shoulder: DMP weights 1 to 6 (x dmp_weight_scale, 300)      | -1  | 1   |
    | 7     | shoulder: end angle (x pi rad from rest)                     | -1  | 1   |
    | 8-13  | elbow: DMP weights 1 to 6                                    | -1  | 1   |
    | 14    | elbow: end angle                                             | -1  | 1   |
    | 15-20 | wrist: DMP weights 1 to 6                                    | -1  | 1   |
    | 21    | wrist: end angle                                             | -1  | 1   |
    | 22-25 | articulator 1: start, end, DMP weights 1 and 2               | -1  | 1   |
    | 26-29 | articulator 2: start, end, DMP weights 1 and 2               | -1  | 1   |
    | 30-33 | articulator 3: start, end, DMP weights 1 and 2               | -1  | 1   |
    | 34-37 | articulator 4: start, end, DMP weights 1 and 2               | -1  | 1   |
    | 38-41 | articulator 5: start, end, DMP weights 1 and 2               | -1  | 1   |
    | 42-45 | articulator 6: start, end, DMP weights 1 and 2               | -1  | 1   |
    | 46-49 | articulator 7: start, end, DMP weights 1 and 2               | -1  | 1   |

    ## Observation Space

    Box((70,), float32): the context of the next command (0-9, where things lie before it), then
    the last movement's feedback (10-69; zeros after `reset`), each block 5 samples after
    control steps 1, 13, 25, 38 and 50, in that order. Positions are in m, within the table's
    half-size (1.3); sounds are log2 Hz less an offset (F1 - 8.5, F2 - 10.25), within 4: the
    agent's own after a voice command, the caregiver's word after an arm command.

    | Num   | Observation                                            | Min  | Max |
    |-------|--------------------------------------------------------|------|-----|
    | 0     | stick handle x                                         | -1.3 | 1.3 |
    | 1     | stick handle y                                         | -1.3 | 1.3 |
    | 2     | toy1 x                                                 | -1.3 | 1.3 |
    | 3     | toy1 y                                                 | -1.3 | 1.3 |
    | 4     | toy2 x                                                 | -1.3 | 1.3 |
    | 5     | toy2 y                                                 | -1.3 | 1.3 |
    | 6     | toy3 x                                                 | -1.3 | 1.3 |
    | 7     | toy3 y                                                 | -1.3 | 1.3 |
    | 8     | caregiver x                                            | -1.3 | 1.3 |
    | 9     | caregiver y                                            | -1.3 | 1.3 |
    | 10-14 | hand x at the 5 samples                                | -1.3 | 1.3 |
    | 15-19 | hand y at the 5 samples                                | -1.3 | 1.3 |
    | 20-24 | stick handle x at the 5 samples                        | -1.3 | 1.3 |
    | 25-29 | stick handle y at the 5 samples                        | -1.3 | 1.3 |
    | 30-34 | toy1 x at the 5 samples                                | -1.3 | 1.3 |
    | 35-39 | toy1 y at the 5 samples                                | -1.3 | 1.3 |
    | 40-44 | toy2 x at the 5 samples                                | -1.3 | 1.3 |
    | 45-49 | toy2 y at the 5 samples                                | -1.3 | 1.3 |
    | 50-54 | toy3 x at the 5 samples                                | -1.3 | 1.3 |
    | 55-59 | toy3 y at the 5 samples                                | -1.3 | 1.3 |
    | 60-64 | sound F1 at the 5 samples                              | -4   | 4   |
    | 65-69 | sound F2 at the 5 samples                              | -4   | 4   |

    `info` holds the movement's `motor_space` ("arm" or "voice"), its `events` (dicts: kind,
    step, obj, by, word), `event_counts` (one per `sim.envs.world.EVENT_KINDS`), the room's
    `iteration` and the episode's `seed`.

    ## Rewards

    0.0 at every step: the study's agent sets its own goals (Model Babbling).

    ## Starting State

    `reset(seed=s)` builds the room of seed s, the world of `playroom run --seed s`; `reset()`
    one of a seed drawn from `np_random` (`info["seed"]` says which).

    ## Episode End

    Never terminated. An episode is one of the study's runs, 80000 commands: the registered
    ids declare it as `max_episode_steps` and Gymnasium's TimeLimit truncates it there
    (`gymnasium.make(id, max_episode_steps=N)` shortens it). Made directly, the environment
    truncates itself after `iterations` commands, then `step` wants a `reset`.

    ## Arguments

    | Argument      | Default      | What                                                    |
    |---------------|--------------|---------------------------------------------------------|
    | `grasp`       | "kinematic"  | the grasp backend: "kinematic" or "physical"            |
    | `preset`      | "study"      | the world: "study" or "project" (or a whole `config`)   |
    | `config`      | None         | a `WorldConfig`, instead of a preset                    |
    | `voice`       | None ("vtl") | the vocal tract: "vtl" or "diva" (DIVA's data: below)   |
    | `voice_config`| VoiceConfig()| the voice's numbers (vowels, words, recognition)        |
    | `iterations`  | 80000        | commands per episode, made directly (not with `make`)   |
    | `render_mode` | None         | "rgb_array", "rgb_array_list" or "human" (a display)    |
    | `render_size` | (640, 480)   | (width, height) of an "rgb_array" frame                 |
    | `camera`      | "top"        | the MJCF's camera: "top" or "hand_view"                 |

    DIVA's formant map is the user's: `playroom voice-data diva PATH` installs it once; without
    it "diva" raises DivaDataMissing, which names the file and the command.

    Rendering (sim/envs/rendering.py): under "rgb_array" a frame after `step` shows the room at
    the movement's last control step, before the arm returns to rest and the room places things
    for the next command (RecordVideo, one frame a step at `render_fps` 1, a movement a second,
    shows where each movement ended); after `reset`, the room as it is. "rgb_array_list"
    (Gymnasium's name) gives the movement itself: `render()` returns every frame since the last
    one, a frame after each reset and one after each of a movement's 50 control steps, at
    `render_fps` 50 (real time), which Gymnasium's `save_video` writes as a video. To see a
    movement the room steps it one control step at a time (the path videos take, the same world
    bit for bit but slower), which an episode does from its first `render()` on ("rgb_array":
    render after `reset`, as RecordVideo does) or from its reset ("rgb_array_list"); an
    environment never rendered (stable-baselines3 makes them with "rgb_array") steps at full
    speed. Frames come offscreen from the GL backend MUJOCO_GL names (EGL when unset); with no
    render mode nothing loads a GL library. "human" shows the room in MuJoCo's viewer after
    every reset and step; it is declared only where a display exists (DISPLAY or
    WAYLAND_DISPLAY), so that Gymnasium's `check_env`, which makes the environment in every
    declared mode, passes on a machine without one.

    ## Version History

    * v1: float32 spaces; the episode's length declared (`max_episode_steps`, 80000) and ended
      by TimeLimit, `iterations` refused by `make`; `voice` names the tract as the command line
      does ("vtl", "diva"), its numbers are `voice_config`; the variants PlayroomPhysical-v1
      (grasp="physical") and PlayroomDiva-v1 (voice="diva"); a frame after a step shows the
      movement's end; "human" declared only where a display exists; an "rgb_array" renderer
      not closed is closed at exit; later, with no change to what v1 did: "rgb_array_list",
      a movement's frames at `render_fps` 50.
    * v0: initial version: float64 spaces, no `max_episode_steps` (the environment truncated
      itself after `iterations`), `voice` a VoiceConfig, frames after a step showing the arm
      back at rest.
    """

    # One step is one movement of 50 control steps of 20 ms: a second of the room, one frame
    # (RecordVideo's). What `make` reads; an instance declares the modes that can work where it
    # runs, and "rgb_array_list"'s rate, a frame a control step (`__init__`).
    metadata: dict[str, Any] = {"render_modes": list(RENDER_MODES), "render_fps": 1}

    def __init__(
        self,
        grasp: str = DEFAULT_GRASP,
        preset: str | None = None,
        config: WorldConfig | None = None,
        voice: str | None = None,
        voice_config: VoiceConfig = DEFAULT_VOICE,
        iterations: int | None = STUDY_ITERATIONS,
        render_mode: str | None = None,
        render_size: tuple[int, int] = DEFAULT_SIZE,
        camera: str = "top",
    ) -> None:
        if render_mode is not None and render_mode not in RENDER_MODES:
            raise ValueError(
                f"unknown render_mode {render_mode!r}: one of {list(RENDER_MODES)} or None"
            )
        if render_mode == "human" and display_missing() is not None:
            raise RenderError(display_missing())
        # Gymnasium's MuJoCo environments declare "human" everywhere and fail at the first
        # render; check_env makes and renders every declared mode, so there it would fail.
        modes = [m for m in RENDER_MODES if m != "human" or display_missing() is None]
        self.movement_env = PlayroomMovementEnv(
            grasp, preset, config, voice, voice_config, iterations
        )
        fps = type(self).metadata["render_fps"]
        if render_mode == FRAME_LIST:  # 50: one frame a 20 ms control step
            timestep = self.movement_env.room.physics.model.opt.timestep
            fps = round(1.0 / (timestep * CONTROL_SUBSTEPS))
        self.metadata = {**type(self).metadata, "render_modes": modes, "render_fps": fps}
        self.render_mode = render_mode
        self.render_size = checked_view(
            self.movement_env.room.physics.model.ptr, render_size, camera
        )
        self.camera = camera
        # Made on the first render, for the episode's room (each episode is a new Playroom).
        self._renderer: OffscreenRenderer | Viewer | None = None
        self._rendered_room: Any = None
        self._render_data: Any = None
        # The episode's movements are watched from its first render on (see the docstring).
        self._watcher: MovementEnd | None = None
        self._frames: list[Any] = []  # "rgb_array_list"'s frames since the last render
        self._stepped_unwatched = False
        self._warned_unwatched = False
        b = self.movement_env.bounds
        high = np.concatenate([b.context, b.feedback]).astype(SPACE_DTYPE)
        self.action_space = spaces.Box(-1.0, 1.0, (ACTION_DIM,), SPACE_DTYPE)
        self.observation_space = spaces.Box(-high, high, dtype=SPACE_DTYPE)
        self._state = "unreset"  # unreset | running | truncated

    def reset(
        self, *, seed: int | None = None, options: dict[str, Any] | None = None
    ) -> tuple[np.ndarray, dict[str, Any]]:
        if seed is not None:
            seed = checked_seed(seed)
        if options:
            raise ValueError(f"reset takes no options, got {sorted(options)}")
        super().reset(seed=seed)
        room_seed = int(self.np_random.integers(SEED_BOUND)) if seed is None else seed
        timestep = self.movement_env.reset(seed=room_seed)
        self._state = "running"
        self._watcher, self._stepped_unwatched = None, False
        info = {"seed": room_seed, "iteration": 0, "events": [], "event_counts": _counts(timestep)}
        if self.render_mode == "human":
            self.render()
        if self.render_mode == FRAME_LIST:
            self._frames = [self._frame(None)]  # and from here on each movement's
        return _flat(timestep.observation), info

    def step(self, action: np.ndarray) -> tuple[np.ndarray, float, bool, bool, dict[str, Any]]:
        if self._state != "running":
            raise RuntimeError(
                "call reset() first"
                if self._state == "unreset"
                else f"the episode ended after {self.movement_env.settings.iterations} "
                "iterations (truncated): call reset()"
            )
        motor_space, command = _motor_command(action)
        if self._watcher is not None:
            self._watcher.forget()
        timestep = self.movement_env.step({"motor_space": motor_space, motor_space: command})
        feedback = self.movement_env.last_feedback
        assert feedback is not None  # a step after reset acts
        if self._watcher is None:
            self._stepped_unwatched = True
        elif any(e.kind == ev.DIVERGED for e in feedback.events):
            self._watcher.forget()  # the room was put back as it was before the movement
        if timestep.last():
            self._state = "truncated"
        info = {
            "motor_space": motor_space,
            "events": event_dicts(feedback),
            "event_counts": _counts(timestep),
            "iteration": self.movement_env.room.iteration,
            "seed": self.movement_env.episode_seed,
        }
        if self.render_mode == "human":
            self.render()
        if self.render_mode == FRAME_LIST:
            assert self._watcher is not None  # set by reset
            path = self._watcher.path  # None: the movement diverged, the room put back
            self._frames += [self._frame(None)] if path is None else map(self._frame, path)
        return _flat(timestep.observation), 0.0, False, timestep.last(), info

    def render(self) -> np.ndarray | list[Any] | None:
        """A frame under "rgb_array", the viewer shown under "human" (None): the room at the
        last movement's last control step, or as it is after a reset; under "rgb_array_list",
        every frame since the last render (after a reset, the room; after a step, one a control
        step of its movement); with no render mode, a warning and None, as Gymnasium's own
        environments do."""
        if self.render_mode is None:
            logger.warn(
                "render() without a render mode renders nothing: make the environment with "
                'render_mode="rgb_array" or "human"'
            )
            return None
        if self.render_mode == FRAME_LIST:
            frames, self._frames = self._frames, []
            return frames
        if self._watcher is None:
            if self._stepped_unwatched and not self._warned_unwatched:
                self._warned_unwatched = True
                logger.warn(
                    "this frame shows the room after the last movement, the arm back at rest: "
                    "an episode's movements are shown from its first render() on; render after "
                    "reset() to see them all (RecordVideo does)"
                )
        pose = self._ready().pose
        if self.render_mode == "rgb_array":
            return self._frame(pose)
        self._pose(pose)
        assert isinstance(self._renderer, Viewer)
        self._renderer.show()
        return None

    def _ready(self) -> MovementEnd:
        """The renderer of the episode's room (a new room: a new model and data), and its
        watcher of movements."""
        room = self.movement_env.room
        if room is not self._rendered_room:
            self.close()
            # The frames come from a copy of the room's state, made consistent by mj_forward
            # there: the room's own MjData is never computed on, so rendering changes no bit of
            # the world.
            model = room.physics.model.ptr
            self._render_data = mujoco.MjData(model)
            if self.render_mode == "human":
                self._renderer = Viewer(model, self._render_data)
            else:
                self._renderer = OffscreenRenderer(model, self.render_size, self.camera)
            self._rendered_room = room
        if self._watcher is None:
            self._watcher = MovementEnd(room)
        return self._watcher

    def _pose(self, pose: tuple[np.ndarray, np.ndarray, np.ndarray] | None) -> None:
        """The render data posed as `pose` (qpos, mocap_pos, mocap_quat), or as the room is."""
        room = self.movement_env.room
        data = room.physics.data.ptr
        now = (data.qpos, data.mocap_pos, data.mocap_quat)
        posed_as(room.physics.model.ptr, self._render_data, *(now if pose is None else pose))

    def _frame(self, pose: tuple[np.ndarray, np.ndarray, np.ndarray] | None) -> np.ndarray:
        """An RGB frame of the room posed as `pose`, or as it is."""
        self._ready()
        self._pose(pose)
        assert isinstance(self._renderer, OffscreenRenderer)
        return self._renderer.render(self._render_data)

    def close(self) -> None:
        """Frees the renderer or closes the viewer (a renderer not closed is freed at exit)."""
        if self._renderer is not None:
            self._renderer.close()
        self._renderer = self._rendered_room = self._render_data = None


def make_registered(**kwargs: Any) -> PlayroomGymEnv:
    """The environment of a registered id (sim/envs/versions.py), as `gymnasium.make` builds it:
    its episodes are ended by Gymnasium's TimeLimit at `max_episode_steps`, which its spec
    declares, so it has no end of its own and refuses `iterations` (one-line ValueError)."""
    if "iterations" in kwargs:
        raise ValueError(
            "with gymnasium.make the episode's length is max_episode_steps (the study's "
            f"{STUDY_ITERATIONS} by default): give max_episode_steps={kwargs['iterations']!r}, "
            "not iterations"
        )
    return PlayroomGymEnv(iterations=None, **kwargs)


def _motor_command(action: object) -> tuple[str, np.ndarray]:
    """(motor space, its command) of a flat action; ValueError in one line if the action is not
    of the action space, the part not chosen included (sim/envs/actions.py)."""
    a = checked_numbers(action, ACTION_DIM, "the action")
    if a[SELECTOR] < 0:
        return ARM, a[ARM_PART].copy()
    return VOICE, a[VOICE_PART].copy()


def _flat(observation: dict[str, np.ndarray]) -> np.ndarray:
    """The float64 context and feedback, rounded into the observation space's dtype (rounding
    keeps each value within the space's bounds, themselves rounded)."""
    return np.concatenate([observation["context"], observation["feedback"]]).astype(SPACE_DTYPE)


def _counts(timestep: Any) -> np.ndarray:
    return timestep.observation["events"].copy()
