"""Videos of playroom movements: offscreen frames, an overlay, and a sound track, in one MP4.

An `EpisodeRenderer` turns iterations into video: a few still frames before each movement, its
50 frames (experiments/video/recording.py), a few held frames after it, with the overlay of
experiments/video/overlay.py drawn in, and the iteration's sound clips placed at their time
(experiments/video/sound.py). `write` mixes the clips into one track and muxes it with the frames
into the MP4, which is moved into place atomically (experiments/video/encoding.py). This module
holds the checks of what the caller asked for, made before anything renders, and the two ways of
filming: `render_random` and `film_iteration` (which `experiments.video.replay` uses).

Rendering is offscreen with the OpenGL backend MuJoCo loaded (`MUJOCO_GL`): the `playroom`
command chooses EGL by default before importing mujoco (experiments/video/gl.py); a program of one's
own sets `MUJOCO_GL` before its first import of mujoco.
"""

from __future__ import annotations

import math
import os
import tempfile
from collections.abc import Callable, Sequence
from pathlib import Path

import numpy as np
from tqdm import tqdm

from experiments.video.encoding import FrameEncoder, mux_into_place
from experiments.video.overlay import Caption, Overlay
from experiments.video.recording import CAMERAS, DEFAULT_SIZE, FrameRecorder, parse_size
from experiments.video.sound import AUDIO_RATE, Clip, write_track
from models.layout import ARM_DIM, N_STEPS, VOICE_DIM
from models.presets import DEFAULT_PRESET
from models.tracts import DEFAULT_TRACT
from sim import Feedback, Playroom
from sim import events as ev
from sim.config import world_preset
from sim.mujoco_import import mujoco

# 50 frames per second shows one 50-step movement in 1 s, which is also its simulated time
# (20 ms control steps).
DEFAULT_FPS = 50.0
# Still frames before each movement (the scene as the agent sees it) and after it (time to
# read the events and hear the caregiver's word).
LEAD_FRAMES = 5
HOLD_FRAMES = 25


# Checks of what the caller asked for ---------------------------------------------------------
def check_output_path(path: str | os.PathLike) -> Path:
    """The output path, or ValueError naming why it cannot be written (checked before any
    rendering, so a bad path fails in a second, not after minutes)."""
    out = Path(path)
    if out.is_dir():
        raise ValueError(f"output {out} is a directory; give a file name such as {out}/video.mp4")
    folder = out.parent
    if not folder.is_dir():
        raise ValueError(f"cannot write {out}: directory {folder} does not exist")
    if not os.access(folder, os.W_OK | os.X_OK):
        raise ValueError(f"cannot write {out}: directory {folder} is not writable")
    if out.exists() and not os.access(out, os.W_OK):
        raise ValueError(f"cannot write {out}: the file exists and is not writable")
    return out


def _check_fps(fps: float) -> float:
    if isinstance(fps, bool) or not isinstance(fps, int | float) or not math.isfinite(fps):
        raise ValueError(f"fps must be a positive number, got {fps!r}")
    if fps <= 0:
        raise ValueError(f"fps must be positive, got {fps}")
    return float(fps)


def _check_camera(camera: str) -> None:
    if camera not in CAMERAS:
        raise ValueError(f"unknown camera {camera!r}: choose one of {list(CAMERAS)}")


# Iterations into video ----------------------------------------------------------------------
class EpisodeRenderer:
    """Renders iterations of rooms into one video with overlay and sound.

    Per iteration: `lead_frames` still frames of the scene before the movement, one frame per
    control step, and `hold_frames` copies of the last frame, all with the overlay. size, fps,
    camera, shadows: as for `FrameRecorder`; audio_rate: Hz of the sound track. Frames
    stream to a temporary H.264 file as each iteration ends, so memory holds one iteration.
    Use it as a context manager, or call `close`.
    """

    def __init__(
        self,
        size: str | tuple[int, int] = DEFAULT_SIZE,
        fps: float = DEFAULT_FPS,
        camera: str = "top",
        lead_frames: int = LEAD_FRAMES,
        hold_frames: int = HOLD_FRAMES,
        audio_rate: int = AUDIO_RATE,
        shadows: bool = False,
    ) -> None:
        self.size = parse_size(size)
        self.fps = _check_fps(fps)
        _check_camera(camera)
        for name, value in (("lead_frames", lead_frames), ("hold_frames", hold_frames)):
            if isinstance(value, bool) or not isinstance(value, int) or value < 0:
                raise ValueError(f"{name} must be a non-negative integer, got {value!r}")
        self.camera = camera
        self.lead_frames, self.hold_frames = lead_frames, hold_frames
        self.audio_rate = int(audio_rate)
        self.shadows = shadows
        self.clips: list[Clip] = []
        # What the sound track is, shown on every frame once a film adds sound (set by
        # `film_iteration` from the room's vocal tract).
        self.sound_label: str | None = None
        self._recorder: FrameRecorder | None = None
        self._overlay: Overlay | None = None
        self._model: mujoco.MjModel | None = None
        self._tmp = tempfile.TemporaryDirectory(prefix="playroom-video-")
        self._encoder = FrameEncoder(Path(self._tmp.name) / "frames.mp4", self.size, self.fps)

    @property
    def n_frames(self) -> int:
        """Frames rendered so far (all iterations)."""
        return self._encoder.n_frames

    @property
    def duration_s(self) -> float:
        return self.n_frames / self.fps

    def render_iteration(
        self,
        room: Playroom,
        motor_space: str,
        m: np.ndarray,
        model: str | None = None,
        goal: np.ndarray | None = None,
        goal_block: str | None = None,
        audio: Sequence[Clip] | None = None,
        iteration: int | None = None,
    ) -> Feedback:
        """Execute one command in `room` while filming it; return the room's feedback.

        motor_space: "arm" (m (21,)) or "voice" (m (28,)). model, goal, goal_block: what the
        overlay says the agent chose (see `experiments.video.overlay.Caption`). audio: clips whose
        time is in s after the movement's first frame (a control step lasts 1/fps s of video).
        iteration: the number shown; default the room's own count. If the command is refused
        (ValueError), nothing is added to the video.
        """
        if motor_space not in ("arm", "voice"):
            raise ValueError(f"unknown motor space {motor_space!r}: 'arm' or 'voice'")
        recorder = self._recorder_for(room)
        caption = Caption(
            room.iteration if iteration is None else int(iteration),
            motor_space,
            model,
            None if goal is None else np.asarray(goal, dtype=float),
            goal_block,
            self.sound_label,
        )
        for _ in range(self.lead_frames):
            recorder.capture()
        try:
            feedback = recorder.film(motor_space, m)
        except Exception:
            recorder.take()  # a refused or failed command leaves no frames behind
            raise
        frames, views = recorder.take()
        if len(frames) > self.lead_frames:
            frames += [frames[-1]] * self.hold_frames
            views += [views[-1]] * self.hold_frames
        movement_start_s = (self.n_frames + self.lead_frames) / self.fps
        n_steps = N_STEPS
        assert self._overlay is not None  # _recorder_for made it with the recorder
        for k, (frame, view) in enumerate(zip(frames, views, strict=True)):
            tick = k - self.lead_frames + 1  # control step of this frame
            image = self._overlay.draw(
                frame, view, caption, tick, n_steps, feedback.events, feedback.positions
            )
            self._write_frame(image)
        for time_s, waveform, rate in audio or ():
            self.clips.append((movement_start_s + float(time_s), waveform, rate))
        return feedback

    def write(self, out_path: str | os.PathLike) -> Path:
        """Encode everything rendered so far into the MP4 `out_path` (video + sound track);
        the file appears whole or not at all. Returns the path."""
        out = check_output_path(out_path)
        if self.n_frames == 0:
            raise ValueError("nothing to write: no iteration was rendered")
        self._encoder.finish()
        # One frame of sound more than the video: with -shortest the video then ends the file,
        # and AAC's frame rounding cannot cut its last picture.
        wav = Path(self._tmp.name) / "sound.wav"
        write_track(wav, self.clips, (self.n_frames + 1) / self.fps, self.audio_rate)
        return mux_into_place(self._encoder.path, wav, out)

    def close(self) -> None:
        """Release the renderer and the temporary files."""
        self._encoder.close()
        if self._recorder is not None:
            self._recorder.close()
            self._recorder = None
        self._tmp.cleanup()

    def __enter__(self) -> EpisodeRenderer:
        return self

    def __exit__(self, *exc_info: object) -> None:
        self.close()

    # Internals ----------------------------------------------------------------------------
    def _recorder_for(self, room: Playroom) -> FrameRecorder:
        """One renderer per MuJoCo model: its GL context holds that model's meshes and
        textures. A replay that keeps its room reuses it."""
        model = room.physics.model.ptr
        if self._recorder is None or self._model is not model:
            if self._recorder is not None:
                self._recorder.close()
            self._recorder = FrameRecorder(room, self.size, self.camera, self.shadows)
            self._overlay = Overlay(model, *self.size, fps=self.fps)
            self._model = model
        self._recorder.room = room
        return self._recorder

    def _write_frame(self, image: np.ndarray) -> None:
        if self._encoder.finished:
            # `write` ended the stream of the frames so far; a new one would overwrite them.
            raise RuntimeError("this video was already written; start a new EpisodeRenderer")
        self._encoder.add(image)


# A room driven by random commands -----------------------------------------------------------
def render_random(
    grasp: str,
    seed: int,
    out_path: str | os.PathLike,
    iterations: int = 4,
    size: str | tuple[int, int] = DEFAULT_SIZE,
    fps: float = DEFAULT_FPS,
    camera: str = "top",
    voice_audio: Callable[[np.ndarray], tuple[np.ndarray, int]] | None = None,
    word_audio: Callable[[str], tuple[np.ndarray, int]] | None = None,
    lead_frames: int = LEAD_FRAMES,
    hold_frames: int = HOLD_FRAMES,
    shadows: bool = False,
    voice: str = DEFAULT_TRACT,
    sound: bool = False,
    progress: bool | None = None,
) -> Path:
    """Film `iterations` random commands (half arm, half voice, in a seeded random order) in a
    new room and write the MP4 with overlay and sound to `out_path`.

    voice_audio(m (28,)) -> (waveform, rate Hz): the agent's sound of a voice command, placed at
    the movement's start; word_audio(word) -> (waveform, rate Hz): the caregiver's word, placed
    at the step she says it. None: silent, unless `sound`, which takes both from the room's
    vocal tract. voice: the tract (models/tracts.py). shadows: see `FrameRecorder`. Every
    argument is checked before anything renders. progress: a bar on stderr (None: only on a
    terminal).
    """
    if isinstance(iterations, bool) or not isinstance(iterations, int) or iterations <= 0:
        raise ValueError(f"iterations must be a positive integer, got {iterations!r}")
    size, fps = parse_size(size), _check_fps(fps)
    _check_camera(camera)
    out = check_output_path(out_path)
    room = Playroom(grasp=grasp, seed=seed, config=world_preset(DEFAULT_PRESET, voice=voice))
    if sound:
        voice_audio, word_audio = tract_audio(room)
    rng = np.random.default_rng([seed, 1])  # a stream apart from the room's own
    spaces = ["arm"] * math.ceil(iterations / 2) + ["voice"] * (iterations // 2)
    spaces = [spaces[k] for k in rng.permutation(iterations)]
    with EpisodeRenderer(size, fps, camera, lead_frames, hold_frames, shadows=shadows) as renderer:
        disable = None if progress is None else not progress
        for space in tqdm(spaces, disable=disable, desc="render", unit="iteration"):
            m = rng.uniform(-1.0, 1.0, ARM_DIM if space == "arm" else VOICE_DIM)
            film_iteration(renderer, room, space, m, voice_audio, word_audio, model="random")
        return renderer.write(out)


def tract_audio(
    room: Playroom,
) -> tuple[Callable[[np.ndarray], tuple[np.ndarray, int]], Callable[[str], tuple[np.ndarray, int]]]:
    """(voice_audio, word_audio) of the room's vocal tract, for `film_iteration`."""
    tract = room.vocal_tract
    return (lambda m: tract.audio(tract.trajectory(m))), tract.word_audio


def film_iteration(
    renderer: EpisodeRenderer,
    room: Playroom,
    motor_space: str,
    m: np.ndarray,
    voice_audio: Callable[[np.ndarray], tuple[np.ndarray, int]] | None = None,
    word_audio: Callable[[str], tuple[np.ndarray, int]] | None = None,
    **overlay,
) -> Feedback:
    """Film one command with its sounds: the agent's voice from the movement's start, the
    caregiver's word at the step she says it. `overlay` goes to `render_iteration`."""
    clips: list[Clip] = []
    if voice_audio is not None or word_audio is not None:
        renderer.sound_label = room.vocal_tract.sound_label
    if motor_space == "voice" and voice_audio is not None:
        clips.append((0.0, *voice_audio(m)))
    before = renderer.n_frames
    feedback = renderer.render_iteration(room, motor_space, m, audio=clips, **overlay)
    if word_audio is not None:
        start = (before + renderer.lead_frames) / renderer.fps
        for e in feedback.events:
            if e.kind == ev.CAREGIVER_SAID and e.word:
                renderer.clips.append((start + e.step / renderer.fps, *word_audio(e.word)))
    return feedback
