"""Bad-input trial 45's findings in evolution checkpoints and the files neurohover unpickles: T45-B03 (a CMA or UH-CMA
state's pickle could name any class of a ``cma.*`` module, and cma.logger.Logger deleted a file before the checkpoint was
refused; CleanRL's obs_rms.pkl, the trial's note, was read with an unrestricted pickle.load), T45-B01 (a checkpoint's
``counters.wall_seconds`` of 1e300 was resumed) and T45-B08 (a policy set manifest's ``seconds``)."""

from __future__ import annotations

import base64
import io
import json
import pickle
from pathlib import Path

import cma.logger
import numpy as np
import pytest
from store_edits import edited_policy_set

from neurohover.errors import NeurohoverError
from neurohover.evolution.evolve import evolve
from neurohover.evolution.optimisers.cma import CMAES
from neurohover.evolution.optimisers.uh_cma import UHCMAES, UHCMASettings
from neurohover.integrations.cleanrl import load_obs_statistics
from neurohover.tasks import get_task_family

ZERO = get_task_family("ghh08").zero()


def _state(obj: object) -> dict:
    return {"type": "CMAES", "version": 1, "pickle": base64.b64encode(pickle.dumps(obj, protocol=4)).decode()}


def test_a_pickled_pycma_logger_is_refused_before_it_deletes_a_file(tmp_path: Path) -> None:
    """T45-B03: the reproducer's Logger(path, ..., delete=True) removed ``victim`` as it was collected, and its
    constructor made directories; now the pickle is refused as it names the class, before anything is made."""
    victim, made = tmp_path / "victim.txt", tmp_path / "made" / "sub"
    victim.write_text("keep")

    class Deleter:
        def __reduce__(self):
            return (cma.logger.Logger, (str(victim), None, None, "", None, None, True))

    class Maker:
        def __reduce__(self):
            return (cma.logger.Logger, ("obj", None, None, f"{made}/"))

    for hostile in (Deleter(), Maker()):
        for kind in (CMAES, UHCMAES):
            with pytest.raises(NeurohoverError, match=r"its pickle names 'cma\.logger\.Logger', which no CMA state holds"):
                kind.from_state_dict(_state(hostile))
    assert victim.read_text() == "keep" and not made.parent.exists()


def test_a_pickle_calling_a_class_a_cma_state_holds_is_refused(tmp_path: Path) -> None:
    """T45-B03: the classes a state holds are made empty and filled, never called: a call of CMADataLogger or
    CMAEvolutionStrategy ran their constructors with whatever the pickle gave them."""

    class Logger:
        def __reduce__(self):
            return (cma.logger.CMADataLogger, (str(tmp_path / "out" / "x"),))

    class Strategy:
        def __reduce__(self):
            return (cma.CMAEvolutionStrategy, (np.zeros(2), 1.0, {"verbose": -9}))

    with pytest.raises(NeurohoverError, match=r"its pickle calls 'cma\.logger\.CMADataLogger', which no CMA state calls"):
        CMAES.from_state_dict(_state(Logger()))
    with pytest.raises(NeurohoverError, match=r"its pickle calls 'cma\.evolution_strategy\.CMAEvolutionStrategy'"):
        CMAES.from_state_dict(_state(Strategy()))
    state = {"type": "CMAES", "version": 1, "pickle": base64.b64encode(pickle.dumps(np.zeros(2), protocol=1)).decode()}
    with pytest.raises(NeurohoverError, match=r"which no CMA state holds|INST or OBJ"):
        CMAES.from_state_dict(state)
    assert not (tmp_path / "out").exists()


def test_a_damaged_bytearray_length_is_refused_before_it_is_allocated() -> None:
    """The closing check's fuzz of T45-B03's unpickler (one byte of a real state changed, 3,000 times): a BYTEARRAY8
    opcode's length of terabytes was allocated before it was read, a MemoryError; no state holds one (protocol 4)."""
    data = pickle.PROTO + bytes([4]) + pickle.BYTEARRAY8 + (2**50).to_bytes(8, "little") + pickle.STOP
    for kind in (CMAES, UHCMAES):
        state = {"type": kind.__name__, "version": 1, "pickle": base64.b64encode(data).decode()}
        with pytest.raises(NeurohoverError, match=r"holds a bytearray \(pickle protocol 5\), which no CMA state does"):
            kind.from_state_dict(state)


def _told(kind):
    opt = CMAES(np.zeros(5), 0.3, seed=1) if kind is CMAES else UHCMAES(np.zeros(5), UHCMASettings(), seed=1)
    for _ in range(2):
        asked = opt.ask()
        opt.tell(-np.arange(len(asked), dtype=float))
    return opt


@pytest.mark.parametrize("kind", [CMAES, UHCMAES])
def test_a_state_whose_pickle_was_damaged_is_refused_by_its_digest(kind) -> None:
    """The closing check's fuzz of T45-B03's unpickler: one byte changed in a dtype's pickled state was NumPy's
    SystemError, or a RuntimeError raised later from its internals; a state now carries its pickle's sha256."""
    state = _told(kind).state_dict()
    data = bytearray(base64.b64decode(state["pickle"]))
    for at in range(0, len(data), max(1, len(data) // 50)):  # fifty places through the pickle
        damaged = bytearray(data)
        damaged[at] ^= 0x10
        with pytest.raises(NeurohoverError, match="sha256 differs from the state's"):
            kind.from_state_dict({**state, "pickle": base64.b64encode(bytes(damaged)).decode()})
    for digest in ("x", None, 5, "A" * 64):
        with pytest.raises(NeurohoverError, match="'sha256' entry .* is damaged .*64 hex digits"):
            kind.from_state_dict({**state, "sha256": digest})
    legacy = {k: v for k, v in state.items() if k != "sha256"}  # written before the digest: still read
    assert kind.from_state_dict(legacy).ask().shape == _told(kind).ask().shape


def test_states_the_cma_optimisers_write_still_resume() -> None:
    """T45-B03: the allowed globals are those the states of CMA-ES and UH-CMA-ES (with re-evaluations, after several
    generations) pickle; each state read back continues as the optimiser it was written from."""
    rng = np.random.default_rng(0)
    for opt in (CMAES(np.zeros(4), seed=1, popsize=6), UHCMAES(np.zeros(4), UHCMASettings(popsize=6, min_evaluations=2), seed=2)):
        for _ in range(8):
            x = opt.ask()
            opt.tell(-np.sum(x**2, axis=1) + rng.normal(size=len(x)))
        back = type(opt).from_state_dict(opt.state_dict())
        np.testing.assert_array_equal(back.ask(), opt.ask())


def test_obs_rms_pkl_is_read_with_only_numpy_arrays_allowed(tmp_path: Path) -> None:
    """Trial 45's note: cleanrl_policy read obs_rms.pkl with pickle.load, which runs what the file says; now only the
    NumPy arrays (or lists) the docstring's pickle.dump((mean, var), ...) writes are read, in every pickle protocol."""
    path = tmp_path / "obs_rms.pkl"
    for protocol in range(pickle.HIGHEST_PROTOCOL + 1):
        path.write_bytes(pickle.dumps((np.zeros(20), np.ones(20)), protocol=protocol))
        mean, var = load_obs_statistics(path)
        assert mean.tolist() == [0.0] * 20 and var.tolist() == [1.0] * 20
    victim = tmp_path / "victim.txt"
    victim.write_text("keep")

    class Hostile:
        def __reduce__(self):
            return (cma.logger.Logger, (str(victim), None, None, "", None, None, True))

    path.write_bytes(pickle.dumps(Hostile()))
    with pytest.raises(NeurohoverError, match=r"its pickle names 'cma\.logger\.Logger', which no \(mean, var\) of arrays holds"):
        load_obs_statistics(path)
    assert victim.read_text() == "keep"


def _checkpoint(tmp_path: Path, target, **run) -> Path:
    ckpt = tmp_path / "run.ckpt.json"
    evolve(target, topology="slp", seed=0, n_steps=20, checkpoint=ckpt, **run)
    return ckpt


@pytest.mark.parametrize(
    "target, run",
    [
        (ZERO, dict(budget=5)),
        (ZERO, dict(budget=8, optimizer="openai-es", settings={"popsize": 4})),
        (get_task_family("ghh08"), dict(budget=8, settings={"pop_size": 4, "select_size": 2, "generations": 2})),
    ],
    ids=["steady-state", "openai-es", "generational"],
)
def test_a_checkpoints_wall_seconds_past_100_years_are_refused(tmp_path: Path, target, run: dict) -> None:
    """T45-B01: counters.wall_seconds of 1e300 was resumed into the result's seconds, its history and the rewritten
    checkpoint, while the optimiser state's 1e300 was refused; now both are refused as more than 100 years."""
    ckpt = _checkpoint(tmp_path, target, **run)
    state = json.loads(ckpt.read_text())
    state["counters"].update(wall_seconds=1e300)
    ckpt.write_text(json.dumps(state))
    with pytest.raises(NeurohoverError, match=r"counter 'wall_seconds' is 1e\+300, more seconds than 100 years"):
        evolve(target, topology="slp", seed=0, n_steps=20, checkpoint=ckpt, resume=True, **{**run, "budget": 200})


def test_a_manifests_seconds_below_its_policies_seconds_are_taken(tmp_path: Path) -> None:
    """T45-B08, not a bug: a manifest's ``seconds`` are the wall time of the build that wrote it, from its start
    (policysets.build_policy_set), not the sum of its policies' ``seconds``. A build resumed after an interruption keeps
    the runs already finished, with their own seconds (finished_stage), and times only itself: its manifest holds fewer
    seconds than its policies add up to. So 0.5 seconds beside policies of 322.8 is a set such a build can write."""
    from neurohover.policysets import load_policy_set

    pd = edited_policy_set(tmp_path, "ghh08", lambda m: m.update(seconds=0.5))
    loaded = load_policy_set("ghh08", pd)
    assert loaded.manifest["seconds"] == 0.5
    assert sum(p.metadata["seconds"] for p in (loaded.generic, *loaded.specialised)) > 300


def test_a_state_naming_pycma_classes_where_older_pycma_keeps_them_is_read(monkeypatch) -> None:
    """After T45-B03: pycma 3.4 pickles CMAOptions as cma.evolution_strategy's (4.4 on: cma.options_parameters'), 4.0
    BoundTransform as cma.constraints_handler's; the allow-list named the modules of 4.5 only, so every pycma the
    package takes before 4.4 (cma>=3.4) had its own checkpoints refused. Here 4.5's class pickled under 3.4's module."""
    import cma.evolution_strategy
    import cma.options_parameters

    assert cma.evolution_strategy.CMAOptions is cma.options_parameters.CMAOptions
    monkeypatch.setattr(cma.options_parameters.CMAOptions, "__module__", "cma.evolution_strategy")
    opt = CMAES(np.zeros(5), 0.3, seed=1)
    state = opt.state_dict()
    named = []

    class Recorder(pickle.Unpickler):
        def find_class(self, module, name):
            named.append((module, name))
            return super().find_class(module, name)

        def persistent_load(self, pid):
            return None

    Recorder(io.BytesIO(base64.b64decode(state["pickle"]))).load()
    assert ("cma.evolution_strategy", "CMAOptions") in named and ("cma.options_parameters", "CMAOptions") not in named
    np.testing.assert_array_equal(CMAES.from_state_dict(state).ask(), opt.ask())
