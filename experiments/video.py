"""Videos of playroom movements: offscreen frames, an overlay, and a sound track, in one MP4.

A `FrameRecorder` watches a room through `Playroom.step_observers` and renders one frame per
control step with MuJoCo's offscreen renderer. An `EpisodeRenderer` turns iterations into
video: a few still frames before each movement, its 50 frames, a few held frames after it,
with the overlay of `experiments.overlay` drawn in, and the iteration's sound clips placed at
their time. `write` encodes the frames with mediapy, mixes the clips into one WAV track and
muxes both into the MP4 with the ffmpeg binary of imageio-ffmpeg, then moves the file into
place atomically.

Rendering is offscreen with the OpenGL backend MuJoCo loaded (`MUJOCO_GL`): the `playroom`
command chooses EGL by default before importing mujoco (experiments/gl.py); a program of one's
own sets `MUJOCO_GL` before its first import of mujoco.
"""

from __future__ import annotations

import contextlib
import math
import os
import re
import subprocess
import tempfile
import time
from collections.abc import Callable, Iterator, Sequence
from pathlib import Path

import imageio_ffmpeg
import mediapy
import mujoco
import numpy as np
from scipy.io import wavfile
from scipy.signal import resample_poly

from experiments import gl
from experiments.overlay import CameraView, Caption, Overlay
from sim import Feedback, Playroom
from sim import events as ev
from sim.config import ARM_DIM, VOICE_DIM

DEFAULT_SIZE = (640, 480)  # width, height (px)
# 50 frames per second shows one 50-step movement in 1 s, which is also its simulated time
# (20 ms control steps).
DEFAULT_FPS = 50.0
CAMERAS = ("top", "hand_view")
# Still frames before each movement (the scene as the agent sees it) and after it (time to
# read the events and hear the caregiver's word).
LEAD_FRAMES = 5
HOLD_FRAMES = 25
AUDIO_RATE = 44_100  # Hz of the mixed sound track
# Every clip is scaled to this peak: VocalTractLab's output level varies with the articulation
# (a word peaks near 0.06, a random babble near 0.002), and a video should let both be heard.
CLIP_PEAK = 0.5
MAX_CLIP_GAIN = 1000.0
# Quality of the H.264 stream (constant rate factor: lower is better and larger).
VIDEO_CRF = 20

# A clip of sound: (time in s, waveform (n,) float in [-1, 1], sample rate in Hz).
Clip = tuple[float, np.ndarray, int]


class RenderError(RuntimeError):
    """The machine cannot render or encode: no offscreen GL context, or ffmpeg failed."""


# Checks of what the caller asked for ---------------------------------------------------------
def parse_size(size: str | Sequence[int]) -> tuple[int, int]:
    """'WxH' or (width, height) -> (width, height) in px; ValueError unless both are positive
    even integers (H.264 in 4:2:0 needs even sides)."""
    if isinstance(size, str):
        match = re.fullmatch(r"\s*(\d+)\s*[xX]\s*(\d+)\s*", size)
        if match is None:
            raise ValueError(f"size must be WxH with positive integers, e.g. 640x480, got {size!r}")
        width, height = int(match[1]), int(match[2])
    else:
        try:
            width, height = size
        except (TypeError, ValueError):
            raise ValueError(f"size must be (width, height), got {size!r}") from None
        if not all(isinstance(v, int | np.integer) and not isinstance(v, bool) for v in size):
            raise ValueError(f"size must be two integers (width, height), got {size!r}")
        width, height = int(width), int(height)
    if width <= 0 or height <= 0:
        raise ValueError(f"size must be positive, got {width}x{height}")
    if width % 2 or height % 2:
        raise ValueError(f"size must have even width and height for H.264, got {width}x{height}")
    return width, height


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


def _check_camera(camera: str, model: mujoco.MjModel) -> None:
    if mujoco.mj_name2id(model, mujoco.mjtObj.mjOBJ_CAMERA, camera) < 0:
        raise ValueError(f"unknown camera {camera!r}: choose one of {list(CAMERAS)}")


# Frames -------------------------------------------------------------------------------------
class FrameRecorder:
    """Renders a room's scene offscreen: on demand (`capture`) and, while attached to the
    room's `step_observers`, once after every control step.

    size: (width, height) px; camera: a camera of the MJCF ("top" or "hand_view"); shadows:
    MuJoCo's shadow maps, off by default: on Mesa's software EGL they halve the frame rate, and
    from the top camera they wash out the table and hide the reach circles. Frames are
    (height, width, 3) uint8; each comes with the `CameraView` it was taken from. Close it
    (or use it as a context manager): an EGL context left to the garbage collector at exit
    prints errors.
    """

    def __init__(
        self,
        room: Playroom,
        size: tuple[int, int] = DEFAULT_SIZE,
        camera: str = "top",
        shadows: bool = False,
    ) -> None:
        self.width, self.height = parse_size(size)
        self.room = room
        self.camera = camera
        self.shadows = bool(shadows)
        model = room.physics.model.ptr
        _check_camera(camera, model)
        limit = (model.vis.global_.offwidth, model.vis.global_.offheight)
        if self.width > limit[0] or self.height > limit[1]:
            raise ValueError(
                f"size {self.width}x{self.height} exceeds the model's offscreen buffer "
                f"{limit[0]}x{limit[1]} (<visual><global offwidth offheight> in the MJCF)"
            )
        try:
            self._renderer = mujoco.Renderer(model, self.height, self.width)
        except Exception as exc:  # the GL backends raise many kinds; all mean the same here
            raise RenderError(
                f"cannot create an offscreen renderer with "
                f"{gl.VARIABLE}={os.environ.get(gl.VARIABLE, '(unset)')} "
                f"({type(exc).__name__}: {exc}); {gl.choices()}"
            ) from exc
        self.frames: list[np.ndarray] = []
        self.views: list[CameraView] = []

    def capture(self) -> np.ndarray:
        """Render the room as it is now; append and return the frame."""
        model, data = self.room.physics.model.ptr, self.room.physics.data.ptr
        self._renderer.update_scene(data, camera=self.camera)
        self._renderer.scene.flags[mujoco.mjtRndFlag.mjRND_SHADOW] = self.shadows
        frame = self._renderer.render()
        self.frames.append(frame)
        self.views.append(CameraView.of(model, data, self.camera, self.width, self.height))
        return frame

    def __call__(self, step: int, observation: dict) -> None:
        """The step observer: one frame per control step."""
        self.capture()

    def take(self) -> tuple[list[np.ndarray], list[CameraView]]:
        """The frames and views captured so far; the recorder starts empty again."""
        frames, views = self.frames, self.views
        self.frames, self.views = [], []
        return frames, views

    @contextlib.contextmanager
    def watching(self) -> Iterator[FrameRecorder]:
        """Attached to the room's step observers inside the block, detached after it."""
        self.room.step_observers.append(self)
        try:
            yield self
        finally:
            self.room.step_observers.remove(self)

    def close(self) -> None:
        if self._renderer is not None:
            self._renderer.close()
            self._renderer = None

    def __enter__(self) -> FrameRecorder:
        return self

    def __exit__(self, *exc_info: object) -> None:
        self.close()


# Sound --------------------------------------------------------------------------------------
def mix_audio(
    clips: Sequence[Clip],
    duration_s: float,
    rate: int = AUDIO_RATE,
    peak: float | None = CLIP_PEAK,
) -> np.ndarray:
    """One mono track (n,) float32 in [-1, 1] of `duration_s`, n = round(duration_s * rate).

    clips: (time_s, waveform (m,) float in [-1, 1], rate_hz); each is resampled to `rate`,
    added at its time and cut at the end of the track. peak: each clip is scaled to this peak
    (gain at most `MAX_CLIP_GAIN`), so that a quiet babble is heard as well as a word; None
    keeps the clips' levels. Overlapping clips add up; the sum is clipped to [-1, 1] rather
    than wrapped around by the int16 conversion.
    """
    track = np.zeros(int(round(duration_s * rate)), dtype=np.float64)
    for k, (time_s, waveform, clip_rate) in enumerate(clips):
        wave = np.asarray(waveform, dtype=np.float64)
        if wave.ndim != 1:
            raise ValueError(f"audio clip {k}: waveform must be 1-D, got shape {wave.shape}")
        if not np.isfinite(wave).all():
            raise ValueError(f"audio clip {k}: waveform contains NaN or inf")
        if int(clip_rate) != clip_rate or clip_rate <= 0:
            raise ValueError(f"audio clip {k}: rate must be a positive integer, got {clip_rate}")
        if not math.isfinite(time_s) or time_s < 0:
            raise ValueError(f"audio clip {k}: time must be >= 0 s, got {time_s}")
        if clip_rate != rate:
            g = math.gcd(int(clip_rate), rate)
            wave = resample_poly(wave, rate // g, int(clip_rate) // g)
        if peak is not None and wave.size:
            # Silence (peak 0) stays silence; near-silence is not blown up into noise.
            loudest = np.abs(wave).max()
            wave = wave * min(peak / loudest, MAX_CLIP_GAIN) if loudest > 0 else wave
        start = int(round(time_s * rate))
        end = min(len(track), start + len(wave))
        if end > start:
            track[start:end] += wave[: end - start]
    return np.clip(track, -1.0, 1.0).astype(np.float32)


def write_wav(path: str | os.PathLike, track: np.ndarray, rate: int = AUDIO_RATE) -> None:
    """Write a mono float track in [-1, 1] as 16-bit PCM WAV, levels unchanged."""
    pcm = np.round(np.clip(track, -1.0, 1.0) * 32767).astype(np.int16)
    wavfile.write(os.fspath(path), int(rate), pcm)


def ffmpeg_exe() -> str:
    """The ffmpeg binary shipped by imageio-ffmpeg (nothing to install by hand)."""
    try:
        return imageio_ffmpeg.get_ffmpeg_exe()
    except RuntimeError as exc:
        raise RenderError(f"imageio-ffmpeg has no ffmpeg binary: {exc}") from exc


def mux(video_path: Path, wav_path: Path, out_path: Path) -> None:
    """Copy the video stream and encode the WAV as AAC into the MP4 `out_path`."""
    argv = [
        ffmpeg_exe(),
        "-y",
        "-loglevel",
        "error",
        "-i",
        os.fspath(video_path),
        "-i",
        os.fspath(wav_path),
        "-map",
        "0:v:0",
        "-map",
        "1:a:0",
        "-c:v",
        "copy",
        "-c:a",
        "aac",
        # The track is a little longer than the video (see `write`), so the video's end decides.
        "-shortest",
        "-movflags",
        "+faststart",
        "-f",
        "mp4",
        os.fspath(out_path),
    ]
    result = subprocess.run(argv, capture_output=True, text=True)
    if result.returncode != 0:
        detail = result.stderr.strip().splitlines()[-1:] or ["no message"]
        raise RenderError(f"ffmpeg failed to mux the sound (exit {result.returncode}): {detail[0]}")


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
        if camera not in CAMERAS:
            raise ValueError(f"unknown camera {camera!r}: choose one of {list(CAMERAS)}")
        for name, value in (("lead_frames", lead_frames), ("hold_frames", hold_frames)):
            if isinstance(value, bool) or not isinstance(value, int) or value < 0:
                raise ValueError(f"{name} must be a non-negative integer, got {value!r}")
        self.camera = camera
        self.lead_frames, self.hold_frames = lead_frames, hold_frames
        self.audio_rate = int(audio_rate)
        self.shadows = shadows
        self.n_frames = 0
        self.clips: list[Clip] = []
        self._recorder: FrameRecorder | None = None
        self._overlay: Overlay | None = None
        self._model: mujoco.MjModel | None = None
        self._tmp = tempfile.TemporaryDirectory(prefix="playroom-video-")
        self._video_path = Path(self._tmp.name) / "frames.mp4"
        self._writer: mediapy.VideoWriter | None = None

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
        overlay says the agent chose (see `experiments.overlay.Caption`). audio: clips whose
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
        )
        for _ in range(self.lead_frames):
            recorder.capture()
        act = room.act_arm if motor_space == "arm" else room.act_voice
        try:
            with recorder.watching():
                feedback = act(m)
        except Exception:
            recorder.take()  # a refused or failed command leaves no frames behind
            raise
        frames, views = recorder.take()
        if len(frames) > self.lead_frames:
            frames += [frames[-1]] * self.hold_frames
            views += [views[-1]] * self.hold_frames
        movement_start_s = (self.n_frames + self.lead_frames) / self.fps
        n_steps = room.config.n_steps
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
        self._close_writer()
        # One frame of sound more than the video: with -shortest the video then ends the file,
        # and AAC's frame rounding cannot cut its last picture.
        track = mix_audio(self.clips, (self.n_frames + 1) / self.fps, self.audio_rate)
        wav = Path(self._tmp.name) / "sound.wav"
        write_wav(wav, track, self.audio_rate)
        fd, tmp_name = tempfile.mkstemp(prefix=f".{out.name}.", suffix=".tmp", dir=out.parent)
        os.close(fd)
        try:
            mux(self._video_path, wav, Path(tmp_name))
            os.replace(tmp_name, out)
        finally:
            with contextlib.suppress(FileNotFoundError):
                os.unlink(tmp_name)
        return out

    def close(self) -> None:
        """Release the renderer and the temporary files."""
        if self._writer is not None:
            with contextlib.suppress(Exception):
                self._writer.close()
            self._writer = None
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
        if self._writer is None and self.n_frames > 0:
            # The encoder of the frames so far was closed by `write`; a new one would
            # overwrite them.
            raise RuntimeError("this video was already written; start a new EpisodeRenderer")
        if self._writer is None:
            mediapy.set_ffmpeg(ffmpeg_exe())
            width, height = self.size
            self._writer = mediapy.VideoWriter(
                self._video_path, (height, width), fps=self.fps, crf=VIDEO_CRF
            )
            try:
                self._writer.__enter__()
            except Exception as exc:
                self._writer = None
                raise RenderError(f"ffmpeg could not start encoding frames: {exc}") from exc
        self._writer.add_image(image)
        self.n_frames += 1

    def _close_writer(self) -> None:
        if self._writer is not None:
            try:
                self._writer.close()
            except Exception as exc:
                raise RenderError(f"ffmpeg failed to encode the frames: {exc}") from exc
            finally:
                self._writer = None


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
) -> Path:
    """Film `iterations` random commands (half arm, half voice, in a seeded random order) in a
    new room and write the MP4 with overlay and sound to `out_path`.

    voice_audio(m (28,)) -> (waveform, rate Hz): the agent's sound of a voice command, placed at
    the movement's start; word_audio(word) -> (waveform, rate Hz): the caregiver's word, placed
    at the step she says it. None: silent. shadows: see `FrameRecorder`. Every argument is
    checked before anything renders.
    """
    if isinstance(iterations, bool) or not isinstance(iterations, int) or iterations <= 0:
        raise ValueError(f"iterations must be a positive integer, got {iterations!r}")
    size, fps = parse_size(size), _check_fps(fps)
    if camera not in CAMERAS:
        raise ValueError(f"unknown camera {camera!r}: choose one of {list(CAMERAS)}")
    out = check_output_path(out_path)
    room = Playroom(grasp=grasp, seed=seed)
    rng = np.random.default_rng([seed, 1])  # a stream apart from the room's own
    spaces = ["arm"] * math.ceil(iterations / 2) + ["voice"] * (iterations // 2)
    spaces = [spaces[k] for k in rng.permutation(iterations)]
    with EpisodeRenderer(size, fps, camera, lead_frames, hold_frames, shadows=shadows) as renderer:
        for space in spaces:
            m = rng.uniform(-1.0, 1.0, ARM_DIM if space == "arm" else VOICE_DIM)
            film_iteration(renderer, room, space, m, voice_audio, word_audio, model="random")
        return renderer.write(out)


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


# Speed --------------------------------------------------------------------------------------
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
                    with recorder.watching():
                        room.act_arm(m)
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
