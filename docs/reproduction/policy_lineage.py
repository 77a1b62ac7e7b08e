"""Table 3, feedback gains and shared genes of ten specialised policies (the Figure 2 discussion).

    python3 docs/reproduction/policy_lineage.py --task ghh08 neurohover/data/policies/ghh08/specialised_{0..9}.json
    python3 docs/reproduction/policy_lineage.py --task ghh08 AUTHORS/ghh08/policies/mdp{0..9}.net --gain-path

Policy i must be the one evolved for training MDP i. It prints:
- Table 3's robustness figures: each policy flown ``--episodes`` episodes (10, as in the paper) on
  every training MDP; r on its own MDP and r_G over all ten, averaged over the policies;
- the policies' feedback gains, linearised at hover (d action / d observation), beside the
  baseline policy's;
- gene values (to four decimals) that several policies share and the baseline does not have: a
  sign of common descent, since independent runs would not meet on the same value;
- with ``--gain-path``: a linear policy whose gains move from the baseline's to the policies' mean
  gains geometrically (gain = baseline * (mean / baseline)^t), flown on every training MDP.
"""

from __future__ import annotations

import argparse
from collections import Counter

import numpy as np

from neurohover import evaluate, get_task_family
from neurohover.policies import (
    BASELINE_GAINS,
    INPUT_NAMES,
    MLP_GENE_NAMES,
    Policy,
    baseline_policy,
    load_policy,
    mlp_baseline_genome,
    slp_baseline_genome,
)
from neurohover.sim.constants import OBS_NAMES

# (action row, observation index, label) of the baseline policy's nine gains
GAINS = [(int(action[1]) - 1, OBS_NAMES.index(obs), f"{obs}->{action}") for action, obs in BASELINE_GAINS]
SLP_COLUMNS = [OBS_NAMES.index(name) for name in INPUT_NAMES]  # the observation entries an SLP sees


def jacobian(policy: Policy, h: float = 1e-5) -> np.ndarray:
    """d action / d observation at hover (all observations zero): a (4, 12) array."""
    a0 = np.asarray(policy.act(np.zeros(12)), float)
    jac = np.zeros((4, 12))
    for i in range(12):
        obs = np.zeros(12)
        obs[i] = h
        jac[:, i] = (np.asarray(policy.act(obs), float) - a0) / h
    return jac


def main() -> None:
    ap = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    ap.add_argument("--task", default="ghh08")
    ap.add_argument("--episodes", type=int, default=10)
    ap.add_argument("--seed", type=int, default=0)
    ap.add_argument("--gain-path", action="store_true")
    ap.add_argument("policies", nargs="+")
    args = ap.parse_args()
    train = get_task_family(args.task).training_mdps()
    policies = [load_policy(p) for p in args.policies]
    if len(policies) != len(train):
        raise SystemExit(f"give {len(train)} policies, policy i evolved for training MDP i")
    ev = evaluate(policies, train, episodes=args.episodes, seed=args.seed)
    returns = ev.returns.mean(axis=2)
    own, across = np.diag(returns), returns.mean(axis=1)
    print(f"Table 3 ({args.episodes} episodes per cell): r = {own.mean():.1f} (sd {own.std(ddof=1):.1f}), ", end="")
    print(f"r_G = {returns.mean():.1f} (sd over policies {across.std(ddof=1):.1f}), crashed episodes {int(ev.crashed.sum())} of {ev.crashed.size}")

    jacs = np.array([jacobian(p) for p in policies])
    base = jacobian(baseline_policy())
    print(f"\n{'gain':>8} {'baseline':>9} {'mean':>8} {'ratio':>6}   per policy")
    for row, col, label in GAINS:
        values = jacs[:, row, col]
        print(f"{label:>8} {base[row, col]:+9.3f} {values.mean():+8.3f} {values.mean() / base[row, col]:6.1f}   " + " ".join(f"{v:+.2f}" for v in values))

    if all(p.topology == "mlp" for p in policies):
        genomes = np.round(np.array([p.genome for p in policies]), 4)
        seed_genome = np.round(mlp_baseline_genome(), 4)
        print("\nshared gene values (not the baseline's):")
        for g, name in enumerate(MLP_GENE_NAMES):
            value, count = Counter(genomes[:, g]).most_common(1)[0]
            if count > 1 and value != seed_genome[g]:
                print(f"  {name:>10} = {value:+.4f} in policies {[i for i in range(len(policies)) if genomes[i, g] == value]}")

    if args.gain_path:
        w_base = slp_baseline_genome()[:36].reshape(4, 9)
        target = jacs.mean(axis=0)[:, SLP_COLUMNS]
        ratio = np.divide(target, w_base, out=np.ones_like(w_base), where=w_base != 0)
        print("\nlinear policy, gains baseline * (mean / baseline)^t, baseline biases:")
        for t in np.linspace(0, 1, 11):
            w = np.where(w_base != 0, w_base * np.abs(ratio) ** t, 0.0)
            slp = Policy("slp", np.concatenate([w.ravel(), slp_baseline_genome()[36:]]))
            path = evaluate(slp, train, episodes=3, seed=args.seed)
            print(f"  t = {t:.1f}: mean return over the training MDPs {path.returns.mean():10.0f}, crashed episodes {int(path.crashed.sum())}")


if __name__ == "__main__":
    main()
