"""A model of the SIMD lanes flying a run's selection races, to read where a race's time goes without
the machine's noise (docs/performance.md, Races on two threads).

It runs `evolve` (FGHH sigma 0.3 from the shipped race generic, race:0.5, as `neurohover bench`),
flies every sample slot of each of its races once more to learn each slot's length and fitness, and
replays the races through a model of the lanes: 8 lanes a thread taking jobs from one queue, a call
listing a round's required samples and then the undecided candidates' later ones (most contested
first), ending when the required ones are over and parking the rest. A thread's control step costs
A + B * (busy lanes) of a full 8-lane step (the packed substeps are shared, the policy, noise and
bookkeeping are per lane: docs/performance.md, One core today), or S per lane when at most 2 fly
with the queue empty (the scalar tail). Python between calls is a pause, measured from the run.
The model's ratio is used steps / (8 * threads) / the modelled time, against the raw kernel.

Run: python3 docs/performance/race_lanes_model.py [threads] [episodes]
"""

import sys
import time

import numpy as np

from neurohover.evaluate import PolicyTable, evaluate_jobs
from neurohover.evolution.evolve import evolve
from neurohover.evolution.fitness import episode_fitness
from neurohover.evolution.seeding import noise_seed
from neurohover.policysets import load_policy_set
from neurohover.tasks import get_task_family

A, B, S = 0.356, 0.0805, 0.264  # 8 lanes: 36 ns of packed substeps + 65 ns scalar per lane-step; scalar kernel 213 ns
LANES, SEED, EPISODE_STEPS = 8, 1, 6000


def races_of(trace: list, threads: int, fitness: str) -> list[dict]:
    """Each race's candidates' sample counts, and every slot's length and fitness (slot t * n + i)."""
    races = []
    for genomes, rows, _, used, episodes in trace:
        n = genomes.shape[0]
        t_limit = rows.shape[0] // n
        slots = np.arange(n * t_limit, dtype=np.int64)
        base = int(episodes[0] - used[0])
        ev = evaluate_jobs(PolicyTable.from_genomes(genomes, "mlp"), rows, slots % n, slots, base + slots, seed=noise_seed(SEED), threads=threads)
        races.append(
            {
                "n_samples": np.bincount(used % n, minlength=n),
                "steps": ev.steps.reshape(t_limit, n).astype(float),
                "fitness": episode_fitness(ev.returns, fitness).reshape(t_limit, n),
            }
        )
    return races


def contested_first(fit: np.ndarray, asked: np.ndarray, active: np.ndarray, mu: int) -> np.ndarray:
    mask = np.arange(fit.shape[0])[:, None] < asked[None, :]
    f = np.where(mask, fit, 0.0)
    count = np.maximum(asked, 1)
    with np.errstate(all="ignore"):
        means = f.sum(0) / count
        boundary = np.sort(means)[::-1][mu - 1 : mu + 1].mean()
        var = (np.where(mask, f - means, 0.0) ** 2).sum(0) / np.maximum(count - 1, 1)
        z = np.abs(means[active] - boundary) / np.sqrt(var[active] / count[active])
    return active[np.argsort(np.nan_to_num(z, nan=np.inf), kind="stable")]


def model(races: list[dict], threads: int, mu: int, oracle: bool = False) -> tuple[float, float, int]:
    """Modelled lane time (in full 8-lane steps), lane-steps flown and calls. A pause between calls (Python)
    parks every episode and changes nothing else, so it adds calls x pause to the time."""
    now, flown, calls = 0.0, 0.0, 0
    for race in races:
        ns, steps, fit = race["n_samples"], race["steps"], race["fitness"]
        t_limit, n = steps.shape
        progress, over = np.zeros((t_limit, n)), np.zeros((t_limit, n), dtype=bool)
        asked = np.zeros(n, dtype=np.int64)
        for r in range(2, int(ns.max()) + 1):  # rounds 1 and 2 fly in one call
            active = np.flatnonzero(ns >= r)
            asked[active] = r
            required = [(t, i) for t in ((0, 1) if r == 2 else (r - 1,)) for i in active if not over[t, i]]
            if not required:
                continue
            order = active if r == 2 else contested_first(fit, asked, active, mu)
            optional = [(t, i) for t in range(r, t_limit) for i in order if not over[t, i] and (not oracle or t < ns[i])]
            queue, left, taken = required + optional, len(required), 0
            lanes: list[list] = [[] for _ in range(threads)]
            calls += 1
            while left:
                for lane_set in lanes:  # idle lanes take the next jobs
                    while len(lane_set) < LANES and taken < len(queue):
                        t, i = queue[taken]
                        lane_set.append([t, i, steps[t, i] - progress[t, i], taken < len(required)])
                        taken += 1
                empty = taken >= len(queue)
                rates = [1.0 / (S * len(ls) if empty and len(ls) <= 2 else A + B * len(ls)) if ls else 0.0 for ls in lanes]
                dt = min(job[2] / rate for ls, rate in zip(lanes, rates) for job in ls)
                now += dt
                for k, ls in enumerate(lanes):
                    for job in ls:
                        done = dt * rates[k]
                        job[2] -= done
                        progress[job[0], job[1]] += done
                        flown += done
                    for job in [j for j in ls if j[2] <= 1e-9]:
                        over[job[0], job[1]] = True
                        left -= job[3]
                        ls.remove(job)
    return now, flown, calls


def main(threads: int, episodes: int) -> None:
    fghh, generic = get_task_family("fghh", 0.3), load_policy_set("fghh").generics["race"]
    evolve(fghh, topology="mlp", prototype=generic, budget=200, resampling="race:0.5", seed=0, n_steps=10, threads=threads)
    trace: list = []
    flown: dict = {}
    run = evolve(fghh, topology="mlp", prototype=generic, budget=episodes, resampling="race:0.5", seed=SEED, threads=threads, _trace=trace, _flown=flown)
    genomes = np.vstack([t[0] for t in trace])
    offsets = np.cumsum([0] + [len(t[0]) for t in trace])[:-1]
    row_offsets = np.cumsum([0] + [len(t[1]) for t in trace])[:-1]
    t0 = time.perf_counter()
    evaluate_jobs(
        PolicyTable.from_genomes(genomes, "mlp"), np.vstack([t[1] for t in trace]),
        np.concatenate([t[2] + o for t, o in zip(trace, offsets)]), np.concatenate([t[3] + o for t, o in zip(trace, row_offsets)]),
        np.concatenate([t[4] for t in trace]), seed=noise_seed(SEED), threads=threads,
    )  # fmt: skip
    raw = time.perf_counter() - t0
    races = races_of(trace, threads, run.settings["settings"]["fitness"])
    mu = run.settings["settings"]["select_size"]
    ideal = run.steps / (LANES * threads)
    unit = raw / ideal  # seconds of one full 8-lane step, from the raw kernel
    lane_time, lane_steps, calls = model(races, threads, mu)
    print(f"{threads} thread(s), {run.episodes} episodes, {len(races)} races, {calls} calls")
    python = run.seconds - run.kernel_seconds
    pause = python / calls / unit
    print(f"measured: ratio {raw / run.seconds:.3f}, flown / used steps {flown['steps'] / run.steps:.3f}, Python {python:.2f} s of {run.seconds:.2f} s")
    for name, oracle in (("model", False), ("model, oracle", True)):
        if oracle:
            lane_time, lane_steps, calls = model(races, threads, mu, oracle=True)
        for label, t in ((name, lane_time + calls * pause), (f"{name}, no Python", lane_time)):
            print(f"{label:26s} ratio {ideal / t:.3f}, flown / used steps {lane_steps / run.steps:.3f}")


if __name__ == "__main__":
    main(int(sys.argv[1]) if len(sys.argv) > 1 else 2, int(sys.argv[2]) if len(sys.argv) > 2 else 20000)
