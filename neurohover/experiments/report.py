"""``neurohover report``: the paper's figures from a results store, and ``report.md`` beside the paper.

For every experiment (and scale) in the store the report has: a header stating scale, settings,
units done, wall time, sessions and cores; the figure in the paper's form (champion error over
episodes on a log scale for Figures 2, 12, 13, 15; mean cumulative error per episode on a linear
and a log scale for Figures 7, 8, 11, 16); the tables with the paper's numbers beside ours
(Tables 3 and 4, crash counts, per-episode returns); Student's and Welch's t tests
(``scipy.stats.ttest_ind``) for the comparisons where the paper gave p-values; an automatically
generated comparison line per anchor ("ours X vs paper Y"); the paper's claims; and an empty
discussion paragraph to fill in.

Error is minus the return (lower is better), as in the paper's plots.
"""

from __future__ import annotations

import json
import sys
import time
from pathlib import Path

import numpy as np

from ..errors import NeurohoverError, OutputError, brief, check_flag, whole_number
from ..filekinds import REPORT_HEADER, REPORT_KIND
from .config import ORDER, ExperimentConfig, check_paper_table, shipped_counterpart, with_shipped_paper
from .export import checked_units
from .keys import UnitKey
from .report_base import Section, agent_panel, fmt, log_errors, new_figure, paired_p, paired_verdict, ratio_verdict, sd, table
from .report_claims import PAPER_FIGURES, DiscussionError, claims_section, conclusions_discussion, read_discussion
from .report_evolution import EvolutionSection
from .report_factorial import FitFactorial, authors_policy_runs, authors_policy_section, test_run_effects, test_run_figure, varies
from .report_models import SensorModels
from .report_readme import Status, fill_generated, linked_claims, status_table
from .report_scale import header_note, paper_protocol, quick_discussion, scale_note
from .results import ModelResult, TestRunResult
from .settings import Group, ModelLearningSettings
from .store import Store
from .wins import DEFAULT_DRAWS, win_probabilities

#: Competition lengths the report gives win odds for (the paper's analysis of GHH-09: 20 runs).
WIN_RUNS = (1, 5, 20)


def crash_rate(crashes: int, episodes: int) -> str:
    """A crash fraction as a percentage that is never 0 % when some episode crashed (1 of 20,000: 0.005%)."""
    if not whole_number(episodes) or episodes < 1:  # (1, 0) was a ZeroDivisionError, (5, 2) '250%' (thirteenth trial, F20)
        raise NeurohoverError(f"episodes={brief(episodes)} is not allowed: give a whole number of episodes >= 1")
    if not whole_number(crashes) or not 0 <= crashes <= episodes:
        raise NeurohoverError(f"crashes={brief(crashes)} is not allowed: give a whole number of crashed episodes from 0 to episodes={episodes}")
    rate = int(crashes) / int(episodes)
    return f"{rate:.0%}" if rate == 0 or rate >= 0.01 else f"{100 * rate:.2g}%"


def _runs(n: int) -> str:
    return f"{n} run{'s' if n > 1 else ''}"


class _ModelLearning(Section):
    def figure(self) -> str | None:
        data: dict[str, list[ModelResult]] = {m: self.group("model", m) for m in self.s.methods}
        data = {m: v for m, v in data.items() if v}
        if not data:
            return None
        fig, axes = new_figure(figsize=(6.5, 4))
        ax = axes[0, 0]
        errors = [log_errors([float(r.test_mean) for r in v]) for v in data.values()]
        ax.boxplot(errors)
        ax.set_xticks(range(1, len(data) + 1), [m.upper() for m in data])
        ax.set_yscale("log")
        ax.set_ylabel("error of the evolved policy in the true MDP (log scale)")
        ax.set_title(f"Table 4: policies evolved on learned models ({self.cfg.scale} scale)", fontsize=10)
        ax.grid(alpha=0.3, which="both")
        return self.save(fig)

    def body(self) -> str:
        ref = self.paper.get("table", {})
        rows = []
        means = {}
        for m in self.s.methods:
            units: list[ModelResult] = self.group("model", m)
            if not units:
                continue
            r = np.array([float(u.test_mean) for u in units])
            t = np.array([u.timing.learn_seconds for u in units])
            crashes = sum(u.test_crashes for u in units)
            episodes = sum(len(u.test_returns) for u in units)
            p = ref.get(m, {})
            means[m] = r.mean()
            rows.append(
                [
                    m.upper(),
                    str(len(units)),
                    fmt(t.mean()),
                    fmt(p.get("t")),
                    fmt(np.median(r)),
                    fmt(p.get("r_m")),
                    fmt(r.mean()),
                    fmt(p.get("r_a")),
                    fmt(sd(r)),
                    fmt(p.get("sd")),
                    f"{crashes} of {episodes}",
                ]
            )
            if p:
                self.add_claim(f"Table 4, {m.upper()}: median r_m", fmt(p.get("r_m")), fmt(np.median(r)), ratio_verdict(float(np.median(r)), float(p["r_m"])))
                self.comparisons.append(
                    f"{m.upper()}: our median {fmt(np.median(r))} vs paper {fmt(p.get('r_m'))}; our mean "
                    f"{fmt(r.mean())} vs paper {fmt(p.get('r_a'))}; our time to learn {fmt(t.mean())} s vs paper "
                    f"{fmt(p.get('t'))} s."
                )
        if ref and means:
            ours = sorted(means, key=lambda k: -means[k])
            paper = sorted((k for k in ref if k in means), key=lambda k: -ref[k]["r_a"])
            if paper:  # conclusion (2): of the paper's methods, LR's policies are the best (by mean return)
                mine = [k for k in ours if k in paper]
                self.add_claim(
                    "Table 4: the best method by mean return",
                    paper[0].upper(),
                    mine[0].upper(),
                    "holds" if mine[0] == paper[0] else "differs (ours: " + " > ".join(x.upper() for x in mine) + ")",
                    "ranking",
                )
            self.comparisons.append(
                "Ranking by mean return (best first): ours "
                + " > ".join(x.upper() for x in ours)
                + "; paper "
                + " > ".join(x.upper() for x in paper)
                + (" (same order)." if ours == paper else " (different order).")
            )
        return (
            "### Table 4\n\n"
            + table(["method", "MDPs", "t (s)", "paper t", "r_m", "paper r_m", "r_a", "paper r_a", "sd", "paper sd", "crashed episodes"], rows)
            + f"\n\nt: seconds to learn the model from one episode of flight data of the generic policy; r_m, r_a, sd: median, "
            f"mean and sd over MDPs of the evolved policy's mean return over {self.s.test_episodes} episodes in the true MDP.\n"
        )


class _TestRuns(Section):
    def groups(self) -> tuple[Group, ...]:
        return self.s.groups

    def runs(self, label: str) -> list[TestRunResult]:
        return self.group("run", label)

    def paired_runs(self, label: str) -> dict[str, TestRunResult]:
        """A group's runs by MDP and repetition (groups flying the same seeds pair on these keys)."""
        keys = sorted(k for k in self.results if (self.keys[k].stage, self.keys[k].group) == ("run", label))
        return dict(zip((f"{self.keys[k].mdp}/rep{self.keys[k].rep}" for k in keys), self.runs(label)))  # runs(): the same keys, in order

    def figure(self) -> str | None:
        if varies(self.groups()):  # the LR-fit factorial: a panel per agent, its fits told apart by colour and line
            fig = test_run_figure(self.groups(), self.runs, f"{self.cfg.title} ({self.cfg.scale} scale)")
            return None if fig is None else self.save(fig)
        data = {g.label: self.runs(g.label) for g in self.groups()}
        data = {k: v for k, v in data.items() if v}
        if not data:
            return None
        if len(data) > MAX_CURVES:  # too many for one panel: a panel per agent
            return self.save(self._panels_by_agent(data))
        fig, axes = new_figure(2, figsize=(11, 4.2))
        axes = axes[0]
        for i, (label, runs) in enumerate(data.items()):
            cum = -np.cumsum(np.array([[float(x) for x in r.returns] for r in runs]), axis=1).mean(axis=0)
            episodes = np.arange(1, cum.size + 1)
            for ax in axes:
                ax.plot(episodes, cum, label=f"{label} ({len(runs)} runs)", **curve_style(i))
        return self.save_panels(fig, axes, "episode", ("mean cumulative error (-cumulative reward)", "mean cumulative error (log scale)"))

    def _panels_by_agent(self, data: dict[str, list[TestRunResult]]):
        """One log-scale panel per agent (its groups' mean cumulative error, told apart by colour, then line
        style), each with its legend below it: a figure for the benchmarks' many AGENT/CONDITION groups."""
        by_agent: dict[str, list[str]] = {}
        for g in self.groups():
            if g.label in data:
                by_agent.setdefault(g.agent, []).append(g.label)
        n = len(by_agent)
        cols = min(n, 3)
        rows = -(-n // cols)
        fig, axes = new_figure(cols, figsize=(5.2 * cols, 4.8 * rows), nrows=rows)
        flat = list(np.ravel(axes))
        for ax, (agent, labels) in zip(flat, by_agent.items()):
            for i, label in enumerate(labels):
                runs = data[label]
                cum = -np.cumsum(np.array([[float(x) for x in r.returns] for r in runs]), axis=1).mean(axis=0)
                short = label[len(agent) + 1 :] if label.startswith(agent + "/") else label
                ax.plot(np.arange(1, cum.size + 1), cum, label=f"{short} ({len(runs)})", **curve_style(i))
            agent_panel(ax, agent)
        for ax in flat[n:]:
            ax.set_visible(False)
        fig.suptitle(f"{self.cfg.title} ({self.cfg.scale} scale); legend: condition (runs)", fontsize=10)
        return fig

    def _matrix(self) -> str:
        """Where every group is labelled AGENT/CONDITION (the benchmarks): agents by conditions, crash rate and median score."""
        split = [g.label.split("/") for g in self.groups()]
        if not split or any(len(parts) != 2 for parts in split):
            return ""
        agents = list(dict.fromkeys(a for a, _ in split))
        conditions = list(dict.fromkeys(c for _, c in split))
        rows = []
        for agent in agents:
            row = [agent]
            for condition in conditions:
                runs = self.runs(f"{agent}/{condition}")
                if not runs:
                    row.append("n/a")
                    continue
                episodes = sum(len(r.returns) for r in runs)
                crashes = sum(len(r.crash_episodes) for r in runs)
                row.append(f"{crash_rate(crashes, episodes)} ({fmt(np.median([float(r.score) for r in runs]))})")
            rows.append(row)
        return (
            "### Agents by condition\n\n"
            + table(["agent", *conditions], rows)
            + "\n\nEach cell: the fraction of all the group's episodes that crashed (the median over runs of the cumulative reward).\n\n"
        )

    def _wins(self) -> str:
        """Each agent's bootstrap probability of winning competitions of 1, 5 and 20 runs against the
        section's other groups that flew the same MDPs (the same sensors and drift)."""
        by_condition: dict[str, list[str]] = {}
        for g in self.groups():
            if self.runs(g.label):
                by_condition.setdefault(json.dumps([g.sensor, g.drift], sort_keys=True), []).append(g.label)
        rows = []
        for group in by_condition.values():
            runs: dict[str, dict[str, list[float]]] = {}
            for label in group:
                for r in self.runs(label):
                    runs.setdefault(label, {}).setdefault(r.mdp, []).append(float(r.score))
            common = set.intersection(*(set(m) for m in runs.values())) if len(runs) > 1 else set()
            if not common:
                continue
            odds = {n: win_probabilities(runs, n, seed=self.s.seed) for n in WIN_RUNS}
            if len(group) > 2:  # which agent (which risk level) to enter for each length
                self.comparisons.append(
                    "Best odds of winning a competition of "
                    + "; ".join(f"{_runs(n)}: {max(odds[n], key=odds[n].__getitem__)} ({max(odds[n].values()):.1%})" for n in WIN_RUNS)
                    + "."
                )
            for label in group:
                rows.append([label, str(len(common)), *(f"{odds[n][label]:.1%}" for n in WIN_RUNS)])
        if not rows:
            return ""
        return (
            "### Winning a competition\n\n"
            + table(["agent", "MDPs shared", *(f"P(win), {_runs(n)}" for n in WIN_RUNS)], rows)
            + f"\n\nEach agent's probability of the highest total cumulative reward in a competition of N runs against the other "
            f"{'groups that flew the same MDPs (sensors, drift)' if len(by_condition) > 1 else 'groups'}: {DEFAULT_DRAWS:,} simulated competitions, each "
            "N of the MDPs every agent flew (with replacement) and, on each, one of the agent's stored runs there; ties share "
            "the win (neurohover.experiments.wins; binomial standard error at most 0.5 %).\n\n"
        )

    def body(self) -> str:
        ref = self.paper.get("groups", {})
        rows, samples, labels = [], {}, {}
        for g in self.groups():
            label = g.label
            runs = self.runs(label)
            if not runs:
                continue
            scores = np.array([float(r.score) for r in runs])
            crashed = [r for r in runs if r.crash_episodes]
            clean = [r for r in runs if not r.crash_episodes]
            per_episode_clean = float(np.mean([float(x) for r in clean for x in r.returns])) if clean else float("nan")
            crash_rate = len(crashed) / len(runs)
            samples[label], labels[label] = scores.tolist(), label
            p = ref.get(label, {})
            rows.append(
                [
                    label,
                    str(len(runs)),
                    fmt(scores.mean()),
                    fmt(sd(scores)),
                    f"{len(crashed)} ({crash_rate:.1%})",
                    str(sum(len(r.crash_episodes) for r in runs)),
                    f"{p['crash_rate']:.2%}" if "crash_rate" in p else "n/a",
                    fmt(per_episode_clean),
                    fmt(p.get("return_per_episode_no_crash")),
                    fmt(np.mean([float(r.mean_return_after_learning) for r in runs])),
                    fmt(np.mean([r.learning_episodes for r in runs])),
                    str(sum(len(r.safeguard_episodes) for r in runs)),
                    fmt(np.mean([r.timing.seconds for r in runs])),
                ]
            )
            if "crash_rate" in p:
                near = abs(crash_rate - p["crash_rate"]) <= 0.05
                self.add_claim(f"{label}: runs with a crash", f"{p['crash_rate']:.1%}", f"{crash_rate:.1%}", "holds (within 5 points)" if near else "differs")
            if "return_per_episode_no_crash" in p and clean:
                paper_r = float(p["return_per_episode_no_crash"])
                self.add_claim(
                    f"{label}: return per episode (runs without a crash)", fmt(paper_r), fmt(per_episode_clean), ratio_verdict(per_episode_clean, paper_r)
                )
            if p:
                line = f"{label}: our crash rate {crash_rate:.1%} of {len(runs)} runs"
                if "crash_rate" in p:
                    line += f" vs paper {p['crash_rate']:.2%}"
                if "return_per_episode_no_crash" in p:
                    line += f"; our mean return per episode without a crash {fmt(per_episode_clean)} vs paper {fmt(p['return_per_episode_no_crash'])}"
                self.comparisons.append(line + ".")
        if samples:
            order = sorted(samples, key=lambda k: -np.mean(samples[k]))
            self.comparisons.append("Ranking by mean cumulative reward (best first): ours " + " > ".join(order) + ".")
        self.add_tests(samples, labels, "final cumulative reward")
        effects, lines = test_run_effects(self.groups(), self.paired_runs) if varies(self.groups()) else ("", [])
        self.comparisons += lines
        on_fig8 = any(g.seeds_of is not None and g.seeds_of["experiment"] == "fig8" for g in self.groups())
        if effects and on_fig8:  # the LR-fit factorial on Figure 8's runs: beside the authors' policy set flown on them
            theirs, lines = authors_policy_section(authors_policy_runs(self.out, self.cfg.scale), self.paired_runs)
            effects += theirs and f"\n{theirs}"
            self.comparisons += lines
        return (
            self._matrix()
            + self._wins()
            + "### Test runs\n\n"
            + table(
                [
                    "agent",
                    "runs",
                    "mean cumulative reward",
                    "sd",
                    "runs with a crash",
                    "crashes",
                    "paper crash rate",
                    "return/episode (runs without crash)",
                    "paper",
                    "return/episode after learning",
                    "learning episodes",
                    "safeguard fired",
                    "seconds/run",
                ],
                rows,
            )
            + f"\n\nEach run: {self.s.episodes} episodes of {self.s.n_steps} control steps on one MDP; the score is the "
            "cumulative reward of the whole run.\n" + (f"\n{effects}" if effects else "") + self._paired_elsewhere()
        )

    def _paired_elsewhere(self) -> str:
        """Each group that flew another experiment's seeds against that experiment's group, run by run (Wilcoxon)."""
        rows = []
        for g in self.groups():
            of = g.seeds_of
            if of is None or of["experiment"] == self.cfg.name or not self.runs(g.label):
                continue
            theirs = {}
            for u in self.store.units(of["experiment"], self.cfg.scale, missing_ok=True):
                key = UnitKey.parse(u["key"])
                if (key.stage, key.group) == ("run", of["group"]):
                    theirs[f"{key.mdp}/rep{key.rep}"] = float(u["result"]["score"])
            mine = {k: float(r.score) for k, r in self.paired_runs(g.label).items()}
            common = sorted(set(mine) & set(theirs))
            if len(common) < 2:
                continue
            diff = np.array([mine[k] - theirs[k] for k in common])
            p = paired_p(diff)
            a, b = float(np.mean([mine[k] for k in common])), float(np.mean([theirs[k] for k in common]))
            median = float(np.median(diff))
            rows.append(
                [
                    g.label,
                    f"{of['experiment']}/{of['group']}",
                    str(len(common)),
                    fmt(a),
                    fmt(b),
                    f"{int((diff > 0).sum())} of {len(common)}" if diff.any() else f"none: all {len(common)} equal",
                    fmt(median),
                    fmt(p) if diff.any() else "n/a",
                ]
            )
            if not diff.any():  # the same runs again (same seeds, gusts and settings): no test to run
                self.comparisons.append(
                    f"{g.label} vs {of['experiment']}'s {of['group']} on the same seeds: the same runs, all {len(common)} pairs equal "
                    f"(mean cumulative reward {fmt(a)})."
                )
                continue
            self.comparisons.append(
                f"{g.label} vs {of['experiment']}'s {of['group']} on the same seeds: {paired_verdict(diff)}, Wilcoxon p = {fmt(p)}"
                + (", significant at 5%" if p < 0.05 else ", not significant")
                + f"; mean cumulative reward {fmt(a)} vs {fmt(b)})."
            )
        if not rows:
            return ""
        return (
            "\n### Paired with another experiment's runs\n\n"
            + table(
                ["group", "paired with", "run pairs", "mean cumulative reward", "its pair's", "runs better", "median paired difference", "Wilcoxon p"], rows
            )
            + "\n\nEach run flew the seed of the other experiment's run of that group on the same MDP (the same gusts and draws); "
            "Wilcoxon signed-rank test on the run pairs' cumulative rewards.\n"
        )


#: The most curves one panel of a figure holds: more are split into panels (issue 33).
MAX_CURVES = 8


def curve_style(i: int) -> dict:
    """The i-th curve's colour (ten, then again) and line style (solid, dashed, dotted, dash-dot by tens)."""
    return {"color": f"C{i % 10}", "ls": ("-", "--", ":", "-.")[(i // 10) % 4]}


_SECTIONS = {"evolution": EvolutionSection, "model_learning": _ModelLearning, "test_runs": _TestRuns}

_SETTING_KEYS = (
    "task",
    "sigma",
    "target",
    "n_mdps",
    "runs",
    "episodes",
    "n_steps",
    "budget",
    "policy_budget",
    "generic_budget",
    "generics_per_agent",
    "model_budget",
    "validation_episodes",
    "test_episodes",
    "policies",
    "generic",
)


def _header(cfg: ExperimentConfig, store: Store, units: list[dict], total: int | None) -> str:
    done = len(units)
    sessions = store.sessions(cfg.name, cfg.scale)
    wall = sum(s["wall_seconds"] for s in sessions)
    cores = sorted({s["cores"] for s in sessions})
    executors = sorted({s["executor"] for s in sessions})
    unit_seconds = sum(u["seconds"] for u in units)
    settings = ", ".join(f"{k} = {cfg.settings[k]}" for k in _SETTING_KEYS if cfg.settings.get(k) not in (None, ""))
    if cfg.kind == "test_runs":
        settings += "; " + ", ".join(f"{g.label}: {g.n_mdps} {g.mdps} MDPs x {g.runs_per_mdp}" for g in getattr(cfg.typed, "groups", ()))
    status = "complete" if total is not None and done >= total else f"INCOMPLETE ({done} of {total} units)"
    return (
        f"- Paper: {cfg.paper_ref or 'n/a'}\n"
        f"- Scale: **{cfg.scale}** ({scale_note(cfg)}); config hash `{cfg.hash}`\n"
        f"- Settings: {settings}\n"
        f"- Units: {done} finished, {status}\n"
        f"- Time: {wall:.1f} s wall over {len(sessions)} session(s) on {', '.join(map(str, cores)) or '?'} core(s) "
        f"({', '.join(executors) or '?'}); {unit_seconds:.1f} s summed over units\n"
    )


def _section(cfg: ExperimentConfig, store: Store, out: Path, current: bool | None, scale: str) -> tuple[str, list[dict[str, str]], Status]:
    """The section of one stored experiment at the store row's ``scale`` (``current``: whether its shipped config still hashes as stored, for the
    status table; None: not a shipped config, or not paper scale)."""
    from .plans import plan

    _, units, results = checked_units(store, cfg.name, scale)  # results' check (the row's scale: T21-01), and its messages
    try:
        total = plan(cfg, {u["key"]: u["result"] for u in units}).total
    except NeurohoverError:
        total = None
    kind = _SECTIONS[cfg.kind]
    if isinstance(cfg.typed, ModelLearningSettings):
        kind = SensorModels if cfg.typed.conditions else FitFactorial if cfg.typed.fits else kind
    sec = kind(cfg, results, store, out)
    text = [f"## {cfg.title} [{cfg.scale}]\n", _header(cfg, store, units, total)]
    figure = sec.figure()
    if figure:
        text.append(f"![{cfg.title}]({figure})\n")
    text.append(sec.body())
    tests = sec.tests_markdown()
    if tests:
        text.append(tests)
    text.append("### Against the paper\n")
    lines = [f"- {c}" for c in sec.comparisons] or ["- (no numbers to compare)"]
    claims = cfg.paper.get("claims", [])
    if claims:
        lines.append("- The paper reports:")
        lines += [f"  - {c}" for c in claims]
    notes = cfg.paper.get("notes", [])
    if notes:
        lines.append("- Protocol notes (where this reproduction differs from, or had to fill in, the paper):")
        lines += [f"  - {n}" for n in notes]
    text.append("\n".join(lines) + "\n")
    text.append("### Discussion\n\n" + _discussion(cfg, out) + "\n")
    sessions = store.sessions(cfg.name, cfg.scale)
    wall, unit_time, cores = sum(s["wall_seconds"] for s in sessions), sum(u["seconds"] for u in units), tuple(sorted({s["cores"] for s in sessions}))
    status = Status(cfg.name, cfg.title, cfg.scale, len(units), total, wall, unit_time, cores, current=current)
    return "\n".join(text), sec.claims, status


def _discussion(cfg: ExperimentConfig, out: Path) -> str:
    """The hand-written discussion ``discussion/<name>-<scale>.md`` beside the report, kept across regenerations."""
    path = out / "discussion" / f"{cfg.name}-{cfg.scale}.md"
    text = read_discussion(path)
    if text is not None:
        return text
    if cfg.scale == "quick":
        return quick_discussion(cfg)
    return (
        f"_Not written yet: how these results compare with the paper's, and why, goes in "
        f"`discussion/{cfg.name}-{cfg.scale}.md` beside this report; `neurohover report` includes it._"
    )


def check_names(names: object) -> None:
    """NeurohoverError unless ``names`` (:func:`write_report`'s) is None or a non-empty list of experiment names, each
    given once; ``neurohover report`` asks it before making --out (T23-18: 'fig2 fig2' made the folder, then removed it).
    'fig2' was read as f, i, g, 2; 5 (any number, np.ma.masked) was a TypeError (seventeenth trial, T17-5)."""
    if names is not None and (not isinstance(names, (list, tuple)) or not all(isinstance(n, str) for n in names)):
        raise NeurohoverError(f"names={brief(names)} is not allowed: give a list of experiment names, e.g. ['fig2']")
    if names is not None and not names:  # [] was read as None and reported every experiment (thirteenth trial, F21)
        raise NeurohoverError(f"names={brief(names)} is not allowed: give one or more experiment names, or None for all")
    twice = sorted({n for n in names or () if list(names or ()).count(n) > 1})
    if twice:  # taken once without a word (seventh trial)
        raise NeurohoverError(f"experiment {twice[0]!r} is named more than once: give each once")


def write_report(store: Store, out: str | Path, *, scale: str | None = None, names: list[str] | None = None, refuse_all_damaged: bool = False) -> Path:
    """Write figures and ``report.md`` for the experiments in ``store`` into ``out``; returns report.md's path.

    A ``README.md`` in ``out`` with generated blocks gets them filled from the store (:mod:`.report_readme`). A damaged
    experiment is said in its place and in a warning line on stderr; ``refuse_all_damaged`` (the command line's): when
    every experiment asked for is damaged, NeurohoverError and nothing written, not a report of the damage alone.
    """
    from ..paths import created_dirs_removed_on_failure, output_dir
    from .report_replaced import held_report, note_replaced

    if not isinstance(store, Store):  # None was an AttributeError (sixth trial)
        raise NeurohoverError(f"store={store!r:.60} is not allowed: give a Store(PATH)")
    if scale is not None and not isinstance(scale, str):  # an array was numpy's 'truth value is ambiguous' (T18-3)
        raise NeurohoverError(f"scale={brief(scale)} is not allowed: give a scale's name, e.g. 'quick', or None for all")
    check_names(names)
    check_flag(refuse_all_damaged, "refuse_all_damaged", "write nothing when every experiment is damaged")
    with created_dirs_removed_on_failure():  # a failure leaves no directory it made, as on the command line (eleventh trial)
        out = output_dir(out, "report directory")  # '' wrote into the current directory; a file, a device or 5: OSError, TypeError
        held = held_report(out / "report.md")  # what it replaces, said once written (T40-A04)
        path = _write_report(store, out, scale, names, refuse_all_damaged)
    note_replaced(held, path, store.path)
    return path


def _write_report(store: Store, out: Path, scale: str | None, names: list[str] | None, refuse_all_damaged: bool) -> Path:
    from ..paths import printable, refuse_foreign_output, writing

    path = out / "report.md"
    refuse_foreign_output(path, "report", REPORT_KIND)  # before any figure: only a report.md it wrote is replaced (T28-A04)

    entries = [(n, s) for n, s, _, _ in store.experiments() if (scale is None or s == scale) and (not names or n in names)]
    if names:
        missing = [n for n in names if n not in {e[0] for e in entries}]
        if missing:
            raise NeurohoverError(store.missing_message(missing[0], scale))
    if not entries:
        raise NeurohoverError(store.missing_message(None, scale))
    rank = {n: i for i, n in enumerate(ORDER)}
    entries.sort(key=lambda e: (rank.get(e[0], len(ORDER)), e[0], e[1]))
    sections, toc = [], []
    claims: dict[str, tuple[str, list[dict[str, str]]]] = {}  # paper figure -> (its section's anchor, its claims)
    statuses: list[Status] = []
    from ..progress import progress_bar

    bar = progress_bar(iterable=entries, desc="report", unit="experiment", dynamic_ncols=True)  # a terminal only
    for name, sc in bar:
        try:
            stored = ExperimentConfig.from_dict(store.config(name, sc))
            shipped = shipped_counterpart(stored)  # loaded once: its [paper] table, and whether it still hashes as stored
            current = (None if shipped is None else shipped.hash == stored.hash) if sc == "paper" else None  # the status table: paper scale
            cfg = with_shipped_paper(stored, shipped)
            check_paper_table(cfg.paper, "the stored config")  # a store written before twelfth trial T1's check: said here, not a traceback
            text, checked, status = _section(cfg, store, out, current, sc)
        except (OutputError, DiscussionError):  # a full disk or an unreadable discussion is no damaged store (eighth, ninth trial)
            raise
        except NeurohoverError as err:  # one damaged experiment: said in its place, the others reported as usual
            sections.append(f"## {name} [{sc}]\n\n**Not reported: the store's copy is damaged.** {err}\n")
            toc.append(f"- [{name} [{sc}]](#{_anchor(name + ' [' + sc + ']')}) (damaged)")
            bar.write(f"neurohover report: warning: {name} ({sc}) is not reported: {err}", file=sys.stderr)  # said only in report.md (T19-07)
            continue
        statuses.append(status)
        sections.append(text)
        anchor = _anchor(cfg.title + " [" + sc + "]")
        toc.append(f"- [{cfg.title} [{sc}]](#{anchor})")
        if sc == "paper" and name in PAPER_FIGURES and paper_protocol(cfg):  # not one whose --set ran less (T34-A01)
            claims[name] = (anchor, checked)
    if refuse_all_damaged and not statuses:  # the command said "report written" and exited 0, the damage only inside (T19-07)
        raise NeurohoverError(f"nothing could be reported from {str(store.path)!r}: every experiment asked for is damaged (said above); no report written")
    head = (
        f"{REPORT_HEADER}\n"
        f"Generated {time.strftime('%Y-%m-%d %H:%M:%S')} from the results store `{printable(store.path)}`. Error is minus the "
        f"return (lower is better).{header_note({sc for _, sc in entries})}\n\n" + "\n".join(toc) + "\n"
    )
    summary = claims_section(claims) if claims else ""
    head += "\n" + summary + conclusions_discussion(out) if summary else ""
    refuse_foreign_output(path, "report", REPORT_KIND)  # made while the figures were drawn
    with writing(path, "report") as partial:  # a full disk left an empty report.md and an unnamed error (seventh trial)
        partial.write_text(head + "\n" + "\n".join(sections), encoding="utf-8", errors="backslashreplace")  # no text can fail it half-way
    readme = out / "README.md"
    fill_generated(readme, "status", status_table([s for s in statuses if s.scale == "paper"]))
    if summary:
        fill_generated(readme, "claims", linked_claims(summary))
    return path


def _anchor(title: str) -> str:
    keep = "".join(c for c in title.lower() if c.isalnum() or c in " -_")
    return keep.replace(" ", "-")
