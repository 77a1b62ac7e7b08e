"""EvoTorch's SNES on a GHH-08 MDP through the batched kernel (``neurohover.integrations.evotorch``).

A single-file script: it evolves the paper's SLP, starting from the competition's baseline, with
EvoTorch's SNES on ``HoverProblem`` (a whole population flown in one kernel call), then flies the
final centre and the baseline on the same fresh episodes and prints both. ``--compare-gymne``
also times one generation of each path like for like, EvoTorch's own ``GymNE`` (one helicopter at
a time in Python) and ``HoverProblem`` (a population in one kernel call): the same start (the
baseline), population, spread and full episodes, each with the control steps it flew::

    pip install 'neurohover[evotorch]'        # for a CPU build of torch first: pip install torch==2.13.0
    python examples/evotorch_snes.py --mdp train:3 --generations 50
    python examples/evotorch_snes.py --generations 5 --compare-gymne
"""

from __future__ import annotations

import argparse
import sys
import time

import numpy as np

try:
    import torch
    from evotorch.algorithms import SNES

    from neurohover.integrations.evotorch import HoverProblem
except ModuleNotFoundError as missing:  # the extra is not installed: one clear line, exit 2
    print(
        f"examples/evotorch_snes.py needs {missing.name}: pip install 'neurohover[evotorch]' (for a CPU build of torch first: pip install torch==2.13.0)",
        file=sys.stderr,
    )
    raise SystemExit(2) from None

import neurohover as nh


def parse_args(argv: list[str] | None = None) -> argparse.Namespace:
    p = argparse.ArgumentParser(description=__doc__.split("\n")[0], formatter_class=argparse.ArgumentDefaultsHelpFormatter)
    p.add_argument("--mdp", default="train:3", help="GHH-08 MDP to evolve on")
    p.add_argument("--generations", type=int, default=50)
    p.add_argument("--popsize", type=int, default=40)
    p.add_argument("--stdev", type=float, default=0.02, help="SNES's initial spread around the baseline")
    p.add_argument("--episodes", type=int, default=2, help="episodes per solution per generation")
    p.add_argument("--n-steps", type=int, default=6000, help="control steps per episode")
    p.add_argument("--seed", type=int, default=0)
    p.add_argument("--compare-gymne", action="store_true", help="also time one generation of EvoTorch's GymNE")
    return p.parse_args(argv)


def baseline_linear() -> torch.Tensor:
    """The baseline SLP as GymNE's ``Linear(12, 4)`` parameters (weight row by row, then bias; p, q, r unused)."""
    genome = nh.baseline_policy().genome
    weight = np.zeros((4, 12))
    weight[:, [0, 1, 2, 3, 4, 5, 9, 10, 11]] = genome[:36].reshape(4, 9)
    return torch.as_tensor(np.concatenate([weight.ravel(), genome[36:]]), dtype=torch.float32)


def compare_gymne(args: argparse.Namespace) -> None:
    """One SNES generation on each path, like for like: the same start (the baseline), population, spread, episodes
    per solution and full episodes (GymNE on the 6000-step id), each timed with the control steps it flew."""
    from evotorch.neuroevolution import GymNE

    rates = {}
    hover = HoverProblem("ghh08", mdps=args.mdp, topology="slp", episodes=args.episodes, n_steps=args.n_steps, seed=args.seed)
    searcher = SNES(hover, popsize=args.popsize, stdev_init=args.stdev, center_init=hover.baseline_center())
    t0 = time.perf_counter()
    searcher.step()
    rates["HoverProblem"] = (time.perf_counter() - t0, hover.steps_flown)
    gym_problem = GymNE(
        env="neurohover:neurohover/GHH08-v0",
        env_config={"mdp": args.mdp, "episode_steps": args.n_steps, "max_episode_steps": args.n_steps},
        network="Linear(obs_length, act_length)",
        observation_normalization=False,
        num_episodes=args.episodes,
        num_actors=0,
    )
    gym_searcher = SNES(gym_problem, popsize=args.popsize, stdev_init=args.stdev, center_init=baseline_linear())
    t0 = time.perf_counter()
    gym_searcher.step()
    rates["GymNE"] = (time.perf_counter() - t0, int(gym_problem.status.get("total_interaction_count", 0)))
    for name, (seconds, steps) in rates.items():
        what = f"one generation of {args.popsize} x {args.episodes} episodes from the baseline"
        print(f"{name:<12} {what}: {steps:,} control steps in {seconds:.1f} s ({steps / seconds:,.0f}/s)")
    (hs, hn), (gs, gn) = rates["HoverProblem"], rates["GymNE"]
    print(f"HoverProblem flies {(hn / hs) / (gn / gs):.0f}x GymNE's control steps per second")


def main(argv: list[str] | None = None) -> int:
    args = parse_args(argv)
    torch.manual_seed(args.seed)  # SNES samples with torch's generator: the same seed, the same run
    problem = HoverProblem("ghh08", mdps=args.mdp, topology="slp", episodes=args.episodes, n_steps=args.n_steps, seed=args.seed)
    searcher = SNES(problem, popsize=args.popsize, stdev_init=args.stdev, center_init=problem.baseline_center())
    start = time.perf_counter()
    searcher.run(args.generations)
    seconds = time.perf_counter() - start
    steps = args.generations * args.popsize * args.episodes * args.n_steps  # at most: a crash ends an episode early
    rate = steps / seconds
    print(f"SNES on HoverProblem: {args.generations} generations x {args.popsize} solutions in {seconds:.1f} s (at most {rate:,.0f} control steps/s)")

    centre = nh.Policy("slp", np.asarray(searcher.status["center"], dtype=float))
    mdp = nh.get_task_family("ghh08").mdp(args.mdp)
    ev = nh.evaluate([nh.baseline_policy(), centre], mdp, episodes=20, seed=args.seed + 1, n_steps=args.n_steps)
    for name, r, c in zip(("baseline", "SNES centre"), ev.returns.mean(axis=(1, 2)), ev.crashed.sum(axis=(1, 2))):
        print(f"{name:<12} mean return {r:12.1f} over 20 fresh episodes, {int(c)} crashed")

    if args.compare_gymne:
        compare_gymne(args)
    return 0


if __name__ == "__main__":
    raise SystemExit(main())
