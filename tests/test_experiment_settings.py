"""Typed experiment settings (neurohover.experiments.settings) and unit params (neurohover.experiments.params)."""

from __future__ import annotations

import dataclasses

import pytest

from neurohover import NeurohoverError
from neurohover.experiments import params, settings
from neurohover.experiments.config import experiment_names, load_config
from neurohover.experiments.params import PARAMS, unit_params
from neurohover.experiments.plans import plan
from neurohover.experiments.schema import SCHEMAS
from neurohover.experiments.settings import KIND_SETTINGS, EvolutionSettings, Group, Variant


def test_every_schema_key_is_a_field_of_its_kinds_settings_class() -> None:
    nested = {"variants": Variant, "groups": Group, "conditions": settings.Condition, "fits": settings.Fit}
    for kind, schema in SCHEMAS.items():
        names = {f.name for f in dataclasses.fields(KIND_SETTINGS[kind])}
        assert set(schema) == names, kind
        for key, (_, check) in schema.items():
            if isinstance(check, tuple):  # a list of sub-tables
                assert set(check[1]) == {f.name for f in dataclasses.fields(nested[key])}, key


def test_a_default_written_in_both_the_schema_and_the_settings_class_is_the_same() -> None:
    """Issue 34: the schema (what a config gets when it leaves a setting out) and the typed settings (what the planner
    reads) name each default twice; they must agree. (A setting the schema omits when absent, added later, has only
    the class's default; one the schema always fills may have none in the class.)"""
    from neurohover.experiments.schema import OMIT, REQUIRED

    nested = {"variants": Variant, "groups": Group, "conditions": settings.Condition, "fits": settings.Fit}
    tables = [(KIND_SETTINGS[kind], schema) for kind, schema in SCHEMAS.items()]
    tables += [(nested[key], check[1]) for schema in SCHEMAS.values() for key, (_, check) in schema.items() if isinstance(check, tuple)]
    for cls, schema in tables:
        for f in dataclasses.fields(cls):
            default, _ = schema[f.name]
            ours = f.default if f.default is not dataclasses.MISSING else f.default_factory() if f.default_factory is not dataclasses.MISSING else None
            if default is REQUIRED or default is OMIT or (ours is None and f.default is dataclasses.MISSING):
                continue  # required; added later (the class's default is what its absence means); or always filled in
            assert (tuple(default) if isinstance(default, list) else default) == ours, (cls.__name__, f.name, default, ours)


@pytest.mark.slow
@pytest.mark.parametrize("scale", ["quick", "paper"])
def test_every_shipped_config_reads_as_its_typed_settings(scale: str) -> None:
    for name in experiment_names():
        cfg = load_config(name, scale)
        typed = cfg.typed
        assert isinstance(typed, KIND_SETTINGS[cfg.kind])
        assert typed.task == cfg.settings["task"] and typed.seed == cfg.settings["seed"]
        if isinstance(typed, EvolutionSettings):
            assert [v.key for v in typed.variants] == [v["key"] for v in cfg.settings["variants"]]
        if isinstance(typed, settings.TestRunsSettings):
            assert [g.label for g in typed.groups] == [g["label"] for g in cfg.settings["groups"]]
        with pytest.raises(dataclasses.FrozenInstanceError):
            typed.seed = 1  # type: ignore[misc]


@pytest.mark.slow
@pytest.mark.parametrize("scale", ["quick", "paper"])
def test_every_planned_unit_reads_as_its_typed_params(scale: str) -> None:
    kinds = set()
    for name in experiment_names():
        cfg = load_config(name, scale)
        try:  # test runs need policies: the shipped sets plan every run at once
            units = plan(load_config(name, scale, {"policies": "shipped"}), {}, {}).units if cfg.kind == "test_runs" else plan(cfg, {}, {}).units
        except NeurohoverError:  # FGHH runs drawing several generics per agent take no policy set
            units = plan(cfg, {}, {}).units
        for unit in units:
            if unit.kind in PARAMS:
                params = unit_params(unit.kind, unit.params)
                assert params.seed == unit.params["seed"]
                kinds.add(unit.kind)
    assert kinds >= {"evolve", "test_run"}


def test_unit_params_refuse_a_key_they_do_not_declare() -> None:
    fields = {f.name: None for f in dataclasses.fields(params.TestRunParams) if f.default is dataclasses.MISSING}
    with pytest.raises(ValueError, match="does not declare"):
        unit_params("test_run", {**fields, "sensr": {}})
    assert unit_params("test_run", fields).sensor is None


def test_a_group_with_seeds_of_flies_the_seeds_of_the_other_experiments_group() -> None:
    # wind-fig8's groups take Figure 8's seeds: its wind-blind runs are Figure 8's runs, and the wind-aware
    # runs fly the same gusts (the paired comparison issue 22 asks for).
    figure = {u.key: u.params["seed"] for u in plan(load_config("fig8", "paper", {"policies": "shipped"}), {}).units}
    wind = {u.key: u.params["seed"] for u in plan(load_config("wind-fig8", "paper"), {}).units}
    assert wind["run/incremental/wind-aware/train3/rep5"] == wind["run/incremental/wind-blind/train3/rep5"] == figure["run/incremental/train3/rep5"]
    assert wind["run/hybrid/wind-aware/train0/rep0"] == figure["run/hybrid/train0/rep0"] != figure["run/hybrid/train0/rep1"]


@pytest.mark.parametrize(
    "bad",
    [{"experiment": "fig8", "seed": 2010}, {"experiment": "", "seed": 1, "group": "hybrid"}, {"experiment": "fig8", "seed": -1, "group": "hybrid"}, "fig8"],
)
def test_a_bad_seeds_of_is_refused_when_the_config_loads(bad) -> None:
    with pytest.raises(NeurohoverError, match="seeds_of"):
        load_config("wind-fig8", "paper", {"groups": [{"agent": "hybrid", "n_mdps": 1, "seeds_of": bad}]})


@pytest.mark.parametrize(("key", "value"), [("runs", 10**13), ("n_steps", 10**13), ("budget", 10**13), ("validation_episodes", 10**13)])
def test_sizes_beyond_what_planning_and_memory_hold_are_refused_when_the_config_loads(key: str, value: int) -> None:
    """`--set runs=10**13` planned for minutes and grew until stopped (bad-input trial): refused up front, the limit named."""
    with pytest.raises(NeurohoverError, match=rf"{key} = {value} is not allowed: expected an integer in \d+\.\.\d+"):
        load_config("fig2", "quick", {key: value})
