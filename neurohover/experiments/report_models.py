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

from .report_base import Section, fmt, fmt_p, log_errors, new_figure, table
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
