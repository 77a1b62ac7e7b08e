"""Internal: a competition's output folder (:func:`neurohover.compete.compete`'s ``out``): the lock a running
competition holds there, the files it may replace there (and those it refuses to), and its ``episodes.csv`` and
``summary.json``, each written whole or not at all (plumbing: its callers give it checked values)."""

from __future__ import annotations

import csv
import json
import os
import sys
from collections.abc import Iterator, Sequence
from contextlib import contextmanager
from pathlib import Path

from .compete_files import CSV_COLUMNS  # the columns plot --compete reads, each checked (T23-07)
from .errors import NeurohoverError, brief

__all__ = [
    "LOCK_FILE", "OUT_FILES", "OWN_FILES", "episode_rows", "held_competition", "note_replaced", "refuse_other_files", "refuse_store_in_out",
    "sole_competition", "write_episodes", "write_partial", "write_summary",
]  # fmt: skip


def episode_rows(run: int, result, n_steps: int) -> list[list]:
    """The ``episodes.csv`` rows of one test run (a ``TestRunResult``)."""
    policy = [""] * len(result.returns)
    for e, label in result.policy_changes:
        policy[e:] = [label] * (len(policy) - e)
    steps = [n_steps] * len(policy)
    for e, s in zip(result.crash_episodes, result.crash_steps or (), strict=False):
        steps[e] = s
    crashed, fired = set(result.crash_episodes), set(result.safeguard_episodes)
    return [[run, result.mdp, e, repr(float(ret)), int(e in crashed), steps[e], policy[e], int(e in fired)] for e, ret in enumerate(result.returns)]


#: The lock file a running competition holds in its output directory (:func:`sole_competition`).
LOCK_FILE = ".compete.lock"


@contextmanager
def sole_competition(out: Path) -> Iterator[None]:
    """Be the only competition writing into ``out`` inside this block: a second run there is refused, naming the first's
    pid. Two runs into one folder with other --store files both finished, each printing the folder's files as its own
    results, which were the second's (trial 31, borderline). A lock on :data:`LOCK_FILE` in ``out``
    (:func:`~neurohover.locks.holding`, beside the default store's own lock)."""
    from .locks import holding

    busy = "is in use: another compete run ({}) is writing its files; wait for it to end, or give another output directory"
    with holding(out / LOCK_FILE, lambda who: f"out {brief(str(out))} {busy.format(who)}"):
        yield


def write_partial(episodes_csv: Path, ordered: list, n_steps: int) -> None:
    """The finished runs of a competition that stopped before its end, as its ``episodes_csv`` alone: an earlier
    competition's summary.json and cumulative.png in that folder are removed first, as :func:`note_replaced` says. They
    stayed beside the new rows, and plot --compete refused the folder, blaming the new rows (T34-A04); a folder without
    a summary is what an interrupted competition leaves, and plot --compete labels it by its name."""
    for name in ("summary.json", "cumulative.png"):
        stale = episodes_csv.parent / name
        if stale.is_file() or stale.is_symlink():  # refuse_other_files let only a competition's summary (or an empty file) stay
            stale.unlink()
    write_episodes(episodes_csv, ordered, n_steps)


def write_summary(path: Path, summary: dict) -> None:
    from .paths import writing

    with writing(path, "summary file") as partial:  # whole or not at all
        partial.write_text(json.dumps(summary, indent=1) + "\n", encoding="utf-8")


#: The files compete writes in its output directory that another neurohover file may sit at, and what
#: :func:`~neurohover.filekinds.held_kind` calls each when compete wrote it.
OWN_FILES = {"summary.json": "a competition summary (summary.json)", "episodes.csv": "a competition's episodes (episodes.csv)"}


#: Every file compete writes in its output directory (its runs' files and its lock), none of which a store may be.
OUT_FILES = (*OWN_FILES, "cumulative.png", LOCK_FILE)


def refuse_store_in_out(out: Path, store: Path) -> None:
    """Refuse a results ``store`` that is one of :data:`OUT_FILES` in ``out``, or whose lock file is (its paths resolved:
    './', symbolic and hard links): compete wrote its summary.json or episodes.csv over the store it had just filled,
    and its runs were lost (T60-A01); an existing store there is refused the same way, before anything is written."""
    from .filekinds import STORE_ENDS

    real = os.path.realpath(store)
    for name in OUT_FILES:
        mine = out / name
        for end in ("", *STORE_ENDS):  # STORE.lock is written beside it: a store 'OUT/.compete' locked compete's lock
            if not _same_file(real + end, mine):
                continue
            what = "is" if not end else f"has its {end} file at"
            harm = "writing it would destroy the store and its runs" if not end else f"the store's {end} file and compete's {name} would be one"
            raise NeurohoverError(
                f"store {brief(str(store))} {what} {name} in the output directory {brief(str(out))}, one of the files compete "
                f"writes there itself ({', '.join(OUT_FILES)}): {harm}; give the store another path"
            )


def _same_file(a: str, b: Path) -> bool:
    """Whether the paths ``a`` and ``b`` name one file, existing or not: the same once resolved, or hard links."""
    return a == os.path.realpath(b) or (os.path.exists(a) and os.path.exists(b) and os.path.samefile(a, b))


def refuse_other_files(out: Path, store: Path) -> None:
    """Refuse a ``store`` among compete's own files in ``out`` (:func:`refuse_store_in_out`), and an output directory
    whose summary.json or episodes.csv is not a competition's, naming what it is, before any run: flight data, a model
    or a policy file there was replaced without a word (T26-A06). An empty file is replaced (nothing is lost), and so is
    an older competition's summary (its task and agent, which :func:`note_replaced` names); a file no neurohover command
    wrote is refused too (it may be anyone's). So is a cumulative.png the plot would not replace, as the plot checks it
    (it was checked once every run flew; T50-A05)."""
    from .filekinds import PNG_KIND, held_kind
    from .paths import output_file, refuse_foreign_output, refuse_special_file

    refuse_store_in_out(out, store)  # first: a store there is named as the store, whatever else it is (T60-A01)
    for name, own in OWN_FILES.items():
        path = out / name
        refuse_special_file(path, "--out", instead="move it away or give another output directory")  # a FIFO hung it (T28-A08)
        if not (path.is_dir() or path.is_file()) or (path.is_file() and path.stat().st_size == 0):
            continue
        held = "a directory" if path.is_dir() else held_kind(path)
        if held == own or (held is None and name == "summary.json" and held_competition(path) is not None):
            continue
        what, written = held or "no file compete wrote", own.replace(f" ({name})", "")
        raise NeurohoverError(f"{name} in {brief(str(out))} is {what}: compete would replace it with {written}; move it away or give another output directory")
    plot = out / "cumulative.png"  # checked as plot_cumulative and write_png check it once every run flew (T50-A05)
    output_file(plot, "plot file", suffixes=(".png",), what="a plot is PNG")
    refuse_foreign_output(plot, "plot file", PNG_KIND)


def held_competition(summary_path: Path) -> tuple[str, str, object] | None:
    """The (task, agent, scale) of the competition summary at ``summary_path``, None for anything else (no file, not one)."""
    try:
        before = json.loads(summary_path.read_text(encoding="utf-8"))
        return (before["task"], before["agent"], before.get("scale"))
    except (OSError, ValueError, RecursionError, KeyError, TypeError, AttributeError):
        return None


def note_replaced(summary_path: Path, task: str, agent: str, scale: str) -> None:
    """Say when ``out`` holds another competition, whose files this one replaces (without a word before; eighth trial):
    of another agent or task, or of the same with other settings (its ``scale``, settings-HASH: a re-run with only --seed
    changed replaced them without a word, trial 27); its runs stay in the store."""
    held = held_competition(summary_path)
    if held is None:  # no summary, nothing to name
        return
    if held[:2] != (task, agent):
        what = f"the competition of {held[1]} on {held[0]}"
    elif held[2] != scale:
        what = f"a competition of {agent} on {task} with other settings ({brief(held[2])}; these are {scale})"
    else:
        return
    print(
        f"neurohover compete: note: {str(summary_path.parent)!r} held {what}; its episodes.csv, summary.json and plot are replaced "
        "(its runs stay in the store; stopped before its end, this one leaves only the episodes.csv of its finished runs, and the "
        "folder as it was if none had finished)",
        file=sys.stderr,
    )


def write_episodes(path: Path, results: Sequence, n_steps: int) -> None:
    from .paths import writing

    with writing(path, "episodes file") as partial, open(partial, "w", newline="", encoding="utf-8") as f:  # whole or not at all (a full disk: eighth trial)
        writer = csv.writer(f)
        writer.writerow(CSV_COLUMNS)
        for run, result in enumerate(results):
            writer.writerows(episode_rows(run, result, n_steps))
