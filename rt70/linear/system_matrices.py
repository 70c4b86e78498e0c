"""A state space's matrices and names as plain arrays, before python-control holds them."""

from __future__ import annotations

from dataclasses import dataclass

import numpy as np

from rt70.linear.second_order import SecondOrder


@dataclass(frozen=True)
class SystemMatrices:
    """A state space's matrices and labels before python-control holds them.

    ``ẋ = A x + B u``, ``y = C x + D u`` assembled from :attr:`second_order`
    (:func:`rt70.linear.responses.system_matrices`). python-control's ``StateSpace`` is the
    system type (:meth:`state_space`); this record lets a command that only writes the
    matrices to a file (``rt70 plant --out``) skip importing python-control, which imports
    matplotlib and scipy.signal (2.2 s of a 10 s target on 2004 coordinates). Its
    attribute names are python-control's.
    """

    A: np.ndarray
    B: np.ndarray
    C: np.ndarray
    D: np.ndarray
    state_labels: tuple[str, ...]
    input_labels: tuple[str, ...]
    output_labels: tuple[str, ...]
    second_order: SecondOrder

    @property
    def nstates(self) -> int:
        """Number of states."""
        return self.A.shape[0]

    @property
    def ninputs(self) -> int:
        """Number of inputs."""
        return self.B.shape[1]

    @property
    def noutputs(self) -> int:
        """Number of outputs."""
        return self.C.shape[0]

    def state_space(self):  # -> rt70.linear.state_space.StateSpace (python-control: lazy)
        """The python-control system (:class:`rt70.linear.state_space.StateSpace`)."""
        from rt70.linear.state_space import StateSpace

        return StateSpace(
            self.A,
            self.B,
            self.C,
            self.D,
            states=self.state_labels,
            inputs=self.input_labels,
            outputs=self.output_labels,
            second_order=self.second_order,
        )
