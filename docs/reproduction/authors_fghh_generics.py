"""Fly the authors' published FGHH generic policies on the validation MDPs of Figures 12, 13 and 15.

Their FGHH experiment code publishes 16 generics evolved with selection races and 24 each with fixed
resampling at k = 2, 5 and 10 (SLP ``.net`` files in ``policies/race``, ``resampling_02``, ``_05`` and
``_10`` beside their ``mdp.py``). Each is flown exactly as an experiment's final champions are validated
(``validation_mdps = "test"``: once on each test MDP, with the experiment's shared validation gusts), so
the report can place them beside ours. Writes ``authors-fghh-generics.json`` (read by ``neurohover
report`` from the report's directory)::

    python3 docs/reproduction/authors_fghh_generics.py AUTHORS/helicopter/ghh10/policies \\
        --out docs/reproduction/authors-fghh-generics.json
"""

from __future__ import annotations

import argparse
import json
from pathlib import Path

from neurohover.experiments import load_config
from neurohover.experiments.units import fly_on_test_mdps, unit_seed
from neurohover.policies import load_policy
from neurohover.tasks import family_for

FOLDERS = ("race", "resampling_02", "resampling_05", "resampling_10")


def main() -> None:
    ap = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    ap.add_argument("policies", type=Path, help="the authors' FGHH policies/ folder (holding race/, resampling_02/, ...)")
    ap.add_argument("--out", type=Path, required=True)
    ap.add_argument("--scale", default="paper", choices=("quick", "paper"))
    args = ap.parse_args()
    out: dict = {}
    for name in ("fig12", "fig13", "fig15"):
        cfg = load_config(name, args.scale)
        s = cfg.settings
        family = family_for(s["task"], s["sigma"])
        seed = unit_seed(s["seed"], cfg.name, "validation")  # the experiment's shared validation gusts (plans.py)
        entry = {}
        for folder in FOLDERS:
            files = sorted((args.policies / folder).glob("*.net"))
            flights = [fly_on_test_mdps(load_policy(f), family, s["validation_episodes"], seed, s["n_steps"], None, "cpu") for f in files]
            entry[folder] = {
                "files": [f.name for f in files],
                "returns": [[float(f"{x:.7g}") for x in ev.returns] for ev in flights],
                "crashed": [[bool(c) for c in ev.crashed] for ev in flights],
            }
            print(f"{name}: {folder}: {len(files)} policies flown")
        out[f"{name}-{args.scale}"] = entry
    args.out.write_text(json.dumps(out))
    print(f"wrote {args.out}")


if __name__ == "__main__":
    main()
