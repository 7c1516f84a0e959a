"""What an import loads: reading results, drawing pages, building the command line's parser and
recording provenance load no simulator, so that they run on any machine, quickly (the layering
itself is checked by `make lint`: pyproject.toml's [tool.importlinter])."""

from __future__ import annotations

import subprocess
import sys

import pytest

SIMULATOR = ("mujoco", "dm_control", "numba", "sim", "learner")
# What a reader of trials loads of sim: the plain settings dataclasses, whose fields declare
# what older trials ran with (experiments/trial_dir/config_file.py), and the package's face (its GL
# library check and environment guard, plain Python); no room, no tract.
SIM_SETTINGS = (
    "sim",
    "sim.gl_library",
    "sim.process_environment",
    "sim.config",
    "sim.vocal",
    "sim.vocal.config",
)


@pytest.mark.parametrize(
    "statement, not_loaded",
    [
        ("import experiments.analysis.results", SIMULATOR),
        ("import experiments.analysis.stats", SIMULATOR),
        ("import experiments.report.comparison", SIMULATOR),
        ("from experiments.analysis.logs import read_log, read_batch_logs", SIMULATOR),
        # The trial directory's package, whole: its two faces, its layout, schema, records,
        # checks and checkpoint restore (into an agent and room the run's stage builds).
        (
            "import experiments.trial_dir.layout, experiments.trial_dir.log_schema, "
            "experiments.trial_dir.backend_record, experiments.trial_dir.checks, "
            "experiments.trial_dir.opening, experiments.trial_dir.reading, "
            "experiments.trial_dir.writing",
            SIMULATOR,
        ),
        # Naming and checking the grasp backends imports none of them.
        ("from sim.grasping.names import GRASPS", ("mujoco", "dm_control", "numba")),
        # The parser reads the settings' allowed values from sim.config and learner.config.
        (
            "from experiments.cli.main import build_parser; build_parser()",
            ("mujoco", "dm_control", "numba"),
        ),
        (
            "from experiments.trial_dir.provenance import machine_record; machine_record()",
            ("mujoco", "dm_control", "pandas"),
        ),
    ],
)
def test_an_import_loads_only_what_it_needs(statement, not_loaded):
    # A package named here counts with its modules, but for sim's plain settings.
    code = (
        f"import sys; {statement}; print(' '.join(m for m in sys.modules "
        f"if m.split('.')[0] in {not_loaded!r} and m not in {SIM_SETTINGS!r}))"
    )
    loaded = subprocess.run(
        [sys.executable, "-c", code], capture_output=True, text=True, check=True
    )
    assert loaded.stdout.strip() == ""


def test_no_module_of_sim_imports_the_package_or_a_module_that_imports_it_back():
    """sim's import graph has no cycle, its package `__init__` included (docs/architecture.md,
    "sim/ inside"): the package's face imports only plain modules, none of which imports it."""
    import grimp

    graph = grimp.build_graph("sim", include_external_packages=False)
    assert graph.find_modules_that_directly_import("sim") == set()
    for module in graph.modules:
        for imported in graph.find_modules_directly_imported_by(module):
            assert not graph.chain_exists(imported, module), f"{module} <-> {imported}"
