"""OpenGL only where something renders: a machine without GL libraries runs and evaluates
batches, and rendering there fails in one line that names MUJOCO_GL."""

from __future__ import annotations

import json
import os
import subprocess
import sys
from pathlib import Path

import pytest

PLAYROOM = [sys.executable, "-m", "experiments.cli.main"]


@pytest.fixture
def no_gl_env(tmp_path) -> dict[str, str]:
    """An environment as on a cluster node without graphics libraries: the Python GL bindings
    (PyOpenGL, GLFW) fail to import, libEGL.so.1 is an empty file, MUJOCO_GL is unset."""
    fake = tmp_path / "no-gl"
    for package in ("OpenGL", "glfw"):
        (fake / package).mkdir(parents=True)
        (fake / package / "__init__.py").write_text(
            f"raise ImportError('{package}: no GL library on this machine (test)')\n"
        )
    libs = tmp_path / "no-egl"
    libs.mkdir()
    (libs / "libEGL.so.1").write_bytes(b"")
    env = {k: v for k, v in os.environ.items() if k != "MUJOCO_GL"}
    env["PYTHONPATH"] = os.pathsep.join([str(fake), env.get("PYTHONPATH", "")]).rstrip(os.pathsep)
    env["LD_LIBRARY_PATH"] = os.pathsep.join([str(libs), env.get("LD_LIBRARY_PATH", "")])
    return env


def _playroom(env: dict, *args: str, cwd: Path) -> subprocess.CompletedProcess:
    return subprocess.run([*PLAYROOM, *args], capture_output=True, text=True, env=env, cwd=cwd)


def test_fake_gl_really_breaks_rendering_imports(no_gl_env, tmp_path):
    # The fixture must make a GL import fail, or the batch test below would prove nothing.
    code = "import OpenGL"
    result = subprocess.run([sys.executable, "-c", code], env=no_gl_env, capture_output=True)
    assert result.returncode != 0 and b"no GL library" in result.stderr


# About 20 s (a local cluster and three fresh interpreters): `make test-slow` runs it; the quick
# suite keeps the import checks below and tests/test_layers.py.
@pytest.mark.slow
def test_batch_report_and_compare_run_without_any_gl_library(no_gl_env, tmp_path):
    config = tmp_path / "tiny.json"
    config.write_text(
        json.dumps(
            {
                "grasps": ["kinematic", "physical"],
                "seeds": [0],
                "iterations": 30,
                "checkpoint_every": 30,
                "eval_placements": 2,
            }
        )  # fmt: skip
    )
    batch = tmp_path / "batch"
    result = _playroom(
        no_gl_env, "batch", "--config", str(config), "--out", str(batch), "--workers", "1",
        cwd=tmp_path,
    )  # fmt: skip
    assert result.returncode == 0, result.stderr
    assert "2 trials complete" in result.stdout
    for name in ("kinematic-random-seed0000", "physical-random-seed0000"):
        assert (batch / name / "eval.json").exists()
    few = ["--study-reference-commands", "10"]
    report = _playroom(no_gl_env, "report", str(batch), *few, cwd=tmp_path)
    assert report.returncode == 0, report.stderr
    compare = _playroom(
        no_gl_env, "compare", str(batch), str(batch), "--out", str(tmp_path / "cmp"), *few,
        "--grasp-rate-commands", "20", cwd=tmp_path,
    )  # fmt: skip
    assert compare.returncode == 0, compare.stderr


def test_render_without_gl_is_one_line_naming_mujoco_gl(no_gl_env, tmp_path):
    out = tmp_path / "v.mp4"
    result = _playroom(no_gl_env, "render", "--random", "--out", str(out), cwd=tmp_path)
    assert result.returncode == 2
    lines = result.stderr.strip().splitlines()
    assert len(lines) == 1, result.stderr
    assert "MUJOCO_GL" in lines[0] and "egl, osmesa, glfw" in lines[0]
    assert not out.exists()


def test_an_unknown_backend_is_one_line_naming_the_choices(tmp_path):
    env = dict(os.environ, MUJOCO_GL="vulkan")
    result = _playroom(env, "render", "--random", "--out", str(tmp_path / "v.mp4"), cwd=tmp_path)
    assert result.returncode == 2
    assert "MUJOCO_GL='vulkan' cannot render" in result.stderr
    assert len(result.stderr.strip().splitlines()) == 1


def test_importing_the_packages_leaves_the_environment_alone():
    code = (
        "import os, sim, learner, experiments.run.trial, experiments.batches.runner, "
        "experiments.report.batch_report; "
        "sim.Playroom('kinematic'); print(os.environ.get('MUJOCO_GL'))"
    )
    env = {k: v for k, v in os.environ.items() if k != "MUJOCO_GL"}
    result = subprocess.run([sys.executable, "-c", code], env=env, capture_output=True, text=True)
    assert result.returncode == 0, result.stderr
    assert result.stdout.strip() == "None"


def test_using_sim_on_a_headless_machine_prints_nothing():
    # dm_control tries GLFW when MUJOCO_GL is unset; without a display GLFW used to warn
    # "The DISPLAY environment variable is missing" on every import of the room.
    env = {k: v for k, v in os.environ.items() if k not in ("MUJOCO_GL", "DISPLAY")}
    code = "import sim; sim.Playroom('kinematic').act_arm([0.1] * 21)"
    result = subprocess.run([sys.executable, "-c", code], env=env, capture_output=True, text=True)
    assert result.returncode == 0, result.stderr
    assert result.stderr == ""


def test_a_missing_gl_library_is_named_with_its_package(monkeypatch):
    import ctypes.util

    from experiments.video import gl

    real = ctypes.util.find_library
    monkeypatch.setattr(
        ctypes.util, "find_library", lambda name: None if name == "OSMesa" else real(name)
    )
    monkeypatch.setenv(gl.VARIABLE, "osmesa")
    with pytest.raises(gl.GLError) as caught:
        gl.for_rendering()
    message = str(caught.value)
    assert message.startswith("libOSMesa not found")
    assert "libosmesa6" in message and "mesa-libOSMesa" in message and "\n" not in message


@pytest.mark.skipif(
    __import__("ctypes.util").util.find_library("OSMesa") is not None,
    reason="libOSMesa is installed here: nothing is missing",
)
def test_render_with_osmesa_absent_is_one_line_naming_the_package(tmp_path):
    env = dict(os.environ, MUJOCO_GL="osmesa")
    result = _playroom(env, "render", "--random", "--out", str(tmp_path / "v.mp4"), cwd=tmp_path)
    assert result.returncode == 2
    assert result.stderr.strip().splitlines() == [
        "playroom render: error: libOSMesa not found (MUJOCO_GL=osmesa): install the system "
        "package libosmesa6 (Debian/Ubuntu) or mesa-libOSMesa (Fedora), or set MUJOCO_GL to one "
        "of egl, osmesa, glfw"
    ]
