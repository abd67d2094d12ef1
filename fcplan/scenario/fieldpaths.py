"""How validation messages name scenario fields and show values.

:func:`is_number` and :func:`is_integer` are the format's number types (a bool is neither);
:func:`fmt_value`, :func:`fmt_point` and :func:`fmt_box` show values in messages.

A scenario file gives an agent value once per role (``team.action.tank = 10``) or as a list with
one value per agent (``team.action.tank = [10, 5]``); messages name the field the way the file
would write it. :class:`AgentPaths` works this out for a whole team in linear time (validation
of a 10,000-agent team names fields without looking at every agent again for each one).

Examples
--------
>>> from fcplan.scenario import load_scenario
>>> s = load_scenario(12)
>>> paths = AgentPaths(list(s.agents))
>>> paths.of(3, "tank"), paths.of(3, "start")
('team.action.tank', 'team.action.start[0]')
>>> fmt_point((350.0, 750.0)), is_number(True)
('(350, 750)', False)
"""

from __future__ import annotations

from numbers import Integral, Real
from typing import Any

from fcplan.scenario.parts import AgentSpec, Role

__all__ = [
    "AgentPaths",
    "agent_field",
    "is_number",
    "is_integer",
    "fmt_value",
    "fmt_point",
    "fmt_box",
]


def is_number(v: Any) -> bool:
    """True for int/float (numpy scalars included) but not bool."""
    return isinstance(v, Real) and not isinstance(v, bool)


def is_integer(v: Any) -> bool:
    """True for int (numpy integers included) but not bool."""
    return isinstance(v, Integral) and not isinstance(v, bool)


def fmt_value(v: Any) -> str:
    """A number as ``%g``, anything else as its repr."""
    return f"{v:g}" if is_number(v) else repr(v)


def fmt_point(p: tuple[float, float]) -> str:
    """``(x, y)``."""
    return f"({fmt_value(p[0])}, {fmt_value(p[1])})"


def fmt_box(box: tuple[float, float, float, float]) -> str:
    """``x in (x0, x1), y in (y0, y1)``."""
    return f"x in ({fmt_value(box[0])}, {fmt_value(box[1])}), y in ({fmt_value(box[2])}, {fmt_value(box[3])})"


def agent_field(agents: list[AgentSpec], role: Role, k: int, name: str) -> str:
    """TOML path of agent field ``name`` for the ``k``-th (0-based) agent of ``role``.

    ``team.<role>.<name>`` when every agent of that role has the same value (a scalar in TOML),
    else ``team.<role>.<name>[k]``. Start positions are always per agent. (One call looks at
    every agent; :class:`AgentPaths` answers many calls in linear time overall.)
    """
    return AgentPaths(agents).field(role, k, name)


class AgentPaths:
    """TOML paths of agent fields, as :func:`agent_field`, for a whole team: whether a role's
    agents share a value is worked out once per (role, field), on first use.

    Parameters
    ----------
    agents : list of AgentSpec
        The team, in order.
    """

    def __init__(self, agents: list[AgentSpec]) -> None:
        self.agents = agents
        self.index: list[int] = []  # agent n -> its index within its role
        seen: dict[Any, int] = {}
        for a in agents:
            role = getattr(a, "role", None)
            self.index.append(seen.get(role, 0))
            seen[role] = seen.get(role, 0) + 1
        self._shared: dict[tuple[Role, str], bool] = {}

    def field(self, role: Role, k: int, name: str) -> str:
        key = (role, name)
        if key not in self._shared:
            same = [a for a in self.agents if getattr(a, "role", None) is role]
            values = {repr(getattr(a, name, None)) for a in same}
            self._shared[key] = len(values) == 1 and name != "start"
        base = f"team.{role.key}.{name}"
        return base if self._shared[key] else f"{base}[{k}]"

    def of(self, n: int, name: str) -> str:
        """Path of field ``name`` of agent ``n`` (its index in the team)."""
        return self.field(self.agents[n].role, self.index[n], name)
