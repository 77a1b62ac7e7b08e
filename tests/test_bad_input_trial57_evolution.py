"""Bad-input trial 57 (evolution settings): ``evolve --setting mutate_std=1e-320`` (5e-324, 1e-100; init_mutate_std,
eonn's spawn_std alike) was taken and flew as mutate_std=0, a Gaussian of that spread moving no gene (T57-A01): now 0 or
a spread from 2**-52 (require_spread's rule, mutate()'s too); np.float32 and np.float16 values of DangerousState's
box and tilt and of the NE settings' probabilities and spreads kept their binary value (np.float32(0.3) stored as
0.30000001192092896, np.float32(0.99) a tilt "not read by rule 'paper'") where every other settings class stores the
decimal, and -0.0 stayed -0.0 (T57-B01)."""

from __future__ import annotations

import math
from dataclasses import dataclass

import numpy as np
import pytest

from neurohover.errors import NeurohoverError
from neurohover.evolution.common import require_spread
from neurohover.evolution.eonn import EonnSettings
from neurohover.evolution.generational import GenerationalSettings
from neurohover.evolution.operators import mutate
from neurohover.evolution.steady_state import SteadyStateSettings
from neurohover.safeguard import DangerousState

MIN_SPREAD = 2.0**-52  # the smallest spread but 0 (a literal: the test runs without the fix too)
TINY = [1e-320, 5e-324, 1e-100, 2e-16, np.float32(1e-20)]
TOO_SMALL = r"is out of range, too small to move a gene \(below 2\*\*-52\): allowed 0 \(no mutation\) or a number in 2.23e-16..1e\+100"
SPREADS = [
    (SteadyStateSettings, "mutate_std"),
    (SteadyStateSettings, "init_mutate_std"),
    (GenerationalSettings, "mutate_std"),
    (GenerationalSettings, "init_mutate_std"),
    (EonnSettings, "mutate_std"),
    (EonnSettings, "spawn_std"),
]


@pytest.mark.parametrize(("cls", "name"), SPREADS)
@pytest.mark.parametrize("value", TINY)
def test_a_spread_too_small_to_move_a_gene_is_refused(cls, name: str, value) -> None:
    with pytest.raises(NeurohoverError, match=f"^{name}=.* {TOO_SMALL}$"):
        cls(**{name: value})
    assert getattr(cls(**{name: 2.23e-16}), name) == 2.23e-16  # the smallest the message names is taken
    assert getattr(cls(**{name: 0}), name) == 0.0  # as is 0, no mutation


def test_require_spread_refuses_a_tiny_spread_only_where_zero_is_allowed() -> None:
    for value in TINY:
        with pytest.raises(NeurohoverError, match=f"^mutate_std=.* {TOO_SMALL}$"):
            require_spread("mutate_std", value)
    assert require_spread("mutate_std", MIN_SPREAD) == MIN_SPREAD
    assert require_spread("sigma0", 1e-100, positive=True) == 1e-100  # a step size an optimiser adapts keeps its own floor


@dataclass
class _Mutation:
    mutate_frac: float = 1.0
    mutate_std: float = 1e-320
    mutate_repl: float = 0.0


def test_mutate_refuses_a_tiny_spread_from_any_settings() -> None:
    """mutate() takes any object with the three fields: its fast path took 1e-320 and returned the genome unchanged."""
    with pytest.raises(NeurohoverError, match=f"^mutate_std=1e-320 {TOO_SMALL}$"):
        mutate(np.ones(4), np.random.default_rng(0), _Mutation())
    assert not np.array_equal(mutate(np.ones(4), np.random.default_rng(0), _Mutation(mutate_std=MIN_SPREAD)), np.ones(4))  # it moves genes of 1


@pytest.mark.parametrize("setting", ["mutate_std=1e-320", "mutate_std=5e-324", "init_mutate_std=1e-100"])
def test_evolve_refuses_a_tiny_mutation_std(cli, tmp_path, setting: str) -> None:
    out = tmp_path / "p.json"
    argv = ("evolve", "--task", "ghh08", "--setting", setting, "--setting", "pop_size=4", "--setting", "elite_size=2")
    rc, _, err = cli(*argv, "--budget", "8", "--episode-steps", "20", "--out", str(out))
    assert rc == 2 and f"bad steady-state settings: {setting} is out of range, too small to move a gene" in err, err
    assert "Traceback" not in err and not out.exists()


def _plain(value: object, expected: float) -> bool:
    return type(value) is float and value == expected and math.copysign(1.0, value) == 1.0


@pytest.mark.parametrize(
    ("kwargs", "expected"),
    [
        ({"tilt": np.float32(0.3)}, {"tilt": 0.3}),
        ({"box": np.float16(0.5), "tilt": np.float32(0.95)}, {"box": 0.5, "tilt": 0.95}),
        ({"rule": "ratio-sum", "threshold": np.float32(0.2)}, {"threshold": 0.2}),
        ({"rule": "paper", "tilt": np.float32(0.99), "box": np.float32(0.4)}, {"tilt": 0.99, "box": 0.4}),  # 0.99: the default, not "not read"
    ],
)
def test_dangerous_state_stores_the_decimal_of_a_narrow_float(kwargs: dict, expected: dict) -> None:
    d = DangerousState(**kwargs)
    assert all(_plain(getattr(d, k), v) for k, v in expected.items()), d


NE_FIELDS = [
    (SteadyStateSettings, ("crossover_prob", "averaging_prob", "mutate_prob", "mutate_frac", "mutate_repl", "mutate_std", "init_mutate_frac")),
    (SteadyStateSettings, ("init_mutate_std", "mutation_floor")),
    (GenerationalSettings, ("crossover_prob", "averaging_prob", "mutate_prob", "mutate_frac", "mutate_repl", "mutate_std", "init_mutate_frac")),
    (GenerationalSettings, ("init_mutate_std",)),
    (EonnSettings, ("mutate_prob", "mutate_frac", "mutate_repl", "averaging_prob", "spawn_frac", "mutate_std", "spawn_std")),
]


@pytest.mark.parametrize(("cls", "names"), NE_FIELDS)
@pytest.mark.parametrize(("value", "expected"), [(np.float32(0.3), 0.3), (np.float16(0.1), 0.1), (np.float32(0.7), 0.7)])
def test_ne_settings_store_the_decimal_of_a_narrow_float(cls, names: tuple, value, expected: float) -> None:
    s = cls(**dict.fromkeys(names, value))
    assert all(_plain(getattr(s, n), expected) for n in names), s


@pytest.mark.parametrize(("cls", "names"), [(SteadyStateSettings, ("mutate_frac", "crossover_prob")), (GenerationalSettings, ("mutate_prob",))])
def test_ne_settings_store_minus_zero_as_zero(cls, names: tuple) -> None:
    s = cls(**dict.fromkeys(names, -0.0))
    assert all(_plain(getattr(s, n), 0.0) for n in names), s
