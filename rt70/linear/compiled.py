"""Linear models of large scenes from the compiled kernels, without any nv³ workspace.

Above :data:`LARGE_NV` coordinates the dense textbook form (L and S, O(nb²) products)
and Pinocchio's ``Data`` (four ``nv³`` tensors: 100 GB at nv = 1000) are the wall, not
the arithmetic. :func:`rt70.linear.linearize.equilibrium` and
:func:`~rt70.linear.linearize.linearize` then take their forces and matrices from the
compiled kernels of the book's model, which hold O(nb) work arrays and produce each
matrix in O(nv²):

- the static force ``Q_g + Q_c``, and ``K = −∂(Q_g + Q_c)/∂q`` with its gravity part:
  gravity's exact, each bushing's by central differences over its own path
  (:mod:`rt70.textbook.static_kernel`);
- ``M = A(q0)`` (4.79) from the mass kernel (:mod:`rt70.textbook.mass_kernel`);
- ``D = Σ Jᵀ D J`` exact (:func:`rt70.textbook.static_kernel.element_gains`).

The kernels compute the same quantities as the textbook side's readable form: the tests
hold them equal on every scene they cover and on random trees, and hold the whole linear
model and its modes equal to the standard path (which differences Pinocchio's forces) on
a chain that Pinocchio can hold. A scene the kernels do not cover (modal bodies, mimic joints,
closed loops) keeps the standard path at any size.
"""

from __future__ import annotations

from dataclasses import dataclass

import numpy as np

from rt70.model.scene import Scene

#: From this many coordinates on, a scene the kernels cover is linearised by them.
LARGE_NV = 200

#: Finite-difference step of the stiffness matrix (as rt70.linear.linearize.FD_STEP).
FD_STEP = 1e-6


@dataclass
class Kernels:
    """The compiled static forces and mass matrix of one scene (:func:`kernels_for`)."""

    scene: Scene

    def static_force(self, q: np.ndarray) -> np.ndarray:
        """``Q_g + Q_c`` at rest, N or N·m per coordinate."""
        from rt70.textbook.static_kernel import static_force

        return static_force(self.scene.textbook, self.scene.static_kernels, q)

    def stiffness_matrix(self, q: np.ndarray) -> np.ndarray:
        """``−∂(Q_g + Q_c)/∂q``, symmetrised."""
        return self._stiffness(q)[0]

    def _stiffness(self, q: np.ndarray) -> tuple[np.ndarray, np.ndarray]:
        from rt70.textbook.static_kernel import stiffness_matrices

        return stiffness_matrices(self.scene.textbook, self.scene.static_kernels, q, FD_STEP)

    def matrices(self, q: np.ndarray) -> tuple[np.ndarray, np.ndarray, np.ndarray, np.ndarray]:
        """``(M, K, D, K_gravity)`` at ``q``, over all coordinates (m, rad)."""
        from rt70.textbook import mass_kernel
        from rt70.textbook.static_kernel import element_gains

        model = self.scene.textbook
        M = mass_kernel.mass_matrix(model, mass_kernel.KernelData(model), q)
        D = element_gains(model, self.scene.static_kernels, q)[1]
        K, K_gravity = self._stiffness(q)
        return M, K, D, K_gravity


def kernels_for(scene: Scene) -> Kernels | None:
    """The compiled path for ``scene`` if it is large and covered (module docstring), else None."""
    if scene.textbook.nv < LARGE_NV or scene.description.loops:
        return None
    return None if scene.static_kernels is None else Kernels(scene)
