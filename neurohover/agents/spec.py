"""What an agent is to the rest of neurohover: a name, the tasks it runs on, the policies it flies
and how to build it. Every agent module declares its agents in ``AGENT_SPECS``; the registry
(:mod:`neurohover.agents.registry`) collects them, and the CLI, the competitions and the
experiments read them from there.
"""

from __future__ import annotations

import dataclasses
from collections.abc import Callable
from dataclasses import dataclass
from typing import TYPE_CHECKING, Any, ClassVar

from ..errors import NeurohoverError, brief, check_name_text, frozen_dataclass_class, refused_signature
from ..policies import Policy
from ..settings_checks import settings_defaults_problem, settings_from_dict

if TYPE_CHECKING:
    from ..tasks import TaskFamily
    from .model_based import ModelEvolution
    from .protocol import Agent

#: The policies an agent can need: the generic policy, the specialised policies (one per training
#: MDP), and the safe pair of specialised policies (the paper's rule, :mod:`neurohover.policysets`).
POLICY_NEEDS = ("generic", "specialised", "safe")
#: FGHH's generic policies, by kind: how each was evolved (agents named ``<agent>-<kind>`` fly one).
FGHH_GENERIC_KINDS = (("zero", "on the zero setting"), ("fixed", "over G with fixed resampling"), ("race", "over G with selection races"))
#: Which task families an agent runs on, by what the families' policy sets hold: every family;
#: the families with specialised policies (one per training MDP: GHH-08, GHH-09, and any family
#: whose generic is not evolved over G); or the families whose generics are evolved over G, by kind (FGHH).
FAMILY_CONDITIONS = ("any", "specialised", "generics-by-kind")


@dataclass(frozen=True)
class AgentPolicies:
    """The policies one agent flies (those its spec ``needs``; the rest stay empty)."""

    generic: Policy | None = None
    specialised: tuple[Policy, ...] = ()
    safe: tuple[Policy, ...] = ()


@dataclass(frozen=True)
class AgentOptions:
    """What a run hands an agent's ``build``: ``evolution``, how the learning agents evolve policies
    on learned models (a ``ModelEvolution``, shared by all of them; None: its defaults), and
    ``settings``, the agent's own typed settings (an instance of its spec's ``settings`` class;
    None: that class's defaults)."""

    evolution: ModelEvolution | None = None
    settings: Any = None


class AgentSettings:
    """What an agent's own settings class provides (a frozen dataclass that also subclasses this):
    ``from_dict`` (unknown keys refused, a NeurohoverError for a bad value: one its ``__post_init__`` refuses, one
    that is not its field's type where that is int, float, bool or text, or a non-finite number), ``to_dict``, and
    ``from_unit``, the settings of an experiment's test-run unit: by default its params'
    ``agent_settings`` table, which the planner copies from the config group's ``settings``."""

    UNIT_KEY: ClassVar[str] = "agent_settings"

    @classmethod
    def from_dict(cls, values: dict) -> Any:
        return settings_from_dict(cls, values, unknown_what=cls.__name__, bad_what=cls.__name__)

    def to_dict(self) -> dict:
        return dataclasses.asdict(self)  # type: ignore[call-overload]  # subclasses are dataclasses

    @classmethod
    def from_unit(cls, params: dict) -> Any:
        return cls.from_dict(params.get(cls.UNIT_KEY) or {})

    def check_episode_steps(self, n_steps: int) -> None:
        """Refuse settings that cannot act in episodes of ``n_steps`` control steps (a NeurohoverError naming both): the
        settings class cannot see the episode length, so the run checks it here before any episode flies."""

    def check_episodes(self, agent: str, episodes: int) -> None:
        """Refuse settings with which ``agent`` cannot act within a run of ``episodes`` episodes (a NeurohoverError naming
        both): the settings class cannot see the run's length, so the competition checks it before any run."""

    @classmethod
    def unused(cls, agent: str, given: dict) -> str | None:
        """Why one of the ``given`` settings would do nothing for ``agent`` (refused rather than ignored): a non-empty
        one-line text, or None; a setting given at its default says nothing (a table written whole, as compete's, names
        every one). Its callers read it through :func:`unused_reason`, which checks the answer."""
        return None


def unused_reason(settings: type[AgentSettings], agent: str, given: dict) -> str | None:
    """``settings.unused(agent, given)``, the settings class's reason why one of the ``given`` settings would do nothing
    for ``agent``, or None; any other answer than None or a non-empty printable one-line text is refused (a
    NeurohoverError naming the agent, the method and the answer): '', True or 5 became a refusal of the settings that
    gave no reason, "agent 'a': " (T60-B06). The one call of it, for compete's table and an experiment group's."""
    why = settings.unused(agent, given)
    if why is None or (isinstance(why, str) and why.strip() and why.isprintable()):
        return why
    raise NeurohoverError(
        f"agent {agent!r}: its settings class {settings.__name__}'s unused() answered {type(why).__name__} {brief(why)}, which is not allowed: "
        "unused(agent, given) answers None (every setting given does something) or a non-empty one-line text saying why one would do nothing"
    )


@dataclass(frozen=True)
class AgentSpec:
    """One agent, as everything else sees it.

    Attributes
    ----------
    name : str
        What ``--agent`` and experiment configs call it.
    runs_on : {"any", "specialised", "generics-by-kind"}
        The task families it runs on (:data:`FAMILY_CONDITIONS`), a condition on the family rather
        than a list of names, so a new family gets every agent its policy set can serve.
    needs : frozenset of str
        Which of :data:`POLICY_NEEDS` it flies.
    build : callable
        ``build(policies, options) -> Agent``: a fresh agent from an :class:`AgentPolicies` and
        :class:`AgentOptions` (its signature checked when the spec is made, its answer by :meth:`built`).
    generic_kind : str or None
        On a family with generic policies by kind (FGHH: ``"zero"``, ``"fixed"``, ``"race"``),
        which one is this agent's generic policy.
    settings : type, optional
        Its own typed settings (a frozen dataclass subclass of :class:`AgentSettings`, every field with a default,
        finite and of its field's type where that is int, float, bool or text), handed to ``build`` as
        ``AgentOptions.settings``; None: it has none.
    learns_models : bool
        Whether it learns LR models from its flight data (so the model options, such as the
        wind model, apply to it).
    idle_model_options : frozenset of str
        The model options (a :class:`~neurohover.agents.model_based.ModelEvolution` field, a config group's key, a
        CLI option's name) that it learns models without: refused for it rather than ignored (the authors' FGHH agents
        always evolve on the model as the authors did, whatever ``model_policy`` says; T40-A03).
    summary : str
        One line for help texts.
    """

    name: str
    runs_on: str
    needs: frozenset[str]
    build: Callable[[AgentPolicies, AgentOptions], Agent]
    generic_kind: str | None = None
    settings: type[AgentSettings] | None = None
    learns_models: bool = False
    idle_model_options: frozenset[str] = frozenset()
    summary: str = ""

    def __post_init__(self) -> None:
        # NeurohoverErrors naming the value and what is allowed (they were bare ValueErrors, T52-B13)
        check_name_text("AgentSpec name", self.name, "the agent (what --agent and experiment configs call it)")
        needs = self.needs
        if not isinstance(needs, (frozenset, set, tuple, list)) or not all(isinstance(n, str) for n in needs):
            raise NeurohoverError(f"agent {self.name!r}: needs={brief(needs)} is not allowed: give a frozenset of {POLICY_NEEDS} (frozenset() for none)")
        unknown = set(needs) - set(POLICY_NEEDS)
        if unknown:
            raise NeurohoverError(f"agent {self.name!r}: unknown policy needs {sorted(unknown)}; allowed {POLICY_NEEDS}")
        object.__setattr__(self, "needs", frozenset(needs))  # a set or a list, as a frozen spec holds it (hashable)
        if not isinstance(self.runs_on, str) or self.runs_on not in FAMILY_CONDITIONS:
            raise NeurohoverError(f"agent {self.name!r}: runs_on={brief(self.runs_on)}; allowed {FAMILY_CONDITIONS}")
        kinds = tuple(kind for kind, _ in FGHH_GENERIC_KINDS)
        if self.generic_kind is not None and (not isinstance(self.generic_kind, str) or self.generic_kind not in kinds):
            raise NeurohoverError(f"agent {self.name!r}: generic_kind={brief(self.generic_kind)} is not allowed: give one of {kinds}, or None")
        if self.runs_on != "specialised" and "generic" in self.needs and self.generic_kind is None:
            raise NeurohoverError(
                f"agent {self.name!r} (runs_on={self.runs_on!r}) flies a generic policy on families with generics by kind: "
                f"name its generic_kind (one of {kinds})"
            )
        self._check_build_and_settings()

    def _check_build_and_settings(self) -> None:
        """Refuse a ``build`` that cannot be called as ``build(policies, options)`` (a TypeError at make_agent, T52-B14)
        and ``settings`` that are no frozen AgentSettings dataclass (an AttributeError or TypeError once settings were
        given, T52-B15) or whose defaults are missing, not their fields' plain types or not finite (T56-B01)."""
        build = self.build
        if not callable(build):
            raise NeurohoverError(f"agent {self.name!r}: build={brief(build)} is not allowed: give a callable; {_BUILD}")
        refused = refused_signature(build, 2)
        if refused:
            raise NeurohoverError(
                f"agent {self.name!r}: build of signature {brief(refused)} is not allowed: it is called as build(policies, options); "
                "give a callable of those two arguments answering an Agent"
            )
        cls = self.settings
        if cls is None:
            return
        if isinstance(cls, type) and issubclass(cls, AgentSettings) and frozen_dataclass_class(cls):
            defaults = settings_defaults_problem(cls)  # NaN or 'x' for an int flew unchecked (T56-B01)
            if defaults:
                raise NeurohoverError(f"agent {self.name!r}: its settings class {cls.__name__}'s {defaults}")
            return
        raise NeurohoverError(
            f"agent {self.name!r}: settings={brief(cls)} is not allowed: give a frozen dataclass subclass of "
            "neurohover.agents.spec.AgentSettings (@dataclass(frozen=True) class MySettings(AgentSettings): ...), or None (no settings)"
        )

    def built(self, policies: AgentPolicies, options: AgentOptions) -> Agent:
        """``build(policies, options)``, its answer checked to be an :class:`~neurohover.agents.protocol.Agent` (None or a
        Policy was an AttributeError or FrozenInstanceError where make_agent marked it, T52-B14) that, where settings were
        given and it holds settings of this kind (or None) as ``settings``, holds those given (T55-B07)."""
        from .protocol import Agent

        agent = self.build(policies, options)
        if not isinstance(agent, Agent):
            raise NeurohoverError(f"agent {self.name!r}: its build answered {brief(agent)}, which is not allowed: {_BUILD}")
        given, held = options.settings, getattr(agent, "settings", _NONE_HELD)
        # a build that dropped them flew with settings None while the run recorded those given (T55-B07); an agent that
        # holds them elsewhere (the shipped agents' settings are a ModelEvolution, say) is not compared
        if given is not None and (held is None or isinstance(held, AgentSettings)) and held != given:
            raise NeurohoverError(
                f"agent {self.name!r}: its build made an agent whose settings are {brief(held)}, not the {type(given).__name__} it was given "
                f"({brief(given)}), which the run records: hand options.settings on to the agent"
            )
        return agent

    def applies_to(self, family: TaskFamily) -> bool:
        """Whether the agent runs on ``family`` (its :attr:`runs_on` condition)."""
        by_kind = family.generic_over_distribution
        return self.runs_on == "any" or (self.runs_on == "generics-by-kind") == by_kind

    @property
    def tasks(self) -> tuple[str, ...]:
        """The registered task families it runs on, by name (for help texts)."""
        from ..tasks import get_task_family, task_names

        return tuple(name for name in task_names() if self.applies_to(get_task_family(name)))  # run-time entries too (T46-B07)


#: An agent without a ``settings`` attribute: it holds its settings, if any, where :meth:`AgentSpec.built` cannot see them.
_NONE_HELD = object()

#: What a spec's ``build`` must be, for messages.
_BUILD = "build(policies, options) (an AgentPolicies and an AgentOptions) must answer an Agent (neurohover.agents.protocol.Agent)"
