"""The report's first section: the paper's claims checked at paper scale, and what the measurements say of its conclusions."""

from __future__ import annotations

from pathlib import Path

from ..errors import NeurohoverError
from ..paths import refuse_special_file
from .report_base import table

#: The paper's tables and figures, whose claims the claims table lists (at paper scale), in the paper's order.
PAPER_FIGURES = ("fig2", "table4", "fig7", "fig8", "fig11", "fig12", "fig13", "fig15", "fig16")

#: The paper's conclusions (Section 8) and the figures whose tests bear on each.
CONCLUSIONS = (
    ("(1) neuroevolution can be effective for complex on-line reinforcement learning tasks", ("fig2", "fig7", "fig8")),
    ("(2) neuroevolution excels at finding effective policies but not at learning helicopter models", ("table4",)),
    ("(3)-(4) model-based approaches are feasible, and superior, only with a suitable model representation", ("fig7", "fig8", "fig11")),
    ("(5) efficient resampling lets neuroevolution tackle more aggressively generalized tasks", ("fig15", "fig16")),
)


def claims_section(claims: dict[str, tuple[str, list[dict[str, str]]]]) -> str:
    """The report's first section: every claim of the paper's figures checked at paper scale, then each conclusion
    with the verdicts of the claims that bear on it. A reversed effect is counted as reversed, never as agreement."""
    rows = [
        [f"[{name}](#{anchor})", c["claim"], c["paper"], c["ours"], c["verdict"]]
        for name in PAPER_FIGURES
        if name in claims
        for anchor, checked in [claims[name]]
        for c in checked
    ]
    if not rows:
        return ""
    lines = []  # each conclusion with the verdicts of the t tests and rankings of its figures (not their numbers)
    for conclusion, figures in CONCLUSIONS:
        verdicts = [c["verdict"] for f in figures if f in claims for c in claims[f][1] if c["kind"] in ("test", "ranking")]
        tests = [v for v in verdicts if v]
        held = sum(v.startswith("holds") or v.startswith("within") for v in tests)
        reversed_ = sum(v.startswith("reversed") for v in tests)
        where = ", ".join(f"[{f}](#{claims[f][0]})" for f in figures if f in claims) or "no figure at paper scale yet"
        lines.append(
            [conclusion, where, f"{held} of {len(tests)}", str(reversed_), str(len(tests) - held - reversed_)] if tests else [conclusion, where, "", "", ""]
        )
    return (
        "## Claims and conclusions (paper scale)\n\n"
        + table(["figure", "claim", "paper", "ours", "verdict"], rows)
        + "\n\nEach t test's verdict weighs direction before significance: *holds* (same direction, as significant), "
        "*same direction, weaker* or *not significant*, *reversed* (the effect runs the other way, whatever the p-values). "
        "Numbers: *within a factor of two* of the paper's, or how many times it. Each figure's section says why a claim differs.\n\n"
        "### The paper's conclusions\n\n"
        + table(["conclusion (Section 8)", "figures", "claims that hold", "reversed", "weaker, not significant or otherwise differing"], lines)
        + "\n"
    )


#: The hand-written account of the paper's conclusions, beside the report (kept across regenerations).
CONCLUSIONS_DISCUSSION = Path("discussion") / "conclusions-paper.md"


def conclusions_discussion(out: Path) -> str:
    """``discussion/conclusions-paper.md`` beside the report, under the conclusions table: each conclusion read from
    the measurements (its figures' sections and the experiments beyond the paper that measured why a claim differs)."""
    text = read_discussion(Path(out) / CONCLUSIONS_DISCUSSION)
    return "" if text is None else "\n### The conclusions, measured\n\n" + text + "\n"


class DiscussionError(NeurohoverError):
    """A hand-written discussion that cannot be read: the user's file, not a damaged store."""


def read_discussion(path: Path) -> str | None:
    """A hand-written discussion's text (a byte-order mark dropped), None where there is none.

    Raises
    ------
    DiscussionError
        If something is there that is no readable UTF-8 file (a directory was skipped without a word, other bytes a
        traceback; ninth trial).
    """
    if not (path.exists() or path.is_symlink()):
        return None
    try:  # a FIFO hung the report for ever (T28-A08)
        refuse_special_file(path, "discussion", instead="give a Markdown file in UTF-8, or remove it")
    except NeurohoverError as err:
        raise DiscussionError(str(err)) from None
    try:
        return path.read_text(encoding="utf-8-sig").strip()
    except (OSError, UnicodeDecodeError) as err:
        reason = "it is not UTF-8 text" if isinstance(err, UnicodeDecodeError) else (err.strerror or str(err))
        raise DiscussionError(f"discussion {str(path)!r} cannot be read ({reason}): give a Markdown file in UTF-8, or remove it") from None
