"""Two measured causes behind the one-episode OLS models of Table 4 and Figure 8 (docs/model.md).

    python3 docs/reproduction/model_data_check.py [AUTHORS/helicopter]

1. **The model's integration.** A learned model integrates one 0.1 s Euler step per control step;
   the simulator ten 0.01 s substeps. Every policy is flown 5 episodes in the one-substep model with
   the default helicopter's parameters converted to that integration (``one_substep_params``: the
   best a model can be), with its gusts and without: how many episodes crash. A policy that crashes
   there cannot be a useful start for evolution on any learned model.
2. **Whose flight data.** On each GHH-09 training MDP (and each of the first 20 GHH-08 test MDPs,
   Table 4's), one episode of a data-gathering policy, an OLS model learned from it (ours: D_u
   kept, innovation noise; the authors': D_u discarded, rms noise), and the baseline flown 5
   episodes in that model: the models in which it crashes.

With the authors' ``helicopter/`` folder (afcarl/ATAA at 1be44a3), their GHH-09 generic and their
hybrid's pair (mdp3, mdp6) and their GHH-08 generic are measured beside ours. Prints one line per
measurement.
"""

from __future__ import annotations

import sys
from pathlib import Path

import numpy as np

from neurohover import baseline_policy, evaluate, get_task_family
from neurohover.models import LearnedModel, learn_lr, one_substep_params
from neurohover.policies import load_policy
from neurohover.policysets import load_policy_set

FITS = {"ours": {}, "authors": {"d_u": "discard", "noise": "rms"}}


def integration(policies: dict) -> None:
    params, noise = one_substep_params()
    for label, noisy in (("with gusts", noise), ("without gusts", np.zeros(6))):
        model = LearnedModel(tuple(params), tuple(noisy), "lr", 0.0, {}, 0.0).mdp()
        ev = evaluate(list(policies.values()), model, episodes=5, seed=2)
        crashes = ev.crashed.sum(axis=(1, 2))
        steps = ev.steps.mean(axis=(1, 2))
        print(f"one-substep model, default parameters, {label}: crashed episodes of 5 (mean steps flown)")
        for name, c, s in zip(policies, crashes, steps):
            print(f"  {name:<24} {int(c)}  ({s:.0f})")


def data_source(task: str, mdps: list, sources: dict) -> None:
    print(f"{task}: OLS models from one episode of each policy on each of {len(mdps)} MDPs; models in which the baseline crashes")
    for name, policy in sources.items():
        crashed = {fit: 0 for fit in FITS}
        returns = []
        for k, mdp in enumerate(mdps):
            ev = evaluate(policy, mdp, record=True, seed=100 + k)
            returns.append(float(ev.returns.mean()))
            for fit, kw in FITS.items():
                model = learn_lr(ev.flight_data, **kw).mdp()
                crashed[fit] += int(evaluate(baseline_policy(), model, episodes=5, seed=200 + k).crashed.any())
        counts = ", ".join(f"{n} of {len(mdps)} ({fit} fit)" for fit, n in crashed.items())
        print(f"  {name:<24} data return per episode {np.mean(returns):9.0f}; baseline crashes in {counts}")


def main() -> None:
    ghh08, ghh09 = load_policy_set("ghh08"), load_policy_set("ghh09")
    policies = {"baseline": baseline_policy(), "ghh08 generic (ours)": ghh08.generic, "ghh09 generic (ours)": ghh09.generic}
    policies.update({f"ghh09 specialised {i} (ours)": p for i, p in enumerate(ghh09.specialised)})
    sources09 = {"ours: generic": ghh09.generic, "ours: specialised 3": ghh09.specialised[3], "ours: specialised 6": ghh09.specialised[6]}
    sources08 = {"ours: generic": ghh08.generic}
    if len(sys.argv) > 1:
        root = Path(sys.argv[1])
        folder = root / "ghh09" / "policies"
        policies["ghh09 generic (authors')"] = load_policy(folder / "generic.net")
        policies.update({f"ghh09 mdp{i} (authors')": load_policy(folder / f"mdp{i}.net") for i in range(10)})
        sources09.update({f"authors': {n}": load_policy(folder / f"{n}.net") for n in ("generic", "mdp3", "mdp6")})
        sources08["authors': generic"] = load_policy(root / "ghh08" / "policies" / "generic.net")
    sources09["baseline"] = baseline_policy()
    integration(policies)
    data_source("GHH-09 training MDPs", list(get_task_family("ghh09").training_mdps()), sources09)
    data_source("GHH-08 test MDPs 0-19", list(get_task_family("ghh08").test_mdps()[:20]), sources08)


if __name__ == "__main__":
    main()
