"""A GL library that MUJOCO_GL names but that cannot be loaded (an empty libEGL.so.1, as on many
cluster nodes): one line naming the variable, the library and what to do, from the command line
and from `import sim`'s room; and with MUJOCO_GL unset, everything that does not render works
there, the non-rendering tests included."""

from __future__ import annotations

import os
import subprocess
import sys
from pathlib import Path

import pytest

PLAYROOM = [sys.executable, "-m", "experiments.cli.main"]
ROOT = Path(__file__).resolve().parent.parent
LINE = (
    "MUJOCO_GL=egl but the EGL library cannot be loaded ({lib}: file too short); unset "
    "MUJOCO_GL for commands that do not render, or install libEGL (libegl1 on Debian/Ubuntu, "
    "mesa-libEGL on Fedora) or use MUJOCO_GL=osmesa"
)


@pytest.fixture
def broken_egl(tmp_path) -> tuple[dict[str, str], str]:
    """An environment whose libEGL cannot be loaded, MUJOCO_GL unset, and the file PyOpenGL
    tries first: empty files under every name PyOpenGL tries, first on LD_LIBRARY_PATH."""
    libs = tmp_path / "broken-egl"
    libs.mkdir()
    names = ["libEGL.so", *(f"libEGL.so.{i}" for i in range(10))]
    for name in names:
        (libs / name).write_bytes(b"")
    env = {k: v for k, v in os.environ.items() if k != "MUJOCO_GL"}
    env["LD_LIBRARY_PATH"] = os.pathsep.join([str(libs), env.get("LD_LIBRARY_PATH", "")])
    return env, str(libs / names[0])


def _python(env: dict, code: str) -> subprocess.CompletedProcess:
    return subprocess.run(
        [sys.executable, "-c", code], env=env, capture_output=True, text=True, cwd=ROOT
    )


def test_the_emulation_really_breaks_pyopengls_egl(broken_egl):
    # Without it, the tests below would prove nothing.
    env, _ = broken_egl
    result = _python(dict(env, PYOPENGL_PLATFORM="egl"), "import OpenGL.EGL")
    assert "has no attribute 'eglQueryString'" in result.stderr


@pytest.mark.parametrize("command", [["batch", "--profile", "smoke"], ["report", "nowhere"]])
def test_a_command_names_the_unloadable_library_in_one_line(broken_egl, tmp_path, command):
    env, lib = broken_egl
    argv = [*command, "--out", str(tmp_path / "out")] if command[0] == "batch" else command
    result = subprocess.run(
        [*PLAYROOM, *argv], env=dict(env, MUJOCO_GL="egl"), capture_output=True, text=True,
        cwd=tmp_path,
    )  # fmt: skip
    assert result.returncode == 2
    assert result.stderr.splitlines() == [f"playroom {command[0]}: error: {LINE.format(lib=lib)}"]
    assert not (tmp_path / "out").exists()


def test_the_room_names_the_unloadable_library(broken_egl):
    env, lib = broken_egl
    result = _python(dict(env, MUJOCO_GL="egl"), "from sim import Playroom")
    assert result.stderr.strip().splitlines()[-1] == f"ImportError: {LINE.format(lib=lib)}"


def test_with_mujoco_gl_unset_the_room_and_its_environments_work_and_rendering_says_why_not(
    broken_egl,
):
    env, lib = broken_egl
    code = """
import gymnasium, sim
sim.Playroom(grasp="physical").act_arm([0.1] * 21)
env = gymnasium.make("sim.envs:Playroom-v1", max_episode_steps=10, render_mode="rgb_array")
env.reset(seed=0)
env.step(env.action_space.sample())
print("stepped", flush=True)
env.render()
"""
    result = _python(env, code)
    assert result.stdout == "stepped\n"
    assert result.stderr.strip().splitlines()[-1] == (
        f"sim.envs.rendering.RenderError: {LINE.format(lib=lib)}"
    )


def test_without_glfw_either_the_room_still_works(broken_egl, tmp_path):
    # Where GLFW cannot be imported, dm_control's own choice goes on to the broken EGL
    # (sim/dm_control_import.py).
    env, _ = broken_egl
    fake = tmp_path / "no-glfw" / "glfw"
    fake.mkdir(parents=True)
    (fake / "__init__.py").write_text("raise ImportError('glfw: none on this machine (test)')\n")
    env = dict(env, PYTHONPATH=os.pathsep.join([str(ROOT), str(fake.parent)]))
    code = "import os, sim; sim.Playroom(grasp='physical').act_arm([0.1] * 21); print('acted')"
    result = _python(env, code)
    assert result.stdout == "acted\n", result.stderr[-2000:]


# About 15 s: pytest in a fresh process, collecting and running one test file.
def test_the_non_rendering_tests_pass_there(broken_egl):
    env, _ = broken_egl
    result = subprocess.run(
        [sys.executable, "-m", "pytest", "-q", "-n", "0", "-p", "no:cacheprovider",
         "tests/sim/envs/test_envs.py", "-k", "refuse"],
        env=env, capture_output=True, text=True, cwd=ROOT,
    )  # fmt: skip
    assert result.returncode == 0, result.stdout[-3000:]
