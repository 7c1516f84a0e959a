"""Experiments: the command line, trials, evaluation, batches, reports, videos, bench.

Importing it changes nothing in the process: the `playroom` command chooses MuJoCo's OpenGL
backend per command (experiments/video/gl.py), before anything imports mujoco.
"""
