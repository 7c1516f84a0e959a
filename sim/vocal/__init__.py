"""The agent's voice: two vocal tracts, VocalTractLab's and DIVA's (no MuJoCo in here).

Modules, one concept each:
- `config`: the study's vocal numbers (docs/protocol.md §6, §7) in `VoiceConfig`.
- `voice`: `Voice`, what the world uses of a vocal tract, whichever it is.
- `registry`: the tracts by name, and `make_tract`.
- `tract`: `VocalTract`, VocalTractLab's tract, this project's ("vtl"):
  - `articulators`: 7 PCA articulators in [-1, 1] -> 19 VocalTractLab tract parameters.
  - `formants`: exact formants (VTL area function + lossless-tube resonances).
  - `formant_map`: the fast fitted map articulators -> (log2 F1, log2 F2), plain NumPy.
  - `words`: vowel targets (the speaker's own), the 6 words, their trajectories, recognition.
  - `produce`: voice parameters that say each word (found by optimisation).
  - `audio`: waveform synthesis with VTL and WAV writing.
- `diva/`: `DivaTract`, DIVA's formant map as the study ran it ("diva"), from the user's data.
- `fitting/fit_voice_model`: the build-time script that regenerates the data files in `data/`
  (not installed with the package).
"""
