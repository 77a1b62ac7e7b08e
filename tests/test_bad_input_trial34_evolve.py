"""Bad-input trial 34 (Python API), evolution: T34-B01 (pickle of CMAES / UHCMAES), T34-B04 (deepcopy of CMAES / UHCMAES
shared the generator), T34-B08 (two runs on one checkpoint), T34-B10 (a relative checkpoint path after os.chdir),
T34-B09 (NEAT records with a cycle or self-loop), T34-B12 (NeatSettings with NumPy numbers)."""

from __future__ import annotations

import copy
import os
import pickle

import numpy as np
import pytest

import neurohover as nh
from neurohover.evolution import CMAES
from neurohover.evolution.optimisers.uh_cma import UHCMAES, UHCMASettings


def _cma() -> CMAES:
    return CMAES(nh.baseline_policy().genome, seed=1, popsize=6)


def _uh() -> UHCMAES:
    return UHCMAES(nh.baseline_policy().genome, UHCMASettings(popsize=6), seed=1)


def _rounds(opt, n: int = 3) -> list[np.ndarray]:
    out = []
    for _ in range(n):
        g = opt.ask()
        out.append(g)
        opt.tell(-np.arange(len(g), dtype=float))
    return out


@pytest.mark.parametrize("make", [_cma, _uh], ids=["cma", "uh-cma"])
def test_cma_pickles_and_continues_identically(make):
    """T34-B01: pickle.dumps was an AttributeError on the randn lambda."""
    a = make()
    _rounds(a, 1)
    b = pickle.loads(pickle.dumps(a))
    for x, y in zip(_rounds(a), _rounds(b), strict=True):
        assert np.array_equal(x, y)


@pytest.mark.parametrize("make", [_cma, _uh], ids=["cma", "uh-cma"])
def test_cma_deepcopy_has_its_own_generator(make):
    """T34-B04: a deepcopy drew from the original's generator, so copy and original diverged from a fresh run."""
    a = make()
    b = copy.deepcopy(a)
    copied = _rounds(b)
    original = _rounds(a)
    fresh = _rounds(make())
    for x, y, z in zip(copied, original, fresh, strict=True):
        assert np.array_equal(x, y) and np.array_equal(y, z)


def test_cma_state_dict_still_round_trips():
    """The state_dict pickle still replaces the generator's draws by its persistent id."""
    a = _cma()
    _rounds(a, 1)
    b = CMAES.from_state_dict(a.state_dict())
    assert b._es.opts["randn"].holder[0] is b._rng
    for x, y in zip(_rounds(a), _rounds(b), strict=True):
        assert np.array_equal(x, y)


def _tiny_evolve(**kw):
    from neurohover.evolution import evolve

    mdp = nh.get_task_family("ghh08").mdp("train:0")
    return evolve(mdp, **{"topology": "slp", "budget": 20, "n_steps": 20, "seed": 1, **kw})


def test_a_checkpoint_another_run_writes_is_refused(tmp_path):
    """T34-B08: two runs on one checkpoint both ran and overwrote each other's; the second is now refused by the writer
    lock the CLI's --out takes (here held by this process, as another run would hold it), a resume too."""
    from neurohover.locks import sole_writer

    ck = tmp_path / "ck.json"
    with sole_writer(ck, "checkpoint"):
        for resume in (False, True):
            with pytest.raises(nh.NeurohoverError, match=r"checkpoint '.*ck\.json' is being written by another run \(pid \d+"):
                _tiny_evolve(checkpoint=ck, resume=resume)
    assert not ck.exists()
    _tiny_evolve(checkpoint=ck)  # released: taken, and the lock file removed after
    _tiny_evolve(checkpoint=ck, resume=True, budget=200)
    assert ck.is_file() and sorted(p.name for p in tmp_path.iterdir()) == ["ck.json"]


def test_a_relative_checkpoint_is_resolved_when_the_run_starts(tmp_path, monkeypatch):
    """T34-B10: after an os.chdir in the run, a relative checkpoint was written under the new folder."""
    (tmp_path / "elsewhere").mkdir()
    monkeypatch.chdir(tmp_path)

    def progress(info) -> None:
        os.chdir(tmp_path / "elsewhere")

    _tiny_evolve(checkpoint="run/ck.json", progress=progress, progress_every_s=0, checkpoint_every_s=1e-6)
    assert (tmp_path / "run" / "ck.json").is_file() and not (tmp_path / "elsewhere" / "run").exists()


def _neat_record(conns: list[float]) -> list[float]:
    from neurohover.integrations.neat import ACTIVATIONS

    ident = float(ACTIVATIONS.index("identity"))
    nodes = [v for k in range(6) for v in (k, 0.0, 1.0, ident)]  # outputs 0..3, hidden 4 and 5
    return [6.0] + nodes + conns


@pytest.mark.parametrize(
    "conns, cycle",
    [
        ([-1, 0, 1.0, 0, 0, 5.0], "0 -> 0"),
        ([-1, 0, 1.0, 0, 1, 3.0, 1, 0, 3.0], "0 -> 1 -> 0"),
        ([-1, 4, 1.0, 4, 4, 2.0, 4, 0, 1.0], "4 -> 4"),
        ([-1, 4, 1.0, 4, 5, 1.0, 5, 4, 1.0, 5, 0, 1.0], "4 -> 5 -> 4"),
    ],
)
def test_a_neat_record_with_a_cycle_is_refused(conns, cycle):
    """T34-B09: a cycle's or self-loop's nodes were dropped by neat-python's feed-forward network without a word."""
    from neurohover.integrations.neat import network_of_record

    with pytest.raises(nh.NeurohoverError, match=f"^a NEAT record's connection cycle {cycle} is not allowed: give a feed-forward network"):
        network_of_record(_neat_record(conns))


def test_a_neat_record_without_a_cycle_still_flies():
    """Chains through hidden nodes and links between outputs are feed-forward, and fly."""
    from neurohover.integrations.neat import forward, network_of_record

    record = _neat_record([-1, 4, 1.0, 4, 5, 1.0, 5, 0, 1.0, 0, 1, 2.0, 1, 2, 1.0, -2, 2, 1.0])
    out = forward(network_of_record(record), np.zeros(1, np.int64), np.ones((1, 12)))
    assert out.tolist() == [[1.0, 2.0, 3.0, 0.0]]


def test_neat_settings_take_numpy_numbers():
    """T34-B12: np.int64 sizes were "must be an integer", np.float32 probabilities "must be a probability in [0, 1]"; they
    are taken and stored as Python numbers."""
    from neurohover.integrations.neat import NeatSettings

    s = NeatSettings(
        pop_size=np.int64(4), episodes=np.int32(2), node_add_prob=np.float32(0.25), weight_mutate_power=np.float64(0.5), bias_init_stdev=np.float32(0)
    )
    assert (s.pop_size, s.episodes, s.node_add_prob) == (4, 2, 0.25)
    assert all(type(v) in (int, float) for v in (s.pop_size, s.episodes, s.node_add_prob, s.weight_mutate_power, s.bias_init_stdev))
    for bad, words in (
        ({"pop_size": np.int64(3)}, r"pop_size=np.int64\(3\) must be an integer in 4..100000"),
        ({"pop_size": np.bool_(True)}, "pop_size="),
        ({"node_add_prob": np.float32(1.5)}, r"node_add_prob=np.float32\(1.5\) must be a probability"),
    ):
        with pytest.raises(nh.NeurohoverError, match=words):
            NeatSettings(**bad)
