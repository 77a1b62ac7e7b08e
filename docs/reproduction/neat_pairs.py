"""The NEAT variants of topology-ghh08 against each other, run by run (issue 35): the report pairs each with the MLP;
this pairs the tanh variant with the identity one, which shares its seeds, budget (15,450 episodes) and search, so the
pair differs by the hidden nodes' activation alone.

    python3 docs/reproduction/neat_pairs.py docs/reproduction/results.sqlite
"""

from __future__ import annotations

import json
import sqlite3
import sys

import numpy as np
from scipy.stats import wilcoxon

PAIRS = [("neat-baseline-tanh", "neat-baseline-fine"), ("neat-baseline-tanh", "mlp-baseline"), ("neat-baseline-fine", "mlp-baseline")]


def mean_validation(conn: sqlite3.Connection, setting: str) -> dict[str, float]:
    """Each run's mean validation return, by its run key (train MDP and run)."""
    rows = conn.execute("SELECT key, result FROM units WHERE name = 'topology-ghh08' AND scale = 'paper' AND key LIKE ?", (f"evolve/{setting}/%",))
    return {key.split("/", 2)[2]: float(np.mean(json.loads(result)["validation"])) for key, result in rows}


def main(store: str) -> None:
    conn = sqlite3.connect(f"file:{store}?mode=ro", uri=True)
    for a, b in PAIRS:
        va, vb = mean_validation(conn, a), mean_validation(conn, b)
        keys = sorted(set(va) & set(vb))
        x, y = np.array([va[k] for k in keys]), np.array([vb[k] for k in keys])
        d = x - y
        print(
            f"{a} vs {b}: {len(keys)} pairs, mean validation return {x.mean():.1f} vs {y.mean():.1f}, {a} better in "
            f"{int((d > 0).sum())}, median difference {np.median(d):+.1f}, Wilcoxon p = {wilcoxon(x, y).pvalue:.2g}"
        )


if __name__ == "__main__":
    main(sys.argv[1] if len(sys.argv) > 1 else "docs/reproduction/results.sqlite")
