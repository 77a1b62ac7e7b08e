"""The benchmark report's format: figures and the fraction of one core's estimated limit."""

from __future__ import annotations

from neurohover.bench import ESTIMATED_LIMIT_PER_CORE, format_report


def test_the_report_states_the_fraction_of_the_estimated_limit() -> None:
    one = 750.0
    report = {
        "machine": {"cores": 2, "cpu": "x86_64"},
        "workload": "MLP",
        "reference_episodes_per_second": 1.0,
        "kernel_1_core": {
            "episodes_per_second": one,
            "substeps_per_second": one * 60000,
            "speedup_vs_reference": one,
            "fraction_of_estimated_limit": [one / ESTIMATED_LIMIT_PER_CORE[1], one / ESTIMATED_LIMIT_PER_CORE[0]],
        },
        "gpu": {"status": "no CUDA device"},
    }
    text = format_report(report)
    assert "15%-25% of one core's estimated limit" in text
    assert "no CUDA device" in text
