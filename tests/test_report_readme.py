"""The reproduction README's generated blocks (neurohover.experiments.report_readme)."""

from __future__ import annotations

import pytest


@pytest.mark.slow
def test_the_readme_beside_the_report_gets_its_numbers_from_the_store(tmp_path) -> None:
    """Issue 33: a README's generated blocks are filled from the store; the text around them is kept."""
    from neurohover.experiments import LocalExecutor, Store, load_config, reproduce, write_report
    from neurohover.experiments.report_readme import Status, fill_generated, status_table

    readme = tmp_path / "README.md"
    readme.write_text("# Runs\n\nkept above\n\n<!-- generated: status -->\nstale 1,234 of 9\n<!-- /generated: status -->\n\nkept below\n")
    cfg = load_config("fig2", "quick", {"runs": 1, "n_mdps": 1, "budget": 40, "n_steps": 40, "robustness_episodes": 1})
    with Store(tmp_path / "s.sqlite") as store:
        reproduce(cfg, store, LocalExecutor(1), progress=False)
        write_report(store, tmp_path)
        done = len(store.units("fig2", "quick"))
    text = readme.read_text()
    assert "kept above" in text and "kept below" in text and "stale" not in text
    assert text.count("<!-- generated: status -->") == 1 and text.count("<!-- /generated: status -->") == 1
    # only paper-scale experiments are listed: a quick store leaves the table empty of rows
    assert "`fig2`" not in text and "| experiment | title | units |" in text
    row = status_table([Status("fig8", "Figure 8", "paper", done, done + 1, 12.0, 30.0, (2, 16))])
    assert f"{done:,} of {done + 1:,} (**incomplete**)" in row and "12 s on 2/16 cores" in row
    assert not fill_generated(tmp_path / "absent.md", "status", row)
    stale = status_table([Status("fig8", "Figure 8", "paper", 3, 3, 1.0, 1.0, (2,), current=False)])
    assert "complete; **to be re-run**: its config is not the shipped one" in stale
    from neurohover.experiments.report_readme import is_current

    assert is_current(load_config("fig2", "quick")) is True
    assert is_current(load_config("fig7", "quick", {"policies": "shipped"})) is True  # the policy source a run set is its own
    assert is_current(cfg) is False  # set otherwise
    assert not fill_generated(readme, "claims", "x")  # no such block: the file is left alone
    assert readme.read_text() == text
