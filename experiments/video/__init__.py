"""Videos of trials: rendering, overlay, sound, encoding, exact replay."""
