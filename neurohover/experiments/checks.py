"""How a config setting is declared: :func:`setting` makes a settings dataclass's field carry its check and what a
config that leaves it out resolves to, so the typed settings (:mod:`.settings`) are the one source of the config
schema (:func:`schema_of`, read by :mod:`.schema`), of the defaults the planner reads and of the checks.

A check is ``value -> (ok, what is allowed)``, or ``(ok, what is allowed, the value as read)`` where a setting has one
spelling of several (a task's name: :func:`task_family`). What an absent setting resolves to: :data:`REQUIRED` (the config
must give it), :data:`OMIT` (a setting added later: absent from the resolved config unless given, so that older
configs keep their hash; the field's default is what its absence means) or a value (written into the resolved
config, and so into its hash).
"""

from __future__ import annotations

import copy
from dataclasses import MISSING, Field, field, fields
from typing import Any

from ..agents.registry import usable_agents
from ..errors import NeurohoverError
from ..evolution.evolve import parse_resampling
from ..evolution.races import RACE_RULES
from ..models.model import MODEL_SUBSTEPS
from ..sim.constants import MAX_EPISODE_STEPS
from ..tasks import Drift, Sensor, task_key, task_names

REQUIRED = object()
OMIT = object()  # default of a setting added later: absent from the resolved config unless given (older configs keep their hash)
_UNSET = object()


def setting(check: Any = None, default: Any = _UNSET, *, absent: Any = _UNSET, table: type | None = None) -> Any:
    """A settings dataclass field: its ``check``, its ``default`` in the class (none: the class requires it), what a
    config that leaves it out resolves to (``absent``; by default the ``default``, or :data:`REQUIRED` without one),
    and for a list of sub-tables (``[[variants]]``) the ``table`` class each is read as."""
    resolved = (REQUIRED if default is _UNSET else default) if absent is _UNSET else absent
    metadata = {"check": check, "absent": resolved, "table": table}
    if default is _UNSET:
        return field(metadata=metadata)
    if isinstance(default, (dict, list)):
        return field(default_factory=lambda: copy.deepcopy(default), metadata=metadata)
    return field(default=default, metadata=metadata)


def schema_of(cls: type) -> dict[str, tuple[Any, Any]]:
    """``{name: (absent, check)}`` of a settings class's fields; a list of sub-tables as ``("list", its schema)``."""
    out: dict[str, tuple[Any, Any]] = {}
    for f in fields(cls):
        table = f.metadata.get("table")
        out[f.name] = (f.metadata["absent"], ("list", schema_of(table)) if table is not None else f.metadata["check"])
    return out


def field_default(f: Field) -> Any:
    """A field's default in its class (None where it has none)."""
    if f.default is not MISSING:
        return f.default
    return f.default_factory() if f.default_factory is not MISSING else None


# ----------------------------------------------------------------------------------------------- checks


def integer(minimum: int, maximum: int | None = None):
    def check(v):
        ok = isinstance(v, int) and not isinstance(v, bool) and v >= minimum and (maximum is None or v <= maximum)
        return ok, f"an integer >= {minimum}" if maximum is None else f"an integer in {minimum}..{maximum}"

    return check


#: Caps on an experiment's sizes, far above any run of the paper's, below what planning and memory can hold.
MAX_RUNS, MAX_EPISODES, MAX_STEPS = 10_000, 1_000_000, MAX_EPISODE_STEPS


def number(lo: float, hi: float):
    def check(v):
        return isinstance(v, (int, float)) and not isinstance(v, bool) and lo <= v <= hi, f"a number in [{lo:g}, {hi:g}]"

    return check


def choice(*allowed: Any):
    def check(v):
        return v in allowed, "one of " + ", ".join(repr(a) for a in allowed)

    return check


def seed():
    return lambda v: (isinstance(v, int) and not isinstance(v, bool) and 0 <= v <= 2**63 - 1, "an integer in 0..2**63-1")


def agent():
    def check(v):
        agents = usable_agents()  # a bad registry entry is refused as a config's agent (T44-B14)
        return isinstance(v, str) and v in agents, "one of " + ", ".join(repr(a) for a in agents)

    return check


def task_family():
    def check(v):
        names = task_names()  # the registry as it is, as agent() reads its own: run-time entries too (T46-B07)
        key = task_key(v) if isinstance(v, str) else v  # 'GHH08' is ghh08, as --task reads it, and is stored and hashed so (T58-A01)
        return isinstance(key, str) and key in names, "one of " + ", ".join(repr(a) for a in names), key

    return check


def text():
    def check(v):
        # a label of spaces only was an empty row in the report (trial 45)
        return isinstance(v, str) and v.strip() != "", "a non-empty string (not only spaces)"

    return check


def boolean():
    def check(v):
        return isinstance(v, bool), "true or false"

    return check


def table():
    def check(v):
        return isinstance(v, dict), "a table"

    return check


def text_list(*allowed: str):
    def check(v):
        ok = isinstance(v, list) and len(v) > 0 and all(isinstance(x, str) for x in v) and len(set(v)) == len(v)  # ["lr", "lr"]: eighth trial
        if ok and allowed:
            ok = all(x in allowed for x in v)
        return ok, "a non-empty list of distinct " + ("strings" if not allowed else "names from " + ", ".join(allowed))

    return check


def keys_list():
    def check(v):  # a key given twice: its row twice in the report's Table 3 (T45-A03)
        return isinstance(v, list) and all(isinstance(x, str) for x in v) and len(set(v)) == len(v), "a list of distinct variant keys"

    return check


def resampling():
    def check(v):
        if not isinstance(v, str):
            return False, "a string fixed:K or race:DELTA"
        try:
            parse_resampling(v)
        except NeurohoverError:
            return False, "fixed:K (K >= 1) or race:DELTA[:RULE] (0 < DELTA < 1, RULE " + ", ".join(RACE_RULES) + ")"
        return True, ""

    return check


def _settings_table(cls, keys: str):
    """A table that ``cls.from_dict`` reads (a Sensor's or a Drift's), checked by it; ``keys`` names its settings."""

    def check(v):
        if not isinstance(v, dict):
            return False, f"a table of {cls.__name__.lower()} settings ({keys})"
        try:
            cls.from_dict(v)
        except NeurohoverError as exc:
            return False, f"a valid {cls.__name__.lower()} ({exc})"
        return True, ""

    return check


def sensor_table():
    return _settings_table(Sensor, ", ".join(["level", *(f.name for f in fields(Sensor))]))


def drift_table():
    return _settings_table(Drift, ", ".join(f.name for f in fields(Drift) if f.init))


def seeds_of(names: tuple[str, ...] = ("experiment", "group")):
    def check(v):
        ok = (
            isinstance(v, dict)
            and set(v) == {*names, "seed"}
            and all(isinstance(v[k], str) and v[k] != "" for k in names)
            and isinstance(v["seed"], int)
            and not isinstance(v["seed"], bool)
            and 0 <= v["seed"] <= 2**63 - 1
        )
        what = ", ".join(["experiment = NAME", "seed = ITS ROOT SEED", *(["group = ITS GROUP'S LABEL"] if "group" in names else [])])
        return ok, "a table {" + what + "}"

    return check


def substeps():
    return lambda v: (v in MODEL_SUBSTEPS and not isinstance(v, bool), " or ".join(map(str, MODEL_SUBSTEPS)))


def policy_source():
    def check(v):
        return isinstance(v, str) and v != "", "'evolve', 'shipped' or a directory holding <task>/ policy sets (a relative one from the working directory)"

    return check
