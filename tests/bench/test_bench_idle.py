"""`playroom bench world` times the Python a physical iteration runs after its MuJoCo steps,
back to back and after a gap."""

from __future__ import annotations

import math

from experiments.bench import idle


def test_the_after_step_calls_are_timed_after_each_gap_and_compared(monkeypatch) -> None:
    monkeypatch.setattr(idle, "_SAMPLES", 5)
    figures = {name: (value, unit) for name, value, unit in idle.idle_figures()}
    assert list(figures) == [
        "after_step_calls_back_to_back",
        "after_step_calls_after_500_mj_step",
        "after_step_calls_after_as_long_a_python_loop",
        "after_step_calls_after_mj_step_over_back_to_back",
    ]
    back_to_back = figures["after_step_calls_back_to_back"][0]
    after_steps = figures["after_step_calls_after_500_mj_step"][0]
    assert back_to_back > 0 and after_steps > 0
    ratio = figures["after_step_calls_after_mj_step_over_back_to_back"]
    assert ratio[1] == "ratio" and math.isclose(ratio[0], after_steps / back_to_back)
