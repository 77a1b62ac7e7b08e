"""Reproducing the paper's experiments: configs, units of work, executors, a results store, a report.

An experiment is a TOML config (``configs/<name>.toml``, with a ``quick`` and a ``paper`` scale)
-> a list of units of work (:class:`Unit`: one evolution run, one test run, ...) -> the pure
function :func:`run_unit` (``unit -> JSON-able dict``), run by a local or a Ray executor. Every
finished unit is written at once to an SQLite :class:`Store`, so an interrupted experiment resumes
where it stopped. :func:`write_report` draws the paper's figures and writes ``report.md``.

Example
-------
A script (the ``__main__`` guard is needed: ``LocalExecutor(jobs=2)`` spawns worker processes,
which import the main module again)::

    from neurohover.experiments import LocalExecutor, Store, load_config, reproduce, write_report

    if __name__ == "__main__":
        config = load_config("fig7", "quick")  # seconds on 2 cores; "paper" runs the paper's protocol
        with Store("results.sqlite") as store:
            summary = reproduce(config, store, LocalExecutor(jobs=2))
            print(summary)
            write_report(store, "report/")
"""

from .config import ExperimentConfig, experiment_names, load_config, load_configs, parse_override
from .executors import LocalExecutor, RayExecutor, make_executor
from .export import export_results
from .plans import Plan, plan
from .report import write_report
from .runner import RunSummary, reproduce
from .store import SCHEMA_VERSION, Store
from .units import Unit, run_unit, strip_timing, unit_seed

__all__ = [
    "SCHEMA_VERSION",
    "ExperimentConfig",
    "LocalExecutor",
    "Plan",
    "RayExecutor",
    "RunSummary",
    "Store",
    "Unit",
    "experiment_names",
    "export_results",
    "load_config",
    "load_configs",
    "make_executor",
    "parse_override",
    "plan",
    "reproduce",
    "run_unit",
    "strip_timing",
    "unit_seed",
    "write_report",
]
