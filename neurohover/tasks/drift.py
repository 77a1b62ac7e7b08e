"""Drifting dynamics: an MDP whose dynamics change between the episodes of a test run (docs/benchmarks.md).

The paper (Section 7) names the harder problem its benchmark leaves out: "a more challenging
problem would require the agent to constantly refine its model as new flight data arrives". A
:class:`Drift` on an MDP makes episode ``e`` of a test run fly the MDP with its 11 dynamics
parameters (C and D, ``sim.constants.PARAM_NAMES``)

    p_e = p_0 * exp(walk * W_e) * (factor where e >= E),   W_e = z_1 + ... + z_e

``z`` standard normals, one per parameter and episode; ``E`` the episode of the abrupt change,
drawn uniformly from ``change_at`` (the agent is not told it). Both come from the run's own drift
stream (its seed), so two agents run with one seed meet the same drift, and the gusts and sensors
are unchanged. Within an episode the MDP stays fixed.

=============  ==========  =========================================================================
setting        default     meaning
=============  ==========  =========================================================================
walk           0           per-episode std of each parameter's log random walk (0.01: about the
                           breadth of FGHH's G, sigma 0.3, after 1000 episodes); 0 or 2**-52..1
change         {}          factors (0.01..100) of named parameters at the change, e.g.
                           ``{"D_w": 0.8}``: the collective's gain loses 20 %, as under a
                           heavier load
change_at      (200, 800)  the change happens at an episode drawn uniformly from lo..hi
=============  ==========  =========================================================================
"""

from __future__ import annotations

import operator
from collections.abc import Iterator
from dataclasses import dataclass, field

import numpy as np

from ..errors import (
    FloatRangeError,
    NeurohoverError,
    as_floats,
    brief,
    comma_separated,
    finite_real,
    float_of,
    int_of,
    lowest_allowed,
    real_number,
    refuse_reloaded,
    setting_float,
    whole_number,
)
from ..sim.constants import MDP_ROW_LEN, MIN_NOISE, PARAM_NAMES, ROW_PARAMS
from ..sim.rng import MAX_SEED

_DRIFT_TAG = 0xD81F7  # separates a run's drift stream from its agent's and its gusts'
CHANGE_AT = (200, 800)  # the default range of the abrupt change's episode
#: The factors a change may apply: a parameter 100 times larger (or smaller) is already no helicopter; 1e300 was flown
#: as dynamics far outside what --params allows (fifth trial).
MIN_FACTOR, MAX_FACTOR = 0.01, 100.0
#: The latest episode a change may come at: a trillion episodes of 6000 steps outlast any test run (run_test refuses a
#: window past its last episode), and below NumPy's int64, in which the episode is drawn.
MAX_CHANGE_AT = 10**12
#: The most episodes whose rows one call makes (36 floats each: 29 GB at this bound, compete's bound on a call's episodes);
#: past NumPy's int64 (10**20) the count was an OverflowError (fourteenth trial, T14-21).
MAX_RUN_EPISODES = 10**8
#: The smallest walk but 0 (none), float64's epsilon 2**-52 (sim.constants.MIN_NOISE): a parameter's step of one std,
#: exp(walk), is 1.0 below it, and a drifted row was the fixed one (walk=1e-300 was taken, while walk=0 is refused for drifting nothing; T40-B08).
MIN_WALK = MIN_NOISE
_WALK_RANGE = (
    f"allowed 0 (none) or a number in {lowest_allowed(MIN_WALK)}..1 (a per-episode log std; below 2**-52 a step of one std, exp(walk), is 1.0 in float64)"
)
_PARSE_FORM = "give walk=STD or PARAM=FACTOR[@LO-HI], e.g. walk=0.01,D_w=0.8@200-800"
_NOTHING = "give walk > 0 (up to 1) or a change of a factor other than 1, or leave it out (fixed dynamics)"


@dataclass(frozen=True)
class Drift:
    """How an MDP's dynamics change between episodes; ``Drift()`` is none (see the module docstring's table)."""

    walk: float = 0.0
    change: tuple[tuple[str, float], ...] = ()
    change_at: tuple[int, int] = CHANGE_AT
    _factors: np.ndarray | None = field(default=None, init=False, repr=False, compare=False, hash=False)

    def __post_init__(self) -> None:
        w = self.walk
        if not real_number(w):  # NumPy's numbers are numbers too; not a bool, nor a NumPy time (T17-1)
            raise NeurohoverError(f"drift walk={brief(w)} is not a number: allowed a number in 0..1 (a per-episode log std)")
        if not finite_real(w) or not 0 <= w <= 1:
            raise NeurohoverError(f"drift walk={brief(w)} is out of range: allowed a number in 0..1 (a per-episode log std)")
        if 0 < w < MIN_WALK:  # a walk that moves no parameter: every drifted row the fixed one
            raise NeurohoverError(f"drift walk={brief(w)} is out of range, too small to change the dynamics: {_WALK_RANGE}")
        object.__setattr__(self, "walk", setting_float(w))  # -0.0 as 0.0, np.float32 as printed (T56-B03, B04)
        try:  # a one-shot iterator (a generator, map, zip) is refused, as change_at and walk refuse one (T43-B08)
            if isinstance(self.change, Iterator):
                raise TypeError
            change = dict(self.change) if not isinstance(self.change, (dict, str)) else self.change
            if not isinstance(change, dict) or not all(isinstance(n, str) for n in change):  # no assert: python -O strips it (T32-B03)
                raise TypeError
        except (TypeError, ValueError):
            pairs = " or a list of (name, factor) pairs, not a one-shot iterator" if isinstance(self.change, Iterator) else ""
            raise NeurohoverError(
                f"drift change={self.change!r} is not allowed: give parameter factors as a table{pairs}, e.g. {{'D_w': 0.8}} (Drift.parse reads 'D_w=0.8')"
            ) from None
        if not isinstance(self.change, dict) and len(change) != len(self.change):  # (D_w, 0.8), (D_w, 0.9): the last kept (sixth trial)
            raise NeurohoverError(f"drift change={self.change!r:.80} sets a parameter twice: give each once")
        factors = np.ones(len(PARAM_NAMES))
        for name, factor in change.items():
            if name not in PARAM_NAMES:
                raise NeurohoverError(f"drift change of {name!r}: not a dynamics parameter; allowed {', '.join(PARAM_NAMES)}")
            if not real_number(factor):  # '0.8' and Decimal('0.8') were called "out of range" (T14-21)
                raise NeurohoverError(f"drift change {name}={brief(factor)} is not a number: allowed a factor in {MIN_FACTOR:g}..{MAX_FACTOR:g}")
            if not finite_real(factor) or not MIN_FACTOR <= factor <= MAX_FACTOR:  # np.float32(0.8), Fraction(4, 5) in range too (thirteenth trial)
                raise NeurohoverError(f"drift change {name}={brief(factor)} is out of range: allowed a factor in {MIN_FACTOR:g}..{MAX_FACTOR:g}")
            if factor == 1:  # flown as another experiment with results identical to none (eleventh trial, S3)
                raise NeurohoverError(
                    f"drift change {name}={factor!r} changes nothing: give a factor other than 1 (in {MIN_FACTOR:g}..{MAX_FACTOR:g}) or leave {name} out"
                )
            factors[PARAM_NAMES.index(name)] = setting_float(factor)
        object.__setattr__(self, "change", tuple(sorted((n, setting_float(f)) for n, f in change.items())))
        object.__setattr__(self, "_factors", factors)
        try:
            # True was read as episode 1 (second trial); a masked array's masked entry was NumPy's MaskError (T16-13)
            # finite_real: np.timedelta64(4) was read as episode 4, inf was int()'s OverflowError (T17-1)
            # 1.5 (no whole episode) was called out of range (T26-B17)
            # 5.0 (a float) is no episode number, as whole_in refuses it everywhere else (it was taken as 5, T37-B12)
            if isinstance(self.change_at, np.ma.MaskedArray) or not all(whole_number(x) for x in self.change_at):
                raise TypeError
            lo, hi = (operator.index(x) for x in self.change_at)
        except (TypeError, ValueError):
            raise NeurohoverError(
                f"drift change_at={brief(self.change_at)} is not allowed: give two episode numbers lo, hi, whole, with 0 <= lo <= hi <= {MAX_CHANGE_AT:,}"
            ) from None
        if not 0 <= lo <= hi <= MAX_CHANGE_AT:  # 10**30 was NumPy's int64 error at reset (ninth trial)
            raise NeurohoverError(f"drift change_at={brief(self.change_at)} is out of range: allowed whole episode numbers 0 <= lo <= hi <= {MAX_CHANGE_AT:,}")
        if not self.change and (lo, hi) != CHANGE_AT:  # said when, but no change to happen then: nothing would
            raise NeurohoverError(f"drift change_at={[lo, hi]} is given without a change: {_PARSE_FORM}")
        object.__setattr__(self, "change_at", (lo, hi))

    def check_run(self, episodes: int, where: str = "", *, at_given: bool | None = None, config: bool = False) -> None:
        """Refuse a walk in runs of one episode, which it never reaches, and an abrupt change that some test runs of
        ``episodes`` episodes would never reach (``where``: a prefix naming
        the run). ``at_given``: whether change_at was given (False: the default; None: not known, the default assumed where
        it is the default's value); ``config``: given in a config's drift table, so its example is a TOML change_at, not the
        command line's @LO-HI (T27-A08)."""
        episodes = _whole("episodes", episodes, "a whole number of episodes >= 1", 1)  # 0 suggested the window 0..-1 (thirteenth trial)
        if self.walk > 0 and episodes == 1:  # stored as drifting, flown as fixed: episode 0 flies the MDP as given (T61-A01)
            raise NeurohoverError(
                f"{where + ': ' if where else ''}drift walk={self.walk:g} drifts nothing in a test run of 1 episode (its first episode "
                "flies the MDP as given): give 2 or more episodes, or leave the walk out"
            )
        if self.change and self.change_at[1] >= episodes:
            lo, hi = self.change_at
            default = not at_given if at_given is not None else (lo, hi) == CHANGE_AT
            none_given = "the drift table gives no change_at" if config else "no @LO-HI is given"
            note = f" (the default where {none_given})" if default else ""
            factors = ",".join(f"{name}={factor:g}" for name, factor in self.change)
            at = min(lo, episodes - 1)
            example = f"change_at = [{at}, {episodes - 1}]" if config else f"{factors}@{at}-{episodes - 1}"
            raise NeurohoverError(
                f"{where + ': ' if where else ''}drift change_at={[lo, hi]}{note} can come after the last of a test run's {episodes} episodes, "
                f"so some runs would never change: give change_at within 0..{episodes - 1} (e.g. {example}) or more episodes"
            )

    @property
    def none(self) -> bool:
        """Whether the dynamics stay fixed."""
        return self.walk == 0.0 and not self.change

    def change_episode(self, seed: int) -> int | None:
        """The episode at which run ``seed`` changes abruptly (None: no abrupt change)."""
        seed = _seed(seed)
        if not self.change:
            return None
        return int(self._rng(seed).integers(self.change_at[0], self.change_at[1] + 1))

    def rows(self, row: np.ndarray, episodes: int, seed: int) -> np.ndarray:
        """The (episodes, MDP_ROW_LEN) rows that episodes 0..episodes-1 of run ``seed`` fly, from the MDP's ``row``."""
        row, episodes = _row(row), _whole("episodes", episodes, f"a whole number of episodes >= 1 (at most {MAX_RUN_EPISODES:,})", 1, MAX_RUN_EPISODES)
        rng = self._rng(_seed(seed))
        change = int(rng.integers(self.change_at[0], self.change_at[1] + 1)) if self.change else episodes
        out = np.repeat(row[None, :], episodes, axis=0)
        if self.walk:
            walk = np.cumsum(rng.standard_normal((episodes, len(PARAM_NAMES))), axis=0)
            walk[0] = 0.0  # episode 0 flies the MDP as given
            out[:, ROW_PARAMS] *= np.exp(self.walk * walk)
        if self._factors is not None:
            out[change:, ROW_PARAMS] *= self._factors
        return out

    def _rng(self, seed: int) -> np.random.Generator:
        return np.random.default_rng(np.random.SeedSequence([int(seed), _DRIFT_TAG]))

    def to_dict(self) -> dict:
        return {"walk": self.walk, "change": dict(self.change), "change_at": list(self.change_at)}

    @classmethod
    def from_dict(cls, d: dict) -> Drift:
        """A drift from a table of its settings (unknown keys refused by name).

        A table that gives walk 0 and drifts nothing is refused as a likely slip ({walk = 0}: leave the drift out), except
        the whole table :meth:`to_dict` writes for ``Drift()`` (walk, change and change_at all given, no change, the default
        change_at): it reads back as ``Drift()``, no drift (it was refused, T53-B06)."""
        if not isinstance(d, dict):
            raise NeurohoverError(f"a drift must be a table of settings (walk, change, change_at), got {d!r}")
        unknown = sorted(set(d) - {"walk", "change", "change_at"})
        if unknown:
            raise NeurohoverError(f"unknown drift setting(s) {', '.join(map(repr, unknown))}: allowed walk, change, change_at")
        change = d.get("change", {})
        if not isinstance(change, dict):
            raise NeurohoverError(f"drift change={change!r} is not allowed: give a table of parameter factors, e.g. {{D_w = 0.8}}")
        drift = cls(d.get("walk", 0.0), tuple(change.items()), d.get("change_at", CHANGE_AT))  # checked in __post_init__
        written = set(d) == {"walk", "change", "change_at"}  # Drift().to_dict(): change_at is the default where there is no change
        if "walk" in d and drift.none and not written:  # {walk = 0}: a drift table that drifts nothing (eleventh trial, S3)
            raise NeurohoverError(f"drift walk={d['walk']!r} changes nothing: {_NOTHING}")
        return drift

    @classmethod
    def of(cls, value) -> Drift:
        """The drift of a ``drift`` option (of the environments): None (none), a :class:`Drift`, a dict of
        its settings (:meth:`from_dict`) or the command line's text (:meth:`parse`)."""
        if value is None:
            return NO_DRIFT
        if isinstance(value, Drift):
            return value
        if isinstance(value, dict):
            return cls.from_dict(value)
        if isinstance(value, str):
            return cls.parse(value)
        raise NeurohoverError(f"drift={value!r} is not allowed: give None, a Drift, a dict of walk/change/change_at or text ({_PARSE_FORM})")

    @classmethod
    def parse(cls, text: str) -> Drift:
        """A drift from the command line: ``walk=0.01``, ``D_w=0.8@200-800`` (a change, at an episode in 200..800), or both, comma-separated."""
        walk, change, at = 0.0, {}, CHANGE_AT
        if not str(text).isascii() or not str(text).strip():  # float() and int() read other scripts' digits
            raise NeurohoverError(f"drift {text!r} is not understood: {_PARSE_FORM}, numbers in ASCII digits")
        seen: set[str] = set()
        windows: set[tuple[int, int]] = set()  # every change happens at one episode: windows that differ were the last's (sixth trial)
        for part in (p.strip() for p in str(text).split(",")):
            if not part:
                raise NeurohoverError(f"drift {text!r} has an empty setting between commas: {_PARSE_FORM}")
            key, eq, value = part.partition("=")
            if key.strip() in seen:
                raise NeurohoverError(f"drift {text!r} sets {key.strip()} twice: give each once")
            seen.add(key.strip())
            value, after, when = value.partition("@")
            if after and not when.strip():  # 'D_w=0.8@' was read as the default window (ninth trial)
                raise NeurohoverError(
                    f"drift {text!r:.80}: empty window after '@' in {part!r:.40}: give @LO-HI (or leave out '@' for {CHANGE_AT[0]}-{CHANGE_AT[1]})"
                )
            try:
                number = float_of(value)
                if when:
                    lo, dash, hi = when.partition("-")
                    at = (_episode(lo), _episode(hi if dash else lo))  # '@200-' is no window: int('') refuses it
            except ValueError as err:
                why = f" ({err})" if isinstance(err, FloatRangeError) else ""
                commas = comma_separated(part)  # 'walk=0.01 D_w=0.8': separated by a space (T49-A03)
                form = f"separate settings with commas ({commas:.80}); {_PARSE_FORM}" if commas and not why else _PARSE_FORM
                raise NeurohoverError(f"drift {part[:40]!r} is not understood{why}: {form}") from None
            if not eq:
                raise NeurohoverError(f"drift {part!r} is not understood: {_PARSE_FORM}")
            if when and key.strip() == "walk":  # walk=0.01@0-1 beside a change gave the change its window
                raise NeurohoverError(f"drift {part!r}: the walk has no window (it drifts every episode); a window '@LO-HI' follows a change")
            if when:
                windows.add(at)
            if len(windows) > 1:
                raise NeurohoverError(f"drift {text!r} gives its changes different windows: they happen together, at one episode; give one window")
            if key.strip() == "walk":
                if number == 0:  # 'walk=0' was flown as a drift that drifts nothing (eleventh trial, S3)
                    raise NeurohoverError(f"drift {part!r} changes nothing: {_NOTHING}")
                walk = number
            elif key.strip() not in PARAM_NAMES:  # 'WALK=0.01' was named only "not a dynamics parameter" (trial 59, side A)
                named = f"{key.strip()!r:.40} is not walk and not a dynamics parameter"
                raise NeurohoverError(f"drift {part!r:.60}: {named}; allowed walk=STD and {', '.join(PARAM_NAMES)}")
            else:
                change[key.strip()] = number
        return cls(walk, tuple(change.items()), at)


NO_DRIFT = Drift()


def _episode(text: str) -> int:
    """An episode of a window, read as :func:`float_of` reads a number (Sensor.parse's): no '_' between digits, which
    int() reads ('@1_000-2_000' was episodes 1000..2000; T35-B09); a whole number, as int() reads it."""
    if "_" in text:
        raise ValueError(f"invalid literal for int(): {text!r} (no '_' between digits)")
    return int_of(text)  # past 4,300 digits a FloatRangeError naming it, as a number past a float's range is (T53-A03)


def _whole(name: str, value, what: str, low: int, high: int | None = None) -> int:
    """``value`` as an int in ``low..high`` (NumPy integers too), or a NeurohoverError naming it (thirteenth trial, F9)."""
    if not whole_number(value) or not low <= int(value) or (high is not None and int(value) > high):
        raise NeurohoverError(f"{name}={brief(value)} is not allowed: give {what}")
    return int(value)


def _seed(seed) -> int:
    """A run's seed, checked as every seed is: -1 was NumPy's error, 1.5 silently seed 1 (thirteenth trial, F9)."""
    return _whole("seed", seed, f"a whole number in 0..{MAX_SEED}", 0, MAX_SEED)


def _row(row) -> np.ndarray:
    """An MDP's row (``MDP_ROW_LEN`` finite numbers) as a float array, or a NeurohoverError saying what it is not."""
    try:  # real numbers only: a masked array's hidden values, text and dates were read as numbers (T16-9)
        out: np.ndarray | None = as_floats(row, "row", "")
    except NeurohoverError:
        out = None
    if out is None or out.shape != (MDP_ROW_LEN,) or not np.isfinite(out).all():
        raise NeurohoverError(f"row={brief(row)} is not allowed: give an MDP's row of {MDP_ROW_LEN} finite numbers (MDP.row())")
    return out


class DriftRun:
    """The rows that the episodes of one test run of a drifting MDP fly, one at a time (an environment
    resets through them): ``row(e)`` is ``drift.rows(row, e + 1, seed)[e]``, computed in growing blocks."""

    def __init__(self, drift: Drift, row: np.ndarray, seed: int) -> None:
        if not isinstance(drift, Drift):
            refuse_reloaded(drift, Drift, "drift")  # T42-B07
            raise NeurohoverError(f"drift={brief(drift)} is not allowed: give a Drift (Drift.of reads its other forms)")
        self.drift, self._row, self.seed = drift, _row(row), _seed(seed)
        self._rows = np.zeros((0, self._row.shape[0]))

    def row(self, episode: int) -> np.ndarray:
        # -1 was the last row computed, 1.5 an IndexError, 10**20 an OverflowError (T14-21)
        episode = _whole("episode", episode, f"an episode number, a whole number >= 0 (below {MAX_RUN_EPISODES:,})", 0, MAX_RUN_EPISODES - 1)
        if episode >= self._rows.shape[0]:  # a longer prefix of the same draws: the earlier rows do not change
            self._rows = self.drift.rows(self._row, min(max(2 * self._rows.shape[0], episode + 1, 1024), MAX_RUN_EPISODES), self.seed)
        return self._rows[episode]


def refuse_drift(mdp, where: str) -> None:
    """A clear error where an MDP (or task family) that drifts would be flown as if its dynamics were fixed:
    only test runs and :class:`neurohover.envs.HoverEnv` fly the drift."""
    if not isinstance(getattr(mdp, "drift", None), Drift):  # a name or None was an AttributeError (T47-B05)
        refuse_reloaded(getattr(mdp, "drift", None), Drift, "mdp's drift")  # a reloaded module's MDP is an MDP, of another import
        raise NeurohoverError(f"mdp={brief(mdp)} is not allowed: give an MDP or a task family (neurohover.get_task_family('ghh08'))")
    if not mdp.drift.none:
        raise NeurohoverError(
            f"{getattr(mdp, 'label', None) or mdp.name} has drifting dynamics ({mdp.drift.to_dict()}), which {where} would fly as if fixed: "
            "drift is flown by test runs (compete, run_test, test-runs configs) and HoverEnv(drift=...); "
            "for the fixed dynamics use .with_drift(Drift())"
        )
