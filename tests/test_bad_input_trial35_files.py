"""Trial 35, helper B (Python API and hand-edited files): T35-B04 (race bounds of huge or denormal returns), T35-B10
(a race's delta of the wrong type), T35-B05 (plots written under a name that is no .png), T35-B06 (a store with a
column added by hand), T35-B09 (drift windows read as Python's int() reads)."""

from __future__ import annotations

import decimal
import re

import numpy as np
import pytest

from neurohover.errors import NeurohoverError
from neurohover.evolution import bayes_mean_bounds, selection_race


@pytest.mark.parametrize("delta", ["0.5", decimal.Decimal("0.5"), np.array(0.5), True, [0.5]])
def test_t35_b10_delta_of_the_wrong_type_is_not_a_number(delta):
    pattern = r"is not a number: allowed a confidence level strictly between 0 and 1"
    with pytest.raises(NeurohoverError, match=pattern):
        selection_race(lambda idx: -np.ones(len(idx)), 4, 2, delta)
    with pytest.raises(NeurohoverError, match=pattern):
        bayes_mean_bounds(np.array([1.0, 2.0]), delta)
    with pytest.raises(NeurohoverError, match=r"delta=1\.5 must be a confidence level"):
        bayes_mean_bounds(np.array([1.0, 2.0]), 1.5)


@pytest.mark.parametrize("unit", [1e200, 1e-320, 1e300])
def test_t35_b04_bounds_of_huge_and_denormal_returns_are_those_of_scaled_ones(unit):
    x = np.array([-1.0, -2.0, -3.0])
    lo, hi = bayes_mean_bounds(x, 0.05)
    with np.errstate(all="raise"):  # the overflow was a RuntimeWarning, then (-inf, inf)
        got = bayes_mean_bounds(x * unit, 0.05)
    assert np.all(np.isfinite(got)) and got[0] < got[1]
    assert got == pytest.approx((lo * unit, hi * unit), rel=1e-3 if unit < 1e-300 else 1e-12)


def test_t35_b04_the_race_kernel_gives_the_same_bounds_for_huge_returns():
    rng = np.random.default_rng(0)
    table = -1e200 * (1 + np.arange(4)[:, None] + rng.random((4, 3)))
    drawn = np.zeros(4, dtype=int)

    def sample(idx):  # each candidate's next column (a candidate listed twice flies two episodes)
        out = np.empty(len(idx))
        for n, i in enumerate(idx):
            out[n] = table[i, drawn[i]]
            drawn[i] += 1
        return out

    r = selection_race(sample, 4, 2, 0.9, t_limit=3)
    for i in range(4):
        k = int(r.n_samples[i])
        assert (r.lower[i], r.upper[i]) == bayes_mean_bounds(table[i, :k], 0.9)
    assert np.all(np.isfinite(r.lower)) and np.all(np.isfinite(r.upper))


@pytest.mark.parametrize("text", ["D_w=0.8@1_000-2_000", "D_w=0.8@1_0", "D_w=0.8@200-8_00"])
def test_t35_b09_drift_windows_refuse_underscores_as_sensor_parse_does(text):
    from neurohover.tasks.drift import Drift
    from neurohover.tasks.sensor import Sensor

    with pytest.raises(NeurohoverError, match="is not understood"):
        Drift.parse(text)
    with pytest.raises(NeurohoverError, match="needs a number after '='"):
        Sensor.parse("delay=1_0")
    assert Drift.parse("D_w=0.8@200-800").change_at == (200, 800)


@pytest.mark.parametrize("name", ["figure.pdf", "pc.jpg", "notes.txt", "noext"])
def test_t35_b05_a_plot_named_other_than_png_is_refused(tmp_path, name):
    from neurohover import plots

    fig = plots.new_figure(3, 3)
    with pytest.raises(NeurohoverError, match=r"is not allowed: a plot is PNG; give a path ending \.png"):
        plots.save_figure(fig, tmp_path / name)
    assert not (tmp_path / name).exists()
    assert plots.save_figure(fig, tmp_path / "upper.PNG").read_bytes()[:4] == b"\x89PNG"


@pytest.mark.parametrize("table", ["units", "sessions"])
def test_t35_b06_a_store_with_a_column_added_by_hand_is_refused_at_open(tmp_path, table):
    import sqlite3

    from neurohover.experiments.store import Store

    path = tmp_path / "s.sqlite"
    with Store(path):
        pass
    with sqlite3.connect(path) as c:
        c.execute(f"ALTER TABLE {table} ADD COLUMN note TEXT")
    c.close()
    message = f"results store {str(path)!r} holds column(s) 'note' in its table {table} that neurohover did not make; give another --store file"
    with pytest.raises(NeurohoverError, match=re.escape(message)):
        Store(path, create=False)
