"""Trial 50, evolution and integrations (T50-B01, T50-B03, T50-B04).

- T50-B01: ``evolve_topology`` (and every neat-python config) wrote its config through ``tempfile.mkstemp``; a temporary
  folder removed mid-session (a job's TMPDIR cleaned; Python keeps the first one it found) was a FileNotFoundError
  traceback. neat-python's ``Config`` reads a file by name only, so the file stays; a folder that cannot take it is one
  OutputError naming it and what is allowed (``paths.temp_text_file``).
- T50-B03: OpenAI-ES's ``l2`` and ``epsilon`` had no upper bound: l2=1e300 overflowed Adam's second moment to inf (a
  NumPy warning only) and the checkpoint written held it, which its own resume refused; epsilon=1e300 froze the mean
  without a word. Both are capped (``MAX_L2``, ``MAX_EPSILON``), and an update that would leave a state its resume
  refuses stops the run, the state unchanged.
- T50-B04: ``EonnSettings``' pop_size and generations had no cap (pop_size 10**18 grew memory without end): pop_size is
  2..MAX_POPULATION, generations 1..MAX_BUDGET and the episodes they fly at most MAX_BUDGET, as ``evolve``'s budget.
"""

from __future__ import annotations

import tempfile
import warnings

import numpy as np
import pytest

from neurohover import NeurohoverError, get_task_family
from neurohover.errors import OutputError
from neurohover.evolution.config import MAX_BUDGET
from neurohover.evolution.eonn import EonnSettings, eonn_evolve
from neurohover.evolution.optimisers.openai_es import MAX_EPSILON, MAX_L2, OpenAIES, OpenAIESSettings
from neurohover.integrations.neat import NeatSettings, evolve_topology, neat_config
from neurohover.paths import temp_text_file
from neurohover.policies import baseline_policy

FAMILY = get_task_family("ghh08")


# ----------------------------------------------------------------- T50-B01


def test_a_removed_temporary_folder_is_named_not_a_traceback(tmp_path, monkeypatch) -> None:
    gone = tmp_path / "gone"
    gone.mkdir()
    monkeypatch.setattr(tempfile, "tempdir", str(gone))  # as Python caches it after its first use
    gone.rmdir()
    with pytest.raises(OutputError, match=r"the temporary folder '.*gone': cannot write neat-python's config file in it .*TMPDIR naming a writable"):
        evolve_topology(FAMILY.zero(), budget=8, n_steps=10, settings={"pop_size": 4})
    with pytest.raises(OutputError, match="the temporary folder"):
        neat_config(NeatSettings())


def test_neat_config_leaves_no_temporary_file(tmp_path, monkeypatch) -> None:
    monkeypatch.setattr(tempfile, "tempdir", str(tmp_path))
    assert neat_config(NeatSettings(pop_size=4)).pop_size == 4
    with temp_text_file("abc", "a test file") as path:
        assert open(path, encoding="utf-8").read() == "abc"
    assert not list(tmp_path.iterdir())


# ----------------------------------------------------------------- T50-B03


@pytest.mark.parametrize(
    ("name", "value", "allowed"),
    [
        ("l2", 1e300, "finite number >= 0 and <= 1e[+]20 [(]a larger one overflows Adam's moments[)]"),
        ("l2", MAX_L2 * 1.5, "<= 1e[+]20"),
        ("l2", -1.0, ">= 0 and <= 1e[+]20$"),
        ("epsilon", 1e300, "finite number > 0 and <= 1 [(]a larger one, not the gradient, sets Adam's step"),
        ("epsilon", 0.0, "> 0 and <= 1$"),
        ("epsilon", float("inf"), "> 0 and <= 1"),
    ],
)
def test_openai_es_l2_and_epsilon_are_capped(name, value, allowed) -> None:
    with pytest.raises(NeurohoverError, match=rf"^{name}=.* must be a .*{allowed}"):
        OpenAIESSettings(**{name: value})


def test_openai_es_takes_its_largest_l2_and_epsilon_and_resumes(tmp_path) -> None:
    from neurohover.evolution import evolve

    mdp = FAMILY.training_mdps()[0]
    ck = tmp_path / "ck.json"
    # the widest gradient: sigma at its smallest, l2 at its largest; Adam's moments stay finite, its resume takes them
    s = {"l2": MAX_L2, "epsilon": MAX_EPSILON, "sigma": 1e-100, "learning_rate": 1e100, "beta1": 0.0, "popsize": 4}
    with warnings.catch_warnings():
        warnings.simplefilter("error", RuntimeWarning)
        evolve(mdp, topology="slp", prototype="baseline", budget=8, seed=0, n_steps=10, optimizer="openai-es", settings=s, checkpoint=ck)
        evolve(mdp, topology="slp", prototype="baseline", budget=16, seed=0, n_steps=10, optimizer="openai-es", settings=s, checkpoint=ck, resume=True)


def test_an_update_its_resume_would_refuse_stops_the_run() -> None:
    opt = OpenAIES(baseline_policy().genome, OpenAIESSettings(popsize=4), seed=0)
    object.__setattr__(opt.settings, "l2", 1e300)  # as an unchecked setting would: the update overflows
    opt.ask()
    stopped = r"OpenAI-ES stopped at generation 1: Adam's second moment's gene 1 became inf, which is not allowed: allowed finite numbers"
    with pytest.raises(NeurohoverError, match=stopped + "; give smaller settings$"):
        opt.tell(np.array([-1.0, -2.0, -3.0, -4.0]))
    assert opt.generation == 0
    assert opt.state_dict()["adam"] == OpenAIES(baseline_policy().genome, OpenAIESSettings(popsize=4)).state_dict()["adam"]  # unchanged: zeros
    assert np.array_equal(opt.mean, baseline_policy().genome)


# ----------------------------------------------------------------- T50-B04


@pytest.mark.parametrize(
    ("settings", "message"),
    [
        ({"pop_size": 10**18, "generations": 1}, r"pop_size=1000000000000000000 is out of range: allowed an integer in 2..100,000$"),
        ({"pop_size": 100_001}, r"pop_size=100001 is out of range: allowed an integer in 2..100,000$"),
        ({"generations": MAX_BUDGET + 1}, r"generations=10000000001 is out of range: allowed an integer in 1..10,000,000,000$"),
        (
            {"generations": MAX_BUDGET},
            r"generations=10000000000 is out of range: with pop_size=50 and keep=49 it flies 10,000,000,050 episodes; "
            r"allowed at most 10,000,000,000 episodes \(as evolve's budget\), so generations in 1..9,999,999,950$",
        ),
    ],
)
def test_eonn_pop_size_and_generations_are_capped(settings, message) -> None:
    with pytest.raises(NeurohoverError, match=message):
        EonnSettings(**settings)
    with pytest.raises(NeurohoverError, match="bad eonn settings: " + message):
        eonn_evolve(FAMILY.training_mdps()[0], baseline_policy(), settings=settings)


def test_eonn_takes_its_largest_settings() -> None:
    assert EonnSettings(pop_size=100_000, keep=0, generations=99_999).episodes == MAX_BUDGET
    assert EonnSettings(generations=MAX_BUDGET - 50).episodes == MAX_BUDGET
