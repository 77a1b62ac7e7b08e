"""What a policy set's ``manifest.json`` holds (:mod:`neurohover.policysets`): its descriptive fields, its GHH tables of
crashes and mean returns on the training MDPs, Table 3's figures of them and the paper's rule for the safe policies, and
the checks :func:`~neurohover.policysets.load_policy_set` makes of them."""

from __future__ import annotations

from pathlib import Path

import numpy as np

from .errors import NeurohoverError, brief, finite_real, whole_number

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


# Every key a build writes into a manifest, of a GHH or an FGHH set, and the descriptive fields above.
_MANIFEST_KEYS = ("task", *_MANIFEST_FIELDS, "safe", "crashes_on_training_mdps", "mean_return_on_training_mdps", "table3")


def _check_manifest_fields(manifest: dict, path: Path) -> None:
    """Refuse a key no build writes and a descriptive field of the wrong kind by name (sixth trial: n_steps "x", a
    lineage 5 were shown as given)."""
    unknown = [key for key in manifest if key not in _MANIFEST_KEYS]
    if unknown:  # "bogus": 1, or a misspelt "saef", was ignored without a word (T19-13)
        shown = ", ".join(brief(key) for key in unknown[:5]) + (f" and {len(unknown) - 5} more" if len(unknown) > 5 else "")
        raise NeurohoverError(f"policy-set manifest {str(path)!r} has unknown keys {shown}: allowed {', '.join(_MANIFEST_KEYS)}")
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
