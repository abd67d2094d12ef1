"""The information panel drawn to the right of the map: time, fire, scores, agents, legend.

From top to bottom: the scenario's title and difficulty; the simulated time and tick; the number
of known burning and pruned cells (and with ``show_truth`` the true burning count); the frame's
online scores, if any; one row per agent with its role marker, id, mode (:data:`MODE_NAMES`),
battery bar (filled to the battery now, a white tick at the estimate on arrival at the next goal,
``DRAIN_PER_PX`` per px flown), battery percentages, altitude and tank; then a legend of the fire
layers and the agent markers. Rows that do not fit are summarised as ``+k MORE AGENTS``.

The panel is :func:`panel_width` px wide and as tall as the map; its text scale grows by one for
every 480 px of map (:func:`~fcplan.render.raster.text_scale`), so it stays legible on large frames.

Examples
--------
>>> panel_width(512), panel_width(960)
(252, 504)
"""

from __future__ import annotations

from collections.abc import Sequence
from typing import Any

import numpy as np

from fcplan.fire import BURNING
from fcplan.render.frame import FrameData
from fcplan.render.raster import (
    COLORS,
    GLYPH_H,
    GLYPH_W,
    ROLE_SHAPES,
    Color,
    draw_text,
    stamp,
    text_scale,
    text_size,
)
from fcplan.team import DRAIN_PER_PX

__all__ = ["MODE_NAMES", "draw_panel", "panel_width"]

#: Short panel names of :class:`fcplan.team.Mode` values.
MODE_NAMES = {0: "IDLE", 1: "ACTV", 2: "RTRN", 3: "HOME"}


def panel_width(size: int) -> int:
    """Width in px of the information panel drawn next to a ``size`` px map.

    Examples
    --------
    >>> panel_width(512)
    252
    """
    scale = text_scale(size)
    return 40 * GLYPH_W * scale + 12 * scale


def _fmt(v: float) -> str:
    v = float(v)
    if not np.isfinite(v):
        return "-"
    if abs(v) >= 1000:
        return f"{v:.0f}"
    if abs(v) >= 100:
        return f"{v:.1f}"
    return f"{v:.2f}"


class _Writer:
    """The panel image and a text cursor moving down it line by line."""

    def __init__(self, size: int) -> None:
        self.ts = ts = text_scale(size)
        self.width = pw = panel_width(size)
        self.img = np.empty((size, pw, 3), dtype=np.uint8)
        self.img[:] = COLORS["panel"]
        self.img[:, 0:ts] = COLORS["panel_line"]
        self.lh = GLYPH_H * ts + 2 * ts  # line height
        self.x0 = 6 * ts
        self.y = 6 * ts

    def line(self, text: str, color: Color = COLORS["text"]) -> None:
        """One line of text at the left margin; the cursor moves down a line."""
        draw_text(self.img, text, self.x0, self.y, color, self.ts)
        self.y += self.lh

    def rule(self) -> None:
        """A horizontal rule just above the cursor."""
        ts, x0 = self.ts, self.x0
        self.img[self.y - ts : self.y, x0 : self.width - x0] = COLORS["panel_line"]
        self.y += ts * 3


def draw_panel(
    scenario: Any, frame: FrameData, size: int, roles: Sequence[str], show_truth: bool
) -> np.ndarray:
    """The ``(size, panel_width(size), 3)`` uint8 panel of ``frame``.

    ``roles`` names each agent's role (``"perception"``, ``"action"`` or ``"hybrid"``).
    """
    w = _Writer(size)
    title = scenario.name if scenario.number is None else f"SCENARIO {scenario.number}"
    w.line(f"{title}  {scenario.difficulty}", COLORS["accent"])
    w.line(f"T {frame.time_s:6.1f} / {scenario.duration_s:g} S   TICK {frame.tick}")
    n_known = int(np.count_nonzero(frame.known))
    n_pruned = int(np.count_nonzero(frame.pruned))
    fire_line = f"FIRE KNOWN {n_known}  PRUNED {n_pruned}"
    if show_truth and frame.fire is not None:
        fire_line += f"  TRUE {int(np.count_nonzero(frame.fire == BURNING))}"
    w.line(fire_line)
    w.rule()
    if frame.scores:
        w.line("SCORES", COLORS["text_dim"])
        for k, v in frame.scores.items():
            key = str(k).upper().replace("_", " ")[:26]
            draw_text(w.img, key, w.x0, w.y, COLORS["text"], w.ts)
            val = _fmt(v)
            draw_text(
                w.img, val, w.width - w.x0 - text_size(val, w.ts)[0], w.y, COLORS["text"], w.ts
            )
            w.y += w.lh
        w.rule()
    _agent_table(w, scenario, frame, roles, size)
    _legend(w, size, show_truth)
    return w.img


def _battery_percent(scenario: Any, frame: FrameData, n: int) -> tuple[np.ndarray, np.ndarray]:
    """Battery now and on arrival at the next goal, in percent of each agent's capacity."""
    capacity = np.array([a.battery for a in scenario.agents], dtype=np.float64)[:n]
    batt = np.asarray(frame.agent_battery, dtype=np.float64)
    pct = 100.0 * batt / np.maximum(capacity, 1e-9)
    goal_pct = pct.copy()
    for i, route in enumerate(frame.routes[:n]):
        route = np.asarray(route, dtype=np.float64).reshape(-1, 2)
        if len(route):
            d = float(np.hypot(*(route[0] - frame.agent_pos[i])))
            goal_pct[i] = 100.0 * (batt[i] - DRAIN_PER_PX * d) / max(capacity[i], 1e-9)
    return pct, goal_pct


def _agent_table(
    w: _Writer, scenario: Any, frame: FrameData, roles: Sequence[str], size: int
) -> None:
    """The header and one row per agent that fits above the legend."""
    p, ts, x0, pw = w.img, w.ts, w.x0, w.width
    # columns in characters; the id column widens for long ids (P10, H100)
    m = max(4, 2 + max((len(a.id) for a in scenario.agents), default=2))
    cols = {"id": 0, "mode": m, "batt": m + 5, "alt": m + 24, "tank": m + 30}
    cw = GLYPH_W * ts
    for name, c in cols.items():
        label = {"batt": "BATTERY NOW > GOAL"}.get(name, name.upper())
        draw_text(p, label, x0 + c * cw, w.y, COLORS["text_dim"], ts)
    w.y += w.lh
    n = len(roles)
    pct, goal_pct = _battery_percent(scenario, frame, n)
    legend_h = 3 * w.lh + 4 * ts
    rows_fit = max(0, (size - w.y - legend_h) // w.lh)
    shown = n if n <= rows_fit else max(rows_fit - 1, 0)
    bar_x = x0 + cols["batt"] * cw
    bar_w = 8 * cw - 2 * ts
    for i in range(shown):
        y = w.y
        if frame.selected is not None and i == frame.selected:
            p[y - ts : y + 7 * ts + ts, x0 - 2 * ts : pw - x0 + 2 * ts] = COLORS["panel_line"]
        col = COLORS[roles[i]]
        stamp(p, ROLE_SHAPES[roles[i]], x0 + 2 * ts, y + 3.5 * ts, 3.0 * ts, col)
        aid = scenario.agents[i].id if i < len(scenario.agents) else str(i + 1)
        draw_text(p, aid, x0 + 1 * cw, y, COLORS["text"], ts)
        mode = MODE_NAMES.get(int(frame.agent_mode[i]), "?")
        draw_text(p, mode, x0 + cols["mode"] * cw, y, COLORS["text"], ts)
        # battery bar: filled to now, white tick at the goal estimate
        frac = float(np.clip(pct[i] / 100.0, 0, 1))
        p[y : y + 7 * ts, bar_x : bar_x + bar_w] = COLORS["bar_bg"]
        fill = int(round(frac * bar_w))
        bar_col = COLORS["bar_ok"] if pct[i] >= 25 else COLORS["bar_low"]
        p[y : y + 7 * ts, bar_x : bar_x + fill] = bar_col
        g = int(round(float(np.clip(goal_pct[i] / 100.0, 0, 1)) * (bar_w - 1)))
        if goal_pct[i] != pct[i]:
            p[y - ts : y + 8 * ts, bar_x + g : bar_x + g + ts] = COLORS["bar_goal"]
        txt = f"{pct[i]:3.0f}>{goal_pct[i]:3.0f}"
        draw_text(p, txt, bar_x + bar_w + 2 * ts, y, COLORS["text"], ts)
        draw_text(p, f"{frame.agent_z[i]:3.0f}", x0 + cols["alt"] * cw, y, COLORS["text"], ts)
        tank = f"{int(frame.agent_tank[i])}" if frame.agent_can_act[i] else "-"
        draw_text(p, tank, x0 + cols["tank"] * cw, y, COLORS["text"], ts)
        w.y += w.lh
    if shown < n:
        w.line(f"+{n - shown} MORE AGENTS", COLORS["text_dim"])


def _legend(w: _Writer, size: int, show_truth: bool) -> None:
    """Fire layers and agent markers, at the bottom of the panel."""
    p, ts, x0, pw = w.img, w.ts, w.x0, w.width
    y = size - (3 * w.lh + 4 * ts) + ts
    p[y - 2 * ts : y - ts, x0 : pw - x0] = COLORS["panel_line"]
    sw = 5 * ts
    items = [("fire", "KNOWN FIRE"), ("pruned", "PRUNED")]
    if show_truth:
        items.append(("fire_hidden", "UNSEEN"))
    x = x0
    for key, label in items:
        p[y + ts : y + 6 * ts, x : x + sw] = COLORS[key]
        x = draw_text(p, label, x + sw + 2 * ts, y, COLORS["text"], ts) + 3 * ts
    y += w.lh
    x = x0
    for role in ROLE_SHAPES:
        stamp(p, ROLE_SHAPES[role], x + 3 * ts, y + 3.5 * ts, 3.0 * ts, COLORS[role])
        x = draw_text(p, role.upper(), x + 8 * ts, y, COLORS["text"], ts) + 3 * ts
    y += w.lh
    draw_text(p, "BOX = FIELD OF VIEW  - - = ROUTE", x0, y, COLORS["text_dim"], ts)
