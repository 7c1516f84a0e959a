"""Running trials: settings, a trial's files and checks, the loop, its lock."""
