"""`playroom bench emulated` and `make test-slow` emulate another CPU class: the settings
chosen for this CPU, and that they take effect in a process started with them."""

from __future__ import annotations

import json
import subprocess
import sys

import pytest

from experiments.bench import cpu_classes
from experiments.bench.sections import emulated_section


@pytest.mark.parametrize(
    "flags, other", [("avx2 avx512f avx512bw", "no_avx512"), ("avx2", "no_avx2")]
)
def test_the_emulated_class_follows_the_cpu(tmp_path, monkeypatch, flags, other) -> None:
    cpuinfo = tmp_path / "cpuinfo"
    cpuinfo.write_text(f"processor\t: 0\nflags\t\t: fpu sse2 {flags}\n")
    assert cpu_classes.has_avx512(str(cpuinfo)) == ("avx512f" in flags)
    monkeypatch.setattr(cpu_classes, "has_avx512", lambda: "avx512f" in flags)
    assert cpu_classes.emulated_class().name == other


def test_emulation_replaces_settings_already_made(monkeypatch) -> None:
    monkeypatch.setenv("OPENBLAS_CORETYPE", "Zen")
    monkeypatch.setenv("NUMBA_CPU_NAME", "generic")
    env = cpu_classes.emulation_environment(cpu_classes.WITHOUT_AVX2)
    assert env["OPENBLAS_CORETYPE"] == "Sandybridge" and env["NUMBA_CPU_NAME"] == "sandybridge"
    env = cpu_classes.emulation_environment(cpu_classes.WITH_AVX512)
    assert "OPENBLAS_CORETYPE" not in env and "NUMBA_CPU_NAME" not in env


def test_a_process_started_with_the_settings_runs_the_older_kernels() -> None:
    cpu = cpu_classes.emulated_class()
    script = (
        "import json; from experiments.trial_dir import provenance as p; "
        "print(json.dumps([p.simd_record()['dispatched'], p.blas_record(), p.numba_target()]))"
    )
    out = subprocess.run(
        [sys.executable, "-c", script],
        env=cpu_classes.emulation_environment(cpu),
        capture_output=True,
        text=True,
        check=True,
    ).stdout
    dispatched, blas, numba_target = json.loads(out)
    switched_off = "X86_V4" if cpu is cpu_classes.WITHOUT_AVX512 else "X86_V3"
    assert switched_off not in dispatched
    assert [b["kernel"] for b in blas] == [cpu.environment["OPENBLAS_CORETYPE"]]
    assert numba_target == cpu.environment["NUMBA_CPU_NAME"]


@pytest.mark.slow  # a bench section in a second process: about 8 s
def test_the_emulated_figures_come_from_a_process_of_the_other_class(capsys) -> None:
    figures = {name: value for name, value, _ in emulated_section(sections=("tracking",))}
    cpu = cpu_classes.emulated_class()
    assert set(figures) == {
        f"emulated_{cpu.name}_hand_tracking_error_mean",
        f"emulated_{cpu.name}_hand_tracking_error_max",
    }
    assert all(value > 0 for value in figures.values())
    printed = capsys.readouterr().out
    assert "emulated machine: " in printed
    assert cpu.environment["OPENBLAS_CORETYPE"] in printed  # the child's own kernel
