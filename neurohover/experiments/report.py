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

import math
import time
import warnings
from collections.abc import Sequence
from pathlib import Path

import numpy as np

from ..errors import NeurohoverError
from ..evolution.fitness import episode_fitness, error_of_fitness
from .config import ORDER, ExperimentConfig
from .results import EvolveResult, ModelResult, RobustnessResult, TestRunResult, UnitKey, UnitResult, result_from_dict
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


def _table(headers: list[str], rows: list[list]) -> str:
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


def _sd(x) -> float:
    x = np.asarray(x, dtype=float)
    return float(x.std(ddof=1)) if x.size > 1 else float("nan")


def _figure(ncols: int = 1, *, figsize: tuple[float, float]):
    """A new figure with a 1 x ``ncols`` grid of axes (an array, always 2-d), drawn by Agg.

    Object-oriented matplotlib: no pyplot, so the caller's backend and pyplot's figures are untouched."""
    from matplotlib.backends.backend_agg import FigureCanvasAgg
    from matplotlib.figure import Figure

    fig = Figure(figsize=figsize)
    FigureCanvasAgg(fig)
    return fig, fig.subplots(1, ncols, squeeze=False)


def _p_significant(p_paper: str) -> bool | None:
    text = p_paper.strip().lower()
    if text.startswith("not"):
        return False
    try:
        value = float(text.lstrip("<= ").strip())
    except ValueError:
        return None
    return value < 0.05


# --------------------------------------------------------------------------------- sections


class _Section:
    def __init__(self, config: ExperimentConfig, results: dict[str, UnitResult], store: Store, out: Path) -> None:
        self.cfg, self.results, self.store, self.out = config, results, store, out
        self.keys = {k: UnitKey.parse(k) for k in results}
        self.s = config.settings
        self.paper = config.paper
        self.comparisons: list[str] = []
        self.tests: list[list] = []

    def group(self, stage: str, group: str) -> list:
        """The results of the units of ``stage`` and ``group`` (:class:`UnitKey`), in key order."""
        return [self.results[k] for k in sorted(self.results) if (self.keys[k].stage, self.keys[k].group) == (stage, group)]

    @property
    def stem(self) -> str:
        return f"{self.cfg.name}-{self.cfg.scale}"

    def save(self, fig) -> str:
        """Write the section's figure next to the report; returns its file name."""
        fig.tight_layout()
        path = self.out / f"{self.stem}.png"
        fig.savefig(path, dpi=110)
        return path.name

    def save_panels(self, fig, axes, xlabel: str, ylabels: tuple[str, str]) -> str:
        """Label two panels (the second on a log scale), title the figure and save it."""
        axes[0].set_ylabel(ylabels[0])
        axes[1].set_ylabel(ylabels[1])
        axes[1].set_yscale("log")
        for ax in axes:
            ax.set_xlabel(xlabel)
            ax.grid(alpha=0.3, which="both")
            ax.legend(fontsize=8)
        fig.suptitle(f"{self.cfg.title} ({self.cfg.scale} scale)", fontsize=10)
        return self.save(fig)

    def add_tests(self, samples: dict[str, list[float]], labels: dict[str, str], what: str) -> None:
        for t in self.paper.get("ttests", []):
            a, b = t["a"], t["b"]
            if a not in samples or b not in samples:
                continue
            stat, p_student, p_welch = ttest(samples[a], samples[b])
            ma, mb = np.mean(samples[a]), np.mean(samples[b])
            self.tests.append([f"{labels.get(a, a)} vs {labels.get(b, b)}", fmt(ma), fmt(mb), fmt(stat), fmt_p(p_student), fmt_p(p_welch), str(t["p"])])
            expected = _p_significant(str(t["p"]))
            if p_student is not None and expected is not None:
                # Each paper test names the approach the paper found better as ``a``.
                ours = p_student < 0.05
                if ours and expected and ma < mb:
                    agree = f"disagrees: the opposite direction (the paper found {labels.get(a, a)} better)"
                else:
                    agree = "agrees" if ours == expected else "disagrees"
                self.comparisons.append(
                    f"{labels.get(a, a)} vs {labels.get(b, b)} ({what}): our Student's p = {fmt_p(p_student)} "
                    f"({'significant' if ours else 'not significant'} at 5%; mean {fmt(ma)} vs {fmt(mb)}) vs paper p {t['p']}: {agree}."
                )

    def figure(self) -> str | None:
        """Write the section's figure (each kind of section defines it); returns its file name, or None."""
        raise NotImplementedError

    def body(self) -> str:
        """The section's Markdown (each kind of section defines it)."""
        raise NotImplementedError

    def tests_markdown(self) -> str:
        if not self.tests:
            return ""
        return "### Statistical tests\n\n" + _table(["comparison", "mean A", "mean B", "t", "Student's p", "Welch's p", "paper p"], self.tests) + "\n"


def _curve(points: Sequence[Sequence[float | str]], grid: np.ndarray, sign: float = -1.0) -> np.ndarray:
    """Champion error (``sign`` -1; +1: the champion's fitness as recorded) of one run on ``grid``
    (a step function; NaN before its first record, held after its last)."""
    xs = np.array([p[0] for p in points], dtype=float)
    ys = sign * np.array([float(p[1]) for p in points], dtype=float)
    idx = np.searchsorted(xs, grid, side="right") - 1
    out = np.where(idx >= 0, ys[np.clip(idx, 0, None)], np.nan)
    return out


class _Evolution(_Section):
    def variants(self) -> list[dict]:
        return self.s["variants"]

    def runs(self, vkey: str) -> list[EvolveResult]:
        return self.group("evolve", vkey)

    def final_scores(self, runs: list[EvolveResult]) -> list[float]:
        """Per run: the mean validation return, or on the 1/ln(error) scale the mean validation fitness."""
        if self._fghh_style() and all(r.validation is not None for r in runs):
            return [_mean_fitness([float(x) for x in r.validation or ()]) for r in runs]
        return [r.final_score for r in runs]

    def figure(self) -> str | None:
        data = {v["key"]: self.runs(v["key"]) for v in self.variants()}
        if not any(data.values()):
            return None
        if self._fghh_style():
            return self._fitness_figure(data)
        xmax = max(r.history[-1][0] for runs in data.values() for r in runs)
        xmin = min(r.history[0][0] for runs in data.values() for r in runs)
        grid = np.linspace(max(xmin, 1), xmax, 400)
        two = self.cfg.name == "fig2" or self.s["target"] == "train"
        fig, axes = _figure(2 if two else 1, figsize=(11 if two else 6.5, 4.2))
        axes = axes[0]
        for v in self.variants():
            runs = data[v["key"]]
            if not runs:
                continue
            curves = np.array([_curve(r.history, grid) for r in runs])
            with np.errstate(all="ignore"), warnings.catch_warnings():
                warnings.simplefilter("ignore", RuntimeWarning)  # grid points before any run's first champion
                mean = np.nanmean(np.where(np.isfinite(curves), curves, np.nan), axis=0)
            axes[0].plot(grid, mean, label=v["label"])
            if two:
                best = int(np.argmin([-float(r.champion_return) for r in runs]))
                axes[1].plot(grid, curves[best], label=v["label"])
        axes[0].set_title("average of the runs" if two else f"average of {len(next(iter(data.values())))} runs per setting")
        if two:
            axes[1].set_title("best run")
        for ax in axes:
            ax.set_yscale("log")
            ax.set_xlabel("episodes")
            ax.set_ylabel("error of the champion (-return, log scale)")
            ax.grid(alpha=0.3, which="both")
            ax.legend(fontsize=8)
        fig.suptitle(f"{self.cfg.title} ({self.cfg.scale} scale)", fontsize=10)
        return self.save(fig)

    def _fitness_figure(self, data: dict[str, list[EvolveResult]]) -> str:
        """Figures 12, 13, 15 in the paper's form on the scale the runs used: the champion's fitness
        estimate, 1/ln(error), averaged over the runs, and the same curve as error, exp(1/fitness)."""
        xmax = max(r.history[-1][0] for runs in data.values() for r in runs)
        grid = np.linspace(1, xmax, 400)
        fig, axes = _figure(2, figsize=(11, 4.2))
        axes = axes[0]
        for v in self.variants():
            runs = data[v["key"]]
            if not runs:
                continue
            raw = not _on_fitness_scale(runs)  # a variant run on mean raw returns: its curve converted
            curves = np.array([_curve(r.history, grid, sign=-1.0 if raw else 1.0) for r in runs])
            with np.errstate(all="ignore"), warnings.catch_warnings():
                warnings.simplefilter("ignore", RuntimeWarning)  # grid points before any run's first champion
                mean = np.nanmean(np.where(np.isfinite(curves), curves, np.nan), axis=0)
            fitness = episode_fitness(-mean, FITNESS_SCALE) if raw else mean
            error = mean if raw else error_of_fitness(mean, FITNESS_SCALE)
            note = ", raw returns: 1/ln of the mean error" if raw else ""
            axes[0].plot(grid, fitness, label=f"{v['label']} ({len(runs)} runs{note})")
            axes[1].plot(grid, error, label=v["label"])
        return self.save_panels(fig, axes, "episodes", ("champion fitness, 1/ln(error) (mean over runs)", "as error, exp(1/fitness) (log scale)"))

    def _fghh_style(self) -> bool:
        """Whether the section reads as FGHH's as the authors ran it: runs on the 1/ln(error) scale,
        or champions validated on the test MDPs (every variant then compared on 1/ln(error))."""
        runs = [r for v in self.variants() for r in self.runs(v["key"])]
        return bool(runs) and (any(r.fitness == FITNESS_SCALE for r in runs) or self.s.get("validation_mdps") == "test")

    def _fitness_body(self) -> str:
        """Final champions of runs on the 1/ln(error) scale, flown on the test MDPs, beside the authors' generics."""
        rows, samples, labels = [], {}, {}
        for v in self.variants():
            runs = self.runs(v["key"])
            if not runs:
                continue
            row, finals = _validation_row(v["label"], [[float(x) for x in r.validation or ()] for r in runs], [r.validation_crashed for r in runs])
            champ = float(np.mean([float(r.champion_return) for r in runs]))
            if _on_fitness_scale(runs):
                estimate, as_error = fmt(champ), fmt(float(error_of_fitness(champ, FITNESS_SCALE)))
            else:  # a variant run on mean raw returns
                estimate, as_error = f"{fmt(champ)} (a return)", fmt(-champ)
            rows.append([row[0], str(len(runs)), estimate, as_error, *row[1:]])
            rows[-1] += [fmt(np.mean([r.episodes for r in runs])), fmt(np.mean([r.timing.seconds for r in runs]))]
            samples[v["key"]], labels[v["key"]] = finals, v["label"]
        authors = _authors_generics(self.out, self.cfg)
        for folder, entry in authors.items():
            row, _ = _validation_row(f"the authors' {folder} ({len(entry['returns'])} files)", entry["returns"], entry["crashed"])
            rows.append([row[0], str(len(entry["returns"])), "", "", *row[1:], "", ""])
        where = "once on each of the family's test MDPs, the same gusts for every run" if self.s.get("validation_mdps") == "test" else "on fresh MDPs"
        text = (
            "### Final champions\n\n"
            + _table(
                [
                    "setting",
                    "runs",
                    "final fitness estimate (mean)",
                    "as error",
                    "validation crash rate",
                    "median error",
                    "mean 1/ln(error)",
                    "sd over runs",
                    "episodes/run",
                    "seconds/run",
                ],
                rows,
            )
            + "\n\nFinal fitness estimate: the best selected parent's mean 1/ln(error) over its episodes in the last generation "
            "(what the figure's left panel ends on; a variant run on raw returns: its mean return); as error: exp(1/fitness). "
            f"Validation: each final champion flown {where}; "
            "crash rate over all validation episodes, median error over them, mean 1/ln(error) per run then over runs (the "
            "t tests' sample)."
            + (
                " The authors' rows: their published FGHH generics (their `policies/` folders beside `mdp.py`) flown on the same "
                "MDPs with the same gusts (`docs/reproduction/authors_fghh_generics.py`)."
                if authors
                else ""
            )
            + "\n"
        )
        if samples:
            order = sorted(samples, key=lambda k: -np.mean(samples[k]))
            self.comparisons.append("Ranking by mean validation 1/ln(error) (best first): ours " + " > ".join(labels[k] for k in order) + ".")
            for folder, entry in authors.items():
                fits = [_mean_fitness(r) for r in entry["returns"]]
                self.comparisons.append(
                    f"The authors' {folder} generics on the same MDPs: mean 1/ln(error) {fmt(np.mean(fits))}, crash rate "
                    f"{np.mean([c for cs in entry['crashed'] for c in cs]):.1%} (ours: "
                    + ", ".join(f"{labels[k]} {fmt(np.mean(samples[k]))}" for k in order)
                    + ")."
                )
        self.add_tests(samples, labels, "mean validation 1/ln(error) of the final champions")
        return text

    def body(self) -> str:
        if self._fghh_style():
            return self._fitness_body()
        parts = []
        rows = []
        samples, labels = {}, {}
        validated = False
        for v in self.variants():
            runs = self.runs(v["key"])
            if not runs:
                continue
            champ = [-float(r.champion_return) for r in runs]
            finals = self.final_scores(runs)
            validated = runs[0].validation is not None
            samples[v["key"]], labels[v["key"]] = finals, v["label"]
            stops: dict[str, int] = {}
            for r in runs:
                stops[r.stop_reason] = stops.get(r.stop_reason, 0) + 1
            rows.append(
                [
                    v["label"],
                    str(len(runs)),
                    fmt(np.mean(champ)),
                    fmt(np.median(champ)),
                    fmt(np.min(champ)),
                    fmt(-np.mean(finals)) if validated else "n/a",
                    fmt(_sd(finals)) if validated else "n/a",
                    fmt(np.mean([r.episodes for r in runs])),
                    fmt(np.mean([r.timing.seconds for r in runs])),
                    ", ".join(f"{k} {n}" for k, n in sorted(stops.items())),
                    # stores written before the flag was recorded have no answer
                    str(sum(bool(r.champion_crashed) for r in runs)) if all(r.champion_crashed is not None for r in runs) else "n/a",
                ]
            )
        what = "mean return of the final champion on fresh validation episodes" if validated else "final champion return"
        parts.append(
            "### Final champions\n\n"
            + _table(
                [
                    "setting",
                    "runs",
                    "mean champion error",
                    "median",
                    "best",
                    "validation error (mean)",
                    "sd",
                    "episodes/run",
                    "seconds/run",
                    "stopped by",
                    "champion crashing at the end",
                ],
                rows,
            )
            + "\n\nChampion error: minus the champion's fitness estimate at the end "
            "of the run (what the figure shows). Champion crashing at the end: runs whose final champion's own "
            "evaluation crashed (steady state). Validation: the final champion flown on fresh episodes"
            + (" (each on a fresh MDP from G)" if self.s["target"] == "family" else " of its MDP")
            + ".\n"
        )
        if samples:
            order = sorted(samples, key=lambda k: -np.mean(samples[k]))
            self.comparisons.append("Ranking by " + what + " (best first): ours " + " > ".join(labels[k] for k in order) + ".")
        self.add_tests(samples, labels, what)
        if self.s["robustness_variants"]:
            parts.append(self.table3())
        return "\n".join(parts)

    def table3(self) -> str:
        rows = []
        ref = self.paper.get("table3", {})
        for vkey in self.s["robustness_variants"]:
            label = next(v["label"] for v in self.variants() if v["key"] == vkey)
            units: list[RobustnessResult] = self.group("robust", vkey)
            if not units:
                continue
            own = [float(np.mean([float(x) for x in u.returns[u.own]])) for u in units]
            across = [float(np.mean([float(x) for row in u.returns for x in row])) for u in units]
            crashes_own = sum(u.crashes[u.own] for u in units)
            crashes_all = sum(sum(u.crashes) for u in units)
            episodes = sum(len(row) for u in units for row in u.returns)
            p = ref.get(vkey, {})
            rows.append(
                [
                    label,
                    str(len(units)),
                    fmt(np.mean(own)),
                    fmt(_sd(own)),
                    fmt(p.get("r")),
                    fmt(p.get("sd")),
                    fmt(np.mean(across)),
                    fmt(_sd(across)),
                    fmt(p.get("r_G")),
                    fmt(p.get("sd_G")),
                    f"{crashes_own} / {crashes_all} of {episodes}",
                    str(p.get("crashes_G", "n/a")),
                ]
            )
            if p:
                self.comparisons.append(
                    f"Table 3, {label}: our r = {fmt(np.mean(own))} vs paper {fmt(p.get('r'))}; "
                    f"our r_G = {fmt(np.mean(across))} vs paper {fmt(p.get('r_G'))}; "
                    f"crashes across the training MDPs: ours {crashes_all}" + (f" vs paper {p['crashes_G']}" if "crashes_G" in p else "") + "."
                )
        if not rows:
            return ""
        n = self.s["robustness_episodes"]
        return (
            "### Table 3: robustness of the best champions\n\n"
            + _table(
                [
                    "policy",
                    "MDPs",
                    "r (own MDP)",
                    "sd",
                    "paper r",
                    "paper sd",
                    "r_G (all MDPs)",
                    "sd_G",
                    "paper r_G",
                    "paper sd_G",
                    "crashes own / all",
                    "paper crashes",
                ],
                rows,
            )
            + f"\n\nThe best champion of each training MDP's runs flown {n} episodes on its own MDP (r) and on every "
            f"training MDP used (r_G); sd over the policies' mean returns.\n"
        )


FITNESS_SCALE = "inv-log-error"


def _mean_fitness(returns) -> float:
    """Mean 1/ln(error) of one policy's episode returns (a run's validation, or one authors' file's)."""
    return float(np.mean(episode_fitness(np.asarray(returns, dtype=float), FITNESS_SCALE)))


def _on_fitness_scale(runs: list[EvolveResult]) -> bool:
    """Whether the runs recorded their champions on the 1/ln(error) scale (FGHH as the authors ran it)."""
    return bool(runs) and all(r.fitness == FITNESS_SCALE for r in runs)


def _validation_row(label: str, returns: list[list[float]], crashed: list) -> tuple[list[str], list[float]]:
    """[label, crash rate, median error, mean 1/ln(error), sd over runs] of validation flights, and the per-run means."""
    flat = np.array([x for r in returns for x in r], dtype=float)
    if flat.size == 0:
        return [label, "n/a", "n/a", "n/a", "n/a"], []
    per_run = [_mean_fitness(r) for r in returns if r]
    known = [c for cs in crashed if cs is not None for c in cs]
    rate = f"{np.mean(known):.1%}" if known else "n/a"
    return [label, rate, fmt(float(np.median(-flat))), fmt(float(np.mean(per_run))), fmt(_sd(per_run))], per_run


def _authors_generics(out: Path, cfg: ExperimentConfig) -> dict:
    """The authors' published FGHH generics flown on this experiment's validation MDPs, if measured
    (``authors-fghh-generics.json`` beside the report, written by docs/reproduction/authors_fghh_generics.py)."""
    import json

    path = out / "authors-fghh-generics.json"
    if not path.is_file():
        return {}
    return json.loads(path.read_text()).get(f"{cfg.name}-{cfg.scale}", {})


class _ModelLearning(_Section):
    def figure(self) -> str | None:
        data: dict[str, list[ModelResult]] = {m: self.group("model", m) for m in self.s["methods"]}
        data = {m: v for m, v in data.items() if v}
        if not data:
            return None
        fig, axes = _figure(figsize=(6.5, 4))
        ax = axes[0, 0]
        errors = [np.maximum(-np.array([float(r.test_mean) for r in v]), 1e-3) for v in data.values()]
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
        for m in self.s["methods"]:
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
                    fmt(_sd(r)),
                    fmt(p.get("sd")),
                    f"{crashes} of {episodes}",
                ]
            )
            if p:
                self.comparisons.append(
                    f"{m.upper()}: our median {fmt(np.median(r))} vs paper {fmt(p.get('r_m'))}; our mean "
                    f"{fmt(r.mean())} vs paper {fmt(p.get('r_a'))}; our time to learn {fmt(t.mean())} s vs paper "
                    f"{fmt(p.get('t'))} s."
                )
        if ref and means:
            ours = sorted(means, key=lambda k: -means[k])
            paper = sorted((k for k in ref if k in means), key=lambda k: -ref[k]["r_a"])
            self.comparisons.append(
                "Ranking by mean return (best first): ours "
                + " > ".join(x.upper() for x in ours)
                + "; paper "
                + " > ".join(x.upper() for x in paper)
                + (" (same order)." if ours == paper else " (different order).")
            )
        return (
            "### Table 4\n\n"
            + _table(["method", "MDPs", "t (s)", "paper t", "r_m", "paper r_m", "r_a", "paper r_a", "sd", "paper sd", "crashed episodes"], rows)
            + f"\n\nt: seconds to learn the model from one episode of flight data of the generic policy; r_m, r_a, sd: median, "
            f"mean and sd over MDPs of the evolved policy's mean return over {self.s['test_episodes']} episodes in the true MDP.\n"
        )


class _TestRuns(_Section):
    def groups(self) -> list[dict]:
        return self.s["groups"]

    def runs(self, label: str) -> list[TestRunResult]:
        return self.group("run", label)

    def figure(self) -> str | None:
        data = {g["label"]: self.runs(g["label"]) for g in self.groups()}
        data = {k: v for k, v in data.items() if v}
        if not data:
            return None
        fig, axes = _figure(2, figsize=(11, 4.2))
        axes = axes[0]
        for label, runs in data.items():
            cum = -np.cumsum(np.array([[float(x) for x in r.returns] for r in runs]), axis=1).mean(axis=0)
            episodes = np.arange(1, cum.size + 1)
            for ax in axes:
                ax.plot(episodes, cum, label=f"{label} ({len(runs)} runs)")
        return self.save_panels(fig, axes, "episode", ("mean cumulative error (-cumulative reward)", "mean cumulative error (log scale)"))

    def body(self) -> str:
        ref = self.paper.get("groups", {})
        rows, samples, labels = [], {}, {}
        for g in self.groups():
            label = g["label"]
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
                    fmt(_sd(scores)),
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
        return (
            "### Test runs\n\n"
            + _table(
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
            + f"\n\nEach run: {self.s['episodes']} episodes of {self.s['n_steps']} control steps on one MDP; the score is the "
            "cumulative reward of the whole run.\n"
        )


QUICK_NOTE = "a fast smoke-scale run: short episodes and few runs; magnitudes are not comparable with the paper"
_SECTIONS = {"evolution": _Evolution, "model_learning": _ModelLearning, "test_runs": _TestRuns}

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
        settings += "; " + ", ".join(f"{g['label']}: {g['n_mdps']} {g['mdps']} MDPs x {g['runs_per_mdp']}" for g in cfg.settings["groups"])
    status = "complete" if total is not None and done >= total else f"INCOMPLETE ({done} of {total} units)"
    return (
        f"- Paper: {cfg.paper_ref or 'n/a'}\n"
        f"- Scale: **{cfg.scale}** ({'the paper protocol' if cfg.scale == 'paper' else QUICK_NOTE}); config hash `{cfg.hash}`\n"
        f"- Settings: {settings}\n"
        f"- Units: {done} finished, {status}\n"
        f"- Time: {wall:.1f} s wall over {len(sessions)} session(s) on {', '.join(map(str, cores)) or '?'} core(s) "
        f"({', '.join(executors) or '?'}); {unit_seconds:.1f} s summed over units\n"
    )


def _section(cfg: ExperimentConfig, store: Store, out: Path) -> str:
    from .plans import plan

    units = store.units(cfg.name, cfg.scale)
    try:
        total = plan(cfg, {u["key"]: u["result"] for u in units}).total
    except NeurohoverError:
        total = None
    results = {u["key"]: result_from_dict(u["kind"], u["result"], u["key"]) for u in units}
    sec = _SECTIONS[cfg.kind](cfg, results, store, out)
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
    return "\n".join(text)


QUICK_DISCUSSION = (
    "Quick scale only: a check of the whole pipeline with 200-step episodes, few runs and tiny evolution "
    "budgets. Its numbers are not comparable with the paper's; run `neurohover reproduce NAME --scale "
    "paper` for that."
)


def _discussion(cfg: ExperimentConfig, out: Path) -> str:
    """The hand-written discussion ``discussion/<name>-<scale>.md`` beside the report, kept across regenerations."""
    path = out / "discussion" / f"{cfg.name}-{cfg.scale}.md"
    if path.is_file():
        return path.read_text().strip()
    if cfg.scale == "quick":
        return QUICK_DISCUSSION
    return (
        f"_Not written yet: how these results compare with the paper's, and why, goes in "
        f"`discussion/{cfg.name}-{cfg.scale}.md` beside this report; `neurohover report` includes it._"
    )


def write_report(store: Store, out: str | Path, *, scale: str | None = None, names: list[str] | None = None) -> Path:
    """Write figures and ``report.md`` for the experiments in ``store`` into ``out``; returns report.md's path."""
    out = Path(out)
    out.mkdir(parents=True, exist_ok=True)
    entries = [(n, s) for n, s, _, _ in store.experiments() if (scale is None or s == scale) and (not names or n in names)]
    if names:
        missing = [n for n in names if n not in {e[0] for e in entries}]
        if missing:
            raise NeurohoverError(store.missing_message(missing[0], scale))
    if not entries:
        raise NeurohoverError(store.missing_message("(any)", scale))
    rank = {n: i for i, n in enumerate(ORDER)}
    entries.sort(key=lambda e: (rank.get(e[0], len(ORDER)), e[0], e[1]))
    sections, toc = [], []
    for name, sc in entries:
        cfg = ExperimentConfig.from_dict(store.config(name, sc))
        sections.append(_section(cfg, store, out))
        toc.append(f"- [{cfg.title} [{sc}]](#{_anchor(cfg.title + ' [' + sc + ']')})")
    head = (
        f"# Reproduction report: Koppejan & Whiteson (2011)\n\n"
        f"Generated {time.strftime('%Y-%m-%d %H:%M:%S')} from the results store `{store.path}`. Error is minus the "
        f"return (lower is better). Quick-scale runs use short episodes and few runs: they check the pipeline, and "
        f"their numbers are not comparable in magnitude with the paper's.\n\n" + "\n".join(toc) + "\n"
    )
    path = out / "report.md"
    path.write_text(head + "\n" + "\n".join(sections))
    return path


def _anchor(title: str) -> str:
    keep = "".join(c for c in title.lower() if c.isalnum() or c in " -_")
    return keep.replace(" ", "-")
