"""The committed results store against today's configs and planner: every stored experiment's config
hashes as stored, and every unit it holds is planned again with the very params it was run with, so a
`reproduce` resumes it rather than refusing it or running it again (issue 20: results bit-identical)."""

from __future__ import annotations

import json
from pathlib import Path

import pytest

from neurohover.experiments.config import ExperimentConfig, load_config, shipped_configs
from neurohover.experiments.plans import plan, source_experiments
from neurohover.experiments.runner import POLICY_SOURCES, unchanged_units
from neurohover.experiments.store import Store

#: Paper-scale experiments whose config changed on purpose and whose re-run (`reproduce NAME --scale paper
#: --update`) is under way; each must still be taken by --update (its unchanged units kept). Emptied as the
#: store receives the re-runs: the model-substeps re-runs of issue 31 all landed by 2026-12-06.
AWAITING_RERUN: set[str] = set()


@pytest.mark.slow
def test_every_stored_experiment_is_planned_again_with_its_stored_params(committed_store: Path) -> None:
    shipped = set(shipped_configs())
    checked = rerun = 0
    with Store(committed_store, create=False) as store:
        for name, scale, stored_hash, _ in store.experiments():
            if name not in shipped:
                continue
            as_stored = ExperimentConfig.from_dict(store.config(name, scale))  # what the report reads
            assert as_stored.hash == stored_hash and as_stored.typed.seed == as_stored.settings["seed"], f"{name} ({scale})"
            stored = store.config(name, scale)["settings"]
            # the documented override (`reproduce ... --set policies=shipped`): where the policies come from
            overrides = {k: stored[k] for k in POLICY_SOURCES if k in stored}
            cfg = load_config(name, scale, overrides)
            if scale == "paper" and name in AWAITING_RERUN and cfg.hash != stored_hash:
                unchanged_units(cfg, store)  # --update takes it (refused: its units were computed by other unit code)
                rerun += 1
                continue
            assert cfg.hash == stored_hash, f"{name} ({scale}): the config no longer hashes as stored"
            units = store.units(name, scale)
            results = {u["key"]: u["result"] for u in units}
            sources = {src: store.results(src, scale) for src in source_experiments(cfg)}
            planned = {u.key: u.params for u in plan(cfg, results, sources).units}
            for u in units:
                if u["key"] in planned:  # a unit planned only before its sources finished is checked by its key alone
                    assert json.dumps(planned[u["key"]], sort_keys=True) == json.dumps(u["params"], sort_keys=True), f"{name} ({scale}) {u['key']}"
                    checked += 1
    assert checked > 1000
    assert rerun <= len(AWAITING_RERUN)
