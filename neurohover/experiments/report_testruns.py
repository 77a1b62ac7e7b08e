"""The report's section of a test-runs experiment (Figures 7, 8, 11, 16; Table 3 and the agents' competitions): mean
cumulative error per episode, the groups' returns and crashes beside the paper's, paired and unpaired tests, and the
odds of winning a competition of N runs."""

from __future__ import annotations

import json

import numpy as np

from ..errors import NeurohoverError, brief, whole_number
from .keys import UnitKey
from .report_base import Section, agent_panel, fmt, new_figure, paired_p, paired_verdict, ratio_verdict, sd, table
from .report_factorial import authors_policy_runs, authors_policy_section, test_run_effects, test_run_figure, varies
from .results import TestRunResult
from .settings import Group
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


class TestRunsSection(Section):
    """A test-runs experiment's section: the groups' cumulative error, their tables against the paper's, paired tests and win odds."""

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
