"""rt70's one state-space type: python-control's ``StateSpace``, with its second-order model.

:class:`StateSpace` is what :func:`rt70.linear.plant.plant`,
:func:`rt70.linear.responses.state_space` and the reductions of :mod:`rt70.linear.reduce`
return; :func:`as_state_space` checks what a function is given (any continuous-time
python-control system) and :func:`second_order_of` reads the model behind it.

python-control imports matplotlib, so this module is imported by the functions that build
or take a system, not by the modules the core loads (tests/test_import_rules.py).
"""

from __future__ import annotations

from collections.abc import Sequence

import control
import numpy as np

from rt70.errors import Rt70Error
from rt70.linear.second_order import SecondOrder


class StateSpace(control.StateSpace):
    """python-control's ``StateSpace`` that remembers the second-order model it came from.

    ``ẋ = A x + B u``, ``y = C x + D u`` (D is the feedthrough, not the damping), with
    python-control's names ``state_labels``, ``input_labels``, ``output_labels`` and
    sizes ``nstates``, ``ninputs``, ``noutputs``: it *is* a python-control system, so
    ``control.bode``, ``control.feedback``, ``control.lqe`` and the rest take it as it
    is. What rt70 adds is :attr:`second_order`, which
    :func:`rt70.linear.responses.frequency_response` solves directly and
    :func:`rt70.linear.reduce.modal_truncation` needs. A system that
    python-control derives from it (a feedback, a series connection, a slice) is a plain
    ``control.StateSpace``: it is no longer that second-order model.

    Parameters
    ----------
    A, B, C, D : array_like
        System matrices.
    states, inputs, outputs : sequence of str
        Labels.
    second_order : SecondOrder, optional
        The second-order model the matrices were assembled from.
    name : str, optional
        python-control's system name.

    Attributes
    ----------
    second_order : SecondOrder or None
        The second-order model it was built from, if any.

    Notes
    -----
    python-control's systems (0.10) cannot be pickled with :mod:`pickle` (a lambda
    in their constructor); ``cloudpickle``, which Dask uses, can.
    """

    def __init__(
        self,
        A: np.ndarray,
        B: np.ndarray,
        C: np.ndarray,
        D: np.ndarray,
        *,
        states: Sequence[str],
        inputs: Sequence[str],
        outputs: Sequence[str],
        second_order: SecondOrder | None = None,
        name: str | None = None,
    ) -> None:
        super().__init__(
            A, B, C, D, states=list(states), inputs=list(inputs), outputs=list(outputs), name=name
        )
        self.second_order = second_order


def second_order_of(sys: control.StateSpace) -> SecondOrder | None:
    """The second-order model ``sys`` was built from, or None (any python-control system)."""
    return getattr(sys, "second_order", None)


def as_state_space(sys) -> control.StateSpace:
    """``sys`` checked to be a continuous-time python-control ``StateSpace``.

    rt70's :class:`StateSpace` is one; so is any system python-control builds.

    Raises
    ------
    Rt70Error
        If ``sys`` is not a python-control ``StateSpace`` (a transfer function is refused:
        convert it with ``control.ss`` if it is of low order), or is discrete-time.
    """
    if not isinstance(sys, control.StateSpace):
        raise Rt70Error(
            f"expected a python-control StateSpace (rt70's plants are ones), "
            f"got {type(sys).__name__}"
        )
    if sys.isdtime(strict=True):
        raise Rt70Error(f"expected a continuous-time system, got one with dt = {sys.dt}")
    return sys
