"""Policy sets shipped with the package, and the command that builds them.

A policy set is a directory ``<task>/`` holding JSON policy files and a ``manifest.json``:

- GHH-08 and GHH-09: ``generic.json`` (evolved on the zero setting) and ``specialised_<i>.json``
  (evolved on training MDP i, i = 0..9). The manifest lists the two ``safe`` specialised policies
  for the hybrid agent, computed by the paper's rule: policies that never crashed on the other
  training MDPs (the two with the best mean return there when more qualify).
- FGHH (sigma 0.3): ``generic_zero.json`` (evolved on the zero setting), ``generic_fixed.json``
  (fixed resampling over G) and ``generic_race.json`` (selection races over G).

The shipped sets live in ``neurohover/data/policies``; ``neurohover build-policies`` rebuilds them
with the project's own evolution (or writes a set elsewhere with ``--out``).
"""

from __future__ import annotations

import json
import time
from collections.abc import Callable
from dataclasses import dataclass, field
from pathlib import Path

import numpy as np

from .errors import NeurohoverError
from .evaluate import evaluate
from .policies import Policy, load_policy, save_policy
from .tasks import get_task_family

SHIPPED = Path(__file__).parent / "data" / "policies"
FGHH_GENERICS = ("zero", "fixed", "race")


@dataclass(frozen=True)
class PolicySet:
    """The policies of one task family that the agents use."""

    task: str
    directory: Path
    generic: Policy
    specialised: tuple[Policy, ...] = ()
    safe: tuple[int, ...] = ()
    generics: dict[str, Policy] = field(default_factory=dict)
    manifest: dict = field(default_factory=dict)


def policy_dir(task: str, directory: str | Path | None = None) -> Path:
    return (Path(directory) if directory is not None else SHIPPED) / task


def _load(path: Path, what: str) -> Policy:
    if not path.is_file():
        raise NeurohoverError(
            f"policy set {str(path.parent)!r} is missing {what} ({path.name}); "
            f"build it with: neurohover build-policies --task {path.parent.name} --out {path.parent.parent}"
        )
    return load_policy(path)


def load_policy_set(task: str, directory: str | Path | None = None) -> PolicySet:
    """Load the policy set of ``task`` (the shipped one unless ``directory`` is given)."""
    family = get_task_family(task)
    root = policy_dir(family.name, directory)
    manifest_path = root / "manifest.json"
    if not manifest_path.is_file():
        raise NeurohoverError(
            f"no policy set for {family.name} in {str(root)!r} (manifest.json missing); build it with: neurohover build-policies --task {family.name}"
        )
    manifest = json.loads(manifest_path.read_text())
    if family.generic_over_distribution:
        generics = {name: _load(root / f"generic_{name}.json", f"the {name} generic policy") for name in FGHH_GENERICS}
        return PolicySet(family.name, root, generics["race"], generics=generics, manifest=manifest)
    generic = _load(root / "generic.json", "the generic policy")
    specialised = tuple(_load(root / f"specialised_{i}.json", f"specialised policy {i}") for i in range(10))
    return PolicySet(family.name, root, generic, specialised, tuple(manifest.get("safe", ())), manifest=manifest)


def crash_matrix(policies: list[Policy], mdps: list, episodes: int, seed: int, n_steps: int = 6000) -> tuple[np.ndarray, np.ndarray]:
    """Crash counts and mean returns of every policy on every MDP: arrays (P, M)."""
    ev = evaluate(policies, mdps, episodes=episodes, seed=seed, n_steps=n_steps)
    return ev.crashed.sum(axis=2), ev.returns.mean(axis=2)


def choose_safe(crashes: np.ndarray, returns: np.ndarray, n: int = 2) -> tuple[int, ...]:
    """The paper's rule: specialised policies that never crashed on the *other* training MDPs;
    the ``n`` with the best mean return there. Fewer qualify: the fewest crashes, then return."""
    p = crashes.shape[0]
    others = ~np.eye(p, dtype=bool)
    crash_others = np.array([crashes[i][others[i]].sum() for i in range(p)])
    return_others = np.array([returns[i][others[i]].mean() for i in range(p)])
    order = np.lexsort((-return_others, crash_others))  # fewest crashes first, then best return
    return tuple(int(i) for i in order[:n])


def build_policy_set(
    task: str,
    out: str | Path | None = None,
    *,
    budget: int = 40000,
    fghh_budget: int = 200000,
    seed: int = 0,
    safety_episodes: int = 3,
    n_steps: int = 6000,
    progress: Callable[[str], None] | None = None,
) -> PolicySet:
    """Evolve the policy set of ``task`` with the project's own evolution and write it."""
    from .evolution import SteadyStateSettings
    from .evolution.evolve import evolve
    from .policies import prototype

    family = get_task_family(task)
    root = policy_dir(family.name, out)
    root.mkdir(parents=True, exist_ok=True)
    say = progress or (lambda _msg: None)
    manifest: dict = {"task": family.name, "budget": budget, "seed": seed, "n_steps": n_steps, "built": time.strftime("%Y-%m-%d %H:%M:%S")}
    seeds = np.random.SeedSequence(seed).generate_state(16, dtype=np.uint32)
    start = time.perf_counter()

    def run(target, name: str, child_seed: int, **kwargs) -> Policy:
        t0 = time.perf_counter()
        if "resampling" not in kwargs:  # steady state: spend the whole budget (no plateau stop)
            kwargs["settings"] = SteadyStateSettings(plateau_threshold=kwargs["budget"])
        result = evolve(target, topology="mlp", prototype=prototype("mlp", "baseline"), seed=child_seed, n_steps=n_steps, **kwargs)
        policy = result.champion
        save_policy(policy, root / f"{name}.json", task=family.name, name=name, episodes=int(result.episodes), seconds=round(time.perf_counter() - t0, 2))
        say(f"{family.name}/{name}: champion {result.champion_return:.1f} after {result.episodes} episodes ({time.perf_counter() - t0:.0f} s)")
        return policy

    if family.generic_over_distribution:
        manifest.update({"sigma": family.sigma, "fghh_budget": fghh_budget})
        generics = {
            "zero": run(family.zero(), "generic_zero", int(seeds[0]), budget=budget),
            "fixed": run(family, "generic_fixed", int(seeds[1]), budget=fghh_budget, resampling="fixed:5"),
            "race": run(family, "generic_race", int(seeds[2]), budget=fghh_budget, resampling="race:0.2"),
        }
        manifest["seconds"] = round(time.perf_counter() - start, 1)
        (root / "manifest.json").write_text(json.dumps(manifest, indent=1) + "\n")
        return PolicySet(family.name, root, generics["race"], generics=generics, manifest=manifest)

    generic = run(family.zero(), "generic", int(seeds[0]), budget=budget)
    train = family.training_mdps()
    specialised = [run(mdp, f"specialised_{i}", int(seeds[1 + i]), budget=budget) for i, mdp in enumerate(train)]
    crashes, returns = crash_matrix(specialised, train, safety_episodes, seed=int(seeds[11]), n_steps=n_steps)
    safe = choose_safe(crashes, returns)
    manifest.update(
        {
            "safe": list(safe),
            "safety_episodes": safety_episodes,
            "crashes_on_training_mdps": crashes.tolist(),
            "mean_return_on_training_mdps": returns.round(2).tolist(),
            "seconds": round(time.perf_counter() - start, 1),
        }
    )
    (root / "manifest.json").write_text(json.dumps(manifest, indent=1) + "\n")
    say(f"{family.name}: safe specialised policies {safe}")
    return PolicySet(family.name, root, generic, tuple(specialised), safe, manifest=manifest)
