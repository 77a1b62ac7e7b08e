"""One spelling of equal settings, so that they hash alike (T29-A07): :func:`canonical_settings` rewrites an experiment's
checked settings before :class:`~.config.ExperimentConfig` hashes them, and :func:`typed_numbers` is the rule for
numbers that compete's agent settings share.

Equal settings spelt otherwise were other experiments: ``sensor = {}``, ``drift = {}`` or ``sensor = { level = 0.5,
dropout = 0 }`` gave another config hash than the same config without them, and an agent's ``level = 1`` another than
``level = 1.0``, so stored results were refused or flown again. The rules keep every shipped config's hash (each spells
its settings in the form kept here; tests/test_bad_input_trial29_configs.py checks them all at both scales):

- a number given as an int for a setting whose default is a float is that float (``level = 1`` is ``1.0``);
- a sensor table keeps only the keys that change its sensor (``dropout = 0``, ``level = 0`` go); an exact one is no
  sensor, and a group's or a condition's equal to what it would fly without it is left out;
- a drift that drifts nothing is no drift (``drift = {}``); a drift's ``walk = 0`` beside a change goes, and a change's
  ``change_at`` is written in (the default range, as the shipped configs write it);
- hybrid settings equal to their defaults are none given. A group's own agent settings are kept as given even when all are
  the agent's defaults (risk-ghh09 spells them so, and its hash must stay): a config that leaves them out is another
  spelling, as before. ``neurohover compete`` leaves out agent settings equal to the defaults itself (its tables are
  written whole), so there the three spellings of the trial are one.
"""

from __future__ import annotations

from dataclasses import fields
from typing import Any

from ..agents.hybrid import HybridSettings
from ..agents.registry import AGENTS
from ..errors import NeurohoverError
from ..tasks import Drift
from ..tasks.drift import CHANGE_AT
from ..tasks.sensor import Sensor


def _int(v: Any) -> bool:
    return isinstance(v, int) and not isinstance(v, bool)


def typed_numbers(defaults: dict, values: dict) -> dict:
    """``values`` with an int given for a setting whose default in ``defaults`` is a float as that float."""
    return {k: float(v) if isinstance(defaults.get(k), float) and _int(v) else v for k, v in values.items()}


_SENSOR_DEFAULTS = {"level": 0.0, **{f.name: f.default for f in fields(Sensor)}}


def canonical_sensor(table: dict) -> dict:
    """A sensor table without the keys that change nothing, its numbers typed (:func:`typed_numbers`)."""
    out = typed_numbers(_SENSOR_DEFAULTS, table)
    whole = Sensor.from_dict(out)
    for key in sorted(out):
        rest = {k: v for k, v in out.items() if k != key}
        try:
            if Sensor.from_dict(rest) == whole:
                out = rest
        except NeurohoverError:  # the key is needed (a correlation without its noise is refused)
            pass
    return out


def canonical_drift(table: dict) -> dict | None:
    """A drift table in one spelling (None: it drifts nothing)."""
    if Drift.from_dict(table).none:
        return None
    out = dict(table)
    if _int(out.get("walk")):
        out["walk"] = float(out["walk"])
    if out.get("walk") == 0.0:
        del out["walk"]
    if "change" in out:
        out["change"] = {k: float(v) if _int(v) else v for k, v in out["change"].items()}
        if not out["change"]:
            del out["change"]
    if out.get("change"):
        out["change_at"] = list(out.get("change_at", CHANGE_AT))
    return out


def _own_sensor(entry: dict, inherited: dict | None) -> None:
    """An entry's (a group's, a condition's) sensor in one spelling, left out where it flies what it would without it."""
    if entry.get("sensor") is not None:
        entry["sensor"] = canonical_sensor(entry["sensor"])
        if entry["sensor"] == (inherited or {}):
            del entry["sensor"]


def _group(g: dict, sensor: dict | None, drift: dict | None) -> None:
    _own_sensor(g, sensor)
    if g.get("drift") is not None:
        own = canonical_drift(g["drift"])  # None: fixed dynamics, which {} says beside the experiment's drift
        if (own or None) == drift:
            del g["drift"]
        elif own is not None:
            g["drift"] = own
    spec = AGENTS.get(g["agent"])
    if g.get("settings") is not None and spec is not None and spec.settings is not None:
        defaults = spec.settings().to_dict()
        g["settings"] = typed_numbers(defaults, g["settings"])  # kept when all are defaults: risk-ghh09 spells them so
    if g.get("hybrid"):
        defaults = HybridSettings().to_dict()
        g["hybrid"] = typed_numbers(defaults, g["hybrid"])
        if g["hybrid"] == defaults:
            g["hybrid"] = {}


def canonical_settings(resolved: dict) -> dict:
    """An experiment's checked settings (:func:`~.config.make_config`'s) with equal settings in one spelling (in place)."""
    if resolved.get("sensor") is not None:
        resolved["sensor"] = canonical_sensor(resolved["sensor"])
        if not resolved["sensor"]:
            del resolved["sensor"]
    if resolved.get("drift") is not None:
        drift = canonical_drift(resolved["drift"])
        if drift is None:
            del resolved["drift"]
        else:
            resolved["drift"] = drift
    for g in resolved.get("groups", []):
        _group(g, resolved.get("sensor"), resolved.get("drift"))
    for c in resolved.get("conditions", []):
        _own_sensor(c, None)
    return resolved
