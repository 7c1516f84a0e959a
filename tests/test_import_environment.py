"""Importing the packages changes no environment variable (docs/usage.md), whatever the
libraries they import do at theirs: threadpoolctl (through scipy.io) sets KMP_DUPLICATE_LIB_OK,
which would hide two OpenMP runtimes in a process with torch, and Gymnasium sets
PYGAME_HIDE_SUPPORT_PROMPT."""

from __future__ import annotations

import json
import os
import subprocess
import sys

import pytest

# Every public module of a package, imported in a fresh process; the variables that changed.
CODE = """
import importlib, json, os, pkgutil, sys
before = dict(os.environ)
package = importlib.import_module(sys.argv[1])
names = [
    info.name
    for info in pkgutil.walk_packages(package.__path__, package.__name__ + ".")
    if not any(part.startswith("_") for part in info.name.split("."))
]
for name in names:
    importlib.import_module(name)
after = dict(os.environ)
changed = {k: [before.get(k), after.get(k)] for k in before.keys() | after.keys()
           if before.get(k) != after.get(k)}
print(json.dumps({"modules": len(names), "changed": changed}))
"""


@pytest.mark.parametrize("package", ["models", "sim", "learner", "experiments"])
def test_importing_a_package_and_its_public_modules_changes_no_environment_variable(package):
    # MUJOCO_GL unset, as on most machines (a user's EGL choice makes mujoco set
    # PYOPENGL_PLATFORM, its own business); the variables the libraries set, unset.
    dropped = ("MUJOCO_GL", "KMP_DUPLICATE_LIB_OK", "PYGAME_HIDE_SUPPORT_PROMPT")
    env = {k: v for k, v in os.environ.items() if k not in dropped}
    result = subprocess.run(
        [sys.executable, "-c", CODE, package], env=env, capture_output=True, text=True
    )
    assert result.returncode == 0, result.stderr[-3000:]
    report = json.loads(result.stdout)
    assert report["modules"] > 0
    assert report["changed"] == {}


def test_a_value_the_user_set_is_kept():
    env = dict(os.environ, KMP_DUPLICATE_LIB_OK="FALSE", PYGAME_HIDE_SUPPORT_PROMPT="1")
    code = (
        "import os, sim.envs.gym_env; "
        "print(os.environ['KMP_DUPLICATE_LIB_OK'], os.environ['PYGAME_HIDE_SUPPORT_PROMPT'])"
    )
    result = subprocess.run([sys.executable, "-c", code], env=env, capture_output=True, text=True)
    assert result.stdout.split() == ["FALSE", "1"]
