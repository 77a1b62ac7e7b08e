"""``neurohover results``: export an experiment's finished units as CSV or JSON.

CSV: one row per unit, one plain value per cell, for a spreadsheet or ``pandas.read_csv``:
experiment, scale, key, kind, the key's parts (group, mdp, rep:
:class:`~neurohover.experiments.results.UnitKey`), seconds, worker, then the params (``param.*``)
and the typed result's columns (``result.*``: :meth:`~neurohover.experiments.results.EvolveResult.columns`).
Nested values are spread out: a dict as dotted columns (``param.target.mdp.label``), a list of at
most ``SHORT_LIST`` (8) plain values one column per entry (``.0``, ``.1``), a longer list of numbers
its count and mean (``.n``, ``.mean``; flags: ``.n``, ``.sum``), any other list (a history, a
genome, episodes of several MDPs) its count alone. JSON: the units exactly as the store holds
them, every list in full.
"""

from __future__ import annotations

import csv
import io
import json
from collections.abc import Mapping
from dataclasses import replace
from typing import Any

from ..agents.spec import FGHH_GENERIC_KINDS
from ..errors import NeurohoverError, brief, first_difference
from .config import ExperimentConfig
from .external import external_digest
from .keys import UnitKey
from .plans import Plan, plan, run_keys, source_results
from .put_checks import key_shape_problem
from .result_checks import identity_problem, params_problem
from .results import UnitResult, flat_cells, result_from_dict
from .settings import TestRunsSettings
from .store import Store
from .store_checks import hash_problem, read_config, unit_seconds_problem
from .stored_agents import StoredAgent, UnregisteredAgentError, agent_runs, stored_agents
from .units import family_of

FORMATS = ("csv", "json")


def orphan_message(store: Store, name: str, scale: str, count: int, key: str) -> str:
    """The damage of :meth:`Store.orphan_units`' row ``(name, scale, count, key)``, naming the store, the experiment and a unit."""
    return (
        f"results store {str(store.path)!r}, experiment {name} ({scale}), is damaged: it holds {count} finished unit(s) of it but no record "
        f"of its config, so they cannot be checked (the first: unit {key!r}): give another store (reproduce --fresh discards them)"
    )


def refuse_orphans(store: Store, name: str) -> None:
    """NeurohoverError (:func:`orphan_message`) when experiment ``name`` has orphan units at any scale
    (:meth:`Store.orphan_units`: units whose config row is gone, so nothing can check them).

    The choice (T21-15: a unit copied to scale 'paper' with no paper config was ignored by results and report and left
    alone by reproduce): the shared check :func:`checked_units` refuses an experiment that has orphans at any scale, so
    results, wins, report's section of it, reproduce and compete all call it damaged; :func:`resolve_scale` names them
    rather than "holds no experiment"; and ``neurohover report`` warns of orphans of an experiment it has no section for,
    by one line on stderr each (refused, exit 2, when they are all it was asked for)."""
    found = store.orphan_units(name)
    if found:
        raise NeurohoverError(orphan_message(store, *found[0]))


def resolve_scale(store: Store, name: str, scale: str | None) -> str:
    """The scale of experiment ``name`` in the store: ``scale``, or its only one (a clear error otherwise; units of it
    at a scale of no config row are damage: :meth:`Store.orphan_units`)."""
    scales = store.scales(name)
    refuse_orphans(store, name)
    if not scales:
        raise NeurohoverError(store.missing_message(name, None))
    if scale is None:
        if len(scales) > 1:
            raise NeurohoverError(f"experiment {name!r} is in the store at scales {', '.join(scales)}: choose one with --scale (e.g. --scale {scales[-1]})")
        return scales[0]
    if not isinstance(scale, str):  # an array was numpy's 'truth value is ambiguous' (T18-3)
        raise NeurohoverError(f"scale={brief(scale)} is not allowed: give one of {', '.join(scales)}")
    if scale not in scales:
        raise NeurohoverError(store.missing_message(name, scale))
    return scale


def _check_hashes(store: Store, name: str, scale: str, stored: dict, config: ExperimentConfig) -> None:
    """Refuse an experiment whose recorded config hash is not its config's, or a unit run under another hash: a
    config_hash set to 'deadbeef' was exported and reported, a unit's set to 'x' reused by reproduce (T20-04).
    ``store.update`` gives every kept unit the new hash, so a unit of another hash is never one a run left."""
    held = store.config_hash(name, scale)
    problem = hash_problem(held, stored, config)  # Store.begin's check too (T29-B07)
    if problem:
        raise NeurohoverError(problem)
    for key, unit_hash in sorted(store.unit_config_hashes(name, scale).items()):
        if unit_hash != held:
            raise NeurohoverError(
                f"unit {key!r} was run under config hash {brief(unit_hash)}, not the experiment's {held}: its result is not this config's "
                "(reproduce --fresh runs it again)"
            )


def _check_key(config: ExperimentConfig, unit: dict) -> None:
    """Refuse a unit key of no shape the experiment's plan gives (:func:`~.put_checks.key_shape_problem`; T20-05)."""
    problem = key_shape_problem(config.kind, unit["key"], unit["kind"])
    if problem:
        raise NeurohoverError(problem)  # the caller names the unit


def _replannable(config: ExperimentConfig, unregistered: Mapping[str, StoredAgent]) -> bool:
    """Whether ``config``'s plan can be made again as its units were: the policies it reads from outside the store (the
    shipped set, a directory) digest as they did when it was stored. A policy directory since removed or changed (the
    paper-scale fig16-authors-generics reads 'dir:AUTHORS/...') leaves its units checked by key, kind and result alone.
    Agents this process has not registered come as their stored runs show them (``unregistered``): their "unknown agent"
    was taken for a directory gone, and the check skipped (T60-B04). Whether they fly the set is then taken either way,
    as runs of none show nothing of it (an agent that needs specialised policies flies none on FGHH)."""
    flies = (None, True) if unregistered else (None,)
    try:
        return config.external_digest in {external_digest(config.kind, config.settings, unregistered, f) for f in flies}
    except NeurohoverError:  # the directory is gone
        return False


def _as_stored(params: dict) -> dict:
    """A planned unit's params as the store writes them (tuples as lists)."""
    return json.loads(json.dumps(params))


def stored_plan(
    config: ExperimentConfig, units: list[dict], sources: dict[str, dict] | None = None, unregistered: Mapping[str, StoredAgent] | None = None
) -> Plan:
    """:func:`~.plans.plan` of a stored ``config`` and its stored ``units`` (:meth:`Store.units`' dicts; ``sources``: as
    plan takes them), its agents this process has not registered planned as those units show them (``unregistered``;
    None: :func:`~.stored_agents.stored_agents`): one that flies a generic on a family of generics by kind flies the kind
    whose plan gives most of its stored runs their policies (T60-B04)."""
    unregistered = stored_agents(config, units) if unregistered is None else unregistered
    results = {u["key"]: u["result"] for u in units}
    s = config.typed
    open_kind = [a for a in unregistered.values() if "generic" in a.needs and a.generic_kind is None]
    if open_kind and isinstance(s, TestRunsSettings) and family_of(s.task, s.sigma, s.sensor).generic_over_distribution:
        best: dict[str, tuple[int, str]] = {}
        for kind, _ in FGHH_GENERIC_KINDS:
            made = plan(config, results, sources, {**unregistered, **{a.name: replace(a, generic_kind=kind) for a in open_kind}})
            planned = {u.key: _as_stored(u.params).get("policies") for u in made.units}
            for a in open_kind:
                found = sum(planned.get(u["key"]) == u["params"]["policies"] for u in agent_runs(units, a.name))
                if a.name not in best or found > best[a.name][0]:
                    best[a.name] = (found, kind)
        unregistered = {**unregistered, **{a.name: replace(a, generic_kind=best[a.name][1]) for a in open_kind}}
    return plan(config, results, sources, unregistered)


def _stray_text(key: str, more: str, units: list[dict], planned: dict) -> str:
    """The refusal of stored unit ``key`` that the config does not plan. Where a unit it is made from is missing, that is
    the fault named: its params' ``source`` (a robustness unit's: the evolution run whose champion it flies) that the
    store does not hold, else a planned unit of its group and MDP it does not hold (a robustness unit is planned once
    every run of its variant on its MDP is stored). A deleted evolution run was told as a robustness unit the config
    does not plan (T26-B15)."""
    held = {u["key"] for u in units}
    params = next((u["params"] for u in units if u["key"] == key), None)
    source = params.get("source") if isinstance(params, dict) else None
    parsed = UnitKey.parse(key)
    if not (isinstance(source, str) and source not in held and UnitKey.parse(source).stage):
        same = (UnitKey.parse(k) for k in sorted(planned) if k not in held)
        source = next((k.key for k in same if k.stage != parsed.stage and (k.group, k.mdp) == (parsed.group, parsed.mdp)), None)
    if source is not None and parsed.stage:
        return (
            f"it holds unit {key!r}{more}, made from unit {source!r}, which it does not hold: the config plans the one once the other "
            "is stored; the unit it is made from was removed or moved (reproduce --fresh starts it over)"
        )
    return f"it holds unit {key!r}{more}, which the config does not plan (reproduce --fresh starts it over)"


def _check_planned(store: Store, config: ExperimentConfig, units: list[dict]) -> Plan | None:
    """Refuse a stored unit its stored config does not plan, or one whose kind or params (the seed, the episodes) are not
    those the config plans for its key: reproduce refused both (seventh, eighth trial) while results and report exported
    a unit whose seed was edited in the store (T21-02). The plan is made from every stored unit (a later stage is planned
    from earlier results); a test run planned only once its policies are stored is checked by its key alone. A
    'diagnostic' unit (the tests' own plans) is not planned by any config. An agent this process has not registered is
    planned as its stored runs show it (:func:`stored_plan`; T60-B04). Returns the plan (None where none was made)."""
    checked = [u for u in units if u["kind"] != "diagnostic"]
    unregistered = stored_agents(config, units)
    if not checked or not _replannable(config, unregistered):
        return None
    made = stored_plan(config, units, source_results(config, store), unregistered)
    planned = {u.key: u for u in made.units}
    known = set(planned) | set(run_keys(config))
    stray = sorted(u["key"] for u in checked if u["key"] not in known)
    if stray:
        more = f" (and {len(stray) - 1} more)" if len(stray) > 1 else ""
        raise NeurohoverError(_stray_text(stray[0], more, checked, planned))
    for u in checked:
        p = planned.get(u["key"])
        if p is None:
            continue
        want = {"kind": p.kind, "params": _as_stored(p.params)}
        if want != {"kind": u["kind"], "params": u["params"]}:
            differ = first_difference("unit", {"kind": u["kind"], "params": u["params"]}, want)
            raise NeurohoverError(
                f"unit {u['key']!r} holds other settings than its config plans for it ({differ.replace(', given ', ', planned ')}): "
                "it was changed in the store (reproduce --fresh starts it over)"
            )
    return made


def check_run_lengths(episodes: Any, results: dict[str, Any]) -> None:
    """Refuse a stored test run whose episodes are not the experiment's ``episodes`` (None: not a test-runs experiment), by
    its key: the report stacks every run's returns (a shorter one was a NumPy ValueError there; seventh trial). ``results``
    are the test runs' results as stored (key -> dict), checked before :func:`result_from_dict` reads them, so a run of
    another length is named as such rather than for a return it holds (T22-05); one of no returns is left to that check."""
    if episodes is None:
        return
    for key, result in results.items():
        returns = result.get("returns") if isinstance(result, dict) else None
        if isinstance(returns, list) and returns and len(returns) != episodes:
            raise NeurohoverError(f"test run {key!r} holds {len(returns)} episodes' returns where its experiment flies {episodes}")


def checked_units(store: Store, name: str, scale: str) -> tuple[ExperimentConfig, list[dict], dict[str, UnitResult]]:
    """Experiment (name, scale)'s stored config and finished units, each read back and checked: the one check of a stored
    experiment that results, wins, report and reproduce (compete too) share.

    Returns
    -------
    config : ExperimentConfig
        The stored config.
    units : list of dict
        The finished units, as :meth:`~neurohover.experiments.Store.units` gives them.
    results : dict
        Unit key -> its typed result (:func:`~neurohover.experiments.results.result_from_dict`).

    Raises
    ------
    NeurohoverError
        One message naming the store, the experiment and the damaged unit (where one is): wins took a unit of kind
        'bogus' for a test run (T19-05), and results' messages named neither the store nor the unit (T19-14). Also a
        config that does not hash to its recorded hash, a unit run under another hash (T20-04), a unit key of no
        shape the experiment's plan gives (T20-05), and a unit the stored config does not plan, or plans with other
        kind or params (T21-02; :func:`_check_planned`), and units of the experiment at a scale of no config row
        (T21-15; :meth:`Store.orphan_units`), and a result that contradicts its unit's params (an agent, MDP or crash
        step of none they name; T22-07, T22-08: :func:`~neurohover.experiments.result_checks.params_problem`).
    """
    return checked_experiment(store, name, scale)[:3]


def checked_experiment(store: Store, name: str, scale: str) -> tuple[ExperimentConfig, list[dict], dict[str, UnitResult], Plan | None]:
    """:func:`checked_units`' config, units and results, and the plan its check made of the stored config and units
    (None where it made none: no units, or policies from outside the store that changed): reproduce's first round, so a
    resumed experiment is planned once, not again after its check."""
    where = f"results store {str(store.path)!r}, experiment {name} ({scale}), is damaged"
    refuse_orphans(store, name)  # its units at a scale of no config row, ignored (T21-15): refuse_orphans says why
    stored = store.config(name, scale)  # the store names a row that is no JSON object itself, as for the units below
    try:  # Store.begin's check too (T29-B07)
        config = read_config(stored, scale)
    except NeurohoverError as err:
        raise NeurohoverError(f"{where}: {err}") from None
    units = store.units(name, scale)
    runs = {u["key"]: u["result"] for u in units if u["kind"] == "test_run"}
    try:  # before the results are read: a run of another length is named as such (T22-05)
        check_run_lengths(config.settings.get("episodes") if config.kind == "test_runs" else None, runs)
    except NeurohoverError as err:
        raise NeurohoverError(f"{where}: {err}") from None
    results: dict[str, UnitResult] = {}
    contradicted = ""  # a result naming another agent or MDP than its params, which its own check blamed on a sound field (T55-A04)
    for u in units:
        try:
            results[u["key"]] = result_from_dict(u["kind"], u["result"], u["key"])
            _check_key(config, u)
        except NeurohoverError as err:
            contradicted = identity_problem(u["kind"], u["result"], u["params"])
            if contradicted:  # named after the plan check, which names params changed instead
                contradicted = f"{where}: unit {u['key']!r}: its result contradicts its params: {contradicted}"
                break
            unit = "" if repr(u["key"]) in str(err) else f"unit {u['key']!r}: "
            raise NeurohoverError(f"{where}: {unit}{err}") from None
    try:
        _check_hashes(store, name, scale, stored, config)
        made = _check_planned(store, config, units)
    except UnregisteredAgentError as err:  # not damage: this process lacks the agent (T60-B04)
        raise NeurohoverError(f"results store {str(store.path)!r}, experiment {name} ({scale}): {err}") from None
    except NeurohoverError as err:
        raise NeurohoverError(f"{where}: {err}") from None
    if contradicted:
        raise NeurohoverError(contradicted)
    for u in units:  # a result must be its unit's (T22-07, T22-08); after the plan check, which names params changed
        problem = params_problem(results[u["key"]], u["params"])
        if problem:
            raise NeurohoverError(f"{where}: unit {u['key']!r}: its result contradicts its params: {problem}")
        problem = unit_seconds_problem(u["seconds"], results[u["key"]])  # last: an edited result's own timing named first (T45-B02)
        if problem:
            raise NeurohoverError(f"{where}: unit {u['key']!r}: {problem}")
    store.sessions(name, scale)  # its sessions rows, last (a damaged unit named first): for every command, not report alone (T27-A07)
    return config, units, results, made


def export_results(store: Store, name: str, fmt: str = "csv", scale: str | None = None) -> str:
    """The finished units of ``name`` as CSV (one row per unit, one plain value per cell) or JSON (everything)."""
    if not isinstance(store, Store):  # a path was an AttributeError (seventh trial)
        raise NeurohoverError(f"store={store!r:.60} is not allowed: give a Store(PATH)")
    if not isinstance(fmt, str) or fmt not in FORMATS:  # an array was numpy's 'truth value is ambiguous' (T18-3)
        raise NeurohoverError(f"unknown format {brief(fmt)}: allowed {', '.join(FORMATS)}")
    scale = resolve_scale(store, name, scale)
    if not any(n for e, s, _, n in store.experiments() if (e, s) == (name, scale)):  # it printed an empty line (seventh trial)
        raise NeurohoverError(f"experiment {name} ({scale}) has no finished unit yet: nothing to export (neurohover reproduce runs its units)")
    _, units, typed = checked_units(store, name, scale)  # JSON exports what CSV does: no damaged config or unit (sixth trial)
    config = store.config(name, scale)  # exported as stored
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
        flat_cells("param", u["params"], row)
        row.update({f"result.{k}": v for k, v in typed[u["key"]].columns().items()})
        rows.append(row)
    columns: list[str] = []
    for row in rows:
        columns += [c for c in row if c not in columns]
    buf = io.StringIO()
    writer = csv.DictWriter(buf, fieldnames=columns)
    writer.writeheader()
    writer.writerows(rows)
    return buf.getvalue()
