"""A model file checked against itself when it is read (:meth:`LearnedModel.from_dict <neurohover.models.model.LearnedModel.from_dict>`):
:func:`model_file_problem`, the one place of those checks (T23-10), and the entries they know (:data:`FILE_ENTRIES`).

Only entries a file holds are checked (older files lack some), so every model ``learn_lr``, ``learn_ec_meno`` and
``learn_ec_mer`` write loads.

Internal: neurohover's plumbing, called with values neurohover has checked: its helpers trust their callers and do not
check their own arguments (README, Python API, What is public).
"""

from __future__ import annotations

import math

from ..errors import NeurohoverError, brief, finite_real, whole_number
from ..sim.constants import DEFAULT_PARAMS, MAX_EPISODE_STEPS, NOISE_NAMES, PARAM_NAMES, WORST_RETURN
from ..sim.rng import MAX_SEED
from .model import LearnedModel, check_vector

__all__ = ["FILE_ENTRIES", "model_entry_problem", "model_file_problem"]


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
#: Every stats entry a fit of each method writes (learn_lr with a wind's entries, learn_ec_meno, learn_ec_mer): stats
#: holding one are a fit's and hold no other (stats.zzz was taken where a top-level zzz was refused; T24-08). A caller's
#: own stats (LearnedModel(stats=...)) hold none of them and stay as they are.
_FIT_STATS = {
    "lr": (
        "estimator", "intercepts", "n_transitions", "n_episodes", "param_se", "discarded_intercepts", "residual_rms", "noise_std_stationary",
        "noise_std_innovations", "noise_std_rms", "noise", "d_u", "wind_model", "wind_fit_rounds", "uv_residual_rms", "uv_residual_rms_wind_blind",
    ),
    "ec-meno": (
        "budget", "scaling", "evaluations", "seed", "n_transitions", "n_episodes", "one_step_error", "prototype_one_step_error",
        "least_squares_one_step_error", "excess", "gene_scale", "noise_std_stationary", "history",
    ),
    "ec-mer": (
        "budget", "evaluations", "seed", "episode_seed", "episodes", "n_steps", "true_return", "predicted_return", "return_error",
        "prototype_predicted_return", "prototype_return_error", "noise_std_stationary", "history",
    ),
}  # fmt: skip
#: LR's stats of a fitted wind alone (learn_lr with wind_model 'constant' or 'sinusoid'; T24-08).
_WIND_STATS = ("wind_fit_rounds", "uv_residual_rms", "uv_residual_rms_wind_blind")
#: Stats entries of returns: an episode's, in [-WORST_RETURN, 0] (every reward is minus a sum of squares; T24-08).
_STATS_RETURNS = ("true_return", "predicted_return", "prototype_predicted_return")
#: Stats entries of errors and rms: finite numbers >= 0 (T24-08); the least-squares error may be null (no unique minimum).
_STATS_ERRORS = (
    "return_error", "prototype_return_error", "one_step_error", "prototype_one_step_error", "least_squares_one_step_error", "uv_residual_rms",
    "uv_residual_rms_wind_blind",
)  # fmt: skip


def _its(field: str, value: object, allowed: str) -> str:
    """The house message of a model file's entry ``field`` whose ``value`` is not allowed."""
    return f"its {field} {brief(value)} is not allowed: {allowed}"


def model_entry_problem(d: dict) -> str:
    """What entry of model file ``d`` is of a kind no model file holds, '' when none is: param_names other than the list
    of the parameter names (None was a TypeError), a d_u or seconds not a number (text, a bool and null were converted
    or Python's message) or seconds past policy files' bound, stats not a JSON object (a list of pairs became a dict).
    Checked before the model is made of them (T27-B01, T27-B02, T27-B11); only entries the file holds."""
    from ..policy_records import seconds_problem  # the one check of a file's seconds (policy files', T26-B13)

    for key, length in (("params", len(PARAM_NAMES)), ("noise_std", len(NOISE_NAMES))):  # nested lists were read flat (T47-B09)
        if isinstance(d[key], list) and any(isinstance(x, (list, dict)) for x in d[key]):
            return _its(key, d[key], f"allowed a flat list of {length} numbers (a list inside it is not read as numbers)")
    names = d.get("param_names", list(PARAM_NAMES))
    if not (isinstance(names, list) and names == list(PARAM_NAMES)):
        return _its("param_names", names, f"allowed the list {list(PARAM_NAMES)} (the names of params, in order)")
    if "d_u" in d and not finite_real(d["d_u"]):
        return _its("d_u", d["d_u"], "allowed a finite number (D_u, the constant u acceleration; 0.0 where none is fitted)")
    if "stats" in d and not isinstance(d["stats"], dict):
        return _its("stats", d["stats"], "allowed a JSON object (the fit's statistics by name)")
    newer = [why for why, has in (("its stats say d_u 'keep'", d.get("stats", {}).get("d_u") == "keep"), ("it has a wind entry", "wind" in d)) if has]
    if "d_u" not in d and newer:  # read as a file from before D_u: loaded with D_u 0.0, flown without its u acceleration (T56-B05)
        return (
            f"it has no d_u entry, but {' and '.join(newer)}, which files hold only since D_u is recorded: give d_u, a finite number "
            "(D_u, the constant u acceleration; 0.0 where none is fitted)"
        )
    return (_wind_problem(d["wind"]) if "wind" in d else "") or seconds_problem(d)


#: A model file's wind table and each of its axes, as :meth:`LearnedModel.to_dict` writes them (every file since winds).
_WIND_ENTRIES = ("kind", "x", "y")
_AXIS_ENTRIES = ("amplitude", "omega", "phase", "offset")


def _wind_problem(wind: object) -> str:
    """What in a model file's wind table is not what a model file holds, '' when nothing is: an entry beside kind, x
    and y, a missing x or y (read as no wind), or an axis without all of amplitude, omega, phase and offset (an entry
    'X' was dropped without a word and a missing axis read as zeros, where every other table is strict; T37-B05).
    WindModel.from_dict, given a table in Python, still takes an axis's missing entries as 0."""
    allowed = f"a model file's wind holds {', '.join(_WIND_ENTRIES)} (x and y each {', '.join(_AXIS_ENTRIES)})"
    if not isinstance(wind, dict):
        return _its("wind", wind, f"allowed a JSON object: {allowed}")
    stranger = next((k for k in wind if k not in _WIND_ENTRIES), None)
    if stranger is not None:
        return f"its wind entry {brief(stranger)} is not allowed: {allowed}"
    missing = [k for k in _WIND_ENTRIES if k not in wind]
    if missing:
        return f"its wind {brief(wind)} is not allowed: it lacks {', '.join(missing)}; {allowed}"
    for name in ("x", "y"):
        axis = wind[name]
        if not isinstance(axis, dict) or sorted(axis, key=str) != sorted(_AXIS_ENTRIES):
            return _its(f"wind.{name}", axis, f"allowed a JSON object of exactly {', '.join(_AXIS_ENTRIES)} (numbers)")
    return ""


def model_file_problem(d: dict, model: LearnedModel) -> str:
    """What in model file ``d`` (read as ``model``) does not fit together, '' when all does: an entry no model file has,
    noise named in another order, stats another method writes or of values no fit makes (estimator 'zz', -1
    transitions, 99999 episodes of 6000 transitions, 3 standard errors of 11 parameters), or an LR fit's intercepts,
    discarded intercepts, D_u and wind that contradict each other. Each was loaded as it was (T23-10); so were an
    entry beside a fit's stats that no fit writes, seeds, returns and errors out of range, and EC errors, returns and
    champion histories that contradict each other (T24-08). Only entries a file holds are checked (older files lack
    some), so every model learn_lr, learn_ec_meno and learn_ec_mer write loads."""
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
    fit = _FIT_STATS[method]
    stranger = next((k for k in stats if k not in fit), None) if any(k in fit for k in stats) else None
    if stranger is not None:  # T24-08: an unknown stats entry beside a fit's was taken
        return f"its stats entry {brief(stranger)} is not allowed: the stats of a {method} fit hold only {', '.join(fit)}"
    return _stats_problem(stats, method) or (_lr_problem(model) if method == "lr" else _ec_problem(model))


def _stats_problem(stats: dict, method: str) -> str:
    """'' when a model's stats' counts, seeds, returns, errors and vectors are ones a ``method`` fit writes, else what is
    wrong (T23-10; the seeds, returns and errors, and the counts' upper bounds, T24-08)."""
    from .ec import MAX_EC_MER_EPISODES
    from .transitions import MIN_TRANSITIONS

    n = stats.get("n_transitions")
    if "n_transitions" in stats and not (whole_number(n) and n >= MIN_TRANSITIONS):
        return _its("stats.n_transitions", n, f"allowed an integer >= {MIN_TRANSITIONS} (the transitions a model is learned from)")
    if "n_episodes" in stats:
        top = n if whole_number(n) else None
        episodes = stats["n_episodes"]
        if not (whole_number(episodes) and 1 <= episodes <= (top or episodes)):
            return _its("stats.n_episodes", episodes, f"allowed an integer in 1..{top or 'n_transitions'} (each episode has a transition or more)")
        if top is not None and top > episodes * MAX_EPISODE_STEPS:  # T48-B03: 10**30 transitions in 3 episodes were taken
            top = episodes * MAX_EPISODE_STEPS
            return _its(
                "stats.n_transitions",
                n,
                f"allowed an integer in {MIN_TRANSITIONS}..{top:,} (its {episodes} episodes of at most {MAX_EPISODE_STEPS:,} steps each)",
            )
    null = ("budget",) if method == "ec-meno" else ()  # EC-MENO's plateau stop; EC-MER's budget is a number (T24-08)
    for key, high in (("budget", None), ("evaluations", None), ("episodes", MAX_EC_MER_EPISODES), ("n_steps", MAX_EPISODE_STEPS), ("wind_fit_rounds", None)):
        if key in stats and not (stats[key] is None and key in null) and not (whole_number(stats[key]) and 1 <= stats[key] <= (high or stats[key])):
            allowed = f"allowed an integer in 1..{high:,}" if high else "allowed an integer >= 1"
            return _its(f"stats.{key}", stats[key], allowed + (" or null (the plateau stop)" if key in null else ""))
    for key in ("seed", "episode_seed"):  # T24-08: seed -1 was taken
        if key in stats and not (whole_number(stats[key]) and 0 <= stats[key] <= MAX_SEED):
            return _its(f"stats.{key}", stats[key], "allowed an integer in 0..2**63-1 (the seed the fit ran with)")
    for key in _STATS_RETURNS:  # T24-08: a return of 5.0 was taken
        if key in stats and not (finite_real(stats[key]) and -WORST_RETURN <= stats[key] <= 0):
            return _its(f"stats.{key}", stats[key], f"allowed a finite return in [{-WORST_RETURN:.3g}, 0] (every reward is minus a sum of squares)")
    for key in _STATS_ERRORS:  # T24-08: an error of -5 was taken
        if key in stats and not (finite_real(stats[key]) and stats[key] >= 0) and not (stats[key] is None and key == "least_squares_one_step_error"):
            return _its(f"stats.{key}", stats[key], "allowed a finite number >= 0" + (" or null" if key == "least_squares_one_step_error" else ""))
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
    from .lr import D_U_CHOICES, ESTIMATORS, INTERCEPTS, NOISE_ESTIMATES, has_intercept
    from .wind import WIND_MODELS

    stats = model.stats
    for key, allowed in (("estimator", ESTIMATORS), ("intercepts", INTERCEPTS), ("noise", NOISE_ESTIMATES), ("d_u", D_U_CHOICES), ("wind_model", WIND_MODELS)):
        if key in stats and (not isinstance(stats[key], str) or stats[key] not in allowed):
            return _its(f"stats.{key}", stats[key], f"allowed {' or '.join(allowed)} (LR's {key} choices)")
    wind = stats.get("wind_model", model.wind.kind)
    if wind != model.wind.kind:
        return _its("wind", model.wind.kind, f"stats.wind_model is {wind!r}: allowed a {wind!r} wind")
    problem = _lr_noise_wind_problem(model)
    if problem:
        return problem
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
    fitted = {name for axis, name in enumerate(NOISE_NAMES) if has_intercept(axis, intercepts)} - {"v"}  # the v constant is D_v
    optional = {"u"} if intercepts == "uv" and "d_u" not in stats and wind == "none" else set()  # before d_u: "uv" discarded u
    expected = fitted - ({"u"} if kept or wind != "none" else set())
    if not expected - optional <= set(discarded) <= expected | optional:
        discards = ", ".join(sorted(expected)) or "none"
        return _its(
            "stats.discarded_intercepts", discarded, f"its intercepts {intercepts!r} (d_u {stats.get('d_u', 'keep')!r}, wind {wind!r}) discard {discards}"
        )
    return ""


def _lr_noise_wind_problem(model: LearnedModel) -> str:
    """'' when an LR model's noise std is the estimate its stats.noise names, its stationary noise estimate its residual
    rms times :data:`~neurohover.models.transitions.STATIONARY_PER_RMS` (both of the same residuals; T26-B14) and its
    stats hold a wind fit's entries only with a wind, else what contradicts what (T24-08)."""
    from .transitions import STATIONARY_PER_RMS

    stats, noise = model.stats, model.stats.get("noise")
    estimate = stats.get(f"noise_std_{noise}")
    if estimate is not None and not all(_near(a, b) for a, b in zip(model.noise_std, estimate)):
        return _its("noise_std", list(model.noise_std), f"its stats.noise {noise!r} gives stats.noise_std_{noise} {brief(estimate)}")
    rms, stationary = stats.get("residual_rms"), stats.get("noise_std_stationary")
    if rms is not None and stationary is not None and not all(_near(s, STATIONARY_PER_RMS * r) for r, s in zip(rms, stationary)):
        why = f"LR writes its stats.noise_std_stationary {brief(stationary)} as {STATIONARY_PER_RMS:g} x the residual rms of the same fit"
        return _its("stats.residual_rms", rms, why)  # T26-B14: a residual_rms 10 times the fit's was taken
    key = next((k for k in _WIND_STATS if k in stats), None) if model.wind.kind == "none" else None
    if key is not None:
        return _its(f"stats.{key}", stats[key], "allowed only in the stats of a model with a wind (its wind is 'none')")
    return ""


#: How near two numbers a fit computed twice (a batch and one alone: rounding apart) are taken as the same (T24-08).
_REL, _ABS = 1e-6, 1e-9


def _near(a: float, b: float) -> bool:
    return math.isclose(a, b, rel_tol=_REL, abs_tol=_ABS)


def _ec_problem(model: LearnedModel) -> str:
    """'' when an EC-MENO or EC-MER model has the D_u and wind those methods leave out (they evolve neither; T23-10) and
    stats whose errors, returns and champion history agree (T24-08)."""
    if model.d_u != 0.0:
        return _its("d_u", model.d_u, f"allowed 0.0: {model.method} evolves no D_u")
    if model.wind.kind != "none":
        return _its("wind", model.wind.kind, f"allowed 'none': {model.method} fits no wind")
    stats = model.stats
    meno = model.method == "ec-meno"
    problem = _ec_meno_problem(stats) if meno else _ec_mer_problem(stats)
    champion = ("n_transitions", "one_step_error") if meno else ("return_error",)  # the champion's return: -n x error, -error
    last = -math.prod(stats[k] for k in champion) if all(k in stats for k in champion) else None
    return problem or (_history_problem(stats, " x ".join(champion), last) if "history" in stats else "")


def _ec_mer_problem(stats: dict) -> str:
    """'' when EC-MER's errors are its returns' distances and its champion no worse than the prototype (T24-08)."""
    for error, predicted in (("return_error", "predicted_return"), ("prototype_return_error", "prototype_predicted_return")):
        if error in stats and predicted in stats and "true_return" in stats:
            distance = abs(stats[predicted] - stats["true_return"])
            if not _near(stats[error], distance):
                return _its(f"stats.{error}", stats[error], f"allowed |{predicted} - true_return| = {distance!r}")
    if "return_error" in stats and "prototype_return_error" in stats and not _below(stats["return_error"], stats["prototype_return_error"]):
        return _its("stats.return_error", stats["return_error"], "allowed at most stats.prototype_return_error (the prototype is evaluated first)")
    return ""


def _ec_meno_problem(stats: dict) -> str:
    """'' when EC-MENO's scaling, gene scale, errors and excess agree: the champion no worse than the prototype, the
    least-squares minimum below both, excess the champion's relative distance to it (T24-08)."""
    from .ec import EC_MENO_SCALINGS

    scaling = stats.get("scaling")
    if "scaling" in stats and (not isinstance(scaling, str) or scaling not in EC_MENO_SCALINGS):
        return _its("stats.scaling", scaling, f"allowed {' or '.join(EC_MENO_SCALINGS)} (EC-MENO's gene scalings)")
    if scaling == "default" and "gene_scale" in stats and not all(_near(a, abs(b)) for a, b in zip(stats["gene_scale"], DEFAULT_PARAMS)):
        return _its("stats.gene_scale", stats["gene_scale"], "allowed |default parameters| (its scaling 'default')")
    error, proto = stats.get("one_step_error"), stats.get("prototype_one_step_error")
    if error is not None and proto is not None and not _below(error, proto):
        return _its("stats.one_step_error", error, "allowed at most stats.prototype_one_step_error (the prototype is evaluated first)")
    least = stats.get("least_squares_one_step_error")
    if least is not None and error is not None and not _below(least, error):
        return _its("stats.least_squares_one_step_error", least, "allowed at most stats.one_step_error (it is the smallest one-step error)")
    if "excess" in stats and "least_squares_one_step_error" in stats and error is not None:
        excess = None if least is None or least <= 0 else (error - least) / least
        given = stats["excess"]
        if (excess is None) != (given is None) or (excess is not None and not (finite_real(given) and _near(given, excess))):
            return _its("stats.excess", given, f"allowed (one_step_error - least_squares_one_step_error) / least_squares_one_step_error = {excess!r}")
    return ""


def _below(a: float, b: float) -> bool:
    """Whether ``a`` is at most ``b``, or as near as :func:`_near` takes."""
    return a <= b or _near(a, b)


def _history_problem(stats: dict, champion: str, last: float | None) -> str:
    """'' when an EC model's stats.history is the champion records its evolution keeps: [evaluations, return] of each new
    champion, both rising, evaluations in 1..stats.evaluations, returns <= 0, the last the champion's (minus ``champion``,
    ``last``); else what is wrong (an evaluation past those made and a return not the champion's were taken; T24-08)."""
    history, top = stats["history"], stats.get("evaluations")
    top = top if whole_number(top) else None
    records = isinstance(history, list) and bool(history) and all(isinstance(h, list) and len(h) == 2 for h in history)
    before = (0, -math.inf)
    for h in history if records else ():
        if not (whole_number(h[0]) and finite_real(h[1]) and before[0] < h[0] <= (top or h[0]) and before[1] < h[1] <= 0):
            records = False
            break
        before = (h[0], h[1])
    if not records:
        return _its(
            "stats.history",
            history,
            f"allowed [evaluations, return] of each new champion, both rising, evaluations in 1..{top or 'evaluations'}, returns <= 0",
        )
    if last is not None and not _near(before[1], last):
        return _its("stats.history", history, f"its last record is the champion's: a return of {last!r} (minus its {champion})")
    return ""
