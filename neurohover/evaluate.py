"""Batched evaluation: fly many (policy, MDP, episode) jobs in parallel through the kernel.

Every episode draws its gust noise from its own stream derived from (seed, episode index), so a
result never depends on batch size, order or thread count. Jobs with the same episode index see
the same noise (common random numbers), which makes comparisons between policies fairer.

Example
-------
>>> from neurohover import evaluate, baseline_policy, get_task_family
>>> ev = evaluate([baseline_policy()], get_task_family("ghh08").training_mdps(), episodes=2, seed=1)
>>> ev.returns.shape            # (policies, MDPs, episodes)
(1, 10, 2)
"""

from __future__ import annotations

from collections.abc import Iterable, Sequence
from dataclasses import dataclass, field
from pathlib import Path

import numpy as np

from .errors import NeurohoverError, as_floats, brief, finite_real, whole_in, whole_number
from .flightdata import FlightData, same_values
from .flyer import KernelFlyer, refuse_other_import
from .launch import DEVICES, KIND, MAX_EPISODES_PER_CALL, MAX_SEED, Batch, Flown, check_device, launch, num_threads, use_lanes
from .policies import GENOME_LENGTH, Policy, check_genome, check_padding, frozen, genome_rows, load_policy, refuse_own_act
from .safeguard import DangerousState, Safeguard
from .sim.constants import (
    EPISODE_STEPS,
    MAX_EPISODE_STEPS,
    ROW_SENSOR,
    SAFEGUARD_ARM,
    SAFEGUARD_LAYOUT_LEN,
    SAFEGUARD_LIMITS,
    return_floor,
)
from .sim.kernel import GENOME_WIDTH
from .tasks import MDP, TASK_NAMES, Sensor, check_rows, refuse_drift, refuse_unordered_mdps
from .tasks.held import LEARNED_MODEL

# Re-exported where they were first defined: KernelFlyer, DEVICES, check_device, num_threads, use_lanes.
__all__ = [
    "DEVICES",
    "check_first_episode",
    "MAX_EPISODES_PER_CALL",
    "DangerousState",
    "Evaluation",
    "KernelFlyer",
    "PolicyTable",
    "Safeguard",
    "as_policies",
    "check_device",
    "check_episode_count",
    "evaluate",
    "evaluate_jobs",
    "mdp_rows",
    "num_threads",
    "use_lanes",
]


def as_policies(policies) -> list[Policy]:
    """``policies`` as a list of :class:`Policy`: a Policy, a policy file's path or ``"baseline"``, or a sequence of these."""
    refuse_other_import(policies if isinstance(policies, (list, tuple)) else [policies])  # a reloaded module's (T36-B10)

    allowed = "give a Policy, a policy file's path or 'baseline' (or a sequence of these, or a PolicyTable)"

    def one(p) -> Policy:
        if isinstance(p, (Policy, str, Path)):
            return p if isinstance(p, Policy) else load_policy(p)
        raise NeurohoverError(f"policy {brief(p)} is not allowed: {allowed}")  # brief: a set of 100 policies was 44,495 characters (T28-B02)

    if isinstance(policies, (Policy, str, Path)):
        return [one(policies)]
    if isinstance(policies, Sequence):
        return [one(p) for p in policies]
    raise NeurohoverError(f"policies={brief(policies)} is not allowed: {allowed}")


@dataclass(frozen=True, eq=False)
class PolicyTable:
    """Policies as the kernel reads them: a kind per row and genomes padded to 42 columns.

    ``==`` compares the kinds and genomes bit for bit (NaN equals NaN); like a list, a table is not hashable.
    """

    kinds: np.ndarray  # (P,) int64
    genomes: np.ndarray  # (P, 42) float64

    def __eq__(self, other: object) -> bool:  # the generated one raised NumPy's "truth value is ambiguous" (tenth trial)
        if not isinstance(other, PolicyTable):
            return NotImplemented
        return same_values((self.kinds, self.genomes), (other.kinds, other.genomes))  # int64 and float64 both, after __post_init__

    __hash__ = None  # type: ignore[assignment]

    def __post_init__(self) -> None:
        """A table built by hand, checked for what the kernel would misread (a kind 9 flew as an SLP; second trial). A
        non-finite genome is allowed: its non-finite actions crash, as the simulator defines (the tests fly that path)."""
        for name in ("kinds", "genomes"):  # np.asarray dropped the mask: the hidden values were flown (T16-9)
            if isinstance(getattr(self, name), np.ma.MaskedArray):
                raise NeurohoverError(f"PolicyTable {name}={brief(getattr(self, name))} is not allowed: give a plain array, not a masked one")
        kinds, genomes = np.asarray(self.kinds), np.asarray(self.genomes)
        if kinds.ndim != 1 or kinds.dtype.kind not in "iu" or not np.isin(kinds, list(KIND.values())).all():
            raise NeurohoverError(f"PolicyTable kinds must be a 1-D integer array of {sorted(KIND.values())} ({', '.join(KIND)}), got {kinds!r:.80}")
        if genomes.shape != (kinds.shape[0], GENOME_WIDTH):
            raise NeurohoverError(f"PolicyTable genomes must be an array of shape ({kinds.shape[0]}, {GENOME_WIDTH}), got shape {genomes.shape}")
        if genomes.dtype.kind not in "iuf":  # not issubdtype(np.integer): time spans are NumPy integers (T17-1); booleans are kind 'b'
            raise NeurohoverError(f"PolicyTable genomes must be real numbers, got dtype {genomes.dtype} (complex and objects were a ValueError in the kernel)")
        check_padding(kinds, genomes, KIND)  # an MLP row declared an SLP flew as one, its genes 40 and 41 unread (T33-B10)
        # uint8 kinds were refused by the kernel's batch; read-only, as a Policy's genome: a row made an SLP after the
        # padding check flew as one (T35-B01), the caller's own array copied rather than frozen
        object.__setattr__(self, "kinds", frozen(kinds.astype(np.int64, copy=False), self.kinds))
        object.__setattr__(self, "genomes", frozen(genomes.astype(np.float64, copy=False), self.genomes))

    @classmethod
    def from_policies(cls, policies: Sequence[Policy]) -> PolicyTable:
        if isinstance(policies, Policy):  # one policy where a sequence goes (was a TypeError; second trial)
            policies = [policies]
        if not isinstance(policies, Sequence) or isinstance(policies, str) or len(policies) == 0:
            raise NeurohoverError(f"policies={policies!r:.60} is not allowed: give a non-empty sequence of Policy objects")
        # 'baseline' was an AttributeError (second trial); None too, read as the 'nothing found' default (T26-B01)
        bad = [p for p in refuse_other_import(policies) if not isinstance(p, Policy)]
        if bad:
            raise NeurohoverError(f"policy {bad[0]!r:.60} is not a Policy: load one with neurohover.load_policy (e.g. load_policy('baseline'))")
        refuse_own_act(policies)  # a subclass's own act was ignored: the kernel flies the genome (T33-B11)
        # checked again as save_policy does: a frozen field overwritten (object.__setattr__) was a KeyError or flown (T41-B11)
        checked = [check_genome(p.genome, p.topology) for p in policies]
        kinds = np.array([KIND[p.topology] for p in policies], dtype=np.int64)
        genomes = np.zeros((len(policies), GENOME_WIDTH))
        for i, genome in enumerate(checked):
            genomes[i, : genome.size] = genome
        return cls(frozen(kinds, None), frozen(genomes, None))  # made here: frozen, not copied again

    @classmethod
    def from_genomes(cls, genomes: np.ndarray, topology: str) -> PolicyTable:
        """A table of genomes (P, D) of one topology (the evolution fast path).

        Non-finite genes are allowed here, unlike in :class:`Policy`: an optimiser's diverged sample is flown and
        crashes at once, as the simulator defines, instead of stopping the run (a policy file, meant to be flown as
        it is, is refused instead).
        """
        g, n = genome_rows(genomes, topology), GENOME_LENGTH[topology]  # the checks: a ragged list was NumPy's ValueError (T34-B02)
        table = np.zeros((g.shape[0], GENOME_WIDTH))
        table[:, :n] = g
        return cls(frozen(np.full(g.shape[0], KIND[topology], dtype=np.int64), None), frozen(table, None))  # not copied again

    def __len__(self) -> int:
        return self.kinds.shape[0]


@dataclass(frozen=True, eq=False)  # eq=False: the generated == compared arrays as tuples, NumPy's ValueError (tenth trial)
class Evaluation:
    """Outcome of a batch of episodes; arrays share the shape of the jobs.

    ``==`` compares outcomes: the same arrays (shape, dtype and values, NaN equal to NaN) and equal flight data,
    ``seconds`` left out. An Evaluation is unhashable (it holds arrays), as a list is.

    Attributes
    ----------
    returns : numpy.ndarray
        Undiscounted return of each episode (minus the paper's "error").
    crashed : numpy.ndarray of bool
    steps : numpy.ndarray of int
        Control steps flown (6000 for a full episode; the crashing step counts).
    safeguard_step : numpy.ndarray of int
        Control step at which the safeguard handed over to the fallback, or -1.
    flight_data : FlightData or None
        Flight data of the recorded episodes, in job order.
    seconds : float
        Wall time of the kernel call (not part of ``==``).
    """

    returns: np.ndarray
    crashed: np.ndarray
    steps: np.ndarray
    safeguard_step: np.ndarray
    flight_data: FlightData | None
    seconds: float = field(compare=False)  # wall-clock, not part of the outcome

    __hash__ = None  # type: ignore[assignment]  # mutable arrays: the generated hash was a TypeError on ndarray (tenth trial)

    def __post_init__(self) -> None:
        """Checked as evaluate() builds it: text returns were an AttributeError later, arrays of other shapes NumPy's
        ValueError in reshape(), flight_data='x' and seconds=nan taken (T26-B02)."""
        kinds = {"returns": ("fiu", "real numbers"), "crashed": ("b", "True/False flags"), "steps": ("iu", "integers"), "safeguard_step": ("iu", "integers")}
        for name, (allowed, what) in kinds.items():
            value = getattr(self, name)
            if not isinstance(value, np.ndarray) or isinstance(value, np.ma.MaskedArray) or value.dtype.kind not in allowed:
                raise NeurohoverError(f"Evaluation {name}={brief(value)} is not allowed: give a NumPy array of {what}, one per episode")
            if value.shape != self.returns.shape:
                raise NeurohoverError(f"Evaluation {name} has shape {value.shape}, returns {self.returns.shape}: give one entry per episode in each")
        steps, fired, r = self.steps, self.safeguard_step, self.returns
        lo, hi = (int(steps.min()), int(steps.max())) if steps.size else (1, 1)
        if lo < 1 or hi > MAX_EPISODE_STEPS:
            raise NeurohoverError(f"Evaluation steps holds {brief(lo if lo < 1 else hi)}: allowed 1..{MAX_EPISODE_STEPS:,}")
        bad = np.flatnonzero((fired < -1) | (fired >= steps))
        if bad.size:
            i = np.unravel_index(bad[0], fired.shape)
            raise NeurohoverError(f"Evaluation safeguard_step {int(fired[i])} of a {int(steps[i])}-step episode is not allowed: give -1 (never) or 0..steps-1")
        if r.size and not (r.max() <= 0 and r.min() >= return_floor(lo, False)):  # T27-B10: the least floor of all first
            if (bad := np.flatnonzero((r > 0) | (r < (floor := return_floor(steps, self.crashed))) | np.isinf(r))).size:  # NaN: T27-B06's
                i = np.unravel_index(bad[0], r.shape)
                how = "an episode that crashed" if self.crashed[i] else f"a {int(steps[i])}-step episode that did not crash"
                raise NeurohoverError(f"Evaluation returns holds {brief(float(r[i]))} for {how}: allowed {float(floor[i]) / (1 + 1e-9):.10g}..0")
        if not (self.flight_data is None or isinstance(self.flight_data, FlightData)):
            raise NeurohoverError(f"Evaluation flight_data={brief(self.flight_data)} is not allowed: give FlightData or None")
        if self.flight_data is not None and self.flight_data.n_episodes > self.returns.size:
            raise NeurohoverError(f"Evaluation flight_data holds {self.flight_data.n_episodes} episodes, more than the {self.returns.size} flown")
        if not (finite_real(self.seconds) and self.seconds >= 0):
            raise NeurohoverError(f"Evaluation seconds={brief(self.seconds)} is not allowed: give a finite number >= 0 (wall time)")
        object.__setattr__(self, "seconds", float(self.seconds))

    def __eq__(self, other: object) -> bool:
        if not isinstance(other, Evaluation):
            return NotImplemented
        mine = tuple(map(np.asarray, (self.returns, self.crashed, self.steps, self.safeguard_step)))
        theirs = tuple(map(np.asarray, (other.returns, other.crashed, other.steps, other.safeguard_step)))
        return same_values(mine, theirs) and self.flight_data == other.flight_data

    @property
    def episodes(self) -> int:
        return int(self.returns.size)

    @property
    def episodes_per_second(self) -> float:
        return self.episodes / self.seconds if self.seconds > 0 else float("inf")

    def reshape(self, shape: tuple[int, ...]) -> Evaluation:
        """The same outcome with its arrays reshaped to ``shape`` (of as many episodes; NumPy's -1 allowed)."""
        try:
            returns = self.returns.reshape(shape)
        except (TypeError, ValueError):  # (3,) of 2 episodes was NumPy's ValueError, 'x' a TypeError (T14-19)
            raise NeurohoverError(
                f"shape={brief(shape)} is not allowed: give a shape of {self.episodes} episodes, e.g. ({self.episodes},) "
                f"(the arrays' shape is {self.returns.shape})"
            ) from None
        return Evaluation(
            returns,
            self.crashed.reshape(shape),
            self.steps.reshape(shape),
            self.safeguard_step.reshape(shape),
            self.flight_data,
            self.seconds,
        )


def mdp_rows(mdps: MDP | Sequence[MDP] | np.ndarray) -> np.ndarray:
    """MDPs as the (M, MDP_ROW_LEN) float64 array the kernel reads (an array's sensor slots checked)."""
    if isinstance(mdps, MDP):
        refuse_drift(mdps, "this batch")
        return mdps.row()[None, :]
    if isinstance(mdps, np.ndarray):
        check_rows(mdps)  # shape, finiteness, substeps, dt, noise and wind kind: an all-zero row flew as a perfect 0.0 (T14-18)
        sensors = mdps[:, ROW_SENSOR]
        if sensors.any():  # the rows' sensor models, each distinct one checked by Sensor's own rules
            for values in np.unique(sensors, axis=0):
                try:
                    Sensor.from_row_values(values)
                except NeurohoverError as err:
                    i = int(np.flatnonzero((sensors == values).all(axis=1))[0])
                    raise NeurohoverError(f"MDP row {i} has an invalid sensor model {values.tolist()}: {err}") from None
        return np.ascontiguousarray(mdps, dtype=float)
    # Iterable too: a sized object that cannot be iterated (a PolicyTable) was a TypeError "not iterable" (T51-B01)
    sized = isinstance(mdps, Iterable) and not isinstance(mdps, (str, bytes)) and hasattr(mdps, "__len__")
    if not sized or len(mdps) == 0 or not all(isinstance(m, MDP) for m in mdps):
        raise NeurohoverError(f"mdps={brief(mdps)} is not allowed: give an MDP, a non-empty sequence of MDPs or an array of MDP rows")
    for m in refuse_unordered_mdps(mdps):  # a set flew in hash order (T32-B02)
        refuse_drift(m, "this batch")
    return np.stack([m.row() for m in mdps])


def _index_array(values, n_jobs: int | None, what: str, jobs=None) -> np.ndarray:
    """``values`` as a 1-D int64 array of job indices; their range is checked where every launch's is (launch.check_job_indices,
    from :class:`Batch`), so a KernelFlyer's or a hand-made Batch's indices cannot segfault either (thirteenth trial, F1)."""
    if isinstance(values, np.ma.MaskedArray):  # np.asarray dropped the mask: the hidden indices were flown (T16-9)
        raise NeurohoverError(f"{what}={brief(values)} is not allowed: give a plain array of job indices, not a masked one")
    arr = np.asarray(values)
    if arr.ndim > 1:  # one index per job: a 2-D array's jobs would be flattened in an order the caller may not mean
        raise NeurohoverError(f"{what} must be a 1-D array of job indices, got shape {arr.shape}")
    check_episode_count(arr.size, f"{what} of {arr.size:,} jobs")  # before its int64 copy (10**10 int8 indices: 75 GiB; third trial)
    if arr.size and arr.dtype.kind not in "iu":  # not issubdtype(np.integer): a time span's array is one (T17-1)
        given = arr.flat if arr.dtype == object else values if isinstance(values, (list, tuple)) else ()  # [0, 2**63] is float64 (T48-B07)
        wide = next((v for v in given if whole_number(v) and not -(2**63) <= v < 2**63), None)  # T41-B09
        raise NeurohoverError(f"{what} holds {brief(wide)}, out of range: allowed 0..2**63-1" if wide else f"{what} must hold integers, got dtype {arr.dtype}")
    if arr.size and np.issubdtype(arr.dtype, np.unsignedinteger) and arr.max() > np.iinfo(np.int64).max:  # would wrap negative
        raise NeurohoverError(f"{what} holds {arr.max()}, out of range: allowed 0..2**63-1")
    arr = arr.astype(np.int64).reshape(-1)
    if n_jobs is not None and arr.shape[0] != n_jobs:  # policy_index (``jobs``) sets the jobs: an empty one blamed mdp_index (T44-B10)
        raise NeurohoverError(
            f"{what} has {arr.shape[0]} entries but policy_index={brief(jobs)} (shape {np.shape(jobs)}) sets the job count, {n_jobs}: give one per job in each"
        )
    return arr


#: The most control steps one call flies (about a day of the kernel on two cores), and the most memory its recorded
#: flight data may take (12 readings and 4 actions a step, float64).
MAX_STEPS_PER_CALL, MAX_RECORD_BYTES, RECORD_BYTES_PER_STEP = 10**12, 8 * 2**30, 16 * 8


def _check_n_steps(n_steps) -> int:
    return whole_in(n_steps, "n_steps", 1, MAX_EPISODE_STEPS)  # an int: np.int8(127) + 1 overflowed (T31-B02); np.timedelta64 (T17-1)


def _check_call_size(n_jobs: int, n_steps: int, n_rec: int) -> None:
    """Refuse a call that could not finish (10**8 episodes of 10**7 steps passed every check and ran for years) or whose
    recorded flight data memory cannot hold (53.7 GiB was a MemoryError); fourth trial."""
    if n_jobs * n_steps > MAX_STEPS_PER_CALL:
        raise NeurohoverError(
            f"{n_jobs:,} episodes of n_steps={n_steps:,} are {n_jobs * n_steps:,} control steps, more than one call flies "
            f"(at most {MAX_STEPS_PER_CALL:,}, about a day on two cores): use fewer episodes or steps"
        )
    if n_rec * (n_steps + 1) * RECORD_BYTES_PER_STEP > MAX_RECORD_BYTES:
        raise NeurohoverError(
            f"recording {n_rec:,} episodes of n_steps={n_steps:,} takes {n_rec * (n_steps + 1) * RECORD_BYTES_PER_STEP / 2**30:.1f} GiB "
            f"of memory, more than {MAX_RECORD_BYTES / 2**30:.0f} GiB: record fewer episodes or steps (several calls, each saved)"
        )


def _fallback_array(fallback_index, n_jobs: int, n_policies: int) -> np.ndarray:
    """Each job's fallback policy (-1: none) as an int64 array, checked: ``n_jobs`` integers in -1..n_policies-1."""
    if fallback_index is None:
        return np.full(n_jobs, -1, dtype=np.int64)
    fb = np.asarray(fallback_index)
    masked = isinstance(fallback_index, np.ma.MaskedArray)  # np.asarray dropped the mask (T16-9)
    if (fb.dtype.kind not in "iu" and fb.size) or masked:  # ["x"] was NumPy's ValueError (fifth trial); 1.5 was cut to 1
        raise NeurohoverError(f"fallback_index={fallback_index!r:.60} is not allowed: give {n_jobs} integers in -1..{n_policies - 1}")
    if fb.ndim > 1:  # flattened, as the job indexes are not (T34-B11)
        raise NeurohoverError(f"fallback_index must be a 1-D array of job indices, got shape {fb.shape}: give one per job, each in -1..{n_policies - 1}")
    if fb.size != n_jobs:  # T26-B17: the length and the bad entry were not named
        raise NeurohoverError(f"fallback_index has {fb.size} entries but there are {n_jobs} jobs: give one per job, each in -1..{n_policies - 1}")
    bad = np.flatnonzero((fb < -1) | (fb >= n_policies))
    if bad.size:
        raise NeurohoverError(f"fallback_index entry {bad[0]} is {brief(fb.flat[bad[0]].item())}, out of range: allowed -1 (none) or 0..{n_policies - 1}")
    return fb.astype(np.int64).reshape(-1)


def check_episode_count(n: int, what: str) -> None:
    """Refuse ``n`` episodes in one call above :data:`MAX_EPISODES_PER_CALL` (``what`` names where they come from)."""
    if not whole_number(n) or n < 0:  # '5' and None were TypeErrors, 2.5 and -3 were taken (T47-B04)
        raise NeurohoverError(f"{what}: its episode count {brief(n)} is not allowed: give a whole number of episodes, 0..{MAX_EPISODES_PER_CALL:,}")
    if n > MAX_EPISODES_PER_CALL:
        raise NeurohoverError(
            f"{what} is out of range: {n:,} episodes, at most {MAX_EPISODES_PER_CALL:,} in one call (their results are held in memory); use fewer"
        )


def evaluate_jobs(
    policies: Sequence[Policy] | PolicyTable,
    mdps: MDP | Sequence[MDP] | np.ndarray,
    policy_index,
    mdp_index,
    episode_index,
    *,
    seed: int = 0,
    fallback_index=None,
    safeguard_limits: Sequence[float] | np.ndarray | None = None,
    record=None,
    n_steps: int = EPISODE_STEPS,
    threads: int | None = None,
    device: str = "cpu",
) -> Evaluation:
    """Fly the jobs ``(policy_index[j], mdp_index[j], episode_index[j])`` in parallel.

    Parameters
    ----------
    policies : sequence of Policy or PolicyTable
    mdps : MDP, sequence of MDP, or (M, MDP_ROW_LEN) array of MDP rows
    policy_index, mdp_index, episode_index : array_like of int, shape (J,)
        Which policy flies which MDP, and the episode index that (with ``seed``) fixes the noise.
    seed : int
        Root seed of every episode's noise stream.
    fallback_index : array_like of int, optional
        Per job, the policy the safeguard hands control to (-1: no safeguard for that job).
    safeguard_limits : sequence or array of 25 floats, optional
        Only with ``fallback_index``: the dangerous-state test in the kernel's layout (:meth:`DangerousState.limits`): limits on |u|, |v|, |w|,
        |x|, |y|, |z|, |p|, |q|, |r|, the tilt threshold on qw (inf: none), the kind, the ratio-sum threshold and limits. Default: ``DangerousState()``.
    record : bool or array_like of bool, optional
        Per job, whether to record its flight data; one bool (Python's or NumPy's) for every job. Default: none. Their
        metadata hold no ``mdps`` (:func:`evaluate` adds them): run_test hands them to agents, which must not see their MDP.
    n_steps : int
        Control steps per episode (6000 in the benchmark).
    threads : int, optional
        Kernel threads (default: all cores). Results do not depend on it. Unused on ``"cuda"``.
    device : {"cpu", "cuda"}
        Where the kernel runs: the CPU kernel, or the CUDA build of the same source on a GPU
        (one thread per job, the same gust streams; returns agree with the CPU's to about 1e-12
        relative, see docs/gpu.md). ``seconds`` then includes the copies to and from the GPU.
    """
    check_device(device)
    table = policies if isinstance(policies, PolicyTable) else PolicyTable.from_policies(policies)
    rows = mdp_rows(mdps)
    seed = whole_in(seed, "seed", 0, MAX_SEED, "2**63-1")  # True was seed 1; np.timedelta64 int()'s TypeError (T17-1)
    n_steps = _check_n_steps(n_steps)  # the int checked is the int flown: np.int8(127) + 1 was -128 (T31-B02)
    p_idx = _index_array(policy_index, None, "policy_index")
    n_jobs = p_idx.shape[0]
    m_idx = _index_array(mdp_index, n_jobs, "mdp_index", policy_index)
    e_idx = _index_array(episode_index, n_jobs, "episode_index", policy_index)
    fb = _fallback_array(fallback_index, n_jobs, len(table))
    if safeguard_limits is not None and fallback_index is None:  # the limits acted on no job, without a word (T28-B16)
        raise NeurohoverError("safeguard_limits needs fallback_index= (each job's fallback policy, -1: none): alone it acts on no job; give both, or neither")
    try:
        limits = SAFEGUARD_LIMITS if safeguard_limits is None else as_floats(safeguard_limits, "safeguard_limits", "")
    except NeurohoverError:  # 'x' was NumPy's ValueError (fourth trial), a masked array's hidden values were used (T16-9)
        limits = np.full(1, np.nan)  # refused below with the layout
    if (
        limits.shape != (SAFEGUARD_LAYOUT_LEN,)
        or np.isnan(limits).any()
        or not np.all(np.delete(limits, [10, SAFEGUARD_ARM]) > 0)
        or limits[10] not in (0.0, 1.0)
        or not (limits[SAFEGUARD_ARM] >= 0 and float(limits[SAFEGUARD_ARM]).is_integer())
    ):
        raise NeurohoverError(
            f"safeguard_limits must be {SAFEGUARD_LAYOUT_LEN} numbers in the layout of DangerousState.limits() (9 box limits, the tilt "
            f"threshold, the kind 0 or 1, the ratio threshold, 12 ratio limits, all > 0 but the kind; then the arming step, a whole "
            f"number >= 0), got {limits.tolist()}"
        )
    if limits[SAFEGUARD_ARM] >= n_steps and (fb >= 0).any():  # the safeguard never armed, without a word (T35-B03)
        raise NeurohoverError(
            f"safeguard arm_after={int(limits[SAFEGUARD_ARM])} is not below the episode's {n_steps} control steps (n_steps): "
            f"the safeguard would never test; give arm_after below {n_steps}"
        )
    rec = np.zeros(n_jobs, dtype=bool) if record is None else np.asarray(record)
    if rec.dtype != bool or isinstance(record, np.ma.MaskedArray):  # record='x' was read as True (second trial); a mask dropped (T16-9)
        raise NeurohoverError(f"record={record!r:.60} is not allowed: give one True/False flag per job ({n_jobs}), or one for every job")
    rec = np.full(n_jobs, bool(rec)) if rec.ndim == 0 else rec.reshape(-1)  # one bool flags every job, as evaluate's does (T50-B05)
    if rec.shape[0] != n_jobs:
        raise NeurohoverError(f"record must have one flag per job ({n_jobs}), got {rec.shape[0]}")
    n_rec = int(rec.sum())
    _check_call_size(n_jobs, n_steps, n_rec)
    slots = np.full(n_jobs, -1, dtype=np.int64)
    slots[rec] = np.arange(n_rec)
    obs_out = np.zeros((n_rec, n_steps + 1, 12))
    act_out = np.zeros((n_rec, n_steps, 4))
    batch = Batch(rows, table.kinds, table.genomes, p_idx, m_idx, e_idx, seed, n_steps, fb, limits, slots, obs_out, act_out)
    out = Flown.empty(n_jobs)
    with num_threads(threads):
        seconds = launch(batch, out, device)
    flight = None
    if n_rec:
        rec_steps = out.steps[rec]
        meta = {"episode_steps": int(n_steps), "crashed": [bool(c) for c in out.crashed[rec]]}  # a short episode is not a crash
        meta |= {"safeguard_step": out.safeguard_step[rec].tolist()} if (fb[rec] >= 0).any() else {}  # where a fallback took over (T42-B03)
        flight = FlightData(
            tuple(obs_out[i, : rec_steps[i] + 1].copy() for i in range(n_rec)), tuple(act_out[i, : rec_steps[i]].copy() for i in range(n_rec)), meta
        )
    return Evaluation(out.returns, out.crashed, out.steps, out.safeguard_step, flight, seconds)


def check_first_episode(first_episode) -> int:
    """The index of a batch's first episode (its gust streams are (seed, first_episode + k)) as an int in 0..2**62-1;
    text or True (taken as 1) refused by type, anything else by range: one check for every entry that takes it."""
    if not whole_number(first_episode):
        raise NeurohoverError(f"first_episode={brief(first_episode)} is not allowed: give an integer in 0..2**62-1")
    index = int(first_episode)
    if not 0 <= index < 2**62:
        raise NeurohoverError(f"first_episode={brief(index)} is out of range: allowed an integer in 0..2**62-1")
    return index


def evaluate(
    policies: Policy | Sequence[Policy] | PolicyTable,
    mdps: MDP | Sequence[MDP] | np.ndarray,
    *,
    episodes: int = 1,
    seed: int = 0,
    first_episode: int = 0,
    record: bool = False,
    safeguard: Safeguard | None = None,
    n_steps: int = EPISODE_STEPS,
    threads: int | None = None,
    device: str = "cpu",
) -> Evaluation:
    """Fly every policy on every MDP for ``episodes`` episodes; arrays are shaped (P, M, E).

    Episode e on MDP m has episode index ``first_episode + m * episodes + e`` for every policy,
    so all policies meet the same gusts. ``device="cuda"`` flies them on a GPU (:func:`evaluate_jobs`).
    With ``record=True`` the flight data's metadata hold each episode's MDP (``mdps``, as ``fly --record`` writes
    them; none for MDP rows given as an array, or for MDPs of a family registered at run time, which a process without
    it could not read back), so their crash flags are checked against their readings as fly's are.
    """
    table = policies if isinstance(policies, PolicyTable) else PolicyTable.from_policies(as_policies(policies))
    if len(table) == 0:  # an empty table returned an empty Evaluation, where [] is refused (T15-20)
        raise NeurohoverError("policies=PolicyTable of 0 policies is not allowed: give a non-empty sequence of Policy objects or a non-empty PolicyTable")
    rows = mdp_rows(mdps)
    # T24-11: whole_in, so 1.5 or True "is not allowed" (a type) and 0 "is out of range"; both once said out of range
    episodes = whole_in(episodes, "episodes", 1, MAX_EPISODES_PER_CALL, f"{MAX_EPISODES_PER_CALL:,} (policies x MDPs x episodes in one call)")
    if not isinstance(record, (bool, np.bool_)):
        raise NeurohoverError(f"record={record!r} is not allowed: give True or False")
    first_episode = check_first_episode(first_episode)  # ints from here on: NumPy's small ints overflowed (T31-B02)
    if safeguard is not None and not isinstance(safeguard, Safeguard):
        raise NeurohoverError(f"safeguard={safeguard!r:.60} is not allowed: give a neurohover.evaluate.Safeguard(fallback_policy) or None")
    n_pol, n_mdp = len(table), rows.shape[0]
    check_episode_count(n_pol * n_mdp * episodes, f"{n_pol} policies x {n_mdp} MDPs x episodes={episodes}")
    n_steps = _check_n_steps(n_steps)  # both before the job arrays are made (10**8 episodes of 10**7 steps took 50 s to refuse)
    _check_call_size(n_pol * n_mdp * episodes, n_steps, n_pol * n_mdp * episodes if record else 0)
    p_idx, m_idx, e = np.meshgrid(np.arange(n_pol), np.arange(n_mdp), np.arange(episodes), indexing="ij")
    episode_index = first_episode + m_idx * episodes + e
    fallback = limits = None
    if safeguard is not None:
        extra = PolicyTable.from_policies([safeguard.fallback])  # its kind from the checked policy (KIND['rnn'] was a KeyError; T41-B11)
        table = PolicyTable(np.append(table.kinds, extra.kinds), np.vstack([table.genomes, extra.genomes]))
        fallback = np.full(p_idx.size, n_pol, dtype=np.int64)
        limits = safeguard.dangerous.limits()
    ev = evaluate_jobs(
        table,
        rows,
        p_idx.ravel(),
        m_idx.ravel(),
        episode_index.ravel(),
        seed=seed,
        fallback_index=fallback,
        safeguard_limits=limits,
        record=np.full(p_idx.size, record),
        n_steps=n_steps,
        threads=threads,
        device=device,
    )
    if ev.flight_data is not None and not isinstance(mdps, np.ndarray):  # an edited crashed flag was taken without them (T59-B04)
        flown = [mdps] if isinstance(mdps, MDP) else list(mdps)
        if all(m.family in (*TASK_NAMES, LEARNED_MODEL) for m in flown):  # a run-time family's: unreadable where it is not registered
            ev.flight_data.metadata["mdps"] = [flown[m].to_dict() for m in m_idx.ravel()]  # one table per episode, in job order
    return ev.reshape((n_pol, n_mdp, episodes))
