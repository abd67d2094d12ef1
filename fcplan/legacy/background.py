"""The scenario of a 2020 GUI game, from its ``Background_Info.pkl``.

The scenario comes from ``Background_Info.pkl`` (``[environment_para, robo_team_para, set_loci,
adv_setting, ...]``, section 3): map size, duration, fire regions (uniform or per-region
settings), depot, facilities, lakes, team and per-agent parameters; ``Battery_Info.pkl`` gives the
capacities when present. The pruning gate is marked ``reference`` (the 2020 rule).

Every number must be finite; the map side must be an integer in 100..4000 px (the GUI used 800,
1000 and 1200), the duration in (0, 7200] s and each role's count in 0..50, so a hostile file
cannot make the importer allocate a huge map or episode; at most 1000 fire regions,
fronts per region, facilities of each kind and lakes. Any other layout problem is a
:class:`~fcplan.errors.LegacyError` naming ``Background_Info.pkl``.

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
        return [_num(v, "altitude") for v in item]
    if isinstance(item, (list, tuple, np.ndarray)):
        return item[min(i, len(item) - 1)] if len(seq) == 1 else item[0]
    return item


def _num(x: Any, where: str) -> float:
    try:
        v = float(np.asarray(x).reshape(-1)[0]) if np.ndim(x) else float(x)
    except (TypeError, ValueError, IndexError, OverflowError):
        raise LegacyError(f"Background_Info.pkl: {where} must be a number, got {x!r:.80}") from None
    if not np.isfinite(v):
        raise LegacyError(f"Background_Info.pkl: {where} must be a finite number, got {v}")
    return v


def _int_in(x: Any, where: str, lo: int, hi: int) -> int:
    v = _num(x, where)
    if v != int(v) or not lo <= v <= hi:
        raise LegacyError(f"Background_Info.pkl: {where} must be an integer in {lo}..{hi}, got {v}")
    return int(v)


#: Bounds of the GUI's settings that size the imported episode.
MAX_WORLD, MAX_DURATION_S, MAX_ROLE_COUNT, MAX_PLACES = 4000, 7200.0, 50, 1000


def scenario_dict_from_background(bg: Any, batteries: Any = None, name: str = "legacy") -> dict:
    """The fcplan scenario document for a ``Background_Info.pkl`` list (section 3 layout)."""
    try:
        return _scenario_dict(bg, batteries, name)
    except LegacyError:
        raise
    except (IndexError, TypeError, KeyError, ValueError, OverflowError, AttributeError) as exc:
        raise LegacyError(
            f"Background_Info.pkl: unexpected layout ({type(exc).__name__}: {exc})"
        ) from None


def _bounded(group: Any, what: str) -> Any:
    """A list of regions, facilities or lakes, refused beyond :data:`MAX_PLACES` entries."""
    if len(group) > MAX_PLACES:
        raise LegacyError(f"Background_Info.pkl: more than {MAX_PLACES} {what}")
    return group


def _regions(centres: Any, fs: Any, specific: bool) -> list[dict[str, Any]]:
    """The fire regions: one setting for all (uniform) or one per region (specific)."""

    def region_param(k: int, r: int) -> float:
        v = fs[k]
        return _num(v[r] if specific and isinstance(v, (list, tuple)) else v, f"fire setting {k}")

    def fronts(r: int) -> int:
        n = max(1, int(region_param(0, r)))
        if n > MAX_PLACES:
            raise LegacyError(f"Background_Info.pkl: more than {MAX_PLACES} fire fronts")
        return n

    return [
        {
            "center": [_num(c[0], "fire centre"), _num(c[1], "fire centre")],
            "fronts": fronts(r),
            "delay_s": region_param(1, r),
            "fuel": region_param(2, r),
            "wind_speed": region_param(3, r),
            "wind_dir_deg": region_param(4, r),
        }
        for r, c in enumerate(_bounded(centres, "fire regions"))
    ]


def _scenario_dict(bg: Any, batteries: Any, name: str) -> dict:
    try:
        env, team, loci, adv = bg[0], bg[1], bg[2], bg[3]
        world = _int_in(env[0], "W", 100, MAX_WORLD)
        duration = _num(env[1], "duration")
        n_p, n_a, n_h = (
            _int_in(team[k], f"robo_team_para[{k}]", 0, MAX_ROLE_COUNT) for k in range(3)
        )
        centres, fs, depot = loci[0], loci[1], loci[2]
        houses, hospitals, powers, lakes = loci[3], loci[4], loci[5], loci[6]
    except (IndexError, TypeError, KeyError) as exc:
        raise LegacyError(f"Background_Info.pkl: unexpected layout ({exc})") from None
    if not 0 < duration <= MAX_DURATION_S:
        raise LegacyError(
            f"Background_Info.pkl: duration must be in (0, {MAX_DURATION_S:g}] s, got {duration}"
        )
    specific = int(_num(fs[9], "fire setting mode")) == 1
    regions = _regions(centres, fs, specific)
    for what, group in (("lakes", lakes), ("houses", houses), ("hospitals", hospitals)):
        _bounded(group, what)
    facilities = [
        {"kind": kind, "center": [_num(c[0], kind), _num(c[1], kind)]}
        for kind, group in (("house", houses), ("hospital", hospitals), ("power_station", powers))
        for c in _bounded(group, kind)
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
        out["battery"] = [_num(b, "battery") for b in bats]
        out["speed"] = [_num(_per_agent(adv[speed_k], i), "speed") for i in idx]
        if tank_k is not None:
            out["tank"] = [int(_num(_per_agent(adv[tank_k], i), "tank")) for i in idx]
            out["prune_confidence"] = (conf or 0.0) / 100.0  # (conf is given with a tank)
        return out

    try:
        team_doc = {
            "perception": role(n_p, 0, 2, 5, None, 0, None),
            "action": role(n_a, None, 3, 6, 8, n_p, a_conf),
        }
        if n_h:
            team_doc["hybrid"] = role(n_h, 1, 4, 7, 9, n_p + n_a, h_conf)
    except LegacyError:
        raise
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
            "center": [_num(depot[0][0], "depot"), _num(depot[0][1], "depot")],
            "orientation": "vertical" if int(_num(depot[1], "depot orientation")) else "horizontal",
        },
        "facilities": facilities,
        "lakes": [{"center": [_num(c[0], "lake"), _num(c[1], "lake")]} for c in lakes],
        "team": team_doc,
    }
