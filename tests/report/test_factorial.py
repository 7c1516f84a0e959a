"""Two rules crossed (`playroom factorial`): each rule's effect with the other off and on, its
main effect and the interaction, contrasts of the four cells per seed, tested over seeds."""

from __future__ import annotations

import io
from pathlib import Path

import numpy as np
import pandas as pd
import pytest
from test_ladder import KEY, _config, _read
from trial_recompute import check_factorial_page

from experiments.cli.main import main
from experiments.report import ladder
from experiments.report.factorial import CONTRASTS, factorial_files
from experiments.report.trial_data import read_trial_data

SEEDS = range(8)
CELLS = ("neither", "first", "second", "both")
# The first rule adds 0.04, the second 0.10, and with both on the first adds 0.04 - 0.06.
EFFECTS = {"neither": 0.0, "first": 0.04, "second": 0.10, "both": 0.04 + 0.10 - 0.06}


def _values() -> pd.DataFrame:
    rng = np.random.default_rng(2)
    seed_noise = {s: float(rng.normal(0, 0.05)) for s in SEEDS}
    rows = [
        (cell, "own", s, KEY, 0.1 + effect + seed_noise[s] + float(rng.normal(0, 0.002)))
        for cell, effect in EFFECTS.items()
        for s in SEEDS
    ]
    return pd.DataFrame(rows, columns=ladder.VALUE_COLUMNS)


def test_each_rule_with_the_other_off_and_on_its_main_effect_and_the_interaction():
    cells = [ladder.Rung(c, Path(c)) for c in CELLS]
    read = _read(_values(), {c: _config("kinematic") for c in CELLS})
    files = factorial_files(read, cells, ("catch rule", "servo arm"), "cmd")
    tests = pd.read_csv(io.BytesIO(files["factorial.csv"])).set_index("contrast")
    expected = {
        "first, second off": 0.04,
        "first, second on": -0.02,
        "first, main effect": 0.01,
        "second, first off": 0.10,
        "second, first on": 0.04,
        "second, main effect": 0.07,
        "interaction": -0.06,
    }
    assert list(tests.index) == list(CONTRASTS)
    for contrast, value in expected.items():
        assert tests.loc[contrast, "mean"] == pytest.approx(value, abs=0.004), contrast
        assert tests.loc[contrast, "n"] == len(SEEDS)
    # Paired by seed: the seeds' shared noise (sd 0.05) leaves every contrast's test sharp.
    assert (tests["p"] < 1e-4).all() and np.allclose(tests["p_rank"], 2 / 2**8)
    page = files["factorial.md"].decode()
    assert "| catch rule, servo arm off | catch rule, servo arm on |" in page
    # The contrasts again from the per-trial data alone.
    trials = read_trial_data(io.BytesIO(files["factorial-trials.csv"])).pivot(
        index="seed", columns="rung", values=KEY
    )
    again = (trials["both"] - trials["second"]) - (trials["first"] - trials["neither"])
    assert tests.loc["interaction", "mean"] == pytest.approx(again.mean(), rel=1e-12)


def test_a_design_of_other_than_four_cells_is_refused_in_one_line(batches, tmp_path, capsys):
    cells = [f"c{i}={batches['kinematic']}" for i in range(3)]
    assert main(["factorial", *cells, "--factors", "a", "b", "--out", str(tmp_path / "o")]) == 2
    err = capsys.readouterr().err.strip()
    assert err.count("\n") == 0 and "a 2 x 2 design has 4 cells" in err
    assert not (tmp_path / "o").exists()


def test_cells_holding_more_seeds_than_others_are_said_so_and_enter_no_contrast():
    """The real designs cross 16-seed cells with 32-seed rungs and the comparison's 64: every
    contrast is on the seeds all four hold, and the page says so (not "Incomplete", and not
    the ladder's whole on every seed, which a factorial does not compute)."""
    values = _values()
    values = pd.concat([values.assign(tested=t) for t in ("own", *ladder.WORLDS)])
    values = values[(values["rung"] != "first") | (values["seed"] < 4)]
    values = values[(values["rung"] != "second") | (values["seed"] < 6)]
    cells = [ladder.Rung(c, Path(c)) for c in CELLS]
    files = factorial_files(
        _read(values, {c: _config("kinematic") for c in CELLS}), cells, ("a", "b"), "cmd"
    )
    tests = pd.read_csv(io.BytesIO(files["factorial.csv"]))
    assert set(tests["n"]) == {4}
    page = files["factorial.md"].decode()
    # Each cell named with the seeds it lacks, not the union of all (it lacks only its own).
    assert "first lacks 4–7; second lacks 6, 7. Every contrast is taken on the seeds" in page
    assert "Incomplete" not in page and "the whole" not in page.split("## Completeness")[1]


def test_every_cell_of_the_page_is_computed_again_from_its_per_trial_data_alone():
    """factorial-trials.csv holds all a reader needs: each contrast's mean, interval, t and
    signed-rank p, the Holm stars and counts, and each cell's mean, computed again with scipy
    (trial_recompute.check_factorial_page, which also checks the published pages)."""
    cells = [ladder.Rung(c, Path(c)) for c in CELLS]
    read = _read(_values(), {c: _config("kinematic") for c in CELLS})
    named = " ".join(f"{c}={c}" for c in CELLS)
    command = f'playroom factorial {named} --factors "catch rule" "servo arm" --out x'
    files = factorial_files(read, cells, ("catch rule", "servo arm"), command)
    page = files["factorial.md"].decode()
    trials = read_trial_data(io.BytesIO(files["factorial-trials.csv"]))
    check_factorial_page(page, trials, read.measures)
    # Another trial's value, or a cell of the table written by hand, fails the check.
    moved = trials[KEY].where(trials["rung"] != "both", trials[KEY] + 0.01)
    with pytest.raises(AssertionError):
        check_factorial_page(page, trials.assign(**{KEY: moved}), read.measures)
    mean = f"{100 * trials.loc[trials['rung'] == 'neither', KEY].mean():.1f}"
    with pytest.raises(AssertionError):
        check_factorial_page(page.replace(f"| {mean} |", "| 0.0 |", 1), trials, read.measures)


def test_each_cell_says_what_it_changes_from_the_cell_of_neither_rule():
    """A factorial's cells have no order: the page lists what each changes from the first
    cell (neither rule), so that the cell of both names both rules."""
    configs = {
        "neither": _config("kinematic"),
        "first": _config("kinematic", catch_rule="held_stick"),
        "second": _config("kinematic", arm_dynamics="servo"),
        "both": _config("kinematic", catch_rule="held_stick", arm_dynamics="servo"),
    }
    cells = [ladder.Rung(c, Path(c)) for c in CELLS]
    page = factorial_files(_read(_values(), configs), cells, ("a", "b"), "cmd")["factorial.md"]
    table = page.decode().split("## Each rule")[0]
    rows = {line.split(" | ")[0][2:]: line for line in table.splitlines()}
    assert "| rung | batch | changes from neither |" in table
    assert "catch_rule: study -> held_stick" in rows["both"]
    assert "arm_dynamics: set -> servo" in rows["both"]
    assert "catch_rule" not in rows["second"]
