"""``neurohover settings [NAME]``: every setting of a settings class (the evolution methods, the optimisers, NEAT, the
agents), its default, type and meaning, read from the class itself."""

from __future__ import annotations

import argparse

from ..errors import NeurohoverError, brief


def settings_classes() -> dict[str, type]:
    """Every settings class a run or an agent takes, by the name ``neurohover settings NAME`` knows it: the
    neuroevolution's two methods, each population optimiser, the authors' eonn, NEAT, and each agent's own."""
    from ..agents.fghh_code import CodeAgentSettings
    from ..agents.registry import usable_agents
    from ..evolution.eonn import EonnSettings
    from ..evolution.generational import GenerationalSettings
    from ..evolution.optimisers import OPTIMISERS
    from ..evolution.steady_state import SteadyStateSettings
    from ..integrations.neat import NeatSettings

    found: dict[str, type] = {"steady-state": SteadyStateSettings, "generational": GenerationalSettings}
    found.update({name: spec.settings for name, spec in OPTIMISERS.items()})
    found.update({"eonn": EonnSettings, "neat": NeatSettings, "authors-fghh": CodeAgentSettings})
    for agent in usable_agents().values():  # one entry per class, by its name (a bad registry entry breaks only its own use)
        if agent.settings is not None:
            found[_settings_name(agent.settings)] = agent.settings
    return found


def _settings_name(cls: type) -> str:
    """An agent's settings class as `neurohover settings` names it: IncrementalSettings -> incremental."""
    return cls.__name__.removesuffix("Settings").lower()


def cmd_settings(args: argparse.Namespace) -> int:
    """Print a settings class's table (name = default [type], then its help), or list the names."""
    from ..settingsdoc import format_settings, summary

    found = settings_classes()
    if args.name is None:
        width = max(map(len, found))
        for name, cls in found.items():
            print(f"{name:<{width}}  {summary(cls)}")
        return 0
    from ..agents.registry import usable_agents

    name = args.name
    if name not in found and name in (agents := usable_agents()):  # an agent's name: its settings class's entry
        own = agents[name].settings
        if own is None:
            raise NeurohoverError(f"agent {name!r} takes no settings of its own (agents that do: {', '.join(a for a, s in agents.items() if s.settings)})")
        name = _settings_name(own)
    if name == "ne":  # evolve --optimizer ne, the default: its settings are the method's (T36-A06)
        print("ne (evolve's default optimiser) takes the settings of steady-state on one MDP (--mdp) and of generational over a family:\n")
        print(format_settings(found["steady-state"], "steady-state") + "\n")
        print(format_settings(found["generational"], "generational"))
        return 0
    if name not in found:
        raise NeurohoverError(f"no settings named {brief(args.name)}: allowed {', '.join(found)}, ne, or an agent's name")
    print(format_settings(found[name], name))
    return 0


def register(sub) -> None:
    p = sub.add_parser(
        "settings",
        help="list the settings of a method, an optimiser or an agent, with their defaults and meaning",
        description="Every setting of a settings class (the evolution methods, the optimisers, NEAT, the agents): its default, "
        "type and meaning, read from the class itself. Without NAME: the names.",
    )
    p.add_argument("name", nargs="?", help="steady-state, generational, an optimizer (cma, ...), eonn, neat or an agent's settings")
    p.set_defaults(func=cmd_settings)
