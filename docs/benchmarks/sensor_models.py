"""docs/benchmarks.md, "What sensor noise does to the learned models": LR (OLS) models learned from the
baseline policy's flight data on GHH-08 test MDP 0 seen through white sensor noise of increasing level,
from one and from five episodes (seed 3). For each: the relative error of the 11 learned dynamics
parameters against the true ones, the model's one-step error on exact flight data of the true MDP,
and the return in the true MDP (exact sensors, 5 episodes) of a policy evolved on the model from the
baseline (2,000 model episodes). Writes sensor_models.json beside this script (a few minutes on 2 cores).

    python docs/benchmarks/sensor_models.py
"""

from __future__ import annotations

import json
from pathlib import Path

import numpy as np

from neurohover import Sensor, baseline_policy, evaluate, get_task_family
from neurohover.agents.model_based import ModelEvolution, evolve_on_model
from neurohover.models import learn_lr
from neurohover.models.transitions import one_step_error

LEVELS = (0.0, 0.25, 0.5, 1.0, 2.0, 4.0)


def main() -> None:
    mdp = get_task_family("ghh08").mdp("test:0")
    truth = np.array(mdp.params)
    exact_data = evaluate(baseline_policy(), mdp, episodes=2, seed=99, record=True).flight_data
    out = []
    for level in LEVELS:
        for episodes in (1, 5):
            seen = mdp.with_sensor(Sensor.at_level(level))
            data = evaluate(baseline_policy(), seen, episodes=episodes, seed=3, record=True).flight_data
            model = learn_lr(data)
            rel = np.abs(np.array(model.params) - truth) / np.abs(truth)
            policy, predicted = evolve_on_model(model.mdp(), baseline_policy(), ModelEvolution(), seed=1)
            flown = evaluate(policy, mdp, episodes=5, seed=5)
            out.append(
                {
                    "level": level,
                    "episodes": episodes,
                    "median_relative_parameter_error": float(np.median(rel)),
                    "D_w_relative_error": float(rel[4]),
                    "one_step_error_on_exact_data": float(one_step_error(model, exact_data)),
                    "predicted_return": predicted,
                    "true_mean_return": float(flown.returns.mean()),
                    "true_crash_fraction": float(flown.crashed.mean()),
                }
            )
            print(out[-1])
    path = Path(__file__).with_name("sensor_models.json")
    path.write_text(json.dumps(out, indent=1) + "\n")


if __name__ == "__main__":
    main()
