"""Fly the authors' published GHH-09 policies through Figure 8's protocol, beside ours.

Their GHH-09 code publishes a generic policy and the ten specialised policies (``generic.net``,
``mdp0.net`` .. ``mdp9.net`` beside their ``mdp.py``; afcarl/ATAA at 1be44a3, ``helicopter/ghh09/policies``).
This script makes them a policy set (the hybrid's safe pair is their hybrid agent's, 3 and 6) and
runs Figure 8's protocol with it: 8 runs on each training MDP, 1,000 episodes, every group on the
seeds of Figure 8's group of its agent (so each run meets the MDP and gusts of the same Figure 8
run, and of the same run of ``lr-authors-fig8``). The groups:

- ``model-free``: their specialised policies, skipping the run's own MDP (issue 31, point 3);
- ``incremental/ours``, ``incremental/authors``, ``hybrid/ours``, ``hybrid/authors``: the model-based
  agents with their generic (the incremental agent's flight data) or their safe pair (the hybrid's)
  and their generic as the fallback, with our LR fit or theirs (``d_u``, ``noise``, ``model_policy``),
  so that, beside ``lr-authors-fig8``'s groups, the policy set is a factor of its own.

Writes its scale's entry of ``authors-ghh09-policies.json`` (per group: every run's MDP, score, crash episodes and
number of episodes), which ``neurohover report`` reads from the report's directory::

    python3 docs/reproduction/authors_ghh09_policies.py AUTHORS/helicopter/ghh09/policies \\
        --out docs/reproduction/authors-ghh09-policies.json [--scale quick|paper] [--jobs 2]
"""

from __future__ import annotations

import argparse
import json
import tempfile
from pathlib import Path

from neurohover.experiments import LocalExecutor, Store, load_config, reproduce
from neurohover.experiments.config import make_config
from neurohover.experiments.results import result_from_dict
from neurohover.policies import load_policy, save_policy

SAFE = (3, 6)  # their hybrid agent's POLICIES = mdp3.net, mdp6.net
FITS = {"ours": {}, "authors": {"d_u": "discard", "noise": "rms", "model_policy": "authors"}}


def policy_set(source: Path, root: Path) -> Path:
    """Their .net files as a neurohover GHH-09 policy set under ``root`` (written again each time: the same files)."""
    out = root / "ghh09"
    out.mkdir(parents=True, exist_ok=True)
    save_policy(load_policy(source / "generic.net"), out / "generic.json")
    for i in range(10):
        save_policy(load_policy(source / f"mdp{i}.net"), out / f"specialised_{i}.json")
    (out / "manifest.json").write_text(json.dumps({"task": "ghh09", "source": "the authors' published GHH-09 policies", "safe": list(SAFE)}))
    return root


def config(policies: Path, scale: str):
    fig8 = load_config("fig8", scale)
    base = {k: fig8.settings[k] for k in ("episodes", "n_steps", "model_budget", "max_learning_episodes")}
    reps = 8 if scale == "paper" else 1
    n = 10 if scale == "paper" else 2
    seeds = {"experiment": "fig8", "seed": fig8.typed.seed}
    groups = [
        {
            "agent": "model-free",
            "label": "model-free",
            "mdps": "train",
            "n_mdps": n,
            "runs_per_mdp": reps,
            "exclude_own": True,
            "seeds_of": {**seeds, "group": "model-free"},
        }
    ]
    for agent in ("incremental", "hybrid"):
        for fit, values in FITS.items():
            groups.append(
                {"agent": agent, "label": f"{agent}/{fit}", "mdps": "train", "n_mdps": n, "runs_per_mdp": reps, **values, "seeds_of": {**seeds, "group": agent}}
            )
    settings = {"task": "ghh09", "seed": 2033, "policies": str(policies), **base, "authors_generations": 500 if scale == "paper" else 3, "groups": groups}
    return make_config("authors-ghh09-policies", "test_runs", scale, settings, title="The authors' GHH-09 policies through Figure 8's protocol")


def main() -> None:
    ap = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    ap.add_argument("policies", type=Path, help="the authors' GHH-09 policies/ folder (generic.net, mdp0.net .. mdp9.net)")
    ap.add_argument("--out", type=Path, required=True)
    ap.add_argument("--scale", default="paper", choices=("quick", "paper"))
    ap.add_argument("--jobs", type=int, default=1)
    ap.add_argument("--workdir", type=Path, help="where the policy set and the runs' store are kept (default: a temporary folder); the same folder resumes")
    args = ap.parse_args()
    with tempfile.TemporaryDirectory() as tmp:
        work = args.workdir or Path(tmp)
        cfg = config(policy_set(args.policies, work / "policies"), args.scale)
        with Store(work / "runs.sqlite") as store:
            reproduce(cfg, store, LocalExecutor(args.jobs), progress=False)
            units = store.units(cfg.name, cfg.scale)
    groups: dict[str, list] = {}
    for u in sorted(units, key=lambda u: u["key"]):
        if u["kind"] != "test_run":
            continue
        r = result_from_dict(u["kind"], u["result"], u["key"])
        group = u["params"]["group"]
        groups.setdefault(group, []).append(
            {
                "key": u["key"],
                "mdp": r.mdp,
                "score": float(r.score),
                "crash_episodes": list(r.crash_episodes),
                "episodes": len(r.returns),
            }
        )
    out = json.loads(args.out.read_text()) if args.out.is_file() else {}
    out[f"fig8-{args.scale}"] = groups  # the other scale's entry is kept
    args.out.write_text(json.dumps(out))
    print(f"wrote {args.out}: " + ", ".join(f"{g} ({len(v)} runs)" for g, v in groups.items()))


if __name__ == "__main__":
    main()
