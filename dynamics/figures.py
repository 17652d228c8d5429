"""Figures without pyplot: every ``plot`` of appdyn builds a `matplotlib.figure.Figure`.

Library code never selects a backend or touches pyplot's global state (python-control's
``ctrlplot`` habit): a plot draws on the axes or figure it is given, or on a new
``Figure``, and returns the figure; the caller shows or saves it.
"""
from __future__ import annotations

import numpy as np

__all__ = ["new_figure", "axes_or_new_figure", "finish_figure", "unit_groups",
           "plot_signals", "panel_grid", "panel_axes", "plot_attitude"]


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


def axes_or_new_figure(ax, figsize):
    """``(ax.figure, ax)``, or a new Figure with one axes."""
    if ax is not None:
        return ax.figure, ax
    fig = new_figure(figsize)
    return fig, fig.add_subplot(1, 1, 1)


def panel_grid(ax, nrows: int, ncols: int, figsize):
    """``(fig, grid)``: a `matplotlib.gridspec.GridSpec` of ``nrows x ncols`` slots for a
    multi-panel plot (``fig.add_subplot(grid[i, j], projection=...)``).

    ``ax`` may be None (a new `matplotlib.figure.Figure` of ``figsize`` [in]), a Figure
    (cleared), or one Axes (its slot of the figure is divided into the panels).

    Examples
    --------
    >>> from appdyn.dynamics.figures import new_figure, panel_grid
    >>> fig, grid = panel_grid(new_figure().subplots(1, 2)[1], 2, 1, (8, 5))
    >>> fig.add_subplot(grid[1, 0]) in fig.axes
    True
    """
    if ax is None or type(ax).__name__ in ("Figure", "SubFigure"):
        fig = new_figure(figsize) if ax is None else ax
        fig.clear()
        return fig, fig.add_gridspec(nrows, ncols)
    if not hasattr(ax, "get_subplotspec"):
        raise TypeError(f"`ax` must be a matplotlib Axes or Figure, got {type(ax).__name__}")
    fig, grid = ax.figure, ax.get_subplotspec().subgridspec(nrows, ncols)
    ax.remove()
    return fig, grid


def panel_axes(ax, nrows: int, ncols: int, figsize, **subplot_kw):
    """``(fig, axes)`` for a multi-panel plot, axes of shape (nrows, ncols).

    ``ax`` may be None, a Figure or one Axes (as in `panel_grid`), or a sequence of
    ``nrows * ncols`` axes (used as given).

    Examples
    --------
    >>> from appdyn.dynamics.figures import new_figure, panel_axes
    >>> fig, axes = panel_axes(new_figure().subplots(1, 2)[1], 2, 1, (8, 5))
    >>> axes.shape, len(fig.axes)
    ((2, 1), 3)
    """
    flat = None if ax is None or hasattr(ax, "get_subplotspec") or \
        type(ax).__name__ in ("Figure", "SubFigure") else list(np.ravel(np.asarray(ax, dtype=object)))
    if flat is not None:
        if len(flat) != nrows * ncols:
            raise ValueError(f"`ax` must be one axes, a Figure or {nrows * ncols} axes, "
                             f"got {len(flat)}")
        return flat[0].figure, np.asarray(flat, dtype=object).reshape(nrows, ncols)
    fig, grid = panel_grid(ax, nrows, ncols, figsize)
    axes = np.empty((nrows, ncols), dtype=object)
    for k in range(nrows * ncols):
        axes.flat[k] = fig.add_subplot(grid[k // ncols, k % ncols], **subplot_kw)
    return fig, axes


def finish_figure(fig):
    """Lay ``fig`` out and return it (the caller saves it: only the command line writes
    files)."""
    fig.tight_layout()
    return fig


def unit_groups(names, units) -> dict:
    """``{unit: [names]}`` in first-seen order; names without a unit go under ``"-"``.

    Examples
    --------
    >>> from appdyn.dynamics.figures import unit_groups
    >>> unit_groups(["q1", "w1", "q2"], {"w1": "rad/s"})
    {'-': ['q1', 'q2'], 'rad/s': ['w1']}
    """
    groups: dict = {}
    for name in names:
        groups.setdefault(units.get(name) or "-", []).append(name)
    return groups


def plot_signals(t, series, units=None, *, bounds=None, ax=None, title=None, figsize=None):
    """Signals against time, one labelled subplot per unit (python-control's ``ctrlplot``).

    Parameters
    ----------
    t : array_like, shape (n,) [s]
    series : mapping of str to array_like, shape (n,) or (n, K)
        Each signal by name (``K`` runs drawn in one colour, the first labelled).
    units : mapping of str to str, optional
        Unit of each signal (`Model.units`); signals sharing a unit share a subplot whose
        y label names it.
    bounds : mapping of str to (float, float), optional
        Drawn as dashed horizontal lines (infinite bounds skipped).
    ax : matplotlib.axes.Axes, sequence of Axes or matplotlib.figure.Figure, optional
        Draw on these: one axes draws every group on it; a sequence needs one per unit group;
        a figure is cleared and gets one row per group, as does the new
        `matplotlib.figure.Figure` made by default.
    title : str, optional
        The figure's title.
    figsize : (float, float), optional
        Size of a new figure [in] (default 8 wide, 2.4 per group).

    Returns
    -------
    matplotlib.figure.Figure

    Examples
    --------
    >>> import numpy as np
    >>> from appdyn.dynamics.figures import plot_signals
    >>> t = np.linspace(0.0, 1.0, 5)
    >>> fig = plot_signals(t, {"x": t, "v": 1 + 0 * t}, {"x": "m", "v": "m/s"})
    >>> [a.get_ylabel() for a in fig.axes]
    ['[m]', '[m/s]']
    """
    units = dict(units or {})
    bounds = dict(bounds or {})
    groups = unit_groups(list(series), units)
    t = np.asarray(t, dtype=float)
    if ax is None or type(ax).__name__ in ("Figure", "SubFigure"):
        fig = new_figure(figsize or (8.0, max(2.6, 2.4 * len(groups)))) if ax is None else ax
        fig.clear()
        axes = list(fig.subplots(len(groups), 1, sharex=True, squeeze=False)[:, 0])
    else:
        axes = list(np.ravel(np.asarray(ax, dtype=object)))
        fig = axes[0].figure
        if len(axes) == 1:
            axes = axes * len(groups)
        elif len(axes) != len(groups):
            raise ValueError(f"`ax` must be one axes or {len(groups)} (one per unit "
                             f"{list(groups)}), got {len(axes)}")
    for a, (unit, names) in zip(axes, groups.items()):
        for k, name in enumerate(names):
            y = np.asarray(series[name], dtype=float)
            color = f"C{k % 10}"
            lines = a.plot(t, y, color=color, lw=1.2 if y.ndim == 1 else 0.8)
            lines[0].set_label(name)
            lo, hi = bounds.get(name, (-np.inf, np.inf))
            for b in (lo, hi):
                if np.isfinite(b):
                    a.axhline(b, color=color, ls="--", lw=0.8, alpha=0.7)
        a.set_ylabel(f"[{unit}]")
        a.grid(True, alpha=0.3)
        a.legend(fontsize=8, loc="best", ncol=min(len(names), 4))
    axes[-1].set_xlabel("t [s]")
    if title:
        fig.suptitle(title, fontsize=10)
    fig.tight_layout()
    return fig


def plot_attitude(t, x, u, model, *, u_bounds=None, ax=None, title=None):
    """An attitude motion: quaternion, body rates, controls (bounds dashed) and the rotation
    path (the body axes on the unit sphere, inertial frame).

    Parameters
    ----------
    t : array_like, shape (n,) [s]
    x : array_like, shape (nx, n)
        States of ``model`` (its ``attitude`` locates the quaternion and the body rates).
    u : array_like, shape (nu, n)
        Controls of ``model``, drawn grouped by unit (`Model.units`).
    model : Model
        With an ``attitude``.
    u_bounds : array_like, shape (2, nu), optional
        Lower and upper control bounds (``+-inf`` for none), dashed.
    ax : matplotlib.axes.Axes or matplotlib.figure.Figure, optional
        Draw the four panels in this axes' slot or on this figure (cleared); by default on a
        new `matplotlib.figure.Figure`.
    title : str, optional

    Returns
    -------
    matplotlib.figure.Figure

    Examples
    --------
    >>> import numpy as np
    >>> from appdyn.dynamics import rigid_body
    >>> from appdyn.dynamics.figures import plot_attitude
    >>> t = np.linspace(0.0, 1.0, 3)
    >>> x = np.tile([[0.0], [0.0], [0.0], [1.0], [0.0], [0.0], [0.0]], (1, 3))
    >>> fig = plot_attitude(t, x, np.zeros((3, 3)), rigid_body([1.0, 2.0, 3.0]))
    >>> [a.get_ylabel() for a in fig.axes[:3]]
    ['quaternion [-]', 'body rate [rad/s]', 'control [N m]']
    """
    from .attitude import dcm_from_quat

    if model.attitude is None:
        raise ValueError(f"`model` {model.name!r} has no attitude (quaternion and body rates)")
    t, x, u = (np.asarray(v, dtype=float) for v in (t, x, u))
    iq, iw = model.attitude
    q, w = x[iq:iq + 4], x[iw:iw + 3]
    fig, grid = panel_grid(ax, 2, 2, (12.0, 8.0))
    controls = list(model.controls)
    units = {c: model.units.get(c) or "-" for c in controls}
    unit = units[controls[0]] if controls and len(set(units.values())) == 1 else "mixed units"
    bounds = np.full((2, len(controls)), np.inf) * [[-1], [1]] if u_bounds is None else \
        np.asarray(u_bounds, dtype=float)
    panels = [(q, "quaternion [-]", [model.states[iq + i] for i in range(4)], None),
              (w, f"body rate [{model.units.get(model.states[iw]) or 'rad/s'}]",
               [model.states[iw + i] for i in range(3)], None),
              (u, f"control [{unit}]", controls, bounds)]
    for k, (data, label, names, lim) in enumerate(panels):
        a = fig.add_subplot(grid[k // 2, k % 2])
        for j, (row, name) in enumerate(zip(np.atleast_2d(data), names)):
            line, = a.plot(t, row, label=name)
            for v in ([] if lim is None else lim[:, j]):
                if np.isfinite(v):
                    a.axhline(v, color=line.get_color(), ls="--", lw=0.8, alpha=0.7)
        a.set(xlabel="t [s]", ylabel=label)
        a.legend(loc="best", fontsize=8)
        a.grid(alpha=0.3)
    a = fig.add_subplot(grid[1, 1], projection="3d")
    A = dcm_from_quat(q / np.linalg.norm(q, axis=0))  # (3, 3, n): rows = body axes
    for i, c in enumerate(("tab:red", "tab:green", "tab:blue")):
        a.plot(A[i, 0], A[i, 1], A[i, 2], color=c, label=f"body axis {i + 1}")
        a.scatter(*A[i, :, -1], color=c, marker="o")
    a.set(title="Rotation path (inertial)", xlim=(-1, 1), ylim=(-1, 1), zlim=(-1, 1),
          xlabel="x [-]", ylabel="y [-]", zlabel="z [-]")
    a.legend(fontsize=8)
    if title:
        fig.suptitle(title, fontsize=10)
    return finish_figure(fig)
