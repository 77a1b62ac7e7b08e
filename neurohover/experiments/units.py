"""Units of work and the one pure function that runs them: :func:`run_unit`.

A unit is one evolution run, one robustness test, one model-learning trial, one test run of an
agent, ... Everything it needs travels in its ``params`` (plain JSON: MDPs as dicts, policies as
``{"topology", "genome"}``, its own seed), so a unit runs the same in this process, in a spawned
worker or on a Ray node, and its result depends on nothing else: no global random state, no
files, no thread count. Each unit kind builds its typed result
(:mod:`~neurohover.experiments.results`) and returns its JSON dict, which the store keeps.

Seeds come from the unit's key: :func:`unit_seed` feeds the root seed of the config and a SHA-256
of ``"<experiment>/<key>"`` to ``numpy.random.SeedSequence``.

Results keep wall-clock measurements under the key ``"timing"`` (outside the results' ``==``);
everything else is a deterministic function of the params.
"""

from __future__ import annotations

import hashlib
import os
import time
from collections.abc import Sequence
from dataclasses import dataclass, field
from typing import Any, TypeVar

import numpy as np

from ..agents.model_based import ModelEvolution, evolve_on_model
from ..agents.protocol import after_learning_start, run_test
from ..agents.registry import AgentOptions, AgentPolicies, agent_spec
from ..errors import NeurohoverError, brief, whole_number
from ..evaluate import evaluate, evaluate_jobs, num_threads
from ..evolution.config import optimiser_of
from ..evolution.eonn import EonnSettings
from ..evolution.evolve import evolve, reevaluated_champion, validation_return
from ..evolution.seeding import MAX_SEED, validation_seeds
from ..integrations.neat import NEAT_TOPOLOGY, genome_record
from ..models import learn_ec_meno, learn_ec_mer, learn_lr, one_step_error
from ..policies import Policy
from ..policies import prototype as make_prototype
from ..policysets import choose_safe
from ..tasks import EXACT, MDP, Sensor, family_for, family_from_dict
from .params import PARAMS, checked_unit_params, unit_params
from .results import (
    DiagnosticResult,
    EvolveResult,
    EvolveTiming,
    ModelResult,
    ModelTiming,
    Reevaluation,
    RobustnessResult,
    SafetyResult,
    StoredPolicy,
    TestRunResult,
    TestRunTiming,
    num,
)

_P = TypeVar("_P", bound=Sequence)  # a point (x, y, ...) of subsample


@dataclass(frozen=True)
class Unit:
    """One unit of work of ``experiment``: ``key`` is unique within the experiment."""

    experiment: str
    key: str
    kind: str
    params: dict = field(hash=False, compare=False)

    def to_dict(self) -> dict:
        return {"experiment": self.experiment, "key": self.key, "kind": self.kind, "params": self.params}


def unit_seed(root: int, experiment: str, key: str) -> int:
    """A 63-bit seed for unit ``key``: ``SeedSequence([root, *sha256(experiment/key) words])``."""
    if not whole_number(root) or not 0 <= root <= MAX_SEED:  # 'x', -1 were NumPy's errors (twelfth trial, T7); 2**64 taken (T16-17)
        raise NeurohoverError(f"root={brief(root)} is not allowed: give the config's seed, an integer in 0..2**63-1")
    for name, value in (("experiment", experiment), ("key", key)):
        if not isinstance(value, str):
            raise NeurohoverError(f"{name}={brief(value)} is not allowed: give text")
        from .store_checks import check_text  # the store's check of its text fields (here: a cycle at import time)

        check_text(value, name, "unit_seed", empty=True)  # a lone surrogate was encode()'s UnicodeEncodeError (T43-B12)
    digest = hashlib.sha256(f"{experiment}/{key}".encode()).digest()
    words = [int(w) for w in np.frombuffer(digest, dtype="<u4")]
    state = np.random.SeedSequence([int(root), *words]).generate_state(1, np.uint64)[0]
    return int(state >> np.uint64(1))


# --------------------------------------------------------------------------------- helpers


def policy_dict(policy) -> dict:
    """A policy as params and results hold it: ``{"topology", "genome"}``."""
    return StoredPolicy.of(policy).to_dict()


def _policy(d: dict):
    return Policy(d["topology"], np.array(d["genome"], dtype=float))


def _mdp(d: dict):
    return MDP.from_dict(d)


def family_of(task: str, sigma: float | None, sensor: dict | None = None):
    """A config's or a unit's task family: its task, breadth and sensor table (None: exact sensors)."""
    return family_for(task, sigma, None if sensor is None else Sensor.from_dict(sensor))


def subsample(points: list[_P], n: int) -> list[_P]:
    """At most ``n`` of ``points`` (sorted by x), keeping the first and last, spread on a log-x grid."""
    if len(points) <= n:
        return points
    xs = np.array([p[0] for p in points], dtype=float)
    grid = np.unique(np.geomspace(max(xs[0], 1.0), xs[-1], n))
    idx = np.unique(np.clip(np.searchsorted(xs, grid, side="right") - 1, 0, len(points) - 1))
    idx = np.unique(np.concatenate([[0], idx, [len(points) - 1]]))
    return [points[i] for i in idx]


# --------------------------------------------------------------------------------- unit kinds


def _evolve_target(t: dict):
    """An evolution unit's target: the MDP, or the family (its task, breadth and sensors)."""
    if t["kind"] == "mdp":
        return _mdp(t["mdp"])
    return family_from_dict({k: v for k, v in t.items() if k != "kind"})


def run_evolve(p: dict, threads: int | None, device: str = "cpu") -> dict:
    """One evolution run (paper Section 3.1 / 5): champion, history, optional validation."""
    q = unit_params("evolve", p)

    target = _evolve_target(q.target)
    if q.topology == NEAT_TOPOLOGY:
        return _run_neat(q, target)
    proto = _policy(q.prototype) if isinstance(q.prototype, dict) else make_prototype(q.topology, q.prototype)
    optimizer, settings = optimiser_of(q.optimiser)
    t0 = time.perf_counter()
    result = evolve(
        target,
        topology=q.topology,
        prototype=proto,
        optimizer=optimizer,
        resampling=q.resampling,
        budget=q.budget or None,
        settings=settings or None,
        seed=q.seed,
        n_steps=q.n_steps,
        threads=threads,
        device=device,
    )
    history = [(int(h.episodes), num(h.champion_return)) for h in result.history]

    def validated(policy) -> tuple[tuple | None, tuple | None]:
        if q.validation_mdps == "test":  # every run's champion on the family's test MDPs, with shared noise (paired)
            ev = fly_on_test_mdps(policy, target, q.validation_episodes, q.validation_seed, q.n_steps, threads, device)
            return tuple(num(x) for x in ev.returns), tuple(bool(c) for c in ev.crashed)
        if q.validation_episodes:
            v = validation_return(policy, target, episodes=q.validation_episodes, seed=q.seed, n_steps=q.n_steps, threads=threads, device=device)
            return tuple(num(x) for x in v), None
        return None, None

    validation, crashed = validated(result.champion)

    def chosen_again(among: str) -> Reevaluation:
        again, means = reevaluated_champion(result, target, episodes=q.champion_reevaluation, among=among, n_steps=q.n_steps, threads=threads, device=device)
        index = int(again.metadata["reevaluated_from"])
        v, c = validated(again)
        return Reevaluation(
            champion=StoredPolicy.of(again), parent=index, episodes=q.champion_reevaluation, estimate=num(means[index]), validation=v, validation_crashed=c
        )

    # the champion chosen again among the last parents and among the run's best generation champions, validated alike
    reevaluated = chosen_again("last") if q.champion_reevaluation else None
    best_ever = chosen_again("best-ever") if q.champion_reevaluation else None
    scale = result.settings["settings"].get("fitness") if result.settings.get("method") == "generational" else None
    return EvolveResult(
        champion=StoredPolicy.of(result.champion),
        champion_return=num(result.champion_return),
        episodes=int(result.episodes),
        evaluations=int(result.evaluations),
        generations=int(result.generations),
        stop_reason=result.stop_reason,
        champion_crashed=bool(result.champion_crashed),
        history=tuple(subsample(history, q.history_points)),
        validation=validation,
        validation_crashed=crashed,
        fitness=scale,
        reevaluated=reevaluated,
        reevaluated_best_ever=best_ever,
        timing=EvolveTiming(seconds=time.perf_counter() - t0, kernel_seconds=float(result.kernel_seconds)),
    ).to_dict()


def _run_neat(q, target) -> dict:
    """An evolution run whose topology evolves too (NEAT, :mod:`neurohover.integrations.neat`; the variant's
    ``neat`` table its settings), validated on the episodes an evolution run's champion meets: the same MDPs and
    gusts (:func:`~neurohover.evolution.evolve.validation_return` on an MDP, :func:`fly_on_test_mdps` on a family).
    Its champion is stored as topology ``"neat"`` with :func:`~neurohover.integrations.neat.genome_record` as genome."""
    from ..integrations.flying import evaluate_callable
    from ..integrations.neat import NeatSettings, evolve_topology

    settings = NeatSettings.of({k: v for k, v in q.optimiser.items() if k != "name"})
    t0 = time.perf_counter()
    result = evolve_topology(target, budget=q.budget, seed=q.seed, settings=settings, n_steps=q.n_steps)
    if isinstance(target, MDP):
        noise_seed, _ = validation_seeds(q.seed)
        mdps, seed = [target] * q.validation_episodes, noise_seed  # episode i: stream (noise seed, i), as validation_return's
    else:
        tests = target.test_mdps()
        mdps, seed = [tests[i % len(tests)] for i in range(q.validation_episodes)], q.validation_seed  # as fly_on_test_mdps
    ev = evaluate_callable(result.act, mdps, seed=seed, n_steps=q.n_steps, obs_dtype="float64") if mdps else None
    history = [(int(h["episodes"]), num(h["best"])) for h in result.history]
    return EvolveResult(
        champion=StoredPolicy(NEAT_TOPOLOGY, genome_record(result.champion)),
        champion_return=num(result.champion_fitness),
        episodes=int(result.episodes),
        evaluations=int(result.episodes),
        generations=int(result.generations),
        stop_reason="budget",
        champion_crashed=None,
        history=tuple(subsample(history, q.history_points)),
        validation=None if ev is None else tuple(num(x) for x in np.ravel(ev.returns)),
        validation_crashed=None if ev is None else tuple(bool(c) for c in np.ravel(ev.crashed)),
        fitness=settings.fitness,
        reevaluated=None,
        reevaluated_best_ever=None,
        timing=EvolveTiming(seconds=time.perf_counter() - t0, kernel_seconds=0.0),
    ).to_dict()


def fly_on_test_mdps(policy, family, episodes: int, seed: int, n_steps: int, threads, device):
    """``policy`` flown once on each of the first ``episodes`` test MDPs of ``family`` (cycling), episode
    ``i`` with noise stream ``(seed, i)``: the same MDPs and gusts for every policy flown so."""

    rows = np.array([m.row() for m in family.test_mdps()])
    idx = np.arange(episodes, dtype=np.int64)
    return evaluate_jobs([policy], rows, np.zeros(episodes, dtype=np.int64), idx % len(rows), idx, seed=seed, n_steps=n_steps, threads=threads, device=device)


def run_robustness(p: dict, threads: int | None, device: str = "cpu") -> dict:
    """Table 3: fly one policy ``episodes`` times on each of the given MDPs."""
    q = unit_params("robustness", p)

    mdps = [_mdp(m) for m in q.mdps]
    ev = evaluate(_policy(q.policy), mdps, episodes=q.episodes, seed=q.seed, n_steps=q.n_steps, threads=threads, device=device)
    return RobustnessResult(
        returns=tuple(tuple(num(x) for x in row) for row in ev.returns[0]), crashes=tuple(int(c) for c in ev.crashed[0].sum(axis=1)), own=q.own
    ).to_dict()


def run_safety(p: dict, threads: int | None, device: str = "cpu") -> dict:
    """Crash matrix of the specialised policies on the training MDPs, and the two safe ones."""
    q = unit_params("safety", p)

    policies = [_policy(d) for d in q.policies]
    ev = evaluate(policies, [_mdp(m) for m in q.mdps], episodes=q.episodes, seed=q.seed, n_steps=q.n_steps, threads=threads, device=device)
    crashes, returns = ev.crashed.sum(axis=2), ev.returns.mean(axis=2)
    return SafetyResult(
        crashes=tuple(tuple(int(c) for c in row) for row in crashes),
        mean_returns=tuple(tuple(num(x) for x in r) for r in returns),
        safe=choose_safe(crashes, returns),
    ).to_dict()


def model_unit_seeds(seed: int) -> np.ndarray:
    """A model unit's four seeds from its own: flight data, model learning, the evolution on the model, the test episodes."""
    return np.random.SeedSequence(seed).generate_state(4, np.uint64) >> np.uint64(1)


def run_model(p: dict, threads: int | None, device: str = "cpu") -> dict:
    """Table 4: fly the generic policy once (flight data), learn a model, evolve a policy on the
    model, fly that policy ``test_episodes`` times in the true MDP. Methods: ``lr`` (OLS, the
    paper's), ``lr-gls`` (the GLS option), ``ec-meno`` (``ec_meno_budget`` evaluations, 0: the
    plateau stop) and ``ec-mer`` (``model_budget`` evaluations). The model learns from ``data_episodes``
    episodes (flown through the MDP's sensors, when it has a sensor model); with ``exact_checks`` the
    model and its policy are also checked against exact sensors (:class:`ModelResult`)."""
    q = unit_params("model", p)

    mdp = _mdp(q.mdp)
    generic = _policy(q.generic)
    seeds = model_unit_seeds(q.seed)
    data = evaluate(generic, mdp, episodes=q.data_episodes, seed=int(seeds[0]), record=True, n_steps=q.n_steps, threads=threads, device=device)
    flight = data.flight_data
    assert flight is not None  # recorded
    t0 = time.perf_counter()
    if q.method in ("lr", "lr-gls"):  # ordinary least squares (the paper's), or the GLS option
        model = learn_lr(flight, estimator="gls" if q.method == "lr-gls" else "ols", d_u=q.d_u, noise=q.noise)
    elif q.method == "ec-meno":
        model = learn_ec_meno(flight, budget=q.ec_meno_budget or None, seed=int(seeds[1]))
    else:
        model = learn_ec_mer(flight, generic, float(data.returns.ravel()[0]), budget=q.model_budget, seed=int(seeds[1]), episodes=q.ec_mer_episodes)
    learn_seconds = time.perf_counter() - t0
    flown_mdp = model.flown_mdp(q.model_substeps)  # as fitted where an axis has no equivalent
    flown = flown_mdp.substeps
    proto = generic if q.prototype == "generic" else "baseline"
    t1 = time.perf_counter()
    if q.model_policy == "authors":  # their GHH-09 agents: an SLP from the baseline by their eonn
        authors = ModelEvolution(n_steps=q.n_steps, device=device, model_policy="authors", authors_generations=q.authors_generations)
        champion, predicted = evolve_on_model(flown_mdp, generic, authors, int(seeds[2]))
        policy_episodes = EonnSettings(generations=q.authors_generations).episodes
    else:
        evolved = evolve(
            flown_mdp,
            topology=generic.topology,
            prototype=proto,
            budget=q.policy_budget or None,
            seed=int(seeds[2]),
            n_steps=q.n_steps,
            threads=threads,
            device=device,
        )
        champion, policy_episodes, predicted = evolved.champion, evolved.episodes, evolved.champion_return
    evolve_seconds = time.perf_counter() - t1
    test = evaluate(champion, mdp, episodes=q.test_episodes, seed=int(seeds[3]), n_steps=q.n_steps, threads=threads, device=device, record=True)
    returns = test.returns.ravel()
    assert test.flight_data is not None  # recorded
    w_sd = float(np.std(np.concatenate([o[:, 2] for o in test.flight_data.observations])))  # the collective loop's oscillation
    checks = {}
    if q.exact_checks:
        checks = _exact_checks(q, mdp, generic, model, flight, champion, int(seeds[3]), threads, device)
    return ModelResult(
        method=q.method,
        mdp=mdp.label,
        generic_return=num(data.returns.ravel().mean()),
        generic_crashed=bool(data.crashed.any()),
        model_params=tuple(num(x) for x in model.params),
        model_noise_std=tuple(num(x) for x in model.noise_std),
        predicted_return=num(predicted),
        test_returns=tuple(num(x) for x in returns),
        test_mean=num(returns.mean()),
        test_crashes=int(test.crashed.sum()),
        policy_episodes=int(policy_episodes),
        timing=ModelTiming(learn_seconds=learn_seconds, evolve_seconds=evolve_seconds),
        test_w_sd=num(w_sd),
        flown_substeps=None if flown == q.model_substeps else flown,
        **checks,
    ).to_dict()


def _exact_checks(q, mdp, generic, model, flight, champion, test_seed: int, threads: int | None, device: str) -> dict:
    """What a model learned through the MDP's sensors does against exact ones: its one-step error on its own
    data and on an exact episode of the generic policy (gusts of its own seed), its parameters' relative
    errors, and its policy flown with exact sensors on the test's gusts."""
    exact = mdp.with_sensor(EXACT)
    exact_seed = int(np.random.SeedSequence([q.seed, 1]).generate_state(1, np.uint64)[0] >> np.uint64(1))
    exact_flight = evaluate(generic, exact, seed=exact_seed, record=True, n_steps=q.n_steps, threads=threads, device=device).flight_data
    assert exact_flight is not None  # recorded
    truth = np.asarray(mdp.params, dtype=float)
    flown = evaluate(champion, exact, episodes=q.test_episodes, seed=test_seed, n_steps=q.n_steps, threads=threads, device=device)
    return {
        "own_one_step_error": num(one_step_error(model, flight)),
        "exact_one_step_error": num(one_step_error(model, exact_flight)),
        "param_relative_errors": tuple(num(x) for x in np.abs(np.asarray(model.params) - truth) / np.abs(truth)),
        "exact_test_returns": tuple(num(x) for x in flown.returns.ravel()),
        "exact_test_crashes": int(flown.crashed.sum()),
    }


def unit_agent(p: dict, device: str = "cpu"):
    """The agent of a test-run unit, built from the policies in its params and the run's settings
    (policies evolved on learned models fly episodes of the run's length, on ``device``)."""

    q = unit_params("test_run", p)
    spec = agent_spec(q.agent)
    pol = q.policies
    policies = AgentPolicies(
        generic=_policy(pol["generic"]) if "generic" in pol else None,
        specialised=tuple(_policy(d) for d in pol.get("specialised", ())),
        safe=tuple(_policy(d) for d in pol.get("safe", ())),
    )
    options = AgentOptions(
        evolution=ModelEvolution(
            budget=q.model_budget,
            predict_episodes=q.predict_episodes,
            n_steps=q.n_steps,
            estimator=q.estimator,
            device=device,
            wind_model=q.wind_model,
            d_u=q.d_u,
            noise=q.noise,
            model_policy=q.model_policy,
            authors_generations=q.authors_generations,
            model_substeps=q.model_substeps,
        ),
        settings=None if spec.settings is None else spec.settings.from_unit(p),  # the agent's own, typed (from its UNIT_KEY)
    )
    return spec.built(policies, options)


def run_test_run(p: dict, threads: int | None, device: str = "cpu") -> dict:
    """One test run (docs/model.md, On-line agents): ``episodes`` episodes of an agent on one MDP it does not know."""
    q = unit_params("test_run", p)

    family = family_of(q.task, q.sigma, q.sensor)
    mdp = _mdp(q.mdp)
    agent = unit_agent(p, device)
    r = run_test(agent, family, mdp, episodes=q.episodes, seed=q.seed, n_steps=q.n_steps, threads=threads, device=device)
    start = after_learning_start(r.policy)
    changes = tuple((e, r.policy[e]) for e in range(len(r.policy)) if e == 0 or r.policy[e] != r.policy[e - 1])
    return TestRunResult(
        agent=q.agent,
        mdp=mdp.label,
        score=num(r.score),
        returns=tuple(num(x) for x in r.returns),
        crash_episodes=tuple(int(e) for e in np.flatnonzero(r.crashed)),
        safeguard_episodes=tuple(int(e) for e in np.flatnonzero(r.safeguard_fired)),
        policy_changes=changes,
        learning_episodes=int(start),
        mean_return_after_learning=num(r.returns[start:].mean()),
        crash_steps=tuple(int(s) for s in r.steps[r.crashed]),
        timing=TestRunTiming(seconds=float(r.seconds), offline_seconds=float(r.offline_seconds.sum())),
    ).to_dict()


def run_diagnostic(p: dict, threads: int | None, device: str = "cpu") -> dict:
    """Diagnostics for the executors (used by the tests): sleep, or kill the worker process.

    ``exit_unless`` names a marker file: if it does not exist, the unit creates it and the worker
    process exits at once (as if killed), so a retry succeeds; ``always_exit`` always exits.
    ``wait_for`` names a gate file: the unit waits until it exists (at most 600 s), so a test holds
    a run at a unit of its choosing, whatever the machine's speed.
    """
    if p.get("always_exit"):
        os._exit(3)
    gate = p.get("wait_for")
    if gate:
        deadline = time.monotonic() + 600.0
        while not os.path.exists(gate) and time.monotonic() < deadline:
            time.sleep(0.01)
    marker = p.get("exit_unless")
    if marker and not os.path.exists(marker):
        with open(marker, "w", encoding="utf-8") as f:
            f.write(str(os.getpid()))
        os._exit(3)
    time.sleep(float(p.get("sleep", 0.0)))
    return DiagnosticResult(value=p.get("value"), seed=p.get("seed")).to_dict()


_RUNNERS = {
    "evolve": run_evolve,
    "robustness": run_robustness,
    "safety": run_safety,
    "model": run_model,
    "test_run": run_test_run,
    "diagnostic": run_diagnostic,
}


def run_unit(unit: Unit | dict, threads: int | None = 1, device: str = "cpu") -> dict:
    """Run one unit and return its JSON-able result (a pure function of the unit's params): the
    ``to_dict()`` of its typed result (:data:`~neurohover.experiments.results.RESULT_TYPES`).

    ``threads`` are kernel threads (1 when many units run in parallel; None: all cores); results
    do not depend on it. ``device`` (``"cpu"`` or ``"cuda"``) is where every unit flies its episodes; like ``threads`` it is no
    part of the unit's params or the config hash: results agree across devices to within
    docs/gpu.md's tolerance.
    """
    if isinstance(unit, dict) and set(unit) == {"experiment", "key", "kind", "params"}:
        unit = Unit(unit["experiment"], unit["key"], unit["kind"], unit["params"])
    if not isinstance(unit, Unit) or not isinstance(unit.params, dict):  # {} was a KeyError, 'x' an AttributeError (twelfth trial, T7)
        raise NeurohoverError(
            f"unit={brief(unit)} is not allowed: give a Unit of a plan (neurohover.experiments.plans.plan) or its to_dict(), "
            "a dict of experiment, key, kind and params"
        )
    runner = _RUNNERS.get(unit.kind)
    if runner is None:
        raise NeurohoverError(f"unknown unit kind {unit.kind!r}: allowed {', '.join(_RUNNERS)}")
    if unit.kind in PARAMS:  # a unit edited by hand is refused by unit and param (T44-B11, T44-B12)
        checked_unit_params(unit.kind, unit.params, unit.key)
    with num_threads(threads):  # also for library calls that take no thread count (e.g. EC-MER)
        return runner(unit.params, threads, device)


def strip_timing(result: Any) -> Any:
    """A result without its wall-clock measurements (for comparing runs). A result that holds itself (no stored one,
    JSON, can) or is nested past Python's recursion limit is refused by name (was a RecursionError, T29-B09)."""
    inside: set[int] = set()  # the dicts and lists on the path from the top to the value at hand

    def strip(value: Any) -> Any:
        if not isinstance(value, (dict, list)):
            return value
        if id(value) in inside:
            raise NeurohoverError(
                f"result={brief(result)} is not allowed: it holds itself (a {type(value).__name__} inside its own), as no stored result (JSON) can"
            )
        inside.add(id(value))
        out = {k: strip(v) for k, v in value.items() if k != "timing"} if isinstance(value, dict) else [strip(v) for v in value]
        inside.discard(id(value))
        return out

    try:
        return strip(result)
    except RecursionError:
        raise NeurohoverError(f"result={brief(result)} is not allowed: it is nested too deep to read (past Python's recursion limit)") from None
