"""fcplan.batch.pages: paged_zeros gives zeros of any shape and dtype, writable, and takes
memory only at the pages written (read off the kernel's own account of the mapping); a copy
through PagedRows carries only the written rows and is paged again."""

from __future__ import annotations

import copy
import pickle
import sys
from pathlib import Path

import numpy as np
import pytest
from hypothesis import given
from hypothesis import strategies as st

from fcplan.batch.pages import PagedRows, paged_zeros


@given(
    st.lists(st.integers(0, 40), min_size=1, max_size=3),
    st.sampled_from([np.uint8, np.bool_, np.int32, np.int64, np.float64]),
)
def test_zeros_of_the_shape_and_dtype_that_keep_what_is_written(shape, dtype):
    """Property: the array equals numpy.zeros of the same shape and dtype (empty shapes
    included), is C-contiguous and writable, and reads back a write."""
    a = paged_zeros(tuple(shape), dtype)
    np.testing.assert_array_equal(a, np.zeros(shape, dtype=dtype), strict=True)
    assert a.flags.c_contiguous and a.flags.writeable
    if a.size:
        a.reshape(-1)[-1] = 1
        assert a.reshape(-1)[-1] == 1 and int(a.sum()) == 1


def _mapping_kb(a: np.ndarray) -> dict[str, int]:
    """The kB fields of /proc/self/smaps summed over the mappings that overlap ``a``'s bytes
    (the kernel may split one allocation into several)."""
    lo_a = a.ctypes.data
    hi_a = lo_a + a.nbytes
    fields: dict[str, int] = {}
    inside = False
    for line in Path("/proc/self/smaps").read_text().splitlines():
        head = line.split()[0]
        if "-" in head and not head.endswith(":"):
            lo, hi = (int(x, 16) for x in head.split("-"))
            inside = lo < hi_a and lo_a < hi
        elif inside and line.endswith(" kB"):
            key = head.rstrip(":")
            fields[key] = fields.get(key, 0) + int(line.split()[1])
    return fields


@pytest.mark.skipif(not sys.platform.startswith("linux"), reason="reads /proc/self/smaps")
def test_only_the_written_pages_are_resident():
    """64 MB of paged zeros written at one byte per MB: the kernel counts at most a few small
    pages per write resident in that mapping (no huge pages), where the whole array would be
    64 MB."""
    a = paged_zeros((64, 1 << 20), np.uint8)
    a[:, 12345] = 1
    kb = _mapping_kb(a)
    assert kb, "the array's mapping was not found"
    assert kb["Rss"] <= 64 * 4 * 4, kb  # (at most four 4-KB pages per write)
    assert kb.get("AnonHugePages", 0) == 0, kb
    assert int(a.sum()) == 64


@pytest.mark.parametrize("clone", [copy.deepcopy, lambda r: pickle.loads(pickle.dumps(r))])
def test_a_copy_keeps_the_written_rows_only(clone):
    """A (4, 256, 4096) int32 array (16 MB) with two rows written pickles to a few tens of kB,
    and comes back equal, in a mapping of its own that holds only the pages written."""
    a = paged_zeros((4, 256, 4096), np.int32)
    a[1, 7, ::512] = 3
    a[3, 200, 5] = -1
    written = np.zeros((4, 256), dtype=bool)
    written[1, 7] = written[3, 200] = True
    assert len(pickle.dumps(PagedRows(a, written))) < 64 * 1024
    b = clone(PagedRows(a, written))
    if sys.platform.startswith("linux"):  # (before the comparison reads every page)
        assert _mapping_kb(b)["Rss"] <= 2 * 4 * 4, _mapping_kb(b)
    np.testing.assert_array_equal(b, a, strict=True)
    assert not np.shares_memory(a, b) and b.flags.c_contiguous and b.flags.writeable
