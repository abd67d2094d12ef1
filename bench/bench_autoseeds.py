"""The ``--seeds auto`` stopping rule on simulated paired studies: false stops and cost.

Each simulated study compares two schedulers whose paired differences are ``N(d, 1)`` (``d`` is
Cohen's ``d_z``; ``d = 0``: no true difference), ``batch`` pairs per look up to ``max`` pairs, as
``fcplan compare --seeds auto`` does with one scenario. Two rules are run on the same draws:

* ``corrected``: fcplan's rule (:class:`fcplan.experiments.autoseeds.AutoSeeds`): the interval at
  level ``1 - 0.05 / looks`` excludes 0 and the Holm-adjusted Wilcoxon p is below ``0.05 / looks``;
* ``naive``: stop at the first look whose 95 % paired interval excludes 0.

For each ``d`` the table gives the share of studies stopped as resolved before the cap (for
``d = 0`` every such stop is false), the share resolved the wrong way round, and the median
number of pairs at the stop (capped studies count at the cap). Deterministic (seeded draws), so
the figures do not depend on the machine; the CPU time is printed for reference.

Usage::

    python bench/bench_autoseeds.py [--trials 1000] [--batch 5] [--max 50]
"""

from __future__ import annotations

import argparse
import os
import time

import numpy as np
from scipy import stats

from fcplan.experiments.autoseeds import AutoSeeds
from fcplan.experiments.stats import paired_comparisons


def _corrected(d: np.ndarray, plan: AutoSeeds) -> tuple[bool, int, float]:
    """(resolved before the cap, pairs at the stop, sign of the mean at the stop)."""
    for look in range(1, plan.looks + 1):
        n = len(plan.seeds(look))
        pairs = paired_comparisons(
            {"a": d[:n], "b": np.zeros(n)}, plan.look_confidence, alpha=plan.look_alpha
        )
        decision = plan.decide(pairs, look)
        if decision.stop:
            return not decision.unresolved, n, float(np.sign(d[:n].mean()))
    raise AssertionError("the plan always stops at the cap")


def _naive(d: np.ndarray, plan: AutoSeeds) -> tuple[bool, int, float]:
    for look in range(1, plan.looks + 1):
        n = len(plan.seeds(look))
        x = d[:n]
        half = stats.t.ppf(0.975, n - 1) * x.std(ddof=1) / np.sqrt(n)
        if abs(x.mean()) > half:
            return True, n, float(np.sign(x.mean()))
    return False, plan.max_seeds, 0.0


def main() -> None:
    ap = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    ap.add_argument("--trials", type=int, default=1000)
    ap.add_argument("--batch", type=int, default=5)
    ap.add_argument("--max", type=int, default=50)
    args = ap.parse_args()
    plan = AutoSeeds(batch=args.batch, max_seeds=args.max)
    print(f"load average before: {os.getloadavg()}")
    print(
        f"{args.trials} simulated studies per row; {args.batch} pairs per look, cap {args.max} "
        f"({plan.looks} looks; corrected level {100 * plan.look_confidence:.2f}%)"
    )
    head = f"{'d_z':>5}  {'rule':<9} {'resolved':>8} {'wrong sign':>10} {'median pairs':>12}"
    print(head)
    t0 = time.process_time()
    for k, effect in enumerate((0.0, 0.2, 0.5, 1.0)):
        draws = np.random.default_rng(100 + k).normal(effect, 1.0, (args.trials, args.max))
        for name, rule in (("corrected", _corrected), ("naive", _naive)):
            out = [rule(d, plan) for d in draws]
            resolved = np.array([r for r, _, _ in out])
            pairs = np.array([n for _, n, _ in out])
            wrong = np.array([r and s < 0 for r, _, s in out]) if effect > 0 else resolved
            print(
                f"{effect:5.1f}  {name:<9} {resolved.mean():8.3f} {wrong.mean():10.3f} "
                f"{np.median(pairs):12.0f}"
            )
    print(f"CPU time {time.process_time() - t0:.1f} s; load average after: {os.getloadavg()}")


if __name__ == "__main__":
    main()
