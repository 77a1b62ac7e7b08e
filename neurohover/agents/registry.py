"""Agents by name: the one registry that the CLI, the competitions and the experiments read.

Every module of :mod:`neurohover.agents` that declares ``AGENT_SPECS`` (a sequence of
:class:`~neurohover.agents.spec.AgentSpec`) is found here; adding an agent is one new module in
this package (see the README's contributor section).
"""

from __future__ import annotations

import dataclasses
import importlib
import pkgutil

from ..errors import NeurohoverError, brief
from ..integrations.flying import generic_sigma_problem
from ..policysets import PolicySet, load_policy_set
from ..tasks import TaskFamily, get_task_family
from .protocol import Agent
from .spec import AgentOptions, AgentPolicies, AgentSpec

# Modules listed first come first in help texts and messages; any other module follows by name.
_FIRST = ("reference", "model_free", "model_based", "hybrid")


def discover(package: str) -> dict[str, AgentSpec]:
    """The ``AGENT_SPECS`` of every module of ``package``, by agent name, in a stable order."""
    path = importlib.import_module(package).__path__
    names = sorted((m.name for m in pkgutil.iter_modules(path)), key=lambda n: (_FIRST.index(n) if n in _FIRST else len(_FIRST), n))
    specs: dict[str, AgentSpec] = {}
    for name in names:
        if name == "registry":
            continue
        for spec in getattr(importlib.import_module(f"{package}.{name}"), "AGENT_SPECS", ()):
            if spec.name in specs:
                raise RuntimeError(f"agent {spec.name!r} is declared twice (module {name!r} and another)")
            specs[spec.name] = spec
    return specs


#: Every agent by name, in a stable order.
AGENTS: dict[str, AgentSpec] = discover(__package__)
#: The agents that take hybrid settings (safeguard and replacement rule): those whose own settings are HybridSettings.
HYBRID_AGENTS: tuple[str, ...] = tuple(name for name, spec in AGENTS.items() if spec.settings is not None and spec.settings.UNIT_KEY == "hybrid")


def agent_spec(name: str, task: str | TaskFamily | None = None) -> AgentSpec:
    """The spec of agent ``name``; refuses unknown names and, given ``task`` (a name or a family), agents for other tasks."""
    if not isinstance(name, str) or name not in AGENTS:  # a list was unhashable's TypeError
        raise NeurohoverError(f"unknown agent {brief(name)}: allowed {', '.join(AGENTS)}")
    spec = AGENTS[name]
    if task is not None:
        family = get_task_family(task) if isinstance(task, str) else task
        if not spec.applies_to(family):
            raise NeurohoverError(f"agent {name!r} does not apply to task {family.name!r}: it runs on {', '.join(spec.tasks)}")
    return spec


def policies_from_set(spec: AgentSpec, ps: PolicySet) -> AgentPolicies:
    """The policies of a policy set that agent ``spec`` flies."""
    generic = None
    if "generic" in spec.needs:
        kind = spec.generic_kind if ps.generics else None
        generic = ps.generics[kind] if kind is not None and ps.generics else ps.generic
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
        idle = ", ".join(name for name, s in AGENTS.items() if not s.needs and s.applies_to(family))
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
        idle = ", ".join(name for name, s in AGENTS.items() if not s.needs)  # a few: the rest (16 now) is a long list
        raise NeurohoverError(
            f"policy_dir={brief(policy_dir)} is not allowed for agent {spec.name!r}: it flies no policy set, so leave it out "
            f"(a policy set's directory applies to every agent but {idle})"
        )


def check_agent(name: str, family: TaskFamily, policy_dir: str | None = None) -> None:
    """Refuse unknown agents, agents for another task, a policy directory for an agent that flies no policy set, and
    missing or mismatched policy sets, with clear messages."""
    spec = agent_spec(name, family)
    _refuse_idle_policy_dir(spec, policy_dir)
    if spec.needs:
        spec.build(policies_from_set(spec, _policy_set(family, policy_dir)), AgentOptions())


def make_agent(name: str, family: TaskFamily | str, *, policy_dir: str | None = None, options: AgentOptions = AgentOptions()) -> Agent:
    """A fresh agent called ``name`` for ``family`` (a task family or its name), flying the policies of its policy set
    (``policy_dir``: the directory of policy sets, default the shipped ones; only for an agent that flies a policy set)."""
    if isinstance(family, str):  # a task's name, as agent_spec takes it (was an AttributeError; bad-input trial)
        family = get_task_family(family)
    if not isinstance(family, TaskFamily):
        raise NeurohoverError(f"family={family!r:.80} is not allowed: give a task family (neurohover.get_task_family('ghh08')) or its name")
    if not isinstance(options, AgentOptions):
        raise NeurohoverError(f"options={options!r:.80} is not allowed: give an AgentOptions")
    spec = agent_spec(name, family)
    _refuse_idle_policy_dir(spec, policy_dir)
    options = _checked_options(spec, options)
    if policy_dir is not None:
        from ..paths import checked_path

        policy_dir = str(checked_path(policy_dir, "policy_dir", "policy set's directory"))  # 3 was a TypeError (fourth trial)
    policies = policies_from_set(spec, _policy_set(family, policy_dir)) if spec.needs else AgentPolicies()
    agent = spec.build(policies, options)
    agent.made_for = (family.name, family.sigma)  # run_test refuses another family (tenth trial)
    return agent


def _checked_options(spec: AgentSpec, options: AgentOptions) -> AgentOptions:
    """``options`` as ``spec``'s build reads them: an evolution that is a ModelEvolution, settings of the agent's own class
    (a dict is read by that class); settings for an agent without any, or of another class, refused (fourth trial: they
    were accepted and ignored, or an AttributeError once the agent learned)."""
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
    return options


__all__ = ["AGENTS", "HYBRID_AGENTS", "AgentOptions", "AgentPolicies", "AgentSpec", "agent_spec", "check_agent", "discover", "make_agent", "policies_from_set"]
