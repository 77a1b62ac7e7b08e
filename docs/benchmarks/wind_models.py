"""docs/model.md, "Wind-aware models": LR models learned from the baseline policy's flight data on each
of GHH-09's 10 training MDPs (the competition's), from one and from five episodes (seed 3), wind-blind
(the paper's) and with a sinusoidal wind. For each: the identified wind against the effective true
wind (what a one-substep model sampled at 10 Hz can see: neurohover.models.wind.effective_wind), the
one-step error of every model on a held-out episode (seed 99), and, from one episode, the return in
the true MDP (5 episodes, seed 5) of a policy evolved on each model from the baseline (2,000 model
episodes, as the agents do). Writes wind_models.json beside this script (several minutes on 2 cores).

    python docs/benchmarks/wind_models.py
"""

from __future__ import annotations

import json
import math
from pathlib import Path

from neurohover import baseline_policy, evaluate, get_task_family
from neurohover.agents.model_based import ModelEvolution, evolve_on_model
from neurohover.models import effective_wind, learn_lr, one_step_error
from neurohover.models.wind import sinusoid_axes

KINDS = ("none", "constant", "sinusoid")


def _phase_error(a: float, b: float) -> float:
    return abs((a - b + math.pi) % (2 * math.pi) - math.pi)


def main() -> None:
    family = get_task_family("ghh09")
    out = []
    for i, mdp in enumerate(family.training_mdps()):
        held_out = evaluate(baseline_policy(), mdp, seed=99, record=True).flight_data
        true_axes = sinusoid_axes(mdp.wind)
        for episodes in (1, 5):
            data = evaluate(baseline_policy(), mdp, episodes=episodes, seed=3, record=True).flight_data
            models = {k: learn_lr(data, wind_model=k) for k in KINDS}
            row: dict = {"mdp": i, "episodes": episodes, "transitions": data.n_transitions}
            row["one_step_error_held_out"] = {k: one_step_error(m, held_out) for k, m in models.items()}
            axes = []
            for name, true, got in (("x", true_axes[0], models["sinusoid"].wind.x), ("y", true_axes[1], models["sinusoid"].wind.y)):
                eff = effective_wind(true)
                axes.append(
                    {
                        "axis": name,
                        "true": true.to_dict(),
                        "effective": eff.to_dict(),
                        "identified": got.to_dict(),
                        "aliased": true.omega > math.pi / 0.1,
                        "omega_rel_error": abs(got.omega - eff.omega) / eff.omega if eff.omega else None,
                        "amplitude_rel_error": abs(got.amplitude - eff.amplitude) / eff.amplitude if eff.amplitude else None,
                        "phase_error": _phase_error(got.phase, eff.phase),
                        "offset_error": got.offset - eff.offset,
                    }
                )
            row["axes"] = axes
            if episodes == 1:
                flown = {}
                for k in ("none", "sinusoid"):
                    policy, predicted = evolve_on_model(models[k].mdp(), baseline_policy(), ModelEvolution(), seed=1)
                    ev = evaluate(policy, mdp, episodes=5, seed=5)
                    flown[k] = {"predicted": predicted, "mean_return": float(ev.returns.mean()), "crashes": int(ev.crashed.sum())}
                base = evaluate(baseline_policy(), mdp, episodes=5, seed=5)
                flown["baseline"] = {"mean_return": float(base.returns.mean()), "crashes": int(base.crashed.sum())}
                row["evolved_on_model"] = flown
            out.append(row)
            print(json.dumps({k: row[k] for k in ("mdp", "episodes", "one_step_error_held_out")}), flush=True)
    path = Path(__file__).with_suffix(".json")
    path.write_text(json.dumps(out, indent=1) + "\n")
    print(f"wrote {path}")


if __name__ == "__main__":
    main()
