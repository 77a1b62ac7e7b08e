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

import sys
import time
from contextlib import AbstractContextManager
from pathlib import Path

from ..errors import NeurohoverError, OutputError, brief, check_flag
from ..filekinds import REPORT_HEADER, REPORT_KIND
from ..plots import house_style
from .config import ORDER, ExperimentConfig, check_paper_table, shipped_counterpart, with_shipped_paper
from .export import checked_experiment, stored_plan
from .plans import Plan
from .report_claims import PAPER_FIGURES, DiscussionError, claims_section, conclusions_discussion, read_discussion
from .report_evolution import EvolutionSection
from .report_factorial import FitFactorial
from .report_models import ModelLearningSection, SensorModels
from .report_readme import Status, check_readme, fill_generated, linked_claims, status_table
from .report_scale import header_note, paper_protocol, quick_discussion, scale_note
from .report_testruns import TestRunsSection
from .settings import ModelLearningSettings
from .store import Store

_SECTIONS = {"evolution": EvolutionSection, "model_learning": ModelLearningSection, "test_runs": TestRunsSection}

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


def _header(cfg: ExperimentConfig, store: Store, units: list[dict], total: int | None, unknown: str = "") -> str:
    done = len(units)
    sessions = store.sessions(cfg.name, cfg.scale)
    wall = sum(s["wall_seconds"] for s in sessions)
    cores = sorted({s["cores"] for s in sessions})
    executors = sorted({s["executor"] for s in sessions})
    unit_seconds = sum(u["seconds"] for u in units)
    settings = ", ".join(f"{k} = {cfg.settings[k]}" for k in _SETTING_KEYS if cfg.settings.get(k) not in (None, ""))
    if cfg.kind == "test_runs":
        settings += "; " + ", ".join(f"{g.label}: {g.n_mdps} {g.mdps} MDPs x {g.runs_per_mdp}" for g in getattr(cfg.typed, "groups", ()))
    if total is None:  # it read "INCOMPLETE (1 of None units)", naming neither (T60-B05)
        status = f"of a total this process cannot count: it cannot plan the experiment again ({unknown})"
    else:
        status = "complete" if done >= total else f"INCOMPLETE ({done} of {total} units)"
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
    _, units, results, made = checked_experiment(store, cfg.name, scale)  # results' check (the row's scale: T21-01), and its messages
    total, unknown = _total(cfg, units, made)
    kind = _SECTIONS[cfg.kind]
    if isinstance(cfg.typed, ModelLearningSettings):
        kind = SensorModels if cfg.typed.conditions else FitFactorial if cfg.typed.fits else kind
    sec = kind(cfg, results, store, out)
    text = [f"## {cfg.title} [{cfg.scale}]\n", _header(cfg, store, units, total, unknown)]
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


def _total(cfg: ExperimentConfig, units: list[dict], made: Plan | None) -> tuple[int | None, str]:
    """The experiment's unit count: that of the plan its check made, else of one made here (its agents this process
    has not registered as the store shows them: T60-B05); None and why where none can be made (a policy directory gone)."""
    if made is not None:
        return made.total, ""
    try:
        return stored_plan(cfg, units).total, ""
    except NeurohoverError as err:
        return None, str(err)


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


@house_style  # the figures in matplotlib's default style, whatever the user's matplotlibrc says (T46-A04)
def write_report(store: Store, out: str | Path, *, scale: str | None = None, names: list[str] | None = None, refuse_all_damaged: bool = False) -> Path:
    """Write figures and ``report.md`` for the experiments in ``store`` into ``out``; returns report.md's path.

    A ``README.md`` in ``out`` with generated blocks gets them filled from the store (:mod:`.report_readme`). A damaged
    experiment is said in its place and in a warning line on stderr; ``refuse_all_damaged`` (the command line's): when
    every experiment asked for is damaged, NeurohoverError and nothing written, not a report of the damage alone. A
    report into an ``out`` that another report is writing is refused, naming its pid (:func:`sole_report`).
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
        with sole_report(out):
            held = held_report(out / "report.md")  # what it replaces, said once written (T40-A04)
            path = _write_report(store, out, scale, names, refuse_all_damaged)
            note_replaced(held, path, store.path)
    return path


#: The lock file a report being written holds in its output directory (:func:`sole_report`).
LOCK_FILE = ".report.lock"


def sole_report(out: Path) -> AbstractContextManager[None]:
    """Be the only report writing into ``out`` inside this block: a second one there is refused, naming the first's pid.
    Two reports of different stores into one --out at once both said "report written", the folder left with one's
    report.md and the other's figures, and no note (T47-A02). A lock on :data:`LOCK_FILE` in ``out``, as compete's
    (:func:`~neurohover.compete_folder.sole_competition`)."""
    from ..locks import holding

    busy = "is in use: another report run ({}) is writing its files; wait for it to end, or give another output directory"
    return holding(out / LOCK_FILE, lambda who: f"report directory {brief(str(out))} {busy.format(who)}")


def _write_report(store: Store, out: Path, scale: str | None, names: list[str] | None, refuse_all_damaged: bool) -> Path:
    from ..paths import printable, refuse_foreign_output, writing

    path = out / "report.md"
    refuse_foreign_output(path, "report", REPORT_KIND)  # before any figure: only a report.md it wrote is replaced (T28-A04)
    check_readme(out / "README.md")  # before any figure: one not UTF-8, or a block twice (T46-B10, T46-B11)

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
        f"Generated {_now()} from the results store `{printable(store.path)}`. Error is minus the "
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


def _now() -> str:
    """The report's Generated time: local time with its UTC offset, ``2026-12-08 00:50:13+14:00`` (a bare local time
    read as another zone's, hours off; trial 49). Written from the C library's local time, which takes any TZ it
    accepts: datetime refuses offsets of 24 hours and more (TZ='UTC-25' was a traceback after every figure; T50-A01)."""
    local = time.localtime()
    offset = local.tm_gmtoff or 0
    hours, rest = divmod(abs(offset), 3600)
    minutes, seconds = divmod(rest, 60)
    zone = f"{'-' if offset < 0 else '+'}{hours:02d}:{minutes:02d}" + (f":{seconds:02d}" if seconds else "")
    return time.strftime("%Y-%m-%d %H:%M:%S", local) + zone


def _anchor(title: str) -> str:
    keep = "".join(c for c in title.lower() if c.isalnum() or c in " -_")
    return keep.replace(" ", "-")
