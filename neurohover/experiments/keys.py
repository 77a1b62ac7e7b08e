"""Unit keys: the names the planner gives units (``run/<group>/<mdps><i>/rep<r>``, ...) and their parts.

Internal: neurohover's plumbing, called with values neurohover has checked: its helpers trust their callers and do not
check their own arguments (README, Python API, What is public).
"""

from __future__ import annotations

import functools
import re
from dataclasses import dataclass

__all__ = ["UnitKey", "key_matches"]

_KEY_PATTERNS = (
    ("evolve", re.compile(r"evolve/(?P<group>.+?)(?:/(?P<mdp>train\d+))?/run(?P<rep>\d+)")),
    ("robust", re.compile(r"robust/(?P<group>.+)/(?P<mdp>train\d+)")),
    ("policy", re.compile(r"policy/(?P<group>.+)")),
    ("model", re.compile(r"model/(?P<group>.+)/(?P<mdp>[a-z]+\d+)")),
    ("run", re.compile(r"run/(?P<group>.+)/(?P<mdp>[a-z]+\d+)/rep(?P<rep>\d+)")),
)


@dataclass(frozen=True)
class UnitKey:
    """The parts of a unit key (the scheme of :mod:`~neurohover.experiments.plans`).

    ========================================  ========  =============  =========  =====
    key                                       stage     group          mdp        rep
    ========================================  ========  =============  =========  =====
    ``evolve/<variant>/train<i>/run<r>``      evolve    variant        train<i>   r
    ``evolve/<variant>/run<r>``               evolve    variant        None       r
    ``robust/<variant>/train<i>``             robust    variant        train<i>   None
    ``policy/<name>``                         policy    name           None       None
    ``model/<method>/<mdps><i>``              model     method         <mdps><i>  None
    ``run/<group>/<mdps><i>/rep<r>``          run       group label    <mdps><i>  r
    anything else (e.g. diagnostic units)     ""        ""             None       None
    ========================================  ========  =============  =========  =====

    Attributes
    ----------
    key : str
    stage : str
    group : str
    mdp : str or None
        Which MDP set and index (``"train3"``, ``"test0"``, ``"sample2"``).
    rep : int or None
        The run or repetition number.
    """

    key: str
    stage: str
    group: str
    mdp: str | None = None
    rep: int | None = None

    @property
    def mdp_index(self) -> int | None:
        """The index in :attr:`mdp` (``3`` of ``"train3"``), or None without one."""
        digits = (self.mdp or "").lstrip("abcdefghijklmnopqrstuvwxyz")
        return int(digits) if digits.isdigit() else None

    @classmethod
    def make(cls, stage: str, group: str, mdp: str | None = None, rep: int | None = None) -> str:
        """The key of a unit with these parts (the planner's only way to name units): the inverse of :meth:`parse`.

        Raises ValueError for parts outside the scheme (a part that would not parse back).
        """
        forms = {
            "evolve": f"evolve/{group}/{mdp}/run{rep}" if mdp is not None else f"evolve/{group}/run{rep}",
            "robust": f"robust/{group}/{mdp}",
            "policy": f"policy/{group}",
            "model": f"model/{group}/{mdp}",
            "run": f"run/{group}/{mdp}/rep{rep}",
        }
        if stage not in forms:
            raise ValueError(f"unknown unit stage {stage!r}: allowed {', '.join(forms)}")
        key = forms[stage]
        if cls.parse(key) != cls(key, stage, group, mdp, rep if stage in ("evolve", "run") else None):
            raise ValueError(f"unit key parts {(stage, group, mdp, rep)!r} do not fit the key scheme")
        return key

    @classmethod
    def parse(cls, key: str) -> UnitKey:
        """Split a unit key into its parts.

        Parameters
        ----------
        key : str
            A unit key; one outside the scheme (e.g. a diagnostic unit's) gives stage and group ``""``.

        Returns
        -------
        UnitKey
        """
        for stage, pattern in _KEY_PATTERNS:
            m = pattern.fullmatch(key)
            if m:
                parts = m.groupdict()
                rep = parts.get("rep")
                return cls(key, stage, parts["group"], parts.get("mdp"), None if rep is None else int(rep))
        return cls(key, "", "")


@functools.lru_cache(maxsize=256)
def _pattern_regex(pattern: str) -> re.Pattern[str]:
    """The regular expression of an ``--only`` glob: ``*`` any text within one part of a key (no '/'), ``**`` any text
    across parts, ``?`` one character but '/', ``[...]`` / ``[!...]`` one character of (not of) a set, but '/'."""
    out, i, n = [], 0, len(pattern)
    while i < n:
        ch = pattern[i]
        if pattern.startswith("**", i):
            out.append(".*")
            i += 2
            continue
        i += 1
        if ch == "*":
            out.append("[^/]*")
        elif ch == "?":
            out.append("[^/]")
        elif ch == "[":
            j = i + (i < n and pattern[i] == "!")
            j += j < n and pattern[j] == "]"  # a ']' first is one of the set
            j = pattern.find("]", j)
            if j < 0:  # no closing ']': a literal '['
                out.append(re.escape(ch))
                continue
            body, i = pattern[i:j], j + 1
            negated = body.startswith("!")
            body = re.sub(r"([\\^\[&~|])", r"\\\1", body[negated:])  # literal in the set (a '-' keeps its ranges)
            out.append(f"[^{body}/]" if negated else f"(?!/)[{body}]")
        else:
            out.append(re.escape(ch))
    try:
        return re.compile("".join(out), re.DOTALL)
    except re.error:  # a set no regex takes ("[z-a]"): the pattern as it is written
        return re.compile(re.escape(pattern))


def key_matches(key: str, pattern: str) -> bool:
    """Whether unit ``key`` matches the ``--only`` glob ``pattern`` (case counts): ``*`` and ``?`` stay within one part of
    the key, between two '/', and ``**`` crosses them. A group label may hold '/' (``base/mf``): with fnmatch's ``*``,
    ``run/base/*/rep0`` selected that group's units too (T28-A11)."""
    return _pattern_regex(pattern).fullmatch(key) is not None
