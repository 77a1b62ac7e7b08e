"""The report's section of a model-learning experiment with sensor conditions (``bench-sensor-models``).

Per condition: the LR models learned through its sensors, checked against exact ones (the unit's
exact checks, :class:`~neurohover.experiments.results.ModelResult`): their one-step error on their
own data and on exact flight data, their parameters' relative errors, and the policies evolved on
them flown in the true MDP with exact sensors and through the condition's. The exact condition of
the same MDPs (paired: every condition of an MDP takes its seed) is the reference of the Wilcoxon
signed-rank tests.
"""

from __future__ import annotations

from dataclasses import dataclass

import numpy as np

from .report_base import Section, fmt, fmt_p, log_errors, new_figure, ratio_verdict, sd, table
from .results import ModelResult


@dataclass(frozen=True)
class _Checked:
    """A model unit's exact checks as numbers."""

    mdp: str
    own: float  # one-step error on its own data
    exact: float  # ... on exact flight data
    params: float  # median relative error of the 11 parameters
    true: float  # its policy's mean return, exact sensors
    crashes: int  # ... crashed episodes
    seen: float  # its policy's mean return through the sensors
    seen_crashes: int
    episodes: int

    @classmethod
    def of(cls, u: ModelResult) -> _Checked | None:
        if u.own_one_step_error is None or u.exact_one_step_error is None or u.param_relative_errors is None or u.exact_test_returns is None:
            return None
        return cls(
            mdp=u.mdp,
            own=float(u.own_one_step_error),
            exact=float(u.exact_one_step_error),
            params=float(np.median([float(x) for x in u.param_relative_errors])),
            true=float(np.mean([float(x) for x in u.exact_test_returns])),
            crashes=int(u.exact_test_crashes or 0),
            seen=float(u.test_mean),
            seen_crashes=u.test_crashes,
            episodes=len(u.test_returns),
        )


class SensorModels(Section):
    """A model-learning experiment's sections when it has ``conditions``."""

    def _data(self) -> dict[str, list[_Checked]]:
        out = {}
        for c in self.s.conditions:
            units = [_Checked.of(u) for m in self.s.methods for u in self.group("model", f"{m}@{c.key}")]
            checked = [u for u in units if u is not None]
            if checked:
                out[c.label] = checked
        return out

    def figure(self) -> str | None:
        data = self._data()
        if not data:
            return None
        fig, axes = new_figure(2, figsize=(11, 4.2))
        labels = list(data)
        panels = (
            ("one-step error on exact flight data", [[u.exact for u in v] for v in data.values()]),
            ("policy error, exact sensors", [list(log_errors([u.true for u in v])) for v in data.values()]),
        )
        for ax, (what, values) in zip(axes[0], panels, strict=True):
            ax.boxplot(values)
            ax.set_xticks(range(1, len(labels) + 1), labels, rotation=45, ha="right", fontsize=8)
            ax.set_yscale("log")
            ax.set_ylabel(f"{what} (log scale)")
            ax.grid(alpha=0.3, which="both")
        fig.suptitle(f"{self.cfg.title} ({self.cfg.scale} scale)", fontsize=10)
        return self.save(fig)

    def body(self) -> str:
        data = self._data()
        if not data:
            return "No units finished yet.\n"
        by_key = {c.label: c for c in self.s.conditions}
        exact_label = next((c.label for c in self.s.conditions if c.sensor is None and c.data_episodes == 1), None)
        reference = {u.mdp: u for u in data.get(exact_label, [])} if exact_label else {}
        rows = []
        for label, units in data.items():
            c = by_key[label]
            own = np.array([u.own for u in units])
            exact = np.array([u.exact for u in units])
            par = np.array([u.params for u in units])
            true = np.array([u.true for u in units])
            seen = np.array([u.seen for u in units])
            crashes = sum(u.crashes for u in units)
            seen_crashes = sum(u.seen_crashes for u in units)
            episodes = sum(u.episodes for u in units)
            p = "-"
            paired = [(u.exact, reference[u.mdp].exact) for u in units if u.mdp in reference]
            if label != exact_label and len(paired) >= 5:
                from scipy import stats  # imported where a report is written, not by every command line

                a, b = np.array(paired).T
                p = fmt_p(stats.wilcoxon(a, b).pvalue) + f" ({int((a > b).sum())} of {len(a)} worse)"
            rows.append(
                [
                    label,
                    _sensor_text(c.sensor),
                    str(c.data_episodes),
                    str(len(units)),
                    fmt(np.median(own)),
                    fmt(np.median(exact)),
                    p,
                    f"{np.median(par):.0%}",
                    fmt(np.median(true)),
                    fmt(true.mean()),
                    f"{crashes} of {episodes}",
                    fmt(np.median(seen)),
                    f"{seen_crashes} of {episodes}",
                ]
            )
        return (
            "### LR models learned through the sensors\n\n"
            + table(
                [
                    "condition",
                    "sensors",
                    "episodes of data",
                    "MDPs",
                    "one-step error, own data (median)",
                    "one-step error, exact data (median)",
                    "vs exact sensors (paired Wilcoxon)",
                    "parameter error (median of medians)",
                    "policy, exact sensors: median return",
                    "mean",
                    "crashed episodes",
                    "policy through the sensors: median",
                    "crashed",
                ],
                rows,
            )
            + f"\n\nThe baseline policy's flight data ({', '.join(sorted({str(c.data_episodes) for c in self.s.conditions}))} episodes) "
            "seen through each condition's sensors; an LR model learned from them; a policy evolved on the model from the "
            f"baseline; that policy flown {self.s.test_episodes} episodes in the true MDP with exact sensors and, on the same "
            "gusts, through the condition's sensors. The one-step error is the mean over transitions of the squared error of "
            "the 12 predicted observation entries; on exact data it is measured on an exact episode of the baseline with gusts "
            "of its own. Parameter error: the median over the 11 dynamics parameters of |learned - true| / |true|, then the "
            "median over MDPs.\n"
        )


def _sensor_text(sensor: dict | None) -> str:
    if sensor is None:
        return "exact"
    return ", ".join(f"{k} {v}" for k, v in sensor.items())


class ModelLearningSection(Section):
    """A model-learning experiment's section (Table 4): the policies evolved on each method's learned models, flown in the true MDP."""

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
