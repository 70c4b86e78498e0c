"""Mode shapes drawn on the structure: a 3-D panel per mode, still or animated.

The geometry comes from :mod:`rt70.linear.mode_shapes` (link frames joined along the
tree); this module only draws it: the structure at rest in grey, each mode at its
largest drawn amplitude in colour (and at the opposite phase, light), axes in metres with
equal scales, the drawn amplitude in each title.
"""

from __future__ import annotations

from collections.abc import Sequence

import numpy as np
from matplotlib.animation import FuncAnimation
from matplotlib.figure import Figure

from rt70.linear.mode_shapes import DrawnMode, StructureLines

#: Panels per row of a mode-shape figure.
COLUMNS = 3


def _segments(positions: np.ndarray, lines: StructureLines) -> list[np.ndarray]:
    """The x, y and z arrays of the structure's polyline pieces (NaN-separated)."""
    pieces = np.full((len(lines.segments), 3, 3), np.nan)
    pieces[:, 0] = positions[lines.segments[:, 0]]
    pieces[:, 1] = positions[lines.segments[:, 1]]
    flat = pieces.reshape(-1, 3)
    return [flat[:, 0], flat[:, 1], flat[:, 2]]


def _frame_axes(ax, rest: np.ndarray, modes: Sequence[DrawnMode]) -> None:
    """Equal scales on x, y, z around everything drawn, with labels in metres."""
    every = np.concatenate([rest] + [m.positions.reshape(-1, 3) for m in modes])
    low, high = every.min(axis=0), every.max(axis=0)
    centre, half = (low + high) / 2, max(float((high - low).max()) / 2, 1e-9)
    ax.set_xlim(centre[0] - half, centre[0] + half)
    ax.set_ylim(centre[1] - half, centre[1] + half)
    ax.set_zlim(centre[2] - half, centre[2] + half)
    ax.set_box_aspect((1, 1, 1))
    ax.set_xlabel("x, m")
    ax.set_ylabel("y, m")
    ax.set_zlabel("z, m")


def _layout(count: int) -> tuple[Figure, list]:
    rows = -(-count // COLUMNS)
    cols = min(count, COLUMNS)
    fig = Figure(figsize=(max(4.2 * cols, 7.0), 4.0 * rows))
    axes = [fig.add_subplot(rows, cols, k + 1, projection="3d") for k in range(count)]
    return fig, axes


def plot_structure_modes(
    lines: StructureLines, rest: np.ndarray, modes: Sequence[DrawnMode], title: str
) -> Figure:
    """One 3-D panel per mode: the structure at rest and the mode at ±its drawn amplitude.

    Parameters
    ----------
    lines : StructureLines
        The links and segments (:func:`rt70.linear.mode_shapes.structure_lines`).
    rest : numpy.ndarray, shape (n_points, 3)
        The link positions at rest, m.
    modes : sequence of DrawnMode
        The modes; the phase nearest π/2 is drawn in colour, nearest −π/2 light.
    title : str
        The figure's title.
    """
    fig, axes = _layout(len(modes))
    for ax, mode in zip(axes, modes, strict=True):
        up = int(np.argmin(np.abs(np.sin(mode.phases) - 1.0)))
        down = int(np.argmin(np.abs(np.sin(mode.phases) + 1.0)))
        ax.plot(*_segments(rest, lines), color="0.6", lw=1.0, label="at rest")
        ax.plot(*_segments(mode.positions[down], lines), color="C0", lw=0.8, alpha=0.35)
        ax.plot(*_segments(mode.positions[up], lines), color="C0", lw=1.8, label="mode")
        ax.set_title(f"{mode.label}\n(largest displacement drawn {mode.peak:.3g} m)", fontsize=9)
        _frame_axes(ax, rest, [mode])
    axes[0].legend(loc="upper left", fontsize=8)
    fig.suptitle(title)
    fig.tight_layout()
    return fig


def animate_structure_modes(
    lines: StructureLines, rest: np.ndarray, modes: Sequence[DrawnMode], title: str
) -> FuncAnimation:
    """The panels of :func:`plot_structure_modes` moving through one cycle of each mode.

    Parameters
    ----------
    lines : StructureLines
        The links and segments.
    rest : numpy.ndarray, shape (n_points, 3)
        The link positions at rest, m.
    modes : sequence of DrawnMode
        The modes, all over the same phases (one frame per phase).
    title : str
        The figure's title.
    """
    fig, axes = _layout(len(modes))
    moving = []
    for ax, mode in zip(axes, modes, strict=True):
        ax.plot(*_segments(rest, lines), color="0.6", lw=1.0)
        (line,) = ax.plot(*_segments(mode.positions[0], lines), color="C0", lw=1.8)
        moving.append(line)
        ax.set_title(f"{mode.label}\n(largest displacement drawn {mode.peak:.3g} m)", fontsize=9)
        _frame_axes(ax, rest, [mode])
    fig.suptitle(title)
    fig.tight_layout()

    def frame(k: int) -> list:
        for line, mode in zip(moving, modes, strict=True):
            x, y, z = _segments(mode.positions[k], lines)
            line.set_data_3d(x, y, z)
        return moving

    return FuncAnimation(fig, frame, frames=len(modes[0].phases), interval=80, blit=False)
