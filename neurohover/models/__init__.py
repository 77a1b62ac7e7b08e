"""Learning helicopter models from flight data: LR, EC-MENO and EC-MER (paper Section 3.2; docs/model.md, Learned models).

A learned model has the simulator's equations but integrates once per 0.1 s control step (one
substep; no wind, as in the paper, unless LR is asked for one) with its own 11 dynamics parameters
and 6 gust-noise standard deviations, so it flies in the same compiled kernel as the true MDPs
(:meth:`LearnedModel.mdp`).

Methods
-------
``learn_lr``
    Least squares on consecutive observations (the paper's best method); every choice and why in
    :mod:`neurohover.models.lr`.
``learn_ec_meno``
    Steady-state neuroevolution of the 11 parameters minimising the mean one-step prediction error,
    a quadratic whose exact minimum (per-axis OLS) :meth:`OneStepProblem.least_squares` gives.
``learn_ec_mer``
    Steady-state neuroevolution minimising |model-predicted return of the generic policy over one
    episode - the return observed in the flight data|.

Modules
-------
``model``
    :class:`LearnedModel`, its file format, :func:`equivalent_params` (the model's parameters in
    the simulator's integration) and :func:`parameter_table`; the helpers the others share.
``model_checks``
    :func:`~neurohover.models.model_checks.model_file_problem`: a model file checked against itself when it is read.
``transitions``
    Flight data as transitions, noise from residuals, :class:`OneStepProblem` and :func:`one_step_error`.
``lr``
    :func:`learn_lr`.
``ec``
    :func:`learn_ec_meno`, :func:`learn_ec_mer` and :func:`observed_return`.
``wind``
    :class:`WindModel`: a learned model's world-frame wind (constant or sinusoidal), identified by
    ``learn_lr(..., wind_model=...)``, and :func:`effective_wind`, what of a true wind a model
    sampled at 10 Hz can see.

Every public name is importable from ``neurohover.models`` itself.

Example
-------
>>> from neurohover import baseline_policy, evaluate, get_task_family
>>> from neurohover.models import learn_lr
>>> ev = evaluate(baseline_policy(), get_task_family("ghh08").zero(), record=True, seed=1)
>>> model = learn_lr(ev.flight_data)
>>> mdp = model.mdp()                    # fly policies on the model like on any MDP
"""

from ..sim.constants import NOISE_NAMES, PARAM_NAMES
from .ec import EC_MENO_MAX_EVALUATIONS, EC_MENO_SCALINGS, ec_meno_gene_scale, ec_mer_policy, learn_ec_meno, learn_ec_mer, observed_return
from .lr import (
    D_U_CHOICES,
    DEFAULT_D_U,
    DEFAULT_ESTIMATOR,
    DEFAULT_INTERCEPTS,
    DEFAULT_NOISE_ESTIMATE,
    ESTIMATORS,
    INTERCEPTS,
    LEGACY_NOISE_ESTIMATE,
    NOISE_ESTIMATES,
    learn_lr,
    lr_determined,
)
from .model import (
    AXIS_C,
    AXIS_GAINS,
    FORMAT,
    MODEL_DT,
    MODEL_METHODS,
    LearnedModel,
    ParamRow,
    check_vector,
    equivalent_params,
    format_parameter_table,
    one_substep_params,
    parameter_table,
)
from .transitions import MIN_TRANSITIONS, OneStepProblem, Transitions, authors_noise, noise_from_residuals, one_step_error
from .wind import DEFAULT_WIND_MODEL, NO_WIND, WIND_MODELS, WindAxis, WindModel, effective_wind, fit_wind

__all__ = [
    "D_U_CHOICES",
    "DEFAULT_D_U",
    "DEFAULT_ESTIMATOR",
    "DEFAULT_INTERCEPTS",
    "DEFAULT_NOISE_ESTIMATE",
    "LEGACY_NOISE_ESTIMATE",
    "NOISE_ESTIMATES",
    "DEFAULT_WIND_MODEL",
    "EC_MENO_SCALINGS",
    "ESTIMATORS",
    "FORMAT",
    "INTERCEPTS",
    "LearnedModel",
    "NO_WIND",
    "OneStepProblem",
    "ParamRow",
    "WIND_MODELS",
    "WindAxis",
    "WindModel",
    "effective_wind",
    "fit_wind",
    "equivalent_params",
    "format_parameter_table",
    "ec_mer_policy",
    "learn_ec_mer",
    "learn_ec_meno",
    "learn_lr",
    "lr_determined",
    "ec_meno_gene_scale",
    "observed_return",
    "one_step_error",
    "one_substep_params",
    "parameter_table",
    # constants the former single module offered too, and the helpers its modules share
    "AXIS_C",
    "AXIS_GAINS",
    "EC_MENO_MAX_EVALUATIONS",
    "MODEL_METHODS",
    "MIN_TRANSITIONS",
    "MODEL_DT",
    "NOISE_NAMES",
    "PARAM_NAMES",
    "Transitions",
    "check_vector",
    "noise_from_residuals",
    "authors_noise",
]
