"""What :meth:`~neurohover.experiments.store.Store.put` checks of a finished unit before it writes anything: its
arguments (:func:`put_arguments`), and that its key is one its experiment's stored config plans the shape of and its
own params agree with (:func:`planned_problem`); and the shapes of the unit keys each experiment kind plans
(:func:`key_shape_problem`), which the readers check of every stored unit too.

A unit the config does not plan, once stored, made every reader (results, report, reproduce) refuse the whole
experiment as damaged, and the remedy, ``reproduce --fresh``, lost its sound units as well (T55-B09).
"""

from __future__ import annotations

from typing import Any

from ..errors import NeurohoverError, brief
from ..sim.constants import MAX_SECONDS, seconds_allowed
from .keys import UnitKey
from .plans import run_keys
from .store_checks import check_experiment, check_text, read_config, stored_count, unit_texts

#: The unit key stages (:class:`~neurohover.experiments.keys.UnitKey`) each experiment kind's plan names its units with.
PLANNED_STAGES = {"evolution": ("evolve", "robust"), "model_learning": ("policy", "model"), "test_runs": ("policy", "run")}
KEY_FORMS = {
    "evolve": "evolve/<variant>[/train<i>]/run<r>",
    "robust": "robust/<variant>/train<i>",
    "policy": "policy/<name>",
    "model": "model/<method>/<mdps><i>",
    "run": "run/<group>/<mdps><i>/rep<r>",
}

#: The unit kinds a plan gives each key stage (a policy unit evolves a policy, or checks the safety of ten).
STAGE_KINDS = {"evolve": ("evolve",), "robust": ("robustness",), "policy": ("evolve", "safety"), "model": ("model",), "run": ("test_run",)}


def put_arguments(where: str, name: Any, scale: Any, config_hash: Any, unit: Any, result: Any, seconds: Any, worker: Any, session: Any):
    """Store.put's arguments checked, before anything is written: the unit's params and result as JSON text, and the
    session as an integer (or None). A NaN ``seconds`` was bound as NULL, and the unit dropped (T14-5)."""
    check_experiment(name, scale, where)
    check_text(config_hash, "config_hash", where)
    params, text = unit_texts(unit, result, name, where)
    if not seconds_allowed(seconds):  # what Store.units reads back (1e300 was exported; T45-B02)
        raise NeurohoverError(f"{where}: seconds = {brief(seconds)} is not allowed: give a finite number of seconds >= 0, at most {MAX_SECONDS:.6g}")
    check_text(worker, "worker", where, empty=True)
    return params, text, None if session is None else stored_count(session, "session", where, 1)


def key_shape_problem(experiment_kind: str, key: str, unit_kind: str) -> str:
    """Why unit ``key`` is of no shape a plan of ``experiment_kind`` gives ('' when it is one): a stage that kind plans, its
    parts written back as the key ('run/../../x' was exported and drawn; T20-05). A 'diagnostic' unit (the tests' own
    plans) may have any key."""
    if unit_kind == "diagnostic":
        return ""
    parsed = UnitKey.parse(key)
    stages = PLANNED_STAGES.get(experiment_kind, ())
    try:
        fits = parsed.stage in stages and UnitKey.make(parsed.stage, parsed.group, parsed.mdp, parsed.rep) == key
    except ValueError:
        fits = False
    if fits:
        return ""
    return f"its key is of no shape a {experiment_kind} experiment plans: its unit keys are {' or '.join(KEY_FORMS[s] for s in stages)}"


def _label_problem(key: UnitKey, mdp: Any) -> str:
    """Why the MDP (as a dict) of a unit keyed ``key`` is not the MDP its key names ('' when it is): ``test99`` names the
    MDP labelled ``<family>/test:99`` (or ``seeded-test:99``)."""
    index = key.mdp_index
    which = (key.mdp or "")[: len(key.mdp or "") - len(str(index))]
    label = mdp.get("label") if isinstance(mdp, dict) else None
    tail = label.rpartition("/")[2] if isinstance(label, str) else None
    if tail in (f"{which}:{index}", f"seeded-{which}:{index}"):
        return ""
    return f"its key names MDP {key.mdp}, but its params fly the MDP labelled {brief(label)}"


def _own_params_problem(key: UnitKey, params: dict) -> str:
    """Why unit ``key``'s own params are not those of the unit its key names ('' when they are): the group or agent, the
    MDP or its index (the repetition is not in the params: the plan's keys are checked for it)."""
    if key.stage == "run":
        if params.get("group") != key.group:
            return f"its key names group {key.group!r}, but its params' group is {brief(params.get('group'))}"
        return _label_problem(key, params.get("mdp"))
    if key.stage == "model":
        if params.get("method") != key.group.partition("@")[0]:
            return f"its key names method {key.group!r}, but its params' method is {brief(params.get('method'))}"
        return _label_problem(key, params.get("mdp"))
    if key.stage == "evolve" and key.mdp is not None:
        target = params.get("target")
        return _label_problem(key, target.get("mdp") if isinstance(target, dict) else None)
    if key.stage == "robust" and params.get("own") != key.mdp_index:
        return f"its key names training MDP {key.mdp_index}, but its params' own is {brief(params.get('own'))}"
    return ""


def planned_problem(stored: dict, scale: str, unit: Any) -> str:
    """Why the stored config ``stored`` (its row at ``scale``) does not plan ``unit`` ('' when it may): a key of no shape its
    kind plans, or for a unit of another kind, one its own params contradict, a test run of no group, MDP or repetition of the config (its run keys
    follow from the config alone). Which units a later stage plans follows from earlier results (the champion a
    robustness unit flies, the policies of a test run), so that, and the params the plan gives each, stay the readers'
    check of the whole experiment (:func:`~neurohover.experiments.export.checked_units`)."""
    if unit.kind == "diagnostic":
        return ""
    config = read_config(stored, scale)
    key = UnitKey.parse(unit.key)
    problem = key_shape_problem(config.kind, unit.key, unit.kind)
    if not problem and unit.kind not in STAGE_KINDS[key.stage]:
        problem = f"its key names a {key.stage} unit, whose kind is {' or '.join(map(repr, STAGE_KINDS[key.stage]))}, not {unit.kind!r}"
    problem = problem or _own_params_problem(key, unit.params)
    if not problem and key.stage == "run" and unit.key not in run_keys(config):
        problem = "its config plans no such test run (no such group, MDP or repetition)"
    return problem
