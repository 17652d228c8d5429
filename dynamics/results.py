"""One result protocol: the base every public result of appdyn inherits (scipy's ``_RichResult``).

A result is a frozen dataclass (or a plain class) holding what a job computed. `Result` gives
it the shared surface, so no result writes these by hand:

- ``success`` (bool: verified against what was asked), ``status`` (an **int**, documented by
  each result class: 0 is success, negative a failure, other values the class's documented
  cases), ``message`` (why, in words), ``wall_time`` [s];
- `Result.to_dict` (plain Python: the dataclass fields not starting with ``_``, unless the
  class overrides it) and `Result.to_json` (strict JSON, RFC 8259: NaN and infinities become
  ``null``, written with ``allow_nan=False`` so a NaN token can never appear);
- a compact ``repr`` of at most ten lines (as scipy's ``OptimizeResult`` prints: one field a
  line, arrays summarized by shape) and ``_repr_html_`` for notebooks (the same lines in a
  table);
- ``__str__``: the class's report, units on every number (each class writes its own rows).

``status`` is an int in every result, the collocation solutions of `appdyn.ocp` and the jobs
built on them included: their codes (IPOPT's return statuses by IPOPT's numbers, appdyn's
verification failures) are one table, ``appdyn.ocp.status``, and the text IPOPT returned
(e.g. ``"Solve_Succeeded"``) is their ``solver_status``.

Rules for a new result class
----------------------------
1. Inherit `Result` and declare the dataclass with ``repr=False`` (a dataclass's generated
   ``__repr__`` would hide the compact one).
2. Name the few fields worth a line of the repr in ``_repr_fields`` (``success``, ``status``,
   ``message`` and ``wall_time`` are shown first when the result has them).
3. Override `Result.to_dict` only when the fields are not the plain data (a nested model, a
   cached callable, derived rows); never write ``to_json``.
4. Write ``__str__`` as a report with the unit of every number (`quantity` formats one).
"""
from __future__ import annotations

import functools
import html
import math
import time
from dataclasses import fields, is_dataclass, replace

import numpy as np

from .serialize import to_json

__all__ = ["Result", "quantity", "summarize", "clean_number", "timed"]

#: at most this many lines in a result's repr
REPR_LINES = 10

_FIRST = ("success", "status", "message", "wall_time")


def clean_number(value: float, scale: float | None = None, *, rtol: float = 1e-12) -> float:
    """``value`` with round-off set to 0: ``|value| <= rtol * scale`` gives ``0.0``.

    Parameters
    ----------
    value : float
    scale : float, optional
        The magnitude ``value`` is compared with (default ``|value|``, which cleans only -0.0).
    rtol : float
        The relative size counted as round-off.

    Returns
    -------
    float

    Examples
    --------
    >>> from appdyn.dynamics.results import clean_number
    >>> clean_number(-7.2e-71, scale=1.5)
    0.0
    >>> clean_number(2.9e-5, scale=1.0)
    2.9e-05
    """
    value = float(value)
    if not math.isfinite(value):
        return value
    ref = abs(value) if scale is None or not math.isfinite(scale) else abs(float(scale))
    return 0.0 if abs(value) <= rtol * ref or value == 0.0 else value


def quantity(value, unit: str = "", digits: int = 6, *, scale: float | None = None) -> str:
    """A number and its unit for a report: ``digits`` significant digits, round-off shown as 0.

    Non-finite values read ``inf``, ``-inf`` or ``nan`` (``nan`` as "n/a" where a quantity is
    undefined is the caller's choice); complex values ``a+bj``.

    Parameters
    ----------
    value : float or complex
    unit : str
        Appended after a space (nothing for an empty unit).
    digits : int
        Significant digits.
    scale : float, optional
        Magnitude against which ``|value| <= 1e-12 scale`` is round-off (see `clean_number`).

    Returns
    -------
    str

    Examples
    --------
    >>> from appdyn.dynamics.results import quantity
    >>> quantity(1.0471975511965976, "rad", 4)
    '1.047 rad'
    >>> quantity(-7.2e-71 + 0.5j, "1/s", 4, scale=0.5)
    '0+0.5j 1/s'
    >>> quantity(float("inf"), "dB")
    'inf dB'
    """
    if isinstance(value, (complex, np.complexfloating)):
        ref = abs(value) if scale is None else scale
        re = clean_number(value.real, ref)
        im = clean_number(value.imag, ref)
        text = f"{re:.{digits}g}{im:+.{digits}g}j"
    else:
        text = f"{clean_number(value, scale) + 0.0:.{digits}g}"
    return f"{text} {unit}" if unit else text


def summarize(value, width: int = 72) -> str:
    """One short line describing ``value`` for a repr: arrays by shape and dtype, mappings by
    their keys, sequences by length, results by class, floats to 6 digits.

    Examples
    --------
    >>> import numpy as np
    >>> from appdyn.dynamics.results import summarize
    >>> summarize(np.zeros((7, 101)))
    'array(shape=(7, 101), float64)'
    >>> summarize({"w1": 1.0, "w2": 2.0})
    "{'w1': 1, 'w2': 2}"
    >>> summarize({"t": np.zeros(3), "x": np.zeros((2, 3))})
    "{'t', 'x'}"
    >>> summarize(0.012345678)
    '0.0123457'
    """
    if isinstance(value, np.ndarray):
        text = f"array(shape={value.shape}, {value.dtype})" if value.size > 6 else \
            np.array2string(value, precision=6, separator=", ").replace("\n", "")
    elif isinstance(value, (bool, np.bool_)):
        text = str(bool(value))
    elif isinstance(value, (float, np.floating)):
        text = f"{float(value):.6g}"
    elif isinstance(value, (int, np.integer)):
        text = str(int(value))
    elif isinstance(value, str):
        text = repr(value)
    elif hasattr(value, "keys") and hasattr(value, "__getitem__") and len(value) <= 4 and all(
            isinstance(v, (int, float, np.number)) and not isinstance(v, bool)
            for v in value.values()):
        text = "{" + ", ".join(f"{k!r}: {float(v):.6g}" for k, v in value.items()) + "}"
    elif hasattr(value, "keys") and hasattr(value, "__getitem__"):
        keys = list(value.keys())
        text = "{" + ", ".join(repr(k) for k in keys[:8]) + (", ..." if len(keys) > 8 else "") + "}"
    elif isinstance(value, (list, tuple)):
        if len(value) <= 4 and all(isinstance(v, (int, float, str, np.number)) for v in value):
            text = repr(type(value)(value)) if isinstance(value, tuple) else repr(list(value))
        else:
            text = f"{type(value).__name__} of {len(value)}"
    elif value is None:
        text = "None"
    elif isinstance(getattr(value, "name", None), str):
        text = f"<{type(value).__name__} {value.name!r}>"
    else:
        text = f"<{type(value).__name__}>"
    text = " ".join(text.split())
    return text if len(text) <= width else text[:width - 3] + "..."


class Result:
    """Base of every public result: strict JSON, a compact repr, a notebook view.

    Subclasses are dataclasses declared with ``repr=False``; see the module docstring for the
    rules. ``_repr_fields`` names the fields shown by ``repr`` after ``success``, ``status``,
    ``message`` and ``wall_time``.

    Examples
    --------
    >>> from dataclasses import dataclass
    >>> import numpy as np
    >>> from appdyn.dynamics.results import Result
    >>> @dataclass(frozen=True, repr=False)
    ... class Fit(Result):
    ...     success: bool
    ...     status: int
    ...     message: str
    ...     wall_time: float
    ...     x: np.ndarray
    ...     error: float
    ...     _repr_fields = ("x", "error")
    >>> fit = Fit(True, 0, "converged", 0.0012, np.zeros((3, 50)), float("nan"))
    >>> fit
    Fit
        success: True
         status: 0
        message: 'converged'
      wall_time: 0.0012 s
              x: array(shape=(3, 50), float64)
          error: nan
    >>> fit.to_json().count("null")
    1
    """

    _repr_fields: tuple = ()

    # ------------------------------------------------------------------ data
    def to_dict(self) -> dict:
        """The result as plain Python data (`to_json` makes it strict JSON).

        By default the dataclass fields whose names do not start with ``_``.

        Returns
        -------
        dict
        """
        if not is_dataclass(self):
            raise TypeError(f"{type(self).__name__} must define to_dict()")
        return {f.name: getattr(self, f.name) for f in fields(self) if not f.name.startswith("_")}

    def to_json(self) -> str:
        """`to_dict` as strict JSON text (RFC 8259: non-finite numbers as ``null``,
        arrays as lists, complex numbers as ``[re, im]``), indented by 2.

        Returns
        -------
        str
        """
        return to_json(self.to_dict())

    # ------------------------------------------------------------------ display
    def _repr_items(self) -> list:
        names = [n for n in _FIRST if hasattr(type(self), n) or n in _field_names(self)]
        names += [n for n in self._repr_fields if n not in names]
        items = []
        for name in names:
            try:
                value = getattr(self, name)
            except Exception as exc:  # a derived property that cannot be evaluated
                value = f"<{type(exc).__name__}>"
            text = summarize(value)
            if name == "wall_time" and isinstance(value, (int, float)):
                text = f"{float(value):.3g} s"
            items.append((name, text))
        return items[:REPR_LINES - 1]

    def __repr__(self) -> str:
        items = self._repr_items()
        width = max((len(k) for k, _ in items), default=0) + 2
        return "\n".join([type(self).__name__] + [f"{k:>{width}}: {v}" for k, v in items])

    def _repr_html_(self) -> str:
        rows = "".join(f"<tr><th style='text-align:right'>{html.escape(k)}</th>"
                       f"<td style='text-align:left'><code>{html.escape(v)}</code></td></tr>"
                       for k, v in self._repr_items())
        return (f"<div><b>{html.escape(type(self).__name__)}</b>"
                f"<table>{rows}</table></div>")


def timed(fun):
    """Decorator: the result of ``fun`` gets the call's time as ``wall_time`` [s] when its
    ``wall_time`` field is NaN (not measured inside).

    Examples
    --------
    >>> import math
    >>> from dataclasses import dataclass
    >>> from appdyn.dynamics.results import Result, timed
    >>> @dataclass(frozen=True, repr=False)
    ... class Out(Result):
    ...     success: bool = True
    ...     wall_time: float = math.nan
    >>> @timed
    ... def job():
    ...     return Out()
    >>> math.isfinite(job().wall_time)
    True
    """
    @functools.wraps(fun)
    def call(*args, **kwargs):
        start = time.perf_counter()
        out = fun(*args, **kwargs)
        if is_dataclass(out) and "wall_time" in _field_names(out) and math.isnan(out.wall_time):
            out = replace(out, wall_time=time.perf_counter() - start)
        return out
    return call


def _field_names(obj) -> tuple:
    return tuple(f.name for f in fields(obj)) if is_dataclass(obj) else tuple(vars(obj))
