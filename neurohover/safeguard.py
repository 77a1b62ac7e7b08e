"""The hybrid agents' safeguard (docs/model.md, Safeguard): :class:`DangerousState`, the test of when the state is
dangerous, in the kernel's layout (:meth:`DangerousState.limits`), and :class:`Safeguard`, the fallback policy that
flies the rest of an episode once it is. :func:`neurohover.evaluate.evaluate` and the agents take them; both are
also ``neurohover.evaluate``'s names."""

from __future__ import annotations

from dataclasses import dataclass

import numpy as np

from .errors import NeurohoverError, brief, finite_real, real_number, setting_float, whole_in
from .policies import Policy
from .sim.constants import (
    SAFEGUARD_BOX,
    SAFEGUARD_KIND_BOX,
    SAFEGUARD_KIND_RATIO,
    SAFEGUARD_RATIO_LIMITS,
    SAFEGUARD_RATIO_THRESHOLD,
    SAFEGUARD_TILT,
)

__all__ = ["SAFEGUARD_RULES", "DangerousState", "Safeguard"]

SAFEGUARD_RULES = ("code", "paper", "ratio-sum")


@dataclass(frozen=True)
class DangerousState:
    """When the safeguard hands control to the fallback (docs/model.md, Safeguard).

    Parameters
    ----------
    rule : {"code", "paper", "ratio-sum"}
        ``"code"`` (default, as the authors' GHH-09 code ran it): the helicopter is tilted, qw <
        ``tilt``, and some velocity, position or angular-rate entry of the observation lies outside
        [-box, box]. ``"paper"``: the paper's text, the box test alone. ``"ratio-sum"`` (the
        authors' FGHH agent): the signed sum over the 12 observation entries of entry / limit
        (limits 5 m/s, 20 m, 4 pi rad/s, 1) exceeds ``threshold``.
    box : float
        Bound on |u|, |v|, |w|, |x|, |y|, |z|, |p|, |q|, |r| (> 0; 0.5 in the paper).
    tilt : float
        qw below this counts as tilted, in (0, 1] (0.99 in the authors' code); used by ``"code"`` only.
    threshold : float
        The ``"ratio-sum"`` test's threshold (> 0; 0.15 in the authors' FGHH agent).
    arm_after : int
        Control steps at the start of an episode in which the test does not apply (>= 0; 0, the
        authors': from the first step). A learned policy's start-up correction can trip the test
        in the first steps of an episode it then flies well (docs/benchmarks.md).
    """

    rule: str = "code"
    box: float = SAFEGUARD_BOX
    tilt: float = SAFEGUARD_TILT
    threshold: float = SAFEGUARD_RATIO_THRESHOLD
    arm_after: int = 0

    def __post_init__(self) -> None:
        if not isinstance(self.rule, str) or self.rule not in SAFEGUARD_RULES:  # an array: NumPy's "truth value is ambiguous" (T16-12)
            raise NeurohoverError(f"unknown safeguard rule {brief(self.rule)}: allowed {', '.join(SAFEGUARD_RULES)}")
        # finite_real/whole_number: 10**400 was a TypeError, True taken as 1, np.float32(0.5) refused (T15-2, T15-17);
        # a non-number (box='1', True) "is not allowed", a number outside the range "is out of range" (T26-B17)
        for name, ok, allowed, give in (
            ("box", lambda v: v > 0, "a finite number > 0", "a number > 0"),
            ("tilt", lambda v: 0 < v <= 1, "0 < tilt <= 1 (qw threshold)", "a number with 0 < tilt <= 1 (qw threshold)"),
            ("threshold", lambda v: v > 0, "a finite number > 0", "a number > 0"),
        ):
            value = getattr(self, name)
            if not real_number(value):
                raise NeurohoverError(f"safeguard {name}={brief(value)} is not allowed: give {give}")
            if not (finite_real(value) and ok(value)):
                raise NeurohoverError(f"safeguard {name}={brief(value)} is out of range: allowed {allowed}")
        whole_in(self.arm_after, "safeguard arm_after", 0, 10**6, "1000000 (control steps)")
        for name in ("box", "tilt", "threshold"):  # plain Python numbers: the repr and equality of the Python values
            object.__setattr__(self, name, setting_float(getattr(self, name)))  # np.float32(0.3) as 0.3 (T57-B01)
        object.__setattr__(self, "arm_after", int(self.arm_after))
        unused = {  # a setting the rule does not read, set anyway, would be ignored without a word (third trial)
            "box": self.rule == "ratio-sum" and self.box != SAFEGUARD_BOX,
            "tilt": self.rule != "code" and self.tilt != SAFEGUARD_TILT,
            "threshold": self.rule != "ratio-sum" and self.threshold != SAFEGUARD_RATIO_THRESHOLD,
        }
        for name, ignored in unused.items():
            if ignored:
                raise NeurohoverError(f"safeguard {name}={getattr(self, name)!r} is not read by rule {self.rule!r}: leave it out, or take a rule that uses it")

    def limits(self) -> np.ndarray:
        """The test in the kernel's layout (sim/constants.SAFEGUARD_LIMITS): 9 box limits, the tilt
        threshold (inf: no tilt condition), the kind (0 box, 1 ratio sum), the ratio threshold and
        limits, the arming step."""
        kind = SAFEGUARD_KIND_RATIO if self.rule == "ratio-sum" else SAFEGUARD_KIND_BOX
        tilt = float(self.tilt) if self.rule == "code" else np.inf
        return np.array([float(self.box)] * 9 + [tilt, kind, float(self.threshold), *SAFEGUARD_RATIO_LIMITS, float(self.arm_after)])


@dataclass(frozen=True)
class Safeguard:
    """The hybrid agent's safeguard: once the state is dangerous, ``fallback`` flies the rest of the episode."""

    fallback: Policy
    dangerous: DangerousState = DangerousState()

    def __post_init__(self) -> None:
        if not isinstance(self.fallback, Policy):  # 'baseline' was an AttributeError when first flown (second trial)
            raise NeurohoverError(f"Safeguard fallback={self.fallback!r:.60} is not allowed: give a Policy (e.g. neurohover.baseline_policy())")
        if not isinstance(self.dangerous, DangerousState):
            raise NeurohoverError(f"Safeguard dangerous={self.dangerous!r:.60} is not allowed: give a DangerousState (e.g. DangerousState(rule='paper'))")
