"""Distributions of the dispersed inputs, and seeded per-sample draws.

A *spec* is what `dispersion` accepts for one named input in ``params``:

* a number or array: the same value in every sample;
* a `Distribution`: `Normal`, `Uniform`, `SmallRotation` (a small-angle attitude error)
  or `RandomRotation` (a uniformly distributed attitude);
* a callable ``spec(rng) -> value`` drawing from the ``numpy.random.Generator`` it is given
  (any callable, a lambda too: draws are always made in the calling process).

Reproducibility: sample ``i`` draws from its own generator
``numpy.random.default_rng(numpy.random.SeedSequence(seed).spawn(samples)[i])``, every spec
in the order of ``params``. The draws are made before any sample runs, in the calling
process, so they do not depend on the executor, and sample ``i`` is the same for any
``samples > i`` (``SeedSequence.spawn`` keys children by index).
"""
from __future__ import annotations

from typing import Mapping

import numpy as np

from appdyn.dynamics import validate
from appdyn.dynamics.validate import ArgumentTypeError

__all__ = ["Distribution", "Normal", "Uniform", "SmallRotation", "RandomRotation",
           "check_spec", "draw", "generators", "draw_samples", "describe"]


class Distribution:
    """Base of the distribution specs: ``draw(rng)`` returns one value.

    Subclasses are small frozen value objects (picklable, comparable by ``to_dict``).
    """

    shape: tuple = ()

    def draw(self, rng: np.random.Generator):
        raise NotImplementedError

    def to_dict(self) -> dict:
        raise NotImplementedError

    def __repr__(self) -> str:
        args = ", ".join(f"{k}={v!r}" for k, v in self.to_dict().items() if k != "type")
        return f"{type(self).__name__}({args})"


def _value(a: np.ndarray):
    """A 0-d array as a Python float, anything else as a read-only array."""
    if a.ndim == 0:
        return float(a)
    a.setflags(write=False)
    return a


def _plain(a: np.ndarray):
    return float(a) if a.ndim == 0 else a.tolist()


class Normal(Distribution):
    """Gaussian ``mean + std * N(0, 1)``, elementwise.

    Parameters
    ----------
    mean : float or array_like, shape s [units of the input]
    std : float or array_like, broadcastable to s, ``>= 0`` [same units]

    Examples
    --------
    >>> import numpy as np
    >>> from appdyn.problems.dispersion import Normal
    >>> x = Normal(1.0, 0.1).draw(np.random.default_rng(0))
    >>> round(x, 6)
    1.012573
    """

    def __init__(self, mean, std):
        self.mean = validate.finite_array(mean, "mean")
        self.std = validate.finite_array(std, "std")
        if np.any(self.std < 0):
            raise ValueError(f"`std` must be >= 0, got {std!r}")
        try:
            self.shape = np.broadcast_shapes(self.mean.shape, self.std.shape)
        except ValueError:
            raise ValueError(f"`mean` {self.mean.shape} and `std` {self.std.shape} must "
                             f"broadcast together") from None

    def draw(self, rng):
        return _value(self.mean + self.std * rng.standard_normal(self.shape))

    def to_dict(self) -> dict:
        return {"type": "Normal", "mean": _plain(self.mean), "std": _plain(self.std)}


class Uniform(Distribution):
    """Uniform on ``[low, high)``, elementwise.

    Parameters
    ----------
    low, high : float or array_like, broadcastable, ``low <= high`` [units of the input]

    Examples
    --------
    >>> import numpy as np
    >>> from appdyn.problems.dispersion import Uniform
    >>> round(Uniform(-1.0, 1.0).draw(np.random.default_rng(0)), 6)
    0.273923
    """

    def __init__(self, low, high):
        self.low = validate.finite_array(low, "low")
        self.high = validate.finite_array(high, "high")
        try:
            self.shape = np.broadcast_shapes(self.low.shape, self.high.shape)
        except ValueError:
            raise ValueError(f"`low` {self.low.shape} and `high` {self.high.shape} must "
                             f"broadcast together") from None
        if np.any(self.high < self.low):
            raise ValueError(f"`high` must be >= `low`, got low={low!r}, high={high!r}")

    def draw(self, rng):
        return _value(self.low + (self.high - self.low) * rng.random(self.shape))

    def to_dict(self) -> dict:
        return {"type": "Uniform", "low": _plain(self.low), "high": _plain(self.high)}


def _quat_from_rotation_vector(phi: np.ndarray) -> np.ndarray:
    angle = float(np.linalg.norm(phi))
    if angle == 0.0:
        return np.array([0.0, 0.0, 0.0, 1.0])
    return np.concatenate([phi / angle * np.sin(angle / 2), [np.cos(angle / 2)]])


class SmallRotation(Distribution):
    """Attitude error: a rotation vector ``phi ~ N(0, std^2)`` per body axis, as a quaternion.

    The draw is the scalar-last unit quaternion ``[phi/|phi| sin(|phi|/2), cos(|phi|/2)]``
    of a rotation by ``|phi|`` about ``phi`` (``q4 >= 0`` for ``|phi| <= pi``). Named
    ``"attitude"`` in `dispersion`'s ``params``, it is composed with the nominal
    quaternion of ``x0``: ``quat_mul(dq, q0)``, i.e. ``A = A(dq) A(q0)``, an error about
    the body axes.

    Parameters
    ----------
    std : float or array_like, shape (3,), ``>= 0`` [rad]
        Standard deviation of each rotation-vector component (per body axis).

    Examples
    --------
    >>> import numpy as np
    >>> from appdyn.problems.dispersion import SmallRotation
    >>> dq = SmallRotation(0.01).draw(np.random.default_rng(0))
    >>> dq.shape, bool(abs(np.linalg.norm(dq) - 1) < 1e-15), bool(dq[3] > 0.9999)
    ((4,), True, True)
    """

    shape = (4,)

    def __init__(self, std):
        s = validate.finite_array(std, "std")
        if s.shape not in ((), (3,)) or np.any(s < 0):
            raise ValueError(f"`std` must be a number or 3 numbers >= 0 [rad], got {std!r}")
        self.std = np.broadcast_to(s, (3,)).copy()

    def draw(self, rng):
        return _value(_quat_from_rotation_vector(self.std * rng.standard_normal(3)))

    def to_dict(self) -> dict:
        return {"type": "SmallRotation", "std": self.std.tolist()}


class RandomRotation(Distribution):
    """A uniformly distributed attitude (Haar measure): a normalized 4-D Gaussian, ``q4 >= 0``.

    Examples
    --------
    >>> import numpy as np
    >>> from appdyn.problems.dispersion import RandomRotation
    >>> q = RandomRotation().draw(np.random.default_rng(0))
    >>> bool(abs(np.linalg.norm(q) - 1) < 1e-15), bool(q[3] >= 0)
    (True, True)
    """

    shape = (4,)

    def draw(self, rng):
        g = rng.standard_normal(4)
        q = g / np.linalg.norm(g)
        return _value(-q if q[3] < 0 else q)

    def to_dict(self) -> dict:
        return {"type": "RandomRotation"}


def check_spec(spec, name: str):
    """``spec`` checked: a `Distribution`, a callable ``rng -> value``, or finite numbers
    (returned as a read-only array or float).

    Raises
    ------
    TypeError
        Naming ``name``: not numbers, a distribution or a callable.
    ValueError
        Naming ``name``: numbers that are not finite.
    """
    if isinstance(spec, Distribution) or callable(spec):
        return spec
    try:
        return _value(np.array(validate.finite_array(spec, name)))
    except ArgumentTypeError:
        raise ArgumentTypeError(
            f"`{name}` must be a number, an array, a Distribution or a callable rng -> value, "
            f"got {type(spec).__name__}") from None


def draw(spec, rng: np.random.Generator):
    """One value of ``spec`` (see `check_spec`): a float or a read-only array.

    A callable's value is converted to float or a float array; if that fails, or it is
    not finite, the value is kept as returned (a sample that cannot use it fails alone).
    """
    if isinstance(spec, Distribution):
        return spec.draw(rng)
    if callable(spec):
        value = spec(rng)
        try:
            return _value(np.array(value, dtype=float))
        except (TypeError, ValueError):
            return value
    return spec


def generators(seed: int, samples: int) -> list:
    """The per-sample generators: ``default_rng(SeedSequence(seed).spawn(samples)[i])``."""
    return [np.random.default_rng(child)
            for child in np.random.SeedSequence(seed).spawn(samples)]


def draw_samples(params: Mapping, seed: int, samples: int) -> list[dict]:
    """``samples`` dicts of drawn values, each spec of ``params`` in mapping order.

    Raises
    ------
    TypeError
        If ``params`` is not a mapping of names to specs, or ``seed`` (unless ``None``: fresh
        entropy) or ``samples`` is not an integer.
    ValueError
        If ``seed`` or ``samples`` is negative.

    Examples
    --------
    >>> from appdyn.problems.dispersion import Normal, Uniform, draw_samples
    >>> specs = {"a": Normal(0.0, 1.0), "b": Uniform(0.0, 1.0), "c": 3.0}
    >>> draws = draw_samples(specs, 7, 2)
    >>> [sorted(d) for d in draws], draws[0]["c"]
    ([['a', 'b', 'c'], ['a', 'b', 'c']], 3.0)
    >>> draw_samples(specs, 7, 5)[:2] == draws  # sample i does not depend on `samples`
    True
    """
    if not isinstance(params, Mapping):
        raise ArgumentTypeError(f"`params` must be a mapping of names to specs, "
                                f"got {type(params).__name__}")
    seed = None if seed is None else validate.integer(seed, "seed", minimum=0)
    samples = validate.integer(samples, "samples", minimum=0)
    return [{name: draw(spec, rng) for name, spec in params.items()}
            for rng in generators(seed, samples)]


def describe(spec) -> object:
    """A plain description of ``spec`` for `DispersionResult.to_dict` and ``__str__``."""
    if isinstance(spec, Distribution):
        return spec.to_dict()
    if callable(spec):
        return {"type": "callable", "name": getattr(spec, "__qualname__", repr(spec))}
    return _plain(np.asarray(spec))
