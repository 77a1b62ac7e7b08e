"""What ``--set`` may change in a shipped experiment (:func:`~.config.load_config` calls :func:`check_shipped_overrides`).

A shipped experiment's report judges its runs against the paper's claims, t tests and numbers (its ``[paper]`` table,
keyed by the names of its groups, variants, methods, fits and conditions). Those are claims about the experiment's
conditions: its task, sigma, sensors, drift, target MDPs, and what each named group, variant, fit or condition is.
An override may change how much is run (:data:`SCALE_LIKE`: the settings a shipped config lets differ between its
scales, and a named entry's :data:`ENTRY_SCALE_LIKE` sizes), where the policies come from (:data:`POLICY_LIKE`) and the
seeds; anything else changed would be judged against claims about other conditions under the shipped experiment's
name and title (T29-A02: ``reproduce fig7 --set task="ghh09"`` was reported as Figure 7's GHH-08 runs, "reversed").
Such a run needs a config of one's own (a copy of the shipped config under a new name).
"""

from __future__ import annotations

from typing import Any

from ..errors import NeurohoverError, brief

#: Settings that say how much is run: those some shipped config gives other values at its two scales, and the number
#: of episodes of its checks (the experiment's conditions stay the paper's).
SCALE_LIKE = frozenset(
    {
        "authors_generations", "budget", "champion_reevaluation", "ec_meno_budget", "episodes", "generic_budget", "generics_per_agent",
        "max_learning_episodes", "model_budget", "n_mdps", "n_steps", "policy_budget", "robustness_episodes", "runs", "validation_episodes",
        "history_points", "safety_episodes", "predict_episodes", "test_episodes",
    }
)  # fmt: skip
#: Settings that say where the policies come from (the paper's are one source of several), and the seeds.
POLICY_LIKE = frozenset({"policies", "generic", "generics_from", "generic_resampling", "generic_topology", "robustness_policies", "seed", "seeds_of"})
#: Which of the listed experiments' parts the paper may name (a subset of them is run: the rest is reported as not run).
SUBSETS = frozenset({"methods", "robustness_variants"})
#: The lists of named entries, each entry's name, and the settings of an entry that say how much of it is run.
ENTRIES = {"groups": "label", "variants": "key", "fits": "key", "conditions": "key"}
ENTRY_SCALE_LIKE = frozenset({"n_mdps", "runs_per_mdp", "data_episodes"})


def _changed(shipped: dict, given: dict) -> list[tuple[str, Any, Any, str]]:
    """(setting, the shipped value, the given one, its top-level key) of each setting the overrides changed that the paper's claims are about."""
    out = []
    for key in sorted(set(shipped) | set(given)):
        old, new = shipped.get(key), given.get(key)
        if old == new or key in SCALE_LIKE | POLICY_LIKE | SUBSETS:
            continue
        if key in ENTRIES:
            name = ENTRIES[key]
            before = {e[name]: e for e in old or []}
            for entry in new or []:
                was = before.get(entry[name])
                if was is None:  # an entry the paper names not (reported without a verdict)
                    continue
                for k in sorted(set(was) | set(entry)):
                    if k not in ENTRY_SCALE_LIKE and was.get(k) != entry.get(k):
                        out.append((f"the {k} of {key[:-1]} {entry[name]!r}", was.get(k), entry.get(k), key))
            continue
        out.append((key, old, new, key))
    return out


def check_shipped_overrides(name: str, path: str, shipped: dict, given: dict, where: str) -> None:
    """Refuse overrides of the shipped experiment ``name`` (its resolved settings ``shipped``; with the overrides:
    ``given``; its config file ``path``) that change a setting its paper comparison is conditioned on, naming the first
    and the way to run it."""
    changed = _changed(shipped, given)
    if not changed:
        return
    what, old, new, key = changed[0]
    raise NeurohoverError(
        f"{where}: --set changes {what} from {brief(old)} to {brief(new)}, which is not allowed for the shipped experiment {name!r}: its report "
        f"judges the runs against the paper's claims about {brief(old)} (overrides of a shipped experiment may change its scale, seed and "
        f'policy source only); for other conditions run a config of your own: copy {path} to my-{name}.toml, set name = "my-{name}" '
        f"and {key} there, drop or edit its [paper] table, and reproduce my-{name}.toml"
    )
