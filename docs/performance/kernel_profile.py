"""Where one core's time goes in the benchmark workload (docs/performance.md).

Flies 100 full episodes of the baseline-equivalent MLP in the zero setting with the kernel's own
functions, then the same with one part left out or cut down (the policy, the gust noise, nine of
the ten substeps), and prints episodes/s of each; the differences give each part's share.
Run: python3 docs/performance/kernel_profile.py
"""

import time

import numba as nb
import numpy as np

from neurohover.evaluate import PolicyTable
from neurohover.policies import baseline_policy, prototype
from neurohover.sim import kernel as K
from neurohover.sim.rng import next_normal, seed_stream
from neurohover.tasks import get_task_family


@nb.njit(fastmath={"contract"})
def run(row, kind, g, n_eps, n_steps, use_noise, use_policy, n_sub_override):
    tot = 0.0
    for j in range(n_eps):
        ra = np.empty(4, dtype=np.uint64)
        seed_stream(ra, np.uint64(1), np.uint64(j))
        dyn, std, n_sub, dt, wind = K.unpack_mdp(row)
        if n_sub_override > 0:
            n_sub = n_sub_override
        s = (0.0, 0.0, 0.0, 0.0, 0.0, 0.0, 0.0, 0.0, 0.0, 0.0, 0.0, 0.0, 1.0)
        n = (0.0, 0.0, 0.0, 0.0, 0.0, 0.0)
        o = K.observe(s)
        for k in range(n_steps):
            if use_policy:
                a1, a2, a3, a4 = K.policy_action(kind, g, o[0], o[1], o[2], o[3], o[4], o[5], o[9], o[10], o[11])
            else:
                a1, a2, a3, a4 = 0.02 - 0.0196 * o[4], -0.0185 * o[3], 0.0, 0.23 + 0.0513 * o[5]
            a1 = K.clip_action(a1)
            a2 = K.clip_action(a2)
            a3 = K.clip_action(a3)
            a4 = K.clip_action(a4)
            if use_noise:
                n = K.update_noise(n, std, next_normal(ra), next_normal(ra), next_normal(ra), next_normal(ra), next_normal(ra), next_normal(ra))
            s = K.integrate(s, n, a1, a2, a3, a4, k, dyn, n_sub, dt, wind)
            o = K.observe(s)
            tot += K.reward_of(o)
    return tot


row = get_task_family("fghh").zero().row()
t = PolicyTable.from_policies([prototype("mlp", "baseline"), baseline_policy()])
cases = {
    "full MLP": (0, True, True, 0),
    "full SLP": (1, True, True, 0),
    "no policy": (0, True, False, 0),
    "no noise": (0, False, True, 0),
    "1 substep": (0, True, True, 1),
}
for pi, noise, pol, ns in cases.values():
    run(row, int(t.kinds[pi]), t.genomes[pi], 1, 10, noise, pol, ns)
res = {k: [] for k in cases}
for _ in range(4):
    for name, (pi, noise, pol, ns) in cases.items():
        t0 = time.perf_counter()
        run(row, int(t.kinds[pi]), t.genomes[pi], 100, 6000, noise, pol, ns)
        res[name].append(100 / (time.perf_counter() - t0))
for k, v in res.items():
    if v:
        print(f"{k:12s} {max(v):7.0f} eps/s  (ms/ep {1000 / max(v):.3f})")
