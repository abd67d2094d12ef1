"""Design the benchmark suite's tiers by measurement (issue 12), and freeze them.

A *design file* (``bench/suite_v1.toml``) names the suite and, per tier, the generator preset,
the knobs changed from it and the generator seeds of the tier's scenarios. Three steps:

``screen``
    Plays candidate scenarios (generator seeds ``--candidates``) with screening episode seeds
    (``--seeds``, kept apart from the seeds the tier is measured on) and rejects the degenerate
    ones, by a rule that looks at no scheduler's rank: *saturated* (every policy played ends
    every screening episode with OFS 100 %) or *futile* (even the oracle keeps the negative
    reward ratio at 95 % or more on every seed: nothing can be done). A tier may set
    ``contained_ofs`` (or ``--contained-ofs``): then a scenario is also rejected as *contained*
    when every policy played puts out, on average over the screening seeds, at least that share
    of the fire (OFS %): a team that keeps up with the fire leaves little for an algorithm to
    decide, and the v1 hard tier showed such scenarios to be where the built-in schedulers tie.
    By default the screen plays greedy, its one policy (the cheapest; a scenario greedy clears is
    one a benchmark does not need), and the oracle and idle, references that enter only the
    futile rule. It prints the first ``--keep`` seeds that pass, to copy into the design file.
``freeze``
    Writes the design file's tiers into ``fcplan/data/suites/<suite>/`` (the TOML files and
    ``manifest.json``, :func:`fcplan.scenario.suite.write_suite`).
``measure``
    Plays a tier (the frozen suite's ``--tier``, or a design tier's ``--candidates``) with the
    schedulers over ``--seeds`` and prints the leaderboard's tier section: per scheduler the
    headline metric's mean and interval, the fraction of the oracle, scenarios cleared, solve
    times and fallbacks, the paired Holm-corrected comparisons and the tier check (the issue's
    rule and acceptance). ``--json``/``--csv`` also write the numbers and the per-scenario means.

Episodes run through :func:`fcplan.experiments.sweep` into ``--results`` (one Parquet file per
episode), so an interrupted run resumes where it stopped and the same folder feeds ``fcplan
leaderboard``. Schedulers run in their deterministic modes, so the scores do not depend on the
machine's load; the load average is printed beside every timing.

Usage::

    python bench/design_suite.py screen bench/suite_v1.toml --tier hard --candidates 0-15 \\
        --seeds 100-101 --results bench/results/screen-hard --jobs 2
    python bench/design_suite.py freeze bench/suite_v1.toml
    python bench/design_suite.py measure --tier hard --sweep bench/suite_v1_hard.toml \\
        --results bench/results/bench-v1 --jobs 2 --json bench/results/hard.json

(``--sweep bench/suite_v1_hard.toml`` plays the leaderboard's own sweep: the same episodes as
``fcplan sweep bench/suite_v1_hard.toml``, stored under the same keys.)
"""

from __future__ import annotations

import argparse
import csv
import json
import os
import sys
import time
import tomllib
from pathlib import Path
from typing import Any

import numpy as np

from fcplan.experiments import load_sweep_config, sweep
from fcplan.experiments.leaderboard import finite, is_policy, leaderboard
from fcplan.experiments.leaderboard_page import markdown
from fcplan.experiments.ranges import parse_range
from fcplan.scenario import GeneratorConfig, Scenario, load_scenario
from fcplan.scenario.suite import freeze_entry, load_suite, write_suite

SCHEDULERS = "greedy,routing,milp,cbba,oracle,idle"
SUITES = Path(__file__).resolve().parents[1] / "fcplan" / "data" / "suites"


def load_design(path: str) -> dict[str, Any]:
    """The design file: ``suite``, ``description`` and ``tiers`` (name -> preset, overrides,
    seeds)."""
    doc = tomllib.loads(Path(path).read_text(encoding="utf-8"))
    tiers = {t["name"]: t for t in doc["tiers"]}
    return {"suite": doc["suite"], "description": doc.get("description", ""), "tiers": tiers}


def _knobs(tier: dict[str, Any]) -> dict[str, Any]:
    return {k: tuple(v) if isinstance(v, list) else v for k, v in tier.get("overrides", {}).items()}


def candidates(tier: dict[str, Any], seeds: list[int]) -> list[Scenario]:
    """The tier's generated scenarios for generator ``seeds`` (named ``gen-<seed>-<hash>``)."""
    cfg = GeneratorConfig.preset(tier["preset"], **_knobs(tier))
    return [cfg(s) for s in seeds]


def play(scenarios: list[Any], args: argparse.Namespace) -> list[dict[str, Any]]:
    """Every (scenario, scheduler, seed) episode, stored in (and resumed from) ``args.results``:
    the sweep file ``args.sweep`` if given, else ``scenarios`` x ``args.schedulers`` x
    ``args.seeds``."""
    config: Any = {
        "scenarios": scenarios,
        "schedulers": args.schedulers.split(","),
        "seeds": args.seeds,
    }
    if getattr(args, "sweep", None):
        config = load_sweep_config(args.sweep)
        scenarios, args.seeds = list(config.scenarios), list(config.seeds)
    load0 = os.getloadavg()[0]
    t0 = time.perf_counter()
    summary = sweep(config, args.results, jobs=args.jobs, progress=not args.quiet)
    wall = time.perf_counter() - t0
    print(
        f"# {summary.total} episodes ({summary.skipped} stored before, {summary.ran} now, "
        f"{summary.failed} failed, {len(summary.lost)} lost) in {wall:.0f} s with {args.jobs} "
        f"workers; load average {load0:.1f} at the start, {os.getloadavg()[0]:.1f} at the end",
        flush=True,
    )
    names = {s.name if isinstance(s, Scenario) else load_scenario(s).name for s in scenarios}
    rows = summary.load().to_dict("records")
    return [r for r in rows if r["scenario"] in names and r["seed"] in set(args.seeds)]


def per_scenario(rows: list[dict[str, Any]]) -> dict[str, dict[str, dict[str, float]]]:
    """scenario -> scheduler -> mean final score, mean OFS, min OFS and max NRR."""
    out: dict[str, dict[str, dict[str, float]]] = {}
    for sc in sorted({r["scenario"] for r in rows}):
        for name in dict.fromkeys(r["scheduler"] for r in rows):
            rs = [r for r in rows if r["scenario"] == sc and r["scheduler"] == name]
            rs = [r for r in rs if r["status"] == "ok"]
            if rs:
                out.setdefault(sc, {})[name] = {
                    "final": float(np.mean([r["manual.final_score"] for r in rs])),
                    "ofs": float(np.mean([r["manual.overall_firefighting"] for r in rs])),
                    "ofs_min": float(min(r["manual.overall_firefighting"] for r in rs)),
                    "nrr_min": float(min(r["manual.negative_reward_ratio"] for r in rs)),
                }
    return out


def verdict(by: dict[str, dict[str, float]], contained_ofs: float | None = None) -> str:
    """``keep``, ``saturated``, ``contained`` (when ``contained_ofs`` is given) or ``futile``
    (module docstring) for one scenario's means."""
    policies = [k for k in by if is_policy(k)]
    if policies and all(by[k]["ofs_min"] >= 100.0 for k in policies):
        return "saturated"
    if (
        contained_ofs is not None
        and policies
        and all(by[k]["ofs"] >= contained_ofs for k in policies)
    ):
        return "contained"
    best = by.get("oracle", {}).get("nrr_min", 0.0)
    if best >= 95.0 and all(by[k]["nrr_min"] >= 95.0 for k in policies):
        return "futile"
    return "keep"


def print_scenarios(
    table: dict[str, dict[str, dict[str, float]]],
    seeds: dict[str, int],
    contained_ofs: float | None = None,
) -> None:
    """Per scenario: each scheduler's mean final score (mean OFS %) and the verdict."""
    names = list(dict.fromkeys(k for v in table.values() for k in v))
    print(f"\n{'scenario':<34} {'seed':>5} " + " ".join(f"{n:>15}" for n in names) + "  verdict")
    for sc, by in table.items():
        cells = " ".join(
            f"{by[n]['final']:7.1f} ({by[n]['ofs']:3.0f}%)" if n in by else f"{'-':>15}"
            for n in names
        )
        print(f"{sc:<34} {seeds.get(sc, -1):>5} {cells}  {verdict(by, contained_ofs)}")


def cmd_screen(args: argparse.Namespace) -> None:
    design = load_design(args.design)
    tier = design["tiers"][args.tier]
    scenarios = candidates(tier, args.candidates)
    seed_of = {s.name: c for s, c in zip(scenarios, args.candidates, strict=True)}
    table = per_scenario(play(scenarios, args))
    contained = args.contained_ofs if args.contained_ofs is not None else tier.get("contained_ofs")
    if contained is not None:
        print(f"# contained: every policy played at mean OFS >= {contained:g} %")
    print_scenarios(table, seed_of, contained)
    kept = [seed_of[sc] for sc, by in table.items() if verdict(by, contained) == "keep"]
    kept = sorted(kept)[: args.keep]
    print(f"\nkept (first {args.keep} in seed order): seeds = {kept}")
    if args.json:
        doc = {"tier": args.tier, "candidates": args.candidates, "seeds": args.seeds,
               "contained_ofs": contained, "scenarios": table, "kept": kept}  # fmt: skip
        Path(args.json).write_text(json.dumps(doc, indent=1) + "\n", encoding="utf-8")


def cmd_freeze(args: argparse.Namespace) -> None:
    design = load_design(args.design)
    entries = []
    for name, tier in design["tiers"].items():
        for k, seed in enumerate(tier["seeds"], 1):
            entries.append(
                freeze_entry(
                    design["suite"], f"{name}-{k:02d}", name, seed, tier["preset"], **_knobs(tier)
                )
            )
    path = write_suite(SUITES / design["suite"], entries, design["description"].strip())
    print(f"wrote {len(entries)} scenarios and {path}")


def write_csv(path: str, board: Any, table: dict[str, dict[str, dict[str, float]]]) -> None:
    with open(path, "w", newline="", encoding="utf-8") as fh:
        w = csv.writer(fh)
        w.writerow(["kind", "scenario", "scheduler", "mean", "ci", "fraction", "ofs", "cleared"])
        for t in board.tiers:
            for k in t.order:
                s = t.stats[k]
                w.writerow(["tier", f"{t.suite}/{t.tier}", k, s.mean.mean, s.mean.half_width,
                            s.fraction, s.ofs, s.cleared])  # fmt: skip
        for sc, by in table.items():
            for k, v in by.items():
                w.writerow(["scenario", sc, k, v["final"], "", "", v["ofs"], ""])
        for t in board.tiers:
            for c in t.pairs:
                w.writerow(["pair", f"{t.suite}/{t.tier}", f"{c.a} - {c.b}", c.diff.mean,
                            c.diff.half_width, c.p_holm, c.effect, ""])  # fmt: skip


def cmd_measure(args: argparse.Namespace) -> None:
    if args.tier_of_design:
        design = load_design(args.design)
        scenarios: list[Any] = candidates(design["tiers"][args.tier], args.candidates)
    else:
        scenarios = load_suite().names(args.tier)
    rows = play(scenarios, args)
    board = leaderboard(rows)
    print()
    print(markdown(board, "bench/design_suite.py measure"))
    table = per_scenario(rows)
    print_scenarios(table, {})
    for t in board.tiers:
        c = t.check
        fr = {k: round(s.fraction, 3) for k, s in t.stats.items() if finite(s.fraction)}
        print(f"\n{t.suite}/{t.tier}: keep {c.keep}, accepted {c.accepted}; fractions {fr}")
    if args.json:
        doc = {"board": board.to_dict(), "scenarios": table}
        Path(args.json).write_text(json.dumps(doc, indent=1) + "\n", encoding="utf-8")
    if args.csv:
        write_csv(args.csv, board, table)


def main(argv: list[str] | None = None) -> None:
    ap = argparse.ArgumentParser(description=(__doc__ or "").splitlines()[0])
    sub = ap.add_subparsers(dest="command", required=True)
    common = argparse.ArgumentParser(add_help=False)
    common.add_argument("--seeds", type=parse_range, default="0-9", help="episode seeds")
    common.add_argument("--schedulers", default=SCHEDULERS)
    common.add_argument("--results", required=True, help="results folder (resumable)")
    common.add_argument("--jobs", type=int, default=1)
    common.add_argument("--json", help="also write the numbers as JSON")
    common.add_argument("--quiet", action="store_true", help="no progress lines")
    s = sub.add_parser("screen", parents=[common], help="reject degenerate candidates")
    s.set_defaults(schedulers="greedy,oracle,idle")
    s.add_argument("design")
    s.add_argument("--tier", required=True)
    s.add_argument("--candidates", type=parse_range, required=True, help="generator seeds")
    s.add_argument("--keep", type=int, default=12)
    s.add_argument("--contained-ofs", type=float, default=None,
                   help="also reject scenarios every policy clears to this mean OFS %% "
                        "(default: the tier's contained_ofs, else no such rule)")  # fmt: skip
    f = sub.add_parser("freeze", help="write the design's tiers into the package data")
    f.add_argument("design")
    m = sub.add_parser("measure", parents=[common], help="play a tier and check it")
    m.add_argument("--tier", required=True, help="a tier of the frozen suite (or of --design)")
    m.add_argument("--design", help="measure the design's candidates instead of the frozen tier")
    m.add_argument("--candidates", type=parse_range, default=None, help="generator seeds")
    m.add_argument("--csv", help="also write the tables as CSV")
    m.add_argument("--sweep", help="play this sweep file (its scenarios, schedulers and seeds)")
    args = ap.parse_args(argv)
    if args.command == "measure":
        args.tier_of_design = args.design is not None
        if args.tier_of_design and args.candidates is None:
            ap.error("--design needs --candidates")
    {"screen": cmd_screen, "freeze": cmd_freeze, "measure": cmd_measure}[args.command](args)
    sys.stdout.flush()


if __name__ == "__main__":
    main()
