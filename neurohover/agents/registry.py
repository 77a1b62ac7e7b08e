"""Agents by name: the one registry that the CLI, the competitions and the experiments read.

Every module of :mod:`neurohover.agents` that declares ``AGENT_SPECS`` (a sequence of
:class:`~neurohover.agents.spec.AgentSpec`) is found here; adding an agent is one new module in
this package (see the README's contributor section).
"""

from __future__ import annotations

import dataclasses
import importlib
import pkgutil
from collections.abc import Mapping, Sequence
from types import MappingProxyType
from typing import Any, cast

from ..errors import NeurohoverError, brief, package_path, registry_entry_problem
from ..integrations.flying import generic_sigma_problem
from ..policysets import PolicySet, load_policy_set
from ..settings_checks import checked_settings
from ..tasks import TaskFamily, get_task_family
from .protocol import Agent
from .spec import AgentOptions, AgentPolicies, AgentSpec

# Modules listed first come first in help texts and messages; any other module follows by name.
_FIRST = ("reference", "model_free", "model_based", "hybrid")


def discover(package: str) -> dict[str, AgentSpec]:
    """The ``AGENT_SPECS`` of every module of ``package`` (an importable package's dotted name, e.g.
    ``"neurohover.agents"``), by agent name, in a stable order. Modules whose names start with ``_`` are not imported:
    ``__main__`` ran a package's command line (``discover("neurohover")`` exited with the CLI's usage error, and a user's
    package's ``__main__.py`` ended the interpreter; T44-B06)."""
    path = _package_path(package)
    names = sorted(
        (m.name for m in pkgutil.iter_modules(path) if not m.name.startswith("_")), key=lambda n: (_FIRST.index(n) if n in _FIRST else len(_FIRST), n)
    )
    specs: dict[str, AgentSpec] = {}
    for name in names:
        if package == __package__ and name == "registry":
            continue
        declared = getattr(importlib.import_module(f"{package}.{name}"), "AGENT_SPECS", ())
        if isinstance(declared, (str, bytes)) or not isinstance(declared, Sequence) or not all(isinstance(s, AgentSpec) for s in declared):
            raise NeurohoverError(f"module {package}.{name}'s AGENT_SPECS={brief(declared)} is not allowed: declare a tuple of AgentSpecs")
        for spec in declared:
            if spec.name in specs:
                raise NeurohoverError(f"agent {spec.name!r} is declared twice (module {package}.{name} and another): give each agent a name of its own")
            specs[spec.name] = spec
    return specs


def _package_path(package: object) -> list[str]:
    """The ``__path__`` of the package called ``package``; NeurohoverError naming a value that is no dotted name, a
    package that is not importable or a module that is not a package (T44-B06; :func:`~neurohover.errors.package_path`,
    which the task families' discover shares)."""
    return package_path(package, __package__, "agent modules")


#: Every agent by name, in a stable order. A run-time entry is an AgentSpec under its own name; a shipped name holds its
#: shipped spec (:func:`agent_spec` checks the entry it reads).
AGENTS: dict[str, AgentSpec] = discover(__package__)
#: The agents this package's modules declare: what a shipped name holds wherever the registry is read (T44-B15).
SHIPPED_SPECS: Mapping[str, AgentSpec] = MappingProxyType(dict(AGENTS))
#: The agents that take hybrid settings (safeguard and replacement rule): those whose own settings are HybridSettings.
HYBRID_AGENTS: tuple[str, ...] = tuple(name for name, spec in AGENTS.items() if spec.settings is not None and spec.settings.UNIT_KEY == "hybrid")


def entry_problem(name: object, spec: object) -> str:
    """What is wrong with the registry entry ``AGENTS[name] = spec`` ('' when nothing): no :class:`AgentSpec` (a text was
    an AttributeError 'applies_to' in make_agent and compete, T44-B14), a shipped name holding another spec, or a key
    other than its spec's name (``AGENTS["alias"]`` made the best-of-two agent without a word, T44-B15)."""
    return registry_entry_problem("AGENTS", name, spec, AgentSpec, SHIPPED_SPECS, "agent", "spec")


def usable_agents() -> dict[str, AgentSpec]:
    """The registry's entries that :func:`agent_spec` takes: what a listing of every agent reads, so that one bad entry
    breaks only its own use."""
    return {name: spec for name, spec in list(AGENTS.items()) if not entry_problem(name, spec)}


def _task_family(task: object, what: str) -> TaskFamily:
    """``task`` as a task family: a family as it is, a task's name through :func:`get_task_family` (as make_agent takes
    it); anything else refused, naming ``what`` (check_agent's None or 'ghh08' was an AttributeError, T44-B07/B08)."""
    if isinstance(task, str):
        return get_task_family(task)
    if not isinstance(task, TaskFamily):
        raise NeurohoverError(f"{what}={brief(task)} is not allowed: give a task family (neurohover.get_task_family('ghh08')) or its name")
    return task


def agent_spec(name: str, task: str | TaskFamily | None = None) -> AgentSpec:
    """The spec of agent ``name``, its registry entry checked (:func:`entry_problem`); refuses unknown names and, given
    ``task`` (a name or a family, or an object with a family's ``name`` and ``generic_over_distribution``), agents for
    other tasks."""
    if not isinstance(name, str) or name not in AGENTS:  # a list was unhashable's TypeError
        raise NeurohoverError(f"unknown agent {brief(name)}: allowed {', '.join(usable_agents())}")
    spec = AGENTS[name]
    problem = entry_problem(name, spec)
    if problem:
        raise NeurohoverError(problem)
    if task is not None:
        # a family's stand-in (its name and generic_over_distribution: what applies_to reads) is taken as a family is
        like = isinstance(getattr(task, "name", None), str) and isinstance(getattr(task, "generic_over_distribution", None), bool)
        family = cast("TaskFamily", task) if like else _task_family(task, "task")
        if not spec.applies_to(family):
            raise NeurohoverError(f"agent {name!r} does not apply to task {family.name!r}: it runs on {', '.join(spec.tasks)}")
    return spec


def policies_from_set(spec: AgentSpec | str, ps: PolicySet) -> AgentPolicies:
    """The policies of policy set ``ps`` that agent ``spec`` (an AgentSpec or an agent's name) flies."""
    if isinstance(spec, str):
        spec = agent_spec(spec)
    if not isinstance(spec, AgentSpec):  # None or 5 were AttributeErrors (T44-B08)
        raise NeurohoverError(f"spec={brief(spec)} is not allowed: give an AgentSpec or an agent's name ({', '.join(usable_agents())})")
    if not isinstance(ps, PolicySet):
        raise NeurohoverError(f"ps={brief(ps)} is not allowed: give a PolicySet (neurohover.policysets.load_policy_set(task))")
    generic = None
    if "generic" in spec.needs:
        kind = spec.generic_kind if ps.generics else None
        generic = ps.generics[kind] if kind is not None and ps.generics else ps.generic
    if "safe" in spec.needs and not ps.safe and isinstance(ps.manifest, dict) and "safe" not in ps.manifest:
        raise NeurohoverError(  # not "safe=[]", a value the file does not hold (T47-B17)
            f"policy-set manifest {str(ps.directory / 'manifest.json')!r} has no 'safe' list, which agent {spec.name!r} needs: it flies "
            "exactly 2 safe specialised policies (build-policies writes the 2 the paper's rule chooses; give two indices of its specialised policies)"
        )
    if "safe" in spec.needs and len(ps.safe) != 2:  # the agent's own refusal named no file (tenth trial)
        raise NeurohoverError(
            f"policy-set manifest {str(ps.directory / 'manifest.json')!r}: safe={list(ps.safe)} is not allowed for agent {spec.name!r}: "
            "it flies exactly 2 safe specialised policies (give two indices of its specialised policies)"
        )
    return AgentPolicies(
        generic=generic,
        specialised=tuple(ps.specialised) if "specialised" in spec.needs else (),
        safe=tuple(ps.specialised[i] for i in ps.safe) if "safe" in spec.needs else (),
    )


def _policy_set(family: TaskFamily, policy_dir: str | None) -> PolicySet:
    """The family's policy set, refused when it was evolved for another breadth sigma."""
    ps = load_policy_set(family.name, policy_dir)
    built = generic_sigma_problem(family, ps.manifest.get("sigma"))  # one decision, compare_agent's too (T35-B07)
    if built is not None:
        idle = ", ".join(name for name, s in usable_agents().items() if not s.needs and s.applies_to(family))
        builds = get_task_family(family.name).sigma  # the sigma build-policies evolves the set's generics at
        # "build one for this sigma" could not be followed: build-policies evolves FGHH's generics at its family's sigma only (T29-A05)
        raise NeurohoverError(
            f"the {family.name} policy set in {str(ps.directory)!r} was evolved for sigma = {built}, not {family.sigma}, and "
            f"build-policies builds {family.name} sets for sigma = {builds} only: fly sigma = {built}, or an agent that flies no policy set "
            f"({idle}), or run a test-runs experiment config of your own with task = {family.name!r}, sigma = {family.sigma} and "
            f'policies = "evolve" (it evolves its own generics at that sigma; `neurohover reproduce MY.toml`)'
        )
    return ps


def _refuse_idle_policy_dir(spec: AgentSpec, policy_dir: object) -> None:
    """Refuse a policy directory for an agent that flies no policy set: it was ignored without a word (T17-8)."""
    if policy_dir is not None and not spec.needs:
        idle = ", ".join(name for name, s in usable_agents().items() if not s.needs)  # a few: the rest (16 now) is a long list
        raise NeurohoverError(
            f"policy_dir={brief(policy_dir)} is not allowed for agent {spec.name!r}: it flies no policy set, so leave it out "
            f"(a policy set's directory applies to every agent but {idle})"
        )


def check_agent(name: str, family: TaskFamily | str, policy_dir: str | None = None, settings: Any = None) -> None:
    """Refuse unknown agents, agents for another task (``family``: a task family or its name, as make_agent takes it), a
    policy directory for an agent that flies no policy set, missing or mismatched policy sets, and an agent its spec
    builds otherwise than its ``settings`` say (its settings, as AgentOptions takes them), with clear messages: the
    trial build that compete makes before it writes anything (a build dropping them was refused only once a run began;
    T55-B07)."""
    family = _task_family(family, "family")
    spec = agent_spec(name, family)
    _refuse_idle_policy_dir(spec, policy_dir)
    options = _checked_options(spec, AgentOptions(settings=settings))
    if spec.needs or settings is not None:
        spec.built(policies_from_set(spec, _policy_set(family, policy_dir)) if spec.needs else AgentPolicies(), options)


def make_agent(name: str, family: TaskFamily | str, *, policy_dir: str | None = None, options: AgentOptions = AgentOptions()) -> Agent:
    """A fresh agent called ``name`` for ``family`` (a task family or its name), flying the policies of its policy set
    (``policy_dir``: the directory of policy sets, default the shipped ones; only for an agent that flies a policy set)."""
    family = _task_family(family, "family")  # a task's name, as agent_spec takes it (was an AttributeError; bad-input trial)
    if not isinstance(options, AgentOptions):
        raise NeurohoverError(f"options={options!r:.80} is not allowed: give an AgentOptions")
    spec = agent_spec(name, family)
    _refuse_idle_policy_dir(spec, policy_dir)
    options = _checked_options(spec, options)
    if policy_dir is not None:
        from ..paths import checked_path

        policy_dir = str(checked_path(policy_dir, "policy_dir", "policy set's directory"))  # 3 was a TypeError (fourth trial)
    policies = policies_from_set(spec, _policy_set(family, policy_dir)) if spec.needs else AgentPolicies()
    agent = spec.built(policies, options)  # an Agent, checked before it is marked (T52-B14)
    agent.made_for = (family.name, family.sigma)  # run_test refuses another family (tenth trial)
    return agent


def _checked_options(spec: AgentSpec, options: AgentOptions) -> AgentOptions:
    """``options`` as ``spec``'s build reads them: an evolution that is a ModelEvolution, settings of the agent's own class
    (a dict is read by that class, an instance checked as a dict is, T56-B01); settings for an agent without any, or of
    another class, refused (fourth trial: they were accepted and ignored, or an AttributeError once the agent learned)."""
    from .model_based import ModelEvolution

    if options.evolution is not None and not isinstance(options.evolution, ModelEvolution):
        raise NeurohoverError(f"AgentOptions evolution={options.evolution!r:.60} is not allowed: give a ModelEvolution, or None (its defaults)")
    given = options.settings
    if given is None:
        return options
    if spec.settings is None:
        raise NeurohoverError(f"agent {spec.name!r} takes no settings, got {given!r:.60}")
    if isinstance(given, dict):
        return dataclasses.replace(options, settings=spec.settings.from_dict(given))
    if not isinstance(given, spec.settings):
        raise NeurohoverError(f"agent {spec.name!r} takes settings of {spec.settings.__name__} (or a dict of its fields), got {given!r:.60}")
    # an instance is checked as a dict of its fields is (S(k='x', rate=inf) flew unchecked, T56-B01), and the agent gets
    # its plain values (np.float32(0.1) as 0.1, T57-B02)
    return dataclasses.replace(options, settings=checked_settings(given, bad_what=type(given).__name__))


__all__ = [
    "AGENTS",
    "HYBRID_AGENTS",
    "SHIPPED_SPECS",
    "AgentOptions",
    "AgentPolicies",
    "AgentSpec",
    "agent_spec",
    "check_agent",
    "discover",
    "entry_problem",
    "make_agent",
    "policies_from_set",
    "usable_agents",
]
