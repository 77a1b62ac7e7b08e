"""Bad-input trial 54, side B (optimisers): a user's ask/tell optimiser registered at run time (README, A new optimiser)
whose champion_return was above every return told was recorded as the run's result (T54-B03); whose tell() wrote into
its fitness argument changed the returns the run recorded (T54-B04); whose champion_genome was held with champion_return
-inf was taken, and lost where save_policy refused its metadata (T54-B05); whose champion_genome no ask() gave was
recorded with another genome's return (T54-B06)."""

from __future__ import annotations

import numpy as np
import pytest
from test_bad_input_trial52_optimisers import _evolve, _Mine, _register

import neurohover as nh
from neurohover.evolution import evolve


def _best(s):
    return None if s.best is None else np.asarray(s.best)


@pytest.mark.parametrize("better", [1.0, 1e-9])
def test_a_champion_return_no_return_told_is_refused(monkeypatch, better):  # T54-B03
    _register(monkeypatch)
    monkeypatch.setattr(_Mine, "champion_return", property(lambda s: s.r + better if s.best is not None else s.r))
    with pytest.raises(
        nh.NeurohoverError,
        match=r"optimizer 'mine': its champion_return -[\d.]+ is not allowed: give a return told for its champion_genome \(-[\d.]+(, -[\d.]+)*\)",
    ):
        _evolve()


def test_a_tell_gets_the_returns_read_only(monkeypatch):  # T54-B04
    _register(monkeypatch)
    told = _Mine.tell

    def tell(s, f, info=None):
        f[:] = 0.0
        told(s, f, info)

    monkeypatch.setattr(_Mine, "tell", tell)
    with pytest.raises(ValueError, match="assignment destination is read-only"):
        _evolve()


def test_a_tell_over_a_family_gets_the_returns_read_only(monkeypatch):  # T54-B04
    _register(monkeypatch)
    monkeypatch.setattr(_Mine, "tell", lambda s, f, info=None: f.fill(0.0))
    family = nh.get_task_family("ghh08")
    with pytest.raises(ValueError, match="read-only"):
        evolve(family, optimizer="mine", topology="slp", n_steps=20, budget=4)


def test_a_champion_genome_held_with_return_minus_inf_is_refused(monkeypatch):  # T54-B05
    _register(monkeypatch)
    monkeypatch.setattr(_Mine, "champion_return", property(lambda s: -np.inf))
    with pytest.raises(
        nh.NeurohoverError, match=r"optimizer 'mine': its champion_return -inf with a champion_genome held is not allowed: give -inf with champion_genome None"
    ):
        _evolve()


def test_a_champion_genome_no_ask_gave_is_refused(monkeypatch):  # T54-B06
    _register(monkeypatch)
    monkeypatch.setattr(_Mine, "champion_genome", property(lambda s: None if s.best is None else s.best + 1.0))
    with pytest.raises(nh.NeurohoverError, match=r"optimizer 'mine': its champion_genome array\(\[1\. *, .* is not allowed: it is no genome its ask\(\) gave"):
        _evolve()


def test_a_champion_copied_as_a_list_runs_and_resumes(monkeypatch, tmp_path):  # T54-B03, B06: what an ask() gave, told, is taken
    _register(monkeypatch)
    monkeypatch.setattr(_Mine, "champion_genome", property(lambda s: None if s.best is None else s.best.tolist()))
    monkeypatch.setattr(_Mine, "state_dict", lambda s: {"best": _best(s) if s.best is None else s.best.tolist(), "r": None if s.best is None else s.r})

    def restored(cls, state):
        opt = cls(np.zeros(40), None, 0)
        if state["best"] is not None:
            opt.best, opt.r = np.array(state["best"]), state["r"]
        return opt

    monkeypatch.setattr(_Mine, "from_state_dict", classmethod(restored))
    ck = tmp_path / "ck.json"
    first = _evolve(checkpoint=ck, checkpoint_every_s=1e-9)
    again = _evolve(budget=16, checkpoint=ck, resume=True)
    assert again.champion_return <= 0 and again.episodes == 16 and first.champion_return <= 0
