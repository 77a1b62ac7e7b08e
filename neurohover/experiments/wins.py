"""The competition simulator (issue 22): from stored test runs, each agent's probability of winning a
competition of N runs against the others.

A competition, as the RL Competitions ran GHH: every agent flies one test run on each of N MDPs
drawn from the task family, and the agent with the highest total cumulative reward wins. One crash
costs about 1e7, so the agent best in expectation need not win most often (the paper: "the optimal
amount of risk aversion is a function of known factors such as the number of test runs"). We
estimate the odds by the bootstrap: each simulated competition draws N of the MDPs that every agent
flew (with replacement) and, for each agent and MDP, one of its stored runs there; ties share the
win. Drawing MDPs first keeps the agents paired on the same MDPs, as in a competition.
"""

from __future__ import annotations

from collections.abc import Iterator, Mapping, Sequence, Sized

import numpy as np

from ..errors import NeurohoverError, as_floats, brief, whole_in
from ..evolution.seeding import check_seed
from .config import COMPETE_PREFIX
from .keys import UnitKey
from .results import TestRunResult

__all__ = ["DEFAULT_DRAWS", "WinOdds", "one_agent", "several_groups", "stored_runs", "win_probabilities"]

DEFAULT_DRAWS = 10_000
_MAX_CELLS = 50_000_000  # draws x runs per agent held at once: about 400 MB of float64


class WinOdds(dict):
    """Agent -> probability of winning (a dict), with ``n_runs``, ``draws``, ``mdps`` (MDPs shared by every agent)."""

    n_runs: int
    draws: int
    mdps: int

    def standard_error(self, agent: str) -> float:
        """The bootstrap estimate's binomial standard error."""
        p = self[agent]
        return float(np.sqrt(p * (1.0 - p) / self.draws))


def win_probabilities(runs: Mapping[str, Mapping[str, Sequence[float]]], n_runs: int, draws: int = DEFAULT_DRAWS, seed: int = 0) -> WinOdds:
    """Each agent's probability of the highest total over a competition of ``n_runs`` runs.

    Parameters
    ----------
    runs : mapping
        Agent label -> {MDP label -> the cumulative rewards of its runs on that MDP}. Only MDPs that
        every agent flew take part.
    n_runs : int
        Runs in a competition (the RL Competitions: one per MDP; 20 for GHH-09's paper analysis).
    draws : int
        Simulated competitions.
    seed : int
        Seed of the bootstrap (results depend on nothing else).

    Returns
    -------
    WinOdds
        Agent -> probability; the probabilities sum to 1.
    """
    # T24-11: 1.5 or True "is not allowed" (a type), 0 "is out of range" (both said out of range); the bound below
    n_runs, draws = (whole_in(v, name, 1, _MAX_CELLS, f"{_MAX_CELLS:,} (draws x n_runs)") for name, v in (("n_runs", n_runs), ("draws", draws)))
    seed = check_seed(seed)  # every seed's range, 0..2**63-1: 2**64 was taken (sixteenth trial T16-17)
    if draws * n_runs > _MAX_CELLS:
        raise NeurohoverError(f"draws x n_runs = {draws * n_runs:,} is too large: at most {_MAX_CELLS:,} simulated runs per agent at once")
    if not isinstance(runs, Mapping) or not all(isinstance(r, Mapping) for r in runs.values()):  # [1, 2] was an AttributeError (thirteenth trial, F20)
        raise NeurohoverError(f"runs={brief(runs)} is not allowed: give a dict of agent -> {{MDP -> cumulative rewards of its runs}}")
    agents = list(runs)
    if len(agents) < 2:
        raise NeurohoverError(f"a competition needs at least two agents, got {agents}")
    common = sorted(set.intersection(*(set(m for m, s in runs[a].items() if _run_count(a, m, s)) for a in agents)))
    if not common:
        raise NeurohoverError(f"the agents {', '.join(agents)} flew no MDP in common: their runs cannot be paired into competitions")
    rng = np.random.default_rng(seed)
    picks = rng.integers(len(common), size=(draws, n_runs))
    totals = np.empty((len(agents), draws))
    for i, agent in enumerate(agents):
        pools = [_scores(agent, m, runs[agent][m]) for m in common]
        counts = np.array([p.size for p in pools])
        flat = np.concatenate(pools)
        start = np.concatenate([[0], np.cumsum(counts)[:-1]])
        which = (rng.random((draws, n_runs)) * counts[picks]).astype(np.int64)
        totals[i] = flat[start[picks] + which].sum(axis=1)
    best = totals.max(axis=0)
    winners = totals == best
    share = winners / winners.sum(axis=0)  # ties share the win
    odds = WinOdds({a: float(share[i].mean()) for i, a in enumerate(agents)})
    odds.n_runs, odds.draws, odds.mdps = n_runs, draws, len(common)
    return odds


def _run_count(agent: str, mdp: str, scores: object) -> int:
    """How many runs ``agent`` has on ``mdp``: its scores must be a list or array of them (a number or a one-shot iterator
    was a TypeError "has no len()"; an iterator is refused as Drift and the models' vectors refuse one; T44-B01)."""
    if isinstance(scores, Iterator) or not isinstance(scores, Sized) or getattr(scores, "ndim", 1) == 0:
        one_shot = ", not a one-shot iterator" if isinstance(scores, Iterator) else ""
        raise NeurohoverError(
            f"agent {agent!r} has runs on MDP {mdp!r} given as {brief(scores)}: give a list of the cumulative rewards of its runs there{one_shot}"
        )
    return len(scores)


def _scores(agent: str, mdp: str, scores: Sequence[float]) -> np.ndarray:
    """One agent's scores on one MDP as float64, all finite (NaN was refused; text was NumPy's "could not convert")."""
    try:  # the one array check: '12' was read as 12.0, True as 1.0 and a masked array's hidden values used (T16-9, T16-11)
        pool = as_floats(scores, "scores", "real numbers").ravel()
    except NeurohoverError as err:
        why = str(err).rpartition(" (")[2].rstrip(")") or "real numbers"
        raise NeurohoverError(f"agent {agent!r} has a run whose score is not a finite number: {brief(scores)} on MDP {mdp!r} (give {why})") from None
    if not np.all(np.isfinite(pool)):
        raise NeurohoverError(f"agent {agent!r} has a run whose score is not a finite number: {brief(scores)} on MDP {mdp!r}")
    return pool


def stored_runs(results: Mapping[str, dict]) -> dict[str, dict[str, list[float]]]:
    """Group label -> {MDP label -> cumulative rewards} of an experiment's stored test runs (its ``run/``
    units; ``results``: unit key -> result, as :meth:`neurohover.experiments.Store.results` gives them)."""
    runs: dict[str, dict[str, list[float]]] = {}
    for key, result in results.items():
        unit = UnitKey.parse(key)
        if unit.stage == "run":
            try:  # read as results, report and reproduce read it (only its score was checked; eighth trial)
                run = TestRunResult.from_dict(result, f"result of test_run unit {key!r}")
            except NeurohoverError as err:
                raise NeurohoverError(f"the stored result of unit {key!r} is damaged: {err}") from None
            runs.setdefault(unit.group, {}).setdefault(str(run.mdp), []).append(float(run.score))
    return runs


def several_groups(store) -> list[str]:
    """'NAME (SCALE)' of each test-runs experiment in ``store`` (a :class:`~.store.Store`) that plans two or more groups:
    those ``wins`` can compare (a damaged config is left out; the command that reads it says why)."""
    out = []
    for name, scale, _, _ in store.experiments():
        try:
            groups = store.config(name, scale).get("settings", {}).get("groups")
        except NeurohoverError:
            continue
        if isinstance(groups, list) and len(groups) >= 2:
            out.append(f"{name} ({scale})")
    return out


def one_agent(name: str, scale: str, label: str, others: list[str]) -> str:
    """The refusal of ``wins`` on experiment ``name`` whose stored test runs are of one group (``label``) only, saying
    what works: a compete experiment holds one agent each, and wins compares the groups of one experiment (it said only
    "a competition needs at least two agents, got ['baseline']", though its help offered compete scales; T34-A03).
    ``others``: the store's experiments that :func:`several_groups` finds."""
    compete = ", as every `neurohover compete` experiment does," if name.lower().startswith(COMPETE_PREFIX) else ""
    where = f"this store's {', '.join(others)}" if others else "none in this store"
    return (
        f"experiment {name!r} ({scale}) holds the test runs of one agent ({label}){compete} and a competition needs two or more: "
        f"wins compares the groups of one experiment; give a test-runs experiment of two or more groups ({where}), such as a "
        "reproduce of fig7 or a config of your own with a group per agent"
    )
