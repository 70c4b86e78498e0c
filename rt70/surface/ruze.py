"""Ruze's law: the gain a reflector's surface error costs at a wavelength.

One job: the aperture efficiency factor of a random surface error (Ruze, "Antenna
tolerance theory — a review", Proc. IEEE 54(4):633–640, 1966; spec
flexible-and-reflector.md §5),

    η_s = exp(−(4π ε / λ)²),

ε the effective RMS surface error — the weighted RMS of the half-path-length errors left
by the best-fit paraboloid (:mod:`rt70.surface.best_fit`): the phase error of a ray is
``4π h / λ``, so that RMS is the ε of the law. At 300 GHz (λ ≈ 1 mm) ε = 80 µm gives
η_s ≈ 0.36.
"""

from __future__ import annotations

import numpy as np

from rt70.errors import Rt70Error

#: The speed of light, m/s (exact, SI).
SPEED_OF_LIGHT = 299_792_458.0


def ruze_efficiency(rms: float, frequency_hz: float) -> float:
    """``exp(−(4π ε f / c)²)`` of an effective RMS surface error ``rms`` (m) at ``frequency_hz``.

    Raises
    ------
    Rt70Error
        A negative or non-finite error, or a frequency that is not positive and finite.
    """
    if not (np.isfinite(rms) and rms >= 0.0):
        raise Rt70Error(f"the RMS surface error must be ≥ 0 m, got {rms}")
    if not (np.isfinite(frequency_hz) and frequency_hz > 0.0):
        raise Rt70Error(f"the frequency must be a positive number of hertz, got {frequency_hz}")
    wavelength = SPEED_OF_LIGHT / frequency_hz
    return float(np.exp(-((4.0 * np.pi * rms / wavelength) ** 2)))
