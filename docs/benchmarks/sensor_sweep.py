"""docs/benchmarks.md, "Where the policies start to crash": the baseline and each family's shipped
generic policy on its first 20 test MDPs, 3 episodes each (seed 7), over sensor-noise levels,
correlated noise, delays and dropouts. Writes sensor_sweep.json beside this script (about 2 minutes on 2 cores).

    python docs/benchmarks/sensor_sweep.py
"""

from __future__ import annotations

import json
from pathlib import Path

import numpy as np

from neurohover import baseline_policy, evaluate, get_task_family
from neurohover.policysets import load_policy_set
from neurohover.tasks import Sensor

SENSORS = (
    [("exact", Sensor())]
    + [(f"white, level {level:g}", Sensor.at_level(level)) for level in (0.5, 1, 2, 4)]
    + [(f"AR(1) 0.95, level {level:g}", Sensor.at_level(level, correlation=0.95)) for level in (0.5, 1, 2)]
    + [(f"delay {d} ({d / 10:g} s)", Sensor(delay=d)) for d in (1, 2, 3, 5)]
    + [(f"dropout {p:g}", Sensor(dropout=p)) for p in (0.1, 0.3, 0.5, 0.8)]
)


def main() -> None:
    out: dict = {}
    for task in ("ghh08", "ghh09", "fghh"):
        family, policy_set = get_task_family(task), load_policy_set(task)
        generic = policy_set.generics.get("fixed", policy_set.generic) if family.generic_over_distribution else policy_set.generic
        policies = {"baseline": baseline_policy(), "generic": generic}
        mdps = family.test_mdps()[:20]
        for label, sensor in SENSORS:
            ev = evaluate(list(policies.values()), [m.with_sensor(sensor) for m in mdps], episodes=3, seed=7)
            for i, name in enumerate(policies):
                out.setdefault(task, {}).setdefault(name, {})[label] = {
                    "median_return": float(np.median(ev.returns[i])),
                    "crash_fraction": float(ev.crashed[i].mean()),
                }
    path = Path(__file__).with_name("sensor_sweep.json")
    path.write_text(json.dumps(out, indent=1) + "\n")
    print(f"wrote {path}")


if __name__ == "__main__":
    main()
