"""The fifteenth bad-input trial's findings in the numbers the command line and the settings texts read: each gives one
clear message (exit 2 / NeurohoverError) naming the value and what is allowed."""

from __future__ import annotations

import pytest

from neurohover.errors import NeurohoverError


@pytest.mark.parametrize(
    ("args", "message"),
    [
        (("--obs-noise", "level=1_0"), "sensor setting 'level=1_0' needs a number after '='"),
        (("--obs-noise", "1_0"), "sensor setting '1_0' is not understood"),
        (("--params", "1_0,2"), "--params must be comma-separated numbers, got '1_0,2'"),
    ],
)
def test_a_number_with_an_underscore_is_refused(cli, args, message: str) -> None:
    """T15-13: float() reads '1_0' as 10, so a sensor flew at level 10 and a wind was called [10.0, 2.0]."""
    rc, _, err = cli("fly", "--task", "ghh08", "--episodes", "1", *args)
    assert rc == 2 and message in err


def test_settings_texts_refuse_a_number_with_an_underscore() -> None:
    """T15-13, the Python side of the same parsers (Sensor.parse, Drift.parse)."""
    from neurohover.tasks import Drift, Sensor

    with pytest.raises(NeurohoverError, match="'level=1_0' needs a number after '='"):
        Sensor.parse("level=1_0")
    with pytest.raises(NeurohoverError, match="drift 'walk=1_0' is not understood"):
        Drift.parse("walk=1_0")


def test_the_model_based_agents_refuse_model_substeps_true() -> None:
    """The models fixer's note on T15-29: ModelEvolution(model_substeps=True) was taken as 1 (True in (1, 10)); the
    agents' settings now share the learned model's one check of its substeps."""
    from neurohover.agents.fghh_code import CodeAgentSettings
    from neurohover.agents.model_based import ModelEvolution

    for cls in (ModelEvolution, CodeAgentSettings):
        with pytest.raises(NeurohoverError, match=r"model_substeps=True: allowed 1 or 10"):
            cls(model_substeps=True)
    assert ModelEvolution(model_substeps=10).model_substeps == 10


def test_the_gpu_benchmarks_refuse_a_flag_that_is_no_bool() -> None:
    """T15-26 on the GPU side (the plots fixer's note): gpu_benchmarks(quick='no') was true."""
    from neurohover.bench_gpu import gpu_benchmarks

    with pytest.raises(NeurohoverError, match=r"quick='no' is not allowed: give True \(a short run\) or False"):
        gpu_benchmarks(quick="no")  # type: ignore[arg-type]


def test_flags_of_the_python_api_take_true_or_false_only() -> None:
    """After T15-16 and T15-26 (truthy text taken as True), the same class elsewhere: fit_wind(fit_drags='no') fitted the
    drags; one check, errors.check_flag."""
    from neurohover.models.wind import fit_wind

    with pytest.raises(NeurohoverError, match=r"fit_drags='no' is not allowed: give True \(fit the u and v drags too\) or False"):
        fit_wind(_transitions(), "constant", 0.1, 0.1, 0.1, fit_drags="no")  # type: ignore[arg-type]


def test_sb3_loaders_take_a_deterministic_flag_of_true_or_false_only() -> None:
    """The same class: sb3_policy/rl_zoo_policy(deterministic='no') were deterministic."""
    pytest.importorskip("stable_baselines3", reason="the examples extra (Stable-Baselines3) is not installed")
    from neurohover.integrations.sb3 import rl_zoo_policy, sb3_policy

    for load in (sb3_policy, rl_zoo_policy):  # checked before the file (and Stable-Baselines3) is needed
        with pytest.raises(NeurohoverError, match=r"deterministic='no' is not allowed: give True \(the Gaussian's mean\) or False"):
            load("missing.zip", deterministic="no")  # type: ignore[arg-type]


def _transitions():
    import neurohover as nh
    from neurohover.models import Transitions

    fd = nh.evaluate(nh.baseline_policy(), nh.get_task_family("ghh08").mdp("train:1"), episodes=1, record=True, n_steps=30).flight_data
    return Transitions(fd)
