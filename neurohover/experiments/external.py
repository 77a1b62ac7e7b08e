"""Policies an experiment reads from outside its own units: a policy set directory (``policies``, ``generic``,
``robustness_policies``) or policy files (``generics_from = "dir:PATH"``), loaded and checked, and the digest of
them that a config's hash holds, so that results never mix policy sets."""

from __future__ import annotations

import hashlib
import json
import shlex
from collections.abc import Mapping
from typing import TYPE_CHECKING

from ..agents.registry import agent_spec
from ..errors import NeurohoverError
from ..filekinds import refuse_unencodable
from ..policysets import load_policy_set
from .schema import DIR_SOURCE
from .units import family_of, policy_dict

if TYPE_CHECKING:
    from .stored_agents import StoredAgent

#: What each setting naming a policy source takes besides 'shipped' and a directory (the message names the setting given).
_SOURCE_WORDS = {"policies": "'evolve', ", "generic": "'evolve', 'baseline', ", "robustness_policies": ""}
_SOURCE_KEYS = {"test_runs": "policies", "model_learning": "generic", "evolution": "robustness_policies"}


def load_external(task: str, source: str, key: str = "policies"):
    from pathlib import Path

    if source != "shipped":  # 'pd é' under LC_ALL=C PYTHONUTF8=0 was "no such directory", is_dir() False (T31-A05)
        refuse_unencodable(source, f"{key} =")
    folder = Path(source).expanduser()  # "~/bq0" as generics_from's "dir:~/..." is: the user's home (T30-A06)
    if source != "shipped" and not folder.is_dir():  # a generic "nope" was named as policies (eighth trial)
        try:  # a relative one is read from the working directory, not the config's folder: say which
            where = "" if folder.is_absolute() else f" in the working directory {str(Path.cwd())!r}"
        except OSError:  # the working directory was removed
            where = ""
        raise NeurohoverError(  # the command quoted: 'pd 1' unquoted built 'pd' (T31-A05)
            f"{key} = {source!r} is not allowed: give {_SOURCE_WORDS[key]}'shipped' or a directory holding <task>/ policy sets "
            f"(no such directory{where}; build it with: neurohover build-policies --task {task} --out {shlex.quote(source)})"
        )
    return load_policy_set(task, None if source == "shipped" else folder)


def external_digest(kind: str, s: dict, unregistered: Mapping[str, StoredAgent] | None = None, flies: bool | None = None) -> str:
    """Digest of policies a config reads from a directory (so results never mix policy sets). ``unregistered``: its
    agents this process has not registered, as a store shows them (:func:`~.stored_agents.stored_agents`); ``flies``:
    whether its units fly the set, where that is known otherwise (None: as its agents' needs say)."""
    key = _SOURCE_KEYS.get(kind, "policies")
    source = s.get(key)
    payload: dict = {}
    if source not in (None, "evolve", "baseline"):
        ps = load_external(s["task"], source, key)  # read even where unflown: a directory that is none is named
        if _flies_set(kind, s, unregistered) if flies is None else flies:
            payload = {
                "generic": policy_dict(ps.generic),
                "specialised": [policy_dict(p) for p in ps.specialised],
                "safe": list(ps.safe),
                "generics": {k: policy_dict(v) for k, v in sorted(ps.generics.items())},
            }
    drawn = {k: v for k, v in sorted((s.get("generics_from") or {}).items()) if str(v).startswith(DIR_SOURCE)} if kind == "test_runs" else {}
    if drawn:  # generics read from policy files: their genomes are part of the config
        payload["generics_from"] = {k: [p for _, p in dir_champions(v)] for k, v in drawn.items()}
    if not payload:
        return ""
    return hashlib.sha256(json.dumps(payload, sort_keys=True).encode()).hexdigest()[:16]


def _flies_set(kind: str, s: dict, unregistered: Mapping[str, StoredAgent] | None = None) -> bool:
    """Whether a config's units fly policies of the set its policy source names: test runs whose every group is
    baseline fly none, and their results do not depend on the set's files (T35-A02: they were refused once it changed)."""
    if kind != "test_runs":
        return True
    family = family_of(s["task"], s.get("sigma"))  # what a set holds depends on the task alone, not its sensors
    return bool(policy_needs(family, [g["agent"] for g in s["groups"]], unregistered))


def dir_champions(source: str) -> list[tuple[str, dict]]:
    """``[(label, policy)]`` of the policy files in the directory ``dir:PATH`` names, in file-name order."""
    from pathlib import Path

    from ..policies import load_policy

    refuse_unencodable(source[len(DIR_SOURCE) :], "generics_from dir:")  # as policies = (T31-A05)
    folder = Path(source[len(DIR_SOURCE) :]).expanduser()
    files = sorted(f for f in folder.iterdir() if f.suffix.lower() in (".net", ".json")) if folder.is_dir() else []
    if not files:
        raise NeurohoverError(f"generics_from {source!r}: no directory of policy files (.net or .json) there; give dir:PATH of one")
    return [(f"{source}/{f.name}", policy_dict(load_policy(f))) for f in files]


def policy_needs(family, agents: list[str], unregistered: Mapping[str, StoredAgent] | None = None) -> set[str]:
    """The kinds of policy (generic, specialised, safe, ...) that ``agents`` fly of ``family``'s policy set (those of
    ``unregistered`` as a store shows them: :func:`~.stored_agents.stored_agents`)."""
    needs: set[str] = set()
    for agent in agents:
        spec = (unregistered or {}).get(agent) or agent_spec(agent)
        needs |= spec.needs
        if family.generic_over_distribution and spec.generic_kind is not None:
            needs.add(spec.generic_kind)
    return needs
