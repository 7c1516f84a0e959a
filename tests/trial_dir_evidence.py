"""Evidence that moving the trial directory's code into one package changed no behaviour
(issue 52): the bytes a trial writes, and what every reader of a trial does with a damaged one.

`record OUT` (run it on the code before the change, then again after):
- writes 8 short trials in 8 worlds (the kinematic and physical backends, and six worlds of
  the contact ladder's batch configs, each its world overrides given to `playroom run --set`),
  one of them run in two steps (`--resume` with more `--iterations`), evaluates each
  (`playroom eval`, the kinematic one in the physical world too) and keeps the SHA-256 of every
  log chunk, memory segment, manifest file, checkpoint and evaluation table, and of eval.json's
  numbers (without `evaluated_on`, which names the commit, nor its own checksum);
- makes a probe batch (`playroom batch`: one kinematic trial, evaluated in its own world and
  the physical one) unless OUT holds one already (then the same bytes are probed again), and
  for every file of its trial and each of three damages (missing, truncated to half its bytes,
  one bit flipped in its middle byte) asks every reader of a trial what it does: refuse (the
  exception's type and message, the temporary directory written as <batch>) or read it (with
  the warnings it gave). The readers: `load_trial`, `evaluate_trial` (2 placements), the
  report's `collect`, `collect` in the physical world, `read_log` of both kinds, and the
  batch's checks of what a rerun may skip (`is_complete`, `eval_world_complete`).

`compare BEFORE AFTER`: every hash and every probe's outcome of two records, the differences
listed; exit status 1 if any.

    .venv/bin/python tests/trial_dir_evidence.py record /tmp/evidence-before   # on main
    .venv/bin/python tests/trial_dir_evidence.py record /tmp/evidence-after    # on the branch,
                                     # after copying /tmp/evidence-before/probe-batch there
    .venv/bin/python tests/trial_dir_evidence.py compare /tmp/evidence-before /tmp/evidence-after

`--code DIR` records the code of another tree with this checkout's environment, e.g. the commit
before the change, exported (`git archive e0ac1b2 | tar -x -C /tmp/before`): both records then
come from one checkout, without switching branches.

The hashes are this machine's (a physical trial's bits depend on the CPU and libraries:
tests/reference_trials.py): compare two records made on one machine with one environment.
"""

from __future__ import annotations

import argparse
import hashlib
import importlib
import json
import shutil
import subprocess
import sys
import tempfile
import warnings
from pathlib import Path

# The code recorded: this checkout's, or another's (`--code DIR`, an export of another commit).
# Run as a script, this folder comes first on the path, where tests/sim/ and tests/learner/ would
# be imported in place of the packages: the code's root is put there instead.
CODE = Path(__file__).resolve().parents[1]
sys.path[0] = str(CODE)

ITERATIONS, FIRST_STEP, CHECKPOINT_EVERY, SEED, PLACEMENTS = 400, 200, 200, 3, 2
# Each world: its backend and its world overrides, as the batch configs set them.
WORLDS = {
    "kinematic": ("kinematic", {}),
    "physical": ("physical", {}),
    # experiments/batches/contact-ladder/01-held-stick-catch.json
    "ladder-01-held-stick-catch": ("kinematic", {"catch_rule": "held_stick"}),
    # experiments/batches/contact-ladder/02-servo-arm.json
    "ladder-02-servo-arm": ("kinematic", {"catch_rule": "held_stick", "arm_dynamics": "servo"}),
    # experiments/batches/contact-ladder/03-contact-aligned.json
    "ladder-03-contact-aligned": ("physical", {"push_objects": False, "held_pose": "aligned"}),
    # experiments/batches/contact-ablations/no-push.json (the ladder's rung 4)
    "ablation-no-push": ("physical", {"push_objects": False}),
    # experiments/batches/contact-ablations/settle.json (the ladder's rung 6)
    "ablation-settle": ("physical", {"settle_between_movements": True}),
    # experiments/batches/contact-unbundled/02-contact-reach.json
    "unbundled-02-contact-reach": (
        "physical",
        {
            "push_objects": False,
            "held_pose": "aligned",
            "unheld_contacts": "sensed",
            "caregiver_carrying": "placed",
        },
    ),
}
# The world run in two steps, and the one also evaluated in the physical world.
RESUMED, CROSS_EVALUATED = "ladder-01-held-stick-catch", "kinematic"
# What eval.json holds that names the machine and commit, or vouches for the rest.
NOT_NUMBERS = ("evaluated_on", "checksum")
PROBE_BATCH = "probe-batch"
PROBE_SPEC = {
    "grasps": ["kinematic"],
    "seeds": 1,
    "iterations": ITERATIONS,
    "checkpoint_every": CHECKPOINT_EVERY,
    "eval_placements": PLACEMENTS,
    "eval_worlds": ["physical"],
    "preset": "study",
}
DAMAGES = ("missing", "truncated", "bit-flipped")


def _playroom(*args: str) -> None:
    """`playroom ARGS` of the code recorded."""
    code = f"import sys; sys.path.insert(0, {str(CODE)!r}); from experiments.cli.main import main"
    command = [sys.executable, "-c", f"{code}; sys.exit(main())", *args]
    subprocess.run(command, check=True, capture_output=True, text=True)


def _sha256(path: Path) -> str:
    return hashlib.sha256(path.read_bytes()).hexdigest()


def _hashed(trial: Path) -> dict[str, str]:
    """The SHA-256 of every data file of a trial and its evaluations, by relative path."""
    out = {}
    for path in sorted(trial.rglob("*")):
        name = path.relative_to(trial).as_posix()
        if not path.is_file() or path.name.startswith("."):
            continue
        if path.suffix in (".parquet", ".npz") or name.startswith("manifest/"):
            out[name] = _sha256(path)
        elif path.name == "eval.json":
            held = json.loads(path.read_text())
            summary = {k: v for k, v in held.items() if k not in NOT_NUMBERS}
            text = json.dumps(summary, sort_keys=True)
            out[f"{name} (numbers)"] = hashlib.sha256(text.encode()).hexdigest()
    return out


def make_trials(root: Path) -> dict[str, dict[str, str]]:
    hashes = {}
    for name, (grasp, world) in WORLDS.items():
        trial = root / name
        sets = [f"--set=world.{k}={json.dumps(v)}" for k, v in world.items()]
        common = ["--out", str(trial), "--grasp", grasp, "--seed", str(SEED), "--quiet"]
        common += ["--checkpoint-every", str(CHECKPOINT_EVERY), "--preset", "study", *sets]
        if name == RESUMED:
            _playroom("run", *common, "--iterations", str(FIRST_STEP))
            _playroom("run", "--out", str(trial), "--resume", "--iterations", str(ITERATIONS))
        else:
            _playroom("run", *common, "--iterations", str(ITERATIONS))
        _playroom("eval", str(trial), "--placements", str(PLACEMENTS), "--quiet")
        if name == CROSS_EVALUATED:
            _playroom("eval", str(trial), "--placements", str(PLACEMENTS), "--world", "physical")
        hashes[name] = _hashed(trial)
        print(f"trial {name}: {len(hashes[name])} files hashed", flush=True)
    return hashes


def _make_probe_batch(out: Path) -> None:
    spec = out.parent / "probe-spec.json"
    spec.write_text(json.dumps(PROBE_SPEC))
    _playroom("batch", "--config", str(spec), "--out", str(out), "--workers", "1", "--quiet")


# The readers --------------------------------------------------------------------------------


def _function(candidates: tuple[str, ...], name: str):
    """`name` from the first module of `candidates` that defines it (a reader's home before and
    after the move)."""
    for module in candidates:
        try:
            found = importlib.import_module(module)
        except ImportError:
            continue
        if hasattr(found, name):
            return getattr(found, name)
    raise ImportError(f"none of {candidates} defines {name}")


def _readers() -> dict:
    from experiments.analysis import eval_world_results, results
    from experiments.analysis.logs import read_log
    from experiments.batches.runner import eval_world_complete, is_complete
    from experiments.measure.evaluation import EvaluationSettings
    from experiments.measure.trial_evaluation import evaluate_trial

    load_trial = _function(
        ("experiments.run.trial_parts", "experiments.run.trial_checks"), "load_trial"
    )
    settings = EvaluationSettings(n_placements=PLACEMENTS)
    return {
        "load_trial": lambda batch, trial: load_trial(trial),
        "evaluate_trial": lambda batch, trial: evaluate_trial(trial, settings),
        "collect": lambda batch, trial: results.collect(batch),
        "collect physical world": lambda batch, trial: eval_world_results.collect(
            batch, "physical"
        ),
        "read_log iterations": lambda batch, trial: read_log(trial),
        "read_log words": lambda batch, trial: read_log(trial, "words"),
        "is_complete": lambda batch, trial: is_complete(trial),
        "eval_world_complete": lambda batch, trial: eval_world_complete(
            trial, "physical", PLACEMENTS
        ),
    }


def _damage(path: Path, how: str) -> None:
    data = path.read_bytes()
    if how == "missing":
        path.unlink()
    elif how == "truncated":
        path.write_bytes(data[: len(data) // 2])
    else:
        flipped = bytearray(data)
        flipped[len(data) // 2] ^= 0x01
        path.write_bytes(bytes(flipped))


def _outcome(reader, batch: Path, trial: Path) -> str:
    """What `reader` did: 'read' with its warnings' categories and messages, or the refusal."""

    def shown(text: str) -> str:
        return " ".join(text.replace(str(batch), "<batch>").split())

    with warnings.catch_warnings(record=True) as caught:
        warnings.simplefilter("always")
        try:
            result = reader(batch, trial)
        except Exception as exc:  # every refusal, of whatever type, is what is recorded
            return f"refused: {type(exc).__name__}: {shown(str(exc))}"
    # A ResourceWarning says when the garbage collector ran, not what the reader did.
    said = sorted(
        {
            f"{w.category.__name__}: {shown(str(w.message))}"
            for w in caught
            if not issubclass(w.category, ResourceWarning)
        }
    )
    answer = f" -> {result}" if isinstance(result, bool) else ""
    return "read" + answer + "".join(f" [{w}]" for w in said)


def probe(pristine: Path, work: Path) -> dict[str, dict[str, str]]:
    """Every file of the probe batch's trial, damaged each way, given to every reader."""
    readers = _readers()
    trial_name = next(d.name for d in pristine.iterdir() if d.is_dir())
    files = sorted(
        p.relative_to(pristine / trial_name).as_posix()
        for p in (pristine / trial_name).rglob("*")
        if p.is_file()
    )
    out: dict[str, dict[str, str]] = {}
    for reader_name, reader in readers.items():
        for name in [None, *files]:
            for how in DAMAGES if name is not None else ("intact",):
                batch = work / "batch"
                shutil.rmtree(batch, ignore_errors=True)
                shutil.copytree(pristine, batch)
                trial = batch / trial_name
                if name is not None:
                    _damage(trial / name, how)
                key = "(intact)" if name is None else f"{name} {how}"
                out.setdefault(key, {})[reader_name] = _outcome(reader, batch, trial)
        print(f"probed {reader_name}", flush=True)
    return out


def record(out: Path) -> None:
    out.mkdir(parents=True, exist_ok=True)
    with tempfile.TemporaryDirectory() as tmp:
        hashes = make_trials(Path(tmp) / "trials")
        pristine = out / PROBE_BATCH
        if not pristine.exists():
            _make_probe_batch(pristine)
        probes = probe(pristine, Path(tmp))
    commit = subprocess.run(
        ["git", "-C", str(CODE), "rev-parse", "HEAD"], capture_output=True, text=True, check=False
    ).stdout.strip() or str(CODE)
    evidence = {"commit": commit, "hashes": hashes, "probes": probes}
    (out / "evidence.json").write_text(json.dumps(evidence, indent=1, sort_keys=True) + "\n")
    print(f"{out / 'evidence.json'}: {sum(map(len, hashes.values()))} hashes, {len(probes)} probes")


def _differences(before: dict, after: dict, what: str) -> list[str]:
    lines = []
    for key in sorted(set(before) | set(after)):
        a, b = before.get(key), after.get(key)
        if isinstance(a, dict) and isinstance(b, dict):
            lines += _differences(a, b, f"{what} {key}")
        elif a != b:
            lines.append(f"{what} {key}: {a!r} -> {b!r}")
    return lines


def compare(before: Path, after: Path) -> int:
    a = json.loads((before / "evidence.json").read_text())
    b = json.loads((after / "evidence.json").read_text())
    lines = _differences(a["hashes"], b["hashes"], "hash") + _differences(
        a["probes"], b["probes"], "probe"
    )
    for line in lines:
        print(line)
    hashes = sum(map(len, a["hashes"].values()))
    outcomes = sum(map(len, a["probes"].values()))
    print(
        f"{hashes} hashes and {outcomes} probe outcomes of {a['commit'][:7]} compared with "
        f"{b['commit'][:7]}: {len(lines)} differ"
    )
    return 1 if lines else 0


def main() -> int:
    parser = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    sub = parser.add_subparsers(dest="command", required=True)
    p = sub.add_parser("record")
    p.add_argument("out", type=Path)
    p.add_argument("--code", type=Path, help="the root of the code to record (default: this one)")
    p = sub.add_parser("compare")
    p.add_argument("before", type=Path)
    p.add_argument("after", type=Path)
    args = parser.parse_args()
    if args.command == "record":
        if args.code is not None:
            global CODE
            CODE = args.code.resolve()
            sys.path[0] = str(CODE)
        record(args.out)
        return 0
    return compare(args.before, args.after)


if __name__ == "__main__":
    sys.exit(main())
