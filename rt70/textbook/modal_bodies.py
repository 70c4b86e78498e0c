"""The modal flexible bodies in the tree: what each adds to A, B q̇, S G and the forces.

One job: couple a body of :mod:`rt70.textbook.flexible` (rigid frame motion plus modal
coordinates η, docs/fe-models.md) to the book's tree. The body rides on a pair (its
frame is the pair's body frame), so its velocities are

    w = [V_b; η̇] = W q̇,     W = [S_bᵀ; E_η],

with ``S_b`` the body's columns of the structure matrix (``V_b = S_bᵀ q̇``, (4.63)) and
``E_η`` the rows of the identity that pick its modal coordinates out of q. Its kinetic
energy ``½ wᵀ M(η) w`` and Kirchhoff–Lagrange equations ``M ẇ + h = [F; N; Q_η]``
(:mod:`rt70.textbook.flexible`) enter the tree's ``A q̈ + B q̇ = Q`` as the rigid bodies'
``Θ`` does in (4.79)–(4.81), with ``ẇ = W q̈ + [Ṡ_bᵀ q̇; 0]``:

    A   += Wᵀ M(η) W,
    B q̇ += Wᵀ (M(η) [Ṡ_bᵀ q̇; 0] + h(η, w)),
    S G += Wᵀ M(η) [c_bᵀ g0; 0; 0]                 (4.113), gravity on every node,
    Q_η −= K_η η + D_η η̇                          the modal stiffness and damping.

Each algorithm takes the bodies' frames (:class:`Frame`: orientation, position, ``S_bᵀ``
and ``Ṡ_bᵀ q̇``) from the caller's own forward pass — the dense one of
:mod:`rt70.textbook.kinematics` (:func:`dense_frames`) or the structured one — so both
forms add the same terms.
"""

from __future__ import annotations

from dataclasses import dataclass

import numpy as np

from rt70.textbook.data import Data
from rt70.textbook.flexible import body_mass_matrix, velocity_terms
from rt70.textbook.modal_model import ModalModel
from rt70.textbook.model import Model


@dataclass(frozen=True)
class Frame:
    """The body frame of a modal body at one state.

    Attributes
    ----------
    R : numpy.ndarray, shape (3, 3)
        Its orientation in the ground frame, ``c_{0b}``.
    p : numpy.ndarray, shape (3,)
        Its origin in the ground frame, m.
    J : numpy.ndarray, shape (6, nv)
        ``S_bᵀ``: its velocity ``[v; ω]`` in its own axes is ``J q̇``.
    bias : numpy.ndarray, shape (6,)
        ``Ṡ_bᵀ q̇``: the part of its acceleration not from q̈ (zero without a velocity).
    """

    R: np.ndarray
    p: np.ndarray
    J: np.ndarray
    bias: np.ndarray


def dense_frames(model: Model, data: Data, qd: np.ndarray | None = None) -> list[Frame]:
    """The modal bodies' frames from the dense forward pass already in ``data``.

    Parameters
    ----------
    model : Model
        The textbook model.
    data : Data
        Its work buffers with R, p and S of the configuration
        (:func:`rt70.textbook.kinematics.update_structure`), and ``S_dot`` of the state
        when ``qd`` is given (:func:`rt70.textbook.dynamics.structure_matrix_rate`).
    qd : numpy.ndarray, shape (nv,), optional
        The velocities; None: the frames' ``bias`` is zero.
    """
    frames = []
    for mb in model.modal:
        b = mb.body
        if b < 0:
            frames.append(Frame(np.eye(3), np.zeros(3), np.zeros((6, model.nv)), np.zeros(6)))
            continue
        block = slice(6 * b, 6 * b + 6)
        bias = np.zeros(6) if qd is None else data.S_dot[:, block].T @ qd
        frames.append(Frame(data.R[b], data.p[b], data.S[:, block].T, bias))
    return frames


def _w_map(model: Model, mb: ModalModel, frame: Frame) -> np.ndarray:
    """``W = [S_bᵀ; E_η]``, (6 + k, nv)."""
    E = np.zeros((mb.modes, model.nv))
    E[np.arange(mb.modes), np.arange(mb.coords.start, mb.coords.stop)] = 1.0
    return np.vstack([frame.J, E])


def mass_matrix_terms(model: Model, frames: list[Frame], q: np.ndarray) -> np.ndarray:
    """``Σ Wᵀ M(η) W`` over the modal bodies, (nv, nv) (module docstring).

    Parameters
    ----------
    model : Model
        The textbook model.
    frames : list of Frame
        The bodies' frames at ``q``, in the order of ``model.modal``.
    q : numpy.ndarray, shape (nv,)
        Generalised coordinates, rad or m (the modal ones dimensionless or as the file's).
    """
    A = np.zeros((model.nv, model.nv))
    for mb, frame in zip(model.modal, frames, strict=True):
        W = _w_map(model, mb, frame)
        A += W.T @ body_mass_matrix(mb.invariants, q[mb.coords]) @ W
    return A


def bias_terms(model: Model, frames: list[Frame], q: np.ndarray, qd: np.ndarray) -> np.ndarray:
    """``Σ Wᵀ (M(η) [Ṡ_bᵀ q̇; 0] + h(η, W q̇))``, (nv,) (module docstring).

    Parameters
    ----------
    model : Model
        The textbook model.
    frames : list of Frame
        The bodies' frames at ``(q, q̇)`` (their ``bias`` set).
    q, qd : numpy.ndarray, shape (nv,)
        Generalised coordinates and velocities.
    """
    out = np.zeros(model.nv)
    for mb, frame in zip(model.modal, frames, strict=True):
        W = _w_map(model, mb, frame)
        eta = q[mb.coords]
        accel = np.concatenate([frame.bias, np.zeros(mb.modes)])
        M = body_mass_matrix(mb.invariants, eta)
        out += W.T @ (M @ accel + velocity_terms(mb.invariants, eta, W @ qd, M))
    return out


def gravity_terms(model: Model, frames: list[Frame], q: np.ndarray) -> np.ndarray:
    """``Σ Wᵀ M(η) [c_bᵀ g0; 0; 0]``: gravity on the bodies' nodes, (nv,).

    Parameters
    ----------
    model : Model
        The textbook model.
    frames : list of Frame
        The bodies' frames at ``q``.
    q : numpy.ndarray, shape (nv,)
        Generalised coordinates.
    """
    out = np.zeros(model.nv)
    for mb, frame in zip(model.modal, frames, strict=True):
        W = _w_map(model, mb, frame)
        accel = np.zeros(6 + mb.modes)
        accel[:3] = frame.R.T @ model.gravity
        out += W.T @ (body_mass_matrix(mb.invariants, q[mb.coords]) @ accel)
    return out


def gravity_potential(model: Model, frames: list[Frame], q: np.ndarray) -> float:
    """``−g0 · Σ m_n (p_b + c_{0b} r_n)`` of the bodies' nodes, J.

    Parameters
    ----------
    model : Model
        The textbook model.
    frames : list of Frame
        The bodies' frames at ``q``.
    q : numpy.ndarray, shape (nv,)
        Generalised coordinates.
    """
    total = 0.0
    for mb, frame in zip(model.modal, frames, strict=True):
        inv = mb.invariants
        first = inv.first + inv.first_modal @ q[mb.coords]  # Σ m_n r_n
        total -= float(model.gravity @ (inv.mass * frame.p + frame.R @ first))
    return total


def elastic_force(model: Model, q: np.ndarray, qd: np.ndarray) -> tuple[np.ndarray, np.ndarray]:
    """``(−K_η η, −D_η η̇)`` of every modal body on its coordinates, each (nv,).

    Parameters
    ----------
    model : Model
        The textbook model.
    q, qd : numpy.ndarray, shape (nv,)
        Generalised coordinates and velocities.
    """
    Qc, Qd = np.zeros(model.nv), np.zeros(model.nv)
    for mb in model.modal:
        Qc[mb.coords] = -mb.stiffness @ q[mb.coords]
        Qd[mb.coords] = -mb.damping @ qd[mb.coords]
    return Qc, Qd


def elastic_potential(model: Model, q: np.ndarray) -> float:
    """``Σ ½ ηᵀ K_η η``, J."""
    return float(sum(0.5 * q[mb.coords] @ mb.stiffness @ q[mb.coords] for mb in model.modal))


def frame_wrenches(
    model: Model,
    frames: list[Frame],
    q: np.ndarray,
    qd: np.ndarray,
    qdd: np.ndarray,
    gravity: bool = True,
) -> list[tuple[int, np.ndarray]]:
    """What each modal body needs from its frame: ``[F; N]``, its frame rows of ``M ẇ + h − G``.

    The wrench the body's pair exerts on the body (frame axes, about its origin) to move
    it with ``ẇ = W q̈ + [Ṡ_bᵀ q̇; 0]``: the first six rows of the body's equations
    (:mod:`rt70.textbook.flexible`). The reactions add it to the pair's own body
    wrench (source 004 (9)–(10)).

    Parameters
    ----------
    model : Model
        The textbook model.
    frames : list of Frame
        The bodies' frames at the state (their ``bias`` set when ``q̇ ≠ 0``).
    q, qd, qdd : numpy.ndarray, shape (nv,)
        Generalised coordinates, velocities and accelerations.
    gravity : bool
        Include the nodes' weights.

    Returns
    -------
    list of (int, numpy.ndarray)
        Each body's pair (−1: the ground) and the wrench, (6,).
    """
    out = []
    for mb, frame in zip(model.modal, frames, strict=True):
        W = _w_map(model, mb, frame)
        eta = q[mb.coords]
        M = body_mass_matrix(mb.invariants, eta)
        accel = W @ qdd
        accel[:6] += frame.bias
        if gravity:
            accel[:3] -= frame.R.T @ model.gravity
        wrench = M @ accel + velocity_terms(mb.invariants, eta, W @ qd, M)
        out.append((mb.body, wrench[:6]))
    return out
