"""An interrupted policy-set build's finished runs (``stages/``): :func:`neurohover.policysets.build_policy_set` keeps
each run's champion in ``<set>.building/stages/<run seed>.json`` while the build is under way, and the same build run
again resumes from them; ``stages/build.json`` holds the settings they were flown with."""

from __future__ import annotations

from pathlib import Path

import numpy as np

from .errors import NeurohoverError
from .jsontext import JSONError, strict_json
from .policies import Policy, load_policy


def finished_stage(stage: Path, what: str, say) -> Policy | None:
    """The champion a finished run of an interrupted build left in ``stage``, None when there is none; a damaged one is
    said and removed, and the run flown again (it failed the whole build, which then deleted every finished run;
    eighth trial)."""
    if not stage.is_file():
        return None
    try:
        policy: Policy | None = load_policy(stage)
    except NeurohoverError:
        policy = None
    if policy is not None and {"episodes", "seconds"} <= policy.metadata.keys():  # what the set's file takes from it
        return policy
    say(f"{what}: the interrupted build's stage {stage.name} is damaged; this run is flown again")
    stage.unlink()
    return None


STAGES = "stages"  # a build's finished runs, kept while it is under way (build_policy_set resumes from them)


def stage_file(root: Path, key: str) -> Path:
    """The file of one run (its seed) or of the build's settings (``build``) in the building set ``root``."""
    return root / STAGES / f"{key}.json"


def build_state(root: Path) -> dict:
    """The settings of the interrupted build in ``root``; a damaged state refused by name (an empty one, which a full disk
    left, was a JSONDecodeError; seventh trial), since its finished runs cannot be told to be of this build."""
    state = stage_file(root, "build")
    try:  # strictly: an integer of 5,000 digits or nesting 100,000 deep was a traceback (ninth trial)
        value = strict_json(state.read_bytes())
    except (OSError, JSONError) as err:
        value = err
    if not isinstance(value, dict):
        why = str(value)[:100] if isinstance(value, Exception) else f"a JSON {type(value).__name__}, not an object"
        raise NeurohoverError(f"the interrupted build's state {str(state)!r} is damaged ({why}): delete {str(root)!r} to start the build over")
    return value


def run_seeds(seed: int) -> list[int]:
    """The seeds of a build's runs, by the build's root seed (each run's stage file is named by its own)."""
    return [int(s) for s in np.random.SeedSequence(seed).generate_state(32, dtype=np.uint32)]
