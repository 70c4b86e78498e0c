"""Which closed-loop modes carry a gust response: each one's share and its name.

The pointing budget (:mod:`rt70.telescope.pointing`) splits the main mirror's gust
variance over the modes of the loop driven by the gust filter
(:func:`rt70.linear.covariance.mode_contributions`): the filter's own modes are the
quasi-static response (the structure following the slow gusts); each loop mode is named
by the servo it belongs to or by the coordinate carrying its kinetic energy.
"""

from __future__ import annotations

from dataclasses import dataclass

import numpy as np

from rt70.linear import linearize as lin

#: How many modes the budget names.
TOP_MODES = 3


@dataclass(frozen=True)
class ModeShare:
    """One closed-loop mode's share of an output's gust variance."""

    frequency_hz: float
    damping: float
    share: float
    label: str


def mode_shares(
    augmented, outputs: list[str], rms: np.ndarray, lm: lin.Linearization, drives: list[str]
) -> tuple[list[ModeShare], float]:
    """The loop's :data:`TOP_MODES` largest shares of ``E|y|²``, and the gust filter's share.

    The augmented system is the gust filter in series with the loop, so its A is block
    triangular and its eigenvalues are the filter's and the loop's: a mode whose
    eigenvalue is one of the filter's is the quasi-static response to the wind (the
    structure following the slow gusts). The shares are those of
    :func:`rt70.linear.covariance.mode_contributions` over the outputs' components; each
    loop mode is named by :func:`mode_label`.

    Parameters
    ----------
    augmented : control.StateSpace
        The loop driven by the gust filter (:func:`rt70.telescope.pointing.gust_system`).
    outputs : list of str
        The augmented system's output names whose variance is split (one output's
        components, ``name:x`` …).
    rms : numpy.ndarray
        Each augmented state's stationary rms under the gust, in the state's unit.
    lm : rt70.linear.linearize.Linearization
        The structure's linear model (its M and coordinates name the modes).
    drives : list of str
        The drives' names (their states are ``<drive>_…``).
    """
    from rt70.linear.covariance import mode_contributions

    labels = list(augmented.state_labels)
    filt = [i for i, n in enumerate(labels) if n.startswith("filter.")]
    poles = np.linalg.eigvals(augmented.A[np.ix_(filt, filt)])
    quasi_static, loop = 0.0, []
    for m in mode_contributions(augmented, outputs):
        if np.min(np.abs(poles - m.eigenvalue)) <= 1e-9 * abs(m.eigenvalue):
            quasi_static += m.share
        else:
            loop.append(m)
    loop.sort(key=lambda m: -m.share)
    top = [
        ModeShare(
            m.frequency_hz,
            m.damping,
            m.share,
            mode_label(augmented, m, rms, lm.M, lm.coordinates, drives),
        )
        for m in loop[:TOP_MODES]
    ]
    return top, float(quasi_static)


def mode_label(
    augmented,
    mode,
    rms: np.ndarray,
    M: np.ndarray,
    coordinates: list[str],
    drives: list[str],
) -> str:
    """Name a loop mode: a servo's, or the coordinate that carries its kinetic energy.

    Which block the mode belongs to is decided on the eigenvector's entries divided by
    each state's stationary rms under the gust (so states of any unit compare; the gust
    filter's states left out): a state of one of the ``drives`` (its motor or its
    cascade, named ``<drive>_…`` by :func:`rt70.control.scene_loop.closed_loop`) makes it
    ``<drive> servo``; a structural one names it by the coordinate with the largest
    share of the mode's kinetic energy ``Re(v̇ᵢ* (M v̇)ᵢ)`` (the heavy body that moves,
    not the light one that moves most).

    Parameters
    ----------
    augmented : control.StateSpace
        The loop driven by the gust filter (:func:`gust_system`).
    mode : rt70.linear.covariance.ModeContribution
        The mode, with its eigenvector over the augmented states.
    rms : numpy.ndarray
        Each augmented state's stationary rms under the gust, in the state's unit.
    M : numpy.ndarray, shape (nv, nv)
        The structure's mass matrix.
    coordinates : list of str
        The structure's coordinates, in the order of M.
    drives : list of str
        The drives' names (their states are ``<drive>_…``).
    """
    labels = [n.removeprefix("plant.") for n in augmented.state_labels]
    loop = np.array([not n.startswith("filter.") for n in labels])
    vector = np.asarray(mode.eigenvector)
    v = np.abs(vector) / np.where(rms > 0.0, rms, np.inf)
    v[~loop] = 0.0
    name = labels[int(np.argmax(v))]
    for drive in drives:
        if name.startswith(f"{drive}_"):
            return f"{drive} servo"
    rate = np.array([vector[labels.index(f"structure_{c}_dot")] for c in coordinates])
    energy = np.real(np.conj(rate) * (M @ rate))
    return coordinates[int(np.argmax(energy))]
