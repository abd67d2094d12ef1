"""The legacy pickle reader: a pickle-opcode interpreter that builds only plain data.

:class:`RestrictedUnpickler` reads the opcode stream with :mod:`pickletools`' opcode table and
argument readers (which decode arguments and execute nothing) and interprets it itself, like
:mod:`pickle`'s stack machine, but it only ever builds

* ``None``, bools, ints, floats, strings, bytes (leaves);
* lists, tuples, dicts, sets and frozensets of built values;
* numpy dtypes, scalars and arrays, through :mod:`fcplan.legacy.arrays` from plain arguments.

A pickle names a callable with ``GLOBAL``/``STACK_GLOBAL``; only the names of :data:`GLOBALS`
(what numpy writes for arrays, dtypes and scalars, and ``_codecs.encode``/``bytes`` of protocol-2
bytes) are accepted, as tokens that the interpreter itself applies to plain arguments; any other
name is refused before anything is imported. ``INST``, ``OBJ``, ``NEWOBJ``, persistent ids,
extension codes and out-of-band buffers are refused.

Bounds (:class:`~fcplan.legacy.limits.LegacyLimits`), checked before the work they guard:

* every value carries its *weight* (tree size: a value reached twice through the memo counts
  twice, arrays count their elements, strings one per 8 characters) and *depth*; a value heavier
  than the element bound or deeper than ``max_depth`` is refused, so shared-reference bombs stop
  after a few dozen doublings and later conversions (``numpy.asarray``) stay bounded;
* memo indices are below ``min(max_memo, len(file))`` (the memo is a dict: an index allocates
  nothing);
* a container is sealed once it is used inside another value; modifying it later is refused
  (``pickle.dump`` never does that: it only happens in self-referencing structures, which are
  refused too);
* dict keys and set members are strings, bytes, ``None``, bools or ints of magnitude below
  ``2**61 - 1``: values whose hashes a file cannot make collide.

Examples
--------
>>> import pickle
>>> RestrictedUnpickler(pickle.dumps([1, (2.5, "a")]), source="x.pkl").load()
[1, (2.5, 'a')]
>>> shared = b"\\x80\\x02]q\\x00" + b"h\\x00h\\x00\\x86q\\x00" * 40 + b"."
>>> RestrictedUnpickler(shared, source="x.pkl").load()  # doctest: +ELLIPSIS
Traceback (most recent call last):
...
fcplan.errors.LegacyError: x.pkl: a value of ... elements exceeds the bound of 1048576 ...
"""

from __future__ import annotations

import io
from typing import Any

import numpy as np

from fcplan.errors import LegacyError
from fcplan.legacy.arrays import (
    RefusedError,
    build_array,
    build_dtype,
    build_scalar,
    set_dtype_state,
)
from fcplan.legacy.limits import DEFAULT_LIMITS, LegacyLimits
from fcplan.legacy.opcodes import (
    BINFLOAT,
    BINGET,
    BININT,
    BININT1,
    BINPUT,
    F8,
    GLOBALS,
    I4,
    INLINE_CODES,
    LONG_BINGET,
    MEMOIZE,
    OPCODES,
    PUT_CODES,
    REFUSED_OPS,
    SHORT_BINUNICODE,
    SIZED_TYPES,
    U4,
    MalformedError,
    leaf_weight,
)

__all__ = ["RestrictedUnpickler"]

_DATA, _ARGS, _CALL, _PENDING = "value", "argument tuple", "numpy constructor", "array in making"
_KEY_INT = 2**61 - 1


class _Val:
    """A built value with its weight (tree size) and depth; ``kind`` says whether it is data, a
    tuple holding tokens (only fit as call arguments), a token or an array awaiting its state."""

    __slots__ = ("depth", "kind", "sealed", "value", "weight")

    def __init__(self, value: Any, weight: int, depth: int, kind: str = _DATA) -> None:
        self.value, self.weight, self.depth, self.kind, self.sealed = (
            value,
            weight,
            depth,
            kind,
            False,
        )


class RestrictedUnpickler:
    """Read one pickle into plain data and numeric numpy values, within ``limits``.

    Parameters
    ----------
    data : bytes
        The pickle.
    source : str
        The file name used in error messages.
    limits : LegacyLimits, optional
        Work and memory bounds (default :data:`~fcplan.legacy.limits.DEFAULT_LIMITS`).
    """

    def __init__(
        self, data: bytes, source: str = "<bytes>", limits: LegacyLimits | None = None
    ) -> None:
        self.data, self.source = bytes(data), source
        self.limits = limits or DEFAULT_LIMITS
        self.cap = self.limits.element_cap(len(self.data))
        self.memo_cap = self.limits.memo_cap(len(self.data))
        self.stack: list[Any] = []
        self.marks: list[int] = []
        self.memo: dict[int, Any] = {}
        self.built = 0
        self.entries = 0

    def load(self) -> Any:
        """The pickled value; :class:`~fcplan.errors.LegacyError` naming the file otherwise."""
        if len(self.data) > self.limits.max_bytes:
            raise LegacyError(
                f"{self.source}: {len(self.data)} bytes exceeds the bound of "
                f"{self.limits.max_bytes} (LegacyLimits.max_bytes)"
            )
        try:
            return self._run()
        except RefusedError as exc:
            raise LegacyError(f"{self.source}: {exc}") from None
        except Exception as exc:  # malformed streams raise many types; none may escape
            raise LegacyError(
                f"{self.source}: not a readable pickle ({type(exc).__name__}: {exc})"
            ) from None

    # ----------------------------------------------------------------------------- the loop
    def _run(self) -> Any:
        """The opcode loop: the most frequent fixed-size opcodes inline, the rest through
        pickletools' argument readers and the ``_op_*`` handlers."""
        data, stack, memo, marks = self.data, self.stack, self.memo, self.marks
        f = io.BytesIO(data)
        handlers = {
            code: (reader, getattr(self, f"_op_{name.lower()}", None), name)
            for code, (name, reader) in OPCODES.items()
        }
        pos, end = 0, len(data)
        while pos < end:
            code = data[pos]
            pos += 1
            if code in INLINE_CODES:
                if self.built >= self.cap:
                    raise RefusedError(
                        f"more than {self.cap} values built (LegacyLimits.max_elements)"
                    )
                if code == BINFLOAT:
                    stack.append(F8.unpack_from(data, pos)[0])
                    pos += 8
                elif code == BININT1:
                    stack.append(data[pos])
                    pos += 1
                elif code == BININT:
                    stack.append(I4.unpack_from(data, pos)[0])
                    pos += 4
                elif code == BINGET:
                    stack.append(memo[data[pos]])
                    pos += 1
                elif code == LONG_BINGET:
                    stack.append(memo[U4.unpack_from(data, pos)[0]])
                    pos += 4
                elif code in PUT_CODES:
                    if code == MEMOIZE:
                        idx = len(memo)
                    elif code == BINPUT:
                        idx, pos = data[pos], pos + 1
                    else:
                        idx, pos = U4.unpack_from(data, pos)[0], pos + 4
                    if idx >= self.memo_cap or len(stack) <= (marks[-1] if marks else 0):
                        self._op_put(idx)  # (raises the error)
                    memo[idx] = stack[-1]
                    continue
                else:  # SHORT_BINUNICODE, SHORT_BINBYTES
                    n = data[pos]
                    if pos + 1 + n > end:
                        raise MalformedError("string argument runs past the end of the pickle")
                    raw = data[pos + 1 : pos + 1 + n]
                    stack.append(
                        raw.decode("utf-8", "surrogatepass") if code == SHORT_BINUNICODE else raw
                    )
                    pos += 1 + n
                self.built += 1
                continue
            entry = handlers.get(code)
            if entry is None:
                raise MalformedError(f"unknown opcode {bytes([code])!r} at byte {pos - 1}")
            reader, handler, name = entry
            if reader is not None:
                f.seek(pos)
                arg = reader(f)
                pos = f.tell()
            else:
                arg = None
            if handler is None:
                self._refuse_op(name, arg)
            elif name == "STOP":
                return self._take(self._pop())
            else:
                handler(arg)
        raise MalformedError("pickle exhausted before STOP")

    def _refuse_op(self, name: str, arg: Any) -> None:
        if name == "INST":
            module, _, qual = str(arg).partition(" ")
            raise RefusedError(self._refused_global(module, qual))
        raise RefusedError(f"refused {REFUSED_OPS.get(name, name)} in the pickle")

    @staticmethod
    def _refused_global(module: str, name: str) -> str:
        return (
            f"refused to load {module}.{name}: legacy files may only hold lists, tuples, "
            "numbers, strings and numpy arrays"
        )

    # ----------------------------------------------------------------------------- helpers
    def _push(self, x: Any) -> None:
        self.built += 1
        if self.built > self.cap:
            raise RefusedError(f"more than {self.cap} values built (LegacyLimits.max_elements)")
        self.stack.append(x)

    def _pop(self) -> Any:
        if len(self.stack) <= (self.marks[-1] if self.marks else 0):
            raise MalformedError("stack underflow")
        return self.stack.pop()

    def _pop_n(self, n: int) -> list[Any]:
        if len(self.stack) - n < (self.marks[-1] if self.marks else 0):
            raise MalformedError("stack underflow")
        items = self.stack[-n:]
        del self.stack[-n:]
        return items

    def _top(self) -> Any:
        if len(self.stack) <= (self.marks[-1] if self.marks else 0):
            raise MalformedError("stack underflow")
        return self.stack[-1]

    def _pop_mark(self) -> list[Any]:
        if not self.marks:
            raise MalformedError("MARK expected")
        k = self.marks.pop()
        items = self.stack[k:]
        del self.stack[k:]
        return items

    def _check(self, weight: int, depth: int) -> None:
        if weight > self.cap:
            raise RefusedError(
                f"a value of {weight} elements exceeds the bound of {self.cap} "
                "(LegacyLimits.max_elements; shared references count each time)"
            )
        if depth > self.limits.max_depth:
            raise RefusedError(
                f"nesting deeper than {self.limits.max_depth} (LegacyLimits.max_depth)"
            )

    def _take(self, x: Any) -> Any:
        """The plain value of a stack item (sealing a built container); tokens are refused."""
        return self._weighed(x)[0]

    def _weighed(self, x: Any) -> tuple[Any, int, int]:
        if type(x) is not _Val:
            return x, leaf_weight(x), 0
        if x.kind is not _DATA:
            raise RefusedError(f"a {x.kind} used as a value")
        x.sealed = True
        return x.value, x.weight, x.depth

    def _target(self, kind: type) -> _Val:
        t = self._top()
        if type(t) is not _Val or t.kind is not _DATA or type(t.value) is not kind:
            raise MalformedError(f"expected a {kind.__name__} to add items to")
        if t.sealed:
            raise RefusedError(f"a {kind.__name__} modified after it was used (a cycle?)")
        return t

    def _key(self, x: Any) -> Any:
        ok = isinstance(x, (str, bytes)) or x is None or type(x) is bool
        ok = ok or (type(x) is int and -_KEY_INT < x < _KEY_INT)
        if not ok:
            raise RefusedError(
                "dict keys and set members may only be strings, bytes, None, bools and ints "
                f"below 2**61, got {type(x).__name__}"
            )
        if leaf_weight(x) > self.limits.max_key_weight:
            raise RefusedError(
                f"a dict key of more than {8 * self.limits.max_key_weight} characters"
            )
        self.entries += 1
        if self.entries > self.limits.max_dict_entries:
            raise RefusedError(
                f"more than {self.limits.max_dict_entries} dict or set entries "
                "(LegacyLimits.max_dict_entries)"
            )
        return x

    # ----------------------------------------------------------------------------- leaves
    def _op_leaf(self, arg: Any) -> None:
        self._push(arg)

    _op_int = _op_binint = _op_binint1 = _op_binint2 = _op_leaf
    _op_long = _op_long1 = _op_long4 = _op_float = _op_binfloat = _op_leaf
    _op_string = _op_binstring = _op_short_binstring = _op_leaf
    _op_unicode = _op_binunicode = _op_short_binunicode = _op_binunicode8 = _op_leaf
    _op_binbytes = _op_short_binbytes = _op_binbytes8 = _op_leaf

    def _op_bytearray8(self, arg: Any) -> None:
        self._push(bytearray(arg))

    def _op_none(self, arg: Any) -> None:
        self._push(None)

    def _op_newtrue(self, arg: Any) -> None:
        self._push(True)

    def _op_newfalse(self, arg: Any) -> None:
        self._push(False)

    # ----------------------------------------------------------------------------- stack, memo
    def _op_proto(self, arg: Any) -> None:
        if not 0 <= arg <= 5:
            raise MalformedError(f"unsupported pickle protocol {arg}")

    def _op_frame(self, arg: Any) -> None:
        pass

    def _op_stop(self, arg: Any) -> None:  # (the loop returns at STOP)
        pass

    def _op_mark(self, arg: Any) -> None:
        self.marks.append(len(self.stack))

    def _op_pop(self, arg: Any) -> None:
        if self.marks and self.marks[-1] == len(self.stack):
            self.marks.pop()
        else:
            self._pop()

    def _op_pop_mark(self, arg: Any) -> None:
        self._pop_mark()

    def _op_dup(self, arg: Any) -> None:
        self._push(self._top())

    def _op_put(self, arg: Any) -> None:
        idx = int(arg)
        if not 0 <= idx < self.memo_cap:
            raise RefusedError(
                f"memo index {idx} out of range 0..{self.memo_cap - 1} "
                "(LegacyLimits.max_memo; at most one memo entry per byte of the file)"
            )
        self.memo[idx] = self._top()

    _op_binput = _op_long_binput = _op_put

    def _op_memoize(self, arg: Any) -> None:
        self._op_put(len(self.memo))

    def _op_get(self, arg: Any) -> None:
        try:
            self._push(self.memo[int(arg)])
        except KeyError:
            raise MalformedError(f"memo index {arg} was never set") from None

    _op_binget = _op_long_binget = _op_get

    def _op_global(self, arg: Any) -> None:
        module, _, name = str(arg).partition(" ")
        token = GLOBALS.get((module, name))
        if token is None:
            raise RefusedError(self._refused_global(module, name))
        self._push(_Val(token, 1, 0, _CALL))

    def _op_stack_global(self, arg: Any) -> None:
        name, module = self._pop(), self._pop()
        if not (isinstance(module, str) and isinstance(name, str)):
            raise MalformedError("STACK_GLOBAL needs two strings")
        self._op_global(f"{module} {name}")

    # ----------------------------------------------------------------------------- containers
    def _new(self, value: Any) -> None:
        self._push(_Val(value, 1, 1))

    def _op_empty_list(self, arg: Any) -> None:
        self._new([])

    def _op_empty_dict(self, arg: Any) -> None:
        self._new({})

    def _op_empty_set(self, arg: Any) -> None:
        self._new(set())

    def _op_list(self, arg: Any) -> None:
        items = self._pop_mark()
        self._new([])
        self._extend(items)

    def _op_append(self, arg: Any) -> None:
        self._extend([self._pop()])

    def _op_appends(self, arg: Any) -> None:
        self._extend(self._pop_mark())

    def _extend(self, items: list[Any]) -> None:
        t = self._target(list)
        w, d, out = t.weight, t.depth, []
        for x in items:
            if type(x) is _Val:
                if x is t:
                    raise RefusedError("a list that contains itself")
                v, xw, xd = self._weighed(x)
                out.append(v)
                w += xw
                if xd >= d:
                    d = xd + 1
            else:
                out.append(x)
                w += leaf_weight(x) if type(x) in SIZED_TYPES else 1
        self._check(w, d)
        t.value.extend(out)
        t.weight, t.depth = w, d

    def _tuple(self, items: list[Any]) -> None:
        w, d, plain, out = 1, 1, True, []
        for x in items:
            if type(x) is not _Val:
                out.append(x)
                w += leaf_weight(x) if type(x) in SIZED_TYPES else 1
            elif x.kind is not _DATA:
                plain = False
                out.append(x)  # a token in call arguments: kept as is, never data
                w += 1
            else:
                x.sealed = True
                out.append(x.value)
                w += x.weight
                if x.depth >= d:
                    d = x.depth + 1
        self._check(w, d)
        self._push(_Val(tuple(out), w, d, _DATA if plain else _ARGS))

    def _op_tuple(self, arg: Any) -> None:
        self._tuple(self._pop_mark())

    def _op_empty_tuple(self, arg: Any) -> None:
        self._tuple([])

    def _op_tuple1(self, arg: Any) -> None:
        self._tuple([self._pop()])

    def _op_tuple2(self, arg: Any) -> None:
        self._tuple(self._pop_n(2))

    def _op_tuple3(self, arg: Any) -> None:
        self._tuple(self._pop_n(3))

    def _op_dict(self, arg: Any) -> None:
        items = self._pop_mark()
        self._new({})
        self._set_items(items)

    def _op_setitem(self, arg: Any) -> None:
        v, k = self._pop(), self._pop()
        self._set_items([k, v])

    def _op_setitems(self, arg: Any) -> None:
        self._set_items(self._pop_mark())

    def _set_items(self, items: list[Any]) -> None:
        if len(items) % 2:
            raise MalformedError("odd number of items for a dict")
        t = self._target(dict)
        w, d, pairs = t.weight, t.depth, []
        for k, x in zip(items[::2], items[1::2], strict=True):
            if x is t:
                raise RefusedError("a dict that contains itself")
            v, xw, xd = self._weighed(x)
            pairs.append((self._key(self._take(k)), v))
            w, d = w + xw + 1, max(d, xd + 1)
        self._check(w, d)
        t.value.update(pairs)
        t.weight, t.depth = w, d

    def _op_additems(self, arg: Any) -> None:
        items = self._pop_mark()
        t = self._target(set)
        keys = [self._key(self._take(x)) for x in items]
        self._check(t.weight + len(keys), t.depth)
        t.value.update(keys)
        t.weight += len(keys)

    def _op_frozenset(self, arg: Any) -> None:
        keys = [self._key(self._take(x)) for x in self._pop_mark()]
        self._check(1 + len(keys), 1)
        self._push(_Val(frozenset(keys), 1 + len(keys), 1))

    # ----------------------------------------------------------------------------- numpy
    def _op_reduce(self, arg: Any) -> None:
        args, fn = self._pop(), self._pop()
        if type(fn) is not _Val or fn.kind is not _CALL:
            raise MalformedError("REDUCE needs a callable")
        if type(args) is not _Val or not isinstance(args.value, tuple):
            raise MalformedError("REDUCE needs an argument tuple")
        a = args.value
        if fn.value == "reconstruct":
            if not (a and type(a[0]) is _Val and a[0].value == "ndarray"):
                raise RefusedError("_reconstruct may only rebuild numpy.ndarray")
            self._push(_Val(None, 1, 1, _PENDING))
        elif fn.value == "dtype":
            self._push(_Val(build_dtype(a), 1, 0))
        elif fn.value == "scalar" and len(a) == 2:
            self._push(build_scalar(a[0], a[1]))
        elif fn.value == "frombuffer" and len(a) == 4:
            if a[3] not in ("C", "F"):
                raise RefusedError("_frombuffer order must be 'C' or 'F'")
            arr = build_array(a[0], a[1], a[2], a[3] == "F", cap=self.cap)
            self._push(self._array(_Val(None, 1, 1), arr, args.weight))
        elif fn.value == "encode" and len(a) == 2 and a[1] in ("latin1", "latin-1"):
            if not isinstance(a[0], str):
                raise RefusedError("_codecs.encode is only admitted for latin-1 text")
            self._push(a[0].encode("latin1"))
        elif fn.value == "bytes" and not a:
            self._push(b"")
        else:
            raise RefusedError(f"numpy's {fn.value} called with unexpected arguments {a!r:.60}")

    def _array(self, t: _Val, arr: np.ndarray, payload_weight: int) -> _Val:
        """``t``, made the built array ``arr`` (weight: its elements, or its objects' weight)."""
        weight = payload_weight if arr.dtype.kind == "O" else max(1, arr.size)
        self.built += arr.size
        if self.built > self.cap:
            raise RefusedError(f"more than {self.cap} values built (LegacyLimits.max_elements)")
        self._check(weight, arr.ndim)
        t.value, t.kind, t.weight, t.depth = arr, _DATA, weight, max(arr.ndim, 1)
        return t

    def _op_build(self, arg: Any) -> None:
        state, t = self._pop(), self._top()
        if type(t) is not _Val or t.sealed:
            raise RefusedError("BUILD on a value that is not a numpy array or dtype in making")
        if type(state) is not _Val or not isinstance(state.value, tuple):
            raise MalformedError("BUILD needs a state tuple")
        s = state.value
        if t.kind is _PENDING:
            if len(s) == 5 and s[0] in (0, 1):
                s = s[1:]
            if len(s) != 4:
                raise RefusedError(f"unexpected numpy array state of {len(s)} items")
            self._array(
                t, build_array(s[3], s[1], s[0], s[2], cap=self.cap, native=True), state.weight
            )
        elif t.kind is _DATA and isinstance(t.value, np.dtype):
            t.value = set_dtype_state(t.value, s)
        else:
            raise RefusedError("BUILD on a value that is not a numpy array or dtype in making")
