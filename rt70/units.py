"""Unit conversions, each named by its direction: ``A_PER_B`` turns a number in B into A.

Multiply by ``A_PER_B`` to go from B to A; divide by it to go back. Both directions of
the arc second have a name because both are used: ``x / ARCSEC_PER_RAD`` and
``x * RAD_PER_ARCSEC`` are the same conversion but not always the same last bit, and
every expression keeps the one it was validated with.
"""

from __future__ import annotations

import math

#: Arc seconds per radian, 180·3600/π = 206264.806… (the listing's TURNE0: KANGLE).
ARCSEC_PER_RAD = 180.0 * 3600.0 / math.pi
#: Radians per arc second, π/(180·3600) = 4.8481…e-6 (docs/drives.md, row ``*.arcsec``).
RAD_PER_ARCSEC = math.pi / (180.0 * 3600.0)
#: Arc seconds per degree.
ARCSEC_PER_DEG = 3600.0
#: Millimetres per metre (the listing's TURNE0: KRI0 = 1e3).
MM_PER_M = 1e3
