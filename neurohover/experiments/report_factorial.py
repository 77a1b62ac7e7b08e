"""The report's sections of the LR-fit factorials (``lr-authors-table4``, ``lr-authors-fig8``; docs/model.md).

Three choices where our LR and the policies evolved on it differ from the authors' code, and the
model's substeps (``lr-substeps-table4``), each a factor with our level and another (:data:`FACTORS`).
A factor's **main effect** pairs every cell with the cell that differs from it in that factor alone,
on the same MDP (Table 4) or run (Figure 8's seeds), so each factor is measured over the other
factors' combinations: the median paired difference (the other level minus ours; returns, so
positive is better with the other level), how often the other is better, and a two-sided Wilcoxon
signed-rank test on the differences.
"""

from __future__ import annotations

from collections.abc import Callable, Mapping

import numpy as np

from ..models.lr import LEGACY_NOISE_ESTIMATE
from .report_base import Section, agent_panel, fmt, fmt_p, log_errors, new_figure, paired_p, table
from .results import ModelResult, TestRunResult

#: (setting, our level, the other level, what it is, whose the other level is). The first three are the authors'
#: choices; the model's substeps is our option against the paper's and the authors' one step (lr-substeps-table4).
FACTORS = (
    ("d_u", "keep", "discard", "the u constant D_u", "the authors' choice"),
    ("noise", "innovations", "rms", "the noise estimate", "the authors' choice"),
    ("model_policy", "ours", "authors", "the policy evolved on the model", "the authors' choice"),
    ("model_substeps", 1, 10, "the model's substeps per control step", "ten substeps"),
)
OURS = {f[0]: f[1] for f in FACTORS}
BAD_RETURN = -1000  # a Table 4 policy under this per episode is in the bad mode (about -14,000) rather than the good (about -150)


def levels(obj) -> dict[str, str | int]:
    """A fit's or group's level of each factor (a group's noise left out of a config written before
    2026-12-04 was innovations: :data:`neurohover.models.lr.LEGACY_NOISE_ESTIMATE`)."""
    out = {name: getattr(obj, name, ours) for name, ours, *_ in FACTORS}  # a setting a group lacks is at our level
    out["noise"] = out["noise"] or LEGACY_NOISE_ESTIMATE
    return out


def learns_models(group) -> bool:
    """Whether a group's agent learns models: as its registered spec says, else as the store records it (check_kind
    writes a noise estimate into every such group), so a store of a run-time agent this process has not registered is
    reported too, as its results are exported (it was a KeyError traceback; T59-B03)."""
    from ..agents.registry import usable_agents

    spec = usable_agents().get(group.agent)
    return spec.learns_models if spec is not None else group.noise is not None


def varies(objs) -> bool:
    """Whether these fits, or the groups among these that learn models, differ in a factor (a factorial)."""
    learners = [o for o in objs if not hasattr(o, "agent") or learns_models(o)]
    return len({tuple(sorted(levels(o).items())) for o in learners}) > 1


def main_effects(cells: Mapping[str, dict[str, str | int]], values: Mapping[str, Mapping[str, float]]) -> list[dict]:
    """Each factor's paired effect.

    Parameters
    ----------
    cells : mapping
        Cell label -> its levels (:func:`levels`).
    values : mapping
        Cell label -> {pairing key (MDP, run) -> value (higher is better)}.

    Returns
    -------
    list of dict
        Per factor that the cells vary: ``factor``, ``other`` (whose the other level is), ``pairs``, ``median``
        (the other level - ours), ``better`` (pairs where the other level is higher), ``p`` (Wilcoxon signed-rank,
        None without a nonzero difference).
    """
    out = []
    by_levels = {tuple(sorted(lv.items())): label for label, lv in cells.items()}
    for name, ours, theirs, what, other in FACTORS:
        diffs = []
        for label, lv in cells.items():
            if lv.get(name, ours) != theirs:
                continue
            partner = by_levels.get(tuple(sorted({**lv, name: ours}.items())))
            if partner is None:
                continue
            a, b = values.get(label, {}), values.get(partner, {})
            diffs += [a[k] - b[k] for k in a if k in b]
        d = np.array(diffs, dtype=float)
        if not d.size:  # no two cells differ in this factor alone: it is not varied here
            continue
        p = paired_p(d) if np.any(d != 0) else None
        out.append(
            {
                "factor": f"{what} ({name}: {ours} -> {theirs})",
                "other": other,
                "pairs": int(d.size),
                "median": float(np.median(d)) if d.size else float("nan"),
                "better": int(np.sum(d > 0)),
                "p": p,
            }
        )
    return out


def effects_table(effects: list[dict], what: str) -> str:
    rows = [[e["factor"], str(e["pairs"]), fmt(e["median"]), f"{e['better']} of {e['pairs']}", fmt_p(e["p"]) if e["p"] is not None else "n/a"] for e in effects]
    return table(["factor", "pairs", f"median paired difference of {what} (other level - ours)", "other level better", "Wilcoxon p"], rows)


def effect_lines(effects: list[dict], what: str) -> list[str]:
    """One comparison line per factor: direction and significance."""
    lines = []
    for e in effects:
        if e["p"] is None:
            lines.append(f"{e['factor']}: no effect on {what} in {e['pairs']} pairs.")
            continue
        direction = "better" if e["median"] > 0 else "worse" if e["median"] < 0 else "no different (median)"
        sig = "significant" if e["p"] < 0.05 else "not significant"
        lines.append(
            f"{e['factor']}: {what} {direction} with {e['other']}, median paired difference {fmt(e['median'])}, Wilcoxon p = {fmt_p(e['p'])} ({sig} at 5%)."
        )
    return lines


class FitFactorial(Section):
    """A model-learning experiment with ``fits``: each fit's Table 4 row and each factor's main effect."""

    def _units(self) -> dict[str, list[ModelResult]]:
        return {f.label: [u for m in self.s.methods for u in self.group("model", f"{m}@{f.key}")] for f in self.s.fits}

    def figure(self) -> str | None:
        data = {k: v for k, v in self._units().items() if v}
        if not data:
            return None
        fig, axes = new_figure(figsize=(9, 4.2))
        ax = axes[0, 0]
        ax.boxplot([log_errors([float(u.test_mean) for u in v]) for v in data.values()])
        ax.set_xticks(range(1, len(data) + 1), list(data), rotation=30, ha="right")
        ax.set_yscale("log")
        ax.set_ylabel("error of the evolved policy in the true MDP (log)")
        ref = self.paper.get("table", {}).get("lr", {})
        if "r_m" in ref:
            ax.axhline(-ref["r_m"], color="k", ls="--", lw=1, label=f"paper's LR median ({-ref['r_m']:g})")
            ax.legend(fontsize=8, loc="upper left")
        ax.set_title(f"{self.cfg.title} ({self.cfg.scale} scale)", fontsize=10)
        ax.grid(alpha=0.3, which="both")
        return self.save(fig)

    def body(self) -> str:
        units = self._units()
        ref = self.paper.get("table", {}).get("lr", {})
        rows, cells, values = [], {}, {}
        for f in self.s.fits:
            us = units[f.label]
            if not us:
                continue
            r = np.array([float(u.test_mean) for u in us])
            predicted = np.array([float(u.predicted_return) for u in us])
            crashes = sum(u.test_crashes for u in us)
            w_sd = [float(u.test_w_sd) for u in us if u.test_w_sd is not None]
            episodes = sum(len(u.test_returns) for u in us)
            cells[f.label], values[f.label] = levels(f), {u.mdp: float(u.test_mean) for u in us}
            rows.append(
                [
                    f.label,
                    f.d_u,
                    f.noise,
                    f.model_policy,
                    str(f.model_substeps),
                    str(len(us)),
                    fmt(np.median(r)),
                    fmt(r.mean()),
                    str(int(np.sum(r < BAD_RETURN))),
                    fmt(np.median(w_sd)) if w_sd else "n/a",
                    f"{crashes} of {episodes}",
                    str(sum(1 for u in us if u.test_crashes)),
                    fmt(np.median(predicted)),
                ]
            )
            if ref and f.key in ("ours", "authors", "substeps10"):
                ratio = np.median(r) / ref["r_m"]
                within = "within" if 0.5 <= ratio <= 2 else "not within"
                self.comparisons.append(
                    f"LR, fit {f.label!r}: our median {fmt(np.median(r))} vs the paper's {fmt(ref['r_m'])} ({ratio:.2g} times, {within} a factor of two); "
                    f"our mean {fmt(r.mean())} vs {fmt(ref['r_a'])}."
                )
        effects = main_effects(cells, values)
        self.comparisons += effect_lines(effects, "the evolved policy's return in the true MDP")
        return (
            "### Each fit\n\n"
            + table(
                ["fit", "D_u", "noise", "model policy", "model substeps", "MDPs", "r_m", "r_a", f"under {BAD_RETURN:,}", "median w sd", "crashed episodes"]
                + ["MDPs with a crash", "median predicted return"],
                rows,
            )
            + f"\n\nr_m, r_a: median and mean over MDPs of the evolved policy's mean return over {self.s.test_episodes} episodes in the true MDP"
            + (f" (the paper's LR: {fmt(ref['r_m'])} and {fmt(ref['r_a'])})" if ref else "")
            + f"; under {BAD_RETURN:,}: MDPs whose policy earns less per episode (Table 4's bimodality, docs/model.md); w sd: the"
            + " standard deviation of the vertical velocity over the test episodes (about 1.5 m/s where the collective loop oscillates;"
            + " n/a: units stored before it was recorded); predicted: the policy's return on its model.\n\n### Main effects (paired by MDP)\n\n"
            + effects_table(effects, "the mean return per MDP")
            + "\n"
        )


def test_run_effects(groups, runs: Callable[[str], Mapping[str, TestRunResult]]) -> tuple[str, list[str]]:
    """Per agent of a test-runs experiment whose groups vary the LR fit: each factor's main effect on the
    runs' cumulative reward, paired by run (``runs(label)``: the group's runs by MDP and repetition; the
    groups of an agent fly the same seeds); Markdown and comparison lines."""
    by_agent: dict[str, list] = {}
    for g in groups:
        if learns_models(g):
            by_agent.setdefault(g.agent, []).append(g)
    text, lines = [], []
    for agent, gs in by_agent.items():
        if not varies(gs):
            continue
        cells = {g.label: levels(g) for g in gs}
        values = {g.label: {k: float(r.score) for k, r in runs(g.label).items()} for g in gs}
        effects = main_effects(cells, values)
        text.append(f"#### {agent}\n\n" + effects_table(effects, "the cumulative reward per run") + "\n")
        lines += [f"{agent}: {line}" for line in effect_lines(effects, "the cumulative reward")]
    if not text:
        return "", []
    return "### Main effects of the LR fit (paired by run)\n\n" + "\n".join(text), lines


def authors_policy_runs(out, scale: str) -> dict[str, dict[str, dict]]:
    """The authors' published GHH-09 policies flown through Figure 8's protocol, if measured
    (``authors-ghh09-policies.json`` beside the report, written by docs/reproduction/authors_ghh09_policies.py):
    group label -> {MDP/repetition -> run}."""
    import json
    from pathlib import Path

    path = Path(out) / "authors-ghh09-policies.json"
    if not path.is_file():
        return {}
    groups = json.loads(path.read_text(encoding="utf-8")).get(f"fig8-{scale}", {})
    return {g: {"/".join(r["key"].split("/")[-2:]): r for r in runs} for g, runs in groups.items()}


def authors_policy_section(theirs: Mapping[str, Mapping[str, dict]], ours: Callable[[str], Mapping[str, TestRunResult]]) -> tuple[str, list[str]]:
    """Each group flown with the authors' policy set beside the same group with ours, paired by run; Markdown and comparison lines."""
    rows, lines = [], []
    for label, runs in theirs.items():
        mine = ours(label)
        for name, scores, crashed, per_episode in (
            ("the authors'", [r["score"] for r in runs.values()], [bool(r["crash_episodes"]) for r in runs.values()], _clean_mean(runs.values())),
            (
                "ours",
                [float(r.score) for r in mine.values()],
                [bool(r.crash_episodes) for r in mine.values()],
                _clean_mean({"score": float(r.score), "episodes": len(r.returns), "crash_episodes": r.crash_episodes} for r in mine.values()),
            ),
        ):
            if scores:
                rows.append([label, name, str(len(scores)), fmt(np.mean(scores)), f"{sum(crashed)} ({np.mean(crashed):.1%})", fmt(per_episode)])
        d = np.array([runs[k]["score"] - float(mine[k].score) for k in runs if k in mine])
        if d.size and np.any(d != 0):
            p = paired_p(d)
            direction = "better" if np.median(d) > 0 else "worse"
            lines.append(
                f"{label} with the authors' published policies instead of ours: {direction} (median paired difference of the cumulative reward "
                f"{fmt(float(np.median(d)))} over {d.size} runs, Wilcoxon p = {fmt_p(p)}, {'significant' if p < 0.05 else 'not significant'} at 5%)."
            )
    if not rows:
        return "", []
    return (
        "### The authors' published GHH-09 policies\n\n"
        + table(["group", "policy set", "runs", "mean cumulative reward", "runs with a crash", "return/episode (runs without crash)"], rows)
        + "\n\nThe same runs (MDPs, seeds and gusts) with the authors' generic and specialised policies (their hybrid's safe pair 3 and 6), "
        "flown by docs/reproduction/authors_ghh09_policies.py.\n"
    ), lines


def _clean_mean(runs) -> float:
    """Mean return per episode over the runs without a crash (NaN when every run crashed)."""
    clean = [r for r in runs if not r["crash_episodes"]]
    return sum(r["score"] for r in clean) / sum(r["episodes"] for r in clean) if clean else float("nan")


def test_run_figure(groups, runs: Callable[[str], list[TestRunResult]], title: str):
    """One log-scale panel per agent whose groups vary the LR fit: each fit's mean cumulative error over
    episodes (colour: D_u and noise; dashed: the authors' model policy), the other groups as grey
    references, the legend below the panels. Returns the matplotlib figure, or None without data."""
    learners = [g for g in groups if learns_models(g)]
    agents = list(dict.fromkeys(g.agent for g in learners))
    others = [g for g in groups if not learns_models(g)]
    if not agents or not any(runs(g.label) for g in groups):
        return None
    fig, axes = new_figure(len(agents), figsize=(5.5 * len(agents), 5.2))
    colours = {("keep", "innovations"): "tab:blue", ("discard", "innovations"): "tab:orange", ("keep", "rms"): "tab:green", ("discard", "rms"): "tab:red"}
    for ax, agent in zip(axes[0], agents):
        for g in [*others, *(g for g in learners if g.agent == agent)]:
            data = runs(g.label)
            if not data:
                continue
            cum = -np.cumsum(np.array([[float(x) for x in r.returns] for r in data]), axis=1).mean(axis=0)
            if g in others:
                style = {"color": "0.5", "lw": 2.5, "alpha": 0.6}
            else:
                style = {"color": colours.get((g.d_u, str(levels(g)["noise"])), "k"), "ls": "--" if g.model_policy == "authors" else "-", "lw": 1.4}
            ax.plot(np.arange(1, cum.size + 1), cum, label=g.label, **style)
        agent_panel(ax, agent)
    fig.suptitle(title + "\ncolour: D_u and noise estimate; dashed: the authors' model policy; grey: reference", fontsize=9)
    return fig
