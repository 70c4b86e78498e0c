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
