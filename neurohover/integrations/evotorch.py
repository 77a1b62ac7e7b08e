"""EvoTorch over the batched kernel: a whole population flown in one call.

EvoTorch's ``GymNE`` steps one environment at a time in Python. :class:`HoverProblem` is an
EvoTorch ``Problem`` whose batched evaluation flies every solution of a population (SLP or MLP
genomes in neurohover's order, docs/model.md, Policies) in one :func:`neurohover.evaluate_jobs`
call, and maximises the mean return::

    from evotorch.algorithms import SNES
    from neurohover.integrations.evotorch import HoverProblem

    problem = HoverProblem("ghh08", mdps="train:3", topology="slp", episodes=2, n_steps=1000)
    searcher = SNES(problem, stdev_init=0.05, center_init=problem.baseline_center())
    searcher.run(20)

``mdps``: an MDP name of the family (``"zero"``, ``"train:N"``, ...), a list of them, or
``"sample"``: every solution's episodes each on a fresh MDP from G. Each evaluation flies fresh
episode indices of the gust streams of ``seed``, so no two evaluations share noise.
Needs ``evotorch`` (``pip install evotorch``; it brings torch).
"""

from __future__ import annotations

import numpy as np

from ..errors import NeurohoverError, whole_in

try:
    import torch
    from evotorch import Problem, SolutionBatch
except ModuleNotFoundError as missing:  # the optional extra
    raise NeurohoverError(f"neurohover.integrations.evotorch needs {missing.name}: pip install 'neurohover[evotorch]'") from None

from ..evaluate import MAX_EPISODES_PER_CALL, PolicyTable, evaluate_jobs
from ..evolution.seeding import check_seed
from ..policies import GENOME_LENGTH, TOPOLOGIES, prototype
from ..sim.constants import EPISODE_STEPS
from ..tasks import get_task_family

__all__ = ["HoverProblem"]


class HoverProblem(Problem):
    """Maximise a genome's mean return over ``episodes`` episodes (see the module docstring)."""

    def __init__(
        self,
        task: str = "ghh08",
        *,
        sigma: float | None = None,
        mdps: str | list[str] = "zero",
        topology: str = "slp",
        episodes: int = 1,
        n_steps: int = EPISODE_STEPS,
        seed: int = 0,
        initial_bounds: tuple[float, float] = (-0.1, 0.1),
    ) -> None:
        if topology not in TOPOLOGIES:
            raise NeurohoverError(f"topology={topology!r} is not allowed: use {', '.join(TOPOLOGIES)}")
        # T24-11: 1.5 or True "is not allowed" (a type), 0 "is out of range" (both said out of range); each call's bound
        episodes = whole_in(episodes, "episodes", 1, MAX_EPISODES_PER_CALL, f"{MAX_EPISODES_PER_CALL:,} (solutions x episodes in one call)")
        self.family = get_task_family(task, sigma)
        self.sample = mdps == "sample"
        self.rows = None if self.sample else np.array([self.family.mdp(m).row() for m in ([mdps] if isinstance(mdps, str) else mdps)])
        self.topology, self.episodes, self.n_steps = topology, episodes, n_steps
        self.seed = check_seed(seed)
        self._rng = np.random.default_rng(np.random.SeedSequence(self.seed, spawn_key=(7,)))
        self._next_episode = 0
        self.steps_flown = 0  # control steps flown by all evaluations so far
        super().__init__("max", solution_length=GENOME_LENGTH[topology], initial_bounds=initial_bounds, dtype=torch.float64)

    def baseline_center(self) -> torch.Tensor:
        """The baseline-equivalent genome of the topology (a centre for a search from the baseline)."""
        return torch.tensor(prototype(self.topology, "baseline").genome.copy(), dtype=torch.float64)

    def _evaluate_batch(self, solutions: SolutionBatch) -> None:
        genomes = solutions.values.detach().cpu().numpy().astype(np.float64)
        p, k = genomes.shape[0], self.episodes
        if self.sample:
            rows = self.family.sample_rows(self._rng, p * k)
            m = np.arange(p * k)
        else:
            assert self.rows is not None  # named MDPs
            rows = self.rows
            m = np.tile(np.arange(k), p) % len(rows) if len(rows) > 1 else np.zeros(p * k, dtype=np.int64)
        episodes = self._next_episode + np.arange(p * k)
        self._next_episode += p * k
        ev = evaluate_jobs(
            PolicyTable.from_genomes(genomes, self.topology), rows, np.repeat(np.arange(p), k), m, episodes, seed=self.seed, n_steps=self.n_steps
        )
        self.steps_flown += int(ev.steps.sum())
        solutions.set_evals(torch.as_tensor(ev.returns.reshape(p, k).mean(axis=1), dtype=torch.float64))
