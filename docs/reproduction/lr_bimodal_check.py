"""Table 4's LR policies are bimodal: measure it on the same model, evolution seed by evolution seed.

For each of the first ``--mdps`` LR units of Table 4 (paper scale) in a results store, the script learns
the unit's model again from the same flight data (and checks it is the stored one), then evolves a policy
on it from ``--seeds`` evolution seeds (seed 0 is the unit's own) and flies each in the true MDP on the
unit's test gusts. Variants of the model the policies evolve on:

- ``one``: the model as fitted, one 0.1 s step per control step (Table 4's before 2026-12-04; the authors' FGHH code);
- ``cw-true``: the same with its w drag C_w replaced by the true MDP's (its one-substep equivalent):
  OLS fits C_w at about +2 where the simulator's is -0.49;
- ``ten``: the fitted model in the simulator's ten substeps (``LearnedModel.mdp(substeps=10)``).

Per variant it prints how many policies earn under -1,000 per episode (the bad mode), on how many MDPs
both modes occur, the median standard deviation of the vertical velocity w in each mode (the bad mode's
collective loop oscillates) and the median predicted return (on the model) of each mode; ``--out``
writes every run as JSON::

    python3 docs/reproduction/lr_bimodal_check.py docs/reproduction/results.sqlite --mdps 8 --seeds 4 \\
        --variants one,cw-true --out docs/reproduction/lr-bimodal-check.json
"""

from __future__ import annotations

import argparse
import dataclasses
import json
import sqlite3

import numpy as np

from neurohover import evaluate
from neurohover.evolution.evolve import evolve
from neurohover.experiments.params import unit_params
from neurohover.experiments.units import model_unit_seeds
from neurohover.models.lr import learn_lr
from neurohover.models.model import one_substep_params
from neurohover.policies import policy_from_dict
from neurohover.tasks import MDP

BAD = -1000.0
VARIANTS = ("one", "cw-true", "ten")


def runs(store: str, mdps: int, seeds: int, variants: list[str]):
    conn = sqlite3.connect(store)
    rows = conn.execute("SELECT key, params, result FROM units WHERE name = 'table4' AND scale = 'paper' AND key LIKE 'model/lr/%' ORDER BY key").fetchall()
    for key, params, stored in rows[:mdps]:
        q = unit_params("model", json.loads(params))
        mdp, generic = MDP.from_dict(q.mdp), policy_from_dict(q.generic)
        s = model_unit_seeds(q.seed)  # run_model's four seeds
        data = evaluate(generic, mdp, episodes=q.data_episodes, seed=int(s[0]), record=True, n_steps=q.n_steps, threads=1)
        model = learn_lr(data.flight_data, estimator="ols", d_u=q.d_u, noise=q.noise)
        assert np.allclose(model.params, json.loads(stored)["model_params"], rtol=1e-12), key  # the stored unit's model
        truth = one_substep_params(mdp.params, mdp.noise_std)[0]
        for variant in variants:
            p = np.array(model.params)
            if variant == "cw-true":
                p[3] = truth[3]
            m = dataclasses.replace(model, params=tuple(p))
            flown = m.mdp(substeps=10 if variant == "ten" else 1)
            for seed in range(seeds):
                ev = evolve(flown, topology=generic.topology, prototype=generic, seed=int(s[2]) + seed, n_steps=q.n_steps, threads=1)
                test = evaluate(ev.champion, mdp, episodes=q.test_episodes, seed=int(s[3]), n_steps=q.n_steps, threads=1, record=True)
                w = np.concatenate([o[:, 2] for o in test.flight_data.observations])
                yield {"key": key, "variant": variant, "seed": seed, "true": float(test.returns.mean()), "predicted": float(ev.champion_return)} | {
                    "w_sd": float(w.std())
                }


def summary(rs: list[dict], variant: str) -> str:
    mine = [r for r in rs if r["variant"] == variant]
    bad = [r for r in mine if r["true"] < BAD]
    good = [r for r in mine if r["true"] >= BAD]
    keys = {r["key"] for r in mine}
    both = sum(1 for k in keys if any(r["key"] == k for r in bad) and any(r["key"] == k for r in good))

    def med(xs, f):
        return f"{np.median([x[f] for x in xs]):.3g}" if xs else "n/a"

    return (
        f"{variant}: {len(bad)} of {len(mine)} policies under {BAD:g} per episode; both modes on {both} of {len(keys)} MDPs; "
        f"w sd {med(bad, 'w_sd')} (bad) / {med(good, 'w_sd')} (good); predicted return {med(bad, 'predicted')} (bad) / {med(good, 'predicted')} (good); "
        f"median true return {med(mine, 'true')}"
    )


def main() -> None:
    ap = argparse.ArgumentParser(description=__doc__.split("\n")[0])
    ap.add_argument("store")
    ap.add_argument("--mdps", type=int, default=8)
    ap.add_argument("--seeds", type=int, default=4)
    ap.add_argument("--variants", default="one,cw-true")
    ap.add_argument("--out")
    args = ap.parse_args()
    variants = args.variants.split(",")
    if not set(variants) <= set(VARIANTS):
        ap.error(f"--variants {args.variants!r}: allowed {', '.join(VARIANTS)}")
    rs = []
    for r in runs(args.store, args.mdps, args.seeds, variants):
        rs.append(r)
        print(json.dumps(r), flush=True)
    for v in variants:
        print(summary(rs, v))
    if args.out:
        with open(args.out, "w") as f:
            json.dump({"mdps": args.mdps, "seeds": args.seeds, "runs": rs, "summary": [summary(rs, v) for v in variants]}, f, indent=1)


if __name__ == "__main__":
    main()
