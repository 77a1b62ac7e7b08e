"""Markdown table of neat_ghh08.py's results (one or more JSON files): per method, the validation mean
over seeds, the best and worst seed, crashed validation episodes, and NEAT's champion sizes."""

from __future__ import annotations

import json
import sys
from collections import defaultdict

import numpy as np


def main(paths: list[str]) -> None:
    runs: dict[str, list[dict]] = defaultdict(list)
    for path in paths:
        with open(path) as f:
            data = json.load(f)
        for r in data["runs"]:
            runs[r["method"]].append(r)
    head = ["method", "seeds", "mean validation return", "best / worst seed", "crashed validation episodes", "nodes / enabled connections"]
    print("| " + " | ".join([*head, "episodes flown", "seconds per run"]) + " |")
    print("|---|---|---|---|---|---|---|---|")
    for method, rs in runs.items():
        v = np.array([r["validation_mean"] for r in rs])
        size = ", ".join(f"{r['nodes']}/{r['connections']}" for r in rs) if "nodes" in rs[0] else ""
        crashes = sum(r["validation_crashes"] for r in rs)
        seconds = np.mean([r["seconds"] for r in rs])
        flown = ", ".join(f"{r['episodes']:,}" for r in rs)
        print(f"| {method} | {len(rs)} | {v.mean():,.0f} | {v.max():,.0f} / {v.min():,.0f} | {crashes} | {size} | {flown} | {seconds:,.0f} |")


if __name__ == "__main__":
    main(sys.argv[1:])
