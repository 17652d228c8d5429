"""What the peer runners share: C-level stdout sent to stderr, so stdout carries only JSON.

Imported by the runners of this folder (each run as a script in its own venv, so this folder
is on ``sys.path``); standard library only.
"""
from __future__ import annotations

import contextlib
import ctypes
import os
import sys

__all__ = ["stdout_to_stderr"]


@contextlib.contextmanager
def stdout_to_stderr():
    """Point file descriptor 1 at stderr (catches C-level printf from IPOPT too)."""
    libc = ctypes.CDLL(None)
    sys.stdout.flush()
    libc.fflush(None)
    saved = os.dup(1)
    os.dup2(2, 1)
    try:
        yield
    finally:
        sys.stdout.flush()
        libc.fflush(None)
        os.dup2(saved, 1)
        os.close(saved)
