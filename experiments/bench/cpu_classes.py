"""The two x86-64 CPU classes the speed targets hold on, and how one is emulated on the other.

A trial's speed (and bits) depend on which SIMD kernels NumPy dispatches, which kernel OpenBLAS
picks and what numba compiles for: all three follow the CPU, and all three can be told to use
an older CPU's (docs/cpu-classes.md). So a machine with AVX-512 measures the class without it by
switching its AVX-512 kernels off; a machine without AVX-512 cannot switch them on, and
measures instead the next older class it can emulate (AVX without AVX2), the one `make
test-slow` runs the suite under.

`python -m experiments.bench.cpu_classes` prints the environment settings of the class to
emulate here, for the Makefile.
"""

from __future__ import annotations

import os
import shlex
import sys
from dataclasses import dataclass


@dataclass(frozen=True)
class CpuClass:
    """A class of x86-64 CPUs, and the settings that make this machine's libraries behave as
    on one of them."""

    name: str  # used in figure names: emulated_<name>_...
    description: str
    environment: dict[str, str]


WITH_AVX512 = CpuClass("avx512", "x86-64 with AVX-512 (NumPy X86_V4, OpenBLAS SkylakeX)", {})
WITHOUT_AVX512 = CpuClass(
    "no_avx512",
    "x86-64 with AVX2 but without AVX-512 (NumPy X86_V3, OpenBLAS Haswell)",
    {
        "NPY_DISABLE_CPU_FEATURES": "X86_V4 AVX512_ICL AVX512_SPR",
        "OPENBLAS_CORETYPE": "Haswell",
        "NUMBA_CPU_NAME": "haswell",
    },
)
WITHOUT_AVX2 = CpuClass(
    "no_avx2",
    "x86-64 with AVX but without AVX2 (NumPy X86_V2, OpenBLAS Sandybridge)",
    {
        "NPY_DISABLE_CPU_FEATURES": "X86_V3",
        "OPENBLAS_CORETYPE": "Sandybridge",
        "NUMBA_CPU_NAME": "sandybridge",
    },
)


def has_avx512(cpuinfo: str = "/proc/cpuinfo") -> bool:
    """Whether this CPU has AVX-512 (its foundation, avx512f), whatever the settings say."""
    try:
        with open(cpuinfo) as f:
            return any(line.startswith("flags") and " avx512f" in line for line in f)
    except OSError:  # not Linux: ask NumPy what it found (settings may hide it)
        from experiments.trial_dir.provenance import simd_record

        return "AVX512F" in simd_record()["dispatched"]


def this_class() -> CpuClass:
    return WITH_AVX512 if has_avx512() else WITHOUT_AVX512


def emulated_class() -> CpuClass:
    """The other class where it can be emulated here, else the next older one."""
    return WITHOUT_AVX512 if has_avx512() else WITHOUT_AVX2


def emulation_environment(cpu: CpuClass) -> dict[str, str]:
    """This process's environment with `cpu`'s settings (replacing any emulation already set)."""
    env = {k: v for k, v in os.environ.items() if k not in WITHOUT_AVX512.environment}
    return env | cpu.environment


def shell_assignments(cpu: CpuClass) -> str:
    """`NAME=value ...`, quoted for a shell (the Makefile's `env $(OTHER_CPU) ...`)."""
    return " ".join(f"{k}={shlex.quote(v)}" for k, v in cpu.environment.items())


if __name__ == "__main__":
    sys.stdout.write(shell_assignments(emulated_class()) + "\n")
