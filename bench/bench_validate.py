"""Scenario validation time against team size (issue 17: it must be linear in the agents).

Builds scenario #12 with ``n`` agents (half perception, half action, per-agent batteries so that
field paths are per agent) and times ``Scenario.from_dict`` (physical validity and bounds) and
``manual_limit_violations`` (the GUI-limit report), best of three.

Usage::

    PYTHONPATH=$PWD python bench/bench_validate.py [--sizes 250,1002,5000,10000]
"""

from __future__ import annotations

import argparse
import time

from fcplan.scenario import load_scenario
from fcplan.scenario.model import Scenario


def _doc(n: int) -> dict:
    doc = load_scenario(12).to_dict()
    doc["team"]["perception"]["count"] = n // 2
    doc["team"]["action"]["count"] = n - n // 2
    doc["team"]["perception"]["battery"] = [500.0 + i for i in range(n // 2)]
    return doc


def _best(fn, repeat: int = 3) -> float:
    times = []
    for _ in range(repeat):
        t0 = time.perf_counter()
        fn()
        times.append(time.perf_counter() - t0)
    return min(times)


def main() -> None:
    ap = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    ap.add_argument("--sizes", default="250,1002,5000,10000")
    sizes = [int(x) for x in ap.parse_args().sizes.split(",")]
    print(f"{'agents':>7} {'validate s':>11} {'limits s':>9} {'us/agent':>9}")
    for n in sizes:
        doc = _doc(n)
        build = _best(lambda doc=doc: Scenario.from_dict(doc))
        s = Scenario.from_dict(doc)
        limits = _best(s.manual_limit_violations)
        print(f"{n:>7} {build:>11.3f} {limits:>9.3f} {1e6 * (build + limits) / n:>9.0f}")


if __name__ == "__main__":
    main()
