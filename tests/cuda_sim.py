"""Run a script under numba's CUDA simulator and read the JSON object it prints last.

NUMBA_ENABLE_CUDASIM=1 must be set before numba is imported, so the GPU side of the CUDA tests
runs in a fresh process.
"""

from __future__ import annotations

import json
import os
import subprocess
import sys


def run_simulated(script: str, *args: str) -> dict:
    """Run ``script`` with ``args`` under the simulator; its last line of output, parsed as JSON."""
    env = {**os.environ, "NUMBA_ENABLE_CUDASIM": "1"}
    proc = subprocess.run([sys.executable, "-c", script, *args], env=env, capture_output=True, text=True, timeout=600)
    assert proc.returncode == 0, proc.stderr[-3000:]
    return json.loads(proc.stdout.strip().splitlines()[-1])
