"""Videos: frames per control step, overlay, projection, sound track, and bad input."""

from __future__ import annotations

import os
import subprocess
import sys

import imageio_ffmpeg
import mujoco
import numpy as np
import pytest
from scripted import Waypoint, arm_command_through
from video_checks import (
    FPS,
    HOLD,
    LEAD,
    SIZE,
    STEPS,
    TONE_S,
    decoded_frames,
    decoded_sound,
    stream_listing,
    tone,
)

from experiments.video import encoding, episodes, recording
from experiments.video.overlay import CameraView
from models.layout import N_STEPS, VOICE_DIM
from sim import Playroom
from sim.config import world_preset
from sim.vocal.audio import write_wav

# The world these tests were written for: the project preset (explicit, as Playroom() takes
# the default preset, the study's).
PROJECT = world_preset("project")


@pytest.fixture(scope="module")
def reach_command() -> np.ndarray:
    """An arm command sweeping the hand from rest to the right and down: a large motion."""
    m, _ = arm_command_through([Waypoint(25, (0.35, 0.2)), Waypoint(50, (0.2, -0.3))])
    return m


@pytest.mark.parametrize("grasp", ["kinematic", "physical"])
def test_short_render_has_frames_sound_and_motion(grasp, reach_command, tmp_path):
    room = Playroom(grasp=grasp, seed=0, config=PROJECT)
    out = tmp_path / "short.mp4"
    per_iteration = LEAD + STEPS + HOLD
    with episodes.EpisodeRenderer(SIZE, FPS, lead_frames=LEAD, hold_frames=HOLD) as renderer:
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

    episodes.render_random(
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
    room = Playroom(grasp="kinematic", seed=0, config=PROJECT)
    # Asymmetric places, so that a flipped axis would miss.
    room.arrange(toys=np.array([[0.45, -0.3], [-0.6, 0.25], [0.15, 0.7]]))
    model, data = room.physics.model.ptr, room.physics.data.ptr
    size = (320, 240)
    with recording.FrameRecorder(room, size, camera=camera) as recorder:
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


@pytest.mark.parametrize("size", ["0x120", "160", "abc", "161x120", (160,), (160.0, 120), (-2, 4)])
def test_bad_size_is_refused(size):
    with pytest.raises(ValueError, match="size"):
        recording.parse_size(size)


def test_size_text_is_parsed():
    assert recording.parse_size("640x480") == (640, 480)
    assert recording.parse_size((160, 120)) == (160, 120)


def test_bad_output_fails_before_rendering(tmp_path, monkeypatch):
    def no_room(*args, **kwargs):
        raise AssertionError("a room was built before the output path was checked")

    monkeypatch.setattr(episodes, "Playroom", no_room)
    with pytest.raises(ValueError, match="does not exist"):
        episodes.render_random("kinematic", 0, tmp_path / "missing" / "out.mp4", size=SIZE)
    with pytest.raises(ValueError, match="is a directory"):
        episodes.render_random("kinematic", 0, tmp_path, size=SIZE)
    if os.geteuid() != 0:  # root may write anywhere
        locked = tmp_path / "locked"
        locked.mkdir(mode=0o500)
        with pytest.raises(ValueError, match="not writable"):
            episodes.render_random("kinematic", 0, locked / "out.mp4", size=SIZE)


def test_failed_mux_is_a_render_error(tmp_path):
    wav = tmp_path / "sound.wav"
    write_wav(wav, np.zeros(100), 8000)
    with pytest.raises(encoding.RenderError, match="ffmpeg failed"):
        encoding.mux(tmp_path / "no_such_video.mp4", wav, tmp_path / "out.mp4")


def test_unknown_camera_is_refused(tmp_path):
    with pytest.raises(ValueError, match="camera"):
        episodes.render_random("kinematic", 0, tmp_path / "out.mp4", size=SIZE, camera="side")


def test_missing_gl_names_mujoco_gl_and_its_choices(monkeypatch):
    def no_gl(*args, **kwargs):
        raise RuntimeError("eglInitialize failed")

    monkeypatch.setattr(recording.mujoco, "Renderer", no_gl)
    room = Playroom(grasp="kinematic", seed=0, config=PROJECT)
    with pytest.raises(encoding.RenderError, match="MUJOCO_GL to one of egl, osmesa, glfw"):
        recording.FrameRecorder(room, SIZE)


def test_refused_command_adds_no_frames():
    room = Playroom(grasp="kinematic", seed=0, config=PROJECT)
    with episodes.EpisodeRenderer(SIZE, lead_frames=LEAD, hold_frames=HOLD) as renderer:
        with pytest.raises(ValueError):
            renderer.render_iteration(room, "arm", np.full(21, 2.0))
        assert renderer.n_frames == 0
        assert not room.tracing  # the film left the room as it found it


def test_rendering_after_write_is_refused(reach_command, tmp_path):
    room = Playroom(grasp="kinematic", seed=0, config=PROJECT)
    with episodes.EpisodeRenderer(SIZE, lead_frames=0, hold_frames=0) as renderer:
        renderer.render_iteration(room, "arm", reach_command)
        renderer.write(tmp_path / "once.mp4")
        # A new stream would overwrite the frames already written.
        with pytest.raises(RuntimeError, match="already written"):
            renderer.render_iteration(room, "arm", reach_command)


# The split-out parts: WAV writing, the sound track, encoding ------------------------------------


def test_video_modules_leave_mujoco_gl_to_the_caller():
    """Only the command chooses the GL backend (experiments/video/gl.py); encoding and sound need
    no mujoco at all."""
    code = (
        "import os, sys\n"
        "import experiments.video.encoding, experiments.video.sound\n"
        "assert 'mujoco' not in sys.modules, 'encoding or sound imported mujoco'\n"
        "import experiments.video.episodes\n"
        "print(os.environ.get('MUJOCO_GL', 'unset'))\n"
    )
    env = {k: v for k, v in os.environ.items() if k != "MUJOCO_GL"}
    result = subprocess.run([sys.executable, "-c", code], env=env, capture_output=True, text=True)
    assert result.returncode == 0, result.stderr
    assert result.stdout.strip() == "unset"


# Replaying a trial ----------------------------------------------------------------------------
@pytest.mark.slow  # 3.5-8 s each: in make test-slow, to keep make test's pytest under 2 minutes
@pytest.mark.parametrize("grasp", ["kinematic", "physical"])
def test_replayed_trial_iterations_reproduce_the_logged_events(tmp_path, grasp, request):
    from experiments.analysis.logs import read_log
    from experiments.run.settings import TrialSettings
    from experiments.run.trial import run_trial
    from experiments.video.replay import render_trial

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
    per_iteration = episodes.LEAD_FRAMES + N_STEPS + episodes.HOLD_FRAMES
    assert decoded_frames(path).shape == (len(iterations) * per_iteration, 64, 96, 3)
    assert "Audio:" in stream_listing(path)


def test_render_refuses_bad_trial_input_with_one_line(tmp_path, capsys, trained_trial):
    from experiments.cli.main import main

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


def test_a_diva_film_sounds_through_its_tract_and_says_what_the_sound_is(
    tmp_path, installed_generated_map
):
    """A DIVA room's voice and words come from DIVA's formants through the formant synthesizer,
    and every frame's caption says the sound is not DIVA's own."""
    from sim.vocal.diva.sound import SOUND_LABEL

    out = tmp_path / "diva.mp4"
    captions = []
    real_draw = episodes.Overlay.draw

    def draw(self, frame, view, caption, *args):
        captions.append(caption.sound)
        return real_draw(self, frame, view, caption, *args)

    with pytest.MonkeyPatch.context() as patch:
        patch.setattr(episodes.Overlay, "draw", draw)
        episodes.render_random(
            "kinematic", 3, out, 2, SIZE, voice="diva", sound=True, lead_frames=0, hold_frames=0
        )
    assert captions and set(captions) == {SOUND_LABEL}
    assert "Audio:" in stream_listing(out)
    wave, _ = decoded_sound(out, tmp_path)
    assert np.abs(wave).max() > 1000  # the agent's sound or the caregiver's word is heard


@pytest.mark.parametrize("damage", ["foreign chunk", "truncated chunk", "broken config"])
def test_d1_render_of_a_damaged_trial_is_one_line_naming_the_file(
    tmp_path, capsys, trained_trial, batches, damage
):
    import shutil

    from experiments.cli.main import main

    trial = tmp_path / "trial"
    shutil.copytree(trained_trial.dir, trial)
    chunk = trial / "log" / "iterations" / "chunk-00000000.parquet"
    if damage == "foreign chunk":  # another trial's first chunk in its place
        other = batches["kinematic"] / "kinematic-random-seed0000" / "log" / "iterations"
        shutil.copy(other / "chunk-00000000.parquet", chunk)
        named = chunk.name
    elif damage == "truncated chunk":
        chunk.write_bytes(chunk.read_bytes()[:500])
        named = chunk.name
    else:
        (trial / "config.json").write_text('{"trial": ')
        named = "config.json"
    code = main(["render", str(trial), "--out", str(tmp_path / "a.mp4"), "--iterations", "5"])
    err = capsys.readouterr().err.strip().splitlines()
    assert code == 2 and len(err) == 1 and named in err[0], err
    assert not (tmp_path / "a.mp4").exists()
