# SPDX-License-Identifier: MIT
"""Plotting of bsf frames with matplotlib (install the ``plot`` extra)."""
from __future__ import annotations

from typing import Any, Iterable, List, Union

import numpy as np

from . import Frame


def plot(
    frames: Union[Frame, Iterable[Frame]],
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
    when ``ax`` is None); axes are equal, in metres.
    """
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
