"""The chess-like map grid: cell names and the pixel centres of the objects placed on them.

The map is cut into 100-px square cells. Columns are lettered along x (``A`` for x in [0, 100),
``B`` for [100, 200), ..., ``Z``, then ``AA``, ``AB``, ... for maps wider than 2,600 px); rows are
numbered from 1 along y (y grows downward), written with at least two digits (``01``..``99``, then
``100``...). A cell is named ``"<letters>-<row>"``, e.g. ``"D-05"`` spans x in [300, 400) and
y in [400, 500).

In the FireCommander GUI an object is placed by typing the **top-left** cell of the block of cells
it reserves; its pixel centre is the centre of that block:

=================  ============  ===============================
object (kind)      block (c x r)  centre from top-left cell (c, r)
=================  ============  ===============================
region             1 x 1         ((c+1)*100 - 50, r*100 - 50)
house, hospital,   2 x 2         ((c+1)*100, r*100)
power_station
depot_vertical     2 x 4         ((c+1)*100, (r+1)*100)
depot_horizontal   4 x 2         ((c+2)*100, r*100)
lake               3 x 4         ((c+1)*100 + 50, (r+1)*100)
=================  ============  ===============================

(c is the 0-based column index, r the 1-based row.) All of these follow one rule: the centre is the
block's top-left pixel corner plus half the block.

Examples
--------
>>> cell_center("D-05", "region")
(350.0, 450.0)
>>> cell_center("A-05", "depot_vertical")
(100.0, 600.0)
>>> cell_name(350, 450)
'D-05'
>>> block_cell((100, 600), "depot_vertical")
'A-05'
"""

from __future__ import annotations

import math
import re
from numbers import Real

from fcplan.errors import ScenarioError

__all__ = [
    "CELL_PX",
    "GRID_BLOCKS",
    "cell_center",
    "cell_name",
    "block_cell",
    "block_cells",
    "parse_cell",
    "format_cell",
    "column_letters",
]

CELL_PX = 100
"""Side of one grid cell in pixels."""

GRID_BLOCKS: dict[str, tuple[int, int]] = {
    "region": (1, 1),
    "house": (2, 2),
    "hospital": (2, 2),
    "power_station": (2, 2),
    "depot_vertical": (2, 4),
    "depot_horizontal": (4, 2),
    "lake": (3, 4),
}
"""Grid block (columns, rows) that each kind of object reserves in the GUI."""

_CELL_RE = re.compile(r"^\s*([A-Za-z]+)\s*-\s*(\d+)\s*$")


def column_letters(index: int) -> str:
    """Letters of the 0-based column ``index``: 0 -> ``A``, 25 -> ``Z``, 26 -> ``AA``.

    Examples
    --------
    >>> [column_letters(i) for i in (0, 3, 25, 26, 27, 701, 702)]
    ['A', 'D', 'Z', 'AA', 'AB', 'ZZ', 'AAA']
    """
    if index < 0:
        raise ValueError(f"column index must be >= 0, got {index}")
    letters = ""
    n = index + 1
    while n:
        n, rem = divmod(n - 1, 26)
        letters = chr(ord("A") + rem) + letters
    return letters


def _column_index(letters: str) -> int:
    n = 0
    for ch in letters.upper():
        n = n * 26 + (ord(ch) - ord("A") + 1)
    return n - 1


def format_cell(column: int, row: int) -> str:
    """Name of the cell with 0-based ``column`` index and 1-based ``row``.

    Examples
    --------
    >>> format_cell(3, 5)
    'D-05'
    """
    return f"{column_letters(column)}-{row:02d}"


def parse_cell(cell: str, world_size: int | None = None, *, field: str = "cell") -> tuple[int, int]:
    """Parse a cell name into (0-based column index, 1-based row).

    Letters may be lower case and the row need not be zero-padded (``"d-5"`` is ``"D-05"``).

    Parameters
    ----------
    cell : str
        The cell name.
    world_size : int, optional
        When given, the cell must lie on the ``world_size // 100`` square grid.
    field : str
        Field name used in the error message.

    Raises
    ------
    ScenarioError
        If the name is malformed or off the grid.

    Examples
    --------
    >>> parse_cell("D-05")
    (3, 5)
    >>> parse_cell("aa-100")
    (26, 100)
    """
    if not isinstance(cell, str):
        raise ScenarioError(field, "must be a cell name like 'D-05'", got=cell)
    m = _CELL_RE.match(cell)
    if not m or int(m.group(2)) < 1:
        raise ScenarioError(
            field, "must be a cell name like 'D-05' (column letters, row >= 1)", got=cell
        )
    column, row = _column_index(m.group(1)), int(m.group(2))
    if world_size is not None:
        n = world_size // CELL_PX
        if column >= n or row > n:
            last = format_cell(n - 1, n)
            raise ScenarioError(
                field,
                f"must be a cell of the {n}x{n} grid of a {world_size} px map (A-01..{last})",
                got=cell,
            )
    return column, row


def _block(kind: str) -> tuple[int, int]:
    try:
        return GRID_BLOCKS[kind]
    except KeyError:
        raise ValueError(f"unknown kind {kind!r}; known kinds: {', '.join(GRID_BLOCKS)}") from None


def cell_center(cell: str, kind: str = "region", world_size: int = 1200) -> tuple[float, float]:
    """Pixel centre of an object of ``kind`` whose top-left grid cell is ``cell``.

    Parameters
    ----------
    cell : str
        Top-left cell of the object's block, e.g. ``"D-05"``.
    kind : str
        One of ``region``, ``house``, ``hospital``, ``power_station``, ``depot_vertical``,
        ``depot_horizontal``, ``lake`` (see the module docstring for the blocks).
    world_size : int
        Map side in px; the cell must be on its grid.

    Returns
    -------
    tuple of float
        ``(x, y)`` in pixels.

    Raises
    ------
    ScenarioError
        If the cell name is malformed or off the grid.

    Examples
    --------
    >>> cell_center("D-04", "region")
    (350.0, 350.0)
    >>> cell_center("H-03", "house")
    (800.0, 300.0)
    >>> cell_center("D-09", "lake")
    (450.0, 1000.0)
    """
    cols, rows = _block(kind)
    column, row = parse_cell(cell, world_size)
    return (
        float(CELL_PX * column + CELL_PX * cols / 2),
        float(CELL_PX * (row - 1) + CELL_PX * rows / 2),
    )


def block_cell(center: tuple[float, float], kind: str) -> str | None:
    """Top-left cell of the block of ``kind`` centred at ``center``, or None if it is off the grid.

    This inverts :func:`cell_center`: an object placed by cell in the GUI always has a block cell.

    Examples
    --------
    >>> block_cell((800, 300), "house")
    'H-03'
    >>> block_cell((810, 300), "house") is None
    True
    """
    cols, rows = _block(kind)
    x0 = center[0] - CELL_PX * cols / 2
    y0 = center[1] - CELL_PX * rows / 2
    if x0 < 0 or y0 < 0 or x0 % CELL_PX or y0 % CELL_PX:
        return None
    return format_cell(int(x0 // CELL_PX), int(y0 // CELL_PX) + 1)


def block_cells(cell: str, kind: str) -> set[tuple[int, int]]:
    """Set of (column, row) grid cells covered by a block of ``kind`` with top-left ``cell``.

    Examples
    --------
    >>> sorted(block_cells("A-05", "house"))
    [(0, 5), (0, 6), (1, 5), (1, 6)]
    """
    cols, rows = _block(kind)
    column, row = parse_cell(cell)
    return {(column + i, row + j) for i in range(cols) for j in range(rows)}


def cell_name(x: float, y: float) -> str:
    """Name of the 100-px cell containing the point ``(x, y)``.

    Examples
    --------
    >>> cell_name(350, 450)
    'D-05'
    >>> cell_name(0, 0), cell_name(99.9, 1199)
    ('A-01', 'A-12')
    >>> cell_name(2650, 50)
    'AA-01'
    """
    for name, v in (("x", x), ("y", y)):
        if isinstance(v, bool) or not isinstance(v, Real) or not math.isfinite(v) or v < 0:
            raise ScenarioError(name, "must be a finite number >= 0", got=v)
    return format_cell(int(x // CELL_PX), int(y // CELL_PX) + 1)
