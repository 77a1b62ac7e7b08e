"""Plots leave matplotlib's global state alone: the report and ``compete`` draw through the
object-oriented API (a Figure with an Agg canvas), so a notebook user's backend survives them."""

from __future__ import annotations

import shutil
import struct
from pathlib import Path

import numpy as np
import pytest

from neurohover.experiments import Store, write_report
from neurohover.plots import plot_cumulative

DPI = 110  # what both plotters save with


@pytest.fixture
def svg_backend():
    """matplotlib's backend set to ``"svg"`` (not Agg) for the test, restored afterwards."""
    import matplotlib

    before = matplotlib.get_backend()
    matplotlib.use("svg")
    try:
        yield "svg"
    finally:
        matplotlib.use(before)


def _assert_png(path: Path, sizes_in: set[tuple[float, float]]) -> None:
    """``path`` is a real PNG whose pixel width is one of the figure widths (inches) at DPI, and whose height is at
    least one of theirs (a legend below the panels adds rows)."""
    data = path.read_bytes()
    assert data[:8] == b"\x89PNG\r\n\x1a\n" and data[12:16] == b"IHDR", path.name
    width, height = struct.unpack(">II", data[16:24])
    fits = [(w, h) for w, h in sizes_in if width == round(w * DPI) and round(h * DPI) <= height <= round((h + 4) * DPI)]
    assert fits, (path.name, width, height)
    assert len(data) > 10_000, path.name  # axes, curves and labels, not an empty canvas


def _backend_raw() -> str:
    import matplotlib

    return dict.__getitem__(matplotlib.rcParams, "backend")  # without resolving it


@pytest.mark.slow
def test_compete_plot_keeps_the_backend(svg_backend, tmp_path: Path) -> None:
    rng = np.random.default_rng(0)
    curves = {"a": np.cumsum(-rng.uniform(1, 2, (3, 50)), axis=1), "b": np.cumsum(-rng.uniform(2, 3, (3, 50)), axis=1)}
    path = plot_cumulative(curves, tmp_path / "sub" / "cumulative.png", "two agents")
    assert _backend_raw() == svg_backend
    _assert_png(path, {(11, 4)})


@pytest.mark.slow
def test_report_figures_keep_the_backend(svg_backend, committed_store: Path, tmp_path: Path) -> None:
    store_path = tmp_path / "results.sqlite"
    shutil.copyfile(committed_store, store_path)
    out = tmp_path / "report"
    names = ["fig15", "table4", "fig8"]  # one experiment of each kind: evolution, model learning, test runs
    with Store(store_path, create=False) as store:
        write_report(store, out, scale="quick", names=names)
    assert _backend_raw() == svg_backend
    for name in names:
        _assert_png(out / f"{name}-quick.png", {(11, 4.2), (6.5, 4.2), (6.5, 4)})
