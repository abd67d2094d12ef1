"""The scenario of a 2020 GUI game, from its ``Background_Info.pkl``.

The scenario comes from ``Background_Info.pkl`` (``[environment_para, robo_team_para, set_loci,
adv_setting, ...]``, section 3): map size, duration, fire regions (uniform or per-region
settings), depot, facilities, lakes, team and per-agent parameters; ``Battery_Info.pkl`` gives the
capacities when present. The pruning gate is marked ``reference`` (the 2020 rule).

Examples
--------
>>> bg = [[800, 60], [1, 1, 0], [[(450, 150)], [3, 0, 10, 5, 45, 1.25, 0.1, 90, 80, 0],
...       [(100, 200), 1], [(600, 500)], [], [], []], [[[10, 100]], [[10, 100]], [[500]], [[500]],
...       [[500]], [[20]], [[20]], [[20]], [[10]], [[10]]]]
>>> doc = scenario_dict_from_background(bg)
>>> doc["world_size"], doc["fire"]["regions"][0]["fronts"], doc["team"]["action"]["tank"]
(800, 3, [10])
"""

from __future__ import annotations

from typing import Any

import numpy as np

from fcplan.errors import LegacyError

__all__ = ["scenario_dict_from_background"]


def _per_agent(entries: Any, i: int, pair: bool = False) -> Any:
    """Agent ``i``'s value of an adv_setting entry: ``[[v]]`` (one for all) or ``[[v1], [v2]]``
    (per agent); altitude entries hold ``[lo, hi]`` pairs instead of ``[v]``."""
    seq = list(entries) if isinstance(entries, (list, tuple, np.ndarray)) else [entries]
    if not seq:
        raise ValueError("empty adv_setting entry")
    item = seq[min(i, len(seq) - 1)]
    if pair:
        return [float(v) for v in item]
    if isinstance(item, (list, tuple, np.ndarray)):
        return item[min(i, len(item) - 1)] if len(seq) == 1 else item[0]
    return item


def _num(x: Any, where: str) -> float:
    try:
        v = float(np.asarray(x).reshape(-1)[0]) if np.ndim(x) else float(x)
    except (TypeError, ValueError, IndexError):
        raise LegacyError(f"Background_Info.pkl: {where} must be a number, got {x!r}") from None
    return v


def scenario_dict_from_background(bg: Any, batteries: Any = None, name: str = "legacy") -> dict:
    """The fcplan scenario document for a ``Background_Info.pkl`` list (section 3 layout)."""
    try:
        env, team, loci, adv = bg[0], bg[1], bg[2], bg[3]
        world, duration = int(_num(env[0], "W")), _num(env[1], "duration")
        n_p, n_a, n_h = (int(_num(team[k], f"robo_team_para[{k}]")) for k in range(3))
        centres, fs, depot = loci[0], loci[1], loci[2]
        houses, hospitals, powers, lakes = loci[3], loci[4], loci[5], loci[6]
    except (IndexError, TypeError, KeyError) as exc:
        raise LegacyError(f"Background_Info.pkl: unexpected layout ({exc})") from None
    specific = int(_num(fs[9], "fire setting mode")) == 1

    def region_param(k: int, r: int) -> float:
        v = fs[k]
        return _num(v[r] if specific and isinstance(v, (list, tuple)) else v, f"fire setting {k}")

    regions = [
        {
            "center": [float(c[0]), float(c[1])],
            "fronts": max(1, int(region_param(0, r))),
            "delay_s": region_param(1, r),
            "fuel": region_param(2, r),
            "wind_speed": region_param(3, r),
            "wind_dir_deg": region_param(4, r),
        }
        for r, c in enumerate(centres)
    ]
    facilities = [
        {"kind": kind, "center": [float(c[0]), float(c[1])]}
        for kind, group in (("house", houses), ("hospital", hospitals), ("power_station", powers))
        for c in group
    ]
    a_conf, h_conf = _num(fs[7], "action confidence"), _num(fs[8], "hybrid confidence")

    def role(
        count: int,
        alt_k: int | None,
        batt_k: int,
        speed_k: int,
        tank_k: int | None,
        offset: int,
        conf: float | None,
    ) -> dict[str, Any]:
        out: dict[str, Any] = {"count": count}
        idx = range(count)
        if alt_k is not None:
            out["altitude"] = [_per_agent(adv[alt_k], i, pair=True) for i in idx]
        bats = [_per_agent(adv[batt_k], i) for i in idx]
        if batteries is not None:
            bats = [batteries[offset + i][0] for i in idx]
        out["battery"] = [float(b) for b in bats]
        out["speed"] = [float(_per_agent(adv[speed_k], i)) for i in idx]
        if tank_k is not None:
            out["tank"] = [int(_per_agent(adv[tank_k], i)) for i in idx]
            out["prune_confidence"] = (conf or 0.0) / 100.0  # (conf is given with a tank)
        return out

    try:
        team_doc = {
            "perception": role(n_p, 0, 2, 5, None, 0, None),
            "action": role(n_a, None, 3, 6, 8, n_p, a_conf),
        }
        if n_h:
            team_doc["hybrid"] = role(n_h, 1, 4, 7, 9, n_p + n_a, h_conf)
    except (IndexError, TypeError, ValueError) as exc:
        raise LegacyError(
            f"Background_Info.pkl: adv_setting has an unexpected layout ({exc})"
        ) from None
    return {
        "name": name,
        "difficulty": "custom",
        "world_size": world,
        "duration_s": duration,
        "notes": ["Imported from a FireCommander 2020 GUI recording (fcplan import-legacy)."],
        "fire": {
            "mode": "specific" if specific else "uniform",
            "action_gate": "reference",
            "regions": regions,
        },
        "scoring": {
            "propagation_weight": _num(fs[6], "propagation weight"),
            "temporal_exponent": _num(fs[5], "temporal exponent"),
        },
        "depot": {
            "center": [float(depot[0][0]), float(depot[0][1])],
            "orientation": "vertical" if int(_num(depot[1], "depot orientation")) else "horizontal",
        },
        "facilities": facilities,
        "lakes": [{"center": [float(c[0]), float(c[1])]} for c in lakes],
        "team": team_doc,
    }
