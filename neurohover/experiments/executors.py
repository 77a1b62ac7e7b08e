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

import os
import socket
import time
from collections.abc import Callable, Sequence
from concurrent.futures import FIRST_COMPLETED, ProcessPoolExecutor, wait
from concurrent.futures.process import BrokenProcessPool
from typing import Any

from ..errors import NeurohoverError, brief, whole_number
from ..evaluate import DEVICES, check_device
from ..procs import max_jobs, refuse_few_descriptors, refuse_gone_cwd_for_workers, sigterm_as_interrupt, stop_pool, worker_pool
from .store import worker_name
from .store_checks import EXECUTORS
from .units import Unit, run_unit

OnResult = Callable[[Unit, dict, float, str], None]
OnError = Callable[[Unit, BaseException], None]

RAY_INSTALL_HINT = "--executor ray needs Ray, an optional extra: pip install 'neurohover[ray]' (or pip install 'ray>=2.9'); --executor local runs without it"


def timed_run(unit: dict, threads: int | None = 1, device: str = "cpu") -> tuple[dict, float, str]:
    """Run a unit (given as a dict) on ``device``; return (result, seconds, worker)."""
    t0 = time.perf_counter()
    result = run_unit(unit, threads, device)
    return result, time.perf_counter() - t0, worker_name()


def check_jobs(jobs) -> int:
    """``jobs`` local worker processes: an integer from 1 to the cores this process may use (NeurohoverError otherwise)."""
    cores = max_jobs()
    if not whole_number(jobs):  # '2' was called out of range (twelfth trial, U1)
        raise NeurohoverError(f"--jobs {brief(jobs)} is not allowed: give an integer in 1..{cores} (the cores this process may use)")
    if not 1 <= int(jobs) <= cores:
        raise NeurohoverError(f"--jobs {brief(jobs)} is out of range: allowed an integer in 1..{cores} (the cores this process may use)")
    refuse_gone_cwd_for_workers(int(jobs))  # before anything is written (T32-A06)
    if jobs > 1:  # too low an open-files limit for the workers, too (T45-A01)
        refuse_few_descriptors(int(jobs))
    return int(jobs)  # np.int64(2) as 2


class LocalExecutor:
    """Run units here (``jobs=1``) or in ``jobs`` spawned processes, flying on ``device``
    (``"cpu"`` or ``"cuda"``; with ``jobs > 1`` every worker process uses the same GPU)."""

    name = EXECUTORS[0]  # the names a store's sessions may hold

    def __init__(self, jobs: int = 1, device: str = "cpu") -> None:
        jobs = check_jobs(jobs)
        check_device(device)
        self.jobs = jobs
        self.device = device
        self._pool: ProcessPoolExecutor | None = None

    @property
    def cores(self) -> int:
        if self.jobs == 1:
            import numba

            return int(numba.config.NUMBA_NUM_THREADS)  # type: ignore[attr-defined]
        return self.jobs

    def run(self, units: Sequence[Unit], on_result: OnResult, on_error: OnError) -> None:
        if self.jobs == 1:
            for unit in units:
                try:
                    result, seconds, worker = timed_run(unit.to_dict(), None, self.device)
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
                pending = {pool.submit(timed_run, unit.to_dict(), 1, self.device): unit for unit in units}
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


RAY_ADDRESS_FORMS = (
    "host:port (port 1 to 65535, e.g. 10.0.0.5:6379, as printed by `ray start --head`), "
    "ray://host:port (Ray Client), or auto (the cluster started on this machine)"
)
CONNECT_SECONDS = 3.0  # how long to wait for a cluster's port to accept a connection


def ray_endpoint(address: str, source: str = "--address") -> tuple[str, int] | None:
    """The (host, port) that a Ray cluster ``address`` names.

    Parameters
    ----------
    address : str
        ``host:port``, ``[ipv6]:port``, ``ray://host:port``, or ``auto`` / ``local`` (which Ray
        resolves itself; None is returned for them).
    source : str
        Where the address came from, for the message (``--address`` or ``RAY_ADDRESS``).

    Raises
    ------
    NeurohoverError
        For any other form, naming the address and the forms allowed.
    """
    if not isinstance(address, str):  # 5 was an AttributeError (fourteenth trial, T14-22)
        raise NeurohoverError(f"{source} {brief(address)} is not a Ray cluster address: allowed {RAY_ADDRESS_FORMS}")
    if address in ("auto", "local"):
        return None
    rest = address[len("ray://") :] if address.startswith("ray://") else address
    host, sep, port = rest.rpartition(":")
    if host.startswith("[") and host.endswith("]"):
        host = host[1:-1]
    elif ":" in host:
        host = ""  # an IPv6 host needs brackets: [::1]:6379
    valid_host = host and not any(c.isspace() or c in "/[]@" for c in host)
    if not (sep and valid_host and port.isascii() and port.isdigit() and 1 <= int(port) <= 65535):
        raise NeurohoverError(f"{source} {address!r} is not a Ray cluster address: allowed {RAY_ADDRESS_FORMS}")
    return host, int(port)


def check_ray_address(address: str, source: str = "--address") -> None:
    """Refuse ``address`` at once, with one clear message, if it is malformed or nothing listens there.

    Ray itself retries an unreachable cluster for many minutes; a short TCP connect settles it first.
    """
    endpoint = ray_endpoint(address, source)
    if endpoint is None:
        return
    host, port = endpoint
    try:
        socket.create_connection((host, port), timeout=CONNECT_SECONDS).close()
    except OSError as err:
        if isinstance(err, TimeoutError):
            reason = f"no answer within {CONNECT_SECONDS:g} s"
        elif isinstance(err, socket.gaierror):
            reason = f"unknown host {host!r}"
        else:
            reason = (err.strerror or str(err)).lower()
        instead = "unset RAY_ADDRESS and leave out --address" if source == "RAY_ADDRESS" else "leave out --address"
        raise NeurohoverError(
            f"{source} {address!r}: no Ray cluster is listening at {host}:{port} ({reason}); start one first "
            f"(`ray start --head` prints its address) or {instead} to start a local Ray instance"
        ) from None


def ray_address_used(address: str | None) -> tuple[str, str | None]:
    """Where the cluster that ``ray.init(address)`` joins is named, and its address: ``RAY_ADDRESS`` (when set and
    not empty) for ``address`` None or ``auto``, as Ray reads it; ``--address`` itself otherwise."""
    env = os.environ.get("RAY_ADDRESS") or None
    if address in (None, "auto") and env is not None:
        return "RAY_ADDRESS", env
    return "--address", address


def _one_line(err: BaseException) -> str:
    lines = [ln.strip() for ln in str(err).splitlines() if ln.strip()]
    return lines[0] if lines else type(err).__name__


class RayExecutor:
    """Run units as Ray tasks (one CPU each) on the cluster at ``address`` or on a local one.

    Without ``address``, Ray's own ``RAY_ADDRESS`` environment variable, if set, names the cluster.
    A malformed address, or one where nothing listens, is refused at once with a NeurohoverError.
    ``device`` is where the tasks fly (``"cuda"``: each node needs a GPU; it is checked there).
    """

    name = EXECUTORS[1]

    def __init__(self, address: str | None = None, *, max_retries: int = 3, num_cpus: int | None = None, device: str = "cpu") -> None:
        if not isinstance(device, str) or device not in DEVICES:  # an array was numpy's 'truth value is ambiguous' (T18-3)
            raise NeurohoverError(f"device={brief(device)} is unknown: allowed 'cpu' or 'cuda'")
        if address is not None:  # its form before Ray is imported or started (address=5 was an AttributeError; T14-22)
            ray_endpoint(address)
        self.device = device
        ray = import_ray()
        self.ray = ray
        self.started = False
        if not ray.is_initialized():
            # ray.init(address=None or "auto") joins the cluster that RAY_ADDRESS names, so check that one too (with
            # --address auto it was not checked, and Ray retried a dead one without end; T45-A02).
            source, given = ray_address_used(address)
            if given is not None:
                check_ray_address(given, source)
            kwargs: dict[str, Any] = {"include_dashboard": False, "log_to_driver": True}
            if given is None and num_cpus is not None:
                kwargs["num_cpus"] = num_cpus
            try:
                ray.init(address=address, **kwargs)
            except Exception as err:  # noqa: BLE001 - ConnectionError, ValueError, RuntimeError, ... from Ray
                where = f"the Ray cluster at {source} {given!r}" if given is not None else "a local Ray instance"
                raise NeurohoverError(f"cannot connect to {where}: {_one_line(err)}") from None
            self.started = True
        self.max_retries = max_retries
        self._remote = ray.remote(num_cpus=1, max_retries=max_retries)(timed_run)

    @property
    def cores(self) -> int:
        return int(self.ray.cluster_resources().get("CPU", 1))

    def run(self, units: Sequence[Unit], on_result: OnResult, on_error: OnError) -> None:
        ray = self.ray
        pending = {self._remote.remote(unit.to_dict(), 1, self.device): unit for unit in units}
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


def make_executor(kind: str, *, jobs: int = 1, address: str | None = None, device: str = "cpu"):
    if not isinstance(kind, str):  # an array was numpy's 'truth value is ambiguous' (T18-3)
        raise NeurohoverError(f"unknown executor {brief(kind)}: allowed local, ray")
    if kind == "local":
        if address is not None:
            raise NeurohoverError("--address applies to --executor ray only")
        return LocalExecutor(jobs, device)
    if kind == "ray":
        return RayExecutor(address, device=device)
    raise NeurohoverError(f"unknown executor {brief(kind)}: allowed local, ray")
