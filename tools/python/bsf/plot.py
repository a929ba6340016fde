# SPDX-License-Identifier: MIT
"""Plotting of bsf frames with matplotlib (install the ``plot`` extra)."""
from __future__ import annotations

from typing import Any, Iterable, List, Union

import numpy as np

from . import Frame, Map


def plot_map(
    m: Map,
    ax: Any = None,
    *,
    per_span: int = 8,
    vertices: bool = True,
    path: bool = True,
    color: str = "tab:blue",
    linewidth: float = 0.8,
) -> Any:
    """Draw a fused :class:`bsf.Map`: its curves (world frame), vertices as
    markers and, with ``path``, the robot's path through the stream's pose
    records. Returns the Axes (a new figure's when ``ax`` is None)."""
    try:
        import matplotlib.pyplot as plt
        from matplotlib.collections import LineCollection
    except ImportError:
        raise ImportError("bsf.plot needs matplotlib: pip install './tools/python[plot]'") from None
    if ax is None:
        _, ax = plt.subplots(figsize=(8, 8))
    feats = m.features
    curves = [f.sample(per_span) for f in feats]
    if curves:
        ax.add_collection(LineCollection(curves, colors=color, linewidths=linewidth, label="map features"))
    if vertices and feats:
        v = np.concatenate([f.vertices for f in feats])
        if len(v):
            ax.plot(v[:, 0], v[:, 1], linestyle="none", marker="s", markersize=2.5, color="tab:red", label="vertices")
    if path and len(m.path) > 1:
        p = np.asarray(m.path)
        ax.plot(p[:, 0], p[:, 1], color="tab:green", linewidth=0.6, label="robot path")
    ax.set_aspect("equal", adjustable="datalim")
    ax.autoscale_view()
    ax.set_xlabel("x (m)")
    ax.set_ylabel("y (m)")
    if curves:
        ax.legend(loc="best", fontsize="small")
    return ax


def plot(
    frames: Union[Frame, Iterable[Frame], Map],
    ax: Any = None,
    *,
    world: bool = True,
    samples: int = 24,
    vertices: bool = True,
    path: bool = True,
    color: str = "tab:blue",
    linewidth: float = 0.8,
) -> Any:
    """Draw the features of one frame or many onto a matplotlib Axes.

    Curves are sampled with :meth:`bsf.Feature.sample`; with ``world`` each
    frame's pose places them in the world frame (frames without a pose stay in
    the sensor frame). Vertices are drawn as markers and, with ``path``, the
    laser path through the poses as a line. Returns the Axes (a new figure's
    when ``ax`` is None); axes are equal, in metres. A :class:`bsf.Map` is
    drawn by :func:`plot_map` (``samples`` is then ignored).
    """
    if isinstance(frames, Map):
        return plot_map(frames, ax, vertices=vertices, path=path, color=color, linewidth=linewidth)
    try:
        import matplotlib.pyplot as plt
        from matplotlib.collections import LineCollection
    except ImportError:
        raise ImportError("bsf.plot needs matplotlib: pip install './tools/python[plot]'") from None
    if isinstance(frames, Frame):
        frames = [frames]
    if ax is None:
        _, ax = plt.subplots(figsize=(8, 8))
    curves: List[np.ndarray] = []
    verts: List[np.ndarray] = []
    poses: List[tuple] = []
    for fr in frames:
        if not isinstance(fr, Frame):  # metadata frames draw nothing
            continue
        curves.extend(fr.sample(samples, world=world))
        if vertices:
            verts.append(fr.vertices(world=world))
        if fr.pose is not None:
            poses.append(fr.pose)
    if curves:
        ax.add_collection(LineCollection(curves, colors=color, linewidths=linewidth, label="features"))
    if vertices and verts:
        v = np.concatenate(verts)
        if len(v):
            ax.plot(v[:, 0], v[:, 1], linestyle="none", marker="s", markersize=2.5, color="tab:red", label="vertices")
    if path and world and len(poses) > 1:
        p = np.asarray(poses)
        ax.plot(p[:, 0], p[:, 1], color="0.5", linewidth=0.6, label="laser path")
    ax.set_aspect("equal", adjustable="datalim")
    ax.autoscale_view()
    ax.set_xlabel("x (m)")
    ax.set_ylabel("y (m)")
    ax.legend(loc="best", fontsize="small")
    return ax
