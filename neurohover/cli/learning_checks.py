"""What ``learn-model`` checks of its inputs beside the options: the policy EC-MER learns the closed loop of."""

from __future__ import annotations

from ..errors import NeurohoverError, brief

__all__ = ["policy_that_flew"]


def policy_that_flew(given: str | None, data, flight_data: str):
    """EC-MER's policy: the one the flight data record (``policy_flown``), else the file their metadata names (older
    files), else the baseline; ``--policy`` (``given``) where they record none, and refused where it is not the
    recorded one (a policy that never flew the data was fitted without a word; eleventh trial, S2)."""
    from ..policies import load_policy

    where = f"flight data {flight_data!r}"
    if given is None:
        recorded = data.recorded_policy(where)
        if recorded is not None:
            return recorded
        try:
            return load_policy(data.metadata.get("policy") or "baseline")
        except NeurohoverError as err:
            raise NeurohoverError(f"{err} (the policy the flight data's metadata name; give --policy FILE)") from None
    policy = load_policy(given)
    if data.metadata.get("policy_flown") is None:  # none recorded (older files) or joined recordings of several: --policy says
        return policy
    try:
        recorded = data.recorded_policy(where)
    except NeurohoverError:  # a damaged record: the given policy is all there is
        return policy
    if recorded is not None and recorded != policy:
        name = brief(str(data.metadata.get("policy", "a policy")))
        raise NeurohoverError(
            f"--policy {given!r} is not the policy that flew {where} (they record {name}, a different network): EC-MER fits "
            "the closed loop of the policy that flew the data; leave --policy out to use the recorded one"
        )
    return policy
