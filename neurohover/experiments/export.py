"""``neurohover results``: export an experiment's finished units as CSV or JSON.

CSV: one row per unit: experiment, scale, key, kind, the key's parts (group, mdp, rep:
:class:`~neurohover.experiments.results.UnitKey`), seconds, worker, then the params (``param.*``)
and the typed result's columns (``result.*``: :meth:`~neurohover.experiments.results.EvolveResult.columns`).
JSON: the units exactly as the store holds them.
"""

from __future__ import annotations

import csv
import io
import json

from ..errors import NeurohoverError
from .results import UnitKey, result_from_dict
from .store import Store

FORMATS = ("csv", "json")


def _scale(store: Store, name: str, scale: str | None) -> str:
    scales = store.scales(name)
    if not scales:
        raise NeurohoverError(store.missing_message(name, None))
    if scale is None:
        if len(scales) > 1:
            raise NeurohoverError(f"experiment {name!r} is in the store at scales {', '.join(scales)}: choose one with --scale")
        return scales[0]
    if scale not in scales:
        raise NeurohoverError(store.missing_message(name, scale))
    return scale


def _flat(prefix: str, value, out: dict) -> None:
    """Params as flat columns: nested dicts as ``a.b``, except MDPs and policies (one JSON cell)."""
    if isinstance(value, dict) and not prefix.endswith(("policies", "mdp", "policy", "generic")):
        for k, v in value.items():
            _flat(f"{prefix}.{k}" if prefix else k, v, out)
    else:
        out[prefix] = value if isinstance(value, (int, float, str, bool)) or value is None else json.dumps(value, separators=(",", ":"))


def export_results(store: Store, name: str, fmt: str = "csv", scale: str | None = None) -> str:
    """The finished units of ``name`` as CSV (one row per unit; nested values JSON-encoded) or JSON."""
    if fmt not in FORMATS:
        raise NeurohoverError(f"unknown format {fmt!r}: allowed {', '.join(FORMATS)}")
    scale = _scale(store, name, scale)
    units = store.units(name, scale)
    config = store.config(name, scale)
    if fmt == "json":
        return (
            json.dumps(
                {"experiment": name, "scale": scale, "config_hash": config["hash"], "config": config, "sessions": store.sessions(name, scale), "units": units},
                indent=1,
            )
            + "\n"
        )
    rows = []
    for u in units:
        key = UnitKey.parse(u["key"])
        row = {
            "experiment": name,
            "scale": scale,
            "key": u["key"],
            "kind": u["kind"],
            "group": key.group,
            "mdp": key.mdp,
            "rep": key.rep,
            "seconds": u["seconds"],
            "worker": u["worker"],
        }
        _flat("param", {k: v for k, v in u["params"].items()}, row)
        row.update({f"result.{k}": v for k, v in result_from_dict(u["kind"], u["result"], u["key"]).columns().items()})
        rows.append(row)
    columns: list[str] = []
    for row in rows:
        columns += [c for c in row if c not in columns]
    buf = io.StringIO()
    writer = csv.DictWriter(buf, fieldnames=columns)
    writer.writeheader()
    writer.writerows(rows)
    return buf.getvalue()
