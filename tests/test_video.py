"""Videos: frames per control step, overlay, projection, sound track, and bad input."""

from __future__ import annotations

import os
import subprocess

import imageio_ffmpeg
import mujoco
import numpy as np
import pytest
from scipy.io import wavfile

from experiments import video
from experiments.overlay import CameraView
from sim import Playroom
from sim.config import DEFAULT_WORLD, VOICE_DIM
from sim.scripted import Waypoint, arm_command_through

SIZE = (160, 120)
FPS = 50.0
LEAD, HOLD = 2, 3
STEPS = 50
TONE_HZ = 440.0
TONE_RATE = 22_050
TONE_S = 0.4


def tone(seconds: float = TONE_S) -> tuple[np.ndarray, int]:
    t = np.arange(int(seconds * TONE_RATE)) / TONE_RATE
    return 0.5 * np.sin(2 * np.pi * TONE_HZ * t), TONE_RATE


def decoded_frames(path) -> np.ndarray:
    """(n, h, w, 3) uint8: every frame of the MP4 (mediapy 1.2.7 cannot read with ffmpeg 9:
    it passes -vsync, which ffmpeg 9 removed)."""
    reader = imageio_ffmpeg.read_frames(str(path))
    meta = next(reader)
    width, height = meta["size"]
    return np.stack([np.frombuffer(f, np.uint8).reshape(height, width, 3) for f in reader])


def decoded_sound(path, tmp_path) -> tuple[np.ndarray, int]:
    """The MP4's audio stream decoded to (n,) int16 samples and its rate; fails if absent."""
    wav = tmp_path / "decoded.wav"
    ffmpeg = imageio_ffmpeg.get_ffmpeg_exe()
    result = subprocess.run(
        [ffmpeg, "-v", "error", "-y", "-i", str(path), "-map", "0:a:0", str(wav)],
        capture_output=True,
        text=True,
    )
    assert result.returncode == 0, result.stderr
    rate, samples = wavfile.read(wav)
    return samples, rate


def stream_listing(path) -> str:
    """What `ffmpeg -i FILE` says about the file's streams (it exits 1: no output given)."""
    ffmpeg = imageio_ffmpeg.get_ffmpeg_exe()
    return subprocess.run([ffmpeg, "-i", str(path)], capture_output=True, text=True).stderr


@pytest.fixture(scope="module")
def reach_command() -> np.ndarray:
    """An arm command sweeping the hand from rest to the right and down: a large motion."""
    m, _ = arm_command_through([Waypoint(25, (0.35, 0.2)), Waypoint(50, (0.2, -0.3))])
    return m


@pytest.mark.parametrize("grasp", ["kinematic", "physical"])
def test_short_render_has_frames_sound_and_motion(grasp, reach_command, tmp_path):
    room = Playroom(grasp=grasp, seed=0)
    out = tmp_path / "short.mp4"
    per_iteration = LEAD + STEPS + HOLD
    with video.EpisodeRenderer(SIZE, FPS, lead_frames=LEAD, hold_frames=HOLD) as renderer:
        renderer.render_iteration(room, "arm", reach_command, model="1: arm -> hand")
        voice = np.random.default_rng(0).uniform(-1, 1, VOICE_DIM)
        renderer.render_iteration(room, "voice", voice, audio=[(0.0, *tone())])
        assert renderer.n_frames == 2 * per_iteration
        assert renderer.write(out) == out

    n_frames, seconds = imageio_ffmpeg.count_frames_and_secs(str(out))
    assert n_frames == 2 * per_iteration
    assert seconds == pytest.approx(2 * per_iteration / FPS, abs=1.5 / FPS)
    listing = stream_listing(out)
    assert "Video: h264" in listing and "Audio:" in listing and "Duration:" in listing

    # The sound lasts as long as the video, and the tone sits where the voice movement starts.
    samples, rate = decoded_sound(out, tmp_path)
    assert len(samples) / rate == pytest.approx(seconds, abs=0.05)
    start = (per_iteration + LEAD) / FPS
    loudness = lambda a, b: np.abs(samples[int(a * rate) : int(b * rate)].astype(float)).mean()  # noqa: E731
    assert loudness(start + 0.05, start + TONE_S - 0.05) > 2000
    assert loudness(0.0, start - 0.1) < 50

    frames = decoded_frames(out)
    assert frames.shape == (2 * per_iteration, SIZE[1], SIZE[0], 3)
    # Between the overlay's text boxes (top and bottom 42 px), the arm moves.
    band = slice(42, SIZE[1] - 42)
    first, last = frames[LEAD, band].astype(int), frames[LEAD + STEPS - 1, band].astype(int)
    # Pixels that changed colour clearly; the arm is thin at this size (links 1-2 px wide).
    changed = lambda a, b: int((np.abs(a - b).max(axis=-1) > 60).sum())  # noqa: E731
    assert changed(first, last) > 10
    # Held frames after the movement show the scene standing still (codec noise aside).
    held = frames[LEAD + STEPS : per_iteration, band].astype(int)
    assert max(changed(h, held[0]) for h in held) <= 2


def test_render_random_writes_mp4_with_sound(tmp_path):
    out = tmp_path / "random.mp4"
    calls = []

    def voice_audio(m):
        calls.append(m.shape)
        return tone()

    video.render_random(
        "kinematic", 3, out, 2, SIZE, voice_audio=voice_audio, lead_frames=0, hold_frames=0
    )
    n_frames, _ = imageio_ffmpeg.count_frames_and_secs(str(out))
    assert n_frames == 2 * STEPS
    assert calls == [(VOICE_DIM,)]  # half arm, half voice
    assert "Audio:" in stream_listing(out)
    # Only the final file remains: the temporary ones were moved or removed.
    assert os.listdir(tmp_path) == ["random.mp4"]


@pytest.mark.parametrize("camera", ["top", "hand_view"])
def test_projection_lands_on_bodies(camera):
    room = Playroom(grasp="kinematic", seed=0)
    # Asymmetric places, so that a flipped axis would miss.
    room.arrange(toys=np.array([[0.45, -0.3], [-0.6, 0.25], [0.15, 0.7]]))
    model, data = room.physics.model.ptr, room.physics.data.ptr
    size = (320, 240)
    with video.FrameRecorder(room, size, camera=camera) as recorder:
        frame = recorder.capture()
        view = recorder.views[-1]
    dominant = {"toy1": 0, "toy2": 1, "toy3": 2}  # red, green, purple (blue is largest)
    checked = 0
    for name, channel in dominant.items():
        body = mujoco.mj_name2id(model, mujoco.mjtObj.mjOBJ_BODY, name)
        u, v = view.project(data.xpos[body])[0]
        if not (10 <= u < size[0] - 10 and 0 <= v < size[1]):
            continue  # out of the tracking camera's view
        rgb = frame[int(v), int(u)].astype(int)
        assert rgb.argmax() == channel and rgb.max() - rgb.min() > 40, (name, rgb)
        # Ten pixels away is the table, not the toy: the check can tell them apart.
        away = frame[int(v), int(u) + 10].astype(int)
        assert away.max() - away.min() < 40, (name, away)
        checked += 1
    assert checked >= 2


def test_projection_of_a_point_behind_the_camera_is_nan():
    view = CameraView(np.array([0, 0, 3.0]), np.eye(3), 45.0, 160, 120)
    pixels = view.project(np.array([[0.0, 0.0, 0.0], [0.0, 0.0, 4.0]]))
    np.testing.assert_allclose(pixels[0], [80, 60])
    assert np.isnan(pixels[1]).all()


def test_mix_audio_places_resamples_and_clips():
    ones = np.ones(800)  # 0.1 s at 8 kHz
    track = video.mix_audio([(0.5, ones, 8000), (0.55, ones, 8000)], 1.0, 16_000, peak=None)
    assert track.shape == (16_000,) and track.dtype == np.float32
    assert np.all(track[:7_990] == 0) and np.all(track[10_500:] == 0)
    assert track[8_400] == pytest.approx(1.0, abs=0.05)  # one clip
    assert track[9_000] == 1.0  # two overlapping clips, clipped to full scale
    # Clips are brought to a common peak: a quiet babble is heard as well as a loud word.
    levelled = video.mix_audio([(0.0, 0.002 * ones, 8000), (0.5, 0.2 * ones, 8000)], 1.0, 8000)
    assert levelled[400] == pytest.approx(video.CLIP_PEAK)  # the quiet babble
    assert levelled[4400] == pytest.approx(video.CLIP_PEAK)  # the loud word
    # A clip running past the end is cut, not an error.
    assert video.mix_audio([(0.95, ones, 8000)], 1.0, rate=8000).shape == (8000,)
    with pytest.raises(ValueError, match="NaN"):
        video.mix_audio([(0.0, np.array([np.nan]), 8000)], 1.0)


@pytest.mark.parametrize("size", ["0x120", "160", "abc", "161x120", (160,), (160.0, 120), (-2, 4)])
def test_bad_size_is_refused(size):
    with pytest.raises(ValueError, match="size"):
        video.parse_size(size)


def test_size_text_is_parsed():
    assert video.parse_size("640x480") == (640, 480)
    assert video.parse_size((160, 120)) == (160, 120)


def test_bad_output_fails_before_rendering(tmp_path, monkeypatch):
    def no_room(*args, **kwargs):
        raise AssertionError("a room was built before the output path was checked")

    monkeypatch.setattr(video, "Playroom", no_room)
    with pytest.raises(ValueError, match="does not exist"):
        video.render_random("kinematic", 0, tmp_path / "missing" / "out.mp4", size=SIZE)
    with pytest.raises(ValueError, match="is a directory"):
        video.render_random("kinematic", 0, tmp_path, size=SIZE)
    if os.geteuid() != 0:  # root may write anywhere
        locked = tmp_path / "locked"
        locked.mkdir(mode=0o500)
        with pytest.raises(ValueError, match="not writable"):
            video.render_random("kinematic", 0, locked / "out.mp4", size=SIZE)


def test_failed_mux_is_a_render_error(tmp_path):
    wav = tmp_path / "sound.wav"
    video.write_wav(wav, np.zeros(100), 8000)
    with pytest.raises(video.RenderError, match="ffmpeg failed"):
        video.mux(tmp_path / "no_such_video.mp4", wav, tmp_path / "out.mp4")


def test_unknown_camera_is_refused(tmp_path):
    with pytest.raises(ValueError, match="camera"):
        video.render_random("kinematic", 0, tmp_path / "out.mp4", size=SIZE, camera="side")


def test_missing_gl_names_mujoco_gl_and_its_choices(monkeypatch):
    def no_gl(*args, **kwargs):
        raise RuntimeError("eglInitialize failed")

    monkeypatch.setattr(video.mujoco, "Renderer", no_gl)
    room = Playroom(grasp="kinematic", seed=0)
    with pytest.raises(video.RenderError, match="MUJOCO_GL to one of egl, osmesa, glfw"):
        video.FrameRecorder(room, SIZE)


def test_refused_command_adds_no_frames():
    room = Playroom(grasp="kinematic", seed=0)
    with video.EpisodeRenderer(SIZE, lead_frames=LEAD, hold_frames=HOLD) as renderer:
        with pytest.raises(ValueError):
            renderer.render_iteration(room, "arm", np.full(21, 2.0))
        assert renderer.n_frames == 0
        assert room.step_observers == []


# Replaying a trial ----------------------------------------------------------------------------
@pytest.mark.parametrize("grasp", ["kinematic", "physical"])
def test_replayed_trial_iterations_reproduce_the_logged_events(tmp_path, grasp, request):
    from experiments.replay import render_trial
    from experiments.trial import TrialSettings, read_log, run_trial

    # Each filmed iteration costs a second of VTL synthesis (the voice or the caregiver's word).
    if grasp == "kinematic":
        # The shared trial (read only): a vocal bootstrap iteration, then the first arm
        # iteration of goal babbling, which the replay reaches through 1000 learnt iterations.
        trial = request.getfixturevalue("trained_trial").dir
        log = read_log(trial)
        voice = log["iteration"][log["motor_space"] == "voice"].iloc[0]
        arm = log["iteration"][(log["motor_space"] == "arm") & (log["iteration"] >= 1000)].iloc[0]
        iterations = [int(voice), int(arm)]
    else:
        trial = tmp_path / "trial"
        run_trial(trial, TrialSettings(grasp=grasp, iterations=20, seed=3, checkpoint_every=20),
                  progress=False)  # fmt: skip
        log = read_log(trial)
        iterations = [int(log["iteration"][log["motor_space"] == "arm"].iloc[-1])]
    path, replayed = render_trial(
        trial, tmp_path / "r.mp4", iterations=iterations, size="96x64", progress=False
    )
    assert [r.iteration for r in replayed] == iterations
    assert all(r.matches for r in replayed), [(r.logged, r.replayed) for r in replayed]
    per_iteration = video.LEAD_FRAMES + DEFAULT_WORLD.n_steps + video.HOLD_FRAMES
    assert decoded_frames(path).shape == (len(iterations) * per_iteration, 64, 96, 3)
    assert "Audio:" in stream_listing(path)


def test_render_refuses_bad_trial_input_with_one_line(tmp_path, capsys, trained_trial):
    from experiments.cli import main

    trial = trained_trial.dir
    before = sorted((p.relative_to(trial), p.stat().st_mtime_ns) for p in trial.rglob("*"))
    cases = [
        [str(trial), "--out", str(tmp_path / "a.mp4"), "--iterations", "3000"],
        [str(tmp_path / "nowhere"), "--out", str(tmp_path / "b.mp4"), "--iterations", "1"],
        [str(trial), "--out", str(tmp_path / "missing" / "c.mp4"), "--iterations", "1"],
    ]
    for argv in cases:
        assert main(["render", *argv]) == 2, argv
        err = capsys.readouterr().err
        assert len(err.strip().splitlines()) == 1, err
    assert not list(tmp_path.glob("*.mp4"))
    assert sorted((p.relative_to(trial), p.stat().st_mtime_ns) for p in trial.rglob("*")) == before
