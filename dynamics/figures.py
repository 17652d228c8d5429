"""Figures without pyplot: every ``plot`` of appdyn builds a `matplotlib.figure.Figure`.

Library code never selects a backend or touches pyplot's global state (python-control's
``ctrlplot`` habit): a plot draws on the axes or figure it is given, or on a new
``Figure``, and returns the figure; the caller shows or saves it.
"""
from __future__ import annotations

from pathlib import Path

__all__ = ["new_figure", "cleared_figure", "axes_or_new_figure", "finish_figure"]


def new_figure(figsize=(8.0, 5.0)):
    """A new `matplotlib.figure.Figure` (no pyplot, no backend change).

    Examples
    --------
    >>> from appdyn.dynamics.figures import new_figure
    >>> type(new_figure()).__name__
    'Figure'
    """
    from matplotlib.figure import Figure

    return Figure(figsize=figsize)


def cleared_figure(fig, figsize):
    """``fig`` cleared for a multi-panel plot, or a new Figure of ``figsize`` [in]."""
    fig = new_figure(figsize) if fig is None else fig
    fig.clear()
    return fig


def axes_or_new_figure(ax, figsize):
    """``(ax.figure, ax)``, or a new Figure with one axes."""
    if ax is not None:
        return ax.figure, ax
    fig = new_figure(figsize)
    return fig, fig.add_subplot(1, 1, 1)


def finish_figure(fig, path=None):
    """Lay ``fig`` out, save it to ``path`` if given (PNG unless the suffix says pdf or svg),
    and return it."""
    fig.tight_layout()
    if path is not None:
        suffix = Path(path).suffix.lower().lstrip(".")
        fig.savefig(path, dpi=110, format=suffix if suffix in ("png", "pdf", "svg") else "png")
    return fig
