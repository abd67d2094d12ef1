"""The scenario memory estimate against the measured peak memory of real episodes (issue 17).

Each configuration (scenario #12 resized: world size, duration, team, fronts) plays one greedy
episode in a fresh process; the table gives :func:`fcplan.scenario.bounds.estimate_bytes` and the
process's peak resident memory (``ru_maxrss``), so the estimate can be seen to stay above it.

Usage::

    PYTHONPATH=$PWD nice python bench/bench_memory_estimate.py
"""

from __future__ import annotations

import json
import os
import subprocess
import sys

CONFIGS = [  # world px, duration s, perception, action, fronts of region 0
    (1200, 180, 3, 2, 3),
    (1200, 600, 250, 250, 3),
    (1200, 1200, 500, 500, 3),
    (4000, 60, 12, 12, 30),
    (6000, 30, 150, 150, 10),
    (9600, 5, 3, 2, 10),
    (1200, 20, 3, 2, 50_000),
]

_CHILD = """
import json, resource, sys
from fcplan import run_episode
from fcplan.scenario import load_scenario
from fcplan.scenario.bounds import estimate_bytes
from fcplan.scenario.read import scenario_from_dict
w, d, p, a, f = json.loads(sys.argv[1])
doc = load_scenario(12).to_dict()
doc.update(world_size=w, duration_s=float(d))
doc["team"]["perception"]["count"], doc["team"]["action"]["count"] = p, a
doc["fire"]["regions"][0]["fronts"] = f
s = scenario_from_dict(doc)
run_episode(s, "greedy", seed=0)
peak = resource.getrusage(resource.RUSAGE_SELF).ru_maxrss * 1024
print(json.dumps([estimate_bytes(s), peak]))
"""


def main() -> None:
    env = {**os.environ, "PYTHONPATH": os.getcwd()}
    print(f"{'world':>6} {'dur s':>6} {'agents':>6} {'fronts':>7} {'estimate MiB':>13} "
          f"{'peak MiB':>9} {'peak/est':>8}")  # fmt: skip
    for cfg in CONFIGS:
        out = subprocess.run(
            [sys.executable, "-c", _CHILD, json.dumps(cfg)],
            capture_output=True,
            text=True,
            env=env,
            check=True,
        )
        est, peak = json.loads(out.stdout.strip().splitlines()[-1])
        w, d, p, a, f = cfg
        print(f"{w:>6} {d:>6} {p + a:>6} {f:>7} {est / 2**20:>13.0f} {peak / 2**20:>9.0f} "
              f"{peak / est:>8.2f}")  # fmt: skip


if __name__ == "__main__":
    main()
