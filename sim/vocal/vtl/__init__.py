"""VocalTractLab's vocal tract, this project's voice ("vtl" in models/tracts.py).

DIVA is the study's tract (sim/vocal/diva/); this one is an articulatory synthesizer whose data
ships with the project (data/, fitted by `fitting/`). Modules, one concept each:
- `tract`: `VocalTract`, the `Voice` the world uses.
- `articulators`: 7 PCA articulators in [-1, 1] -> 19 VocalTractLab tract parameters.
- `formants`: exact formants (VTL area function + lossless-tube resonances).
- `formant_map`: the fast fitted map articulators -> (log2 F1, log2 F2), plain NumPy.
- `words`: the speaker's own vowel targets, and its words' features and recognition.
- `produce`: voice parameters that say each word (found by optimisation).
- `productions`: those stored parameters (`say`), and a word's audio through them.
- `audio`: waveform synthesis with VTL.
- `fitting/fit_voice_model`: the build-time script that regenerates the data files in `data/`
  (not installed with the package).
"""
