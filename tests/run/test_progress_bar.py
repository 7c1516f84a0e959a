"""A trial's progress bar shows the trial's pace: an iteration that stalls on a kernel being
compiled or loaded (about 20 s on a fresh install's first trial) is left out of its rate and
time left, which once read eleven hours for a 4-minute trial. Clocks are faked: no test times."""

import io

import pytest

from experiments.run import progress_bar
from experiments.run.settings import TrialSettings
from experiments.run.trial import Trial


class FakeClock:
    def __init__(self) -> None:
        self.now = 0.0

    def __call__(self) -> float:
        return self.now


def _bar(clock: FakeClock):
    bar = progress_bar.trial_bar(total=1000, initial=0, progress=True, desc="test")
    bar.fp = io.StringIO()
    bar._time = clock
    bar.start_t = bar.last_print_t = clock.now
    return bar


def _rate_after_a_stall(leave_out: bool) -> float:
    clock = FakeClock()
    bar = _bar(clock)
    clock.now += 20.0  # the first iteration: kernels compiled
    if leave_out:
        progress_bar.leave_out_stall(bar, 20.0)
    bar.update(1)
    for _ in range(99):  # then 1 ms an iteration
        clock.now += 0.001
        bar.update(1)
    rate = bar.format_dict["n"] / bar.format_dict["elapsed"]
    bar.close()
    return rate


def test_a_stalled_iteration_is_left_out_of_the_rate():
    assert _rate_after_a_stall(leave_out=False) < 10  # what the bar showed before
    assert _rate_after_a_stall(leave_out=True) == pytest.approx(1000, rel=0.05)


def test_an_iteration_at_the_trials_pace_counts():
    clock = FakeClock()
    bar = _bar(clock)
    clock.now += 0.5
    progress_bar.leave_out_stall(bar, 0.5)
    assert bar.start_t == 0.0 and bar.last_print_t == 0.0
    bar.close()


def test_a_trial_leaves_out_the_iterations_that_stalled(tmp_path, monkeypatch):
    """A trial's first iteration made to look 30 s long on the iterations' clock (the others
    take no time on it): the bar's clocks move on by those 30 s, once."""
    ticks = iter([0.0, 30.0])  # the first iteration's start and end
    monkeypatch.setattr(progress_bar, "clock", lambda: next(ticks, 30.0))
    shifts = []
    original = progress_bar.leave_out_stall

    def watch(bar, seconds):
        before = bar.start_t
        original(bar, seconds)
        shifts.append(bar.start_t - before)

    monkeypatch.setattr(progress_bar, "leave_out_stall", watch)
    Trial(tmp_path / "t", TrialSettings(iterations=20, checkpoint_every=20)).run(progress=True)
    assert len(shifts) == 20 and shifts[0] == 30.0 and not any(shifts[1:])
