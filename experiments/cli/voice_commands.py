"""`playroom voice-data`, `sounds` and `say`: the vocal tracts' data, their random sounds
against the words, and a word as audio."""

from __future__ import annotations

import argparse
import os

from experiments.cli.args import (
    UsageError,
    non_negative_int,
    positive_int,
)
from models.tracts import TRACTS
from sim.vocal.config import DEFAULT_VOICE


def add_parsers(sub: argparse._SubParsersAction) -> None:
    p = sub.add_parser("voice-data", help="install the data a vocal tract needs (DIVA's map)")
    p.add_argument("tract", choices=["diva"], help="the tract whose data it is")
    p.add_argument(
        "path",
        nargs="?",
        help="DIVA's diva_synth.mat (or divapy's fmfit_py.mat); left out: say what is installed",
    )
    p.set_defaults(func=cmd_voice_data)

    p = sub.add_parser(
        "sounds", help="random vocal commands against the words, in each vocal tract (Fig. 1b)"
    )
    p.add_argument(
        "--voice",
        nargs="+",
        choices=TRACTS,
        default=list(TRACTS),
        help=f"the tracts to compare (default: {' '.join(TRACTS)}; diva needs its data installed)",
    )
    p.add_argument(
        "--commands",
        type=positive_int,
        default=200,
        help="random commands (default: 200, the paper's)",
    )
    p.add_argument("--seed", type=non_negative_int, default=0, help="of the commands (default: 0)")
    p.set_defaults(func=cmd_sounds)

    p = sub.add_parser("say", help="write a word as audio (WAV), from the agent's voice")
    p.add_argument("word", choices=DEFAULT_VOICE.words, help="one of the caregiver's 6 words")
    p.add_argument("--out", required=True, help="the WAV file to write")
    p.set_defaults(func=cmd_say)


def cmd_voice_data(args: argparse.Namespace) -> None:
    """Check the user's DIVA file and install its map, or say what is installed."""
    from sim.vocal.diva.data import (
        DivaDataError,
        DivaDataMissing,
        cache_path,
        install,
        installed_fit,
    )

    if args.path is None:
        try:
            installed_fit()
        except (DivaDataMissing, DivaDataError) as exc:
            raise UsageError(str(exc)) from None
        print(f"DIVA's map (the study's) is installed in {cache_path()}")
        return
    try:
        where, what = install(args.path)
    except DivaDataError as exc:
        raise UsageError(str(exc)) from None
    print(f"{args.path}: {what}; its map is installed in {where} (`--voice diva` uses it)")


def cmd_sounds(args: argparse.Namespace) -> None:
    """Random vocal commands against the words, one column per tract (the paper's Fig. 1b)."""
    from experiments.measure.random_sounds import random_sound_table

    tracts = tuple(dict.fromkeys(args.voice))  # in the order given, each once
    table = random_sound_table(tracts, args.commands, args.seed, progress=True)
    print(
        f"{args.commands} random vocal commands (seed {args.seed}, the study preset's DMP); "
        "distances in the 10D sound space, recognised below 0.4"
    )
    print(table.T.to_string(float_format=lambda x: f"{x:.3f}"))


def cmd_say(args: argparse.Namespace) -> None:
    """A word as audio, from the voice parameters found to produce it."""
    from pathlib import Path

    from sim.vocal.audio import write_wav
    from sim.vocal.config import DEFAULT_VOICE
    from sim.vocal.vtl.productions import stored_distances, synthesise_word

    if args.word not in DEFAULT_VOICE.words:
        raise UsageError(f"unknown word {args.word!r}: one of {', '.join(DEFAULT_VOICE.words)}")
    out = Path(args.out)
    if not out.parent.is_dir() or not os.access(out.parent, os.W_OK):
        raise UsageError(f"cannot write {out}: {out.parent} is not a writable directory")
    waveform, rate = synthesise_word(args.word)
    write_wav(out, waveform, rate)
    distance = stored_distances()[args.word]
    print(f"{out}: /{args.word}/, {len(waveform) / rate:.2f} s; its sound is {distance:.3f} from "
          "the perfect word (recognised below 0.4)")  # fmt: skip
