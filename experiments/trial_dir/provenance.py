"""Where a trial was computed: the machine, the libraries and the code (`provenance.json`).

A trial is bit-identical when it is run again on one machine with one set of libraries;
elsewhere it gives the same statistics, not the same bits: NumPy's SIMD dispatch, OpenBLAS's
kernel for the CPU and numba's code for the host CPU change last bits, and the physics'
contacts amplify them. So each trial records who computed it: `provenance.json` in the trial
directory is a list of entries `{"from_iteration": N, "record": machine_record()}`, one per
run or resume (the record is null for iterations computed before provenance was recorded):
provenance_file.py. This module makes and compares the records.

Only the standard library, NumPy and threadpoolctl are imported: recording costs a few
hundredths of a second and loads neither MuJoCo nor pandas. Versions are read from the
installed distributions' metadata, not by importing the packages.
"""

from __future__ import annotations

import datetime
import os
import platform
import socket
import subprocess
from importlib import metadata
from pathlib import Path
from typing import Any

# Distributions whose code computes a trial: a change of version may change its bits.
COMPUTING = (
    "playroom",
    "numpy",
    "scipy",
    "numba",
    "llvmlite",
    "mujoco",
    "dm-control",
    "vocaltractlab-cython",
)
# Recorded, not compared: they store and read results, they compute none of them.
RECORDED_ONLY = ("pandas", "pyarrow", "threadpoolctl")
# Environment variables that change what the libraries compute with (SIMD paths, BLAS
# kernels, numba's target CPU), recorded when set. PYTHONHASHSEED is left out: a trial
# resumed in a new process (another hash seed) gives the same bits (tests/run/test_trial.py),
# and pytest-xdist sets it in its workers. Thread counts are left out:
# Dask's nanny sets OMP_NUM_THREADS=1 and its kin in batch workers, and a trial's matrices
# are too small for OpenBLAS to split (a split would not reorder a sum anyway).
BIT_ENVIRONMENT = (
    "NPY_DISABLE_CPU_FEATURES",
    "NPY_ENABLE_CPU_FEATURES",
    "OPENBLAS_CORETYPE",
    "MKL_CBWR",
    "MKL_ENABLE_INSTRUCTIONS",
    "NUMBA_CPU_NAME",
    "NUMBA_CPU_FEATURES",
    "NUMBA_OPT",
    "NUMBA_DISABLE_JIT",
)
GIT_TIMEOUT_S = 5
INSTALLED = "installed package"


def _version(distribution: str) -> str | None:
    try:
        return metadata.version(distribution)
    except metadata.PackageNotFoundError:
        return None


def _git(root: Path, *args: str) -> str:
    # No optional locks: `git status` must not take the index lock of a checkout in use.
    env = {**os.environ, "GIT_OPTIONAL_LOCKS": "0"}
    done = subprocess.run(
        ["git", "-C", str(root), *args],
        capture_output=True,
        text=True,
        timeout=GIT_TIMEOUT_S,
        env=env,
        check=True,
    )
    return done.stdout.strip()


def source_record(root: Path | None = None) -> dict[str, Any]:
    """The code's commit: {"commit", "dirty", "where"}. `root` (default: the directory the
    running `experiments` package was imported from) counts as a checkout only when it is a
    git repository's top level, so that a package installed inside some other repository
    (a virtual environment in a checkout) is not given that repository's commit. Dirty means
    tracked files differ from the commit; untracked files (trial directories) do not count."""
    root = Path(root) if root is not None else Path(__file__).resolve().parents[2]
    try:
        top = Path(_git(root, "rev-parse", "--show-toplevel")).resolve()
        if top != root.resolve():
            return {"commit": None, "dirty": None, "where": INSTALLED}
        commit = _git(root, "rev-parse", "HEAD")
        dirty = bool(_git(root, "status", "--porcelain", "--untracked-files=no"))
    except subprocess.CalledProcessError as exc:  # not a repository, or git refuses it
        if not (root / ".git").exists():
            return {"commit": None, "dirty": None, "where": INSTALLED}
        why = (exc.stderr or "").strip().splitlines()[:1] or [f"exit code {exc.returncode}"]
        return {"commit": None, "dirty": None, "where": f"unknown (git: {why[0]})"}
    except (OSError, subprocess.TimeoutExpired) as exc:  # no git, or a hung file system
        return {"commit": None, "dirty": None, "where": f"unknown (git: {type(exc).__name__})"}
    return {"commit": commit, "dirty": dirty, "where": "git checkout"}


def cpu_model() -> str:
    """The CPU's model name (/proc/cpuinfo on Linux, else what `platform` knows)."""
    try:
        with open("/proc/cpuinfo", encoding="utf-8", errors="replace") as f:
            for line in f:
                key, _, value = line.partition(":")
                if key.strip() in ("model name", "Model", "Hardware"):
                    return value.strip()
    except OSError:
        pass
    return platform.processor() or platform.machine() or "unknown"


def simd_record() -> dict[str, list[str]]:
    """NumPy's SIMD, as `numpy.show_runtime` reports it: the baseline it was built for and the
    dispatched targets found on this CPU (and left on by NPY_DISABLE_CPU_FEATURES)."""
    try:
        # A private module, absent from NumPy's stubs.
        from numpy._core import _multiarray_umath as umath  # type: ignore[attr-defined]
    except ImportError:  # NumPy 1.x kept it in numpy.core
        from numpy.core import _multiarray_umath as umath
    found = umath.__cpu_features__
    return {
        "baseline": list(umath.__cpu_baseline__),
        "dispatched": [f for f in umath.__cpu_dispatch__ if found.get(f)],
    }


def blas_record() -> list[dict[str, Any]]:
    """NumPy's BLAS library as loaded in this process: library, version, kernel (the CPU type
    OpenBLAS chose), threading. Libraries under NumPy's own directories when it ships one;
    otherwise every BLAS library loaded (a system or conda BLAS that NumPy links)."""
    import numpy
    import threadpoolctl

    found = [i for i in threadpoolctl.threadpool_info() if i.get("user_api") == "blas"]
    numpy_dir = Path(numpy.__file__).resolve().parent
    own_dirs = (numpy_dir, numpy_dir.parent / "numpy.libs")
    own = [i for i in found if any(d in Path(i["filepath"]).resolve().parents for d in own_dirs)]
    return [
        {
            "library": i.get("internal_api"),
            "version": i.get("version"),
            "kernel": i.get("architecture"),
            "threading": i.get("threading_layer"),
            "threads": i.get("num_threads"),
            "file": Path(i["filepath"]).name,
        }
        for i in (own or found)
    ]


def numba_target() -> str | None:
    """The CPU numba compiles for (LLVM's name of the host CPU, or NUMBA_CPU_NAME)."""
    if os.environ.get("NUMBA_CPU_NAME"):
        return os.environ["NUMBA_CPU_NAME"]
    try:
        import llvmlite.binding

        return str(llvmlite.binding.get_host_cpu_name())
    except (ImportError, RuntimeError):
        return None


def machine_record() -> dict[str, Any]:
    """Everything that decides a trial's bits besides its config, plus where and when."""
    return {
        "recorded_at": datetime.datetime.now(datetime.UTC).isoformat(timespec="seconds"),
        "host": socket.gethostname(),
        "cpu": {
            "model": cpu_model(),
            "machine": platform.machine(),
            "cores": os.cpu_count(),
            "numba_target": numba_target(),
        },
        "simd": simd_record(),
        "blas": blas_record(),
        "versions": {
            "python": platform.python_version(),
            **{name: _version(name) for name in COMPUTING + RECORDED_ONLY},
        },
        "environment": {k: os.environ[k] for k in BIT_ENVIRONMENT if k in os.environ},
        "platform": platform.platform(),
        "source": source_record(),
    }


def bit_differences(a: dict, b: dict) -> list[str]:
    """What differs between two records in what can change a trial's bits, one short phrase
    each ("numpy 2.4.6 -> 2.4.7"); empty when the machine and libraries agree.

    Compared: the CPU model and architecture, numba's target CPU, NumPy's SIMD baseline and
    dispatched features, each BLAS library's name, version and kernel, the versions of the
    computing libraries (COMPUTING, Python included), the bit-changing environment variables,
    the user's data (`inputs`), and the commit when both records know it. Not compared: the
    host name (the same machine image under another name computes the same bits), the time,
    the core count and BLAS threads (the machine's size, not its arithmetic: the trial's
    matrices are small), the platform string (the kernel's release), the dirty flag (it does
    not say what changed), and pandas, pyarrow, threadpoolctl, which only store and read
    results."""
    out = []

    def differ(label: str, x: Any, y: Any) -> None:
        if x != y:
            out.append(f"{label} {_text(x)} -> {_text(y)}")

    ca, cb = _part(a, "cpu"), _part(b, "cpu")
    for key, label in (("model", "CPU"), ("machine", "arch"), ("numba_target", "numba CPU")):
        differ(label, ca.get(key), cb.get(key))
    for key in ("baseline", "dispatched"):
        differ(f"SIMD {key}", _part(a, "simd").get(key), _part(b, "simd").get(key))
    differ("BLAS", _blas_text(a.get("blas")), _blas_text(b.get("blas")))
    va, vb = _part(a, "versions"), _part(b, "versions")
    for name in ("python", *COMPUTING):
        differ(name, va.get(name), vb.get(name))
    ea, eb = _part(a, "environment"), _part(b, "environment")
    for key in sorted(set(ea) | set(eb)):
        differ(key, ea.get(key, "unset"), eb.get(key, "unset"))
    ia, ib = _part(a, "inputs"), _part(b, "inputs")
    for key in sorted(set(ia) | set(ib)):
        differ(key, ia.get(key, "none"), ib.get(key, "none"))
    commit_a, commit_b = (_part(r, "source").get("commit") for r in (a, b))
    if commit_a and commit_b:
        differ("commit", commit_a[:10], commit_b[:10])
    return out


def _part(record: dict, key: str) -> dict:
    """A section of a record; {} when it is missing or not a dict (a hand-edited file)."""
    part = record.get(key)
    return part if isinstance(part, dict) else {}


def _text(value: Any) -> str:
    if isinstance(value, list):
        return "[" + " ".join(map(str, value)) + "]"
    return str(value)


def _blas_text(blas: Any) -> str:
    """'openblas 0.3.31 Haswell' per library, joined by '; '."""
    blas = [b for b in blas if isinstance(b, dict)] if isinstance(blas, list) else []
    parts = [f"{b.get('library')} {b.get('version')} {b.get('kernel')}" for b in blas]
    return "; ".join(parts) or "none"


def commit_text(source: dict) -> str:
    """'4cd3c5e', '4cd3c5e+dirty', or where the code came from when there is no commit."""
    if not source.get("commit"):
        return source.get("where") or "unknown"
    return source["commit"][:7] + ("+dirty" if source.get("dirty") else "")


def short_record(record: dict | None) -> dict[str, str] | None:
    """The record in the few fields reports show (SHORT_FIELDS); None for None."""
    if record is None:
        return None
    simd, versions = _part(record, "simd"), _part(record, "versions")
    return {
        "host": str(record.get("host")),
        "cpu": str(_part(record, "cpu").get("model")),
        # The dispatched targets found say the level; without any, the baseline is the level.
        "simd": " ".join(simd.get("dispatched") or simd.get("baseline") or ["none"]),
        "blas": _blas_text(record.get("blas")),
        "numpy": str(versions.get("numpy")),
        "mujoco": str(versions.get("mujoco")),
        "commit": commit_text(_part(record, "source")),
    }


SHORT_FIELDS = ("cpu", "simd", "blas", "numpy", "mujoco", "host", "commit")


def describe(short: dict | None) -> str:
    """One machine in a few words: 'host (CPU, SIMD X86_V3, openblas ... , commit abc1234)'."""
    if short is None:
        return "not recorded"
    return (
        f"{short['host']} ({short['cpu']}, SIMD {short['simd']}, {short['blas']}, "
        f"numpy {short['numpy']}, mujoco {short['mujoco']}, commit {short['commit']})"
    )
