"""The noise default's effect, run by run: each experiment re-run with the authors' estimate against its runs stored
before the change (issue 31; docs/reproduction/README.md).

    git show 90691ca:docs/reproduction/results.sqlite.gz | gunzip > before.sqlite
    python3 docs/reproduction/noise_default_check.py before.sqlite docs/reproduction/results.sqlite [NAME ...]

A unit re-run under the new config has the same key as before and the same seed (every stored unit's seed comes
from its key), so the two flew the same MDPs and gusts; only the LR models' noise estimate differs. For every
group (or model-learning method) whose units changed: the units paired, the mean and median score before and
after, how many got better, the Wilcoxon signed-rank p, and the runs with a crashed episode before and after.
Scores: a test run's cumulative reward (Figures 7, 8, 11, ...); a model unit's mean test return (Table 4).
"""

from __future__ import annotations

import json
import sqlite3
import sys
from collections import defaultdict

import numpy as np
from scipy import stats

from neurohover.experiments.keys import UnitKey

PAPER = ("table4", "fig7", "fig8", "fig11", "fig16", "ablation-hybrid", "wind-fig7", "wind-fig8", "wind-fig11", "risk-ghh09")
BENCH = ("bench-sensor-models", "bench-sensors", "bench-sensors-fallback", "bench-drift", "bench-drift-armed")


def units(path: str, name: str) -> dict[str, tuple[dict, dict]]:
    """key -> (params, result) of an experiment's paper-scale units."""
    with sqlite3.connect(f"file:{path}?mode=ro", uri=True) as c:
        rows = c.execute("SELECT key, params, result FROM units WHERE name = ? AND scale = 'paper'", (name,)).fetchall()
    return {k: (json.loads(p), json.loads(r)) for k, p, r in rows}


def score(result: dict) -> tuple[float, bool]:
    """A unit's score (higher is better) and whether any of its episodes crashed."""
    if "score" in result:  # a test run
        return float(result["score"]), bool(result["crash_episodes"])
    return float(result["test_mean"]), bool(result["test_crashes"])


def compare(before: dict, after: dict) -> list[str]:
    groups: dict[str, list[tuple[float, float, bool, bool]]] = defaultdict(list)
    for key, (params, result) in after.items():
        old = before.get(key)
        if old is None or old[0] == params or old[0].get("seed") != params.get("seed"):
            continue  # not re-run (kept), or not the same episodes
        b, a = score(old[1]), score(result)
        group = UnitKey.parse(key).group  # a label may hold a slash (AGENT/CONDITION)
        groups[group].append((b[0], a[0], b[1], a[1]))
    lines = []
    for group, pairs in sorted(groups.items()):
        b, a = np.array([p[0] for p in pairs]), np.array([p[1] for p in pairs])
        diff = a - b
        p = stats.wilcoxon(diff).pvalue if np.any(diff != 0) else 1.0
        lines.append(
            f"  {group}: {len(pairs)} pairs; mean {b.mean():.6g} -> {a.mean():.6g}, median {np.median(b):.6g} -> {np.median(a):.6g}; "
            f"{int((diff > 0).sum())} better, {int((diff < 0).sum())} worse; Wilcoxon p = {p:.2g}; "
            f"runs with a crash {sum(q[2] for q in pairs)} -> {sum(q[3] for q in pairs)}"
        )
    return lines


def main(argv: list[str]) -> None:
    if len(argv) < 2:
        sys.exit(__doc__)
    old, new, names = argv[0], argv[1], argv[2:] or [*PAPER, *BENCH]
    for name in names:
        before, after = units(old, name), units(new, name)
        lines = compare(before, after)
        print(f"{name}: " + ("no unit re-run with the new estimate" if not lines else f"{len(after)} units"))
        for line in lines:
            print(line)


if __name__ == "__main__":
    main(sys.argv[1:])
