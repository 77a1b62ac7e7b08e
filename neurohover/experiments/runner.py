"""Running an experiment: plan units, skip the finished ones, execute the rest, record each at once."""

from __future__ import annotations

import json
import sys
import time
from collections.abc import Callable, Collection, Sequence
from dataclasses import dataclass, field

from ..errors import NeurohoverError, brief, check_flag
from .config import POLICY_SOURCES, ExperimentConfig, check_own_name, check_paper_table
from .keys import key_matches
from .plans import Plan, plan, robust_sources, run_keys, source_results
from .store import Store


@dataclass
class RunSummary:
    """What one ``reproduce`` call did for one experiment."""

    name: str
    scale: str
    executor: str
    cores: int
    units_total: int = 0
    units_before: int = 0
    units_run: int = 0
    failed: list[tuple[str, str]] = field(default_factory=list)
    wall_seconds: float = 0.0
    status: str = "running"

    @property
    def units_done(self) -> int:
        return self.units_before + self.units_run

    @property
    def succeeded(self) -> bool:
        """Every unit asked for (all, or the ``only`` selection) finished."""
        return self.status in ("finished", "selection finished")

    def line(self) -> str:
        text = (
            f"{self.name} ({self.scale}): {self.status}; ran {self.units_run} unit{'' if self.units_run == 1 else 's'}, {self.units_before} already in "
            f"the store, {self.units_done}/{self.units_total} done, {self.wall_seconds:.1f} s on {self.cores} cores ({self.executor})"
        )
        if self.failed:
            text += f"; {len(self.failed)} failed, first: {self.failed[0][0]}: {self.failed[0][1]}"
        return text


def _short(err: BaseException) -> str:
    text = str(err).strip() or type(err).__name__
    lines = [ln for ln in text.splitlines() if ln.strip()]
    return f"{type(err).__name__}: {lines[-1] if lines else text}"[:500]


def selected(key: str, only: Sequence[str], needed: Collection[str] = ()) -> bool:
    """Whether unit ``key`` is in the selection ``only`` (glob patterns, :func:`~.keys.key_matches`; empty: every unit).

    Shared prerequisites (``policy/...`` units: the policies that test runs fly) are always selected, and so are the
    units in ``needed`` (:func:`prerequisites`: the evolve units whose champions selected robustness units fly).
    """
    return not only or key.startswith("policy/") or key in needed or any(key_matches(key, pat) for pat in only)


def prerequisites(config: ExperimentConfig, only: Sequence[str]) -> set[str]:
    """The keys of the units a selection ``only`` needs made first besides ``policy/`` units: the evolve units whose
    best champion a selected robustness unit flies (:func:`~.plans.robust_sources`). They were neither run nor named,
    and the run said "selection finished" (T48-A01)."""
    return {src for key, srcs in robust_sources(config).items() if any(key_matches(key, pat) for pat in only) for src in srcs}


def check_patterns_once(patterns: Sequence[str], option: str) -> None:
    """Refuse a selection naming one pattern twice (``--only P --only P`` was taken without a word, where a repeated
    --obs-noise key is refused)."""
    twice = next((p for i, p in enumerate(patterns) if p in patterns[:i]), None)
    if twice is not None:
        raise NeurohoverError(f"{option} names the pattern {brief(twice)} twice: give each pattern once")


def check_restart(fresh: bool, update: bool, only: Sequence[str] = ()) -> None:
    """Refuse ``fresh`` (discard every stored result) together with ``update`` (keep the unchanged ones) or ``only`` (run a
    selection: the stored units outside it were lost; sixth trial)."""
    if fresh and update:
        raise NeurohoverError("--fresh discards every stored result and --update keeps the unchanged ones: give one of them")
    if fresh and only:
        raise NeurohoverError(
            "--fresh discards every stored result, and --only would run again only some of them: give one of them "
            "(--fresh alone runs the whole experiment again)"
        )


def unchanged_units(config: ExperimentConfig, store: Store) -> set[str]:
    """The keys of the stored units of ``config``'s experiment that ``config`` plans alike: same key,
    kind and params (the seed included), so their results stand under it.

    Planning is repeated with the units kept so far, since later units (test runs) are planned from the
    results of earlier ones (their policies). Refuses a stored config that this version of neurohover
    does not hash alike (another ``UNITS_VERSION``): its units were computed otherwise.
    """
    _refuse_other_version(config, store, ExperimentConfig.from_dict(store.config(config.name, config.scale)))
    stored = {u["key"]: u for u in store.units(config.name, config.scale)}
    sources = source_results(config, store)
    kept: dict[str, dict] = {}
    while True:
        same = [
            u.key
            for u in plan(config, kept, sources).units
            if u.key not in kept and u.key in stored and stored[u.key]["kind"] == u.kind and stored[u.key]["params"] == json.loads(json.dumps(u.params))
        ]
        if not same:
            return set(kept)
        kept.update((key, stored[key]["result"]) for key in same)


def _refuse_other_version(config: ExperimentConfig, store: Store, stored_config: ExperimentConfig) -> None:
    """Refuse an ``--update`` of stored results whose config does not hash to its recorded hash (another ``UNITS_VERSION``)."""
    stored_hash = store.config_hash(config.name, config.scale)
    if stored_config.hash != stored_hash:
        raise NeurohoverError(
            f"{config.name} ({config.scale}): its stored results were computed by another version of the units "
            f"(config hash {stored_hash}, which this version reads as {stored_config.hash}); rerun with --fresh instead of --update"
        )


def _refuse_other_version_first(config: ExperimentConfig, store: Store, held: str | None, update: bool) -> None:
    """:func:`_refuse_other_version` before the shared check, which calls such a store damaged (T20-04): an ``--update``
    of a changed config (``held``: the stored hash) is told why (--fresh, not --update). A config that does not read back
    is left to the shared check to name."""
    if not update or held is None or held == config.hash:
        return
    try:
        stored_config = ExperimentConfig.from_dict(store.config(config.name, config.scale))
    except NeurohoverError:
        return
    _refuse_other_version(config, store, stored_config)


def _take_changed_config(config: ExperimentConfig, store: Store, held: str | None, update: bool) -> bool:
    """Register ``config`` where the store holds its experiment under another hash (``held``), keeping the stored units
    it plans alike, and say so: with ``update``, or where the stored config hashed a policy set none of its units flies
    (an older neurohover's: refused once the set changed, though its results do not depend on it; T35-A02). Whether
    units were dropped (their results must be read again)."""
    if held is None or held == config.hash:
        return False
    if not update:
        if config.same_but_unflown_digest(store.config(config.name, config.scale)):
            kept = store.update(config.name, config.scale, config.hash, config.to_dict(), unchanged_units(config, store))
            print(
                f"{config.name} ({config.scale}): {kept} stored units stand under hash {config.hash} (its {held} hashed an unflown policy set)", file=sys.stderr
            )
        return False
    _check_policy_source(config, store)
    kept = store.update(config.name, config.scale, config.hash, config.to_dict(), unchanged_units(config, store))
    print(f"{config.name} ({config.scale}): the config changed (hash {held} -> {config.hash}); {kept} stored units stand unchanged", file=sys.stderr)
    return True


def _check_policy_source(config: ExperimentConfig, store: Store) -> None:
    """Refuse an ``--update`` whose policies come from elsewhere than the stored runs' (every unit would run again)."""
    stored = store.config(config.name, config.scale)["settings"]
    for key in POLICY_SOURCES:
        if key in stored and stored[key] != config.settings.get(key):
            raise NeurohoverError(
                f"{config.name} ({config.scale}): the stored results fly {key} = {stored[key]!r}, this config {config.settings.get(key)!r}: "
                f"an --update would run every unit again; give --set {key}={json.dumps(stored[key])} as they were run, or --fresh to start over"
            )


def _matches_no_unit(config, pattern: str, units) -> NeurohoverError:
    """The error of an ``--only`` pattern that selects nothing, with what unit keys look like (of every stage)."""
    keys = list(dict.fromkeys([u.key for u in units] + run_keys(config) + list(robust_sources(config))))
    stages: dict[str, list[str]] = {}
    for key in keys:
        stages.setdefault(key.split("/")[0], []).append(key)
    examples = [k for ks in stages.values() for k in ks[:2]]
    across = "*" in pattern and any(key_matches(k, pattern.replace("*", "**")) for k in keys)  # fnmatch's '*' until T28-A11
    hint = " ('*' matches within one part of a key, not across '/': give '**' to cross parts)" if across else ""
    return NeurohoverError(f"{config.name}: --only {pattern!r} matches no unit{hint}; unit keys look like {', '.join(examples[:6])}")


def _checked_results(config: ExperimentConfig, store: Store, held: str | None) -> tuple[dict[str, dict], Plan | None]:
    """Key -> result of every stored unit of the experiment, each read back and checked (:func:`~.export.checked_units`,
    results' check): a damaged unit was counted as finished and never run again (fifth trial), a unit the config does
    not plan was counted as done (seventh trial), one of other params reused (eighth trial). Called before anything is
    written (``held``: the stored config hash, None: no config stored), so a refused run leaves the store as it was: a
    damaged config was rewritten, and units whose config was gone were taken in, by compete (T19-06). Also the plan the
    check made of them (None where it made none), the run's first round: a resumed experiment is planned once."""
    from .export import checked_experiment, refuse_orphans

    if held is None:  # units of it at a scale of no config row, this one's or another's (T21-15)
        refuse_orphans(store, config.name)
        return {}, None
    _, units, _, made = checked_experiment(store, config.name, config.scale)
    return {unit["key"]: unit["result"] for unit in units}, made


def _check_arguments(config, store, executor, progress, on_unit, only, fresh, update) -> tuple[str, ...]:
    """:func:`reproduce`'s arguments of the right kinds (a name or a path was an AttributeError; fourth trial); returns
    ``only`` as a tuple of patterns, a single pattern as one ('run/*' was taken as r, u, n, ...; twelfth trial, U3)."""
    if not isinstance(config, ExperimentConfig):
        raise NeurohoverError(f"config={config!r:.60} is not allowed: give load_config(NAME, SCALE)")
    if not isinstance(store, Store):
        raise NeurohoverError(f"store={store!r:.60} is not allowed: give a Store(PATH)")
    if not callable(getattr(executor, "run", None)):
        raise NeurohoverError(f"executor={executor!r:.60} is not allowed: give an executor, make_executor('local', jobs=N) or LocalExecutor(N)")
    check_paper_table(config.paper, f"experiment {config.name!r}")  # a config made without make_config: refused before the store is written
    check_own_name(config)  # a config of one's own named fig2 or its alias table3 was stored as the shipped one (eleventh trial, S8)
    check_flag(fresh, "fresh", "discard the stored results first")  # 'no' was True: every stored unit was deleted (T14-4)
    check_flag(update, "update", "keep the stored units a changed config plans alike")
    if progress not in (None, True, False):  # "no" drew the bar (twelfth trial, S7)
        raise NeurohoverError(f"progress={brief(progress)} is not allowed: give True, False or None (a bar on a terminal only)")
    if on_unit is not None and not callable(on_unit):  # 5 was a TypeError once the first unit had run (twelfth trial, T7)
        raise NeurohoverError(f"on_unit={brief(on_unit)} is not allowed: give a callable (unit key, result), or None")
    patterns = (only,) if isinstance(only, str) else only
    if not isinstance(patterns, Sequence) or not all(isinstance(p, str) for p in patterns):
        raise NeurohoverError(f"only={brief(only)} is not allowed: give a glob pattern of unit keys or a list of them, e.g. ['run/hybrid/*']")
    check_patterns_once(patterns, "only")
    return tuple(patterns)


def _refuse_unmatched(config: ExperimentConfig, store: Store, held: str | None, only: tuple[str, ...]) -> None:
    """Refuse an ``only`` pattern that matches no unit of a plan complete now (or of the test runs to come). A plan that
    waits for its own policy units is completed with stand-ins for them (:func:`_with_policy_stand_ins`): table4's
    'zzz*' was refused only after its generic policy was evolved and stored (sixteenth trial, T16-8)."""
    sources = source_results(config, store)
    results = store.results(config.name, config.scale) if held == config.hash else {}
    later = run_keys(config)  # a test-runs plan lists its runs once their policies are stored: their keys, now
    first = plan(config, results, sources) if later else _with_policy_stand_ins(config, results, sources)
    keys = [*(u.key for u in first.units), *later, *robust_sources(config)]  # robust units wait for their evolve units (T48-A02)
    unmatched = [pat for pat in only if not any(key_matches(k, pat) for k in keys)]
    if unmatched and (len(set(keys)) >= first.total or later):
        raise _matches_no_unit(config, unmatched[0], first.units)


def _with_policy_stand_ins(config: ExperimentConfig, results: dict[str, dict], sources: dict) -> Plan:
    """The plan of ``config`` (not of test runs: :func:`run_keys` has theirs) from ``results``; where it waits for its
    own ``policy/`` units (a model-learning experiment's generic policy), planned again with the baseline policy
    standing in for each champion: only the unit keys are wanted, and they do not depend on the policy."""
    first = plan(config, results, sources)
    waiting = {u.key for u in first.units if u.key.startswith("policy/") and u.key not in results}
    if len(first.units) == first.total or not waiting:
        return first
    from ..policies import baseline_policy
    from .units import policy_dict

    stand_in = {"champion": policy_dict(baseline_policy())}
    return plan(config, {**results, **dict.fromkeys(waiting, stand_in)}, sources)


def reproduce(
    config: ExperimentConfig,
    store: Store,
    executor,
    *,
    fresh: bool = False,
    update: bool = False,
    progress: bool | None = None,
    only: str | Sequence[str] = (),
    on_unit: Callable[[str, dict], None] | None = None,
) -> RunSummary:
    """Run every unfinished unit of ``config``; each finished unit is written to ``store`` at once.

    ``only`` restricts the run to the units whose keys match this glob pattern or one of these (for example
    ``run/hybrid/*/rep0``); the others stay unfinished, and a later call can run them.
    ``on_unit(key, result)`` is called for every unit finished in this call, once it is stored.
    ``fresh`` discards the experiment's stored results first; ``update`` takes a config that differs from
    the stored one, keeping the stored units it plans unchanged (:func:`unchanged_units`).
    Raises KeyboardInterrupt (after recording every finished unit) when interrupted, and
    NeurohoverError when another run is writing ``store`` (see :meth:`Store.lock`).
    """
    from ..progress import progress_bar

    only = _check_arguments(config, store, executor, progress, on_unit, only, fresh, update)
    store.lock()  # one writer per store: a second run would redo every unit the first has not finished
    check_restart(fresh, update, only)
    held = store.config_hash(config.name, config.scale)
    if only:  # refused before the store records anything
        _refuse_unmatched(config, store, held, only)
    _refuse_other_version_first(config, store, held, update)
    checked = None if fresh else _checked_results(config, store, held)  # before anything is written (T19-04, T19-06)
    if _take_changed_config(config, store, held, update):
        checked = None  # fewer units now: read again
    store.begin(config.name, config.scale, config.hash, config.to_dict(), fresh=fresh)
    results, made = checked if checked is not None else _checked_results(config, store, config.hash)  # read and planned once
    sources = source_results(config, store)
    first_round: Plan | None = made if made is not None else plan(config, results, sources)
    summary = RunSummary(config.name, config.scale, executor.name, executor.cores, units_before=len(results))
    session: int | None = store.start_session(config.name, config.scale, config.hash, executor.name, summary.cores, len(results))
    start = time.perf_counter()
    disable = None if progress is None else not progress
    bar = progress_bar(total=0, initial=len(results), desc=f"{config.name} ({config.scale})", unit="unit", disable=disable, dynamic_ncols=True)

    def on_result(unit, result, seconds, worker) -> None:
        if store.put(config.name, config.scale, config.hash, unit, result, seconds, worker, session):
            summary.units_run += 1
        results[unit.key] = result
        bar.update(1)
        if on_unit is not None:
            on_unit(unit.key, result)

    def on_error(unit, err) -> None:
        summary.failed.append((unit.key, _short(err)))
        bar.write(f"{config.name}: unit {unit.key} failed: {_short(err)}", file=sys.stderr)

    matched: set[str] = set()
    needed = prerequisites(config, only)
    try:
        while True:
            p = first_round if first_round is not None else plan(config, results, sources)
            first_round = None
            matched.update(pat for pat in only for u in p.units if key_matches(u.key, pat))
            summary.units_total = p.total
            bar.total = p.total
            bar.refresh()
            todo = [u for u in p.units if u.key not in results and selected(u.key, only, needed)]
            if not todo:
                break
            executor.run(todo, on_result, on_error)
            if summary.failed:
                break
        if summary.failed:
            summary.status = "failed"
        elif set(only) - matched:
            if held is None and store.forget_if_empty(
                config.name, config.scale
            ):  # registered by this call only: a refused run leaves the store as it was (third trial)
                session = None  # forgotten with its experiment: nothing to end
            raise _matches_no_unit(config, sorted(set(only) - matched)[0], p.units)
        elif only:
            summary.status = "finished" if len(results) >= summary.units_total else "selection finished"
        elif len(results) < summary.units_total:
            why = f": {p.waiting[0]} (run them first, into the same store)" if p.waiting else ""
            raise NeurohoverError(f"{config.name}: {summary.units_total - len(results)} units could not be planned{why}")
        else:
            summary.status = "finished"
    except KeyboardInterrupt:
        summary.status = "interrupted"
        raise
    except BaseException:
        summary.status = "failed"
        raise
    finally:
        summary.wall_seconds = time.perf_counter() - start
        bar.close()
        if session is not None:
            store.end_session(session, summary.status)
    return summary
