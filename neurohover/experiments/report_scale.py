"""What the report says of an experiment's scale: ``quick`` (a smoke run), ``paper`` (the paper's protocol), or a compete
run's ``settings-HASH``, described by its own settings against the paper's (T26-A07: a run at the paper's 1000 episodes
of 6000 steps was called a smoke run).

A config of one's own at its paper scale is the paper's protocol only where its stored settings are a shipped
experiment's at paper scale (the same config hash); else it is "its config's paper scale" (T49-A01: a copy of fig2 with
--set n_steps=20 was called the paper protocol and compared with the paper's numbers without a word). The store holds
the config's settings after --set and the path it was read from, not its ``[scales.paper]`` before --set: that table is
read from the config file at the stored path, as it reads now, and a run whose stored settings are below it is noted
as the shipped case is (``--set ran less than NAME at paper scale as its config says``); where that file no longer
reads as the same experiment (moved, a path relative to another folder, renamed), the note says that whether --set ran
less is not known."""

from __future__ import annotations

import functools
import math

from ..errors import NeurohoverError
from .config import POLICY_SOURCES, ExperimentConfig, load_config, shipped_configs, shipped_counterpart
from .overrides import ENTRIES, ENTRY_SCALE_LIKE, SCALE_LIKE
from .report_claims import PAPER_FIGURES
from .schema import ZERO_MEANS

QUICK_NOTE = "a fast smoke-scale run: short episodes and few runs; magnitudes are not comparable with the paper"
#: The page header's word on quick-scale sections (said only where the report has one).
QUICK_SENTENCE = (
    "Quick-scale runs use short episodes and few runs: they check the pipeline, and their numbers are not comparable in magnitude with the paper's."
)


def quick_discussion(cfg: ExperimentConfig) -> str:
    """A quick-scale section's discussion where none is written: its episode length is the config's own n_steps (a fixed
    "200-step episodes" was wrong for bench-sensor-models' 300 and any --set n_steps; T27-A02)."""
    return (
        f"Quick scale only: a check of the whole pipeline with {cfg.typed.n_steps}-step episodes, few runs and tiny evolution "
        "budgets. Its numbers are not comparable with the paper's; run `neurohover reproduce NAME --scale paper` for that."
    )


def header_note(scales: set[str] | list[str]) -> str:
    """The page header's sentence on the report's scales: the quick-scale one where a section is at quick scale, else none."""
    return f" {QUICK_SENTENCE}" if "quick" in scales else ""


@functools.cache
def _paper_groups() -> tuple[tuple[str, str, int, int, str, str, int], ...]:
    """(figure, task, episodes, n_steps, agent, mdps, runs) of every group of the paper's test-runs figures at paper scale."""
    out = []
    for name in PAPER_FIGURES:
        cfg = load_config(name, "paper")
        if cfg.kind != "test_runs":
            continue
        s = cfg.settings
        out += [(name, s["task"], s["episodes"], s["n_steps"], g["agent"], g["mdps"], g["n_mdps"] * g["runs_per_mdp"]) for g in s["groups"]]
    return tuple(out)


def paper_reference(task: str, agent: str, mdps: str) -> tuple[str, int, int, int] | None:
    """The paper's protocol for runs of ``agent`` on ``task``'s ``mdps`` MDPs: (figure, episodes, n_steps, runs) of the
    paper figure's group of that agent on those MDPs, else of its group on those MDPs with the most runs, else of its
    group on the task with the most runs (None: no paper figure runs the task)."""
    groups = [g for g in _paper_groups() if g[1] == task]
    if not groups:
        return None
    best = min(groups, key=lambda g: (g[4] != agent, g[5] != mdps, -g[6], PAPER_FIGURES.index(g[0])))
    return best[0], best[2], best[3], best[6]


def _shown(key: str, value: object) -> str:
    return "no cap" if key in ZERO_MEANS and value == 0 else str(value)


def _less(key: str, ours: object, paper: object) -> bool:
    """Whether setting ``key``'s value ``ours`` runs less than ``paper`` (a budget of 0 is no cap: more than any)."""
    if not all(isinstance(v, (int, float)) and not isinstance(v, bool) for v in (ours, paper)):
        return False
    if key in ZERO_MEANS:
        ours, paper = ours or math.inf, paper or math.inf
    return ours < paper  # type: ignore[operator]


def _shrunk(ours: dict, paper: dict) -> list[str]:
    """The settings of how much is run (:data:`~.overrides.SCALE_LIKE`, and a named entry's sizes) that ``ours`` sets
    lower than a shipped experiment's paper-scale ``paper``."""
    out = [f"{k} ({_shown(k, ours[k])} < {_shown(k, paper[k])})" for k in sorted(SCALE_LIKE) if k in ours and k in paper and _less(k, ours[k], paper[k])]
    for key, label in ENTRIES.items():
        before = {e.get(label): e for e in paper.get(key) or [] if isinstance(e, dict)}
        for entry in ours.get(key) or []:
            was = before.get(entry.get(label), {})
            out += [
                f"{key[:-1]} {entry[label]!r} {k} ({entry[k]} < {was[k]})"
                for k in sorted(ENTRY_SCALE_LIKE)
                if k in entry and k in was and _less(k, entry[k], was[k])
            ]
    return out


def paper_shortfall(cfg: ExperimentConfig) -> tuple[str, list[str]] | None:
    """The paper protocol ``cfg``'s runs compare with, and what they run less of than it ([]: nothing; None: nothing to
    compare with, at quick scale or in a config of one's own). The one decision of whether a run is the paper's protocol,
    which the report's Scale line and its paper-scale claims table both read: a paper-scale run of a shipped experiment
    against the shipped paper scale (its --set may change how much is run; one that shrank it was called the paper
    protocol and counted in the claims, T34-A01), a compete run's settings-HASH against the paper figure's runs of its
    agent (:func:`paper_reference`; T26-A07)."""
    s = cfg.settings
    if cfg.scale == "paper":
        shipped = shipped_counterpart(cfg)
        return None if shipped is None else (f"{cfg.name} at paper scale as shipped", _shrunk(s, shipped.settings))
    if cfg.scale == "quick" or cfg.kind != "test_runs" or not s.get("groups"):
        return None
    group = min(s["groups"], key=lambda g: g["n_mdps"] * g["runs_per_mdp"])
    runs = group["n_mdps"] * group["runs_per_mdp"]
    ref = paper_reference(s["task"], group["agent"], group["mdps"])
    if ref is None:
        return None
    figure, episodes, n_steps, paper_runs = ref
    short = [
        *([f"fewer episodes ({s['episodes']} < {episodes})"] if s["episodes"] < episodes else []),
        *([f"shorter episodes ({s['n_steps']} < {n_steps} steps)"] if s["n_steps"] < n_steps else []),
        *([f"fewer runs ({runs} < {paper_runs})"] if runs < paper_runs else []),
    ]
    return f"{figure} at paper scale: {episodes} episodes of {n_steps} steps, {paper_runs} runs", short


def _sources(cfg: ExperimentConfig) -> tuple[tuple[str, object], ...]:
    return tuple((k, cfg.settings[k]) for k in POLICY_SOURCES if k in cfg.settings)


@functools.cache
def _shipped_paper_hashes(sources: tuple[tuple[str, object], ...]) -> dict[str, str]:
    """Config hash -> name of each shipped experiment at paper scale with the policy sources ``sources`` (a kind that
    takes none of them is left out: its hash cannot be a stored one's that has them)."""
    out: dict[str, str] = {}
    for name in shipped_configs():
        try:
            out.setdefault(load_config(name, "paper", dict(sources)).hash, name)
        except NeurohoverError:
            continue
    return out


def shipped_match(cfg: ExperimentConfig) -> str | None:
    """The shipped experiment whose paper-scale settings a config of one's own at paper scale runs (the same config hash;
    None: none, or not a config of one's own at paper scale; T49-A01)."""
    if cfg.scale != "paper" or cfg.name in shipped_configs():
        return None
    try:
        return _shipped_paper_hashes(_sources(cfg)).get(cfg.hash)
    except TypeError:  # a policy source that cannot be a cache key (a table): no shipped config has one
        return None


def own_counterpart(cfg: ExperimentConfig) -> ExperimentConfig | None:
    """A stored config of one's own as its config file reads now, at the stored scale before --set (with the stored
    policy sources, as :func:`~.config.shipped_counterpart`); None where it is a shipped experiment, or its file at the
    stored path no longer reads as the same experiment of the same kind (moved, renamed, a relative path from another
    folder: the store holds no copy of the file's ``[scales]``; T49-A01)."""
    if not cfg.source or cfg.name in shipped_configs():
        return None
    try:
        own = load_config(cfg.source, cfg.scale, dict(_sources(cfg)))
    except NeurohoverError:
        return None
    return own if (own.name, own.kind) == (cfg.name, cfg.kind) else None


def paper_protocol(cfg: ExperimentConfig) -> bool:
    """Whether ``cfg`` is a paper-scale run of the paper's protocol, whose claims the paper-scale claims table judges:
    not one whose --set ran less of it (:func:`paper_shortfall`; T34-A01), nor a config of one's own unless its settings
    are a shipped experiment's at paper scale (:func:`shipped_match`; T49-A01)."""
    if cfg.scale != "paper":
        return False
    shortfall = paper_shortfall(cfg)
    if shortfall is None:
        return shipped_match(cfg) is not None
    return not shortfall[1]


_NOT_PAPER = "magnitudes are not comparable with the paper"


def own_paper_note(cfg: ExperimentConfig) -> str:
    """The Scale line's note on a config of one's own at paper scale (T49-A01): the paper protocol where its settings
    are a shipped experiment's at paper scale; not the paper's protocol where --set ran less than its config's own paper
    scale (as the file at its stored path reads now); else its config's paper scale, which is not the paper's protocol."""
    match = shipped_match(cfg)
    if match is not None:
        return f"the paper protocol: its settings are the shipped {match}'s at paper scale"
    own = own_counterpart(cfg)
    short = [] if own is None else _shrunk(cfg.settings, own.settings)
    if short:
        return (
            f"not the paper's protocol: --set ran less than {cfg.name} at paper scale as its config says "
            f"({cfg.source!r}, as it reads now): {', '.join(short)}; {_NOT_PAPER}"
        )
    gone = f"; its config {cfg.source!r} does not read now as this experiment, so whether --set ran less than its paper scale is not known"
    known = "" if own is not None else gone
    return (
        f"its config's paper scale, not the paper's protocol: a config of its own, whose settings are no shipped "
        f"experiment's at paper scale{known}; its numbers compare with the paper's only as far as its settings do (see Settings)"
    )


def scale_note(cfg: ExperimentConfig) -> str:
    """What the report's Scale line says of ``cfg``'s scale: quick, paper (or, where --set ran less than the paper
    scale, not the paper's protocol; a config of one's own: :func:`own_paper_note`), or a settings-HASH run described
    by its own episodes, episode length and runs: paper-comparable where each is at least the paper's for the runs it
    corresponds to (:func:`paper_reference`), else which are shorter or fewer (:func:`paper_shortfall`)."""
    if cfg.scale == "quick":
        return QUICK_NOTE
    shortfall = paper_shortfall(cfg)
    if cfg.scale == "paper":
        if shortfall is None:  # a config of one's own (T49-A01)
            return own_paper_note(cfg)
        if not shortfall[1]:
            return "the paper protocol"
        return (
            f"not the paper's protocol: --set ran less than {shortfall[0]}: {', '.join(shortfall[1])}; magnitudes are not "
            "comparable with the paper, and its claims are left out of the paper-scale claims table"
        )
    s = cfg.settings
    if cfg.kind != "test_runs" or not s.get("groups"):
        return "a run of settings of its own (see Settings)"
    group = min(s["groups"], key=lambda g: g["n_mdps"] * g["runs_per_mdp"])
    ours = f"{s['episodes']} episodes of {s['n_steps']} steps, {group['n_mdps'] * group['runs_per_mdp']} runs"
    if shortfall is None:
        return f"a run of settings of its own ({ours}); no paper figure runs task {s['task']} to compare it with"
    theirs, short = shortfall
    if not short:
        return f"paper-comparable: {ours}, at least the paper's ({theirs})"
    if not any(x.startswith(("fewer episodes", "shorter episodes")) for x in short):  # the runs alone are fewer
        why = "magnitudes per episode compare with the paper's; its spread and tests rest on fewer runs"
    else:
        why = "magnitudes are not comparable with the paper"
    return f"settings of its own, short of the paper's ({theirs}): {', '.join(short)}; {why}"
