"""The information panel drawn to the right of the map: time, fire, scores, agents, legend.

From top to bottom: the scenario's title and difficulty; the simulated time and tick; the number
of known burning and pruned cells (and with ``show_truth`` the true burning count); the frame's
online scores, if any; one row per agent with its role marker, id, mode (:data:`MODE_NAMES`),
battery bar (filled to the battery now, a white tick at the estimate on arrival at the next goal,
``DRAIN_PER_PX`` per px flown), battery percentages, altitude and tank; then a legend of the fire
layers and the agent markers. Rows that do not fit are summarised as ``+k more agents``.

Text is anti-aliased DejaVu Sans (:mod:`fcplan.render.text`) of
:func:`~fcplan.render.raster.font_px` px: 11 px beside maps below 960 px, 22 px up to 1440 px, and
so on. The panel is :func:`panel_width` px wide and as tall as the map; it grows with the text
scale (:func:`~fcplan.render.raster.text_scale`), so it stays legible on large frames.

Examples
--------
>>> panel_width(512), panel_width(960)
(252, 504)
"""

from __future__ import annotations

from collections.abc import Sequence
from functools import lru_cache
from typing import Any

import numpy as np

from fcplan.fire import BURNING
from fcplan.render.frame import FrameData
from fcplan.render.raster import COLORS, ROLE_SHAPES, Color, font_px, stamp, text_scale
from fcplan.render.text import draw_text, line_height, text_size
from fcplan.team import DRAIN_PER_PX

__all__ = ["MODE_NAMES", "draw_panel", "panel_width"]

#: Short panel names of :class:`fcplan.team.Mode` values.
MODE_NAMES = {0: "idle", 1: "active", 2: "return", 3: "home"}


def panel_width(size: int) -> int:
    """Width in px of the information panel drawn next to a ``size`` px map.

    Examples
    --------
    >>> panel_width(512)
    252
    """
    return 252 * text_scale(size)


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

    def __init__(self, size: int, blank: np.ndarray | None = None) -> None:
        self.ts = ts = text_scale(size)
        self.px = font_px(size)
        self.width = pw = panel_width(size)
        if blank is None:
            self.img = np.empty((size, pw, 3), dtype=np.uint8)
            self.img[:] = COLORS["panel"]
            self.img[:, 0:ts] = COLORS["panel_line"]
        else:
            self.img = blank.copy()
        self.th = line_height(self.px)  # text box height
        self.lh = self.th + 2 * ts  # line height
        self.x0 = 6 * ts
        self.y = 5 * ts

    def text(self, text: str, x: int, color: Color = COLORS["text"], bold: bool = False) -> int:
        """Text at column ``x`` of the current line; return the x after it."""
        return draw_text(self.img, text, x, self.y, color, self.px, bold=bold)

    def right(self, text: str, color: Color = COLORS["text"], end: int | None = None) -> None:
        """Text right-aligned at column ``end`` (the right margin) of the current line."""
        end = self.width - self.x0 if end is None else end
        draw_text(self.img, text, end - text_size(text, self.px)[0], self.y, color, self.px)

    def line(self, text: str, color: Color = COLORS["text"], bold: bool = False) -> None:
        """One line of text at the left margin; the cursor moves down a line."""
        self.text(text, self.x0, color, bold)
        self.y += self.lh

    def rule(self) -> None:
        """A horizontal rule just below the cursor's line."""
        ts, x0 = self.ts, self.x0
        self.img[self.y : self.y + ts, x0 : self.width - x0] = COLORS["panel_line"]
        self.y += ts * 4


def draw_panel(
    scenario: Any, frame: FrameData, size: int, roles: Sequence[str], show_truth: bool
) -> np.ndarray:
    """The ``(size, panel_width(size), 3)`` uint8 panel of ``frame``.

    ``roles`` names each agent's role (``"perception"``, ``"action"`` or ``"hybrid"``).
    """
    w = _Writer(size, _blank_panel(size, show_truth))
    title = scenario.name if scenario.number is None else f"Scenario {scenario.number}"
    w.line(f"{title} \u00b7 {scenario.difficulty}", COLORS["accent"], bold=True)
    w.text(f"t = {frame.time_s:.1f} / {scenario.duration_s:g} s", w.x0)
    w.right(f"tick {frame.tick}", COLORS["text_dim"])
    w.y += w.lh
    n_known = int(np.count_nonzero(frame.known))
    n_pruned = int(np.count_nonzero(frame.pruned))
    fire_line = f"fire: {n_known} known, {n_pruned} pruned"
    if show_truth and frame.fire is not None:
        fire_line += f", {int(np.count_nonzero(frame.fire == BURNING))} true"
    w.line(fire_line)
    w.rule()
    if frame.scores:
        for k, v in frame.scores.items():
            w.text(str(k).replace("_", " ")[:30], w.x0)
            w.right(_fmt(v))
            w.y += w.lh
        w.rule()
    _agent_table(w, scenario, frame, roles, size)
    return w.img


@lru_cache(maxsize=16)
def _blank_panel(size: int, show_truth: bool) -> np.ndarray:
    """The panel's background with its legend (the same in every frame), read-only."""
    w = _Writer(size)
    _legend(w, size, show_truth)
    w.img.setflags(write=False)
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
    p, ts, x0, pw, px = w.img, w.ts, w.x0, w.width, w.px
    # columns in px; the id column widens for long ids (P10, H100)
    id_w = max(text_size(a.id, px)[0] for a in scenario.agents) if scenario.agents else 0
    c_mode = x0 + max(34 * ts, 11 * ts + id_w + 4 * ts)
    c_batt = c_mode + 42 * ts
    bar_w = 38 * ts
    c_alt, c_tank = pw - x0 - 30 * ts, pw - x0  # right-aligned columns
    for label, x in (("id", x0), ("mode", c_mode), ("battery now \u203a goal", c_batt)):
        w.text(label, x, COLORS["text_dim"])
    w.right("alt", COLORS["text_dim"], c_alt)
    w.right("tank", COLORS["text_dim"], c_tank)
    w.y += w.lh
    n = len(roles)
    pct, goal_pct = _battery_percent(scenario, frame, n)
    legend_h = 3 * w.lh + 4 * ts
    rows_fit = max(0, (size - w.y - legend_h) // w.lh)
    shown = n if n <= rows_fit else max(rows_fit - 1, 0)
    bh = max(3 * ts, w.th // 2)  # battery bar height, centred on the text line
    for i in range(shown):
        y = w.y
        mid = y + w.th // 2
        if frame.selected is not None and i == frame.selected:
            p[y - ts : y + w.th + ts, x0 - 2 * ts : pw - x0 + 2 * ts] = COLORS["panel_line"]
        col = COLORS[roles[i]]
        stamp(p, ROLE_SHAPES[roles[i]], x0 + 4 * ts, mid, 3.5 * ts, col)
        aid = scenario.agents[i].id if i < len(scenario.agents) else str(i + 1)
        w.text(aid, x0 + 11 * ts)
        w.text(MODE_NAMES.get(int(frame.agent_mode[i]), "?"), c_mode)
        # battery bar: filled to now, white tick at the goal estimate
        frac = float(np.clip(pct[i] / 100.0, 0, 1))
        b0, b1 = mid - bh // 2, mid - bh // 2 + bh
        p[b0:b1, c_batt : c_batt + bar_w] = COLORS["bar_bg"]
        fill = int(round(frac * bar_w))
        p[b0:b1, c_batt : c_batt + fill] = COLORS["bar_ok"] if pct[i] >= 25 else COLORS["bar_low"]
        g = int(round(float(np.clip(goal_pct[i] / 100.0, 0, 1)) * (bar_w - 1)))
        if goal_pct[i] != pct[i]:
            p[b0 - 2 * ts : b1 + 2 * ts, c_batt + g : c_batt + g + ts] = COLORS["bar_goal"]
        w.text(f"{pct[i]:.0f}\u203a{goal_pct[i]:.0f}", c_batt + bar_w + 3 * ts)
        w.right(f"{frame.agent_z[i]:.0f}", end=c_alt)
        w.right(f"{int(frame.agent_tank[i])}" if frame.agent_can_act[i] else "-", end=c_tank)
        w.y += w.lh
    if shown < n:
        w.line(f"+{n - shown} more agents", COLORS["text_dim"])


def _legend(w: _Writer, size: int, show_truth: bool) -> None:
    """Fire layers and agent markers, at the bottom of the panel."""
    p, ts, x0, pw = w.img, w.ts, w.x0, w.width
    w.y = size - (3 * w.lh + 3 * ts)
    p[w.y - 2 * ts : w.y - ts, x0 : pw - x0] = COLORS["panel_line"]
    sw = 8 * ts
    items = [("fire", "known fire"), ("pruned", "pruned")]
    if show_truth:
        items.append(("fire_hidden", "unseen fire"))
    mid = w.y + w.th // 2
    x = x0
    for key, label in items:
        p[mid - 3 * ts : mid + 3 * ts, x : x + sw] = COLORS[key]
        x = w.text(label, x + sw + 3 * ts) + 7 * ts
    w.y += w.lh
    mid += w.lh
    x = x0
    for role in ROLE_SHAPES:
        stamp(p, ROLE_SHAPES[role], x + 4 * ts, mid, 3.5 * ts, COLORS[role])
        x = w.text(role, x + 10 * ts) + 7 * ts
    w.y += w.lh
    w.text("box = field of view, dashes = route", x0, COLORS["text_dim"])
