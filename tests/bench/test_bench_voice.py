"""`playroom bench voice` measures DIVA's vocal part beside VocalTractLab's, in one run, or says
why it could not."""

from __future__ import annotations

import math

from experiments.bench.sections import voice_figures
from sim.vocal.diva import data


def test_diva_is_measured_beside_vtl_when_its_map_is_installed(installed_generated_map) -> None:
    figures = {name: (value, unit) for name, value, unit in voice_figures(repeats=3)}
    diva_ms, vtl_ms = figures["act_voice_vocal_part_diva"][0], figures["act_voice_vocal_part"][0]
    assert diva_ms > 0 and vtl_ms > 0
    ratio = figures["diva_over_vtl_vocal_part"][0]
    assert math.isclose(ratio, diva_ms / vtl_ms, rel_tol=1e-9)


def test_without_diva_s_map_the_bench_says_so(tmp_path, monkeypatch) -> None:
    monkeypatch.setenv(data.DATA_ENV, str(tmp_path))
    figures = {name: (value, unit) for name, value, unit in voice_figures(repeats=3)}
    value, unit = figures["act_voice_vocal_part_diva"]
    assert math.isnan(value) and "not installed" in unit
    assert "diva_over_vtl_vocal_part" not in figures
