"""The report's evolution sections (Figures 2, 12, 13, 15 and the ablations of evolution): champion curves, final scores, FGHH's fitness scale."""

from __future__ import annotations

import warnings
from collections.abc import Sequence
from pathlib import Path

import numpy as np

from ..errors import NeurohoverError
from ..evolution.fitness import episode_fitness, error_of_fitness
from .config import ExperimentConfig, load_config
from .keys import UnitKey
from .report_base import Section, fmt, new_figure, paired_p, ratio_verdict, sd, table, ttest
from .results import EvolveResult, RobustnessResult, result_from_dict
from .schema import POLICY_SET_GROUP
from .settings import EvolutionSettings, Variant


def _curve(points: Sequence[Sequence[float | str]], grid: np.ndarray, sign: float = -1.0) -> np.ndarray:
    """Champion error (``sign`` -1; +1: the champion's fitness as recorded) of one run on ``grid``
    (a step function; NaN before its first record, held after its last)."""
    xs = np.array([p[0] for p in points], dtype=float)
    ys = sign * np.array([float(p[1]) for p in points], dtype=float)
    idx = np.searchsorted(xs, grid, side="right") - 1
    out = np.where(idx >= 0, ys[np.clip(idx, 0, None)], np.nan)
    return out


class EvolutionSection(Section):
    def variants(self) -> tuple[Variant, ...]:
        return self.s.variants

    def runs(self, vkey: str) -> list[EvolveResult]:
        return self.group("evolve", vkey)

    def final_scores(self, runs: list[EvolveResult]) -> list[float]:
        """Per run: the mean validation return, or on the 1/ln(error) scale the mean validation fitness."""
        if self._fghh_style() and all(r.validation is not None for r in runs):
            return [_validation_fitness(r.validation) for r in runs]
        return [r.final_score for r in runs]

    def figure(self) -> str | None:
        data = {v.key: self.runs(v.key) for v in self.variants()}
        if not any(data.values()):
            return None
        if self._fghh_style():
            return self._fitness_figure(data)
        xmax = max(r.history[-1][0] for runs in data.values() for r in runs)
        xmin = min(r.history[0][0] for runs in data.values() for r in runs)
        grid = np.linspace(max(xmin, 1), xmax, 400)
        two = self.cfg.name == "fig2" or self.s.target == "train"
        fig, axes = new_figure(2 if two else 1, figsize=(11 if two else 6.5, 4.2))
        axes = axes[0]
        for v in self.variants():
            runs = data[v.key]
            if not runs:
                continue
            curves = np.array([_curve(r.history, grid) for r in runs])
            with np.errstate(all="ignore"), warnings.catch_warnings():
                warnings.simplefilter("ignore", RuntimeWarning)  # grid points before any run's first champion
                mean = np.nanmean(np.where(np.isfinite(curves), curves, np.nan), axis=0)
            axes[0].plot(grid, mean, label=v.label)
            if two:
                best = int(np.argmin([-float(r.champion_return) for r in runs]))
                axes[1].plot(grid, curves[best], label=v.label)
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
        fig, axes = new_figure(2, figsize=(11, 4.2))
        axes = axes[0]
        for v in self.variants():
            runs = data[v.key]
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
            axes[0].plot(grid, fitness, label=f"{v.label} ({len(runs)} runs{note})")
            axes[1].plot(grid, error, label=v.label)
        return self.save_panels(fig, axes, "episodes", ("champion fitness, 1/ln(error) (mean over runs)", "as error, exp(1/fitness) (log scale)"))

    def _fghh_style(self) -> bool:
        """Whether the section reads as FGHH's as the authors ran it: runs on the 1/ln(error) scale,
        or champions validated on the test MDPs (every variant then compared on 1/ln(error))."""
        runs = [r for v in self.variants() for r in self.runs(v.key)]
        return bool(runs) and (any(r.fitness == FITNESS_SCALE for r in runs) or self.s.validation_mdps == "test")

    def _fitness_body(self) -> str:
        """Final champions of runs on the 1/ln(error) scale, flown on the test MDPs, beside the authors' generics."""
        rows, samples, labels = [], {}, {}
        for v in self.variants():
            runs = self.runs(v.key)
            if not runs:
                continue
            row, finals = _validation_row(v.label, [[float(x) for x in r.validation or ()] for r in runs], [r.validation_crashed for r in runs])
            champ = float(np.mean([float(r.champion_return) for r in runs]))
            if _on_fitness_scale(runs):
                estimate, as_error = fmt(champ), fmt(float(error_of_fitness(champ, FITNESS_SCALE)))
            else:  # a variant run on mean raw returns
                estimate, as_error = f"{fmt(champ)} (a return)", fmt(-champ)
            rows.append([row[0], str(len(runs)), estimate, as_error, *row[1:]])
            rows[-1] += [fmt(np.mean([r.episodes for r in runs])), fmt(np.mean([r.timing.seconds for r in runs]))]
            if finals:  # runs without validation have no final scores to rank or test
                samples[v.key], labels[v.key] = finals, v.label
        authors = _authors_generics(self.out, self.cfg)
        for folder, entry in authors.items():
            row, _ = _validation_row(f"the authors' {folder} ({len(entry['returns'])} files)", entry["returns"], entry["crashed"])
            rows.append([row[0], str(len(entry["returns"])), "", "", *row[1:], "", ""])
        where = "once on each of the family's test MDPs, the same gusts for every run" if self.s.validation_mdps == "test" else "on fresh MDPs"
        text = (
            "### Final champions\n\n"
            + table(
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
        if self.s.seeds_of is not None and samples:
            text += self._paired_block(samples, labels)
        if self.s.champion_reevaluation:
            text += self._reevaluation_block()
        return text

    def _reevaluation_block(self) -> str:
        """Each run's own champion against the one chosen again from its last parents or its best ever (validated alike)."""
        rows = []
        for v in self.variants():
            for among, field in (("last parents", "reevaluated"), ("best ever", "reevaluated_best_ever")):
                rows += self._reevaluation_row(v, among, field)
        if not rows:
            return ""
        n = self.s.champion_reevaluation
        return (
            "\n### The champion chosen again\n\n"
            + table(
                ["setting", "among", "runs", "own champion", "chosen again", "runs better", "same policy", "Wilcoxon p", "own crash rate", "again crash rate"],
                rows,
            )
            + f"\n\nA run's own champion is the last generation's best selected parent by its estimate (the luckiest of mu short "
            f"ones where the race decides nothing). Chosen again: each candidate flown the same {n} fresh episodes (each on a fresh "
            "MDP from G), the best mean 1/ln(error) kept; the candidates are the last generation's selected parents, or the run's "
            "best generation champions by their estimates (best ever). Both champions validated on the same episodes (mean "
            "1/ln(error) per run, then over runs; Wilcoxon signed-rank test on the run pairs).\n"
        )

    def _reevaluation_row(self, v: Variant, among: str, field: str) -> list[list[str]]:
        """The row of variant ``v``'s runs' champions chosen again among ``among`` (their result's ``field``), if any."""
        runs = [r for r in self.runs(v.key) if getattr(r, field) is not None and getattr(r, field).validation is not None and r.validation is not None]
        if not runs:
            return []
        own = np.array([_validation_fitness(r.validation) for r in runs])
        again = np.array([_validation_fitness(getattr(r, field).validation) for r in runs])
        diff = again - own
        p = paired_p(diff) if len(runs) >= 2 else 1.0
        same = sum(getattr(r, field).champion == r.champion for r in runs)
        word = "better" if again.mean() > own.mean() else "worse" if again.mean() < own.mean() else "as good"
        self.comparisons.append(
            f"{v.label}: the champion chosen again among the {among} is {word} than the run's own (mean validation 1/ln(error) {fmt(float(again.mean()))} "
            f"vs {fmt(float(own.mean()))}, Wilcoxon p = {fmt(p)}" + (", significant at 5%)." if p < 0.05 else ", not significant).")
        )
        return [
            [
                v.label,
                among,
                str(len(runs)),
                fmt(float(own.mean())),
                fmt(float(again.mean())),
                f"{int((diff > 0).sum())} of {len(runs)}",
                str(same),
                fmt(p),
                _crash_share(r.validation_crashed for r in runs),
                _crash_share(getattr(r, field).validation_crashed for r in runs),
            ]
        ]

    def _paired_block(self, samples: dict[str, list[float]], labels: dict[str, str]) -> str:
        """Each variant against the runs of the other experiment's variant whose seeds it took (Wilcoxon signed-rank
        on the run pairs' validation 1/ln(error)), and against that experiment's fixed-resampling variants (Welch's t)."""
        source = self.s.seeds_of["experiment"]
        try:
            other = load_config(source, self.cfg.scale)
        except NeurohoverError:
            return f"\nPaired with {source}: not a shipped experiment, so not compared.\n"
        theirs = {u["key"]: result_from_dict(u["kind"], u["result"], u["key"]) for u in self.store.units(source, self.cfg.scale, missing_ok=True)}

        def scores(results: dict, vkey: str) -> dict[int | None, float]:
            """Run number -> mean validation 1/ln(error) of the variant's runs (validated ones)."""
            keys = [(k, UnitKey.parse(k)) for k in results if k.startswith("evolve/")]
            runs = {key.rep: results[k] for k, key in keys if key.group == vkey}
            return {rep: _validation_fitness(r.validation) for rep, r in runs.items() if r.validation is not None}

        if not isinstance(other.typed, EvolutionSettings):
            return f"\nPaired with {source}: not an evolution experiment, so not compared.\n"
        fixed = [v for v in other.typed.variants if v.resampling.startswith("fixed")]
        rows = []
        for v in self.variants():
            if v.key not in samples:
                continue
            mine, pair = scores(self.results, v.key), scores(theirs, v.paired_with or v.key)
            common = sorted(set(mine) & set(pair), key=str)
            row = [v.label, f"{source}/{v.paired_with or v.key}", str(len(common))]
            if len(common) >= 2:
                diff = np.array([mine[r] - pair[r] for r in common])
                p = paired_p(diff)
                better = int(np.sum(diff > 0))
                row += [fmt(np.mean([mine[r] for r in common])), fmt(np.mean([pair[r] for r in common])), f"{better} of {len(common)}", fmt(float(p))]
            else:
                row += ["", "", "", ""]
            for f in fixed:
                base = list(scores(theirs, f.key).values())
                welch = ttest(samples[v.key], base)[2]
                if welch is not None:
                    p = welch
                    mine_mean, base_mean = np.mean(samples[v.key]), np.mean(base)
                    word = "better" if mine_mean > base_mean else "worse" if mine_mean < base_mean else "equal"
                    row.append(f"{word}, p = {fmt(float(p))}")
                    self.comparisons.append(
                        f"{v.label} vs {source}'s {f.label} (mean validation 1/ln(error), Welch): {fmt(np.mean(samples[v.key]))} vs "
                        f"{fmt(np.mean(base))}, {word}, p = {fmt(float(p))}" + (" (significant at 5%)." if p < 0.05 else " (not significant).")
                    )
                else:
                    row.append("")
            rows.append(row)
        header = ["setting", "paired with", "run pairs", "mean 1/ln(error)", "its pair's", "runs better", "Wilcoxon p"]
        header += [f"vs {source}'s {f.label} (Welch)" for f in fixed]
        return (
            f"\n### Paired with {source}\n\n"
            + table(header, [r + [""] * (len(header) - len(r)) for r in rows])
            + f"\n\nRun r of each setting took the seed of run r of the {source} setting it is paired with (the same initial "
            "population and noise streams) and its champion flew the same validation episodes, so the run pairs differ by the "
            "setting alone. Wilcoxon signed-rank test on the pairs' mean validation 1/ln(error); Welch's t test against "
            f"{source}'s fixed-resampling runs (the paper's comparison).\n"
        )

    def body(self) -> str:
        if self._fghh_style():
            return self._fitness_body()
        parts = []
        rows = []
        samples, labels = {}, {}
        validated = False
        for v in self.variants():
            runs = self.runs(v.key)
            if not runs:
                continue
            champ = [-float(r.champion_return) for r in runs]
            finals = self.final_scores(runs)
            validated = runs[0].validation is not None
            samples[v.key], labels[v.key] = finals, v.label
            stops: dict[str, int] = {}
            for r in runs:
                stops[r.stop_reason] = stops.get(r.stop_reason, 0) + 1
            rows.append(
                [
                    v.label,
                    str(len(runs)),
                    fmt(np.mean(champ)),
                    fmt(np.median(champ)),
                    fmt(np.min(champ)),
                    fmt(-np.mean(finals)) if validated else "n/a",
                    fmt(sd(finals)) if validated else "n/a",
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
            + table(
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
            + (" (each on a fresh MDP from G)" if self.s.target == "family" else " of its MDP")
            + ".\n"
        )
        if samples:
            order = sorted(samples, key=lambda k: -np.mean(samples[k]))
            self.comparisons.append("Ranking by " + what + " (best first): ours " + " > ".join(labels[k] for k in order) + ".")
        self.add_tests(samples, labels, what)
        parts.append(self._paired_within())
        if self.s.robustness_variants:
            parts.append(self.table3())
        return "\n".join(parts)

    def _validated_finals(self, vkey: str) -> dict[tuple, float]:
        """(MDP, run) -> mean validation return of variant ``vkey``'s validated runs."""
        runs = {(key.mdp, key.rep): self.results[k] for k, key in self.keys.items() if key.stage == "evolve" and key.group == vkey}
        return {at: r.final_score for at, r in runs.items() if isinstance(r, EvolveResult) and r.validation is not None}

    def _paired_within(self) -> str:
        """Variants paired with another variant of this experiment (``paired_with``: the same seeds, MDPs and validation
        episodes run by run), compared pair by pair on the mean validation return (Wilcoxon signed-rank)."""
        keys = {v.key for v in self.variants()}
        rows = []
        for v in self.variants():
            other = v.paired_with
            if other is None or other == v.key or other not in keys:
                continue
            mine, theirs = self._validated_finals(v.key), self._validated_finals(other)
            common = sorted(set(mine) & set(theirs), key=str)
            if len(common) < 2:
                continue
            diff = np.array([mine[c] - theirs[c] for c in common])
            p = paired_p(diff)
            label = next(x.label for x in self.variants() if x.key == other)
            a, b = float(np.mean([mine[c] for c in common])), float(np.mean([theirs[c] for c in common]))
            rows.append([v.label, label, str(len(common)), fmt(a), fmt(b), f"{int(np.sum(diff > 0))} of {len(common)}", fmt(float(np.median(diff))), fmt(p)])
            word = "better" if a > b else "worse" if a < b else "equal"
            self.comparisons.append(
                f"{v.label} against {label}, run by run on the same seeds and validation episodes: mean validation return {fmt(a)} vs "
                f"{fmt(b)} ({word} on average), better in {int(np.sum(diff > 0))} of {len(common)} pairs, Wilcoxon p = {fmt(p)}"
                + (" (significant at 5%)." if p < 0.05 else " (not significant).")
            )
        if not rows:
            return ""
        header = ["setting", "paired with", "run pairs", "mean validation return", "its pair's", "runs better", "median difference", "Wilcoxon p"]
        return (
            "\n### Paired runs\n\n"
            + table(header, rows)
            + "\n\nRun r on MDP i of each setting took the seed of run r on MDP i of the setting it is paired with, and its champion "
            "flew the same validation episodes (MDP and gusts): each pair differs by the setting alone. Wilcoxon signed-rank test "
            "on the pairs' mean validation returns.\n"
        )

    def table3(self) -> str:
        rows = []
        ref = self.paper.get("table3", {})
        groups = [(vkey, next(v.label for v in self.variants() if v.key == vkey), ref.get(vkey, {})) for vkey in self.s.robustness_variants]
        if self.s.robustness_policies is not None:  # the set's specialised policies are MLPs evolved from the baseline
            groups.append((POLICY_SET_GROUP, f"MLP, the {self.s.robustness_policies} policy set's specialised policies", ref.get("mlp-baseline", {})))
        for vkey, label, p in groups:
            units: list[RobustnessResult] = self.group("robust", vkey)
            if not units:
                continue
            own = [float(np.mean([float(x) for x in u.returns[u.own]])) for u in units]
            across = [float(np.mean([float(x) for row in u.returns for x in row])) for u in units]
            crashes_own = sum(u.crashes[u.own] for u in units)
            crashes_all = sum(sum(u.crashes) for u in units)
            episodes = sum(len(row) for u in units for row in u.returns)
            rows.append(
                [
                    label,
                    str(len(units)),
                    fmt(np.mean(own)),
                    fmt(sd(own)),
                    fmt(p.get("r")),
                    fmt(p.get("sd")),
                    fmt(np.mean(across)),
                    fmt(sd(across)),
                    fmt(p.get("r_G")),
                    fmt(p.get("sd_G")),
                    f"{crashes_own} / {crashes_all} of {episodes}",
                    str(p.get("crashes_G", "n/a")),
                ]
            )
            for what, ours, key in (("r (own MDP)", float(np.mean(own)), "r"), ("r_G (all training MDPs)", float(np.mean(across)), "r_G")):
                if key in p:
                    self.add_claim(f"Table 3, {label}: {what}", fmt(p[key]), fmt(ours), ratio_verdict(ours, float(p[key])))
            if p:
                self.comparisons.append(
                    f"Table 3, {label}: our r = {fmt(np.mean(own))} vs paper {fmt(p.get('r'))}; "
                    f"our r_G = {fmt(np.mean(across))} vs paper {fmt(p.get('r_G'))}; "
                    f"crashes across the training MDPs: ours {crashes_all}" + (f" vs paper {p['crashes_G']}" if "crashes_G" in p else "") + "."
                )
        if not rows:
            return ""
        n = self.s.robustness_episodes
        return (
            "### Table 3: robustness of the best champions\n\n"
            + table(
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
            f"training MDP used (r_G); sd over the policies' mean returns."
            + (
                f' The policy set\'s row (`robustness_policies = "{self.s.robustness_policies}"`): its specialised policy for each '
                "training MDP flown the same way.\n"
                if self.s.robustness_policies is not None
                else "\n"
            )
        )


FITNESS_SCALE = "inv-log-error"


def _mean_fitness(returns) -> float:
    """Mean 1/ln(error) of one policy's episode returns (a run's validation, or one authors' file's)."""
    return float(np.mean(episode_fitness(np.asarray(returns, dtype=float), FITNESS_SCALE)))


def _validation_fitness(validation) -> float:
    """A champion's mean 1/ln(error) over its validation returns (stored as JSON-safe numbers)."""
    return _mean_fitness([float(x) for x in validation or ()])


def _crash_share(flags) -> str:
    """The share of crashed episodes over runs' per-episode crash flags (None: not recorded)."""
    flat = [bool(c) for cs in flags for c in (cs or ())]
    return f"{np.mean(flat):.1%}" if flat else "n/a"


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
    return [label, rate, fmt(float(np.median(-flat))), fmt(float(np.mean(per_run))), fmt(sd(per_run))], per_run


def _authors_generics(out: Path, cfg: ExperimentConfig) -> dict:
    """The authors' published FGHH generics flown on this experiment's validation MDPs, if measured
    (``authors-fghh-generics.json`` beside the report, written by docs/reproduction/authors_fghh_generics.py)."""
    import json

    path = out / "authors-fghh-generics.json"
    if not path.is_file():
        return {}
    return json.loads(path.read_text(encoding="utf-8")).get(f"{cfg.name}-{cfg.scale}", {})
