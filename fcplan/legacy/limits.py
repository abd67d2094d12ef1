"""Work and memory bounds of the legacy reader: :class:`LegacyLimits`.

Every legacy file is read under these bounds, so a small hostile file cannot make the reader
allocate gigabytes or run for minutes. Each bound is checked before the work it guards, and
exceeding one raises :class:`~fcplan.errors.LegacyError` naming the file and the bound.

=====================  =========================================================================
``max_bytes``          size of one file (checked with ``fstat`` before reading; only regular
                       files are read)
``max_elements``       values built from one file, and the tree size of any value: a value
                       reached twice through the pickle memo counts twice (what a later
                       ``numpy.asarray`` would copy); numpy arrays count their elements, strings
                       and bytes one per 8 characters
``elements_per_byte``  the same bound relative to the file: ``max(2**20, elements_per_byte *
                       len(file))``, whichever of the two is smaller applies
``max_depth``          nesting of lists, tuples, dicts and array dimensions
``max_memo``           memo indices (and so memo entries); never more than the file has bytes
``max_key_weight``     size of a dict key or set member (keys are hashed: hashing is O(size))
``max_dict_entries``   dict and set entries per file
=====================  =========================================================================

The defaults admit the files the 2020 GUI writes with room to spare (its largest file,
``Agent_States.pkl``, holds 16 floats per agent per frame: 10 minutes at 60 frames per second
for 10 agents is 5.8 M floats, 52 MB of pickle) and keep the reader's peak memory within a small
multiple of the file's size (about 4x for a file of floats, as for CPython's own unpickler).

Examples
--------
>>> LegacyLimits().element_cap(1000)  # a small file: 2**20 values at most
1048576
>>> LegacyLimits(max_elements=5000).element_cap(10**6)
5000
"""

from __future__ import annotations

from dataclasses import dataclass

__all__ = ["DEFAULT_LIMITS", "LegacyLimits"]


@dataclass(frozen=True)
class LegacyLimits:
    """Bounds on one legacy file (see the module docstring for each field)."""

    max_bytes: int = 256 * 2**20
    max_elements: int = 32 * 2**20
    elements_per_byte: int = 8
    max_depth: int = 32
    max_memo: int = 2**24
    max_key_weight: int = 64
    max_dict_entries: int = 100_000

    def element_cap(self, n_bytes: int) -> int:
        """The element bound for a file of ``n_bytes`` bytes."""
        return min(self.max_elements, max(2**20, self.elements_per_byte * n_bytes))

    def memo_cap(self, n_bytes: int) -> int:
        """Memo indices allowed in a file of ``n_bytes`` bytes (each memo write takes >= 1 byte)."""
        return min(self.max_memo, max(n_bytes, 1))


#: The bounds used when none are given.
DEFAULT_LIMITS = LegacyLimits()
