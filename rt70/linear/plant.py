"""The linear plant a servo engineer closes loops around: named inputs, states, outputs.

One call, :func:`plant`, linearises a scene about a static equilibrium
(:func:`rt70.linear.linearize.linearize`) and assembles ``ẋ = A x + B u``,
``y = C x`` with ``x = [q; q̇]`` (:func:`rt70.linear.responses.state_space`):

- inputs are generalised forces: a torque or force on a named coordinate
  (:class:`CoordinateInput`, what a drive applies to its axis), a load
  (:class:`LoadInput`, a :class:`rt70.physics.loads.Wrench` per unit input — a force on the
  counterweight), whose column is the load's generalised force ``S·U`` (4.129)–(4.131)
  on the textbook side, or any column (:class:`ForceInput`: a wind gust's ``∂Q_w/∂v``
  on each exposed body, :func:`rt70.telescope.pointing.wind_inputs`);
- outputs are coordinates (:class:`CoordinateOutput`, an axis angle) or any
  :class:`rt70.model.outputs.Output` (the optical points, the mirror system's quantities),
  linearised on the textbook side by :func:`rt70.model.outputs.output_matrix` (the exact point
  Jacobians through the output's formula).

The result is a python-control ``StateSpace`` (:class:`rt70.linear.state_space.StateSpace`,
which also keeps the second-order model) with its state, input and output names, for
Bode plots, margins and loop design there; :func:`plant_matrices` gives the same matrices
and names without importing python-control (what ``rt70 plant --out`` writes). Do not
convert a high-order, lightly damped plant to a transfer function (``ss2tf``): the
polynomial coefficients lose the resonances (``scipy.signal.bode`` via ``ss2tf`` is off
by 24 dB at 1 Hz on the RT-70); evaluate the state space
(:func:`rt70.linear.responses.frequency_response`, or python-control's own
``frequency_response`` on the ``StateSpace``).
"""

from __future__ import annotations

from collections import Counter
from collections.abc import Sequence
from dataclasses import dataclass
from typing import TYPE_CHECKING

import numpy as np

from rt70.errors import Rt70Error
from rt70.linear import linearize as lin
from rt70.linear.responses import system_matrices
from rt70.linear.system_matrices import SystemMatrices
from rt70.model.outputs import Output, column_labels, output_matrix
from rt70.model.scene import Scene
from rt70.physics.loads import Wrench
from rt70.textbook import points

if TYPE_CHECKING:
    from rt70.linear.state_space import StateSpace


@dataclass(frozen=True)
class CoordinateInput:
    """A unit generalised force (N or N·m) on one coordinate, e.g. a drive's axis torque."""

    name: str
    coordinate: str


@dataclass(frozen=True)
class LoadInput:
    """A load per unit input: the wrench applied when the input is 1."""

    name: str
    wrench: Wrench


@dataclass(frozen=True, eq=False)
class ForceInput:
    """A generalised-force column per unit input (rows: all the scene's coordinates).

    For loads that are not one fixed wrench: a wind gust's ``∂Q_w/∂v`` on the exposed
    bodies (:func:`rt70.telescope.pointing.wind_inputs`), computed by the caller at q0.
    """

    name: str
    column: np.ndarray


@dataclass(frozen=True)
class CoordinateOutput:
    """One coordinate as an output (m or rad), e.g. an axis angle."""

    name: str
    coordinate: str


PlantInput = CoordinateInput | LoadInput | ForceInput
PlantOutput = CoordinateOutput | Output


def _input_column(lm: lin.Linearization, scene: Scene, u: PlantInput) -> np.ndarray:
    """Generalised force of one unit input, rows in ``lm.coordinates``."""
    if isinstance(u, CoordinateInput):
        if u.coordinate not in lm.coordinates:
            raise Rt70Error(
                f"{scene.name}: input '{u.name}': no free coordinate '{u.coordinate}'"
                + (" (it is locked)" if u.coordinate in lm.locked else "")
            )
        column = np.zeros(len(lm.coordinates))
        column[lm.coordinates.index(u.coordinate)] = 1.0
        return column
    if isinstance(u, ForceInput):
        Q = np.asarray(u.column, dtype=float)
        if Q.shape != (scene.textbook.nv,) or not np.isfinite(Q).all():
            raise Rt70Error(
                f"{scene.name}: input '{u.name}': a column of {scene.textbook.nv} finite "
                f"generalised forces expected, got shape {Q.shape}"
            )
    else:
        Q = points.generalized_force(scene.textbook, scene.textbook_data, lm.q0, u.wrench)
    return Q[lin.coordinate_indices(scene, lm.coordinates)]


def _output_rows(
    lm: lin.Linearization, scene: Scene, y: PlantOutput
) -> tuple[np.ndarray, list[str]]:
    """Rows ``∂y/∂q`` (one per output component) over ``lm.coordinates``, and their names."""
    if isinstance(y, CoordinateOutput):
        if y.coordinate not in lm.coordinates:
            raise Rt70Error(f"{scene.name}: output '{y.name}': no free coordinate '{y.coordinate}'")
        row = np.zeros((1, len(lm.coordinates)))
        row[0, lm.coordinates.index(y.coordinate)] = 1.0
        return row, [y.name]
    keep = lin.coordinate_indices(scene, lm.coordinates)
    rows = output_matrix(scene, lm.q0, [y], "textbook")[:, keep]
    return rows, column_labels(y.name, y.size) if y.size > 1 else [y.name]


def plant(
    scene: Scene,
    q0: np.ndarray,
    inputs: Sequence[PlantInput],
    outputs: Sequence[PlantOutput],
    locked: Sequence[str] = (),
) -> StateSpace:
    """The linear plant about the equilibrium ``q0``: :func:`plant_matrices` in python-control.

    Parameters
    ----------
    scene, q0, inputs, outputs, locked
        As :func:`plant_matrices` takes them.

    Returns
    -------
    StateSpace
        A python-control ``StateSpace`` with its second-order model; states ``q…`` and
        ``q…_dot`` named by coordinate; frequency responses by
        :func:`rt70.linear.responses.frequency_response`.
    """
    return plant_matrices(scene, q0, inputs, outputs, locked).state_space()


def plant_matrices(
    scene: Scene,
    q0: np.ndarray,
    inputs: Sequence[PlantInput],
    outputs: Sequence[PlantOutput],
    locked: Sequence[str] = (),
) -> SystemMatrices:
    """The linear plant's matrices about the equilibrium ``q0``, inputs and outputs named.

    Parameters
    ----------
    scene : Scene
        The scene.
    q0 : ndarray
        A static equilibrium (:func:`rt70.linear.linearize.equilibrium`).
    inputs : sequence of CoordinateInput, LoadInput or ForceInput
        The inputs, in order (their names label B's columns).
    outputs : sequence of CoordinateOutput or rt70.model.outputs.Output
        The outputs, in order; an Output with several components gives one row each
        (``name:x``, ``name:y``, … as in :func:`rt70.model.outputs.column_labels`).
    locked : sequence of str
        Coordinates removed from the model (held rigidly).

    Returns
    -------
    SystemMatrices
        A, B, C, D with the signals' names and the second-order model
        (:meth:`~rt70.linear.system_matrices.SystemMatrices.state_space`: the python-control
        system).

    Raises
    ------
    Rt70Error
        If there is no input or no output, two have the same name, or one refers to a
        coordinate that is not free.
    """
    if not inputs or not outputs:
        raise Rt70Error(f"{scene.name}: a plant needs at least one input and one output")
    lm = lin.linearize(scene, q0, locked=tuple(locked))
    B = np.column_stack([_input_column(lm, scene, u) for u in inputs])
    blocks = [_output_rows(lm, scene, y) for y in outputs]
    C = np.vstack([rows for rows, _ in blocks])
    output_names = [name for _, names in blocks for name in names]
    input_names = [u.name for u in inputs]
    for kind, names in (("input", input_names), ("output", output_names)):
        repeated = sorted(n for n, count in Counter(names).items() if count > 1)
        if repeated:
            raise Rt70Error(f"{scene.name}: {kind} names used twice: {', '.join(repeated)}")
    return system_matrices(
        lm.M,
        lm.K,
        lm.D,
        B,
        C,
        coord_names=lm.coordinates,
        input_names=input_names,
        output_names=output_names,
    )
