"""Did a code change move the scores? Two results folders of ``fcplan sweep``, paired episode by episode.

Each scheduler's episodes in ``OLD`` and ``NEW`` are paired by (scenario, seed); per scheduler the
script prints the paired difference ``new - old`` of a metric with its 95 % Student-t interval,
the wins, ties and losses of the new episodes and the two-sided Wilcoxon signed-rank p. Episodes
present in only one folder, or failed in either, are left out (their count is printed). Typical use, after a change
that alters a scheduler's behaviour and a re-run of the affected episodes::

    git archive <old commit> bench/results/bench-v2 | tar -x -C /tmp/old
    python bench/compare_results.py /tmp/old/bench/results/bench-v2 bench/results/bench-v2 \\
        --schedulers greedy routing cbba oracle --scenarios hard-03 hard-04

The folders are read by :func:`fcplan.experiments.results.load_results` (the leaderboard's
reader: damaged or foreign files are refused by name).
"""

from __future__ import annotations

import argparse
from pathlib import Path

import numpy as np

from fcplan.experiments.results import load_results
from fcplan.experiments.stats import paired_mean_ci, wilcoxon_p


def _episodes(folder: Path, metric: str) -> dict[tuple[str, str, int], float]:
    """(scheduler, scenario, seed) -> metric of every finished episode in ``folder``."""
    df = load_results(folder)
    if "status" in df.columns and len(df):
        df = df[df["status"] != "failed"]
    return {
        (str(sched), str(scen), int(seed)): float(v)
        for sched, scen, seed, v in zip(
            df.get("scheduler", []), df.get("scenario", []), df.get("seed", []),
            df.get(metric, []), strict=True,
        )
    }  # fmt: skip


def main(argv: list[str] | None = None) -> None:
    ap = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    ap.add_argument("old", type=Path)
    ap.add_argument("new", type=Path)
    ap.add_argument("--metric", default="manual.final_score")
    ap.add_argument("--schedulers", nargs="*", help="labels (default: every one in both)")
    ap.add_argument("--scenarios", nargs="*", help="names or their last part (default: all)")
    args = ap.parse_args(argv)
    old, new = _episodes(args.old, args.metric), _episodes(args.new, args.metric)
    labels = args.schedulers or sorted({k[0] for k in old} & {k[0] for k in new})

    def wanted(key: tuple[str, str, int]) -> bool:
        return not args.scenarios or any(
            key[1] == s or key[1].endswith("/" + s) for s in args.scenarios
        )

    print(f"# {args.metric}: new - old, paired by (scenario, seed); {args.old} -> {args.new}")
    print(f"{'scheduler':16s} {'n':>4s}  {'new - old [95% CI]':26s} W/T/L      p       unpaired")
    for label in labels:
        keys = sorted(k for k in old.keys() & new.keys() if k[0] == label and wanted(k))
        alone = sum(1 for k in old.keys() ^ new.keys() if k[0] == label and wanted(k))
        if not keys:
            print(f"{label:16s} {0:4d}  (no episode in both folders){'':8s} {alone}")
            continue
        a = np.array([new[k] for k in keys])
        b = np.array([old[k] for k in keys])
        ci, d = paired_mean_ci(a, b), a - b
        wtl = f"{int((d > 0).sum())}/{int((d == 0).sum())}/{int((d < 0).sum())}"
        p = wilcoxon_p(d) if np.any(d != 0) else 1.0
        print(
            f"{label:16s} {len(keys):4d}  {ci.mean:+8.2f} [{ci.low:+8.2f}, {ci.high:+8.2f}]"
            f"  {wtl:10s} {p:<7.2g} {alone}"
        )


if __name__ == "__main__":
    main()
