"""What the report says of an experiment's scale: ``quick`` (a smoke run), ``paper`` (the paper's protocol), or a compete
run's ``settings-HASH``, described by its own settings against the paper's (T26-A07: a run at the paper's 1000 episodes
of 6000 steps was called a smoke run)."""

from __future__ import annotations

import functools

from .config import ExperimentConfig, load_config
from .report_claims import PAPER_FIGURES

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


def scale_note(cfg: ExperimentConfig) -> str:
    """What the report's Scale line says of ``cfg``'s scale: quick, paper, or a settings-HASH run described by its own
    episodes, episode length and runs: paper-comparable where each is at least the paper's for the runs it corresponds
    to (:func:`paper_reference`), else which are shorter or fewer."""
    if cfg.scale == "paper":
        return "the paper protocol"
    if cfg.scale == "quick":
        return QUICK_NOTE
    s = cfg.settings
    if cfg.kind != "test_runs" or not s.get("groups"):
        return "a run of settings of its own (see Settings)"
    group = min(s["groups"], key=lambda g: g["n_mdps"] * g["runs_per_mdp"])
    runs = group["n_mdps"] * group["runs_per_mdp"]
    ours = f"{s['episodes']} episodes of {s['n_steps']} steps, {runs} runs"
    ref = paper_reference(s["task"], group["agent"], group["mdps"])
    if ref is None:
        return f"a run of settings of its own ({ours}); no paper figure runs task {s['task']} to compare it with"
    figure, episodes, n_steps, paper_runs = ref
    theirs = f"{figure} at paper scale: {episodes} episodes of {n_steps} steps, {paper_runs} runs"
    short = [
        *([f"fewer episodes ({s['episodes']} < {episodes})"] if s["episodes"] < episodes else []),
        *([f"shorter episodes ({s['n_steps']} < {n_steps} steps)"] if s["n_steps"] < n_steps else []),
        *([f"fewer runs ({runs} < {paper_runs})"] if runs < paper_runs else []),
    ]
    if not short:
        return f"paper-comparable: {ours}, at least the paper's ({theirs})"
    if s["episodes"] >= episodes and s["n_steps"] >= n_steps:  # the runs alone are fewer
        why = "magnitudes per episode compare with the paper's; its spread and tests rest on fewer runs"
    else:
        why = "magnitudes are not comparable with the paper"
    return f"settings of its own, short of the paper's ({theirs}): {', '.join(short)}; {why}"
