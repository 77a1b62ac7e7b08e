"""What a policy set's ``manifest.json`` holds (:mod:`neurohover.policysets`): its descriptive fields, its GHH tables of
crashes and mean returns on the training MDPs, Table 3's figures of them and the paper's rule for the safe policies, and
the checks :func:`~neurohover.policysets.load_policy_set` makes of them; and the check of a policy file's record of the
run that evolved it (:func:`policy_record_problem`), which :func:`~neurohover.policies.load_policy` applies to every
policy file: each file kind checked against itself in one place."""

from __future__ import annotations

import math
import re
from pathlib import Path
from typing import Any

import numpy as np

from .errors import NeurohoverError, brief, finite_real, whole_number
from .policies import RECORD_CHECKS
from .sim.constants import MAX_EPISODE_STEPS, WORST_RETURN

#: How GHH-08/09 policy sets seed their runs (see the doc of :mod:`neurohover.policysets`).
LINEAGES = ("chain", "independent")


# What a manifest's descriptive fields may hold (they are shown and compared, never flown): name -> (kinds, what is allowed).
_COUNT = ((int,), "an integer >= 0")
_MANIFEST_FIELDS: dict[str, tuple[tuple[type, ...], str]] = {
    "sigma": ((int, float), "the breadth it was built for, a finite number"),
    "budget": _COUNT, "fghh_budget": _COUNT, "seed": _COUNT, "n_steps": _COUNT, "safety_episodes": _COUNT,
    "seconds": ((int, float), "a number of seconds >= 0"),
    "lineage": ((str,), f"one of {', '.join(LINEAGES)}"),
    "optimizer": ((str,), "an optimiser's name"), "built": ((str,), "a date as text"), "version": ((str,), "a version as text"),
}  # fmt: skip


def _manifest_sizes() -> dict[str, tuple[int, int, str]]:
    """The sizes a build takes (:func:`~neurohover.policysets.check_build`), as a manifest records them: name -> (lowest,
    highest, the range in words). A budget or n_steps of 0 was accepted as a count >= 0 (T23-11)."""
    from .evaluate import MAX_EPISODES_PER_CALL
    from .evolution.config import MAX_BUDGET
    from .sim.rng import MAX_SEED

    return {
        "budget": (1, MAX_BUDGET, f"1..{MAX_BUDGET:,} (episodes of each run)"),
        "fghh_budget": (1, MAX_BUDGET, f"1..{MAX_BUDGET:,} (episodes of each FGHH generic's run over G)"),
        "n_steps": (1, MAX_EPISODE_STEPS, f"1..{MAX_EPISODE_STEPS:,} (control steps per episode)"),
        "safety_episodes": (1, MAX_EPISODES_PER_CALL, f"1..{MAX_EPISODES_PER_CALL:,} (episodes of each specialised policy on each training MDP)"),
        "seed": (0, MAX_SEED, "0..2**63-1 (the build's root seed)"),
    }


# Every key a build writes into a manifest, of a GHH or an FGHH set, and the descriptive fields above.
_MANIFEST_KEYS = ("task", *_MANIFEST_FIELDS, "safe", "crashes_on_training_mdps", "mean_return_on_training_mdps", "table3")


def _check_manifest_fields(manifest: dict, path: Path) -> None:
    """Refuse a key no build writes and a descriptive field of the wrong kind by name (sixth trial: n_steps "x", a
    lineage 5 were shown as given)."""
    unknown = [key for key in manifest if key not in _MANIFEST_KEYS]
    if unknown:  # "bogus": 1, or a misspelt "saef", was ignored without a word (T19-13)
        shown = ", ".join(brief(key) for key in unknown[:5]) + (f" and {len(unknown) - 5} more" if len(unknown) > 5 else "")
        raise NeurohoverError(f"policy-set manifest {str(path)!r} has unknown keys {shown}: allowed {', '.join(_MANIFEST_KEYS)}")
    sizes = _manifest_sizes()
    for name, (kinds, allowed) in _MANIFEST_FIELDS.items():
        value = manifest.get(name)
        if value is None:
            continue
        bad = isinstance(value, bool) or not isinstance(value, kinds)
        if not bad and kinds != (str,):
            bad = not finite_real(value) or (name != "sigma" and value < 0)
        bad = bad or (name == "lineage" and value not in LINEAGES)
        if bad:
            raise NeurohoverError(f"policy-set manifest {str(path)!r}: {name}={value!r:.40} is not allowed: give {allowed}")
        if name == "built" and not _is_build_time(value):  # T25-14: 'yesterday' was shown as the build's time
            raise NeurohoverError(f"policy-set manifest {str(path)!r}: its built {brief(value)} is not allowed: give the build's time as YYYY-MM-DD HH:MM:SS")
        size = sizes.get(name)
        if size is not None and not size[0] <= value <= size[1]:  # T23-11: a budget or n_steps of 0 was taken as a count >= 0
            raise NeurohoverError(f"policy-set manifest {str(path)!r}: its {name} {brief(value)} is not allowed: allowed an integer in {size[2]}")


def _is_build_time(text: str) -> bool:
    """Whether ``text`` is a time as build_policy_set writes a manifest's ``built`` (``time.strftime("%Y-%m-%d %H:%M:%S")``)."""
    import time

    try:
        time.strptime(text, "%Y-%m-%d %H:%M:%S")
    except ValueError:
        return False
    return True


def _check_tables(manifest: dict, path: Path, rows: int, columns: int) -> None:
    """Refuse a GHH manifest's table that is not ``rows`` (specialised policies) x ``columns`` (training MDPs) of numbers,
    counts of crashes whole and >= 0: [[0]] for the shipped set's 10 x 10 was accepted without a word (T20-06)."""
    for name in ("crashes_on_training_mdps", "mean_return_on_training_mdps"):
        table, counts = manifest.get(name), name.startswith("crashes")
        if table is None:
            continue
        fits = isinstance(table, list) and len(table) == rows and all(isinstance(row, list) and len(row) == columns for row in table)
        fits = fits and all(finite_real(v) and (not counts or (whole_number(v) and v >= 0)) for row in table for v in row)
        if not fits:
            what = "whole numbers >= 0 (crashed episodes)" if counts else "finite numbers (mean returns)"
            raise NeurohoverError(
                f"policy-set manifest {str(path)!r}: {name}={brief(table)} is not allowed: give {rows} rows (one per specialised "
                f"policy) of {columns} {what}, one per training MDP"
            )


def table3_summary(crashes: np.ndarray, returns: np.ndarray) -> dict:
    """Table 3's robustness figures of specialised policy i trained on MDP i, from (P, M) arrays of
    crash counts and mean returns: r on its own MDP and r_G over all the MDPs, each averaged over
    the policies, and the crashed episodes in all."""
    return {"r": round(float(np.diag(returns).mean()), 2), "r_G": round(float(returns.mean()), 2), "crashed_episodes": int(crashes.sum())}


def choose_safe(crashes: np.ndarray, returns: np.ndarray, n: int = 2) -> tuple[int, ...]:
    """The paper's rule: specialised policies that never crashed on the *other* training MDPs;
    the ``n`` with the best mean return there. Fewer qualify: the fewest crashes, then return. ``crashes`` and
    ``returns``: (P, P) arrays of real numbers (policy i trained on MDP i), P >= 2; ``n`` in 1..P."""
    crashes, returns = _square(crashes, "crashes"), _square(returns, "returns")
    p = crashes.shape[0]
    if returns.shape != crashes.shape:
        raise NeurohoverError(f"returns of shape {returns.shape} is not allowed beside crashes of shape {crashes.shape}: give both (P, P)")
    if not whole_number(n) or not 1 <= n <= p:  # n=-1 chose P-1, n=0 none (twelfth trial, S8); np.timedelta64 a TypeError (T17-1)
        raise NeurohoverError(f"n={brief(n)} is out of range: allowed an integer in 1..{p} (the number of policies)")
    others = ~np.eye(p, dtype=bool)
    crash_others = np.array([crashes[i][others[i]].sum() for i in range(p)])
    return_others = np.array([returns[i][others[i]].mean() for i in range(p)])
    order = np.lexsort((-return_others, crash_others))  # fewest crashes first, then best return
    return tuple(int(i) for i in order[:n])


def _square(values: object, name: str) -> np.ndarray:
    """``values`` as a (P, P) float array, P >= 2, or a NeurohoverError naming its shape (a list was an AttributeError, a
    (3, 2) array an IndexError; twelfth trial, T7)."""
    try:
        array = np.asarray(values, dtype=float)
    except (TypeError, ValueError):
        array = None
    if array is None or array.ndim != 2 or array.shape[0] != array.shape[1] or array.shape[0] < 2:
        shape = f"of shape {array.shape}" if array is not None else brief(values)
        raise NeurohoverError(f"{name} {shape} is not allowed: give a (P, P) array of numbers, P >= 2 (policy i on training MDP j)")
    return array


#: The keys of a GHH-08/09 set's manifest only (its specialised policies' figures), and of an FGHH set's only (its
#: generics over G): a build writes each into its own kind's manifest, and the other kind's set has no use for them.
GHH_ONLY = ("lineage", "safe", "safety_episodes", "crashes_on_training_mdps", "mean_return_on_training_mdps", "table3")
FGHH_ONLY = ("sigma", "fghh_budget")

#: How far a manifest's figures may stray from those its tables give: its mean returns are rounded to 0.01 (T22-16).
_ROUNDING = 0.02


def check_kind_keys(manifest: dict, path: Path, fghh: bool) -> None:
    """Refuse the other kind of set's keys by name: an FGHH manifest's tables of crashes and returns were accepted and
    never read (T22-16)."""
    given = [key for key in (GHH_ONLY if fghh else FGHH_ONLY) if key in manifest]
    if given:
        what = "a GHH-08/09 set's specialised policies (an FGHH set has none)" if fghh else "an FGHH set's generics over G"
        raise NeurohoverError(f"policy-set manifest {str(path)!r} has {', '.join(given)}: they apply to {what}; remove them")


def check_ghh_manifest(manifest: dict, path: Path, n_policies: int, n_mdps: int) -> tuple[int, ...]:
    """The safe specialised policies a GHH set's manifest lists, its tables checked, and checked against each other: the
    safe list against the paper's rule (:func:`choose_safe`) on them, the crash counts against ``safety_episodes`` and
    ``table3`` against both (a safe policy that crashed 3 times on another training MDP was flown as safe; T22-16)."""
    where = f"policy-set manifest {str(path)!r}"
    safe = manifest.get("safe", [])
    if (
        not isinstance(safe, list)
        or not all(type(i) is int and 0 <= i < n_policies for i in safe)  # "x" was a TypeError (fifth trial)
        or len(set(safe)) != len(safe)  # [6, 6]: one policy flown as both safe ones (sixth trial)
    ):
        raise NeurohoverError(
            f"{where}: safe={safe!r:.60} is not allowed: give a list of the safe specialised policies' distinct indices, each in 0..{n_policies - 1}"
        )
    _check_tables(manifest, path, n_policies, n_mdps)
    crashes, returns = manifest.get("crashes_on_training_mdps"), manifest.get("mean_return_on_training_mdps")
    episodes = manifest.get("safety_episodes")
    if crashes is not None and episodes is not None:
        over = next(((i, j) for i, row in enumerate(crashes) for j, c in enumerate(row) if c > episodes), None)
        if over is not None:
            i, j = over
            raise NeurohoverError(
                f"{where}: crashes_on_training_mdps[{i}][{j}] = {crashes[i][j]} is more than safety_episodes = {episodes}, the episodes "
                f"each specialised policy flew on each training MDP"
            )
    if crashes is not None and safe:
        _check_safe(safe, np.array(crashes, dtype=float), None if returns is None else np.array(returns, dtype=float), where, path.parent.name)
    _check_table3(manifest.get("table3"), crashes, returns, where)
    return tuple(safe)


def _check_safe(safe: list[int], crashes: np.ndarray, returns: np.ndarray | None, where: str, task: str) -> None:
    """Refuse a safe policy the paper's rule would not choose from the manifest's own tables: one that crashed on the other
    training MDPs more often than a policy not listed, or (as rarely) returned less there, beyond rounding."""
    others = ~np.eye(crashes.shape[0], crashes.shape[1], dtype=bool)
    crash_others = np.where(others, crashes, 0).sum(axis=1)
    unlisted = [i for i in range(len(crashes)) if i not in safe]
    rule = (
        "safe policies are those that never crashed on the other training MDPs, the ones with the best mean return there "
        "when more qualify and the fewest crashes there when fewer do: give safe policies the tables agree with, or rebuild "
        f"the set (neurohover build-policies --task {task})"
    )
    for s in safe:
        better = [u for u in unlisted if crash_others[u] < crash_others[s]]
        if better:
            j = next(j for j in range(crashes.shape[1]) if j != s and crashes[s, j] > 0)
            raise NeurohoverError(
                f"{where}: safe lists specialised policy {s}, but crashes_on_training_mdps[{s}][{j}] = {int(crashes[s, j])}: it crashed "
                f"in {int(crashes[s, j])} episodes on training MDP {j} ({int(crash_others[s])} on the other training MDPs in all), while "
                f"policy {better[0]}, not listed, crashed in {int(crash_others[better[0]])} there; {rule}"
            )
        if returns is None:
            continue
        mean = np.array([returns[i][others[i]].mean() for i in range(len(returns))])
        better = [u for u in unlisted if crash_others[u] == crash_others[s] and mean[u] > mean[s] + _ROUNDING]
        if better:
            best = max(better, key=lambda u: mean[u])
            raise NeurohoverError(
                f"{where}: safe lists specialised policy {s}, whose mean return on the other training MDPs is {mean[s]:.2f}, but not "
                f"policy {best}, which crashed there as rarely ({int(crash_others[s])} episodes) and returned {mean[best]:.2f}; {rule}"
            )


def _check_table3(table3: object, crashes: list | None, returns: list | None, where: str) -> None:
    """Refuse a ``table3`` that is no table of Table 3's figures, or whose figures its manifest's tables do not give."""
    if table3 is None:
        return
    if (
        not isinstance(table3, dict)
        or set(table3) != {"r", "r_G", "crashed_episodes"}
        or not (finite_real(table3["r"]) and finite_real(table3["r_G"]) and _count(table3["crashed_episodes"]))
    ):
        raise NeurohoverError(
            f"{where}: table3={brief(table3)} is not allowed: give a table of r and r_G (finite numbers: mean returns on the own "
            "and on all training MDPs) and crashed_episodes (a whole number >= 0)"
        )
    given = table3_summary(np.array(crashes if crashes is not None else [[0]]), np.array(returns if returns is not None else [[0.0]]))
    for name, table in (("crashed_episodes", crashes), ("r", returns), ("r_G", returns)):
        if table is not None and abs(table3[name] - given[name]) > (0 if name == "crashed_episodes" else _ROUNDING):
            source = "crashes_on_training_mdps" if name == "crashed_episodes" else "mean_return_on_training_mdps"
            raise NeurohoverError(f"{where}: table3's {name} = {brief(table3[name])} is not what {source} gives ({given[name]})")


def _count(value: object) -> bool:
    """Whether ``value`` is a whole number >= 0 (a count of crashed episodes)."""
    return whole_number(value) and value >= 0


#: What a policy file's record of its run says the run was over: a task family (``ghh08/G``, ``fghh/G(sigma=0.3)``), not one MDP.
_FAMILY_TARGET = re.compile(r"[a-z0-9]+/G(\(sigma=[^()]*\))?")


def policy_record_problem(meta: dict) -> str:
    """What in a policy file's record of the run that evolved it contradicts itself ('' when nothing does): the keys
    :meth:`Run.result <neurohover.evolution.run.Run.result>` writes, each checked where present, against the evolution's
    own ranges and words and against each other, as :mod:`neurohover.experiments.result_checks` checks a stored test run.
    A budget of -5, n_steps of 0, more evaluations than episodes, a steady-state run over a family, a return of 5.0, a
    stop reason 'zzz' or a seed of -3 were all accepted after hand edits (T23-11); and the keys ``neurohover evolve``
    adds (:func:`_validation_problem`, :func:`_place_problem`, :func:`_run_settings_problem`): a validation_return of 5.0,
    a task other than its target's, mdp_params other than its label's MDP or settings of pop_size 0 (T24-02)."""
    from .evolution.config import MAX_BUDGET, parse_resampling
    from .evolution.fitness import ERROR_FLOOR
    from .evolution.optimisers import NE, OPTIMISERS
    from .evolution.restore import STOP_REASONS
    from .sim.rng import MAX_SEED

    counts = {"seed": (0, MAX_SEED, "in 0..2**63-1 (the run's root seed)"), "budget": (1, MAX_BUDGET, f"in 1..{MAX_BUDGET:,} (episodes), or null"),
              "n_steps": (1, MAX_EPISODE_STEPS, f"in 1..{MAX_EPISODE_STEPS:,} (control steps per episode)"),
              "episodes": (1, None, ">= 1 (episodes flown)"), "evaluations": (1, None, ">= 1 (candidates evaluated)"),
              "generations": (0, None, ">= 0 (generations bred)")}  # fmt: skip
    for name, (low, high, allowed) in counts.items():
        value = meta.get(name)
        if name not in meta or (value is None and name == "budget") or (whole_number(value) and low <= value <= (high or value)):
            continue
        return f"its {name} {brief(value)} is not allowed: allowed an integer {allowed}"
    for small, large, why in (("evaluations", "episodes", "each evaluation flies at least one episode"),
                              ("generations", "evaluations", "each generation evaluates at least one candidate")):  # fmt: skip
        if meta.get(small) is not None and meta.get(large) is not None and meta[small] > meta[large]:
            return f"its {small} {brief(meta[small])} is not allowed: more than its {large} {brief(meta[large])}, and {why}"
    own_stop = {"steady-state": "plateau", "generational": "generations", **{spec.label: spec.stop_reason for spec in OPTIMISERS.values()}}
    method, optimizer = meta.get("method"), meta.get("optimizer")
    if method is not None and (not isinstance(method, str) or method not in own_stop):
        return f"its method {brief(method)} is not allowed: allowed {', '.join(own_stop)}"
    names = {NE: ("steady-state", "generational"), **{name: (spec.label,) for name, spec in OPTIMISERS.items()}}
    if optimizer is not None and (not isinstance(optimizer, str) or optimizer not in names):
        return f"its optimizer {brief(optimizer)} is not allowed: allowed {', '.join(names)}"
    if method is not None and optimizer is not None and method not in names[optimizer]:
        return f"its method {brief(method)} is not allowed: optimizer {optimizer!r} evolves by {' or '.join(names[optimizer])}"
    problem = _run_words_problem(meta, own_stop, STOP_REASONS, parse_resampling, (1 + 1e-9) / math.log(ERROR_FLOOR))
    problem = problem or _validation_problem(meta) or _place_problem(meta) or _run_settings_problem(meta)  # T24-02: what evolve adds
    return problem or _counts_problem(meta, parse_resampling) or _fields_problem(meta)  # T25-04/05/06/12/14


def _run_words_problem(meta: dict, own_stop: dict, stop_reasons: tuple, parse_resampling, best_fitness: float) -> str:
    """:func:`policy_record_problem`'s checks of a record's target, resampling, champion_return and stop_reason against its
    method, budget and episodes ('' when they agree)."""
    method, target = meta.get("method"), meta.get("target")
    if target is not None and not isinstance(target, str):
        return f"its target {brief(target)} is not allowed: give the label of the MDP or task family it was evolved on"
    if method == "steady-state" and target is not None and _FAMILY_TARGET.fullmatch(target):
        why = "steady state evolves on one MDP, a task family needs the generational method"
        return f"its method 'steady-state' is not allowed beside its target {brief(target)}: {why}"
    if meta.get("resampling") is not None:
        try:
            selects = parse_resampling(meta["resampling"]).selects if isinstance(meta["resampling"], str) else None
        except ValueError:  # NeurohoverError among them
            selects = None
        if selects is None:
            return f"its resampling {brief(meta['resampling'])} is not allowed: allowed fixed:K, race:DELTA, lucb:DELTA or kl-lucb:DELTA"
        if selects and method is not None and method != "generational":
            return (
                f"its resampling {brief(meta['resampling'])} is not allowed beside its method {brief(method)}: a race or bandit needs the generational method"
            )
    ret = meta.get("champion_return")
    if ret is not None:
        fitness = method in (None, "generational")  # a generational run's champion is on its fitness scale, 1/ln(error) by default
        if not (finite_real(ret) and (-WORST_RETURN <= ret <= 0 or (fitness and 0 < ret <= best_fitness))):
            allowed = f"a return in [{-WORST_RETURN:.3g}, 0] (every reward is minus a sum of squares)"
            allowed += f", or a fitness 1/ln(error) in (0, {best_fitness:.8g}]" if fitness else f" for a {method} run (on the return scale)"
            return f"its champion_return {brief(ret)} is not allowed: allowed {allowed}"
    reason = meta.get("stop_reason")
    if reason is None:
        return ""
    if not isinstance(reason, str) or reason not in stop_reasons:
        return f"its stop_reason {brief(reason)} is not allowed: allowed {', '.join(stop_reasons)} (why the run stopped)"
    budget, episodes = meta.get("budget"), meta.get("episodes")
    if reason == "budget" and "budget" in meta and (budget is None or (episodes is not None and episodes < budget)):
        has = "it has no budget" if budget is None else f"its {episodes:,} episodes are fewer than its budget {budget:,}"
        return f"its stop_reason 'budget' is not allowed: {has} (a run stops by its budget once it has flown it)"
    if reason != "budget" and method is not None and reason != own_stop[method]:
        return f"its stop_reason {brief(reason)} is not allowed beside its method {method!r}: allowed budget or {own_stop[method]}"
    return ""


def _validation_problem(meta: dict) -> str:
    """A record's validation of its champion (evolve flies it on validation_episodes fresh episodes after the run and
    records their mean return and its standard deviation, :func:`~neurohover.evolution.evolve.validation_return`) against
    the ranges of such figures and each other ('' when they agree; T24-02)."""
    from .evaluate import MAX_EPISODES_PER_CALL

    episodes: Any = meta.get("validation_episodes")
    ret: Any = meta.get("validation_return")
    sd: Any = meta.get("validation_sd")
    if "validation_episodes" in meta and not (whole_number(episodes) and 1 <= episodes <= MAX_EPISODES_PER_CALL):
        allowed = f"an integer in 1..{MAX_EPISODES_PER_CALL:,} (episodes the champion was validated on)"
        return f"its validation_episodes {brief(episodes)} is not allowed: allowed {allowed}"
    if "validation_return" in meta and not (finite_real(ret) and -WORST_RETURN <= ret <= 0):
        return f"its validation_return {brief(ret)} is not allowed: allowed a mean return in [{-WORST_RETURN:.3g}, 0] (every reward is minus a sum of squares)"
    if "validation_sd" in meta and not (finite_real(sd) and 0 <= sd <= WORST_RETURN / 2):
        return f"its validation_sd {brief(sd)} is not allowed: allowed a standard deviation of returns in [0, {WORST_RETURN / 2:.3g}]"
    if episodes == 1 and sd is not None and sd != 0:
        return f"its validation_sd {brief(sd)} is not allowed beside its validation_episodes 1: one return has no spread (0)"
    seconds: Any = meta.get("seconds")
    if "seconds" in meta and not (finite_real(seconds) and seconds >= 0):
        return f"its seconds {brief(seconds)} is not allowed: allowed a number of seconds >= 0 (how long the run took)"
    return ""


def _place_problem(meta: dict) -> str:
    """A record's task, mdp (what evolve's --mdp or --wind/--params named), target (the label of the MDP or family the
    run evolved on) and mdp_params (that MDP) against each other ('' when they agree; T24-02). mdp_params is checked
    as flight data's MDPs are against their labels (:func:`neurohover.flightmeta.held_problem`); a run over a family has
    none (a champion no longer copies its seed policy's record, T25-12)."""
    task, mdp = meta.get("task"), meta.get("mdp")
    target: Any = meta.get("target")
    if "mdp" in meta and not isinstance(mdp, str):
        return f"its mdp {brief(mdp)} is not allowed: give what the run was evolved on as text (G, zero, train:N, ...)"
    named = target.partition("/")[0] if isinstance(target, str) and "/" in target else None
    if isinstance(task, str) and named is not None and named != task:
        return f"its task {brief(task)} is not allowed beside its target {brief(target)}: a run evolves on its task's MDPs, here {named}'s"
    over_family = mdp == "G" or (isinstance(target, str) and _FAMILY_TARGET.fullmatch(target) is not None)
    if isinstance(mdp, str) and named is not None:
        spec = target.partition("/")[2]
        agrees = (
            _FAMILY_TARGET.fullmatch(target) is not None if mdp == "G" else spec == mdp or (not _SPEC.fullmatch(mdp) and not _FAMILY_TARGET.fullmatch(target))
        )
        if not agrees:
            return f"its mdp {brief(mdp)} is not allowed beside its target {brief(target)}: the run was evolved on {target.partition('/')[2]!r}"
    if "mdp_params" not in meta:
        return ""
    if over_family:
        return f"its mdp_params {brief(meta['mdp_params'])} is not allowed beside its target {brief(target)}: a run over a family evolves on no one MDP"
    return _mdp_params_problem(meta["mdp_params"], task, target)


#: What ``neurohover evolve --mdp`` names as one of a family's MDPs (:meth:`TaskFamily.mdp`), labelled ``TASK/<it>``.
_SPEC = re.compile(r"zero|sample|(?:seeded-)?(?:train|test):[0-9]+")


def _mdp_params_problem(params: object, task: object, target: object) -> str:
    """A record's mdp_params (the MDP a run evolved on, as :meth:`MDP.to_dict` writes it) against its task and target,
    and against its own label as flight data's MDPs are checked (T24-02)."""
    from .flightmeta import held_problem
    from .tasks import MDP

    try:
        mdp = MDP.from_dict(params) if isinstance(params, dict) else None
    except NeurohoverError as err:
        return f"its mdp_params {brief(params)} is not allowed: {err}"
    if mdp is None:
        return f"its mdp_params {brief(params)} is not allowed: give the MDP the run was evolved on as a table (MDP.to_dict)"
    if isinstance(target, str) and mdp.label != target:
        return f"its mdp_params label {brief(mdp.label)} is not allowed beside its target {brief(target)}: the run was evolved on its target"
    if isinstance(task, str) and mdp.family != task:
        return f"its mdp_params family {brief(mdp.family)} is not allowed beside its task {brief(task)}: a run evolves on its task's MDPs"
    problem = held_problem(mdp)
    return f"its mdp_params ({brief(mdp.label)}) is not allowed: {problem}" if problem else ""


def _run_settings_problem(meta: dict) -> str:
    """A record's settings (the optimiser's, as the run used them), champion_fitness_scale and episode_steps against its
    method, optimizer, champion_return and n_steps ('' when they agree; T24-02): settings are checked as ``evolve`` checks
    them (:func:`~neurohover.evolution.config.make_settings`)."""
    from .evolution.config import make_settings
    from .evolution.fitness import FITNESS_SCALES
    from .evolution.optimisers import NE

    method, settings = meta.get("method"), meta.get("settings")
    optimizer = meta.get("optimizer", NE if method in ("steady-state", "generational") else None)
    steps: Any = meta.get("episode_steps")
    n_steps: Any = meta.get("n_steps")
    if "episode_steps" in meta and n_steps is not None and steps != n_steps:
        why = "evolve flies the run's and the validation's episodes at one length"
        return f"its n_steps {brief(n_steps)} is not allowed beside its episode_steps {brief(steps)}: {why}"
    if "settings" in meta and not isinstance(settings, dict):
        return f"its settings {brief(settings)} is not allowed: give the optimiser's settings as a table"
    if isinstance(settings, dict) and optimizer is not None and (optimizer != NE or method is not None):
        given = {k: v for k, v in settings.items() if not (optimizer == NE and k == "budget" and v is None)}  # NE's: the run counts its budget
        try:
            make_settings("steady-state" if method == "steady-state" else "generational", optimizer, given)
        except NeurohoverError as err:
            return f"its settings {brief(settings)} is not allowed: {err}"
    scale = meta.get("champion_fitness_scale")
    ret: Any = meta.get("champion_return")
    if "champion_fitness_scale" not in meta:
        return ""
    if not isinstance(scale, str) or scale not in FITNESS_SCALES:
        return f"its champion_fitness_scale {brief(scale)} is not allowed: allowed {', '.join(FITNESS_SCALES)} (the scale of its champion_return)"
    fitness = settings.get("fitness") if isinstance(settings, dict) and method == "generational" else None
    own = fitness if fitness is not None else ("return" if method not in (None, "generational") else None)
    if own is not None and scale != own:
        return f"its champion_fitness_scale {brief(scale)} is not allowed beside its method {brief(method)}: its run's champions are on the {own} scale"
    if finite_real(ret) and (scale == "return") != (ret <= 0):
        why = "a return is <= 0" if scale == "return" else "a fitness 1/ln(error) is > 0"
        return f"its champion_return {brief(ret)} is not allowed beside its champion_fitness_scale {brief(scale)}: {why}"
    return ""


#: Keys no policy file is written with that read as settings a policy file would hold: never read, they misled (T25-12).
_NOT_POLICY_KEYS = {
    "format": "policy files carry no format tag (a model file's or a summary's key?)",
    "obs_noise": "a policy file records the sensor its run saw as 'sensor' (a table of Sensor.to_dict)",
    "obs_delay": "a policy file records the sensor its run saw as 'sensor' (a table of Sensor.to_dict)",
}


def _counts_problem(meta: dict, parse_resampling) -> str:
    """A record's episodes and evaluations against its resampling fixed:K (each evaluation flies K episodes), and a
    steady-state stop by plateau against its plateau_threshold (T25-06): fixed:3 beside 50 episodes of 50 evaluations, or
    a plateau after 50 evaluations at a threshold of 1000, were accepted. A chain set's ancestor (name 'ancestor') records
    the episodes of all its stages and the evaluations of its last: its episodes may be more."""
    episodes, evaluations, resampling = meta.get("episodes"), meta.get("evaluations"), meta.get("resampling")
    if isinstance(resampling, str) and resampling.strip().lower().startswith("fixed:") and whole_number(episodes) and whole_number(evaluations):
        k = parse_resampling(resampling).k
        if episodes != k * evaluations and not (meta.get("name") == "ancestor" and episodes > k * evaluations):
            return (
                f"its episodes {brief(episodes)} is not allowed beside its evaluations {brief(evaluations)} and resampling {brief(resampling)}: "
                f"each evaluation flies {k} episode{'s' if k != 1 else ''}, {k * evaluations:,} in all"
            )
    settings = meta.get("settings")
    threshold = settings.get("plateau_threshold") if isinstance(settings, dict) else None
    if meta.get("stop_reason") == "plateau" and meta.get("method") == "steady-state" and whole_number(threshold) and whole_number(evaluations):
        if evaluations < threshold:
            return (
                f"its stop_reason 'plateau' is not allowed beside its evaluations {brief(evaluations)} and settings' plateau_threshold "
                f"{brief(threshold)}: steady state stops by plateau after plateau_threshold evaluations without a new champion"
            )
    return ""


def _fields_problem(meta: dict) -> str:
    """A record's sensor (read as :meth:`Sensor.from_dict <neurohover.tasks.sensor.Sensor.from_dict>` reads it; T25-04),
    sigma (checked by the FGHH family, against its task and its target's ``G(sigma=...)``; T25-05), prototype against its
    seed_policy (T25-06), seed_policy and history as what evolve writes (T25-14), and keys no policy file holds (T25-12)."""
    from .tasks import get_task_family
    from .tasks.fghh import FGHH
    from .tasks.sensor import Sensor

    bad = next((key for key in _NOT_POLICY_KEYS if key in meta), None)
    if bad is not None:
        return f"its {bad} {brief(meta[bad])} is not allowed: {_NOT_POLICY_KEYS[bad]}"
    if "sensor" in meta:
        try:
            Sensor.from_dict(meta["sensor"])
        except NeurohoverError as err:
            return f"its sensor {brief(meta['sensor'])} is not allowed: {err}"
    task, target = meta.get("task"), meta.get("target")
    if "sigma" in meta:
        sigma = meta["sigma"]
        try:
            FGHH(sigma=sigma)
        except NeurohoverError as err:
            return f"its sigma {brief(sigma)} is not allowed: {err}"
        try:
            family = get_task_family(task) if isinstance(task, str) else None
        except NeurohoverError:  # no task's name: left to the place checks
            family = None
        if family is not None and not family.has_sigma:  # a seeded champion no longer carries its seed's sigma (T25-12)
            return f"its sigma {brief(sigma)} is not allowed beside its task {brief(task)}: {task}'s MDPs have no breadth (sigma is FGHH's)"
        said = re.fullmatch(r"[a-z0-9]+/G\(sigma=([^()]*)\)", target) if isinstance(target, str) else None
        if said is not None and f"{float(sigma):g}" != said.group(1):
            return f"its sigma {brief(sigma)} is not allowed beside its target {brief(target)}: the run was evolved over G(sigma={said.group(1)})"
    seed_policy, proto = meta.get("seed_policy"), meta.get("prototype")
    if "seed_policy" in meta and (not isinstance(seed_policy, str) or seed_policy == ""):
        return f"its seed_policy {brief(seed_policy)} is not allowed: give what the run was seeded from as text (zero, baseline or a policy file)"
    if seed_policy in ("zero", "baseline") and "prototype" in meta and proto != seed_policy:
        return f"its prototype {brief(proto)} is not allowed beside its seed_policy {brief(seed_policy)}: a run seeded from {seed_policy} has its prototype"
    history = meta.get("history")
    if "history" in meta and not (isinstance(history, str) and history.endswith(".history.csv") and Path(history).name == history and "\\" not in history):
        return f"its history {brief(history)} is not allowed: give the name (no folder) of the run's history file beside it, ending .history.csv"
    return ""


RECORD_CHECKS["policy_record_problem"] = policy_record_problem  # every policy file load_policy reads is checked by it (T23-11)
