"""Running an experiment: plan units, skip the finished ones, execute the rest, record each at once."""

from __future__ import annotations

import sys
import time
from dataclasses import dataclass, field

from ..errors import NeurohoverError
from .config import ExperimentConfig
from .plans import plan
from .store import Store


@dataclass
class RunSummary:
    """What one ``reproduce`` call did for one experiment."""

    name: str
    scale: str
    executor: str
    cores: int
    units_total: int = 0
    units_before: int = 0
    units_run: int = 0
    failed: list[tuple[str, str]] = field(default_factory=list)
    wall_seconds: float = 0.0
    status: str = "running"

    @property
    def units_done(self) -> int:
        return self.units_before + self.units_run

    def line(self) -> str:
        text = (f"{self.name} ({self.scale}): {self.status}; ran {self.units_run} units, {self.units_before} already in "
                f"the store, {self.units_done}/{self.units_total} done, {self.wall_seconds:.1f} s on {self.cores} cores ({self.executor})")
        if self.failed:
            text += f"; {len(self.failed)} failed, first: {self.failed[0][0]}: {self.failed[0][1]}"
        return text


def _short(err: BaseException) -> str:
    text = str(err).strip() or type(err).__name__
    lines = [ln for ln in text.splitlines() if ln.strip()]
    return f"{type(err).__name__}: {lines[-1] if lines else text}"[:500]


def reproduce(config: ExperimentConfig, store: Store, executor, *, fresh: bool = False, progress: bool | None = None) -> RunSummary:
    """Run every unfinished unit of ``config``; each finished unit is written to ``store`` at once.

    Raises KeyboardInterrupt (after recording every finished unit) when interrupted.
    """
    from tqdm import tqdm

    store.begin(config.name, config.scale, config.hash, config.to_dict(), fresh=fresh)
    results = store.results(config.name, config.scale)
    summary = RunSummary(config.name, config.scale, executor.name, executor.cores, units_before=len(results))
    session = store.start_session(config.name, config.scale, config.hash, executor.name, summary.cores, len(results))
    start = time.perf_counter()
    disable = None if progress is None else not progress
    bar = tqdm(total=0, initial=len(results), desc=f"{config.name} ({config.scale})", unit="unit", file=sys.stderr,
               disable=disable, dynamic_ncols=True)

    def on_result(unit, result, seconds, worker) -> None:
        if store.put(config.name, config.scale, config.hash, unit, result, seconds, worker, session):
            summary.units_run += 1
        results[unit.key] = result
        bar.update(1)

    def on_error(unit, err) -> None:
        summary.failed.append((unit.key, _short(err)))
        bar.write(f"{config.name}: unit {unit.key} failed: {_short(err)}", file=sys.stderr)

    try:
        while True:
            p = plan(config, results)
            summary.units_total = p.total
            bar.total = p.total
            bar.refresh()
            todo = [u for u in p.units if u.key not in results]
            if not todo:
                break
            executor.run(todo, on_result, on_error)
            if summary.failed:
                break
        if summary.failed:
            summary.status = "failed"
        elif len(results) < summary.units_total:
            raise NeurohoverError(f"{config.name}: {summary.units_total - len(results)} units could not be planned")
        else:
            summary.status = "finished"
    except KeyboardInterrupt:
        summary.status = "interrupted"
        raise
    except BaseException:
        summary.status = "failed"
        raise
    finally:
        summary.wall_seconds = time.perf_counter() - start
        bar.close()
        store.end_session(session, summary.status)
    return summary
