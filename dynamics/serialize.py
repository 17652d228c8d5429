"""JSON for result objects: the one converter every `to_dict` / `to_json` uses.

Strict JSON (RFC 8259) has no NaN or Infinity: non-finite numbers become ``null``. Arrays
become nested lists, numpy scalars Python numbers, complex numbers ``[re, im]``,
dataclasses ``{"type": name, **fields}``.
"""
from __future__ import annotations

import json
import math
from dataclasses import asdict, is_dataclass

import numpy as np

__all__ = ["plain", "jsonable", "to_json", "text_table"]


def plain(v, *, strict: bool = False):
    """A plain-Python copy of ``v``: arrays -> lists, numpy scalars -> Python numbers,
    complex -> ``[re, im]``, dataclasses -> ``{"type": name, **fields}``; with ``strict``
    also non-finite floats -> ``None`` (JSON-ready).

    Examples
    --------
    >>> import numpy as np
    >>> from appdyn.dynamics.serialize import plain
    >>> plain({"x": np.array([1.0, np.inf]), "n": np.int64(3)})
    {'x': [1.0, inf], 'n': 3}
    """
    if isinstance(v, dict):
        return {str(k): plain(x, strict=strict) for k, x in v.items()}
    if isinstance(v, (list, tuple)):
        return [plain(x, strict=strict) for x in v]
    if isinstance(v, np.ndarray):
        return plain(v.tolist(), strict=strict)
    if isinstance(v, (bool, np.bool_)):
        return bool(v)
    if isinstance(v, (int, np.integer)):
        return int(v)
    if isinstance(v, (float, np.floating)):
        return None if strict and not math.isfinite(v) else float(v)
    if isinstance(v, (complex, np.complexfloating)):
        return [plain(float(v.real), strict=strict), plain(float(v.imag), strict=strict)]
    if is_dataclass(v) and not isinstance(v, type):
        return {"type": type(v).__name__, **plain(asdict(v), strict=strict)}
    return v


def jsonable(v):
    """A JSON-ready copy of ``v``: `plain` with non-finite floats as ``None``.

    Parameters
    ----------
    v : object
        Mappings (keys become strings), sequences, numpy arrays, numbers, dataclasses,
        strings, ``None``.

    Returns
    -------
    object

    Examples
    --------
    >>> import numpy as np
    >>> from appdyn.dynamics.serialize import jsonable
    >>> jsonable({"x": np.array([1.0, np.nan]), "z": 1 + 2j, "n": np.int64(3)})
    {'x': [1.0, None], 'z': [1.0, 2.0], 'n': 3}
    """
    return plain(v, strict=True)


def to_json(data) -> str:
    """Strict JSON text of ``data`` (see `jsonable`), indented by 2.

    Examples
    --------
    >>> from appdyn.dynamics.serialize import to_json
    >>> print(to_json({"error": float("inf")}))
    {
      "error": null
    }
    """
    return json.dumps(jsonable(data), indent=2, allow_nan=False)


def text_table(title: str, rows) -> str:
    """``title`` and aligned ``label  value`` rows: the ``__str__`` of result objects.

    Examples
    --------
    >>> from appdyn.dynamics.serialize import text_table
    >>> print(text_table("Result", [("success", True), ("cost", 6.0)]))
    Result
      success  True
      cost     6.0
    """
    rows = list(rows)
    width = max((len(k) for k, _ in rows), default=0)
    return "\n".join([title] + [f"  {k:<{width}}  {v}" for k, v in rows])
