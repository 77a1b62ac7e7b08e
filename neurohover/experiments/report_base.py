"""What every section of ``neurohover report`` shares: number formatting, tables, t tests, figures, and the :class:`Section` base."""

from __future__ import annotations

import math
from pathlib import Path
from typing import Any

import numpy as np

from ..paths import write_png
from ..plots import noting_missing_glyphs
from .config import ExperimentConfig
from .keys import UnitKey
from .results import UnitResult
from .store import Store

# --------------------------------------------------------------------------------- formatting


def fmt(x, digits: int = 4) -> str:
    if x is None:
        return "n/a"
    if isinstance(x, str):
        return x
    x = float(x)
    if not math.isfinite(x):
        return "n/a" if math.isnan(x) else ("inf" if x > 0 else "-inf")
    if x != 0 and (abs(x) >= 1e5 or abs(x) < 1e-3):
        return f"{x:.{digits - 1}e}"
    return f"{x:.{digits}g}" if abs(x) < 10**digits else f"{x:.0f}"


def fmt_p(p) -> str:
    if p is None or (isinstance(p, float) and math.isnan(p)):
        return "n/a"
    return f"{p:.3g}"


def log_errors(returns) -> np.ndarray:
    """Errors (minus the returns) floored at 1e-3, for log scales."""
    return np.maximum(-np.asarray(returns, dtype=float), 1e-3)


def table(headers: list[str], rows: list[list]) -> str:
    lines = ["| " + " | ".join(headers) + " |", "|" + "|".join("---" for _ in headers) + "|"]
    lines += ["| " + " | ".join(fmt(c) if not isinstance(c, str) else c for c in row) + " |" for row in rows]
    return "\n".join(lines)


def ttest(a, b) -> tuple[float | None, float | None, float | None]:
    """(t, Student's p, Welch's p) of two samples, or Nones when a test is undefined."""
    from scipy import stats

    a, b = np.asarray(a, dtype=float), np.asarray(b, dtype=float)
    if a.size < 2 or b.size < 2 or not (np.all(np.isfinite(a)) and np.all(np.isfinite(b))):
        return None, None, None
    if np.var(a) == 0 and np.var(b) == 0:
        return None, None, None
    student = stats.ttest_ind(a, b, equal_var=True)
    welch = stats.ttest_ind(a, b, equal_var=False)
    return float(student.statistic), float(student.pvalue), float(welch.pvalue)


def paired_p(diff) -> float:
    """The Wilcoxon signed-rank p of paired differences (1 when every pair is equal: nothing to rank)."""
    from scipy import stats

    d = np.asarray(diff, dtype=float)
    return float(stats.wilcoxon(d).pvalue) if np.any(d != 0) else 1.0


def paired_verdict(diff) -> str:
    """How paired differences (ours minus theirs) go, for a sentence the Wilcoxon p follows: by the median pair, or,
    where most pairs are equal (median 0; the test drops them), by the pairs that differ. Leaves a parenthesis open."""
    d = np.asarray(diff, dtype=float)
    better, worse, median = int((d > 0).sum()), int((d < 0).sum()), float(np.median(d))
    if median != 0:
        word = "better" if median > 0 else "worse"
        return f"{word} in the median pair ({better} of {d.size} runs better, median paired difference {fmt(median)}"
    word = "better" if better > worse else "worse" if worse > better else "neither better nor worse"
    return f"equal in {d.size - better - worse} of {d.size} pairs and {word} where they differ ({better} better, {worse} worse"


def sd(x) -> float:
    x = np.asarray(x, dtype=float)
    return float(x.std(ddof=1)) if x.size > 1 else float("nan")


def new_figure(ncols: int = 1, *, figsize: tuple[float, float], nrows: int = 1):
    """A new figure with an ``nrows`` x ``ncols`` grid of axes (an array, always 2-d), drawn by Agg.

    Object-oriented matplotlib: no pyplot, so the caller's backend and pyplot's figures are untouched."""
    from matplotlib.backends.backend_agg import FigureCanvasAgg
    from matplotlib.figure import Figure

    fig = Figure(figsize=figsize)
    FigureCanvasAgg(fig)
    return fig, fig.subplots(nrows, ncols, squeeze=False)


def agent_panel(ax, title: str) -> None:
    """Finish one agent's panel of mean cumulative error over episodes: log scale, labels, grid, the legend below it."""
    ax.set_yscale("log")
    ax.set_title(title, fontsize=10)
    ax.set_xlabel("episode")
    ax.set_ylabel("mean cumulative error (log scale)")
    ax.grid(alpha=0.3, which="both")
    ax.legend(fontsize=7, loc="upper center", bbox_to_anchor=(0.5, -0.16), ncol=2, frameon=False)


def p_significant(p_paper: str, level: float = 0.05) -> bool | None:
    """Whether a paper's p-value text says significant at ``level`` (5%, or 1% for :func:`verdict`'s "weaker"): "< X"
    with X <= level does ("< 0.05" read as 0.05 was not significant at 5%, T27-A03; "< 0.01" was
    not at 1%, so ours at 0.03 read "holds" beside it), "<= X" and a plain number where below the level; None when it gives no number."""
    text = p_paper.strip().lower()
    if text.startswith("not"):
        return False
    value = p_value(p_paper)
    if value is None:
        return None
    sign = text[: len(text) - len(text.lstrip("<= "))]
    return value <= level if "<" in sign and "=" not in sign else value < level


def p_value(p_paper: str) -> float | None:
    """The number of a paper's p-value text ("5.8e-12", "< 0.0026"); None when it gives none."""
    try:
        return float(p_paper.strip().lower().lstrip("<= ").split()[0])
    except (ValueError, IndexError):
        return None


def ratio_verdict(ours: float, paper: float) -> str:
    """A number of ours against the paper's of the same sign: within a factor of two, or how many times it is."""
    if paper == 0 or ours == 0 or (ours > 0) != (paper > 0):
        return "differs" if ours != paper else "holds"
    ratio = ours / paper
    return "within a factor of two" if 0.5 <= ratio <= 2 else f"{ratio:.2g} times the paper's"


def verdict(a: str, ma: float, mb: float, p_ours: float, p_paper: str) -> str | None:
    """How our test of ``a`` against ``b`` (means ``ma``, ``mb``; Student's ``p_ours``) stands to the
    paper's (``p_paper``, whose ``a`` is the one the paper found better), by direction first, then
    significance: "holds", "same direction, weaker", "same direction, not significant", "reversed",
    ... (None: the paper gives no p-value to compare with). A reversed effect never holds."""
    expected = p_significant(p_paper)
    if expected is None:
        return None
    significant = p_ours < 0.05
    if p_value(p_paper) is None:  # the paper says "not significant" and gives no number: no direction to keep or reverse
        return "holds (neither significant)" if not significant else f"differs: significant here ({a} {'better' if ma > mb else 'worse'}), not in the paper"
    if ma <= mb:
        return f"reversed{'' if significant else ', not significant'} (the paper found {a} better; ours is worse)"
    if expected and significant:  # the paper significant at 1% by its own text, ours not: weaker
        return "same direction, weaker (p >= 0.01 here)" if p_significant(p_paper, 0.01) and p_ours >= 0.01 else "holds"
    if expected:
        return "same direction, not significant"
    return "holds (same direction, neither significant)" if not significant else "same direction, significant here but not in the paper"


# --------------------------------------------------------------------------------- sections


class Section:
    def __init__(self, config: ExperimentConfig, results: dict[str, UnitResult], store: Store, out: Path) -> None:
        self.cfg, self.results, self.store, self.out = config, results, store, out
        self.keys = {k: UnitKey.parse(k) for k in results}
        self.s: Any = config.typed  # the kind's settings dataclass (neurohover.experiments.settings)
        self.paper = config.paper
        self.comparisons: list[str] = []
        self.tests: list[list] = []
        self.claims: list[dict[str, str]] = []  # the paper's claims this section checks (the report's claims table)

    def group(self, stage: str, group: str) -> list:
        """The results of the units of ``stage`` and ``group`` (:class:`UnitKey`), in key order."""
        return [self.results[k] for k in sorted(self.results) if (self.keys[k].stage, self.keys[k].group) == (stage, group)]

    @property
    def stem(self) -> str:
        return f"{self.cfg.name}-{self.cfg.scale}"

    def save(self, fig) -> str:
        """Write the section's figure next to the report; returns its file name."""
        with noting_missing_glyphs():  # a title the plot font cannot draw: one note, not matplotlib's warnings (T31-A01)
            fig.tight_layout()
            return write_png(fig, self.out / f"{self.stem}.png", "report figure", dpi=110).name

    def save_panels(self, fig, axes, xlabel: str, ylabels: tuple[str, str]) -> str:
        """Label two panels (the second on a log scale), title the figure, put one legend below both (so it
        covers no curve; the figure grows by its rows) and save it."""
        axes[0].set_ylabel(ylabels[0])
        axes[1].set_ylabel(ylabels[1])
        axes[1].set_yscale("log")
        for ax in axes:
            ax.set_xlabel(xlabel)
            ax.grid(alpha=0.3, which="both")
        handles, labels = axes[0].get_legend_handles_labels()
        rows = -(-len(labels) // 2)
        width, height = fig.get_size_inches()
        extra = 0.25 * rows + 0.2
        fig.set_size_inches(width, height + extra)
        fig.suptitle(f"{self.cfg.title} ({self.cfg.scale} scale)", fontsize=10)
        fig.legend(handles, labels, loc="lower center", ncol=2, fontsize=8, frameon=False)
        with noting_missing_glyphs():
            fig.tight_layout(rect=(0, extra / (height + extra), 1, 1))
            return write_png(fig, self.out / f"{self.stem}.png", "report figure", dpi=110).name

    def add_tests(self, samples: dict[str, list[float]], labels: dict[str, str], what: str) -> None:
        for t in self.paper.get("ttests", []):
            a, b = t["a"], t["b"]
            if a not in samples or b not in samples:
                continue
            stat, p_student, p_welch = ttest(samples[a], samples[b])
            ma, mb = np.mean(samples[a]), np.mean(samples[b])
            self.tests.append([f"{labels.get(a, a)} vs {labels.get(b, b)}", fmt(ma), fmt(mb), fmt(stat), fmt_p(p_student), fmt_p(p_welch), str(t["p"])])
            # Each paper test names the approach the paper found better as ``a``.
            judged = None if p_student is None else verdict(labels.get(a, a), float(ma), float(mb), p_student, str(t["p"]))
            if p_student is not None:
                found = f"no significant difference ({t['p']})" if p_value(str(t["p"])) is None else f"{labels.get(a, a)} better, p {t['p']}"
                self.add_claim(
                    f"{labels.get(a, a)} vs {labels.get(b, b)} ({what})",
                    found,
                    f"{fmt(ma)} vs {fmt(mb)}, p = {fmt_p(p_student)}",
                    judged or "no p-value to compare",
                    "test",
                )
            if p_student is not None and judged is not None:
                self.comparisons.append(
                    f"{labels.get(a, a)} vs {labels.get(b, b)} ({what}): our Student's p = {fmt_p(p_student)} "
                    f"({'significant' if p_student < 0.05 else 'not significant'} at 5%; mean {fmt(ma)} vs {fmt(mb)}) vs paper p {t['p']}: {judged}."
                )

    def add_claim(self, claim: str, paper: str, ours: str, judged: str, kind: str = "number") -> None:
        """One row of the report's claims table: what the paper found, what we find, and the verdict; ``kind``
        ``"test"`` (a t test), ``"ranking"`` (an order of methods) or ``"number"`` (a figure beside the paper's)."""
        self.claims.append({"claim": claim, "paper": paper, "ours": ours, "verdict": judged, "kind": kind})

    def figure(self) -> str | None:
        """Write the section's figure (each kind of section defines it); returns its file name, or None."""
        raise NotImplementedError

    def body(self) -> str:
        """The section's Markdown (each kind of section defines it)."""
        raise NotImplementedError

    def tests_markdown(self) -> str:
        if not self.tests:
            return ""
        return "### Statistical tests\n\n" + table(["comparison", "mean A", "mean B", "t", "Student's p", "Welch's p", "paper p"], self.tests) + "\n"
