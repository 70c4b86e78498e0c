"""Numbers and markdown tables shared by the sections of the book report."""

from __future__ import annotations

import numpy as np

from rt70.linear import modal


def frequencies(M: np.ndarray, K: np.ndarray) -> np.ndarray:
    """Eigenfrequencies in Hz of ``K v = ω² M v`` (rigid modes 0, unstable ones NaN)."""
    return modal.modes(M, K).freq_hz


def relative_difference(x: float, ref: float) -> str:
    """``|x − ref| / |ref|`` as text (the absolute value when ref is 0)."""
    if ref == 0.0:
        return "—" if x == 0.0 else f"{abs(x):.1e} (abs)"
    return f"{abs(x - ref) / abs(ref):.1e}"


def fixed(x: float, digits: int) -> str:
    """``x`` with ``digits`` decimals, a value that rounds to zero written ``0`` unsigned.

    A quantity zero by symmetry (the sideways sag of a structure pointed along its plane)
    comes out as ±1e-12 of rounding, whose sign another CPU or solver may flip: the
    report prints it the same either way.
    """
    text = f"{x:.{digits}f}"
    return text[1:] if text.startswith("-") and float(text) == 0.0 else text


def markdown_table(header: list[str], rows: list[list[str]]) -> str:
    """A GitHub markdown table of text cells."""
    lines = ["| " + " | ".join(header) + " |", "|" + "---|" * len(header)]
    lines += ["| " + " | ".join(r) + " |" for r in rows]
    return "\n".join(lines)


def spectrum_table(printed: list[float], reproduced: np.ndarray) -> str:
    """Printed against reproduced frequencies, mode by mode, with their relative difference."""
    rows = [
        [str(i + 1), f"{p:.4f}", f"{r:.4f}", relative_difference(round(r, 4), p)]
        for i, (p, r) in enumerate(zip(printed, reproduced, strict=True))
    ]
    return markdown_table(["mode", "printed, Hz", "reproduced, Hz", "relative difference"], rows)
