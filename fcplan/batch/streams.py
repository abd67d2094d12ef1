"""Per-world random streams of a batch, drawn exactly as :class:`fcplan.World` draws them.

Every world of a batch owns the four generators :meth:`fcplan.World.reset` spawns from its seed
(fire, sensing, pruning, controller). The batch never shares a generator between worlds and never
changes the order in which a world's generator is read, so world ``i`` sees the random numbers a
single world reset with the same seed sees, whatever the other worlds do. Two facts make that
cheap on a per-tick path without a Python loop over worlds:

**Uniform draws ahead** (:class:`UniformBlocks`). Sensing and pruning read their streams only
through ``Generator.random(k)``, which takes one 64-bit output of the bit generator per double
and keeps no state between calls; ``k`` values drawn in one call are the values ``k`` calls of
one draw give. So each world's sensing (pruning) stream is drawn ahead in blocks of ``L``
doubles (one generator call per world per block) and each tick consumes a run of them from a
per-world cursor; the block is refilled, for the few worlds that run short, before the tick's
gather.

**The terrain without storing it** (:class:`TerrainJump`). The fire's stream draws the
``(W + 1)^2`` float32 terrain right after the ignition points: 5.8 MB per 1,200-px world, most of
which no front ever reads. fcplan's seeds give ``PCG64`` generators, a 128-bit LCG
``s_{m+1} = a s_m + c mod 2^128`` whose ``m``-th output is a fixed function of ``s_m``. With
``s_m = A_m s_0 + G_m c`` (``A_m = a^m``, ``G_m = sum_{j<m} a^j``, tabulated once per map side
and shared by every world) the terrain value of any cell is computed from the world's state before
the terrain (``s_0``, ``c`` and the buffered 32-bit half, as numpy keeps it) in a few dozen
integer operations on uint64 arrays, bit for bit the value ``Generator.random(dtype=float32)``
stores: ``(u32 >> 8) 2^-24`` of the cell's 32-bit half. The generator itself is advanced past the
terrain with ``PCG64.advance`` so that everything the fire draws afterwards (wind tables, wind
blocks) is unchanged.

Examples
--------
>>> import numpy as np
>>> g = np.random.default_rng(3)
>>> ref = np.random.default_rng(3).random((5, 5), dtype=np.float32).reshape(-1)
>>> jump = TerrainJump(side=5)
>>> base = jump.skip(g)  # g is now past the 25 values; base describes where they start
>>> cells = np.array([0, 7, 24])
>>> vals = jump.values(np.repeat(base[None], 3, axis=0), cells)
>>> bool(np.array_equal(vals, ref[cells].astype(np.float64)))
True
"""

from __future__ import annotations

from collections.abc import Sequence

import numpy as np

__all__ = ["spawn_streams", "UniformBlocks", "TerrainJump", "PCG64_MULTIPLIER", "world_seeds"]

#: PCG64's 128-bit LCG multiplier (numpy's ``PCG_DEFAULT_MULTIPLIER_128``).
PCG64_MULTIPLIER = 0x2360ED051FC65DA44385DF649FCCF645
_U = np.uint64
_M32 = _U(0xFFFFFFFF)
_S32, _S8, _S58, _S64, _R63 = _U(32), _U(8), _U(58), _U(64), _U(63)
_MASK64 = (1 << 64) - 1
_MASK128 = (1 << 128) - 1
_INV24 = 2.0**-24


def spawn_streams(seed: int | np.integer | np.random.SeedSequence | None) -> list:
    """The four generators :meth:`fcplan.World.reset` makes from ``seed``: fire, sensing,
    pruning, controller (``SeedSequence(seed).spawn(4)``, each a ``default_rng``).

    Raises
    ------
    fcplan.errors.SeedError
        If ``seed`` is not an integer >= 0, a SeedSequence or None (a batch needs PCG64
        streams: :func:`fcplan.world.check_seed` without generators).
    """
    from fcplan.world import check_seed

    checked = check_seed(seed, generator=False)
    assert not isinstance(checked, np.random.Generator)  # (refused above)
    ss = checked if isinstance(checked, np.random.SeedSequence) else np.random.SeedSequence(checked)
    return [np.random.default_rng(s) for s in ss.spawn(4)]


class UniformBlocks:
    """Uniform doubles of ``B`` per-world generators, drawn ahead in blocks (module docstring).

    Parameters
    ----------
    num : int
        Worlds ``B``.
    block : int
        Doubles drawn per world and refill (the buffer grows if one tick needs more).

    Attributes
    ----------
    buf : ndarray, (B, L) float64
        Drawn values; world ``b`` uses ``buf[b, cursor[b]:]`` next.
    cursor : ndarray, (B,) int64
    """

    def __init__(self, num: int, block: int = 4096) -> None:
        self.block = int(block)
        self.buf = np.zeros((num, self.block))
        self.cursor = np.full(num, self.block, dtype=np.int64)
        self.gens: list[np.random.Generator | None] = [None] * num

    def reset(self, b: int, gen: np.random.Generator) -> None:
        """World ``b`` starts reading ``gen`` (nothing drawn ahead yet)."""
        self.gens[b] = gen
        self.cursor[b] = self.buf.shape[1]

    def take(self, worlds: np.ndarray, counts: np.ndarray) -> np.ndarray:
        """The next ``counts[j]`` values of world ``worlds[j]`` for each ``j`` (distinct worlds),
        concatenated in that order: what ``random(counts[j])`` on each world's generator returns.
        """
        width = self.buf.shape[1]
        cur = self.cursor[worlds]
        short = np.flatnonzero(cur + counts > width)
        if short.size:
            need = int(counts[short].max())
            if need > width:
                self._grow(max(need, 2 * width))
                width = self.buf.shape[1]
            for j in short.tolist():
                self._refill(int(worlds[j]))
            cur = self.cursor[worlds]
        total = int(counts.sum())
        start = np.cumsum(counts) - counts
        local = np.arange(total, dtype=np.int64) - np.repeat(start, counts)
        idx = np.repeat(worlds.astype(np.int64) * width + cur, counts) + local
        self.cursor[worlds] = cur + counts
        return self.buf.reshape(-1)[idx]

    def _refill(self, b: int) -> None:
        """Move world ``b``'s unread values to the front and draw the rest of its row."""
        width = self.buf.shape[1]
        c = int(self.cursor[b])
        left = width - c
        row = self.buf[b]
        if left:
            row[:left] = row[c:]
        gen = self.gens[b]
        assert gen is not None
        row[left:] = gen.random(width - left)
        self.cursor[b] = 0

    def _grow(self, width: int) -> None:
        """Widen every row to ``width`` (keeping each world's unread values and cursor)."""
        old = self.buf
        new = np.zeros((old.shape[0], width))
        # each row's unread values keep their place from the end of the row
        pad = width - old.shape[1]
        new[:, pad:] = old
        self.buf = new
        self.cursor = self.cursor + pad


def _mulhi(a: np.ndarray, b: np.ndarray) -> np.ndarray:
    """High 64 bits of the 128-bit products ``a b`` (uint64 arrays, 32-bit halves)."""
    a0, a1, b0, b1 = a & _M32, a >> _S32, b & _M32, b >> _S32
    p00, p01, p10 = a0 * b0, a0 * b1, a1 * b0
    mid = (p00 >> _S32) + (p01 & _M32) + (p10 & _M32)
    return a1 * b1 + (p01 >> _S32) + (p10 >> _S32) + (mid >> _S32)


def _mul128(ah: np.ndarray, al: np.ndarray, bh: np.ndarray, bl: np.ndarray) -> tuple:
    """``(a b) mod 2^128`` of 128-bit numbers given as (high, low) uint64 arrays."""
    return _mulhi(al, bl) + al * bh + ah * bl, al * bl


class TerrainJump:
    """Terrain values of a PCG64 stream without drawing the terrain (module docstring).

    Parameters
    ----------
    side : int
        Side of the square float32 array drawn (``W + 1`` for the fire's terrain).

    Attributes
    ----------
    tables : tuple of 4 ndarray, (M,) uint64
        ``A_m`` and ``G_m`` (high and low words) for ``m = 0 .. M - 1``.
    """

    #: columns of a world's base row (see :meth:`skip`)
    FIELDS = ("state_hi", "state_lo", "inc_hi", "inc_lo", "has_half", "half")

    def __init__(self, side: int) -> None:
        self.side = int(side)
        self.count = self.side * self.side  # 32-bit values drawn
        self.tables = self._tables(self.count // 2 + 2)

    @staticmethod
    def _tables(m: int) -> tuple[np.ndarray, ...]:
        """``A_j = a^j`` and ``G_j = sum_{i<j} a^i`` mod 2^128 for ``j < m``, by doubling:
        ``A_{k+j} = A_k A_j`` and ``G_{k+j} = G_k + A_k G_j``."""
        ah, al = np.zeros(1, _U), np.ones(1, _U)
        gh, gl = np.zeros(1, _U), np.zeros(1, _U)
        k = 1
        while k < m:
            a_k = pow(PCG64_MULTIPLIER, k, 1 << 128)
            g_k = (int(gh[-1]) << 64 | int(gl[-1])) + (int(ah[-1]) << 64 | int(al[-1]))
            g_k &= _MASK128
            kh, kl = np.full(k, a_k >> 64, _U), np.full(k, a_k & _MASK64, _U)
            nh, nl = _mul128(kh, kl, ah, al)
            mh, ml = _mul128(kh, kl, gh, gl)
            sl = ml + _U(g_k & _MASK64)
            sh = mh + _U(g_k >> 64) + (sl < ml)
            ah, al = np.concatenate([ah, nh]), np.concatenate([al, nl])
            gh, gl = np.concatenate([gh, sh]), np.concatenate([gl, sl])
            k *= 2
        return ah[:m].copy(), al[:m].copy(), gh[:m].copy(), gl[:m].copy()

    def skip(self, gen: np.random.Generator) -> np.ndarray:
        """Advance ``gen`` past the ``side x side`` float32 draw, exactly as drawing it would;
        return the (6,) uint64 base row (:attr:`FIELDS`) that :meth:`values` reads it from.

        Raises
        ------
        ValueError
            If ``gen`` is not driven by ``PCG64``.
        """
        bg = gen.bit_generator
        if not isinstance(bg, np.random.PCG64):
            raise ValueError(f"seed: a batch needs PCG64 streams (got {type(bg).__name__})")
        st = bg.state
        s0, inc = int(st["state"]["state"]), int(st["state"]["inc"])
        has, half = int(st["has_uint32"]), int(st["uinteger"])
        base = np.array([s0 >> 64, s0 & _MASK64, inc >> 64, inc & _MASK64, has, half], dtype=_U)
        rest = self.count - has  # 32-bit values taken from fresh 64-bit outputs
        outputs = (rest + 1) // 2
        bg.advance(outputs)
        if rest % 2:  # the last output's high half stays buffered, as numpy leaves it
            s = int(bg.state["state"]["state"])
            st = bg.state
            st["has_uint32"], st["uinteger"] = 1, self._output(s) >> 32
            bg.state = st
        return base

    @staticmethod
    def _output(s: int) -> int:
        """PCG64's XSL-RR output of the 128-bit state ``s``."""
        x = (s >> 64) ^ (s & _MASK64)
        r = s >> 122
        return ((x >> r) | (x << ((64 - r) & 63))) & _MASK64

    def values(self, base: np.ndarray, cells: np.ndarray) -> np.ndarray:
        """Float64 values (exactly the float32 ones) of flat cells ``cells`` of the draw whose
        base rows are ``base`` ((k, 6) uint64, one per cell)."""
        has = base[:, 4].astype(np.int64)
        j = cells - has  # index among the 32-bit values from fresh outputs
        m = (j >> 1) + 1  # (floor division; j = -1 only for the buffered value)
        ah, al, gh, gl = (t[np.maximum(m, 0)] for t in self.tables)
        h1, l1 = _mul128(ah, al, base[:, 0], base[:, 1])
        h2, l2 = _mul128(gh, gl, base[:, 2], base[:, 3])
        lo = l1 + l2
        hi = h1 + h2 + (lo < l1)
        x = hi ^ lo
        r = hi >> _S58
        out = (x >> r) | (x << ((_S64 - r) & _R63))
        u32 = (out >> (_S32 * (j & 1).astype(_U))) & _M32
        buffered = j < 0
        if np.count_nonzero(buffered):
            u32 = np.where(buffered, base[:, 5], u32)
        return (u32 >> _S8).astype(np.float64) * _INV24


def world_seeds(num: int, rows: Sequence[int] | np.ndarray, seeds: Sequence | int | None) -> list:
    """The seed of each world of ``rows`` (of ``num``) that a reset with ``seeds`` starts, by
    Gymnasium's rule (``gymnasium.vector.SyncVectorEnv.reset``): None, None for each (the world
    continues its own seed sequence); an int ``s``, ``s + b`` for world ``b`` whichever worlds
    are reset; a sequence of ``num`` seeds, world ``b``'s is ``seeds[b]``. A sequence of one seed
    per world reset (in the order of ``rows``) is accepted too. The one rule of the batched
    simulator (:meth:`fcplan.batch.BatchWorld.reset`) and the vector envs
    (:func:`fcplan.env.vector_base.reset_seeds`).

    Raises
    ------
    ValueError
        For a sequence of another length.
    fcplan.errors.SeedError
        For a seed that is not an integer >= 0, a SeedSequence or None
        (:func:`fcplan.world.check_seed`), or a string given as the sequence.

    Examples
    --------
    >>> world_seeds(4, [0, 3], 10)
    [10, 13]
    >>> world_seeds(4, [1, 2], [7, 8])
    [7, 8]
    """
    from fcplan.errors import SeedError
    from fcplan.world import check_seed

    rows_l = np.asarray(rows, dtype=np.int64).tolist()
    if seeds is None:
        return [None] * len(rows_l)
    if isinstance(seeds, (str, bytes)):
        raise SeedError(
            f"seed: must be an integer >= 0, a list of them or None (got {seeds!r:.40})"
        )
    if isinstance(seeds, (int, np.integer, np.bool_)):
        check_seed(seeds, generator=False)  # (a bool or a negative integer is refused)
        return [int(seeds) + b for b in rows_l]
    given = [check_seed(s, generator=False) for s in seeds]
    if len(given) == num:
        return [given[b] for b in rows_l]
    if len(given) == len(rows_l):
        return given
    also = f" (or {len(rows_l)}, one per world reset)" if len(rows_l) != num else ""
    raise ValueError(f"seed: need {num} seeds, one per world{also}, got {len(given)}")
