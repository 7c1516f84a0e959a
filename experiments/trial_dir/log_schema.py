"""What a trial's logs hold, column by column: each column declared once, with its type, its
meaning, what trials written before it existed read as, and the change that added it.

The writer (experiments/run/) builds its rows from these declarations (`EMPTY_ROW`,
`LEARNER_COLUMNS`), every reader (experiments/analysis/) names the columns it reads by their
constants here, `upgraded` brings the chunks of older trials to the newest columns when they
are read, and `column_table` is the table of docs/learning.md (a test keeps them equal:
`python -m experiments.trial_dir.log_schema docs/learning.md` writes it again).

Two kinds of log (where their chunks lie: experiments/trial_dir/layout.py):
- `iterations`, one row per iteration: `ITERATIONS`;
- `words`, one row every 100 iterations: `WORDS`, the iteration and one column per word of the
  trial's voice, named by the voice's config (config.json's `voice.words`), so that only their
  kind, not their names, is declared here.

A column a trial never had is not a value it recorded: an event column that older chunks lack
reads as missing (NaN, or pd.NA for a true/false column, which then has pandas' "boolean"
type), never as "", False or 0, so that a number computed from it is missing too (`recorded`).
Pure functions of tables: no simulator, no learner.
"""

from __future__ import annotations

import enum
import sys
from collections.abc import Iterable, Sequence
from dataclasses import dataclass
from pathlib import Path

import numpy as np
import pandas as pd
from pandas.api.extensions import ExtensionDtype
from pandas.api.types import pandas_dtype

from models.layout import BLOCK_DIM, MODELS, TOYS


class Older(enum.Enum):
    """What a chunk written before a column existed reads as, where it is not a value."""

    ALWAYS = "(every chunk holds it)"  # a chunk without it is no trial's log
    FROM_CONFIG = "the trial's, from config.json"  # experiments/trial_dir/layout.py `source_of`
    MISSING = "missing"  # not recorded: NaN, or pd.NA in a "boolean" column


@dataclass(frozen=True)
class Column:
    """One column of a log, or a family of columns alike (goal_0..goal_9), declared once."""

    names: tuple[str, ...]
    dtype: str  # as pandas names it; the writer's rows give it (a test checks written chunks)
    meaning: str  # with its units
    before: object  # what chunks written before it read as: a value, or an `Older`
    added: str  # the change that added it, by commit (the package version was 0.1.0 for all)
    empty: object = None  # in the writer's row until the iteration's events say otherwise

    @property
    def label(self) -> str:
        return self.names[0] if len(self.names) == 1 else f"{self.names[0]}..{self.names[-1]}"


def _one(
    name: str, dtype: str, meaning: str, before: object, added: str, empty: object = None
) -> Column:
    return Column((name,), dtype, meaning, before, added, empty)


FIRST = "625ab7c, the first logs"
ALWAYS, FROM_CONFIG, MISSING = Older.ALWAYS, Older.FROM_CONFIG, Older.MISSING

# The columns' names, for the writer and the readers.
SOURCE_COLUMNS = ("trial", "seed", "backend", "voice")
ITERATION = "iteration"
MOTOR_SPACE = "motor_space"
MODEL = "model"
STICK_DISTANCE = "stick_distance"
STICK_GRASPED = "stick_grasped"


def moved_by(thing: str) -> str:
    """The column of what moved the stick or a toy ("stick", "toy1", ...)."""
    return f"{thing}_moved_by"


STICK_MOVED_BY = moved_by("stick")
TOY_MOVED_BY = tuple(moved_by(toy) for toy in TOYS)
WORD_RECOGNISED = "word_recognised"
CAREGIVER_SAID = "caregiver_said"
DIVERGED = "diverged"
STICK_RETURNED = "stick_returned"
GOAL_COLUMNS = tuple(f"goal_{i}" for i in range(BLOCK_DIM))
REACHED_COLUMNS = tuple(f"reached_{i}" for i in range(BLOCK_DIM))
INTEREST_COLUMNS = tuple(f"interest_{k}" for k in range(len(MODELS)))
# Stored as float32: 7 significant digits are plenty to plot and average them, at half the size
# of float64 (random goals hardly compress).
LEARNER_DTYPE = np.float32

_ROWS_SOURCE = "870b089, rows carry their source"
_STICK_RETURN = "071379b, the stick return"
MOVERS = '"hand", "stick", "push", "caregiver" or ""'
# First in every row of both kinds, so that rows of several trials keep apart.
SOURCE = (
    _one("trial", "str", "the trial directory's name", FROM_CONFIG, _ROWS_SOURCE),
    _one("seed", "int64", "the trial's seed", FROM_CONFIG, _ROWS_SOURCE),
    _one("backend", "str", "the grasp backend", FROM_CONFIG, _ROWS_SOURCE),
    _one("voice", "str", "the vocal tract", FROM_CONFIG, _ROWS_SOURCE),
)
# The iteration and what happened in it (experiments/run/trial_parts.py `log_row`).
EVENTS = (
    _one(ITERATION, "int64", "the iteration, from 0", ALWAYS, FIRST, 0),
    _one(MOTOR_SPACE, "str", '"arm" or "voice"', ALWAYS, FIRST, ""),
    _one(
        MODEL,
        "int64",
        "the chosen model, 0-based into models.layout.MODELS; -1 during the bootstrap's "
        "random motor babbling",
        ALWAYS,
        FIRST,
        -1,
    ),
    _one(
        STICK_DISTANCE,
        "float64",
        "m: the stick's handle from the arm's base, before the movement",
        MISSING,
        _STICK_RETURN,
        0.0,
    ),
    _one(STICK_GRASPED, "bool", "the hand took the stick", ALWAYS, FIRST, False),
    _one(STICK_MOVED_BY, "str", f"what moved the stick: {MOVERS}", ALWAYS, FIRST, ""),
    Column(TOY_MOVED_BY, "str", f"what moved each toy: {MOVERS}", ALWAYS, FIRST, ""),
    _one(WORD_RECOGNISED, "str", 'the word the caregiver understood, or ""', ALWAYS, FIRST, ""),
    _one(CAREGIVER_SAID, "str", 'the word the caregiver said, or ""', ALWAYS, FIRST, ""),
    _one(DIVERGED, "bool", "the physics diverged; the room was put back", ALWAYS, FIRST, False),
    _one(
        STICK_RETURNED,
        "bool",
        "the experimenter returned the stick after the movement",
        MISSING,
        _STICK_RETURN,
        False,
    ),
)
# The learner's values (experiments/run/trial_parts.py `learner_values`).
_LEARNER = "870b089, the learner's values logged"
LEARNER = (
    Column(
        GOAL_COLUMNS,
        "float32",
        "the sensory goal, in the chosen model's 10D block (5 samples of x then 5 of y; of F1 "
        "then F2 for the sound); NaN during the bootstrap",
        MISSING,
        _LEARNER,
    ),
    Column(
        REACHED_COLUMNS,
        "float32",
        "the outcome in that block as the learner reads it (clipped under the study preset): "
        "the competence is -sqrt(sum((goal_i - reached_i)^2)); NaN during the bootstrap",
        MISSING,
        _LEARNER,
    ),
    Column(
        INTEREST_COLUMNS,
        "float32",
        "each model's interest (learning progress) when the iteration's model was chosen, "
        "before its attempt; column k is model k; kept under random babbling too",
        MISSING,
        _LEARNER,
    ),
)
ITERATIONS = (*SOURCE, *EVENTS, *LEARNER)
LEARNER_COLUMNS = tuple(name for column in LEARNER for name in column.names)
# The events' columns of a row as if nothing happened: the writer's row before it fills them.
EMPTY_ROW = {name: column.empty for column in EVENTS for name in column.names}

# Iterations between two rows of the words log: the vocal learning curves are read every 100
# iterations (docs/protocol.md §10).
WORDS_LOG_PERIOD = 100
# The words log: its fixed columns, then one of WORD per word of the trial's voice.
WORD = Column(
    ("<word>",),
    "float64",
    "one column per word of the trial's voice (config.json's voice.words): the best distance "
    "reached so far to it, inf before the voice was used",
    ALWAYS,
    FIRST,
)
WORDS = (
    *SOURCE,
    _one(ITERATION, "int64", "the iterations done by then: 100, 200, ...", ALWAYS, FIRST),
)
KINDS = {"iterations": ITERATIONS, "words": WORDS}


def column_names(kind: str) -> tuple[str, ...]:
    """The declared columns of a kind of log, in the writer's order (the words log's words
    follow them)."""
    return tuple(name for column in KINDS[kind] for name in column.names)


def word_columns(words: pd.DataFrame) -> list[str]:
    """The word columns of a words log: every column but its declared ones."""
    fixed = set(column_names("words"))
    return [c for c in words.columns if c not in fixed]


def recorded(frame: pd.DataFrame, columns: Iterable[str]) -> bool:
    """Whether every row of `frame` holds these columns as recorded: none of them absent or
    missing (a trial, or a stretch of it, written before the column existed)."""
    wanted = list(columns)
    return set(wanted) <= set(frame.columns) and not frame[wanted].isna().to_numpy().any()


def _missing_dtype(column: Column) -> np.dtype | ExtensionDtype:
    """The column's type where some rows are missing: NumPy's bool and int hold no NA."""
    return pandas_dtype({"bool": "boolean", "int64": "Int64"}.get(column.dtype, column.dtype))


def upgraded(frame: pd.DataFrame, kind: str, columns: Sequence[str] | None = None) -> pd.DataFrame:
    """The chunks of one kind of log, read and joined, with the columns the newest writer
    writes: each declared column (of `columns`, if given) that no chunk held, added as its
    `before` says, and each that only some chunks held (missing in the others' rows after the
    join) in its declared type, pd.NA for true/false. `frame` itself when nothing is lacking.
    Columns read from config.json (FROM_CONFIG) are the caller's to add."""
    declared = {name: column for column in KINDS[kind] for name in column.names}
    asked = list(declared if columns is None else columns)
    wanted = [n for n in asked if n in declared]
    changes: dict[str, pd.Series] = {}
    for name in wanted:
        column = declared[name]
        if name in frame.columns:
            held = frame[name]
            if held.dtype != column.dtype and held.isna().any():
                changes[name] = held.astype(_missing_dtype(column))
        elif column.before is MISSING:
            changes[name] = pd.Series(index=frame.index, dtype=_missing_dtype(column))
        elif not isinstance(column.before, Older):
            changes[name] = pd.Series(column.before, index=frame.index, dtype=column.dtype)
    if not changes:
        return frame
    out = frame.assign(**changes)
    # The columns in the order of the request (or the writer's), then any others read.
    order = [*SOURCE_COLUMNS, *asked]
    first = [c for c in dict.fromkeys(order) if c in out.columns]
    return out[[*first, *(c for c in out.columns if c not in first)]]


def _cell(text: str) -> str:
    return text.replace("|", "\\|")


def _older(column: Column) -> str:
    if column.before is MISSING:
        return f"missing: {'pd.NA' if column.dtype == 'bool' else 'NaN'}"
    if isinstance(column.before, Older):
        return column.before.value
    return repr(column.before)


def column_table() -> str:
    """Both logs' columns as a Markdown table, the one docs/learning.md shows."""
    lines = [
        "| log | column | type | what it holds | older trials read | added by |",
        "|---|---|---|---|---|---|",
    ]
    for kind, columns in (("iterations", ITERATIONS), ("words", (*WORDS, WORD))):
        for column in columns:
            cells = (
                kind,
                f"`{column.label}`",
                column.dtype,
                column.meaning,
                _older(column),
                column.added,
            )
            lines.append("| " + " | ".join(_cell(c) for c in cells) + " |")
    return "\n".join(lines) + "\n"


# The lines around the table in the docs page that shows it.
TABLE_START = "<!-- log columns: generated by `python -m experiments.trial_dir.log_schema` -->\n"
TABLE_END = "<!-- end of log columns -->\n"


def with_table(page: str) -> str:
    """A docs page with its generated table (between TABLE_START and TABLE_END) made current.
    ValueError if the page has no such place."""
    start, end = page.find(TABLE_START), page.find(TABLE_END)
    if start < 0 or end < start:
        raise ValueError("the page has no place for the log columns' table")
    return page[: start + len(TABLE_START)] + column_table() + page[end:]


def main(argv: Sequence[str]) -> None:
    """Print the table, or, given docs pages, write it into each."""
    if not argv:
        sys.stdout.write(column_table())
    for name in argv:
        path = Path(name)
        path.write_text(with_table(path.read_text()))


if __name__ == "__main__":
    main(sys.argv[1:])
