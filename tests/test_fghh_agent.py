"""Figure 16 as the authors' code ran it: their FGHH agent, and generics drawn from Figures 13 and 15's champions."""

from __future__ import annotations

import contextlib
import io
from pathlib import Path

import numpy as np
import pytest

from neurohover import NeurohoverError, get_task_family
from neurohover.agents.fghh_code import CodeAgentSettings, CodeFGHHAgent
from neurohover.agents.protocol import run_test
from neurohover.cli import main
from neurohover.experiments import Store, load_config
from neurohover.experiments.plans import plan
from neurohover.policies import load_policy

FGHH = get_task_family("fghh", 0.3)
GENERIC = Path(__file__).parent.parent / "neurohover" / "data" / "policies" / "fghh" / "generic_race.json"


@pytest.mark.parametrize("mdp", [0, 3, 7])
def test_the_authors_agent_flies_the_generic_three_model_policies_then_the_lowest_mean_error(mdp: int) -> None:
    settings = CodeAgentSettings(model_budget=60, n_steps=300)
    agent = CodeFGHHAgent(load_policy(GENERIC), settings)
    r = run_test(agent, FGHH, FGHH.test_mdps()[mdp], episodes=14, seed=mdp, n_steps=300)
    assert r.policy[:4] == ["generic", "model:1", "model:2", "model:3"]
    assert not r.safeguard_fired[0]  # the generic's flight-data episode flies without a safeguard
    errors: dict[str, list[float]] = {}
    for e, label in enumerate(r.policy):
        if e >= 4:  # every later episode: the candidate of lowest mean error so far (the first of equals)
            means = {k: np.mean(v) for k, v in errors.items()}
            assert label == min(means, key=means.get)
        errors.setdefault(label, []).append(settings.fired_error if r.safeguard_fired[e] else -r.returns[e])
    assert agent.errors == errors


def test_the_authors_agent_settings_are_checked() -> None:
    with pytest.raises(NeurohoverError, match="model_budget=10 is out of range"):
        CodeAgentSettings(model_budget=10)
    with pytest.raises(NeurohoverError, match="fired_error=-1 is out of range"):
        CodeAgentSettings(fired_error=-1)


@pytest.fixture(scope="module")
def sources(tmp_path_factory) -> tuple[Path, dict, str]:
    """A store holding quick Figures 13 and 15 (their champions are Figure 16's generics), run as the command line runs
    them: ``reproduce fig16`` on an empty store, its sources first; and what it said on standard error."""
    path = tmp_path_factory.mktemp("fig16") / "store.sqlite"
    said = io.StringIO()
    with contextlib.redirect_stderr(said):
        assert main(["reproduce", "fig16", "--store", str(path), "--no-progress"]) == 0
    with Store(path) as store:
        return path, {name: store.results(name, "quick") for name in ("fig13", "fig15")}, said.getvalue()


@pytest.mark.slow
def test_each_run_draws_its_generic_from_the_sources_champions(sources) -> None:
    _, results, _ = sources
    cfg = load_config("fig16", "quick")
    units = [u for u in plan(cfg, {}, results).units if u.kind == "test_run"]
    fig15 = load_config("fig15", "quick").settings
    races = [v["key"] for v in fig15["variants"] if v["resampling"].startswith("race")]
    best = max(races, key=lambda v: np.mean([results["fig15"][f"evolve/{v}/run{r}"]["champion_return"] for r in range(fig15["runs"])]))
    for u in units:
        p = u.params["policies"]
        source = p["generic_source"]
        if u.params["agent"].endswith("-race"):
            assert source.startswith(f"fig15/evolve/{best}/")
        elif u.params["agent"].endswith("-fixed"):
            assert source.startswith("fig13/evolve/k5/")
        else:
            assert source.startswith("policy/generic-zero")
            continue
        name, key = source.split("/", 1)
        assert p["generic"] == results[name][key]["champion"]
    drawn = [u.params["policies"]["generic_source"] for u in units if u.params["agent"].endswith("-race")]
    assert len(set(drawn)) > 1  # drawn per run, not one for all
    assert [u.params for u in plan(cfg, {}, results).units] == [u.params for u in plan(cfg, {}, results).units]


@pytest.mark.slow
def test_without_its_sources_figure_16_waits_and_says_for_what(sources) -> None:
    cfg = load_config("fig16", "quick")
    p = plan(cfg, {}, {})
    assert not any(u.params.get("agent", "").endswith(("-race", "-fixed")) for u in p.units)
    assert any("fig15" in w and "not in the store yet" for w in p.waiting)
    # On the command line the sources run first, into the same store (the fixture's run, on an empty store).
    path, results, err = sources
    assert "running fig13 first" in err and "running fig15 first" in err
    with Store(path) as store:  # and then Figure 16, its runs on the sources' generics too
        stored = store.results("fig16", "quick")
    assert {u.key for u in plan(cfg, {}, results).units} <= set(stored)
    assert {k.split("/")[1].rsplit("-", 1)[-1] for k in stored if k.startswith("run/")} >= {"race", "fixed"}


def test_a_bad_generics_source_is_refused() -> None:
    with pytest.raises(NeurohoverError, match="generics_from = { fixed = 'fig13' } is not allowed"):
        load_config("fig16", "quick", {"generics_from": {"fixed": "fig13"}})
    with pytest.raises(NeurohoverError, match="fig13 has no variant 'k7'"):
        plan(load_config("fig16", "quick", {"generics_from": {"fixed": "fig13/k7"}}), {}, {})


@pytest.mark.slow
def test_the_report_shows_fghh_runs_on_their_fitness_scale_beside_the_authors_generics(sources, tmp_path: Path) -> None:
    import json

    from neurohover.experiments import write_report

    path, results, _ = sources
    out = tmp_path / "report"
    out.mkdir()
    flights = {"returns": [[-150.0, -1e7], [-1000.0, -200.0]], "crashed": [[False, True], [False, False]]}
    (out / "authors-fghh-generics.json").write_text(json.dumps({"fig13-quick": {"resampling_05": flights}}))
    with Store(path) as store:
        text = write_report(store, out, scale="quick", names=["fig13"]).read_text()
    assert "| setting | runs | final fitness estimate (mean) | as error | validation crash rate | median error | mean 1/ln(error) |" in text
    k5 = [results["fig13"][f"evolve/k5/run{r}"]["champion_return"] for r in range(3)]
    assert f"| k = 5 | 3 | {np.mean(k5):.4g} |" in text
    # The authors' row: 1 crash in 4 episodes, median error 600, mean over policies of their mean 1/ln(error).
    fits = np.mean([np.mean([1 / np.log(150), 1 / np.log(1e7)]), np.mean([1 / np.log(1000), 1 / np.log(200)])])
    assert f"| the authors' resampling_05 (2 files) | 2 |  |  | 25.0% | 600 | {fits:.4g} |" in text
    assert (out / "fig13-quick.png").is_file()


@pytest.mark.slow
def test_fresh_never_discards_the_sources_run_first(sources, tmp_path: Path, capsys) -> None:
    store = tmp_path / "s.sqlite"
    store.write_bytes(sources[0].read_bytes())  # Figures 13 and 15 finished, as a first fig16 run leaves them
    with Store(store) as s:
        before = {u["key"]: u["finished"] for u in s.units("fig13", "quick")}
    assert main(["reproduce", "fig16", "--store", str(store), "--fresh", "--no-progress"]) == 0
    with Store(store) as s:
        assert {u["key"]: u["finished"] for u in s.units("fig13", "quick")} == before  # kept, not recomputed
    assert "fig13 (quick): finished; ran 0 units" in capsys.readouterr().out


@pytest.mark.slow
def test_the_report_compares_variants_of_either_scale_on_the_test_mdps(tmp_path: Path) -> None:
    from neurohover.experiments import write_report

    store = tmp_path / "s.sqlite"
    assert main(["reproduce", "ablation-fghh", "--store", str(store), "--no-progress"]) == 0
    with Store(store) as s:
        text = write_report(s, tmp_path / "out", scale="quick", names=["ablation-fghh"]).read_text()
    assert "| raw-return means | 2 | " in text and "(a return) |" in text  # its estimate is a mean return
    assert "Ranking by mean validation 1/ln(error)" in text  # every variant compared on the test MDPs' 1/ln(error)
