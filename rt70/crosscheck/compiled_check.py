"""The compiled kernels' rows of ``rt70 validate``: the large-model path against Pinocchio.

A scene the kernels of :mod:`rt70.textbook.static_kernel` cover (rigid pairs, bushings,
joint springs; :attr:`rt70.model.scene.Scene.static_kernels` is not None) is linearised
by them from :data:`rt70.linear.compiled.LARGE_NV` coordinates on. So that a user's own
model is checked on the path its large version will take, ``rt70 validate`` compares them
with Pinocchio at each sampled state:

- ``compiled_static``: the kernel's static force ``Q_g + Q_c`` at q (rest) against
  Pinocchio's gravity and spring force at rest, on the scale of gravity's weight moment
  plus the springs' terms (:func:`rt70.reference.spring_damper_magnitudes`);
- ``compiled_damping``: ``D q̇`` with the kernel's ``D = Σ Jᵀ D J`` against minus
  Pinocchio's damper force at (q, q̇), on the scale of the dampers' terms;
- ``compiled_dynamics``: the residual ``A q̈ + B q̇ − Q_g − Q_c − Q_d`` of
  :mod:`rt70.textbook.motion_kernel` (what ``--method generalized-alpha`` integrates)
  against Pinocchio's ``A q̈ + B q̇ − Q_g`` (CRBA and RNEA) less its spring and damper
  force, with q̈ taken equal to the sampled q̇'s numbers (so that A is in it), on the
  scale of the static row's terms plus the dampers' and the residual's own size.

The textbook column of these rows times the compiled kernels.
"""

from __future__ import annotations

from collections.abc import Callable

import numpy as np

from rt70.model.scene import Scene

#: Rows compared for a scene the kernels cover, after the others.
ROWS = ("compiled_static", "compiled_damping", "compiled_dynamics")

#: Their units, as :data:`rt70.crosscheck.validate.QUANTITY_UNITS` states them.
UNITS = {
    "compiled_static": "N·m or N (per coordinate)",
    "compiled_damping": "N·m or N (per coordinate)",
    "compiled_dynamics": "N·m or N (per coordinate)",
}


def compiled_quantities(scene: Scene) -> tuple[str, ...]:
    """:data:`ROWS` if the kernels cover the scene, else none."""
    return ROWS if scene.static_kernels is not None else ()


def compiled_pairs(
    scene: Scene, q: np.ndarray, qd: np.ndarray
) -> dict[str, tuple[Callable, Callable]]:
    """(compiled, reference) evaluations of :data:`ROWS` at (q, q̇); empty if not covered.

    Parameters
    ----------
    scene : Scene
        The scene compared.
    q : numpy.ndarray, shape (nv,)
        The sampled coordinates, rad or m.
    qd : numpy.ndarray, shape (nv,)
        The sampled velocities, rad/s or m/s.
    """
    if not compiled_quantities(scene):
        return {}
    from rt70 import reference
    from rt70.textbook import motion_kernel, static_kernel

    tm, data = scene.textbook, scene.static_kernels
    ref, rd = scene.reference, scene.reference_data
    rest = np.zeros_like(qd)
    # numba loads the kernels' cached code on their first call in a process: called once
    # here, so that the timed calls time the computation, not the loading
    static_kernel.static_force(tm, data, q)
    static_kernel.element_gains(tm, data, q)
    motion = motion_kernel.MotionData(data)
    motion_kernel.residual(tm, motion, q, qd, qd)

    def ref_static() -> np.ndarray:
        springs = reference.spring_damper_force(ref, rd, q, rest)[0]
        return reference.gravity_force(ref, rd, q) + springs

    return {
        "compiled_static": (lambda: static_kernel.static_force(tm, data, q), ref_static),
        "compiled_damping": (
            lambda: static_kernel.element_gains(tm, data, q)[1] @ qd,
            lambda: -reference.spring_damper_force(ref, rd, q, qd)[1],
        ),
        "compiled_dynamics": (
            lambda: motion_kernel.residual(tm, motion, q, qd, qd)[0],
            lambda: _pinocchio_residual(scene, q, qd),
        ),
    }


def _pinocchio_residual(scene: Scene, q: np.ndarray, qd: np.ndarray) -> np.ndarray:
    """Pinocchio's ``A q̈ + B q̇ − Q_g − Q_c − Q_d`` at q̈ = q̇'s numbers (module docstring)."""
    from rt70 import reference

    ref, rd = scene.reference, scene.reference_data
    Qc, Qd = reference.spring_damper_force(ref, rd, q, qd)
    inertial = reference.mass_matrix(ref, rd, q) @ qd + reference.bias_force(ref, rd, q, qd)
    return inertial - reference.gravity_force(ref, rd, q) - Qc - Qd


def compiled_scales(values: dict, g0: float, Sc: np.ndarray, Sd: np.ndarray) -> dict:
    """The rows' natural scales (module docstring), for those in ``values``.

    Parameters
    ----------
    values : dict
        Every row's ``(textbook value, reference value)`` at the state.
    g0 : float
        Gravity's weight moment at the state (:func:`rt70.reference.weight_moment`).
    Sc, Sd : numpy.ndarray
        The springs' and dampers' term magnitudes (:func:`rt70.reference.spring_damper_magnitudes`).
    """
    if ROWS[0] not in values:
        return {}
    static = g0 + float(np.max(Sc, initial=0.0)) + float(np.max(np.abs(values[ROWS[0]][1])))
    damping = float(np.max(Sd, initial=0.0))
    dynamics = static + damping + float(np.max(np.abs(values[ROWS[2]][1]), initial=0.0))
    return {ROWS[0]: static, ROWS[1]: damping, ROWS[2]: dynamics}
