"""The steady-state plateau rule (docs/model.md, Neuroevolution): ``no-crash`` (default) counts evaluations without a new
champion only once the champion's evaluation completed without crashing; ``literal`` is Appendix A
as written. Also the eonn-style options of :class:`SteadyStateSettings` (selection, initial
population)."""

from __future__ import annotations

import json

import numpy as np
import pytest

from neurohover.errors import NeurohoverError
from neurohover.evolution import SteadyStateNE, SteadyStateSettings, evolve
from neurohover.evolution.common import TellInfo
from neurohover.policies import Policy, prototype
from neurohover.tasks import get_task_family

SMALL = dict(pop_size=5, elite_size=4, plateau_threshold=20)


def _run(opt: SteadyStateNE, returns, crashed, max_tells: int = 500) -> int:
    """Tell ``returns(k)`` / ``crashed(k)`` for the k-th told genome until ``stop()``; tells made."""
    k = 0
    for tells in range(max_tells):
        if opt.stop():
            return tells
        n = len(opt.ask())
        opt.tell([returns(k + i) for i in range(n)], TellInfo(crashed=np.array([crashed(k + i) for i in range(n)])))
        k += n
    return max_tells


def test_default_rule_is_no_crash() -> None:
    assert SteadyStateSettings().plateau_rule == "no-crash"


def test_crashing_champion_stalls_only_under_the_literal_rule() -> None:
    # Every candidate crashes at the same step: the same return, never a new champion.
    stops = {}
    for rule in ("literal", "no-crash"):
        opt = SteadyStateNE(np.zeros(3), SteadyStateSettings(**SMALL, plateau_rule=rule), seed=0)
        stops[rule] = _run(opt, lambda k: -1e5, lambda k: True)
        assert opt.champion_crashed and opt.evaluations_since_champion == opt.evaluations - 1
    assert stops["literal"] == 1 + 16  # the initial population (4 counted), then one offspring per tell
    assert stops["no-crash"] == 500  # never stopped at the plateau


def test_counter_runs_once_the_champion_completes_an_episode() -> None:
    # Crashing candidates for 200 evaluations; evaluation 200 is a non-crashing new champion.
    opt = SteadyStateNE(np.zeros(3), SteadyStateSettings(**SMALL), seed=0)
    tells = _run(opt, lambda k: -100.0 if k == 200 else -1e5 - (k == 0), lambda k: k != 200)
    assert not opt.champion_crashed and opt.champion_return == -100.0
    assert opt.evaluations == 201 + 20 and tells == 1 + 196 + 20
    assert opt.plateau_evaluations == opt.evaluations_since_champion == 20


def test_crashing_new_champion_stops_the_counter_again() -> None:
    opt = SteadyStateNE(np.zeros(3), SteadyStateSettings(**SMALL), seed=0)
    for k in range(10):
        opt.ask()
        opt.tell(np.full(5 if k == 0 else 1, -500.0 + k), TellInfo(crashed=np.array([k >= 5] * (5 if k == 0 else 1))))
    assert opt.champion_crashed and opt.plateau_evaluations == 0 and not opt.stop()


def test_without_crash_flags_both_rules_are_identical() -> None:
    runs = []
    for rule in ("literal", "no-crash"):
        opt = SteadyStateNE(np.zeros(3), SteadyStateSettings(**SMALL, plateau_rule=rule), seed=3)
        while not opt.stop():
            g = opt.ask()
            opt.tell(-np.sum((g - 0.3) ** 2, axis=1))
        runs.append((opt.evaluations, opt.champion_genome.tobytes(), opt.population.tobytes()))
    assert runs[0] == runs[1]


def test_bad_rule_names_are_refused() -> None:
    with pytest.raises(NeurohoverError, match=r"plateau_rule 'loose'.*allowed no-crash, literal"):
        SteadyStateSettings(plateau_rule="loose")
    with pytest.raises(NeurohoverError, match=r"plateau_rule 'loose'.*no-crash, literal"):
        evolve(get_task_family("ghh08").zero(), budget=10, n_steps=5, settings={"plateau_rule": "loose"})
    with pytest.raises(NeurohoverError, match=r"selection 'rank'.*allowed roulette, tournament"):
        SteadyStateSettings(selection="rank")


def test_bad_crash_flags_are_refused() -> None:
    opt = SteadyStateNE(np.zeros(3), SteadyStateSettings(**SMALL), seed=0)
    opt.ask()
    with pytest.raises(ValueError, match="crashed must be 5 booleans"):
        opt.tell(np.zeros(5), TellInfo(crashed=np.array([True, False])))


def test_state_dict_keeps_the_champion_crash_flag() -> None:
    opt = SteadyStateNE(np.zeros(3), SteadyStateSettings(**SMALL), seed=0)
    _run(opt, lambda k: -1e5 + k % 7, lambda k: True, max_tells=30)
    state = json.loads(json.dumps(opt.state_dict(), allow_nan=False))
    again = SteadyStateNE.from_state_dict(state)
    assert again.champion_crashed and again.settings.plateau_rule == "no-crash"
    assert [h.crashed for h in again.history] == [h.crashed for h in opt.history]
    for o in (opt, again):
        _run(o, lambda k: -1e5, lambda k: True, max_tells=100)
    assert again.evaluations == opt.evaluations and not again.stop()
    # A state written before the plateau rule existed resumes under the literal rule.
    del state["settings"]["plateau_rule"]
    assert SteadyStateNE.from_state_dict(state).settings.plateau_rule == "literal"


# --------------------------------------------------------------------------------- through evolve


def _always_crashing() -> Policy:
    proto = prototype("mlp", "baseline")
    return Policy("mlp", np.full_like(proto.genome, 3.0))  # saturated actions: crashes in a few steps


@pytest.mark.slow
@pytest.mark.parametrize("rule,reason", [("literal", "plateau"), ("no-crash", "budget")])
def test_evolve_passes_crash_flags(rule, reason) -> None:
    settings = dict(plateau_threshold=30, pop_size=10, elite_size=9, mutate_frac=0.0, plateau_rule=rule)
    result = evolve(get_task_family("ghh08").zero(), prototype=_always_crashing(), budget=2000, settings=settings, seed=0, n_steps=100, threads=1)
    assert result.stop_reason == reason
    assert (result.episodes < 300) if rule == "literal" else (result.episodes == 2000)


def test_evolve_is_bit_identical_when_the_champion_never_crashes() -> None:
    keys = []
    for rule in ("literal", "no-crash"):
        r = evolve(
            get_task_family("ghh08").zero(),
            topology="slp",
            budget=3000,
            seed=2,
            n_steps=100,
            threads=1,
            settings=dict(plateau_threshold=60, pop_size=10, elite_size=9, plateau_rule=rule),
        )
        keys.append((r.champion.genome.tobytes(), r.champion_return, r.episodes, r.stop_reason, [(h.evaluations, h.champion_return) for h in r.history]))
    assert keys[0] == keys[1] and keys[0][3] == "plateau"


# --------------------------------------------------------------------------------- eonn options


def test_tournament_selection_and_initial_mutation_options() -> None:
    s = SteadyStateSettings(
        pop_size=10, elite_size=9, selection="tournament", tournament_size=5, crossover_prob=1.0, init_mutate_frac=0.5, init_mutate_std=0.5, budget=400
    )
    opt = SteadyStateNE(np.zeros(20), s, seed=1)
    first = opt.ask()
    assert np.array_equal(first[0], np.zeros(20))
    changed = np.mean(first[1:] != 0.0)
    assert 0.35 < changed < 0.65  # init_mutate_frac 0.5, not mutate_frac 0.1
    opt.tell(-np.sum((first - 1.0) ** 2, axis=1))
    while not opt.stop():
        g = opt.ask()
        opt.tell(-np.sum((g - 1.0) ** 2, axis=1))
    assert opt.champion_return > -20.0 * 0.5
    with pytest.raises(ValueError, match=r"tournament_size=11 must be in \[1, pop_size=10\]"):
        SteadyStateSettings(pop_size=10, elite_size=9, selection="tournament", tournament_size=11)
    with pytest.raises(ValueError, match="tournament_size=3 applies to selection='tournament' only, not to selection='roulette'"):
        SteadyStateSettings(tournament_size=3)  # ignored without a word (second trial)
    assert SteadyStateSettings(pop_size=3, elite_size=2).pop_size == 3  # roulette's unused tournament size is no bound on the population


def test_checkpoint_from_before_the_plateau_rule_resumes_under_the_literal_rule(tmp_path) -> None:
    ckpt = tmp_path / "run.json"
    kw = dict(topology="slp", seed=1, n_steps=50, threads=1, checkpoint=ckpt, settings=dict(pop_size=10, elite_size=9, plateau_rule="literal"))
    mdp = get_task_family("ghh08").zero()
    evolve(mdp, budget=100, **kw)
    state = json.loads(ckpt.read_text())
    for key in ("plateau_rule", "selection", "tournament_size", "init_mutate_frac", "init_mutate_std"):
        del state["config"]["settings"][key]
        del state["optimizer_state"]["settings"][key]
    ckpt.write_text(json.dumps(state))
    resumed = evolve(mdp, budget=200, resume=True, **kw)
    straight = evolve(mdp, budget=200, **{**kw, "checkpoint": tmp_path / "other.json"})
    assert resumed.champion.genome.tobytes() == straight.champion.genome.tobytes() and resumed.episodes == 200
    with pytest.raises(NeurohoverError, match=r"written by a different run \(settings\.\w+: the checkpoint.s "):
        evolve(mdp, budget=300, resume=True, **{**kw, "settings": dict(pop_size=10, elite_size=9)})


def test_evolution_result_says_whether_the_champion_crashed() -> None:
    mdp = get_task_family("ghh08").zero()
    crashing = evolve(mdp, topology="slp", prototype="zero", budget=200, seed=1, n_steps=300, threads=1)
    flying = evolve(mdp, topology="mlp", prototype="baseline", budget=200, seed=1, n_steps=300, threads=1)
    assert crashing.champion_crashed and crashing.champion_return < -1e5
    assert not flying.champion_crashed
