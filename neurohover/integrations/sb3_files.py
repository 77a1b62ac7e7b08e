"""The files a Stable-Baselines3 model or an RL Zoo run is read from, checked without Stable-Baselines3: a neurohover
policy file, flight data or a folder that is no run were answered "needs stable_baselines3: pip install ..." where it
is not installed, naming neither the value nor what to give (T38-A05). :mod:`.sb3` loads what these name."""

from __future__ import annotations

import zipfile
from pathlib import Path

from ..errors import NeurohoverError, brief
from ..filekinds import held_kind
from ..paths import checked_path
from . import SB3_ALGORITHMS

__all__ = ["rl_zoo_files", "sb3_model_file"]

#: What to give instead, for a neurohover file of another kind given as a model (held_kind's words).
_INSTEAD = {"a policy file": "fly it with --policy (Python: load_policy)"}


def check_algo(algo: object) -> str:
    """``algo`` as one of :data:`~neurohover.integrations.SB3_ALGORITHMS`' names."""
    if not isinstance(algo, str) or algo not in SB3_ALGORITHMS:  # ['ppo'] was a TypeError "unhashable" (thirteenth trial, F13)
        raise NeurohoverError(f"algo={brief(algo)} is not supported: allowed {', '.join(SB3_ALGORITHMS)}")
    return algo


def sb3_model_file(path: str | Path) -> Path:
    """``path`` (a str or path object) as a Path where it may be a saved model (a zip that is no neurohover file), else
    one clear error naming it."""
    path = checked_path(path, "path", "MODEL.zip file path")  # a str was an AttributeError 'is_file' (T44-B05)
    if not path.is_file():
        raise NeurohoverError(f"{str(path)!r} is not a Stable-Baselines3 model file (MODEL.zip)")
    kind = held_kind(path)
    if kind is not None:  # a flight-data .npz is a zip too
        instead = _INSTEAD.get(kind, "give the MODEL.zip that model.save wrote")
        raise NeurohoverError(f"{str(path)!r} is {kind} of neurohover's, not a Stable-Baselines3 model file: {instead}")
    if not zipfile.is_zipfile(path):
        raise NeurohoverError(f"{str(path)!r} is not a Stable-Baselines3 model file (a MODEL.zip that model.save wrote)")
    return path


def rl_zoo_files(run: str | Path, algo: str = "ppo") -> tuple[Path, Path | None]:
    """The files :func:`~neurohover.integrations.sb3.rl_zoo_policy` reads in the RL Zoo run folder ``run``: its model
    (``ENV.zip``, or ``best_model.zip`` when there is no final one) and its observation statistics
    (``ENV/vecnormalize.pkl``; None when there are none)."""
    check_algo(algo)
    run = checked_path(run, "run", "path of an RL Zoo run folder")  # None was pathlib's TypeError (thirteenth trial, F13)
    if not run.is_dir():  # "found []" for a folder that is not there (seventh trial)
        raise NeurohoverError(f"RL Zoo run folder {str(run)!r}: {'no such directory' if not run.exists() else 'not a directory'}")
    zips = sorted(z for z in run.glob("*.zip") if not z.name.startswith("rl_model_"))
    finals = [z for z in zips if z.name != "best_model.zip"]
    model_zip = finals[0] if len(finals) == 1 else run / "best_model.zip"
    if len(finals) > 1 or not model_zip.is_file():
        raise NeurohoverError(f"{str(run)!r} is not an RL Zoo run folder: expected one ENV.zip (or best_model.zip) in it, found {[z.name for z in zips]}")
    stats_file = run / model_zip.stem / "vecnormalize.pkl"
    if model_zip.name == "best_model.zip":
        stats_file = next(run.glob("*/vecnormalize.pkl"), stats_file)
    if stats_file.exists() and not stats_file.is_file():  # a directory was skipped: the policy flew unnormalised (ninth trial)
        raise NeurohoverError(f"{str(stats_file)!r} is not a file: expected the run's VecNormalize statistics (or nothing, for a run without them)")
    return model_zip, stats_file if stats_file.exists() else None
