"""The agent's voice: a DIVA-style vocal tract built on VocalTractLab (no MuJoCo in here).

Modules, one concept each:
- `config`: the study's vocal numbers (docs/protocol.md §6, §7) in `VoiceConfig`.
- `articulators`: 7 PCA articulators in [-1, 1] -> 19 VocalTractLab tract parameters.
- `formants`: exact formants (VTL area function + lossless-tube resonances).
- `formant_map`: the fast fitted map articulators -> (log2 F1, log2 F2), plain NumPy.
- `words`: vowel targets, the 6 words, their perfect trajectories, recognition.
- `produce`: voice parameters that say each word (found by optimisation).
- `voice`: `Voice`, what the world uses of a vocal tract, whichever it is.
- `tract`: `VocalTract`, VocalTractLab's tract, the study's ("vtl").
- `registry`: the tracts by name, and `make_tract`.
- `audio`: waveform synthesis with VTL and WAV writing.
- `fitting/fit_voice_model`: the build-time script that regenerates the data files in `data/`
  (not installed with the package).
"""
