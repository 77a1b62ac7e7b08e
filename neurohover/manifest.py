"""What a policy set's ``manifest.json`` holds (:mod:`neurohover.policysets`): its descriptive fields, its GHH tables of
crashes and mean returns on the training MDPs, Table 3's figures of them and the paper's rule for the safe policies, and
the checks :func:`~neurohover.policysets.load_policy_set` makes of them. The check of a policy file's record of the run
that evolved it, :func:`policy_record_problem`, which :func:`~neurohover.policies.load_policy` applies to every policy
file, lives in :mod:`neurohover.policy_records` (re-exported here)."""

from __future__ import annotations

import hashlib
import re
from pathlib import Path
from typing import TYPE_CHECKING

import numpy as np

from .errors import NeurohoverError, brief, finite_real, whole_number
from .policy_records import policy_record_problem, seconds_problem  # noqa: F401  (policy_record_problem re-exported: once here)
from .sim.constants import MAX_EPISODE_STEPS

if TYPE_CHECKING:
    from .policies import Policy
    from .policysets import Role

#: How GHH-08/09 policy sets seed their runs (see the doc of :mod:`neurohover.policysets`).
LINEAGES = ("chain", "independent")
#: The manifest's record of each policy file's network: file name -> :func:`genome_digest` of the policy its build wrote
#: there. A build writes it; an older build's manifest holds none, and its files are loaded unchecked (T36-B05).
DIGESTS = "genome_sha256"
#: Where every policy of a set records its lineage started: a build starts each run from the baseline network (a chain's
#: from its ancestor, which did). A build that writes :data:`DIGESTS` records it in every file.
BUILT_PROTOTYPE = "baseline"


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
_MANIFEST_KEYS = ("task", *_MANIFEST_FIELDS, DIGESTS, "safe", "crashes_on_training_mdps", "mean_return_on_training_mdps", "table3")


def check_manifest_fields(manifest: dict, path: Path) -> None:
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
    optimizer = manifest.get("optimizer")
    if isinstance(optimizer, str) and not _optimiser_name(optimizer):  # '' or 'user:foo' was read beside NE's files (T54-B02)
        raise NeurohoverError(
            f"policy-set manifest {str(path)!r}: its optimizer {brief(optimizer)} is not allowed: give the name build-policies --optimizer "
            "took (ne, a shipped optimiser's, or a run-time one's: at most 64 letters, digits and ._+-)"
        )
    problem = seconds_problem(manifest)  # T26-B13: 1e30 was taken, where a checkpoint's seconds are at most 100 years
    if problem:
        raise NeurohoverError(f"policy-set manifest {str(path)!r}: {problem}")
    digests = manifest.get(DIGESTS, {})
    if not isinstance(digests, dict) or not all(isinstance(d, str) and re.fullmatch("[0-9a-f]{16}", d) for d in digests.values()):
        raise NeurohoverError(
            f"policy-set manifest {str(path)!r}: its {DIGESTS} {brief(digests)} is not allowed: give a table of file name -> 16 hex digits "
            "(each policy file's genome_digest, as build-policies writes it)"
        )


def _optimiser_name(name: str) -> bool:
    """Whether ``name`` is one build-policies --optimizer takes: NE, a shipped optimiser's, or a run-time one's."""
    from .evolution.optimisers import NE, SHIPPED, runtime_name

    return name == NE or name in SHIPPED or runtime_name(name)


def built_as(manifest: dict, role: Role, k: int) -> dict:
    """What the run of ``role`` recorded, as the set's ``manifest`` says its build ran it (where it says): its episode
    length, its budget and its method (a steady-state generic recording a generational run, or n_steps 999 in a set of
    20, was flown; T23-11); and its seed, the ``k``-th of the manifest's root seed's (a manifest seed of 7 beside policies
    of a build from 0 was shown; T25-14)."""
    from .evolution.optimisers import NE, OPTIMISERS, SHIPPED, recorded_names

    family = role.target == "family"
    optimizer = NE if role.kind == "race" else manifest.get("optimizer", NE)  # a race is NE's (build_policy_set)
    method = ("generational" if family else "steady-state") if optimizer == NE else None
    if optimizer != NE and isinstance(optimizer, str) and optimizer in OPTIMISERS:  # a user's, registered here, records user:LABEL (T40-B14)
        method = recorded_names(optimizer)[0]  # (one registered elsewhere, or user:NAME, is not known here: its record is load_policy's to check)
    # the optimiser's own record, as a run records it: a name no build ran ('pso', '') beside files of NE's runs was read (T54-B02)
    recorded = optimizer if optimizer == NE or optimizer in SHIPPED else f"user:{optimizer}"
    built = {"n_steps": manifest.get("n_steps"), "budget": manifest.get("fghh_budget" if family else "budget"), "method": method, "optimizer": recorded}
    built["prototype"] = BUILT_PROTOTYPE  # every run of a build (a chain's from its ancestor) starts from the baseline: 'zero' was taken (T41-B06)
    if whole_number(manifest.get("seed")) and 0 <= manifest["seed"] < 2**63:  # T25-14: as build_policy_set seeds role k
        built["seed"] = int(np.random.SeedSequence(manifest["seed"]).generate_state(32, dtype=np.uint32)[k])
    if family:  # T25-07: race:0.1 on the fixed generic was flown; the build runs each generic over G by its role's resampling
        built["resampling"] = role.resampling
    return {key: value for key, value in built.items() if value is not None}


def genome_digest(policy: Policy) -> str:
    """16 hex digits of SHA-256 over a policy's topology and genes (float64, little-endian): what a set's manifest records
    of each policy file (:data:`DIGESTS`). A gene -0.0 differs from 0.0, as the file's text does."""
    from .policies import Policy

    if not isinstance(policy, Policy):  # None was an AttributeError (T43-B15)
        raise NeurohoverError(f"policy={brief(policy)} is not allowed: give a Policy (neurohover.load_policy of a policy file)")
    genome = np.ascontiguousarray(policy.genome, dtype="<f8")
    return hashlib.sha256(policy.topology.encode() + b":" + genome.tobytes()).hexdigest()[:16]


def set_files(generic: Policy | None = None, specialised=(), ancestor: Policy | None = None, generics: dict | None = None) -> dict[str, Policy]:
    """A set's policies by the file name a build writes each to (those given)."""
    files = {} if generic is None else {"generic.json": generic}
    files.update({f"specialised_{i}.json": p for i, p in enumerate(specialised)})
    files.update({f"generic_{kind}.json": p for kind, p in (generics or {}).items()})
    return files if ancestor is None else {**files, "ancestor.json": ancestor}


def genome_digests(files: dict[str, Policy]) -> dict[str, str]:
    """The manifest's :data:`DIGESTS` of a set's policy ``files`` (:func:`set_files`)."""
    return {name: genome_digest(policy) for name, policy in files.items()}


def check_digests(manifest: dict, path: Path, files: dict[str, Policy], others: tuple[str, ...] | None = None) -> None:
    """Refuse a policy file whose genome is not the one its set's ``manifest`` (at ``path``) recorded: two specialised
    policies scaled by hand loaded with the manifest's safe list, crash table and champion returns of the ones its build
    flew, and the hybrid agent fell back on policies that now always crash (T36-B05). A manifest without
    :data:`DIGESTS` (a build before it was written) is not checked: its set loads as before. Given ``others``, the set's
    files are ``files`` and ``others`` (checked elsewhere), and an entry of another file is refused (T37-B08). A file of
    such a set that records no prototype is refused too (its build wrote :data:`BUILT_PROTOTYPE`; T41-B06)."""
    digests = manifest.get(DIGESTS)
    if digests is None:
        return
    if others is not None:
        check_digest_names(manifest, path, [*files, *others])
    bare = next((name for name, policy in files.items() if "prototype" not in policy.metadata), None)
    if bare is not None:  # a prototype deleted by hand was taken (T41-B06); a build before DIGESTS may not have written it
        raise NeurohoverError(
            f"policy set {str(path.parent)!r}: {bare} records no prototype, which its build wrote (allowed {BUILT_PROTOTYPE!r}: every run of a "
            f"build starts from the baseline): restore it, or rebuild the set with: neurohover build-policies --task {path.parent.name}"
        )
    for name, policy in files.items():
        want, have = digests.get(name), genome_digest(policy)
        if want != have:
            said = f"records no {DIGESTS} of {name}" if want is None else f"records {name}'s genome as {want}, and the file holds {have}"
            raise NeurohoverError(
                f"policy set {str(path.parent)!r}: its manifest.json {said} (a hand edit, or a policy of another build copied in?): its safe "
                f"list, tables and the file's record are of the genome its build wrote; restore the file, or rebuild the set with: neurohover "
                f"build-policies --task {path.parent.name} --out {str(path.parent.parent)!r}"
            )


def check_digest_names(manifest: dict, path: Path, names) -> None:
    """Refuse a :data:`DIGESTS` entry of a file the set (at ``path``'s directory) does not have, by name: the set's
    policy files are ``names``; an entry for specialised_10.json was taken without a word (T37-B08)."""
    digests = manifest.get(DIGESTS) or {}
    stray = next((name for name in digests if name not in names), None)
    if stray == "ancestor.json" and manifest.get("lineage") is None:  # it named the ancestor, not the lineage missing (T40-B07)
        raise NeurohoverError(
            f"policy-set manifest {str(path)!r} has no lineage, and its {DIGESTS} records ancestor.json, which only a chain's build writes: "
            f"give lineage 'chain' (allowed lineages: {', '.join(LINEAGES)}), as the build wrote it, or rebuild the set"
        )
    if stray is not None:
        raise NeurohoverError(
            f"policy-set manifest {str(path)!r}: its {DIGESTS} entry {brief(stray)} is not allowed: the set has no such policy file "
            f"(allowed one entry per file of the set: {', '.join(sorted(names))})"
        )


def _is_build_time(text: str) -> bool:
    """Whether ``text`` is a time as build_policy_set writes a manifest's ``built`` (``time.strftime("%Y-%m-%d %H:%M:%S")``):
    that form exactly, in ASCII digits with one space, and a real date and time (strptime took a newline, a tab or an NBSP
    for the space, Unicode digits and one-digit fields: T49-B01)."""
    import time

    if not re.fullmatch(r"[0-9]{4}-[0-9]{2}-[0-9]{2} [0-9]{2}:[0-9]{2}:[0-9]{2}", text):
        return False
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
    the policies, and the crashed episodes in all. ``crashes`` and ``returns``: (P, P) arrays of real numbers, P >= 1 (a
    (5, 3) beside a (5, 2) was summarised without a word, an empty one NaN; T43-B15)."""
    crashes, returns = _square(crashes, "crashes", least=1), _square(returns, "returns", least=1)
    if returns.shape != crashes.shape:
        raise NeurohoverError(f"returns of shape {returns.shape} is not allowed beside crashes of shape {crashes.shape}: give both (P, P)")
    return {"r": round(float(np.diag(returns).mean()), 2), "r_G": round(float(returns.mean()), 2), "crashed_episodes": int(crashes.sum())}


#: How many safe specialised policies a GHH set has: build-policies chooses (:func:`choose_safe`) and its manifest lists
#: that many, and the hybrid agents fly them.
SAFE_POLICIES = 2


def choose_safe(crashes: np.ndarray, returns: np.ndarray, n: int = SAFE_POLICIES) -> tuple[int, ...]:
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


def _square(values: object, name: str, least: int = 2) -> np.ndarray:
    """``values`` as a (P, P) float array, P >= ``least``, or a NeurohoverError naming its shape (a list was an AttributeError, a
    (3, 2) array an IndexError; twelfth trial, T7)."""
    try:
        array = np.asarray(values, dtype=float)
    except (TypeError, ValueError):
        array = None
    if array is None or array.ndim != 2 or array.shape[0] != array.shape[1] or array.shape[0] < least:
        shape = f"of shape {array.shape}" if array is not None else brief(values)
        raise NeurohoverError(f"{name} {shape} is not allowed: give a (P, P) array of numbers, P >= {least} (policy i on training MDP j)")
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
        or ("safe" in manifest and len(safe) != SAFE_POLICIES)  # [] and [6] were taken, where the tables choose 2 (T32-B12)
    ):
        raise NeurohoverError(
            f"{where}: safe={safe!r:.60} is not allowed: give a list of the {SAFE_POLICIES} safe specialised policies' distinct indices, "
            f"each in 0..{n_policies - 1} (build-policies lists the {SAFE_POLICIES} the paper's rule chooses; the hybrid agents fly them)"
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
    mean = None if returns is None else np.array([returns[i][others[i]].mean() for i in range(len(returns))])
    for s in safe:
        better = [u for u in unlisted if crash_others[u] < crash_others[s]]
        if better:
            j = next(j for j in range(crashes.shape[1]) if j != s and crashes[s, j] > 0)
            raise NeurohoverError(
                f"{where}: safe lists specialised policy {s}, but crashes_on_training_mdps[{s}][{j}] = {int(crashes[s, j])}: it crashed "
                f"in {int(crashes[s, j])} episodes on training MDP {j} ({int(crash_others[s])} on the other training MDPs in all), while "
                f"policy {better[0]}, not listed, crashed in {int(crash_others[better[0]])} there; {rule}"
            )
        if mean is None:
            continue
        better = [u for u in unlisted if crash_others[u] == crash_others[s] and mean[u] > mean[s] + _ROUNDING]
        if better:
            best = max(better, key=lambda u: mean[u])
            raise NeurohoverError(
                f"{where}: safe lists specialised policy {s}, whose mean return on the other training MDPs is {mean[s]:.2f}, but not "
                f"policy {best}, which crashed there as rarely ({int(crash_others[s])} episodes) and returned {mean[best]:.2f}; {rule}"
            )
    _check_safe_order(safe, crash_others, mean, where, task)


def _check_safe_order(safe: list[int], crash_others: np.ndarray, mean: np.ndarray | None, where: str, task: str) -> None:
    """Refuse safe policies listed in another order than the paper's rule (:func:`choose_safe`) gives on the manifest's
    tables: fewest crashes on the other training MDPs first, then the best mean return there. The hybrid agents fly
    safe:0 first, so [2, 6] for the build's [6, 2] changed every run's returns without a word (T37-B07). What the tables
    cannot order is taken in either order: mean returns within their rounding (0.01; :data:`_ROUNDING`), and any two
    of as many crashes in a manifest without mean_return_on_training_mdps (an older manifest loads as before)."""

    def after(a: int, b: int) -> bool:  # the rule puts b before a, whatever the rounding
        if crash_others[b] != crash_others[a]:
            return bool(crash_others[b] < crash_others[a])
        return mean is not None and bool(mean[b] > mean[a] + _ROUNDING)

    wrong = next(((a, b) for k, a in enumerate(safe) for b in safe[k + 1 :] if after(a, b)), None)
    if wrong is None:
        return
    a, b = wrong
    ordered = sorted(safe, key=lambda i: (crash_others[i], 0.0 if mean is None else -mean[i]))
    how = f"{int(crash_others[b])} crashes there to {int(crash_others[a])}"
    if crash_others[a] == crash_others[b] and mean is not None:
        how = f"as few crashes there ({int(crash_others[a])}) and a mean return of {mean[b]:.2f} to {mean[a]:.2f}"
    raise NeurohoverError(
        f"{where}: safe={safe!r} is not allowed: the paper's rule on its tables gives {ordered} (policy {b}, with {how} on the "
        f"other training MDPs, comes before policy {a}; the hybrid agents fly safe:0 first): give safe {ordered}, or rebuild the "
        f"set (neurohover build-policies --task {task})"
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
    shape = np.shape(next((t for t in (crashes, returns) if t is not None), [[0]]))  # a table left out: zeros of the other's shape
    given = table3_summary(np.zeros(shape) if crashes is None else np.array(crashes), np.zeros(shape) if returns is None else np.array(returns))
    for name, table in (("crashed_episodes", crashes), ("r", returns), ("r_G", returns)):
        if table is not None and abs(table3[name] - given[name]) > (0 if name == "crashed_episodes" else _ROUNDING):
            source = "crashes_on_training_mdps" if name == "crashed_episodes" else "mean_return_on_training_mdps"
            raise NeurohoverError(f"{where}: table3's {name} = {brief(table3[name])} is not what {source} gives ({given[name]})")


def _count(value: object) -> bool:
    """Whether ``value`` is a whole number >= 0 (a count of crashed episodes)."""
    return whole_number(value) and value >= 0
