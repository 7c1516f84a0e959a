"""Build-time only: the script that fits the voice's data files (sim/vocal/data/); not part of
the installed package (pyproject.toml excludes it), run from a checkout by `make voice-model`."""
