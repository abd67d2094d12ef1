"""Behaviour cloning on the task-level environment: imitate milp, then beat the random scheduler.

1. Roll ``milp`` out through ``fcplan.env`` and save its demonstrations (npz, no pickle).
2. Fit a small numpy policy (conditional logit over the candidate tasks, ``fcplan.env.bc``).
3. Play it on held-out seeds next to the ``random`` scheduler, uniformly random legal actions
   and the ``milp`` teacher itself, all through the same environment.

Usage::

    python examples/behaviour_cloning.py              # #24, 4 training seeds, 5 held-out seeds
    python examples/behaviour_cloning.py --quick      # 60-step episodes, 2 + 4 seeds (~20 s)
    python examples/behaviour_cloning.py --dagger 3   # also DAgger with milp as the expert
"""

from __future__ import annotations

import argparse
import tempfile
import time
from pathlib import Path

import numpy as np

from fcplan.env import demonstrations, load_demonstrations
from fcplan.env.bc import dagger, evaluate, fit_bc, random_policy, scheduler_scores


def main() -> None:
    ap = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    ap.add_argument("--scenario", default="24", help="scenario name or number (default 24)")
    ap.add_argument("--quick", action="store_true", help="short episodes and fewer seeds")
    ap.add_argument(
        "--dagger", type=int, default=0, metavar="ROUNDS", help="DAgger rounds (0: off)"
    )
    ap.add_argument("--out", type=Path, default=None, help="where to save the demonstrations")
    args = ap.parse_args()
    scenario = int(args.scenario) if args.scenario.isdigit() else args.scenario
    env_kwargs = {"k": 8, "max_steps": 60 if args.quick else None}
    train = [0, 1] if args.quick else [0, 1, 2, 3]
    held = [10, 11, 12, 13] if args.quick else [10, 11, 12, 13, 14]
    out = args.out or Path(tempfile.mkdtemp()) / "milp_demos.npz"

    t0 = time.perf_counter()
    demonstrations("milp", [scenario], train, out, env_kwargs=env_kwargs)
    demo = load_demonstrations(out)  # allow_pickle=False inside
    print(
        f"{len(demo)} agent-steps from {demo.n_episodes} milp episodes -> {out} "
        f"({time.perf_counter() - t0:.1f} s); mapping {demo.metadata['mapping']}"
    )

    policy = fit_bc(demo)
    agree = (policy(demo.agent_obs, demo.task_obs, demo.mask) == demo.action).mean()
    print(f"fitted in-sample agreement with milp: {agree:.1%}")

    rows = {
        "behaviour cloning": evaluate(policy, scenario, held, env_kwargs=env_kwargs),
        "random scheduler": scheduler_scores("random", scenario, held, env_kwargs=env_kwargs),
        "random legal actions": evaluate(
            random_policy(np.random.default_rng(0)), scenario, held, env_kwargs=env_kwargs
        ),
        "milp (teacher)": scheduler_scores("milp", scenario, held, env_kwargs=env_kwargs),
    }
    if args.dagger:
        better = dagger("milp", [scenario], train, rounds=args.dagger, env_kwargs=env_kwargs)
        rows[f"DAgger ({args.dagger} rounds)"] = evaluate(
            better, scenario, held, env_kwargs=env_kwargs
        )
    print(f"manual final score on held-out seeds {held} (scenario {scenario}):")
    for name, s in rows.items():
        print(f"  {name:22s} mean {s.mean():7.1f}   per seed {np.round(s, 1).tolist()}")


if __name__ == "__main__":
    main()
