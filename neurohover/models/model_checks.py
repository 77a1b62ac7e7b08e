"""A model file checked against itself when it is read (:meth:`LearnedModel.from_dict <neurohover.models.model.LearnedModel.from_dict>`):
:func:`model_file_problem`, the one place of those checks (T23-10), and the entries they know (:data:`FILE_ENTRIES`).

Only entries a file holds are checked (older files lack some), so every model ``learn_lr``, ``learn_ec_meno`` and
``learn_ec_mer`` write loads."""

from __future__ import annotations

from ..errors import NeurohoverError, brief, finite_real, whole_number
from ..sim.constants import NOISE_NAMES
from .model import LearnedModel, check_vector

__all__ = ["FILE_ENTRIES", "model_file_problem"]


#: The entries of a model file (:meth:`LearnedModel.to_dict`); files before winds lack "wind" and "d_u".
FILE_ENTRIES = ("format", "method", "param_names", "params", "noise_names", "noise_std", "d_u", "wind", "seconds", "stats")
#: The stats entries only one method writes (LR's wind entries with its wind_model): another method's in a model file
#: contradict its method (T23-10). Entries no method writes are a caller's own (LearnedModel(stats=...)) and stay.
_METHOD_STATS = {
    "lr": (
        "estimator", "intercepts", "param_se", "discarded_intercepts", "residual_rms", "noise_std_innovations", "noise_std_rms", "noise", "d_u",
        "wind_model", "wind_fit_rounds", "uv_residual_rms", "uv_residual_rms_wind_blind",
    ),
    "ec-meno": ("scaling", "one_step_error", "prototype_one_step_error", "least_squares_one_step_error", "excess", "gene_scale"),
    "ec-mer": (
        "episode_seed", "episodes", "n_steps", "true_return", "predicted_return", "return_error", "prototype_predicted_return",
        "prototype_return_error",
    ),
}  # fmt: skip
#: Stats entries of numbers >= 0 and how many: per parameter or per axis (EC-MER's noise_std_stationary is one row of 6).
_STATS_VECTORS = {"param_se": 11, "gene_scale": 11, "residual_rms": 6, "noise_std_stationary": 6, "noise_std_innovations": 6, "noise_std_rms": 6}


def _its(field: str, value: object, allowed: str) -> str:
    """The house message of a model file's entry ``field`` whose ``value`` is not allowed."""
    return f"its {field} {brief(value)} is not allowed: {allowed}"


def model_file_problem(d: dict, model: LearnedModel) -> str:
    """What in model file ``d`` (read as ``model``) does not fit together, '' when all does: an entry no model file has,
    noise named in another order, stats another method writes or of values no fit makes (estimator 'zz', -1
    transitions, 99999 episodes of 6000 transitions, 3 standard errors of 11 parameters), or an LR fit's intercepts,
    discarded intercepts, D_u and wind that contradict each other. Each was loaded as it was (T23-10); only entries a
    file holds are checked (older files lack some), so every model learn_lr, learn_ec_meno and learn_ec_mer write loads."""
    unknown = sorted(set(d) - set(FILE_ENTRIES), key=str)
    if unknown:
        return f"its entry {brief(unknown[0])} is not allowed: a model file has only {', '.join(FILE_ENTRIES)}"
    if "noise_names" in d and d["noise_names"] != list(NOISE_NAMES):
        return _its("noise_names", d["noise_names"], f"allowed {list(NOISE_NAMES)} (the order of noise_std)")
    stats, method = model.stats, model.method
    for other, keys in _METHOD_STATS.items():
        key = next((k for k in keys if k in stats and k not in _METHOD_STATS[method]), None) if other != method else None
        if key is not None:
            return _its("method", method, f"its stats hold {key}, which {other} alone writes (allowed {other}, or the stats a {method} fit writes)")
    return _stats_problem(stats) or (_lr_problem(model) if method == "lr" else _ec_problem(model))


def _stats_problem(stats: dict) -> str:
    """'' when a model's stats' counts and vectors are ones a fit writes, else what is wrong (T23-10)."""
    from .transitions import MIN_TRANSITIONS

    n = stats.get("n_transitions")
    if "n_transitions" in stats and not (whole_number(n) and n >= MIN_TRANSITIONS):
        return _its("stats.n_transitions", n, f"allowed an integer >= {MIN_TRANSITIONS} (the transitions a model is learned from)")
    if "n_episodes" in stats:
        top = n if whole_number(n) else None
        episodes = stats["n_episodes"]
        if not (whole_number(episodes) and 1 <= episodes <= (top or episodes)):
            return _its("stats.n_episodes", episodes, f"allowed an integer in 1..{top or 'n_transitions'} (each episode has a transition or more)")
    for key in ("budget", "evaluations", "episodes", "n_steps"):
        if stats.get(key) is not None and not (whole_number(stats[key]) and stats[key] >= 1):
            return _its(f"stats.{key}", stats[key], "allowed an integer >= 1" + (" or null (the plateau stop)" if key == "budget" else ""))
    for key, length in _STATS_VECTORS.items():
        if key in stats:
            try:
                check_vector(stats[key], length, f"stats.{key}", nonnegative=True)
            except NeurohoverError:
                return _its(f"stats.{key}", stats[key], f"allowed {length} finite numbers >= 0 (one per {'parameter' if length == 11 else 'axis'})")
    return ""


def _lr_problem(model: LearnedModel) -> str:
    """'' when an LR model's stats name its options and its intercepts, discarded intercepts, D_u and wind are what
    :func:`~neurohover.models.lr.learn_lr` makes of them; else what contradicts what (T23-10)."""
    from .lr import D_U_CHOICES, ESTIMATORS, INTERCEPTS, NOISE_ESTIMATES, _intercept
    from .wind import WIND_MODELS

    stats = model.stats
    for key, allowed in (("estimator", ESTIMATORS), ("intercepts", INTERCEPTS), ("noise", NOISE_ESTIMATES), ("d_u", D_U_CHOICES), ("wind_model", WIND_MODELS)):
        if key in stats and (not isinstance(stats[key], str) or stats[key] not in allowed):
            return _its(f"stats.{key}", stats[key], f"allowed {' or '.join(allowed)} (LR's {key} choices)")
    wind = stats.get("wind_model", model.wind.kind)
    if wind != model.wind.kind:
        return _its("wind", model.wind.kind, f"stats.wind_model is {wind!r}: allowed a {wind!r} wind")
    intercepts = stats.get("intercepts")
    if intercepts is None:  # nothing to hold the rest against
        return ""
    kept = intercepts == "uv" and stats.get("d_u", "keep") == "keep" and wind == "none"  # the u constant kept as D_u
    if model.d_u != 0.0 and not kept:
        why = f"intercepts {intercepts!r}" if intercepts != "uv" else ("a wind" if wind != "none" else "d_u 'discard'")
        return _its("d_u", model.d_u, f"allowed 0.0: its stats say {why}, which keeps no u constant")
    if intercepts == "none" and wind == "none" and model.params[2] != 0.0:
        return _its("params D_v", model.params[2], "allowed 0.0: its stats.intercepts 'none' fits no v constant (D_v)")
    discarded = stats.get("discarded_intercepts", {})
    if not (isinstance(discarded, dict) and all(k in NOISE_NAMES and finite_real(v) for k, v in discarded.items())):
        return _its("stats.discarded_intercepts", discarded, f"allowed a table of axes ({', '.join(NOISE_NAMES)}) to finite numbers")
    fitted = {name for axis, name in enumerate(NOISE_NAMES) if _intercept(axis, intercepts)} - {"v"}  # the v constant is D_v
    optional = {"u"} if intercepts == "uv" and "d_u" not in stats and wind == "none" else set()  # before d_u: "uv" discarded u
    expected = fitted - ({"u"} if kept or wind != "none" else set())
    if not expected - optional <= set(discarded) <= expected | optional:
        discards = ", ".join(sorted(expected)) or "none"
        return _its(
            "stats.discarded_intercepts", discarded, f"its intercepts {intercepts!r} (d_u {stats.get('d_u', 'keep')!r}, wind {wind!r}) discard {discards}"
        )
    return ""


def _ec_problem(model: LearnedModel) -> str:
    """'' when an EC-MENO or EC-MER model has the D_u and wind those methods leave out (they evolve neither; T23-10)."""
    if model.d_u != 0.0:
        return _its("d_u", model.d_u, f"allowed 0.0: {model.method} evolves no D_u")
    if model.wind.kind != "none":
        return _its("wind", model.wind.kind, f"allowed 'none': {model.method} fits no wind")
    return ""
