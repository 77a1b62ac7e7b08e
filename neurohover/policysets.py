"""Policy sets shipped with the package, and the command that builds them.

A policy set is a directory ``<task>/`` holding JSON policy files and a ``manifest.json``:

- GHH-08 and GHH-09: ``generic.json`` (evolved on the zero setting) and ``specialised_<i>.json``
  (evolved on training MDP i, i = 0..9). The manifest lists the two ``safe`` specialised policies
  for the hybrid agent, computed by the paper's rule: policies that never crashed on the other
  training MDPs (the two with the best mean return there when more qualify). It also holds the
  table of crashed episodes (``crashes_on_training_mdps``, of ``safety_episodes`` per cell) and of
  mean returns (``mean_return_on_training_mdps``) of every specialised policy on every training MDP
  that the rule was applied to, and Table 3's figures of them (``table3``): a manifest whose safe
  list (its order too: the hybrid agents fly the first first), counts or figures contradict its tables is refused (:mod:`neurohover.manifest`).

  **Lineage.** By default (``lineage="chain"``) every run is seeded from one *ancestor*, and the
  ancestor is itself a chain of runs from the baseline policy over the training MDPs in turn (run
  i is seeded from run i-1's champion); it is kept as ``ancestor.json``. This is what the authors'
  own policy files show: their ten GHH-08 specialised MLPs (and their GHH-09 ones) share gene
  values to four decimals, so they descend from one evolved ancestor, not from ten independent
  runs from the baseline. It matters: a run from the baseline on one MDP mostly cancels that MDP's
  wind through its biases and keeps the baseline's weak feedback gains, while a lineage that meets
  many winds raises the gains (position about 60x, velocity 20x, attitude 8x, as the authors'
  policies have), which is what Table 3's r_G measures (docs/reproduction, Figure 2 discussion).
  Every run uses the paper's operators and settings. ``lineage="independent"`` seeds every run from
  the baseline policy, as the paper's text reads.
- FGHH (sigma 0.3): ``generic_zero.json`` (evolved on the zero setting), ``generic_fixed.json``
  (fixed resampling over G) and ``generic_race.json`` (selection races over G). Its manifest holds
  none of the GHH keys above (it has no specialised policies), and a GHH manifest none of its
  ``sigma`` and ``fghh_budget``: each is refused by name.

The shipped sets live in ``neurohover/data/policies``; ``neurohover build-policies`` rebuilds them
with the project's own evolution (or writes a set elsewhere with ``--out``).

A set is loaded strictly (:func:`load_policy_set`): every policy must be an MLP (a build evolves nothing else), a
chain's set must hold its ``ancestor.json`` (an independent one must not), and a JSON file in the folder that no build
writes (``specialised_10.json`` beside a GHH set's ten) is refused by name rather than ignored. Files of other names
(a README, notes, a run's ``.history.csv``) are left alone: none can be taken for one of the set's policies. A file
whose genome is not the one its manifest's ``genome_sha256`` records (an edit by hand) is refused by name (T36-B05); a
manifest without digests (an older build) loads as before, unchecked. Every file's record of the run must be the one its
manifest says the build ran (name, target, seed, budget, n_steps, method and prototype 'baseline', where recorded; a
build that writes digests records the prototype in every file: T41-B06).
"""

from __future__ import annotations

import functools
import json
import os
import shutil
import time
from collections.abc import Callable
from dataclasses import dataclass, field, replace
from pathlib import Path

import numpy as np

from .errors import NeurohoverError, brief, finite_real, whole_number
from .evaluate import MAX_EPISODES_PER_CALL, evaluate
from .jsontext import JSONError, strict_json
from .manifest import (
    BUILT_PROTOTYPE,
    DIGESTS,
    LINEAGES,
    built_as,
    check_digests,
    check_ghh_manifest,
    check_kind_keys,
    check_manifest_fields,
    choose_safe,
    genome_digests,
    set_files,
    table3_summary,
)
from .paths import sole_writer, writing
from .policies import Policy, load_policy, save_policy, utf8_text
from .policystages import STAGES, build_state, finished_stage, run_seeds, stage_file
from .sim.constants import MAX_EPISODE_STEPS
from .tasks import TaskFamily, get_task_family

SHIPPED = Path(__file__).parent / "data" / "policies"
#: The network of every policy a build evolves (:func:`_evolve_one`), and the one a set's policy may have (T26-B12).
SET_TOPOLOGY = "mlp"
FGHH_GENERICS = ("zero", "fixed", "race")
#: How FGHH's generics over G estimate fitness (the zero-setting one flies one MDP, fixed:1): the
#: paper's k = 5 and delta = 0.2; build-policies and the experiments' planner both read it.
FGHH_GENERIC_RESAMPLING = {"fixed": "fixed:5", "race": "race:0.2"}


@dataclass(frozen=True)
class Role:
    """One policy of a task family's policy set: the recipe that ``build-policies`` and the experiments'
    planner both follow (:func:`policy_set_roles`).

    ``kind``: ``"generic"`` or ``"specialised"`` (GHH-08/09), or an FGHH generic's kind (``"zero"``,
    ``"fixed"``, ``"race"``); ``index``: a specialised policy's training MDP; ``target``: ``"zero"``
    (evolved on the zero setting), ``"train"`` (on training MDP ``index``) or ``"family"`` (over G);
    ``resampling``: how a run over G estimates fitness (``"fixed:1"`` on one MDP).
    """

    kind: str
    index: int
    target: str
    resampling: str = "fixed:1"


def policy_set_roles(family: TaskFamily | str) -> tuple[Role, ...]:
    """The policies of ``family``'s set (a TaskFamily or a task's name, as the other functions here take), in the order
    they are evolved (``build-policies`` seeds the k-th from the k-th child of its root seed)."""
    if isinstance(family, str):  # "ghh08" was an AttributeError (twelfth trial, T7)
        family = get_task_family(family)
    if not isinstance(family, TaskFamily):
        raise NeurohoverError(f"family={brief(family)} is not allowed: give a task's name or a TaskFamily (neurohover.get_task_family(name))")
    if family.generic_over_distribution:
        return (Role("zero", 0, "zero"), *(Role(kind, 0, "family", FGHH_GENERIC_RESAMPLING[kind]) for kind in ("fixed", "race")))
    return (Role("generic", 0, "zero"), *(Role("specialised", i, "train") for i in range(len(family.training_mdps()))))


@dataclass(frozen=True)
class PolicySet:
    """The policies of one task family that the agents use."""

    task: str
    directory: Path
    generic: Policy
    specialised: tuple[Policy, ...] = ()
    safe: tuple[int, ...] = ()
    generics: dict[str, Policy] = field(default_factory=dict)
    manifest: dict = field(default_factory=dict)


def policy_dir(task: str, directory: str | Path | None = None) -> Path:
    """The directory of ``task``'s policy set in ``directory`` (the shipped sets when None; '' refused by name). A task
    that is no task family's name is refused by name (None was pathlib's TypeError; eleventh trial)."""
    from .paths import checked_path

    name = get_task_family(task).name
    return (checked_path(directory, "policy directory", "directory") if directory is not None else SHIPPED) / name


# Every key a build writes into a set's policy file: the network, the evolution's record of the run, and its place.
_POLICY_KEYS = ("topology", "genome", "prototype", "method", "optimizer", "resampling", "target", "seed", "budget", "episodes",
                "evaluations", "generations", "champion_return", "n_steps", "stop_reason", "task", "name", "seconds")  # fmt: skip


def _load(path: Path, what: str, task: str, target: str, built: dict | None = None) -> Policy:
    """The policy ``what`` of ``task``'s set, from ``path``, evolved on ``target`` (an MDP's label, or ``TASK/G`` over G)
    by the run that ``built`` (:func:`~neurohover.manifest.built_as`) says its manifest's build made."""
    _refuse_not_a_file(path, what)
    if not path.is_file():
        raise NeurohoverError(
            f"policy set {str(path.parent)!r} is missing {what} ({path.name}); "
            f"build it with: neurohover build-policies --task {path.parent.name} --out {path.parent.parent}"
        )
    policy = load_policy(path)
    if policy.topology != SET_TOPOLOGY:  # T26-B12: an slp of 40 genes was flown as a specialised policy
        raise NeurohoverError(
            f"policy set {str(path.parent)!r}: {path.name} ({what}) has topology {brief(policy.topology)}, which is not allowed: a build "
            f"evolves every policy of a set as an {SET_TOPOLOGY} (allowed {SET_TOPOLOGY!r}); rebuild the set with: neurohover build-policies "
            f"--task {path.parent.name}"
        )
    unknown = sorted(set(policy.metadata) - set(_POLICY_KEYS))
    if unknown:  # "zzz_extra": 1 was flown without a word, where a manifest's unknown key is refused (T20-07)
        shown = ", ".join(brief(key) for key in unknown[:5]) + (f" and {len(unknown) - 5} more" if len(unknown) > 5 else "")
        raise NeurohoverError(f"policy set {str(path.parent)!r}: {path.name} ({what}) has unknown keys {shown}: allowed {', '.join(_POLICY_KEYS)}")
    _check_place(policy, path, what, {"task": task, "name": path.stem, "target": target})
    _check_place(policy, path, what, built or {}, "what its manifest.json says the build ran: a policy of another build copied in, or a hand edit?")
    return policy


def _refuse_not_a_file(path: Path, what: str) -> None:
    """Refuse a file of a set that is there but is no regular file, in the words of :mod:`neurohover.paths`: a directory
    or a symbolic-link loop as generic.json was called missing (sixteenth trial, T16-7)."""
    try:
        path.stat()
    except FileNotFoundError:
        return  # missing (or a link to nothing): the caller says so
    except OSError as err:  # ELOOP: too many levels of symbolic links
        raise NeurohoverError(f"policy set {str(path.parent)!r}: {path.name} ({what}) cannot be read ({(err.strerror or str(err)).lower()})") from None
    if path.is_dir():
        raise NeurohoverError(f"policy set {str(path.parent)!r}: {path.name} ({what}) is a directory; give a JSON file")
    if not path.is_file():
        raise NeurohoverError(f"policy set {str(path.parent)!r}: {path.name} ({what}) is not a regular file (a device, pipe or socket)")


def _check_place(policy: Policy, path: Path, what: str, place: dict, why: str = "a policy of another place copied in?") -> None:
    """Refuse a policy whose file records another place than the one it holds in its set (task, name, target: each where
    recorded): specialised_4.json copied over specialised_3.json, or another task's generic, was flown (ninth trial); or
    (``why`` says so) another run than its manifest's build made (T23-11)."""
    for key, want in place.items():
        have = policy.metadata.get(key)
        over_g = isinstance(want, str) and want.endswith("/G") and isinstance(have, str) and have.startswith(want)  # /G(sigma=0.3)
        if not (have is None or (have == want and type(have) is type(want)) or over_g):
            raise NeurohoverError(
                f"policy set {str(path.parent)!r}: {path.name} ({what}) records {key} {brief(have)}, not {want!r} ({why}): give the "
                f"policy evolved for it, or rebuild the set with: neurohover build-policies --task {path.parent.name}"
            )


def _refuse_strays(root: Path, family: TaskFamily) -> None:
    """Refuse a JSON name in a set's folder that no build writes (a specialised_10.json beside ten was ignored without a
    word; T26-B12). Other names are left alone (see the module doc): none is read as a policy of the set."""
    n = 0 if family.generic_over_distribution else len(family.training_mdps())
    own = ["manifest", *(f"generic_{k}" for k in FGHH_GENERICS)] if n == 0 else ["manifest", "generic", *(f"specialised_{i}" for i in range(n)), "ancestor"]
    strays = sorted(p.name for p in root.iterdir() if p.name.lower().endswith(".json") and (p.name[-5:] != ".json" or p.name[:-5] not in own))
    if strays:
        files = ", ".join(f"{name}.json" for name in own) if n == 0 else f"manifest.json, generic.json, specialised_0..{n - 1}.json, ancestor.json (a chain's)"
        raise NeurohoverError(
            f"policy set {str(root)!r}: {strays[0]} is no file of a {family.name} set{f' (nor {len(strays) - 1} more)' if len(strays) > 1 else ''}: a "
            f"build writes {files}; move it elsewhere, or rebuild the set with: neurohover build-policies --task {family.name}"
        )


def load_policy_set(task: str, directory: str | Path | None = None) -> PolicySet:
    """Load the policy set of ``task`` (the shipped one unless ``directory`` is given), strictly (see the module doc); an
    older build's manifest, which records no genome digests, loads as before."""
    family = get_task_family(task)
    root = policy_dir(family.name, directory)
    manifest_path = root / "manifest.json"
    if directory is not None and (root.parent.exists() and not root.parent.is_dir()):  # a file was told to hold a set (sixth trial)
        raise NeurohoverError(f"policy directory {str(directory)!r} is not a directory: give the directory that holds {family.name}/")
    _refuse_not_a_file(manifest_path, "its manifest")
    if not manifest_path.is_file():
        if directory is not None and root.parent.name == family.name and (root.parent / "manifest.json").is_file():  # T30-A05
            raise NeurohoverError(f"policy directory {str(directory)!r} is itself a {family.name} set: give its parent {str(root.parent.parent)!r}")
        raise NeurohoverError(
            f"no policy set for {family.name} in {str(root)!r} (manifest.json missing); build it with: neurohover build-policies "
            f"--task {family.name} --out {str(root.parent)!r}"
        )
    try:  # strictly: an integer of 5,000 digits, nesting 100,000 deep or "safe" given twice (the last kept; ninth trial)
        manifest = strict_json(utf8_text(manifest_path.read_bytes(), f"policy-set manifest {str(manifest_path)!r}", "a manifest"))  # T20-08
    except (OSError, JSONError) as err:
        raise NeurohoverError(f"policy-set manifest {str(manifest_path)!r} cannot be read as JSON: {err}") from None
    if not isinstance(manifest, dict):
        raise NeurohoverError(f"policy-set manifest {str(manifest_path)!r} must be a JSON object, got {type(manifest).__name__}")
    if manifest.get("task", family.name) != family.name:  # another task's set copied under this name: its policies fly the wrong task
        raise NeurohoverError(f"policy-set manifest {str(manifest_path)!r} is of task {manifest['task']!r}, not {family.name!r}")
    check_manifest_fields(manifest, manifest_path)
    check_kind_keys(manifest, manifest_path, family.generic_over_distribution)
    _refuse_strays(root, family)
    targets = {"zero": family.zero().label, "family": f"{family.name}/G"}  # what each role's run evolved on
    if family.has_sigma and manifest.get("sigma") is None:  # T46-B12: without one, sigma-0.3 generics flew at any sigma
        what = "its sigma null" if "sigma" in manifest else "no sigma"
        raise NeurohoverError(
            f"policy-set manifest {str(manifest_path)!r} has {what}: not allowed for a {family.name} set, whose generics were evolved for one"
            f" breadth (each file's target says {family.name}/G(sigma=...)): give the sigma build-policies wrote, a finite number"
        )
    if family.has_sigma and finite_real(manifest.get("sigma")):  # T25-07: G(sigma=0.7) in a set of sigma 0.3 was taken by its prefix
        targets["family"] = f"{family.name}/G(sigma={float(manifest['sigma']):g})"
    if family.generic_over_distribution:
        roles = {role.kind: role for role in policy_set_roles(family)}
        generics = {
            name: _load(
                root / f"generic_{name}.json",
                f"the {name} generic policy",
                family.name,
                targets[roles[name].target],
                built_as(manifest, roles[name], list(roles).index(name)),
            )
            for name in FGHH_GENERICS
        }
        check_digests(manifest, manifest_path, set_files(generics=generics), others=())  # a hand-edited genome (T36-B05)
        return PolicySet(family.name, root, generics["race"], generics=generics, manifest=manifest)
    if manifest.get("lineage") == "independent" and (root / "ancestor.json").exists():  # T25-14: a chain's set was shown as independent
        raise NeurohoverError(
            f"policy-set manifest {str(manifest_path)!r}: its lineage 'independent' is not allowed beside ancestor.json, which only a "
            "chain's build writes (its runs seeded from that ancestor): give lineage 'chain', or rebuild the set"
        )
    generic_role, *specialised_roles = policy_set_roles(family)
    generic = _load(root / "generic.json", "the generic policy", family.name, targets["zero"], built_as(manifest, generic_role, 0))
    train = family.training_mdps()
    if manifest.get("lineage") == "chain":  # T26-B12: a chain's set without its ancestor was taken
        _check_ancestor(root, manifest, manifest_path, family.name, train[-1].label, built_as(manifest, generic_role, 12 + len(train) - 1))
    specialised = tuple(
        _load(root / f"specialised_{i}.json", f"specialised policy {i}", family.name, train[i].label, built_as(manifest, specialised_roles[i], i + 1))
        for i in range(10)
    )
    ancestor = ("ancestor.json",) if manifest.get("lineage") == "chain" else ()  # the set's files, a digest of none refused (T37-B08)
    check_digests(manifest, manifest_path, set_files(generic, specialised), others=ancestor)  # two safe genomes x1000 were flown (T36-B05)
    safe = check_ghh_manifest(manifest, manifest_path, len(specialised), len(train))
    return PolicySet(family.name, root, generic, specialised, safe, manifest=manifest)


def _check_ancestor(root: Path, manifest: dict, manifest_path: Path, task: str, target: str, built: dict) -> None:
    """Refuse a chain's set without the ancestor its runs were seeded from, or with one its build did not write: run over
    the training MDPs in turn (its record the last stage's, ``target``, seeded from the build's ``12 + stages - 1``-th
    child seed, ``built``; :func:`_build`)."""
    path = root / "ancestor.json"
    _refuse_not_a_file(path, "the ancestor")
    if not path.is_file():
        raise NeurohoverError(
            f"policy-set manifest {str(manifest_path)!r}: its lineage 'chain' is not allowed without ancestor.json, which a chain's build "
            f"writes (the ancestor its runs were seeded from): restore it, or rebuild the set with: neurohover build-policies --task {task}"
        )
    check_digests(manifest, manifest_path, {"ancestor.json": _load(path, "the ancestor", task, target, built)})


def crash_matrix(policies: list[Policy], mdps: list, episodes: int, seed: int, n_steps: int = 6000) -> tuple[np.ndarray, np.ndarray]:
    """Crash counts and mean returns of every policy on every MDP: arrays (P, M)."""
    ev = evaluate(policies, mdps, episodes=episodes, seed=seed, n_steps=n_steps)
    return ev.crashed.sum(axis=2), ev.returns.mean(axis=2)


def _write_ghh_set(
    task: str,
    root: Path,
    manifest: dict,
    generic: Policy,
    specialised: list[Policy],
    crashes: np.ndarray,
    returns: np.ndarray,
    safety_episodes: int,
    seconds: float,
    say,
) -> PolicySet:
    """Choose a GHH set's safe policies from its crash and return matrix on the training MDPs, write its manifest
    (with Table 3's figures of the build) and say what was chosen."""
    safe = choose_safe(crashes, returns)
    manifest.update(
        {
            "safe": list(safe),
            "safety_episodes": safety_episodes,
            "crashes_on_training_mdps": crashes.tolist(),
            "mean_return_on_training_mdps": returns.round(2).tolist(),
            "table3": table3_summary(crashes, returns),
            "seconds": seconds,
        }
    )
    (root / "manifest.json").write_text(json.dumps(manifest, indent=1) + "\n", encoding="utf-8")
    t3 = manifest["table3"]
    say(f"{task}: safe specialised policies {safe}; Table 3 on the training MDPs: r = {t3['r']:.1f}, r_G = {t3['r_G']:.1f}")
    say(f"{task}: {t3['crashed_episodes']} crashed episodes of {crashes.size * safety_episodes}")
    return PolicySet(task, root, generic, tuple(specialised), safe, manifest=manifest)


def check_build(family, lineage: str | None, fghh_budget: int | None, optimizer: str, **sizes) -> tuple[str, int]:
    """:func:`build_policy_set`'s settings for ``family``, checked before any run (a bad FGHH budget was refused only
    after the first generic was written); the lineage and FGHH budget it runs with (None: the defaults, where they apply)."""
    from .evolution.config import MAX_BUDGET
    from .evolution.optimisers import optimiser_names
    from .evolution.seeding import check_seed

    fghh = family.generic_over_distribution  # FGHH: generics over G, no specialised policies
    if fghh and lineage is not None:  # would be ignored without a word (second trial)
        raise NeurohoverError(f"lineage applies to the GHH tasks' specialised policies; task {family.name!r} has none")
    if not fghh and fghh_budget is not None:
        raise NeurohoverError(
            f"fghh_budget (--fghh-budget) applies to task fghh (its generics over G), not to {family.name!r}: "
            "leave it out (budget, --budget on the command line, sizes every policy of this task)"
        )
    n_train = 0 if fghh else len(family.training_mdps())
    highest = {  # what one run or one call can hold (a larger size failed after the out directory was made: third trial)
        "budget": MAX_BUDGET,
        "fghh_budget": MAX_BUDGET,
        "n_steps": MAX_EPISODE_STEPS,
        "safety_episodes": MAX_EPISODES_PER_CALL // max(1, n_train * n_train),  # every specialised policy on every training MDP at once
    }
    for name, value in {**sizes, "fghh_budget": FGHH_POLICY_BUDGET if fghh_budget is None else fghh_budget}.items():
        if name == "seed":
            check_seed(value)
        elif not whole_number(value) or not 1 <= value <= highest[name]:  # np.timedelta64 passed as an integer (T17-1)
            raise NeurohoverError(f"{name}={brief(value)} is out of range: allowed a whole number in 1..{highest[name]:,}")
    lineage = "chain" if lineage is None else lineage
    if lineage not in LINEAGES:
        raise NeurohoverError(f"lineage {lineage!r} is not known: allowed {', '.join(LINEAGES)}")
    if optimizer not in optimiser_names():
        raise NeurohoverError(f"unknown optimizer {optimizer!r}: allowed {', '.join(optimiser_names())}")
    return lineage, FGHH_POLICY_BUDGET if fghh_budget is None else fghh_budget


def replaceable_set(task: str, out: str | Path | None) -> Path:
    """The directory ``out/<task>`` a build writes, refused where replacing it would lose what is not a policy set: a file
    of that name, or a directory without a set's manifest.json that holds anything (the build replaced it whole; third
    trial)."""
    from .paths import checked_path

    if out is not None:
        given = checked_path(out, "out", "directory")
        above = next((p for p in (given, *given.parents) if p.exists()), None)  # the nearest part of it that exists
        if above is not None and not above.is_dir():  # '/dev/full' or a file: a NotADirectoryError once made (fourth trial)
            kind = "a file" if above.is_file() else "not a directory"
            raise NeurohoverError(f"out {str(out)!r}: {str(above)!r} is {kind}; give a directory to write the {task} set into")
    final = policy_dir(task, None if out is None else checked_path(out, "out"))
    if final.exists() and not final.is_dir():
        raise NeurohoverError(f"{str(final)!r} is a file, not a policy set: give another out directory, or remove it")
    if final.is_dir() and not (final / "manifest.json").is_file() and any(final.iterdir()):
        raise NeurohoverError(f"{str(final)!r} holds files but no policy set (no manifest.json): give another out directory, or empty it")
    return final


def _evolve_one(
    target, name: str, child_seed: int, seed_policy: Policy | None = None, save: bool = True, *, family, root: Path, n_steps: int, optimizer: str, say, **kwargs
) -> Policy:
    """One run of a set's build from ``seed_policy`` (default: the baseline MLP), its champion saved as ``name``."""
    from .evolution import SteadyStateSettings
    from .evolution.evolve import evolve
    from .evolution.optimisers import NE
    from .policies import prototype

    stage = stage_file(root, str(child_seed))  # the run's seed names it: each run of a build has its own
    policy = finished_stage(stage, f"{family.name}/{name}", say)
    if policy is not None:  # finished before the build was stopped: the same run again would give the same champion
        if save:
            save_policy(policy, root / f"{name}.json", task=family.name, name=name, **{k: policy.metadata[k] for k in ("episodes", "seconds")})
        say(f"{family.name}/{name}: kept from the interrupted build")
        return policy
    t0 = time.perf_counter()
    race = str(kwargs.get("resampling", "")).startswith("race")
    kwargs["optimizer"] = NE if race else optimizer
    if "resampling" not in kwargs and kwargs["optimizer"] == NE:  # steady state: spend the whole budget (no plateau stop)
        kwargs["settings"] = SteadyStateSettings(plateau_threshold=kwargs["budget"])
    start_from = seed_policy if seed_policy is not None else prototype(SET_TOPOLOGY, BUILT_PROTOTYPE)  # what the set's loader checks
    result = evolve(target, topology=SET_TOPOLOGY, prototype=start_from, seed=child_seed, n_steps=n_steps, **kwargs)
    policy = result.champion
    meta = {"episodes": int(result.episodes), "seconds": round(time.perf_counter() - t0, 2)}
    if save:
        save_policy(policy, root / f"{name}.json", task=family.name, name=name, **meta)
    save_policy(policy, stage, task=family.name, name=name, **meta)
    say(f"{family.name}/{name}: champion {result.champion_return:.1f} after {result.episodes} episodes ({time.perf_counter() - t0:.0f} s)")
    return policy


def _version() -> str:
    """The installed neurohover's version (a build resumes only runs of the same code)."""
    import importlib.metadata

    try:
        return importlib.metadata.version("neurohover")
    except importlib.metadata.PackageNotFoundError:
        return "0+unknown"


#: Episodes per steady-state evolution of a policy set, and per FGHH generic's evolution over G (build_policy_set's
#: defaults; the command line's too).
POLICY_BUDGET, FGHH_POLICY_BUDGET = 40000, 200000


def build_policy_set(
    task: str,
    out: str | Path,
    *,
    budget: int = POLICY_BUDGET,
    fghh_budget: int | None = None,
    seed: int = 0,
    safety_episodes: int = 3,
    n_steps: int = 6000,
    lineage: str | None = None,
    optimizer: str = "ne",
    progress: Callable[[str], None] | None = None,
) -> PolicySet:
    """Evolve the policy set of ``task`` with the project's own evolution and write it.

    Parameters
    ----------
    task : str
        Task family name.
    out : path
        Directory to write ``<task>/`` into; :data:`SHIPPED` rebuilds the shipped sets (given by name only: a build
        with no directory overwrote them, even at a budget of 1; fifth trial).
    budget : int
        Episodes of each steady-state run (the whole budget is spent: no plateau stop).
    fghh_budget : int, optional
        FGHH only: episodes of each generic-policy run over G (default :data:`FGHH_POLICY_BUDGET`);
        refused for the GHH tasks.
    seed : int
        Root seed of every run.
    safety_episodes : int
        Episodes of each specialised policy on each training MDP for the safe-policy rule.
    n_steps : int
        Control steps per episode.
    lineage : {"chain", "independent"}, optional
        GHH-08/09 only: seed every run from an ancestor evolved over the training MDPs in turn
        (``"chain"``, the default; see the module doc), or from the baseline policy; refused for FGHH.
    optimizer : str
        ``ne`` (the paper's neuroevolution) or a population optimiser of
        :mod:`neurohover.evolution.optimisers` for every run on one MDP and FGHH's fixed-resampling
        generic; FGHH's race generic is always NE's (a selection race is the generational method's).
    progress : callable, optional
        Called with one line of text per finished run.
    """

    if not isinstance(out, (str, os.PathLike)):  # None wrote into the installed package's shipped set (sixth trial)
        raise NeurohoverError(f"out={out!r:.60} is not allowed: give the directory to write the set into (SHIPPED rebuilds the shipped sets)")
    family = get_task_family(task)
    lineage, fghh_budget = check_build(family, lineage, fghh_budget, optimizer, budget=budget, seed=seed, safety_episodes=safety_episodes, n_steps=n_steps)
    if progress is not None and not callable(progress):  # progress=3 was a TypeError after the first run (third trial)
        raise NeurohoverError(f"progress={progress!r:.60} is not allowed: give a callable taking one line of text, or None")
    final = replaceable_set(family.name, out)
    say = progress or (lambda _msg: None)
    # Built beside the set it replaces, which it replaces only once complete: an interrupted build (or a failed one)
    # leaves the old set, shipped or not, as it was. Each finished run is kept in root's stages/, and the same build
    # run again resumes from them (fourth trial: an interrupted build lost every finished stage).
    final.parent.mkdir(parents=True, exist_ok=True)  # where the lock is
    with sole_writer(final, "out"):  # a second build deleted the first's live .building as "interrupted" (T31-A02)
        root = final.with_name(final.name + ".building")
        build = {"task": family.name, "sigma": family.sigma, "budget": budget, "fghh_budget": fghh_budget, "seed": seed, "n_steps": n_steps,
                 "safety_episodes": safety_episodes, "lineage": lineage, "optimizer": optimizer, "version": _version()}  # fmt: skip
        if stage_file(root, "build").is_file() and build_state(root) == build:
            finished = sum(stage_file(root, str(s)).is_file() for s in set(run_seeds(seed)))  # its own runs' (a hand-edited seed's are not)
            say(f"{family.name}: resuming the interrupted build in {root} ({finished} runs finished)")
        else:
            if root.exists():
                say(f"{family.name}: {root} holds an interrupted build of other settings; it is started over")
            shutil.rmtree(root, ignore_errors=True)
            try:
                (root / STAGES).mkdir(parents=True)
                with writing(stage_file(root, "build"), "the build's state") as partial:  # a full disk left it empty (seventh trial)
                    partial.write_text(json.dumps(build) + "\n", encoding="utf-8")
            except BaseException:
                shutil.rmtree(root, ignore_errors=True)
                raise
        try:
            built = _build(family, root, budget, fghh_budget, seed, safety_episodes, n_steps, lineage, optimizer, say)
        except KeyboardInterrupt:  # stopped: the finished runs stay for the same build to resume
            say(f"{family.name}: stopped; the finished runs are kept in {root}: run the same build again to resume")
            raise
        except BaseException as err:  # failed: nothing half-built is left
            shutil.rmtree(root, ignore_errors=True)
            if isinstance(err, OSError):  # a full disk said only "No space left on device" (seventh trial)
                why = err.strerror or err
                raise NeurohoverError(f"out {str(final.parent)!r}: cannot write the {family.name} set ({why}); nothing half-built is left") from None
            raise
        shutil.rmtree(root / STAGES)
        old = final.with_name(final.name + ".replaced")
        shutil.rmtree(old, ignore_errors=True)
        if final.exists():
            final.rename(old)
        root.rename(final)
        shutil.rmtree(old, ignore_errors=True)
        return replace(built, directory=final)


def _build(family, root: Path, budget, fghh_budget, seed, safety_episodes, n_steps, lineage, optimizer, say) -> PolicySet:
    """:func:`build_policy_set`'s runs, written into ``root``."""
    from .evolution.optimisers import NE

    manifest: dict = {"task": family.name, "budget": budget, "seed": seed, "n_steps": n_steps, "built": time.strftime("%Y-%m-%d %H:%M:%S")}
    if optimizer != NE:
        manifest["optimizer"] = optimizer
    seeds = run_seeds(seed)
    roles = policy_set_roles(family)
    start = time.perf_counter()

    run = functools.partial(_evolve_one, family=family, root=root, n_steps=n_steps, optimizer=optimizer, say=say)

    if family.generic_over_distribution:
        manifest.update({"sigma": family.sigma, "fghh_budget": fghh_budget})
        generics = {}
        for k, role in enumerate(roles):
            how = {"budget": fghh_budget, "resampling": role.resampling} if role.target == "family" else {"budget": budget}
            generics[role.kind] = run(family if role.target == "family" else family.zero(), f"generic_{role.kind}", int(seeds[k]), **how)
        manifest.update({"seconds": round(time.perf_counter() - start, 1), DIGESTS: genome_digests(set_files(generics=generics))})
        (root / "manifest.json").write_text(json.dumps(manifest, indent=1) + "\n", encoding="utf-8")
        return PolicySet(family.name, root, generics["race"], generics=generics, manifest=manifest)

    train = family.training_mdps()
    manifest["lineage"] = lineage
    ancestor = None
    if lineage == "chain":  # the ancestor: runs over the training MDPs in turn, each from the last champion
        flown = 0  # the episodes its stages flew: budget * stages was fewer than the last stage's evaluations at a budget under 5
        for i, mdp in enumerate(train):
            ancestor = run(mdp, f"ancestor (stage {i + 1} of {len(train)}, training MDP {i})", int(seeds[12 + i]), ancestor, save=False, budget=budget)
            flown += ancestor.metadata["episodes"]
        assert ancestor is not None
        save_policy(ancestor, root / "ancestor.json", task=family.name, name="ancestor", episodes=flown)
    evolved = [
        run(family.zero(), "generic", int(seeds[k]), ancestor, budget=budget)
        if role.target == "zero"
        else run(train[role.index], f"specialised_{role.index}", int(seeds[k]), ancestor, budget=budget)
        for k, role in enumerate(roles)
    ]
    generic, specialised = evolved[0], evolved[1:]
    manifest[DIGESTS] = genome_digests(set_files(generic, specialised, ancestor))  # what load_policy_set checks (T36-B05)
    crashes, returns = crash_matrix(specialised, train, safety_episodes, seed=int(seeds[11]), n_steps=n_steps)
    seconds = round(time.perf_counter() - start, 1)
    return _write_ghh_set(family.name, root, manifest, generic, specialised, crashes, returns, safety_episodes, seconds, say)
