"""Bad-input trial 40, side B, the evolution area: a progress callback or sample_fn of the wrong arity failed with a raw
TypeError, evolve's only after its first generation (T40-B02); fixed_resampling averaged finite returns of 1e308 into
+inf (T40-B03); a user population optimiser's ask() of the wrong genome length, of no genomes or a list failed in the
flyer or in numba (T40-B05), its state_dict() holding an np.float32 failed in the JSON writer (T40-B06) and its
champion_return of 1e9 was the run's result (T40-B06b); a policy evolved by a user-registered optimiser was refused by
every other process (T40-B14)."""

from __future__ import annotations

import json
import subprocess
import sys
import warnings
from dataclasses import dataclass

import numpy as np
import pytest

import neurohover as nh
from neurohover.errors import NeurohoverError
from neurohover.evolution import evolve, fixed_resampling, selection_race
from neurohover.evolution.optimisers import OPTIMISERS, OptimiserSpec

MDP = nh.get_task_family("ghh08").mdp("train:0")


def _evolve(optimizer: str, **kwargs):
    return evolve(MDP, optimizer=optimizer, topology="slp", budget=8, seed=0, n_steps=20, **kwargs)


@pytest.mark.parametrize("progress", [lambda: None, lambda a, b: None])
def test_progress_of_the_wrong_arity_is_refused_before_flying(progress):
    with pytest.raises(NeurohoverError, match=r"progress of signature '\(.*\)' is not allowed: the run calls progress\(info\)"):
        _evolve("ne", progress=progress)


@pytest.mark.parametrize("call", [lambda fn: fixed_resampling(fn, 3, 2), lambda fn: selection_race(fn, 4, 2, 0.2)])
def test_sample_fn_of_the_wrong_arity_is_refused(call):
    with pytest.raises(NeurohoverError, match=r"sample_fn of signature '\(\)' is not allowed: it is called as sample_fn\(indices\)"):
        call(lambda: [-1.0])


def test_fixed_resampling_averages_huge_returns_without_overflow():
    with warnings.catch_warnings():
        warnings.simplefilter("error")  # NumPy's overflow warning
        result = fixed_resampling(lambda i: np.full(len(i), 1e308), 2, 3)
        assert result.means.tolist() == [1e308, 1e308]
        assert fixed_resampling(lambda i: np.full(len(i), -1.5e308), 1, 4).means.tolist() == [-1.5e308]
    # the race's means are the same numbers (T35-B04's scaled sums)
    samples = [[-1e308, -1.7e308, -0.5e308], [-1e308, -1.7e308, -0.4e308]]
    race = selection_race(lambda i: np.array([samples[j % 2][0] for j in i]), 2, 1, 0.5, t_limit=1)
    assert race.means.tolist() == fixed_resampling(lambda i: np.full(len(i), -1e308), 2, 1).means.tolist()
    assert fixed_resampling(lambda i: -np.arange(1.0, len(i) + 1), 3, 2).means.tolist() == [-1.0, -2.0, -3.0]


@dataclass(frozen=True)
class _Settings:
    pass


class _Mine:
    """A user's population optimiser (README, A new optimiser), answering as ``mode`` says."""

    mode = ""

    def __init__(self, proto, settings, seed):
        self.p, self.best, self.r = np.asarray(proto, float), None, -np.inf

    def ask(self):
        self.last = self.p + np.zeros((4, self.p.size))
        return {"short": self.last[:, 1:], "none": self.last[:0], "list": self.last.tolist(), "nan": self.last * np.nan}.get(self.mode, self.last)

    def tell(self, f, info=None):
        i = int(np.argmax(f))
        self.best, self.r = self.last[i], float(f[i])

    def stop(self):
        return False

    @property
    def champion_genome(self):
        return self.best

    @property
    def champion_return(self):
        return 1e9 if self.mode == "return" else self.r

    def state_dict(self):
        return {"a": [1, {"p": np.float32(1.0)}]} if self.mode == "state" else {}

    @classmethod
    def from_state_dict(cls, state):
        return cls(np.zeros(40), _Settings(), 0)


@pytest.fixture
def mine(monkeypatch):
    monkeypatch.setitem(OPTIMISERS, "mine", OptimiserSpec("mine", "user", _Settings, _Mine, stops_itself=False))
    return monkeypatch


@pytest.mark.parametrize(
    "mode, gave",
    [
        ("short", r"an array of shape \(4, 39\) and dtype float64"),
        ("none", r"an array of shape \(0, 40\) and dtype float64"),
        ("list", r"a list \[\[.*"),
        ("nan", r"an array of shape \(4, 40\) with genes NaN or infinite"),
    ],
)
def test_a_user_optimisers_ask_is_checked(mine, mode, gave):
    mine.setattr(_Mine, "mode", mode)
    allowed = r"which is not allowed: give a NumPy array of real numbers of shape \(n, 40\)"
    with pytest.raises(NeurohoverError, match=rf"optimizer 'mine': its ask\(\) gave {gave}, {allowed}"):
        _evolve("mine")


def test_a_user_optimisers_state_that_json_cannot_write_is_named(mine, tmp_path):
    mine.setattr(_Mine, "mode", "state")
    entry = r"\['a'\]\[1\]\['p'\] is float32 np.float32\(1.0\)"
    with pytest.raises(NeurohoverError, match=rf"optimizer 'mine': its state_dict\(\) entry {entry}, which is not allowed"):
        _evolve("mine", checkpoint=tmp_path / "ck.json")
    assert list(tmp_path.iterdir()) == []


def test_a_user_optimisers_positive_champion_return_is_refused(mine):
    mine.setattr(_Mine, "mode", "return")
    with pytest.raises(NeurohoverError, match=r"optimizer 'mine': its champion_return 1000000000.0 is not allowed: allowed -inf .* or a return told, in \[-3"):
        _evolve("mine")
    mine.setattr(_Mine, "mode", "")
    assert -1e4 < _evolve("mine").champion_return <= 0  # a well-behaved one runs


@pytest.mark.slow
def test_a_user_optimisers_policy_reads_in_another_process(monkeypatch, tmp_path):
    spec = OPTIMISERS["openai-es"]
    monkeypatch.setitem(OPTIMISERS, "my-es", OptimiserSpec("my-es", "mine", spec.settings, spec.make, stops_itself=False))
    result = _evolve("my-es")
    assert (result.champion.metadata["method"], result.champion.metadata["optimizer"]) == ("user:my-es", "user:my-es")
    path = tmp_path / "my_champ.json"
    nh.save_policy(result.champion, path)
    assert nh.load_policy(path).metadata["optimizer"] == "user:my-es"
    record = json.loads(path.read_text())
    edits = {"zzz": {"method": "zzz"}, "bad": {"method": "user:a b", "optimizer": "user:a b"}, "mixed": {"optimizer": "cma"}, "ok": {}}
    for name, edit in edits.items():
        (tmp_path / f"{name}.json").write_text(json.dumps({**record, **edit}))
    script = (
        "import sys, neurohover as nh\n"
        "for name in ('ok', 'zzz', 'bad', 'mixed'):\n"
        "    try:\n"
        "        print(name, nh.load_policy(sys.argv[1] + f'/{name}.json').metadata['method'])\n"
        "    except nh.NeurohoverError as err:\n"
        "        print(name, 'refused:', err)\n"
    )
    run = subprocess.run([sys.executable, "-c", script, str(tmp_path)], capture_output=True, text=True, timeout=60)
    lines = run.stdout.splitlines()
    assert run.returncode == 0 and lines[0] == "ok user:my-es", run.stdout + run.stderr
    assert "its method 'zzz' is not allowed: allowed steady-state, generational" in lines[1]
    assert "its method 'user:a b' is not allowed" in lines[2]
    assert "its method 'user:my-es' is not allowed beside its optimizer 'cma'" in lines[3]
