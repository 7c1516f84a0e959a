"""Build-time only: the script that fits VocalTractLab's data files (sim/vocal/vtl/data/); not
part of the installed package (pyproject.toml excludes it), run from a checkout by
`make voice-model`."""
