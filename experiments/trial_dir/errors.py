"""What every part of a trial directory raises for a trial that cannot be used: one line
saying why (the command line prints it as it is, exit code 2)."""

from __future__ import annotations

from experiments.trial_dir.layout import CONFIG_FILE


class TrialError(Exception):
    """A trial directory or setting that cannot be used; the message says why."""


class TrialConfigError(TrialError, ValueError):
    """A config.json no trial can be made from: a TrialError (one line, exit code 2) and a
    ValueError, as the configs raise for it (callers catching either keep working)."""

    @classmethod
    def making_no_trial(cls, exc: Exception) -> TrialConfigError:
        """The error for a config.json whose settings made the configs raise `exc`."""
        return cls(f"{CONFIG_FILE} makes no trial: {exc}")


class TrialLocked(TrialError):
    """Another process is writing into the trial directory."""
