"""What differs between the config a results store holds for an experiment and a new one: :meth:`Store.begin`'s
refusal of a changed config names each differing setting (moved out of :mod:`.store_checks`, T56-A03)."""

from __future__ import annotations

import itertools
import json
from typing import Any

from ..errors import NeurohoverError, brief
from ..jsontext import strict_json
from .config import ExperimentConfig

__all__ = ["config_changes", "config_differs"]

_ABSENT = object()  # a setting one of two configs does not have


def _setting_changes(old: Any, new: Any, path: str) -> list[tuple[str, Any, Any]]:
    """(setting, stored value, given value) of each setting that differs between two configs' settings: tables key by key,
    lists of named entries (groups, variants, fits, conditions) entry by entry, named by their label or key."""
    if isinstance(old, dict) and isinstance(new, dict):
        keys = sorted(set(old) | set(new), key=str)
        return [c for k in keys for c in _setting_changes(old.get(k, _ABSENT), new.get(k, _ABSENT), f"{path}.{k}" if path else str(k))]
    if isinstance(old, list) and isinstance(new, list) and all(isinstance(e, dict) for e in old + new):
        # lists of other lengths too: entry by entry, an entry one list lacks stored or given absent; both lists shown whole
        # were cut by brief() at the same shared prefix and read alike (T56-A03)
        pairs = list(itertools.zip_longest(old, new, fillvalue=_ABSENT))
        names = [_entry_name(e, n, i) for i, (e, n) in enumerate(pairs)]
        return [c for name, (e, n) in zip(names, pairs) for c in _setting_changes(e, n, f"{path} {name!r}" if isinstance(name, str) else f"{path}[{name}]")]
    same = json.dumps(old, sort_keys=True, default=repr) == json.dumps(new, sort_keys=True, default=repr) if _ABSENT not in (old, new) else old is new
    return [] if same else [(path, old, new)]


def _entry_name(old: Any, new: Any, index: int) -> str | int:
    """How :func:`_setting_changes` names entry ``index`` of a list of named entries: its label or key where both
    configs' entries (or the one that has it) agree on it, else its index."""
    held = [e for e in (old, new) if e is not _ABSENT]
    return next((held[0][k] for k in ("label", "key") if all(k in e and e[k] == held[0][k] for e in held)), index)


def config_changes(stored: Any, given: dict) -> tuple[str, bool]:
    """What differs between the config a store holds (``stored``: its text, as :meth:`ExperimentConfig.to_dict` wrote it) and a
    new one (``given``), for :meth:`Store.begin`'s refusal: each differing setting, stored vs given (reproduce named
    only the two hashes; T34-A02), and whether the stored config only lacks settings a newer neurohover writes in."""
    try:
        held = ExperimentConfig.from_dict(strict_json(stored))
        old, new = held.settings, ExperimentConfig.from_dict(given).settings  # today's spelling
    except (NeurohoverError, TypeError, ValueError):
        return "the stored config cannot be read to compare it", False
    changes = _setting_changes(old, new, "")
    if not changes:
        return "their settings are equal: another version of neurohover (which computes its units otherwise) or another policy set ran them", False
    shown = "; ".join(f"{k}: stored {'absent' if a is _ABSENT else brief(a)}, given {'absent' if b is _ABSENT else brief(b)}" for k, a, b in changes[:6])
    shown += f" (and {len(changes) - 6} more)" if len(changes) > 6 else ""
    defaulted = _defaulted(held.kind, old, new, changes)
    if len(defaulted) == len(changes):
        return f"the settings differ only in ones the stored config lacks, which a newer neurohover added at their defaults ({shown})", True
    absent = f"; {', '.join(defaulted)}: a setting the older neurohover that wrote the store did not have, at its default" if defaulted else ""
    return f"the settings differ ({shown}{absent})", False


def _defaulted(kind: str, old: dict, new: dict, changes: list[tuple[str, Any, Any]]) -> list[str]:
    """The changes (:func:`_setting_changes`) that a newer neurohover made: a setting the stored settings ``old`` lack that
    this version writes in (its schema's default) when it resolves them again, given at that value. A setting this version
    leaves out at its default too (a sensor, an optimizer's name), given now, is the user's change: it was called an older
    neurohover's, at a default it is not at, and the remedies of a changed config were left out (T46-A02)."""
    from .canonical import canonical_settings
    from .schema import SCHEMAS, check_kind, validate_table

    absent = [k for k, a, _ in changes if a is _ABSENT]
    if not absent:
        return []
    try:
        again = validate_table(json.loads(json.dumps(old)), SCHEMAS[kind], "the stored config")
        check_kind(again, kind, "the stored config")
        canonical_settings(again)
    except (NeurohoverError, KeyError, TypeError, ValueError):  # not today's to resolve: no default is told
        return []
    still = {k for k, _, _ in _setting_changes(again, new, "")}
    return [k for k in absent if k not in still]


def config_differs(store: str, name: str, scale: str, held: str, stored: Any, config_hash: str, config: dict) -> str:
    """:meth:`Store.begin`'s refusal of a config other than the one experiment (name, scale) is stored with, naming what differs."""
    what, added = config_changes(stored, config)
    head = (
        f"results store {store!r} already holds experiment {name!r} at scale {scale!r} with config hash {held}, but this config hashes to {config_hash}: {what}"
    )
    update = "rerun with --update to keep the stored units the new config plans with the same params (and run the others)"
    if added:  # the old config cannot be restored: this neurohover writes the new settings in (T34-A02)
        return f"{head}; an older neurohover wrote this store. To go on with it, {update}; or give another --store file"
    return (
        f"{head}, so the results would not be comparable. Use another --store file, restore the old config, {update}, or with --fresh "
        f"to discard every stored result of {name!r} ({scale})"
    )
