"""The kernel's arguments as one named layout: what the scalar kernel, the SIMD lanes and the CUDA kernel take.

A kernel call flies jobs (a policy, an MDP row, an episode index) and writes one result per job:

- :class:`Jobs`: what every path reads (the MDP rows, the policies, each job's three indices, the
  root seed, the control steps per episode);
- :class:`Extras`: the safeguard and the flight-data recording, which only the scalar kernel and its
  CUDA build implement;
- :class:`Flown`: what every path writes per job;
- :class:`Parking`: the lanes' episodes kept between calls (:func:`neurohover.sim.lanes.rollout_lanes_parked`).

They are NamedTuples: numba compiles them as tuples whose fields the compiled code reads by name
(at no cost: a field is a struct member known at compile time) and a CUDA launch takes a tuple as
it takes its members, so each layout is written here once instead of as 18 positional arguments in
every signature and call. :class:`neurohover.launch.Batch` checks shapes and dtypes and builds them.
"""

from __future__ import annotations

from typing import NamedTuple

import numpy as np

from .constants import SENSOR_SCRATCH

__all__ = ["Extras", "Flown", "Jobs", "Parking", "PARK_F", "PARK_U"]

#: Floats kept per parked episode (:func:`neurohover.sim.lanes.park_lane`): state, observation, gust noise,
#: return so far, the sensor model's reading and scratch.
PARK_F = 13 + 12 + 6 + 1 + 12 + SENSOR_SCRATCH
PARK_U = 8  # unsigned words kept per parked episode: its gust stream's state and its sensor stream's


class Jobs(NamedTuple):
    """The jobs of one call: job j flies policy ``policy[j]`` on MDP row ``mdp[j]`` with episode ``episode[j]``'s gusts."""

    rows: np.ndarray  # (M, MDP_ROW_LEN) float64: the MDPs (dynamics, gust noise, wind, sensor model)
    kinds: np.ndarray  # (P,) int64: each policy's topology (kernel.POLICY_SLP or POLICY_MLP)
    genomes: np.ndarray  # (P, GENOME_WIDTH) float64: each policy's weights, padded to the MLP's length
    policy: np.ndarray  # (J,) int64: job j's policy
    mdp: np.ndarray  # (J,) int64: job j's MDP row
    episode: np.ndarray  # (J,) int64: job j's episode index, which with seed fixes its gust stream
    seed: np.uint64  # the root seed of every stream
    n_steps: int  # control steps per episode


class Extras(NamedTuple):
    """The safeguard and the recording of one call (scalar and CUDA kernels only)."""

    fallback: np.ndarray  # (J,) int64: the policy that takes over job j once it is dangerous (-1: none)
    safeguard: bool  # whether any job has a fallback
    limits: np.ndarray  # the safeguard's limits (sim.constants.SAFEGUARD_LIMITS)
    slots: np.ndarray  # (J,) int64: where job j's flight data go in obs_out / act_out (-1: not recorded)
    obs_out: np.ndarray  # (R, n_steps + 1, 12) float64: the observations the policy saw
    act_out: np.ndarray  # (R, n_steps, 4) float64: the actions applied

    @classmethod
    def none(cls, n_jobs: int, limits: np.ndarray) -> Extras:
        """No safeguard and no recording for ``n_jobs`` jobs."""
        minus = np.full(n_jobs, -1, dtype=np.int64)
        return cls(minus, False, limits, minus, np.zeros((0, 1, 12)), np.zeros((0, 1, 4)))


class Flown(NamedTuple):
    """What a call writes per job: return, crash flag, control steps flown, the step the safeguard fired (-1: never)."""

    returns: np.ndarray
    crashed: np.ndarray
    steps: np.ndarray
    safeguard_step: np.ndarray

    @classmethod
    def empty(cls, n_jobs: int) -> Flown:
        return cls(np.empty(n_jobs), np.empty(n_jobs, dtype=np.bool_), np.empty(n_jobs, dtype=np.int64), np.empty(n_jobs, dtype=np.int64))


class Parking(NamedTuple):
    """Episodes left in flight by a parking call, one slot each: what the lanes need to resume them.

    ``steps[s]`` is slot ``s``'s control steps flown (0: not begun); ``floats`` (``(S, PARK_F)``) and
    ``streams`` (``(S, PARK_U)`` uint64) hold its state, gust noise, return so far, sensor state and
    random streams (:func:`neurohover.sim.lanes.park_lane`). No slots: nothing is parked.
    """

    floats: np.ndarray
    streams: np.ndarray
    steps: np.ndarray

    @classmethod
    def empty(cls, n_slots: int) -> Parking:
        return cls(np.zeros((n_slots, PARK_F)), np.zeros((n_slots, PARK_U), dtype=np.uint64), np.zeros(n_slots, dtype=np.int64))

    def clear(self) -> None:
        """Forget every parked episode (a slot then starts from its first step)."""
        self.steps[:] = 0
