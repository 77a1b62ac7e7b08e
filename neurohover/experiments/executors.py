"""Executors: where units run. Both call the same pure :func:`~neurohover.experiments.units.run_unit`.

- :class:`LocalExecutor`: in this process (``jobs=1``, the kernel on all cores), or in ``jobs``
  spawned worker processes (one kernel thread each; spawn, because numba's thread pools are not
  fork-safe). The workers exit when this process dies (see :mod:`neurohover.procs`), and SIGTERM
  ends them like Ctrl-C.
- :class:`RayExecutor`: Ray tasks on a cluster (``address``), or on a local Ray instance it starts.
  The driver collects results with ``ray.wait`` (and drives the progress bar). A task whose worker
  dies is retried by Ray up to ``max_retries`` times; if it still fails, the unit is reported as
  failed and never recorded as finished. The nodes need neurohover installed
  (``pip install 'neurohover[ray]'``).

Results and seeds are the same on every executor: a unit carries its own seed (derived from its key).
"""

from __future__ import annotations

import time
from collections.abc import Callable, Sequence
from concurrent.futures import FIRST_COMPLETED, ProcessPoolExecutor, wait
from concurrent.futures.process import BrokenProcessPool

from ..errors import NeurohoverError
from ..procs import sigterm_as_interrupt, stop_pool, worker_pool
from .store import worker_name
from .units import Unit, run_unit

OnResult = Callable[[Unit, dict, float, str], None]
OnError = Callable[[Unit, BaseException], None]

RAY_INSTALL_HINT = ("--executor ray needs Ray, an optional extra: pip install 'neurohover[ray]' "
                    "(or pip install 'ray>=2.9'); --executor local runs without it")


def timed_run(unit: dict, threads: int | None = 1) -> tuple[dict, float, str]:
    """Run a unit (given as a dict); return (result, seconds, worker)."""
    t0 = time.perf_counter()
    result = run_unit(unit, threads)
    return result, time.perf_counter() - t0, worker_name()


class LocalExecutor:
    """Run units here (``jobs=1``) or in ``jobs`` spawned processes."""

    name = "local"

    def __init__(self, jobs: int = 1) -> None:
        if not isinstance(jobs, int) or isinstance(jobs, bool) or jobs < 1:
            raise NeurohoverError(f"--jobs {jobs!r} is out of range: allowed an integer >= 1")
        self.jobs = jobs
        self._pool: ProcessPoolExecutor | None = None

    @property
    def cores(self) -> int:
        if self.jobs == 1:
            import numba

            return int(numba.config.NUMBA_NUM_THREADS)
        return self.jobs

    def run(self, units: Sequence[Unit], on_result: OnResult, on_error: OnError) -> None:
        if self.jobs == 1:
            for unit in units:
                try:
                    result, seconds, worker = timed_run(unit.to_dict(), None)
                except KeyboardInterrupt:
                    raise
                except Exception as err:  # noqa: BLE001 - reported, the unit stays unfinished
                    on_error(unit, err)
                    continue
                on_result(unit, result, seconds, worker)
            return
        if self._pool is None:
            # One pool for the executor's lifetime (all stages and experiments): spawning workers
            # and loading the compiled kernel costs seconds per process.
            self._pool = worker_pool(self.jobs)
        pool = self._pool
        try:
            with sigterm_as_interrupt():  # SIGTERM ends the workers like Ctrl-C, not leaving them orphaned
                pending = {pool.submit(timed_run, unit.to_dict(), 1): unit for unit in units}
                while pending:
                    done, _ = wait(pending, return_when=FIRST_COMPLETED)
                    for future in done:
                        unit = pending.pop(future)
                        try:
                            result, seconds, worker = future.result()
                        except BrokenProcessPool as err:
                            on_error(unit, RuntimeError(f"worker process died ({err})"))
                            self._pool = None  # a broken pool cannot run more units: start a new one next time
                            continue
                        except Exception as err:  # noqa: BLE001
                            on_error(unit, err)
                            continue
                        on_result(unit, result, seconds, worker)
        except BaseException:
            stop_pool(pool)
            self._pool = None
            raise

    def close(self) -> None:
        if self._pool is not None:
            self._pool.shutdown(wait=True)
            self._pool = None


def import_ray():
    try:
        import ray
    except ImportError:
        raise NeurohoverError(RAY_INSTALL_HINT) from None
    return ray


class RayExecutor:
    """Run units as Ray tasks (one CPU each) on the cluster at ``address`` or on a local one."""

    name = "ray"

    def __init__(self, address: str | None = None, *, max_retries: int = 3, num_cpus: int | None = None) -> None:
        ray = import_ray()
        self.ray = ray
        self.started = False
        if not ray.is_initialized():
            kwargs = {"include_dashboard": False, "log_to_driver": True}
            if address is None and num_cpus is not None:
                kwargs["num_cpus"] = num_cpus
            try:
                ray.init(address=address, **kwargs)
            except ConnectionError as err:
                raise NeurohoverError(f"cannot connect to the Ray cluster at {address!r}: {err}") from None
            self.started = True
        self.max_retries = max_retries
        self._remote = ray.remote(num_cpus=1, max_retries=max_retries)(timed_run)

    @property
    def cores(self) -> int:
        return int(self.ray.cluster_resources().get("CPU", 1))

    def run(self, units: Sequence[Unit], on_result: OnResult, on_error: OnError) -> None:
        ray = self.ray
        pending = {self._remote.remote(unit.to_dict(), 1): unit for unit in units}
        try:
            while pending:
                ready, _ = ray.wait(list(pending), num_returns=1, timeout=5.0)
                for ref in ready:
                    unit = pending.pop(ref)
                    try:
                        result, seconds, worker = ray.get(ref)
                    except Exception as err:  # noqa: BLE001 - RayTaskError, WorkerCrashedError, ...
                        on_error(unit, err)
                        continue
                    on_result(unit, result, seconds, worker)
        except BaseException:
            for ref in pending:
                try:
                    ray.cancel(ref, force=True)
                except Exception:  # noqa: BLE001
                    pass
            raise

    def close(self) -> None:
        if self.started:
            self.ray.shutdown()
            self.started = False


def make_executor(kind: str, *, jobs: int = 1, address: str | None = None):
    if kind == "local":
        if address is not None:
            raise NeurohoverError("--address applies to --executor ray only")
        return LocalExecutor(jobs)
    if kind == "ray":
        return RayExecutor(address)
    raise NeurohoverError(f"unknown executor {kind!r}: allowed local, ray")
