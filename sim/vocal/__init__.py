"""The agent's voice: the shared voice, and one package per vocal tract (no MuJoCo in here).

The shared voice, whichever tract speaks:
- `config`: the study's vocal numbers (docs/protocol.md §6, §7) in `VoiceConfig`.
- `voice`: `Voice`, what the world uses of a vocal tract, whichever it is.
- `words`: the words between a tract's vowel targets: perfect trajectories, 10D features.
- `audio`: a movement's sound timing and the project's one WAV writer.
- `registry`: `load` and `make_tract`, the tracts by name (the lazy table is models/tracts.py's
  `REGISTRY`, which the settings read without importing a synthesizer).

The tracts, one package each:
- `vtl/`: `VocalTract`, VocalTractLab's tract, this project's ("vtl", the default).
- `diva/`: `DivaTract`, DIVA's formant map as the study ran it ("diva"), from the user's data.
"""
