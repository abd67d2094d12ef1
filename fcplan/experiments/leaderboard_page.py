"""The leaderboard page: :class:`~fcplan.experiments.leaderboard.Leaderboard` as Markdown.

:func:`markdown` writes ``docs/leaderboard.md`` (``fcplan leaderboard RESULTS -o FILE``): a header
with the suite version, the headline metric, the date, the command, how many episodes, the wall
time of producing them and the library versions; one section per tier with a table of every
scheduler (ranked policies, then the oracle reference and the baselines), the paired comparisons
of the policies and the tier check; and a short guide to the numbers. The numbers are those of
:mod:`fcplan.experiments.leaderboard`.

Examples
--------
>>> from fcplan.experiments.leaderboard import leaderboard
>>> rows = [{"scenario": "fcplan-bench-v1/hard-01", "scheduler": name, "seed": seed,
...          "status": "ok", "manual.final_score": score + seed}
...         for seed in range(3) for name, score in (("greedy", 1.0), ("cbba", 2.0))]
>>> page = markdown(leaderboard(rows), "fcplan leaderboard results")
>>> page.splitlines()[0], "| 1 | cbba | 3.0 ± 2.5 |" in page
('# Leaderboard', True)
"""

from __future__ import annotations

import datetime as _dt
import math

from fcplan.experiments.leaderboard import (
    HOLM_LEVEL,
    IDLE,
    ORACLE,
    Leaderboard,
    SchedulerStats,
    TierResult,
    finite,
    is_policy,
    metric_direction,
)
from fcplan.scenario.suite import load_suite, suite_versions

__all__ = ["markdown"]


# ---------------------------------------------------------------------------------------- page
_NOTES = {
    ORACLE: "reference: sees the true fire, not a legal policy",
    IDLE: "baseline: does nothing",
    "random": "baseline: random plans",
}


def _span(seeds: list[int]) -> str:
    """``0-9`` for a contiguous run, else the list."""
    if seeds and seeds == list(range(seeds[0], seeds[-1] + 1)) and len(seeds) > 2:
        return f"{seeds[0]}-{seeds[-1]}"
    return ",".join(map(str, seeds))


def _count(n: int, noun: str) -> str:
    return f"{n} {noun}" + ("" if n == 1 else "s")


def _num(v: float, digits: int) -> str:
    return "n/a" if not finite(v) else f"{v:,.{digits}f}"


def _duration(seconds: float) -> str:
    if not finite(seconds):
        return "unknown"
    h, rest = divmod(int(round(seconds)), 3600)
    return f"{h} h {rest // 60:02d} min" if h else f"{rest // 60} min {rest % 60:02d} s"


def _gap(s: SchedulerStats) -> str:
    """``p50 / p95 %`` of the proven gaps and on how many replans; ``-`` without a bound."""
    if not s.bounded_replans:
        return "-"
    pct = [f"{100 * v:.2f}" if finite(v) else "n/a" for v in (s.gap_p50, s.gap_p95)]
    share = f" ({s.bounded_replans}/{s.replans})" if s.bounded_replans != s.replans else ""
    return f"{pct[0]} / {pct[1]}{share}"


def _row(rank: str, name: str, s: SchedulerStats, t: TierResult, digits: int) -> str:
    lo, hi = s.fraction_ci
    frac = "n/a" if not finite(s.fraction) else f"{s.fraction:.3f}"
    if finite(lo):
        frac += f" [{lo:.3f}, {hi:.3f}]"
    note = _NOTES.get(name, _NOTES[ORACLE] if name.startswith(ORACLE) else "")
    label = f"{name} ({note})" if note else name
    failed = f" ({s.failed} failed)" if s.failed else ""
    if s.instances < t.instances:
        failed += f" (partial: {s.instances} of {t.instances} pairs)"
    cells = [
        rank,
        label + failed,
        f"{s.mean.mean:.{digits}f} ± {_num(s.mean.half_width, digits)}",
        frac,
        _num(s.ofs, 1),
        f"{s.cleared}/{len(t.scenarios)}",
        _num(s.containment_s, 1),
        _num(s.burned, 0),
        f"{_num(s.solve_p50_ms, 1)} / {_num(s.solve_p95_ms, 1)}",
        _gap(s),
        f"{s.fallbacks}/{s.replans}",
    ]
    return "| " + " | ".join(cells) + " |"


def _tier_section(t: TierResult, label: str, digits: int) -> list[str]:
    name = f"{t.suite}/{t.tier}" if t.suite else "other scenarios"
    size = len(load_suite(t.suite).tiers().get(t.tier, [])) if t.suite in suite_versions() else 0
    out = [
        f"## Tier `{name}`: {_count(len(t.scenarios), 'scenario')} x "
        f"{_count(len(t.seeds), 'seed')} ({_span(t.seeds)})",
        "",
    ]
    if size > len(t.scenarios):
        out += [f"Only {len(t.scenarios)} of the tier's {size} scenarios have episodes so far.", ""]
    out += [
        f"| # | scheduler | {label} (mean ± 95 % CI) | fraction of oracle [95 % CI] | OFS % "
        "| cleared | containment s | burned cells | solve p50 / p95 ms | gap p50 / p95 % "
        "| fallbacks / replans |",
        "|---|---|---|---|---|---|---|---|---|---|---|",
    ]
    rank = 0
    for k in t.order:
        if not is_policy(k):  # an oracle variant still being played is not in the reference
            r = ("ref" if k in t.reference else "-") if k.startswith(ORACLE) else "base"
        elif t.stats[k].instances < t.instances:
            r = "-"  # partial: not ranked
        else:
            rank += 1
            r = str(rank)
        out.append(_row(r, k, t.stats[k], t, digits))
    if t.settings:
        text = "; ".join(f"{k}: {v}" for k, v in t.settings.items())
        out += ["", f"Scheduler settings: {text}."]
    if t.pairs:
        out += [
            "",
            f"Paired differences of the {label} between policies, each pair on the (scenario, "
            f"seed) instances both completed (Wilcoxon signed-rank p, Holm-adjusted over the "
            f"{len(t.pairs)} pairs; d_z = mean / sd of the differences):",
            "",
            "| a - b | n | mean ± 95 % CI | p | p Holm | d_z | Holm p < 0.01 | verdict |",
            "|---|---|---|---|---|---|---|---|",
        ]
        out += [
            f"| {c.a} - {c.b} | {c.n} | {c.diff.format(digits)} | {c.p:.2g} | {c.p_holm:.2g} "
            f"| {c.effect:+.2f} | {'yes' if c.p_holm < HOLM_LEVEL else 'no'} | {c.verdict()} |"
            for c in t.pairs
        ]
    out += _scenario_table(t, label, digits)
    c = t.check
    top = {None: "no oracle episodes", True: "yes", False: "**no**"}[c.oracle_top]
    verdict = "Accepted" if c.accepted else "Kept" if c.keep else "Not kept"
    if c.incomplete:
        short = ", ".join(f"{k} {t.stats[k].instances} of {t.instances}" for k in c.incomplete)
        verdict = f"Provisional: not every policy has played every pair yet ({short})"

    out += [
        "",
        "Tier check (issue 12): policies "
        + (
            "separated (not all within each other's 95 % intervals)"
            if c.separated
            else "**not separated** (every mean inside every other's 95 % interval)"
        )
        + "; OFS 100 % on every scenario: "
        + f"{', '.join(c.cleared_all) or 'none'}; pairs with Holm p < 0.01: {c.resolved} of "
        f"{c.pairs}; reference (best oracle) mean at least every policy's: {top}. "
        f"**{verdict}.**",
        "",
    ]
    return out


def _scenario_table(t: TierResult, label: str, digits: int) -> list[str]:
    """Per scenario, each scheduler's mean and OFS, the policies' spread and whether every
    policy cleared it (OFS 100 % on every seed): where the tier tells schedulers apart."""
    if not t.per_scenario:
        return []
    cols = t.order
    out = [
        "",
        f"Per scenario: mean {label} (mean OFS %) over the seeds each scheduler completed; "
        "*spread*: best minus worst policy mean; *cleared by all*: every policy at OFS 100 % "
        "on every seed (the scenario does not tell them apart on OFS).",
        "",
        "| scenario | " + " | ".join(cols) + " | spread | cleared by all |",
        "|---|" + "---|" * (len(cols) + 2),
    ]
    for sc, means in t.per_scenario.items():
        cells = [
            f"{_num(means[k][0], digits)} ({_num(means[k][1], 0)})" if k in means else "-"
            for k in cols
        ]
        pol = [means[k] for k in cols if is_policy(k) and k in means]
        spread = max(m[0] for m in pol) - min(m[0] for m in pol) if pol else math.nan
        cleared = bool(pol) and all(m[1] >= 100.0 for m in pol)
        short = sc.rpartition("/")[2]
        out.append(
            f"| {short} | " + " | ".join(cells)
            + f" | {_num(spread, digits)} | {'yes' if cleared else 'no'} |"
        )  # fmt: skip
    return out


def _missing_tiers(board: Leaderboard) -> list[str]:
    """``suite/tier (n scenarios)`` for every tier of the board's suites that it has no row of."""
    have = {(t.suite, t.tier) for t in board.tiers}
    out = []
    for version in board.meta.get("suites", []):
        if version not in suite_versions():
            continue
        for tier, entries in load_suite(version).tiers().items():
            if (version, tier) not in have:
                out.append(f"`{version}/{tier}` ({_count(len(entries), 'scenario')})")
    return out


def markdown(board: Leaderboard, command: str = "") -> str:
    """The leaderboard page (``docs/leaderboard.md``); ``command`` is how it was made."""
    m = board.meta
    label, digits, higher = metric_direction(board.metric)
    direction = "higher" if higher else "lower"
    libs = "; ".join(", ".join(f"{k} {v}" for k, v in sorted(d.items())) for d in m["libraries"])
    modes = {s.deterministic for t in board.tiers for s in t.stats.values()}
    made = _dt.date.today().isoformat()
    out = [
        "# Leaderboard",
        "",
        f"<!-- generated by `{command or 'fcplan leaderboard'}`; do not edit by hand -->",
        "",
        f"Suite **{', '.join(m['suites']) or 'none'}**; headline metric **{label}** "
        f"(`{board.metric}`, {direction} is better). Made on {made}"
        + (f" with `{command}`" if command else "")
        + f" from {m['episodes']} episodes ({m['failed']} failed)"
        + (f", the last finished {m['finished']}" if m["finished"] else "")
        + (f" on {', '.join(m['hosts'])}" if m["hosts"] else "")
        + f". Producing the results took {_duration(m['wall_time_s'])} of wall-clock time "
        f"(while any of these episodes ran; {_duration(m['episode_time_s'])} of episode time).",
        "",
        "Schedulers ran in their deterministic modes where they have one, so their scores do not "
        "depend on machine load; solve times do."
        if False not in modes
        else "Some schedulers ran with wall-clock time limits: their scores depend on load.",
        "",
        f"Libraries: {libs or 'not recorded'}.",
        "",
        "Code (episodes per commit of fcplan): "
        + ", ".join(f"{k} ({_count(n, 'episode')})" for k, n in m.get("code", {}).items())
        + ". Results that span commits hold only if no change in between altered a scheduler's "
        "behaviour: `fcplan verify RESULTS` plays a sample of the stored episodes again and names "
        "the schedulers whose results today's code no longer reproduces.",
        "",
    ]
    missing = _missing_tiers(board)
    if missing:
        out += [f"Tiers of these suites with no episodes in the results: {', '.join(missing)}.", ""]
    for t in board.tiers:
        out += _tier_section(t, label, digits)
    out += [
        "## How to read this page",
        "",
        "* **fraction of oracle**: `sum (s - idle) / sum (oracle - idle)` over the (scenario, "
        "seed) pairs where the scheduler, the clairvoyant reference and the `idle` team all "
        "completed: the share of the oracle's improvement over doing nothing. The reference "
        "on a pair is the best of the oracle variants run on it (each `ref` row; a variant "
        "joins once it has played every pair of the most complete one). A ratio of means, "
        "so that pairs where little was at stake do not dominate; 95 % interval by a bootstrap "
        "of seeds within each scenario. Above 1: better than the oracle on these pairs (the "
        "oracle is a reference, not a bound).",
        "* **mean ± 95 % CI**: Student t over every episode of the tier (it includes the spread "
        "between scenarios); the paired table is the comparison to quote. A *partial* row "
        "(rank `-`) has not played every (scenario, seed) pair of the tier yet: its mean is over "
        "other instances than the ranked rows' and is not comparable with them.",
        "* **cleared**: scenarios where every seed ended with OFS 100 %. **fallbacks**: replans "
        "where the scheduler failed or ran out of time and greedy planned instead.",
        "* **solve p50 / p95**: milliseconds per scheduler call over every replan of the tier, "
        "measured on the machine above (they vary with its load).",
        "* **gap p50 / p95**: the relative optimality gap `(bound - objective) / |objective|` "
        "that the scheduler proved on its own model, over the replans where it proved a bound "
        "(0: solved to optimality; in brackets when that is not every replan); `-`: a scheduler "
        "that proves no bound. A gap is about the scheduler's model of a replan, not about the "
        "episode's score: the oracle's fraction is the reference for that.",
        "",
    ]
    return "\n".join(out)
