"""A refused command ends with its one line and exit status 2, even when the refusal comes
after Parquet files were read from bytes: pyarrow's pool threads once dropped their hold on
those bytes during interpreter exit and aborted the process (exit 134, "terminate called
without an active exception") in about one refusal of ten on a loaded machine."""

import shutil
import subprocess
import sys
from concurrent.futures import ThreadPoolExecutor

import pytest

# Enough refusals, run four at a time on two cores (the load that exposed the abort), that
# the abort's rate before the fix fails this check almost surely.
REFUSALS = 32
AT_ONCE = 4


@pytest.mark.slow
def test_a_refused_eval_exits_with_status_2_every_time(trained_trial, tmp_path):
    command = [
        sys.executable,
        "-c",
        "import sys; from experiments.cli.main import main; sys.exit(main())",
    ]

    def refuse(copy: int) -> subprocess.CompletedProcess:
        trial = tmp_path / f"trial-{copy}"  # one each: an eval holds its trial's lock
        shutil.copytree(trained_trial.dir, trial)
        (trial / "log" / "iterations" / "chunk-00001000.parquet").unlink()
        return subprocess.run(
            [*command, "eval", str(trial), "--quiet"], capture_output=True, text=True
        )

    with ThreadPoolExecutor(AT_ONCE) as pool:
        results = list(pool.map(refuse, range(REFUSALS)))
    aborted = [r.stderr for r in results if r.returncode != 2]
    assert not aborted, f"{len(aborted)} of {REFUSALS} refusals did not exit 2: {aborted[0]}"
    for result in results:
        (line,) = result.stderr.strip().splitlines()
        assert line.startswith("playroom eval: error: ")
        assert "chunk-00001000.parquet is missing" in line
