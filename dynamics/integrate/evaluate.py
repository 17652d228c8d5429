"""Numeric evaluation of CasADi Functions without per-element data conversion."""
from __future__ import annotations

import threading
import weakref

import casadi as ca
import numpy as np

from .. import cache

__all__ = ["call_buffered", "map_eval", "BoundBuffer", "borrow_bound", "return_bound",
           "borrow_state", "return_state"]


def call_buffered(fun: ca.Function, args, out_shape) -> np.ndarray:
    """Evaluate ``fun`` through a buffer: numpy in, numpy out, no per-element conversion.

    Arrays are passed in casadi's column-major layout: a C-ordered ``(ncol, nrow)`` numpy
    array is the casadi ``nrow x ncol`` matrix; inputs not given are zero. The buffer (a
    memory object of ``fun``) is kept per thread and per Function when every input is
    given: a repeated call saves the ``Function.buffer()`` (about 6 us), and no two threads
    ever share one.
    """
    args = [np.ascontiguousarray(a, dtype=float) for a in args]  # alive until trigger()
    out = np.empty(out_shape)
    buffers = _thread_table("buffers")
    key = id(fun)
    entry = buffers.pop(key, None)  # taken out while in use: a nested call makes its own
    if entry is None or entry[0]() is not fun:
        entry = _new_buffer(fun, buffers, key)
    _, buf, trigger, n_in = entry
    if len(args) != n_in:  # an input left out must be a null pointer, as in a new buffer
        buf, trigger = fun.buffer()
    for i, a in enumerate(args):
        buf.set_arg(i, memoryview(a))
    buf.set_res(0, memoryview(out))
    trigger()
    buffers[key] = entry
    return out


_LOCAL = threading.local()


def _thread_table(name: str) -> dict:
    """This thread's table ``name``: ``"buffers"`` (`call_buffered`: ``id(fun) -> (weakref
    to fun, buffer, trigger, n_in)``), ``"bound"`` (``id(fun) -> BoundBuffer``) or
    ``"state"`` (``id(fun) ->`` a `borrow_state` object)."""
    table = getattr(_LOCAL, name, None)
    if table is None:
        table = {}
        setattr(_LOCAL, name, table)
    return table


def _new_buffer(fun: ca.Function, buffers: dict, key: int) -> tuple:
    """A buffer of ``fun`` for this thread, dropped with ``fun`` (a Function evicted from
    `dynamics.cache` releases its memory objects and compiled library)."""
    buf, trigger = fun.buffer()
    ref = weakref.ref(fun, lambda _ref: buffers.pop(key, None))
    return ref, buf, trigger, fun.n_in()


class BoundBuffer:
    """A memory object of a Function with numpy arrays bound to every input and to output
    0: write the inputs in place (``args[i][...] = ...``), call ``trigger()``, read ``out``.

    Arrays follow casadi's column-major layout as in `call_buffered`. Binding once saves
    the per-call conversions and ``set_arg`` calls (about 8 us of a short `simulate` call).
    An instance is used by one caller at a time: `borrow_bound` takes it out of this
    thread's table and `return_bound` puts it back (a nested call makes its own).
    ``tag`` is free for the caller, to remember what the inputs hold (e.g. a constant
    control already written).
    """

    __slots__ = ("ref", "buf", "trigger", "args", "out", "tag")

    def __init__(self, fun: ca.Function, in_shapes, out_shape, ref):
        self.ref = ref
        self.buf, self.trigger = fun.buffer()
        self.args = [np.zeros(shape) for shape in in_shapes]
        self.out = np.empty(out_shape)
        for i, a in enumerate(self.args):
            self.buf.set_arg(i, memoryview(a))
        self.buf.set_res(0, memoryview(self.out))
        self.tag = None


def borrow_bound(fun: ca.Function, shapes) -> BoundBuffer:
    """This thread's `BoundBuffer` of ``fun``, taken out of the table until `return_bound`;
    made on first use with ``shapes() -> (input shapes, output shape)``, those ``fun``
    always takes. Dropped with ``fun``, like `call_buffered`'s buffers."""
    return _borrow(_thread_table("bound"), fun, lambda ref: BoundBuffer(fun, *shapes(), ref))


def return_bound(fun: ca.Function, entry: BoundBuffer) -> None:
    """Put ``entry`` (from `borrow_bound`) back for the next call of this thread."""
    if entry.ref() is fun:
        _thread_table("bound")[id(fun)] = entry


def borrow_state(fun: ca.Function, make):
    """This thread's state object of ``fun`` (e.g. arrays a caller keeps bound to its
    buffers), taken out of the table until `return_state`, as `borrow_bound`.

    Parameters
    ----------
    fun : casadi.Function
        The Function the state belongs to; the state is dropped with it.
    make : callable
        ``make(ref) -> state`` on first use, ``ref`` a weak reference to ``fun`` that the
        state keeps as its attribute ``ref``.
    """
    return _borrow(_thread_table("state"), fun, make)


def return_state(fun: ca.Function, entry) -> None:
    """Put ``entry`` (from `borrow_state`) back for the next call of this thread."""
    if entry.ref() is fun:
        _thread_table("state")[id(fun)] = entry


def _borrow(table: dict, fun: ca.Function, make):
    """``table``'s entry of ``fun`` taken out, or a new one ``make(ref)`` dropped from the
    table with ``fun`` (``ref`` a weak reference to ``fun``, kept as the entry's ``ref``)."""
    key = id(fun)
    entry = table.pop(key, None)
    if entry is None or entry.ref() is not fun:
        entry = make(weakref.ref(fun, lambda _ref: table.pop(key, None)))
    return entry


def map_eval(fun: ca.Function, args) -> np.ndarray:
    """Evaluate a Function column by column over ``n`` columns (cached ``map``); (m, n) out.

    ``args`` are arrays of shape (size_i, n) (or 1-D for inputs broadcast to all columns).
    """
    n = next(a.shape[1] for a in args if np.ndim(a) == 2)
    key = ("map", cache.function_key(fun), n)
    mapped = cache.get(key, lambda: fun.map(n, "serial"), keepalive=fun)
    cols = []
    for a in args:
        a = np.asarray(a, dtype=float)
        cols.append(np.repeat(a.reshape(-1, 1), n, axis=1).T if a.ndim == 1 else a.T)
    out = call_buffered(mapped, cols, (n, fun.numel_out(0)))
    return out.T
