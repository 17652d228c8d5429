"""Pieces shared by the `appdyn` commands: argparse value types and output writing."""
from __future__ import annotations

import argparse
from pathlib import Path

import numpy as np

__all__ = ["vector", "number", "positive", "write_outputs"]


def vector(n_allowed):
    """argparse type: comma-separated finite floats, with one of the allowed lengths."""

    def parse(text):
        try:
            vals = [float(v) for v in text.replace(" ", "").split(",") if v != ""]
        except ValueError:
            raise argparse.ArgumentTypeError(f"expected comma-separated numbers, got {text!r}")
        if len(vals) not in n_allowed:
            raise argparse.ArgumentTypeError(
                f"expected {' or '.join(map(str, n_allowed))} comma-separated numbers, got {len(vals)}"
            )
        if not all(np.isfinite(vals)):
            raise argparse.ArgumentTypeError(f"numbers must be finite, got {text!r}")
        return np.array(vals)

    return parse


def number(text):
    """argparse type: one finite float."""
    try:
        v = float(text)
    except ValueError:
        raise argparse.ArgumentTypeError(f"expected a number, got {text!r}")
    if not np.isfinite(v):
        raise argparse.ArgumentTypeError(f"expected a finite number, got {text!r}")
    return v


def positive(text):
    """argparse type: one finite float > 0."""
    v = number(text)
    if v <= 0:
        raise argparse.ArgumentTypeError(f"expected a positive number, got {text!r}")
    return v


def write_outputs(result, *, plot=None, json=None) -> None:
    """Save ``result.plot(plot)`` and ``result.to_json()`` where asked, saying so on stdout."""
    if plot:
        result.plot(plot)
        print(f"plot written to {plot}")
    if json:
        Path(json).write_text(result.to_json())
        print(f"report written to {json}")
