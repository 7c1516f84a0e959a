"""The video tests render in this process, whatever backend MuJoCo chose when it was imported
(GLFW with MUJOCO_GL unset, which needs a display; none after a non-rendering command ran
here): each test renders offscreen with the backend a rendering command would choose, MUJOCO_GL's
value or EGL (experiments/video/gl.py), its context made by sim/envs/rendering.py."""

from __future__ import annotations

import os

import pytest

from experiments.video import gl


@pytest.fixture(autouse=True)
def offscreen_rendering(monkeypatch):
    import mujoco
    from mujoco.rendering.classic import gl_context

    from sim.envs.rendering import RenderError, context_class

    chosen = os.environ.get(gl.VARIABLE, "").strip().lower()
    monkeypatch.setenv(
        gl.VARIABLE, chosen if chosen in gl.RENDER_BACKENDS else gl.DEFAULT_RENDER_BACKEND
    )
    try:
        context = context_class()
    except RenderError:
        # No backend renders here: the rendering tests fail with the renderer's own one line
        # naming MUJOCO_GL, and the others (the checks of GL's absence among them) run.
        return
    # mujoco.Renderer makes its context from gl_context.GLContext; gl.for_rendering checks
    # mujoco.GLContext against MUJOCO_GL.
    monkeypatch.setattr(gl_context, "GLContext", context)
    monkeypatch.setattr(mujoco, "GLContext", context, raising=False)
