"""DIVA's vocal tract as the study ran it ("diva" in models/tracts.py).

- `fmfit`: DIVA's forward map in its 'audsom' mode (`diva_synth.m`, early 2017): articulators
  through tanh, then a fitted mixture of locally linear maps to F1-F3 in Hz.
- `data`: the map's fitted numbers, which are the user's to provide (no licence allows us to
  ship them): checked against the known DIVA versions, cached in the user's data directory.
- `tract`: the `Voice` the world uses, with the study's use of DIVA (which articulators the 7
  DMP dimensions drive, the fixed others, log2 formants, what a failed frame gives).
- `sound`: audio for videos, a formant synthesizer at DIVA's formants (not DIVA's own sound).
"""
