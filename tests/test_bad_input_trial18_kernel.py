"""Eighteenth bad-input trial: what reaches the kernel (T18-1)."""

from __future__ import annotations

import numpy as np
import pytest

from neurohover.evaluate import PolicyTable
from neurohover.launch import Batch
from neurohover.policies import baseline_policy
from neurohover.tasks import get_task_family


@pytest.mark.parametrize("n_steps", [np.uint16(5), np.int8(5), np.int32(5), 5])
def test_a_batch_hands_the_kernel_its_steps_as_an_int(n_steps) -> None:
    """T18-1: evaluate(n_steps=np.uint16(5)) was right but compiled the kernel again for that type (30-50 s each)."""
    table = PolicyTable.from_policies([baseline_policy()])
    rows = get_task_family("ghh08").zero().row()[None, :]
    one = np.zeros(1, dtype=np.int64)
    batch = Batch(rows, table.kinds, table.genomes, one, one, one, 3, n_steps)
    assert type(batch.n_steps) is int and batch.n_steps == 5
    assert type(batch.jobs().n_steps) is int
