"""The test problems of the work–precision report: scenes, initial states, spans.

Problems
--------
``rt70``
    ``urdf/rt70.urdf`` from the §4.2.3 listing's initial state over ``T = 2 s`` with the
    listing's damping (mostly 0.1 × stiffness; ξ = 0.105 on the first elastic mode).
``rt70_10s``
    The RT-70 problem of the speed targets, what ``rt70 simulate rt70 --t-end 10`` runs: the
    same scene and state over ``T = 10 s`` with the axes free (the structural
    benchmark). The target problem of the simulation-speed targets
    (:mod:`rt70.reports.simulation_targets`); only the stiff methods run on it (the
    explicit ones are over the cap on the 2 s span already) and only the tolerances
    of the targets' ladder, 1e-4 … 1e-8.
``rt70_light``
    The same scene with every damping replaced by ``δ · stiffness``, δ = 0.1/Ω1 (the
    book's rule (2.16), ξ = 0.05 on the first elastic mode; :func:`light_damping_text`),
    same state and span. Ω1 is the first elastic eigenfrequency of the linear model at
    the static equilibrium with the drives holding the listing's pointing
    (``platform_rz = base_rx = 0.8 rad``) and the two axes locked
    (:func:`first_elastic_mode`). The pointing matters (Ω1 = 1.91 rad/s at the zenith,
    2.10 rad/s at the listing's pointing); the run starts at the listing's pointing, so
    Ω1 is taken there. Locking the axes removes the rigid azimuth mode and gravity's
    unstable elevation mode, which are not resonances of the structure.
``double_pendulum``
    ``urdf/double_pendulum.urdf`` (no springs) from ``q = (1.0, −0.5) rad``, ``q̇ = 0``
    over 5 s. q = 0 is the arm stretched horizontally (gravity along −y), so this is a
    large, chaotic swing.
``chain``
    ``serial_chain(50)`` (50 revolute joints, about 40 % of them with springs) from
    ``q`` uniform in ±0.3 rad (seed 1), ``q̇ = 0``, over 1 s: the long, non-stiff chain
    (``elastic_chain(20)`` is as stiff as the RT-70 and would add nothing). Over 2 s the
    chain whips (``|q̇|`` up to 75 rad/s) and is chaotic enough that the errors of all loose
    tolerances saturate at O(1) and the two references part to 2e-9; over 1 s they agree
    to 5e-12.

Both RT-70 problems are stiff (damped eigenvalues down to −4·10⁵ s⁻¹): the explicit
methods need steps of a few µs there and cannot finish within the time cap.
"""

from __future__ import annotations

import math
import xml.etree.ElementTree as ET
from dataclasses import dataclass

import numpy as np

from rt70.errors import Rt70Error

#: Points of the output grid on which runs are compared.
N_EVAL = 201


@dataclass(frozen=True)
class Problem:
    """One test problem.

    Attributes
    ----------
    name : str
        Key of the problem (``rt70``, ``rt70_light``, ``double_pendulum``, ``chain``).
    t_end : float
        The span is ``(0, t_end)``, s.
    references : (str, str)
        Primary and alternate reference methods: a run of the primary method is
        measured against the alternate one, every other run against the primary.
    reference_atol : float or None
        ``atol`` of the reference runs (None: the default of
        :func:`~rt70.simulation.simulate.simulate`).
    chain_bodies : int
        Bodies of the chain (``chain`` only).
    stiff_only : bool
        Run only the implicit methods on it (the explicit ones cannot finish in the cap).
    rtols : tuple of float, optional
        The tolerance ladder of this problem (None: the report's).
    """

    name: str
    t_end: float
    references: tuple[str, str]
    reference_atol: float | None = None
    chain_bodies: int = 50
    stiff_only: bool = False
    rtols: tuple[float, ...] | None = None

    @property
    def t_eval(self) -> np.ndarray:
        """The output grid shared by all runs."""
        return np.linspace(0.0, self.t_end, N_EVAL)

    def reference_for(self, method: str) -> str:
        """The reference method for runs of ``method`` (never ``method`` itself)."""
        primary, alternate = self.references
        return alternate if method == primary else primary


_STIFF_REFS = ("Radau", "BDF")
_SMOOTH_REFS = ("DOP853", "LSODA")
#: The tolerances of the simulation-speed targets' ladder (rtol 1e-4 … 1e-8).
ISSUE13_RTOLS = tuple(10.0**-k for k in range(4, 9))
#: The full report's problems.
PROBLEMS = (
    Problem("rt70_10s", 10.0, _STIFF_REFS, 1e-12, stiff_only=True, rtols=ISSUE13_RTOLS),
    Problem("rt70", 2.0, _STIFF_REFS, 1e-12),
    Problem("rt70_light", 2.0, _STIFF_REFS, 1e-12),
    Problem("double_pendulum", 5.0, _SMOOTH_REFS),
    Problem("chain", 1.0, _SMOOTH_REFS, chain_bodies=50),
)
#: Problems of the quick run (tests): short spans, a 10-body chain.
QUICK_PROBLEMS = (
    Problem("rt70", 0.05, _STIFF_REFS, 1e-12),
    Problem("double_pendulum", 1.0, _SMOOTH_REFS),
    Problem("chain", 0.5, _SMOOTH_REFS, chain_bodies=10),
)


def listing_pointing(scene) -> dict[str, float]:
    """The RT-70 drive coordinates held at the listing's initial values (rad)."""
    from rt70.scenes.rt70_state import (
        AZIMUTH_COORDINATE,
        ELEVATION_COORDINATE,
        listing_initial_state,
    )

    q0, _ = listing_initial_state(scene)
    names = scene.textbook.coordinate_names
    axes = (AZIMUTH_COORDINATE, ELEVATION_COORDINATE)
    return {c: float(q0[names.index(c)]) for c in axes}


def first_elastic_mode(scene) -> tuple[float, float]:
    """Ω1 (rad/s) and its ξ of the RT-70 linearised at the listing's pointing, axes locked.

    The drives hold ``platform_rz`` and ``base_rx`` at the listing's initial values
    (:func:`listing_pointing`), the static equilibrium of the other coordinates is
    solved (:func:`rt70.linear.linearize.equilibrium`), the linear model is taken there
    with the two axes locked (:func:`rt70.linear.linearize.linearize`) and Ω1 is its
    lowest elastic eigenfrequency (:func:`rt70.linear.modal.modes`).

    Parameters
    ----------
    scene : Scene
        An RT-70 scene (``rt70.urdf`` or an edited copy).

    Returns
    -------
    omega1 : float
        Ω1, rad/s.
    zeta1 : float
        Damping ratio of that mode (``(VᵀDV)₁₁ / 2Ω1``).
    """
    from rt70.linear import linearize as lin
    from rt70.linear import modal

    held = listing_pointing(scene)
    model = lin.linearize(scene, lin.equilibrium(scene, held), locked=tuple(held))
    result = modal.modes(model.M, model.K, model.D)
    first = np.flatnonzero(result.elastic)[0]
    return float(result.omega[first]), float(result.zeta[first])


def light_damping_text(text: str, delta: float) -> str:
    """URDF text with every damping replaced by ``delta · stiffness``.

    Every rt70 element carrying a ``stiffness`` attribute (``<rt70:bushing>``,
    ``<rt70:strut>``, ``<rt70:joint_spring>``) gets ``damping = delta · stiffness``,
    component by component (the book's proportional damping ``D = δ C``, (2.16)).

    Parameters
    ----------
    text : str
        URDF text.
    delta : float
        δ, s (non-negative).

    Returns
    -------
    str
        The edited URDF text (comments dropped).
    """
    from rt70.scenes.urdf_writer import fmt_vec
    from rt70.urdf import RT70_NS

    if not (math.isfinite(delta) and delta >= 0.0):
        raise Rt70Error(f"damping factor δ must be finite and non-negative, got {delta}")
    ET.register_namespace("rt70", RT70_NS)
    root = ET.fromstring(text)
    for elem in root.iter():
        if isinstance(elem.tag, str) and elem.tag.startswith("{" + RT70_NS + "}"):
            stiffness = elem.get("stiffness")
            if stiffness is not None:
                k = np.array(stiffness.split(), dtype=float)
                elem.set("damping", fmt_vec(delta * k))
    return '<?xml version="1.0"?>\n' + ET.tostring(root, encoding="unicode") + "\n"


def build_problem(problem: Problem) -> tuple[object, tuple[np.ndarray, np.ndarray], str]:
    """The scene, initial state and a one-line description of a problem.

    Returns
    -------
    scene : Scene
    x0 : (q0, q̇0)
    notes : str
    """
    from rt70.model.scene import load_scene, scene_from_text
    from rt70.scenes import synthetic
    from rt70.scenes.rt70_state import listing_initial_state

    T = f"T = {problem.t_end:g} s"
    if problem.name == "rt70":
        scene = load_scene("rt70")
        return scene, listing_initial_state(scene), f"listing state and damping, {T}"
    if problem.name == "rt70_10s":
        scene = load_scene("rt70")
        notes = f"`rt70 simulate rt70 --t-end 10`: listing state and damping, axes free, {T}"
        return scene, listing_initial_state(scene), notes
    if problem.name == "rt70_light":
        from rt70.linear.topology import book_delta

        base = load_scene("rt70")
        omega1, zeta0 = first_elastic_mode(base)
        delta = book_delta(omega1)
        scene = scene_from_text(light_damping_text(base.text, delta), "rt70_light")
        _, zeta1 = first_elastic_mode(scene)
        notes = (
            f"listing state; damping = δ·stiffness, δ = 0.1/Ω1 = {delta:.4g} s "
            f"(Ω1 = {omega1:.4g} rad/s; ξ1 = {zeta1:.3f}, listing's {zeta0:.3f}), {T}"
        )
        return scene, listing_initial_state(scene), notes
    if problem.name == "double_pendulum":
        scene = load_scene("double_pendulum")
        return scene, (np.array([1.0, -0.5]), np.zeros(2)), f"q = (1, -0.5) rad, q̇ = 0, {T}"
    if problem.name == "chain":
        n = problem.chain_bodies
        scene = scene_from_text(synthetic.serial_chain(n), f"chain_{n}")
        q0 = np.random.default_rng(1).uniform(-0.3, 0.3, scene.textbook.nv)
        notes = f"serial_chain({n}), q uniform in ±0.3 rad (seed 1), q̇ = 0, {T}"
        return scene, (q0, np.zeros(scene.textbook.nv)), notes
    raise Rt70Error(f"unknown work-precision problem '{problem.name}'")
