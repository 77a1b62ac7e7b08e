"""The on-line test-run protocol (docs/model.md, On-line agents) and the interface every agent implements.

A test run flies N episodes on one MDP the agent does not know; its score is the cumulative
return of the whole run, so every crash counts. Before each episode the agent chooses the policy
(and optionally a safeguard fallback); after it, the agent sees the outcome (with flight data if it
asked for it) and may compute off-line, which is timed and recorded.

Writing an agent
----------------
Subclass :class:`Agent` and implement ``choose`` and ``update``::

    class AlwaysBaseline(Agent):
        name = "always-baseline"
        def choose(self, episode):
            return Choice(baseline_policy(), "baseline", final=True)
        def update(self, outcome):
            pass

Per-run state (what the agent learns in a run) is set in ``start(self, family, rng)``, which :func:`run_test` calls
before each run: an agent whose class defines no start and whose attributes changed in a run is refused a second run
(it would begin with what the last one left; make a new agent, or define start).

``final=True`` promises the agent will choose the same policy for every remaining episode, which
lets the harness fly the rest of the run in one parallel batch (same results, far faster).
``choose`` and ``update`` are called as plain Python calls ``agent.choose(episode)`` (a staticmethod or classmethod is
fine; an ``async def`` or generator method is refused: its call would not run its body); an agent with construction
arguments (policies, settings, counts) checks them in ``check_arguments``, which its constructor calls and
:func:`run_test` calls again before the run, so one changed after construction is refused too.
"""

from __future__ import annotations

import functools
import inspect
import time
from collections.abc import Sequence
from dataclasses import dataclass, field
from types import FunctionType

import numpy as np

from ..errors import NeurohoverError, brief, check_name_text, finite_real, refused_signature, whole_in
from ..evaluate import MAX_EPISODES_PER_CALL, DangerousState, PolicyTable, evaluate_jobs
from ..evolution.seeding import check_seed
from ..flightdata import FlightData
from ..flightmeta import compared_by_value
from ..policies import Policy
from ..sim.constants import CRASH_STEP_PENALTY, EPISODE_STEPS, MAX_EPISODE_STEPS, WORST_RETURN, lowest_return
from ..tasks import MDP, TaskFamily
from ..tasks.drift import Drift
from ..tasks.sensor import Sensor
from .kept_state import note_run_start, refuse_kept_state
from .spec import AgentSettings

REPEAT_CHUNK = 64  # most episodes per kernel call for a repeated choice


@dataclass(frozen=True)
class Choice:
    """What the agent flies next.

    Attributes
    ----------
    policy : Policy
    label : str
        Name of the policy in the run's records (e.g. ``"specialised:3"``, ``"model:2"``).
    fallback : Policy or None
        Safeguard fallback: on a dangerous state it flies the rest of the episode.
    dangerous : DangerousState
        What counts as a dangerous state (default: the authors' test, docs/model.md, Safeguard);
        another than the default needs a ``fallback``.
    record : bool
        Whether the agent wants this episode's flight data (not with ``final``).
    final : bool
        The agent keeps this choice for the rest of the run (flown in one batch, without ``update``).
    repeat : bool
        The agent keeps this choice until an episode in which the safeguard fires or the
        helicopter crashes. The harness then flies several episodes per kernel call and reports
        them to ``update`` in order, up to and including that episode (same results, faster).
    """

    policy: Policy
    label: str
    fallback: Policy | None = None
    dangerous: DangerousState = DangerousState()
    record: bool = False
    final: bool = False
    repeat: bool = False

    def __post_init__(self) -> None:
        # A hand-written agent's bad Choice was an AttributeError in the harness, or an int label in the records (thirteenth trial, F11).
        if not isinstance(self.policy, Policy):
            raise NeurohoverError(f"Choice policy={brief(self.policy)} is not allowed: give a Policy (neurohover.policies.baseline_policy(), for example)")
        check_name_text("Choice label", self.label, "the policy (e.g. 'specialised:3')")
        if self.fallback is not None and not isinstance(self.fallback, Policy):
            raise NeurohoverError(f"Choice fallback={brief(self.fallback)} is not allowed: give a Policy or None")
        if not isinstance(self.dangerous, DangerousState):
            raise NeurohoverError(f"Choice dangerous={brief(self.dangerous)} is not allowed: give a DangerousState")
        for name in ("record", "final", "repeat"):
            flag = getattr(self, name)
            if not isinstance(flag, (bool, np.bool_)):
                raise NeurohoverError(f"Choice {name}={brief(flag)} is not allowed: give True or False")
            object.__setattr__(self, name, bool(flag))
        if self.final and self.repeat:
            raise NeurohoverError(
                "Choice final=True with repeat=True is not allowed: final keeps the choice for the rest of the run, repeat until an event; give one"
            )
        if self.final and self.record:  # T34-B06: a final choice is flown in one batch, without update: the recording was never delivered
            raise NeurohoverError(
                "Choice final=True with record=True is not allowed: a final choice flies the rest of the run in one batch "
                "and update never sees its flight data; record an episode before choosing final"
            )
        if self.fallback is None and self.dangerous != DangerousState():  # T34-B07, the agent-level twin of T28-B16
            raise NeurohoverError(
                f"Choice dangerous={brief(self.dangerous)} is not allowed without a fallback: the safeguard hands control to the "
                "fallback, so alone the rule acts on nothing; give fallback= too, or leave dangerous out"
            )


def check_agent_settings(what: str, value: object, kind: type) -> None:
    """An agent's constructor argument ``what`` checked to be settings of class ``kind``: None, 'x' or another class's
    settings were stored, then an AttributeError at the first episode that read them (T39-B02)."""
    if not isinstance(value, kind):
        raise NeurohoverError(f"{what}={brief(value)} is not allowed: give a {kind.__name__} ({kind.__name__}() for its defaults)")


def _check_count(what: str, value: object, least: int) -> int:
    # T24-11: whole_in, so 1.5 or True "is not allowed" (a type) and an integer below least "is out of range"
    return whole_in(value, what, least, 2**63 - 1, "2**63-1")


def _check_return(ret: float, crashed: bool, steps: int) -> None:
    """NeurohoverError unless ``ret`` can be an episode's return (T27-B10): every reward is minus a sum of squares (so a
    return is <= 0); a step that does not crash earns at least -CRASH_STEP_PENALTY (the worst state within the crash
    limits), and a crash is charged that for each step left of a budget of at most MAX_EPISODE_STEPS (so no return is
    below -WORST_RETURN): a return of ``steps`` uncrashed steps is at least -CRASH_STEP_PENALTY * steps."""
    least = -WORST_RETURN if crashed else lowest_return(steps)
    if not least * (1 + 1e-9) <= ret <= 0:  # 1e-9: the rotation into the body frame keeps the squares to rounding
        how = "an episode that crashed" if crashed else f"{steps} steps that did not crash"
        raise NeurohoverError(
            f"EpisodeOutcome ret={brief(ret)} is out of range: allowed {least:.10g}..0 for {how} "
            f"(every reward is minus a sum of squares, at worst {CRASH_STEP_PENALTY:.6g} a step)"
        )


@dataclass(frozen=True)
class EpisodeOutcome:
    """What the agent learns after an episode."""

    episode: int
    ret: float
    crashed: bool
    steps: int
    safeguard_step: int  # control step at which the fallback took over, or -1
    flight_data: FlightData | None

    def __post_init__(self) -> None:
        # EpisodeOutcome('a', 'b', ...) was made, then refused by some agents with a TypeError and taken by others (thirteenth trial, F12).
        object.__setattr__(self, "episode", _check_count("EpisodeOutcome episode", self.episode, 0))  # ints, not NumPy's (T31-B02)
        if not finite_real(self.ret):
            raise NeurohoverError(f"EpisodeOutcome ret={brief(self.ret)} is not allowed: give the episode's return, a finite number")
        if not isinstance(self.crashed, (bool, np.bool_)):
            raise NeurohoverError(f"EpisodeOutcome crashed={brief(self.crashed)} is not allowed: give True or False")
        object.__setattr__(self, "steps", whole_in(self.steps, "EpisodeOutcome steps", 1, MAX_EPISODE_STEPS))  # T27-B10: 0 and 10**8 were taken
        object.__setattr__(self, "safeguard_step", _check_count("EpisodeOutcome safeguard_step", self.safeguard_step, -1))
        # T27-B10: a safeguard step past the episode, a positive return and -1e30 for 20 steps were taken
        if self.safeguard_step >= max(self.steps, 0):
            raise NeurohoverError(
                f"EpisodeOutcome safeguard_step={brief(self.safeguard_step)} of a {self.steps}-step episode is out of range: allowed -1 (never) or 0..steps-1"
            )
        _check_return(self.ret, self.crashed, self.steps)
        if self.flight_data is not None and not isinstance(self.flight_data, FlightData):
            raise NeurohoverError(f"EpisodeOutcome flight_data={brief(self.flight_data)} is not allowed: give the episode's FlightData or None")


def check_agent_policy(what: str, value: object) -> Policy:
    """An agent's constructor argument ``what`` checked to be a Policy, and returned: None was an AttributeError deep in
    the first flight (thirteenth trial, F11). The spec builds check their generic here too: an assert was a bare
    AssertionError (a clean refusal only under python -O, T47-B01)."""
    if not isinstance(value, Policy):
        raise NeurohoverError(f"{what}={brief(value)} is not allowed: give a Policy (neurohover.policies.load_policy(path), for example)")
    return value


def check_agent_policies(what: str, value: object, exactly: int | None = None) -> None:
    """An agent's constructor argument ``what`` checked to be a list of Policies (``exactly`` of them, or at least one):
    None was a TypeError from len() (thirteenth trial, F12)."""
    wanted = f"exactly {exactly}" if exactly is not None else "at least one"
    if isinstance(value, (str, bytes)) or not isinstance(value, Sequence) or not all(isinstance(p, Policy) for p in value):
        raise NeurohoverError(f"{what}={brief(value)} is not allowed: give a list of {wanted} Policy")
    if (len(value) != exactly) if exactly is not None else not value:
        raise NeurohoverError(f"{what} has {len(value)} policies, which is not allowed: give {wanted} {what} {'policies' if exactly else 'policy'}")


_CHECKED: set = set()  # the wrapped methods (a subclass's own method is wrapped once)


def _bound(method, agent):
    """``method`` (a class's own start, choose or update as defined: a function, a staticmethod, a classmethod, a property,
    another callable) as plain Python's ``agent.method`` gives it: through its descriptor. Called raw, a staticmethod got
    the agent too and a classmethod was no callable (T39-B01)."""
    get = getattr(type(method), "__get__", None)
    return method if get is None else get(method, agent, type(agent))


def _checked_start(start):
    @functools.wraps(start)
    def checked(self, family, rng):
        if not isinstance(family, TaskFamily):
            raise NeurohoverError(f"family={brief(family)} is not allowed: give a TaskFamily (neurohover.get_task_family(name))")
        if not isinstance(rng, np.random.Generator):
            raise NeurohoverError(f"rng={brief(rng)} is not allowed: give a numpy Generator (np.random.default_rng(seed))")
        self._asked_record = False
        return _bound(start, self)(family, rng)

    return checked


def _checked_choose(choose):
    @functools.wraps(choose)
    def checked(self, episode):
        choice = _bound(choose, self)(_check_count("episode", episode, 0))
        if not isinstance(choice, Choice):
            raise NeurohoverError(f"agent {self.name!r} chose {brief(choice)} for episode {episode}: its choose must return a Choice")
        self._asked_record = choice.record
        return choice

    return checked


def _checked_update(update):
    @functools.wraps(update)
    def checked(self, outcome):
        if not isinstance(outcome, EpisodeOutcome):
            raise NeurohoverError(f"outcome={brief(outcome)} is not allowed: give an EpisodeOutcome")
        if getattr(self, "_asked_record", False) and outcome.flight_data is None:  # the incremental agent's bare AssertionError
            raise NeurohoverError(f"outcome of episode {outcome.episode} has no flight data, but agent {self.name!r} chose to record it: give its FlightData")
        return _bound(update, self)(outcome)

    return checked


class Agent:
    """Base class of on-line agents. ``start`` is called once per test run, before episode 0."""

    name: str = "agent"
    #: The task family (name, sigma) :func:`~neurohover.agents.registry.make_agent` made it for, its policies that
    #: family's; :func:`run_test` refuses another (None: an agent built by hand, run on any family).
    made_for: tuple[str, float | None] | None = None

    def __init_subclass__(cls, **kwargs) -> None:
        # Every agent's start/choose/update goes through one check of its arguments and answer (thirteenth trial, F11, F12).
        super().__init_subclass__(**kwargs)
        for name, wrap in (("start", _checked_start), ("choose", _checked_choose), ("update", _checked_update)):
            if name in cls.__dict__ and cls.__dict__[name] not in _CHECKED:
                checked = wrap(cls.__dict__[name])
                _CHECKED.add(checked)
                setattr(cls, name, checked)

    def start(self, family: TaskFamily, rng: np.random.Generator) -> None:
        """Prepare for a new run on an unknown MDP of ``family`` (reset any per-run state)."""

    def choose(self, episode: int) -> Choice:  # abstract: a bare NotImplementedError named nothing (T35-B02)
        raise NeurohoverError(_unimplemented(self, "choose"))

    def update(self, outcome: EpisodeOutcome) -> None:  # abstract
        raise NeurohoverError(_unimplemented(self, "update"))

    def check_arguments(self) -> None:
        """Refuse the agent's construction arguments (its policies, settings and counts, as its attributes hold them) with
        a NeurohoverError naming the bad one: its constructor calls it, and :func:`run_test` again before the run starts,
        so one changed after construction (``agent.settings = None``, ``hybrid.safe = []``) is refused as the constructor
        refuses it (T39-B02). An agent with arguments of its own overrides it."""


def _unimplemented(agent: Agent, method: str) -> str:
    """The message for an agent whose class leaves ``method`` to the base class (T35-B02)."""
    return (
        f"agent class {type(agent).__name__} does not define {method}, which is not allowed: an Agent subclass implements both "
        "choose(self, episode) -> Choice and update(self, outcome: EpisodeOutcome) -> None (neurohover.agents.protocol)"
    )


#: How run_test calls each method of an agent (T39-B01: a keyword-only episode was Python's bare TypeError).
_CALLS = {"start": ("start(family, rng)", 2), "choose": ("choose(episode)", 1), "update": ("update(outcome)", 1)}


def _signature_problem(agent: Agent, method: str) -> str:
    """Why run_test cannot call the agent's ``method`` as plain Python would (an instance's attribute that is no callable,
    or a function whose signature cannot take run_test's arguments), or ''."""
    calls, n = _CALLS[method]
    what = f"agent class {type(agent).__name__}'s {method}"
    allowed = f"run_test calls agent.{calls}; give a method {method}(self, {calls[len(method) + 1 :]} (a staticmethod or classmethod called so is fine)"
    if method in vars(agent):  # set on the agent itself: Python calls it as it is
        given = vars(agent)[method]
        if not callable(given):
            return f"agent {agent.name!r}'s {method}={brief(given)} is not allowed: {allowed}"
        return _deferred_problem(f"agent {agent.name!r}'s {method}", given, allowed)
    own = inspect.getattr_static(type(agent), method)
    raw = getattr(own, "__wrapped__", own) if own in _CHECKED else own
    if not isinstance(raw, (FunctionType, staticmethod, classmethod)):  # a property or a callable object: read when called
        return ""
    refused = refused_signature(_bound(raw, agent), n)  # None: no signature to read, its call will say
    return f"{what} of signature {brief(refused)} is not allowed: {allowed}" if refused else _deferred_problem(what, _bound(raw, agent), allowed)


def _deferred_problem(what: str, fn: object, allowed: str) -> str:
    """Why ``fn`` would not run when called: an ``async def`` or a generator function (``yield`` in its body) only makes
    a coroutine or generator object, so an update's body never ran (T40-B04); or ''."""
    kinds = (
        (inspect.iscoroutinefunction, "an async def function", "a coroutine"),
        (inspect.isasyncgenfunction, "an async generator function", "an async generator"),
        (inspect.isgeneratorfunction, "a generator function (yield in its body)", "a generator"),
    )
    for test, kind, makes in kinds:
        if test(fn):
            return f"{what}, {kind}, is not allowed: its call only makes {makes} object, so its body never runs; {allowed}, a plain def"
    return ""


def check_agent_methods(agent: Agent) -> None:
    """Refuse an agent whose class leaves choose or update to the base class (T35-B02), or whose start, choose or update
    run_test cannot call (T39-B01), before any episode flies."""
    for method in ("choose", "update"):
        if getattr(getattr(agent, method, None), "__func__", None) is Agent.__dict__[method]:
            raise NeurohoverError(_unimplemented(agent, method))
    for method in _CALLS:
        problem = _signature_problem(agent, method)
        if problem:
            raise NeurohoverError(problem)


Agent.start = _checked_start(Agent.start)  # type: ignore[method-assign]  # agents that keep the base start are checked too
_CHECKED.add(Agent.start)


@compared_by_value  # == by value: arrays whole (T46-B08)
@dataclass(eq=False)
class RunResult:
    """Per-episode records of one test run; ``score`` is the cumulative return."""

    agent: str
    mdp: MDP
    returns: np.ndarray
    crashed: np.ndarray
    steps: np.ndarray
    policy: list[str]
    safeguard_fired: np.ndarray
    offline_seconds: np.ndarray = field(compare=False)  # wall-clock, like seconds: not part of ==
    seconds: float = field(default=0.0, compare=False)
    extra: dict = field(default_factory=dict)

    @property
    def score(self) -> float:
        return float(self.returns.sum())

    @property
    def cumulative(self) -> np.ndarray:
        return np.cumsum(self.returns)

    def rows(self) -> list[dict]:
        """One dict per episode (for CSV / JSON export)."""
        return [
            {
                "episode": e,
                "return": float(self.returns[e]),
                "crashed": bool(self.crashed[e]),
                "steps": int(self.steps[e]),
                "policy": self.policy[e],
                "safeguard_fired": bool(self.safeguard_fired[e]),
                "offline_seconds": float(self.offline_seconds[e]),
            }
            for e in range(self.returns.size)
        ]


def after_learning_start(policy_labels: Sequence[str]) -> int:
    """First episode from which the policy no longer changes (a run's ``policy`` labels)."""
    start = len(policy_labels) - 1
    while start > 0 and policy_labels[start - 1] == policy_labels[-1]:
        start -= 1
    return start


def _family_label(name: str, sigma: float | None) -> str:
    return name if sigma is None else f"{name} (sigma {sigma:g})"


def _refuse_own(mdp: MDP, what: str, own: Sensor | Drift, family: Sensor | Drift) -> None:
    def text(x: Sensor | Drift) -> str:  # the settings given, as the environments name a sensor
        return type(x).__name__ + "(" + ", ".join(f"{k}={v}" for k, v in x.to_dict().items() if v) + ")"

    raise NeurohoverError(
        f"mdp {mdp.label or mdp.family!r} carries its own {what} {text(own)}, not the run's family's {text(family)}: give "
        f"the MDP without one (mdp.with_{what}({type(own).__name__}())), or a family without a {what}, under which it flies its own"
    )


def _flown_mdp(mdp: MDP, family: TaskFamily) -> MDP:
    """``mdp`` as the run flies it: the family's sensor and drift by the environments' rule for an explicit MDP
    (``neurohover.envs.arguments.sensed_mdp``): an MDP of exact sensors takes the family's sensor, one without drift its
    drift, and an MDP carrying a sensor or drift other than the family's (not exact, not none) is refused. A plain MDP
    flew exact sensors and fixed dynamics in a sensor or drift family's run without a word (T29-B03)."""
    if not (family.sensor.exact or mdp.sensor == family.sensor):
        if not mdp.sensor.exact:
            _refuse_own(mdp, "sensor", mdp.sensor, family.sensor)
        mdp = mdp.with_sensor(family.sensor)
    if not (family.drift.none or mdp.drift == family.drift):
        if not mdp.drift.none:
            _refuse_own(mdp, "drift", mdp.drift, family.drift)
        mdp = mdp.with_drift(family.drift)
    return mdp


def _keeps_base_start(agent: Agent) -> bool:
    """Whether ``agent`` has no start of its own (nor one set on it): nothing resets its state between runs."""
    return "start" not in getattr(agent, "__dict__", {}) and inspect.getattr_static(type(agent), "start") is Agent.__dict__["start"]


def _check_run(agent, family, mdp, episodes, seed, n_steps) -> tuple[MDP, int, int, int]:
    """:func:`run_test`'s arguments checked (NeurohoverError naming the bad one); returns the MDP flown
    (:func:`_flown_mdp`), the seed, episodes and n_steps (Python ints: np.int8(127) + 1 overflowed, T31-B02)."""
    if not isinstance(agent, Agent):
        raise NeurohoverError(f"agent={agent!r:.80} is not allowed: give an Agent (neurohover.agents.registry.make_agent(name, family))")
    check_name_text("agent name", agent.name, "the agent in the run's records")  # RunResult.agent (T39-B04)
    check_agent_methods(agent)
    try:
        agent.check_arguments()  # its arguments as its constructor checks them: changed after construction (T39-B02)
    except NeurohoverError as err:
        raise NeurohoverError(f"agent {agent.name!r}: {err}") from None
    except AttributeError as err:  # a subclass whose own __init__ skipped its base class's: a bare AttributeError
        if err.obj is not agent:
            raise
        raise NeurohoverError(
            f"agent {agent.name!r} has no attribute {err.name!r}, which is not allowed: its class {type(agent).__name__} defines __init__ "
            f"without calling its base class's, which sets it (call super().__init__(...) in {type(agent).__name__}.__init__)"
        ) from None
    if _keeps_base_start(agent):  # nothing resets what its last run left (T49-B02)
        refuse_kept_state(agent)
    if not isinstance(family, TaskFamily):
        raise NeurohoverError(f"family={family!r:.80} is not allowed: give a TaskFamily (neurohover.get_task_family(name))")
    if not isinstance(mdp, MDP):
        raise NeurohoverError(f"mdp={mdp!r:.80} is not allowed: give an MDP (family.mdp('test:3'), for example)")
    made = agent.made_for
    if made is not None and not (isinstance(made, tuple) and len(made) == 2 and isinstance(made[0], str)):  # [] was a TypeError (T39-B02)
        raise NeurohoverError(
            f"agent {agent.name!r}'s made_for={brief(made)} is not allowed: give None (an agent built by hand) or the (family name, sigma) make_agent sets"
        )
    if made is not None and made != (family.name, family.sigma):  # GHH-08's policies flew FGHH without a word (tenth trial)
        raise NeurohoverError(
            f"agent {agent.name!r} was made for {_family_label(*made)}, but the run's family is {_family_label(family.name, family.sigma)}: "
            f"make the agent for it (make_agent(name, family))"
        )
    if mdp.family != family.name:  # the agent prepares for its family (its policies, safe pairs): another family's MDP is a mix-up
        if mdp.family == "model":  # a learned model records no family it was learned for: a test run on one is not its family's (T44-B16)
            raise NeurohoverError(
                f"mdp {mdp.label!r} is a model MDP, but the run's family is {family.name}: an agent's test run flies an MDP of its "
                f"family (its policies were chosen for {family.name}); fly a learned model's MDP with evaluate, evolve or a Gymnasium "
                f"environment, or give an MDP of {family.name}"
            )
        raise NeurohoverError(f"mdp {mdp.label!r} is a {mdp.family} MDP, but the run's family is {family.name}: give an MDP of {family.name}")
    mdp = _flown_mdp(mdp, family)
    # T24-11: whole_in, so 1.5 or True "is not allowed" and 0 "is out of range"; the bound check_episode_count had
    episodes = whole_in(episodes, "episodes", 1, MAX_EPISODES_PER_CALL, f"{MAX_EPISODES_PER_CALL:,} (episodes in one call)")
    mdp.drift.check_run(episodes)
    n_steps = whole_in(n_steps, "n_steps", 1, MAX_EPISODE_STEPS)  # as evaluate_jobs checks it, before the agent starts
    settings = getattr(agent, "settings", None)
    if isinstance(settings, AgentSettings):
        settings.check_episode_steps(n_steps)  # settings that cannot act in episodes this long (twelfth trial, S3)
    seed = check_seed(seed)
    if _keeps_base_start(agent):  # the run starts: what its attributes hold now, compared when the next starts
        note_run_start(agent)
    return mdp, seed, episodes, n_steps


def _chosen(agent: Agent, e: int, flown: dict[str, tuple[Policy, int]]) -> Choice:
    """The agent's choice for episode ``e``, checked: a Choice (a Policy was an AttributeError on .final; thirteenth
    trial, F11) whose label names one policy over the run (``flown``: each label's policy and first episode, updated);
    one label flying two policies recorded the learning episodes as the final policy's (T55-B06)."""
    choice = agent.choose(e)
    if not isinstance(choice, Choice):
        raise NeurohoverError(f"agent {agent.name!r} chose {brief(choice)} for episode {e}: its choose must return a Choice")
    policy, first = flown.setdefault(choice.label, (choice.policy, e))
    if choice.policy != policy:  # (equal: the same topology and genome)
        other = "another topology" if choice.policy.topology != policy.topology else "another genome"
        raise NeurohoverError(
            f"agent {agent.name!r} chose label {brief(choice.label)} for episode {e} with a policy of {other} than it flew under that label from episode "
            f"{first}, which is not allowed: give each policy a label of its own (the label names the policy in the run's records)"
        )
    return choice


def run_test(
    agent: Agent,
    family: TaskFamily,
    mdp: MDP,
    *,
    episodes: int = 1000,
    seed: int = 0,
    n_steps: int = EPISODE_STEPS,
    threads: int | None = None,
    device: str = "cpu",
) -> RunResult:
    """Fly one test run of ``episodes`` episodes of ``agent`` on ``mdp``.

    Episode e's gusts come from stream (seed, e), so two agents run with the same seed meet the same noise. The agent's
    own randomness derives from ``seed`` as well, and so does the drift of an MDP with drifting dynamics (``mdp.drift``:
    episode e flies its row e, the agent unaware). ``device``: where the episodes in the MDP fly (the agent's own
    evolutions on models follow its ``ModelEvolution``). The family's sensor and drift apply as to the environments'
    explicit ``mdp``: an MDP of exact sensors flies through ``family.sensor``, one without drift drifts by
    ``family.drift``, an MDP's own flies beside a family's exact or none, one differing is refused (result.mdp: as flown).
    """
    mdp, seed, episodes, n_steps = _check_run(agent, family, mdp, episodes, seed, n_steps)
    start_time = time.perf_counter()
    agent.start(family, np.random.default_rng(np.random.SeedSequence([seed, 0xA6E27])))
    returns = np.zeros(episodes)
    crashed = np.zeros(episodes, dtype=bool)
    steps = np.zeros(episodes, dtype=np.int64)
    fired = np.zeros(episodes, dtype=bool)
    offline = np.zeros(episodes)
    labels: list[str] = [""] * episodes
    # Drifting dynamics (neurohover.tasks.drift): episode e flies drifted row e; else every episode flies the MDP.
    drifted = None if mdp.drift.none else mdp.drift.rows(mdp.row(), episodes, seed)

    def mdps_of(first: int, n: int):
        """The MDP rows and per-job row indices of episodes first..first+n-1."""
        if drifted is None:
            return mdp, np.zeros(n, dtype=np.int64)
        return drifted[first : first + n], np.arange(n, dtype=np.int64)

    e = 0
    chunk = 1
    flown: dict[str, tuple[Policy, int]] = {}
    while e < episodes:
        choice = _chosen(agent, e, flown)
        if choice.final:
            # The choice holds for the rest of the run: fly it in one parallel batch.
            rest = np.arange(e, episodes)
            zeros = np.zeros(rest.size, dtype=np.int64)
            table = PolicyTable.from_policies([choice.policy] + ([choice.fallback] if choice.fallback else []))
            rows, index = mdps_of(e, rest.size)
            ev = evaluate_jobs(
                table,
                rows,
                zeros,
                index,
                rest,
                seed=seed,
                n_steps=n_steps,
                threads=threads,
                device=device,
                fallback_index=np.full(rest.size, 1 if choice.fallback else -1),
                safeguard_limits=choice.dangerous.limits(),
            )
            returns[e:], crashed[e:], steps[e:] = ev.returns, ev.crashed, ev.steps
            fired[e:] = ev.safeguard_step >= 0
            labels[e:] = [choice.label] * rest.size
            break
        # A repeated choice flies ahead speculatively; the chunk doubles while no event cuts it short
        # and restarts at 1 after one, so frequent safeguard firings waste at most half the work.
        n = min(chunk, episodes - e) if choice.repeat and not choice.record else 1
        table = PolicyTable.from_policies([choice.policy] + ([choice.fallback] if choice.fallback else []))
        zeros = np.zeros(n, dtype=np.int64)
        rows, index = mdps_of(e, n)
        ev = evaluate_jobs(
            table,
            rows,
            zeros,
            index,
            np.arange(e, e + n),
            seed=seed,
            n_steps=n_steps,
            threads=threads,
            device=device,
            fallback_index=np.full(n, 1 if choice.fallback else -1),
            record=np.full(n, choice.record),
            safeguard_limits=choice.dangerous.limits(),
        )
        events = np.flatnonzero((ev.safeguard_step >= 0) | ev.crashed)
        n = int(events[0]) + 1 if events.size else n  # later episodes would have flown another choice
        chunk = 1 if events.size else min(2 * chunk, REPEAT_CHUNK)
        for i in range(n):
            returns[e], crashed[e], steps[e] = ev.returns[i], ev.crashed[i], ev.steps[i]
            fired[e] = ev.safeguard_step[i] >= 0
            labels[e] = choice.label
            t0 = time.perf_counter()
            agent.update(EpisodeOutcome(e, float(ev.returns[i]), bool(ev.crashed[i]), int(ev.steps[i]), int(ev.safeguard_step[i]), ev.flight_data))
            offline[e] = time.perf_counter() - t0
            e += 1
    return RunResult(agent.name, mdp, returns, crashed, steps, labels, fired, offline, time.perf_counter() - start_time)
