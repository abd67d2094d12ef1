"""Convert a folder of the 2020 GUI's files into an fcplan recording: :func:`import_legacy`.

* **Clock.** The GUI ran unthrottled frames against the wall clock (section 8); every event is put
  on fcplan's 10-Hz tick grid by its time: an event at ``ms`` lands in trace row
  ``ceil(ms / 100) - 1`` (the first row whose time is at or after it). Per-frame lists without a
  time (sensed maps) take the frame's time from ``Agent_Base_Loci.pkl`` (``floor(ms / 100)``).
* **Fire.** ``Fire_States.pkl`` rows ``[x, y, I, ms]``: a cell ignites at its first row.
  ``Pruned_Fire_Map.pkl`` entries ``[[x, y, I] rows, [ax, ay, ms]]``: a burning cell is pruned at
  its first such entry (later re-ignitions, a 2020 quirk, are dropped). ``Sensed_Fire_Map.pkl``:
  a cell counts as sensed at the first frame it is seen while burning (the GUI also "sensed" old
  trail and pruned cells). Counts, facility hits and the per-tick trace are derived from these
  events with fcplan's definitions, so both metric definitions apply.
* **Agents** from ``Agent_States.pkl`` (16 values per agent per frame; bit 7 is the time in ms):
  the latest state at or before each tick, ordered by time, which also absorbs the extra 16-tuples
  the GUI appended on agent-switch keys. Battery = capacity - 0.1 distance - 0.05 hover frames;
  move flag 1/0/2 -> active (idle when parked at its slot)/returning/homing; dumps counted from
  the prune entries.
* **Inputs** from ``User_Data.pkl`` (``[x, y, floor(ms / 100), action_type, goal_index]`` per agent):
  kept as the recording's input events. They cannot drive a re-simulation (no seed, and the GUI's
  physics differ), so a legacy recording has ``seed = None`` and no commands.

Examples
--------
>>> _row_of_ms(np.array([0.0, 100.0, 101.0, 250.0]), 1800).tolist()  # 10 ticks per second
[0, 0, 1, 2]
"""

from __future__ import annotations

import os
from collections.abc import Iterator
from contextlib import contextmanager
from typing import TYPE_CHECKING, Any

import numpy as np

from fcplan.errors import FcplanError, LegacyError
from fcplan.legacy.background import scenario_dict_from_background
from fcplan.legacy.limits import LegacyLimits
from fcplan.legacy.unpickle import restricted_load

if TYPE_CHECKING:
    from fcplan.recording import Recording
    from fcplan.scenario import Scenario
    from fcplan.world import World

__all__ = ["LEGACY_FILES", "TICKS_PER_SECOND", "import_legacy"]

#: The 13 files the 2020 GUI wrote per game.
LEGACY_FILES = (
    "Background_Info.pkl",
    "Battery_Info.pkl",
    "User_Data.pkl",
    "Target_Loci.pkl",
    "Agent_Base_Loci.pkl",
    "Lake_info.pkl",
    "Fire_States.pkl",
    "Fire_Map.pkl",
    "Sensing_Data_CoM.pkl",
    "Sensed_Fire_Map.pkl",
    "Pruned_Fire_Map.pkl",
    "target_onFire_List.pkl",
    "Agent_States.pkl",
)
_REQUIRED = ("Background_Info.pkl", "Agent_States.pkl", "Fire_States.pkl")
#: fcplan's tick rate for imported games.
TICKS_PER_SECOND = 10


def _row_of_ms(ms: np.ndarray | float, n_ticks: int) -> np.ndarray:
    """Trace row of an event at ``ms``: the first row whose time (``(k + 1) / 10`` s) is at or
    after it, clipped to the episode. A non-finite time is a ``ValueError``."""
    ms = np.asarray(ms, dtype=np.float64)
    if not np.isfinite(ms).all():
        raise ValueError("a time in ms is not a finite number")
    row = np.ceil(ms / (1000 / TICKS_PER_SECOND)) - 1
    return np.clip(row, 0, n_ticks - 1).astype(np.int64)


@contextmanager
def _about(path: str) -> Iterator[None]:
    """Any failure while converting the content of ``path`` is a LegacyError naming it (with its
    folder)."""
    try:
        yield
    except LegacyError as exc:
        base, msg = os.path.basename(path), str(exc)
        if msg.startswith(f"{base}:"):
            raise LegacyError(f"{path}{msg[len(base) :]}") from None
        raise
    except (
        TypeError,
        ValueError,
        KeyError,
        IndexError,
        AttributeError,
        OverflowError,
        ZeroDivisionError,
        MemoryError,
    ) as exc:
        raise LegacyError(
            f"{path}: unexpected content ({type(exc).__name__}: {str(exc)[:200]})"
        ) from None


def _rows(x: Any, width: int, where: str) -> np.ndarray:
    """A list of rows (or an array) as an (n, width) float array; [] gives (0, width)."""
    if x is None or (isinstance(x, (list, tuple)) and len(x) == 0):
        return np.zeros((0, width))
    try:
        a = np.asarray(x, dtype=np.float64)
    except (TypeError, ValueError):
        raise LegacyError(f"{where}: expected rows of {width} numbers") from None
    if a.size == 0:
        return np.zeros((0, width))
    if a.ndim == 1:
        a = a.reshape(1, -1)
    if a.ndim != 2 or a.shape[1] < width:
        raise LegacyError(f"{where}: expected rows of {width} numbers, got shape {a.shape}")
    return a[:, :width]


def _first_events(cells: np.ndarray, rows: np.ndarray) -> tuple[np.ndarray, np.ndarray]:
    """Earliest row per distinct cell."""
    if cells.size == 0:
        return cells.astype(np.int64), rows.astype(np.int64)
    order = np.lexsort((rows, cells))
    cells, rows = cells[order], rows[order]
    first = np.ones(cells.size, dtype=bool)
    first[1:] = cells[1:] != cells[:-1]
    return cells[first], rows[first]


def import_legacy(folder: str | os.PathLike[str], limits: LegacyLimits | None = None) -> Recording:
    """Convert a folder of the 2020 GUI's ``.pkl`` files into a :class:`fcplan.recording.Recording`.

    Every file present is read with the restricted unpickler within ``limits`` (so a malicious
    file is refused even if its content is not needed). ``Background_Info.pkl``,
    ``Agent_States.pkl`` and ``Fire_States.pkl`` are required.

    Raises
    ------
    LegacyError
        Unsafe, missing or malformed files (the message names the file).
    """
    folder = os.fspath(folder)
    present, data = _read_folder(folder, limits)
    name = os.path.basename(os.path.normpath(folder)) or "legacy"

    def at(file: str) -> str:
        return os.path.join(folder, file)

    with _about(at("Background_Info.pkl")):
        sc = _scenario(data, folder, name)
        world = _world(sc)  # for the facility footprints only
    t_n = sc.n_ticks
    with _about(at("Agent_Base_Loci.pkl")):
        clock = _frame_clock(data)
    with _about(at("Fire_States.pkl")):
        ign_c, ign_r, ign_row = _ignitions(data["Fire_States.pkl"], sc.world_size, t_n)
    with _about(at("Pruned_Fire_Map.pkl")):
        dump_rows, pru_c, pru_r, prune_row = _prunes(data, sc, ign_row)
    with _about(at("Sensed_Fire_Map.pkl")):
        sen_c, sen_r = _sensings(data, sc, clock, ign_row, prune_row)
    with _about(folder):
        arrays = _count_arrays(t_n, (ign_c, ign_r), (sen_c, sen_r), (pru_c, pru_r), prune_row)
        arrays.update(_facility_arrays(world, t_n, (ign_c, ign_r), (pru_c, pru_r)))
    with _about(at("Agent_States.pkl")):
        arrays.update(_agent_arrays(data["Agent_States.pkl"], sc, world, dump_rows))
    with _about(at("User_Data.pkl")):
        inputs, input_ticks = _inputs(data.get("User_Data.pkl", []), sc, t_n)
    return _recording(sc, arrays, inputs, input_ticks, name, present, clock)


def _world(sc: Scenario) -> World:
    from fcplan.world import World

    return World().reset(sc, 0)


def _recording(
    sc: Scenario,
    arrays: dict[str, np.ndarray],
    inputs: list[dict[str, Any]],
    input_ticks: list[int],
    name: str,
    present: list[str],
    clock: np.ndarray | None,
) -> Recording:
    """The recording of the converted arrays (no commands or replans: the GUI has none)."""
    from fcplan.recording import Recording
    from fcplan.recording.reader import check_recording
    from fcplan.recording.schema import FORMAT, FORMAT_VERSION, cast_entries, versions

    t_n = sc.n_ticks
    arrays.update(
        command_tick=np.zeros(0),
        command_agent=np.zeros(0),
        command_flags=np.zeros(0),
        command_altitude=np.zeros(0),
        command_route_len=np.zeros(0),
        command_route_xy=np.zeros((0, 2)),
        replan_tick=np.zeros(0),
        replan_wall_s=np.zeros(0),
    )
    arrays["input_tick"] = np.asarray(input_ticks, dtype=np.int64)
    header = {
        "format": FORMAT,
        "format_version": FORMAT_VERSION,
        "scenario": sc.to_dict(),
        "seed": None,
        "source": "legacy",
        "settings": {
            "legacy_folder": name,
            "files": present,
            "frames": None if clock is None else int(len(clock)),
        },
        "ticks": t_n,
        "versions": versions(),
    }
    rec = Recording(header, cast_entries(arrays), [], inputs)
    try:
        check_recording(rec, f"{name} (converted)")  # what load_recording would refuse
    except FcplanError as exc:
        raise LegacyError(str(exc)) from None
    return rec


def _read_folder(folder: str, limits: LegacyLimits | None) -> tuple[list[str], dict[str, Any]]:
    """The legacy files present in ``folder`` and their contents (restricted unpickler)."""
    if not os.path.isdir(folder):
        raise LegacyError(f"{folder}: not a folder")
    present = [f for f in LEGACY_FILES if os.path.lexists(os.path.join(folder, f))]
    missing = [f for f in _REQUIRED if f not in present]
    if missing:
        raise LegacyError(
            f"{folder}: missing {', '.join(missing)} (not a FireCommander recording?)"
        )
    return present, {f: restricted_load(os.path.join(folder, f), limits) for f in present}


def _scenario(data: dict[str, Any], folder: str, name: str) -> Scenario:
    """The scenario of ``Background_Info.pkl`` (and ``Battery_Info.pkl`` when present)."""
    from fcplan.scenario import Scenario

    doc = scenario_dict_from_background(
        data["Background_Info.pkl"], data.get("Battery_Info.pkl"), name=f"legacy {name}"
    )
    try:
        return Scenario.from_dict(doc, source=os.path.join(folder, "Background_Info.pkl"))
    except FcplanError as exc:
        raise LegacyError(str(exc)) from None


def _frame_clock(data: dict[str, Any]) -> np.ndarray | None:
    """Milliseconds of each GUI frame, from the depot's per-frame entries (None without
    ``Agent_Base_Loci.pkl``)."""
    if "Agent_Base_Loci.pkl" not in data:
        return None
    base = data["Agent_Base_Loci.pkl"]
    try:
        return _rows(base[0], 7, "Agent_Base_Loci.pkl")[:, 6] * 100.0
    except (IndexError, TypeError):
        raise LegacyError("Agent_Base_Loci.pkl: expected per depot a list of frames") from None


def _cells(x: np.ndarray, y: np.ndarray, w: int) -> tuple[np.ndarray, np.ndarray]:
    """Flat cells ``x * w + y`` of the points inside the map, and the mask of those points
    (NaN and infinite coordinates are outside)."""
    ok = (x >= 0) & (x < w) & (y >= 0) & (y < w)
    xi, yi = np.floor(x[ok]).astype(np.int64), np.floor(y[ok]).astype(np.int64)
    return xi * w + yi, ok


def _ignitions(fire_states: Any, w: int, t_n: int) -> tuple[np.ndarray, np.ndarray, np.ndarray]:
    """First ignition row per cell: (cells, rows) and the per-cell row map (int64 max: never)."""
    ig_cells, ig_rows = [], []
    for r, region in enumerate(fire_states):
        a = _rows(region, 4, f"Fire_States.pkl region {r}")
        cells, ok = _cells(a[:, 0], a[:, 1], w)
        ig_cells.append(cells)
        ig_rows.append(_row_of_ms(a[ok, 3], t_n))
    ign_c, ign_r = _first_events(np.concatenate(ig_cells), np.concatenate(ig_rows))
    ign_row = np.full(w * w, np.iinfo(np.int64).max, dtype=np.int64)
    ign_row[ign_c] = ign_r
    return ign_c, ign_r, ign_row


def _prunes(
    data: dict[str, Any], sc: Scenario, ign_row: np.ndarray
) -> tuple[list[list[int]], np.ndarray, np.ndarray, np.ndarray]:
    """Dump rows per agent, first prune row per cell burning by then (cells, rows), and the
    per-cell prune row map."""
    w, t_n = sc.world_size, sc.n_ticks
    actors = [i for i, a in enumerate(sc.agents) if a.role.can_act]
    dump_rows: list[list[int]] = [[] for _ in range(len(sc.agents))]
    pr_cells, pr_rows = [np.zeros(0, np.int64)], [np.zeros(0, np.int64)]
    for k, entries in enumerate(data.get("Pruned_Fire_Map.pkl", [])):
        if k >= len(actors):
            raise LegacyError(f"Pruned_Fire_Map.pkl: entry {k} but only {len(actors)} A/H agents")
        for e in entries:
            if e is None or len(e) < 2:
                continue
            cells = _rows(e[0], 3, "Pruned_Fire_Map.pkl")
            info = _rows(e[1], 3, "Pruned_Fire_Map.pkl")
            row = int(_row_of_ms(info[0, 2], t_n))
            dump_rows[actors[k]].append(row)
            flat, ok = _cells(cells[:, 0], cells[:, 1], w)
            pr_cells.append(flat)
            pr_rows.append(np.full(int(ok.sum()), row, dtype=np.int64))
    pc, prow = np.concatenate(pr_cells), np.concatenate(pr_rows)
    keep = prow >= ign_row[pc]  # only cells burning by then
    pru_c, pru_r = _first_events(pc[keep], prow[keep])
    prune_row = np.full(w * w, np.iinfo(np.int64).max, dtype=np.int64)
    prune_row[pru_c] = pru_r
    return dump_rows, pru_c, pru_r, prune_row


def _sensings(
    data: dict[str, Any],
    sc: Scenario,
    clock: np.ndarray | None,
    ign_row: np.ndarray,
    prune_row: np.ndarray,
) -> tuple[np.ndarray, np.ndarray]:
    """First sensing row of each cell while it burns (cells, rows)."""
    w, t_n = sc.world_size, sc.n_ticks
    sensors = [i for i, a in enumerate(sc.agents) if a.role.can_sense]
    se_cells, se_rows = [np.zeros(0, np.int64)], [np.zeros(0, np.int64)]
    sensed_maps = data.get("Sensed_Fire_Map.pkl", [])
    if len(sensed_maps) and clock is None:
        raise LegacyError("Sensed_Fire_Map.pkl needs Agent_Base_Loci.pkl for the frame times")
    frame_ms = np.zeros(0) if clock is None else clock  # (no sensed maps without a clock)
    for k, frames in enumerate(sensed_maps):
        if k >= len(sensors):
            raise LegacyError(f"Sensed_Fire_Map.pkl: entry {k} but only {len(sensors)} P/H agents")
        for j, fr in enumerate(frames):
            a = _rows(fr, 2, "Sensed_Fire_Map.pkl")
            if a.shape[0] == 0:
                continue
            ms = frame_ms[min(j, len(frame_ms) - 1)] if len(frame_ms) else 0.0
            flat, ok = _cells(a[:, 0], a[:, 1], w)
            se_cells.append(flat)
            se_rows.append(np.full(int(ok.sum()), int(_row_of_ms(ms, t_n)), dtype=np.int64))
    sc_, sr_ = np.concatenate(se_cells), np.concatenate(se_rows)
    keep = (sr_ >= ign_row[sc_]) & (sr_ <= prune_row[sc_])
    return _first_events(sc_[keep], sr_[keep])


def _count_arrays(
    t_n: int,
    ignited: tuple[np.ndarray, np.ndarray],
    sensed: tuple[np.ndarray, np.ndarray],
    pruned: tuple[np.ndarray, np.ndarray],
    prune_row: np.ndarray,
) -> dict[str, np.ndarray]:
    """The recording's fire events (cells by row) and the per-tick counts derived from them."""
    arrays: dict[str, np.ndarray] = {}
    for kind, (cells, rows) in (("ignited", ignited), ("sensed", sensed), ("pruned", pruned)):
        order = np.lexsort((cells, rows))
        arrays[f"{kind}_cells"] = cells[order]
        arrays[f"{kind}_count"] = np.bincount(rows, minlength=t_n)[:t_n]
    ic, pcn, scn = (np.cumsum(arrays[f"{k}_count"]) for k in ("ignited", "pruned", "sensed"))
    sen_c = sensed[0]
    sensed_then_pruned = np.bincount(prune_row[sen_c][prune_row[sen_c] < t_n], minlength=t_n)
    arrays["active"] = ic - pcn
    arrays["pruned"] = pcn
    arrays["sensed_ever"] = scn
    arrays["sensed_active"] = scn - np.cumsum(sensed_then_pruned[:t_n])
    return arrays


def _facility_arrays(
    world: World,
    t_n: int,
    ignited: tuple[np.ndarray, np.ndarray],
    pruned: tuple[np.ndarray, np.ndarray],
) -> dict[str, np.ndarray]:
    """Burning and cumulative pruned cells per facility footprint and tick."""
    (ign_c, ign_r), (pru_c, pru_r) = ignited, pruned
    f_n = world.n_facilities
    lab = world.facility_labels.reshape(-1)
    fb = np.zeros((t_n, f_n), np.int64)
    fp = np.zeros((t_n, f_n), np.int64)
    if f_n:
        li = lab[ign_c]
        np.add.at(fb, (ign_r[li >= 0], li[li >= 0]), 1)
        lp = lab[pru_c]
        np.add.at(fb, (pru_r[lp >= 0], lp[lp >= 0]), -1)
        np.add.at(fp, (pru_r[lp >= 0], lp[lp >= 0]), 1)
    return {"facility_burning": np.cumsum(fb, axis=0), "facility_pruned": np.cumsum(fp, axis=0)}


#: The Agent_States.pkl values used: position, time, distance, hover frames, tank, move flag.
_AGENT_COLUMNS = [0, 1, 2, 7, 10, 11, 12, 13]


def _finite(a: np.ndarray, columns: Any, where: str) -> np.ndarray:
    """``a`` if its ``columns`` hold finite numbers of magnitude below 1e15 (what the GUI wrote:
    pixels, milliseconds, counts); LegacyError otherwise."""
    v = a[:, columns]
    if not (np.isfinite(v) & (np.abs(v) < 1e15)).all():
        raise LegacyError(f"{where}: holds a non-finite or absurd value")
    return a


#: GUI move flag 0 / 1 / 2 -> fcplan.team.Mode returning / active / homing
_MODE_OF_FLAG = np.array([2, 1, 3], dtype=np.int64)


def _agent_arrays(
    states: Any, sc: Scenario, world: World, dump_rows: list[list[int]]
) -> dict[str, np.ndarray]:
    t_n, n = sc.n_ticks, len(sc.agents)
    if len(states) != n:
        raise LegacyError(f"Agent_States.pkl: {len(states)} agents, the scenario has {n}")
    tick_ms = (np.arange(t_n) + 1) * (1000.0 / TICKS_PER_SECOND)
    xyz = np.zeros((t_n, n, 3))
    battery = np.zeros((t_n, n))
    tank = np.zeros((t_n, n), np.int64)
    mode = np.zeros((t_n, n), np.int64)
    cap = world.team.battery_capacity
    home = world.team.home
    for i, flat in enumerate(states):
        a: np.ndarray = np.asarray(flat, dtype=np.float64).reshape(-1)
        if a.size == 0 or a.size % 16:
            raise LegacyError(
                f"Agent_States.pkl: agent {i} holds {a.size} values, not 16 per frame"
            )
        a = _finite(a.reshape(-1, 16), _AGENT_COLUMNS, f"Agent_States.pkl: agent {i}")
        a = a[np.argsort(a[:, 7], kind="stable")]
        k = np.clip(np.searchsorted(a[:, 7], tick_ms, side="right") - 1, 0, len(a) - 1)
        s = a[k]
        xyz[:, i] = s[:, 0:3]
        battery[:, i] = np.maximum(cap[i] - 0.1 * s[:, 10] - 0.05 * s[:, 11], 0.0)
        tank[:, i] = s[:, 12] if sc.agents[i].role.can_act else 0
        m = _MODE_OF_FLAG[np.clip(s[:, 13].astype(np.int64), 0, 2)]
        parked = (m == 1) & np.all(s[:, 0:2] == home[i], axis=1)
        mode[:, i] = np.where(parked, 0, m)
    dumps = np.zeros((t_n, n), np.int64)
    for i, rows in enumerate(dump_rows):
        if rows:
            dumps[:, i] = np.cumsum(np.bincount(rows, minlength=t_n)[:t_n])
    return {
        "agent_xyz": xyz,
        "agent_battery": battery,
        "agent_tank": tank,
        "agent_mode": mode,
        "agent_dumps": dumps,
        "agent_goal_index": np.full((t_n, n), -1),
    }


_ACTIONS = {0: "click", 1: "up", -1: "down"}


def _inputs(user_data: Any, sc: Scenario, t_n: int) -> tuple[list[dict[str, Any]], list[int]]:
    events: list[dict[str, Any]] = []
    ids = [a.id for a in sc.agents]
    for i, rows in enumerate(user_data):
        a = _finite(_rows(rows, 5, "User_Data.pkl"), slice(None), "User_Data.pkl")
        for x, y, ds, kind, goal in a:
            events.append(
                {
                    "agent": ids[i] if i < len(ids) else str(i),
                    "action": _ACTIONS.get(int(kind), str(int(kind))),
                    "x": float(x),
                    "y": float(y),
                    "time_s": float(ds) / 10.0,
                    "goal_index": int(goal),
                }
            )
    events.sort(key=lambda e: e["time_s"])  # stable: per-agent order kept at equal times
    ticks = [int(_row_of_ms(e["time_s"] * 1000.0, t_n)) for e in events]
    return events, ticks
