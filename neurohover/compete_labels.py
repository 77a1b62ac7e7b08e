"""What a competition's files may say: its scale (a digest of its settings), and per agent the policies its rows name
and whether a safeguard or off-line time is possible, checked by compete's readers (:mod:`neurohover.compete_files`) and by the store's (``result_checks``).

Internal: neurohover's plumbing (README, Python API, What is public).
"""

from __future__ import annotations

import re

from .errors import brief
from .tasks import N_TRAINING

__all__ = ["COMPETE_SCALE", "NO_OFFLINE", "NO_SAFEGUARD", "ONE_POLICY", "POLICY_LABELS", "policy_label_problem"]

#: The scale of a competition's experiment: its settings' digest, 10 hex digits (experiments.config.settings_scale).
COMPETE_SCALE = re.compile(r"settings-[0-9a-f]{10}")
#: The agents that fly under no safeguard (no Choice of theirs has a fallback), whose safeguard_fired is 0 in every row
#: (T23-07). The agents' specs do not declare it, and this layer may not read them: tests/test_bad_input_trial23_compete.py
#: checks that every other registered agent is one with a safeguard.
NO_SAFEGUARD = frozenset(
    {"baseline", "generic", "model-free", "model-based", "incremental", "incremental-zero", "incremental-fixed", "incremental-race", "model-free-risk"}
)
#: The agents that fly one policy throughout, and its label in every row's policy column (T23-07).
ONE_POLICY = {"baseline": "baseline", "generic": "generic"}
_GROWS = None  # a count with no bound: a policy of each model learned, or each replacement evolved, so far
#: The policies every other agent names in its rows' policy column and its stored runs' policy_changes (T25-08, T25-09:
#: 'specialised:1' of authors-zero, 'model:1' of model-free were taken): per kind, None for a bare name, else the
#: numbers KIND:N takes (low, high; high None: no bound), as agents/* label their Choices: model_free and risk
#: specialised:{episode} (the task's N_TRAINING specialised policies), model_based (model-based: generic, then model:1;
#: incremental*: model:{models learned} from 1), hybrid (safe:0..1, model:0..N_EVOLVED-1, replacement:{n} from 1),
#: continual (model:{models} from 1), fghh_code (authors-*: model:1..3, its three evolutions). This layer may not import
#: the agents: tests/test_bad_input_trial25_results.py checks the table against them.
POLICY_LABELS: dict[str, dict[str, tuple[int, int | None] | None]] = {
    **dict.fromkeys(("model-free", "model-free-risk"), {"specialised": (0, N_TRAINING - 1)}),
    "model-based": {"generic": None, "model": (1, 1)},
    **dict.fromkeys(("incremental", "incremental-zero", "incremental-fixed", "incremental-race", "continual"), {"generic": None, "model": (1, _GROWS)}),
    **dict.fromkeys(("hybrid", "hybrid-baseline", "hybrid-risk", "hybrid-baseline-risk"), {"safe": (0, 1), "model": (0, 2), "replacement": (1, _GROWS)}),
    **dict.fromkeys(("authors-zero", "authors-fixed", "authors-race"), {"generic": None, "model": (1, 3)}),
}
#: The agents whose first Choice is final: agents.protocol.run_test never calls their update, so every run's offline
#: seconds are 0.0 exactly (T24-07; every stored baseline and generic run of the committed store holds 0.0, every
#: other agent's more). tests/test_bad_input_trial24_results.py checks that each one's first choice is final.
NO_OFFLINE = frozenset({"baseline", "generic"})


def policy_label_problem(agent: object, label: str) -> str:
    """'' when ``agent`` names a policy it flies ``label`` (:data:`ONE_POLICY`, :data:`POLICY_LABELS`; an agent in
    neither, a hand-written one, is not checked), else what it flies (T25-08, T25-09); result_checks asks too. Internal: called with a stored label."""
    fixed = ONE_POLICY.get(agent) if isinstance(agent, str) else None
    if fixed is not None:
        return "" if label == fixed else f"policy {brief(label)} is not allowed: agent {agent} flies {fixed!r} only"
    kinds = POLICY_LABELS.get(agent) if isinstance(agent, str) else None
    if kinds is None:
        return ""
    kind, colon, number = label.partition(":")
    bounds = kinds.get(kind, False)
    if bounds is None and not colon:
        return ""
    if isinstance(bounds, tuple) and number.isascii() and number.isdigit() and len(number) <= 9 and number == str(int(number)):
        low, high = bounds
        if low <= int(number) and (high is None or int(number) <= high):
            return ""
    flies = [k if b is None else f"{k}:{b[0]}" if b[0] == b[1] else f"{k}:N (N >= {b[0]})" if b[1] is None else f"{k}:{b[0]}..{b[1]}" for k, b in kinds.items()]
    return f"policy {brief(label)} is not allowed: agent {agent} flies {', '.join(flies)}"
