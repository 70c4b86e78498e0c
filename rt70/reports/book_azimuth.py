"""The azimuth model (§2.3) of the book report: not reproduced, and why.

The printed spectrum against the printed tables; a search over single and paired slips
of the data (re-wirings, swaps, 90° values), tried as a diagnosis only (the data are kept
as printed); and the tree invariant (:mod:`rt70.linear.tree_invariant`) that proves no
re-wiring or swap can reproduce it.
"""

from __future__ import annotations

import itertools
import math
from collections.abc import Callable
from dataclasses import dataclass

import numpy as np
import scipy.linalg

from rt70.linear import tree_invariant
from rt70.reports.book_format import (
    frequencies,
    markdown_table,
    spectrum_table,
)
from rt70.scenes import rt70_chapter2, rt70_data


@dataclass(frozen=True)
class Edit:
    """A hypothetical single change of the azimuth data, tried only as a diagnosis."""

    label: str
    apply: Callable[[np.ndarray, np.ndarray, np.ndarray], tuple]  # (inertia, C, Γ) → same


def _azimuth_edits() -> list[Edit]:
    names = [n["name"] for n in rt70_data.AZIMUTH_NODES]
    I90 = np.array([n["I_el90"] for n in rt70_data.AZIMUTH_NODES])
    C90 = np.array([c["C_el90"] for c in rt70_data.AZIMUTH_LINKS])
    edits = []
    for s in range(6):
        for i, j in itertools.combinations(range(7), 2):

            def rewire(inertia, C, G, s=s, i=i, j=j):
                G = G.copy()
                G[s] = 0.0
                G[s, i], G[s, j] = -1.0, 1.0
                return inertia, C, G

            edits.append(Edit(f"link {s + 1} joins {names[i]}–{names[j]}", rewire))
    for a, b in itertools.combinations(range(7), 2):

        def swap_i(inertia, C, G, a=a, b=b):
            inertia = inertia.copy()
            inertia[[a, b]] = inertia[[b, a]]
            return inertia, C, G

        edits.append(Edit(f"I of {names[a]} and {names[b]} swapped", swap_i))
    for a, b in itertools.combinations(range(6), 2):

        def swap_c(inertia, C, G, a=a, b=b):
            C = C.copy()
            C[[a, b]] = C[[b, a]]
            return inertia, C, G

        edits.append(Edit(f"C of links {a + 1} and {b + 1} swapped", swap_c))
    for k in range(7):

        def take_i(inertia, C, G, k=k):
            inertia = inertia.copy()
            inertia[k] = I90[k]
            return inertia, C, G

        edits.append(Edit(f"I of {names[k]} from the 90° column", take_i))
    for k in range(6):

        def take_c(inertia, C, G, k=k):
            C = C.copy()
            C[k] = C90[k]
            return inertia, C, G

        edits.append(Edit(f"C of link {k + 1} from the 90° column", take_c))
    return edits


def _rounding_bound(freq_hz: list[float] | np.ndarray, decimals: int = 4) -> float:
    """First-order bound on the relative error of ``Π(2πf)²`` from printing f to ``decimals``."""
    f = np.asarray(freq_hz, dtype=float)
    f = f[f > 0]
    return float(np.sum(2 * 0.5 * 10.0**-decimals / f))


def _single_value_fits(
    target: float, inertia: np.ndarray, C: np.ndarray
) -> list[tuple[str, int, float | None]]:
    """For each single inertia or stiffness, the one value giving the product ``target``.

    With the others fixed, ``ΠC·ΣI/ΠI`` is proportional to ``C_s``, and for ``I_k = x``
    it is ``ΠC (S + x) / (P x)`` (S, P: sum and product of the other inertias), which is
    ``target`` at ``x = ΠC·S / (target·P − ΠC)`` — no positive x when ``target·P ≤ ΠC``.
    Returns ``(kind, index, value or None)`` with kind ``"I"`` or ``"C"``.
    """
    now = tree_invariant.free_tree_omega2_product(inertia, C)
    fits: list[tuple[str, int, float | None]] = []
    for k in range(len(inertia)):
        others = np.delete(inertia, k)
        pc, rest_sum, rest_prod = np.prod(C), others.sum(), np.prod(others)
        den = target * rest_prod - pc
        fits.append(("I", k, float(pc * rest_sum / den) if den > 0 else None))
    fits += [("C", s, float(C[s] * target / now)) for s in range(len(C))]
    return fits


def _invariant_text(
    printed: np.ndarray,
    spectrum: Callable[[np.ndarray, np.ndarray], np.ndarray],
    dev: Callable[[np.ndarray], float],
) -> tuple[str, dict]:
    """The sub-section proving what the search above could only sample."""
    n, rows = _invariant_numbers(printed)
    fit_table, best = _single_value_table(n["printed"], spectrum, dev)
    numbers = {
        "printed": n["printed"],
        "tables_0": n["tables_0"],
        "tables_90": n["tables_90"],
        "ratio_0": n["ratio_0"],
        "ratio_90": n["ratio_90"],
        "rounding_bound": n["rounding_bound"],
        "elevation_ratio": n["elevation_ratio"],
        "elevation_bound": n["elevation_bound"],
        "best_single_value": best,
    }
    return _proof_text(n, rows, fit_table, best), numbers


def _azimuth_columns() -> dict[str, tuple[np.ndarray, np.ndarray]]:
    """Per elevation column of Tables 2.1–2.2 (``"0"``, ``"90"``): (inertias, stiffnesses)."""
    d = rt70_data
    return {
        key: (
            np.array([n[f"I_el{key}"] for n in d.AZIMUTH_NODES]),
            np.array([c[f"C_el{key}"] for c in d.AZIMUTH_LINKS]),
        )
        for key in rt70_chapter2.AZIMUTH_ELEVATIONS
    }


def _invariant_numbers(printed: np.ndarray) -> tuple[dict, list[list[str]]]:
    """The products ``Π ω²`` of the printed spectrum and of the tables, and their table rows.

    Returns the numbers of the sub-section (the keys of :func:`_invariant_text`'s second
    value, and ``eig_check``: the 0° model's ``eigh`` product against the invariant) and
    the rows of its table of products.
    """
    cols = _azimuth_columns()
    p_printed = tree_invariant.printed_omega2_product(printed)
    invariants = {}
    rows = [["printed spectrum, Π(2πf)² over its six non-zero f", f"{p_printed:.5e}", "1"]]
    for label, i_key, c_key in (
        ("Tables 2.1–2.2, 0° columns (the printed spectrum's elevation)", "0", "0"),
        ("Tables 2.1–2.2, 90° columns", "90", "90"),
        ("inertias 0°, stiffnesses 90°", "0", "90"),
        ("inertias 90°, stiffnesses 0°", "90", "0"),
    ):
        value = tree_invariant.free_tree_omega2_product(cols[i_key][0], cols[c_key][1])
        invariants[(i_key, c_key)] = value
        rows.append([label, f"{value:.5e}", f"{p_printed / value:.4g}"])
    m0 = rt70_chapter2.azimuth_model("0")
    w = np.sort(scipy.linalg.eigh(m0.C, m0.m, eigvals_only=True))
    e_printed = tree_invariant.printed_omega2_product(rt70_data.ELEVATION_SPECTRUM_HZ)
    numbers = {
        "printed": p_printed,
        "tables_0": invariants[("0", "0")],
        "tables_90": invariants[("90", "90")],
        "ratio_0": p_printed / invariants[("0", "0")],
        "ratio_90": p_printed / invariants[("90", "90")],
        "rounding_bound": _rounding_bound(printed),
        "elevation_ratio": e_printed
        / tree_invariant.model_omega2_product(rt70_chapter2.elevation_model()),
        "elevation_bound": _rounding_bound(rt70_data.ELEVATION_SPECTRUM_HZ),
        "eig_check": abs(float(np.prod(w[1:])) / tree_invariant.model_omega2_product(m0) - 1),
    }
    return numbers, rows


def _single_value_table(
    p_printed: float,
    spectrum: Callable[[np.ndarray, np.ndarray], np.ndarray],
    dev: Callable[[np.ndarray], float],
) -> tuple[str, float]:
    """The table of single changed values giving the printed product, and the best deviation."""
    d = rt70_data
    names = [n["name"] for n in d.AZIMUTH_NODES]
    inertia, C = _azimuth_columns()["0"]
    fit_rows, fit_devs = [], []
    for kind, k, value in _single_value_fits(p_printed, inertia, C):
        link = d.AZIMUTH_LINKS[k]["name"] if kind == "C" else ""
        what = f"I of {names[k]}" if kind == "I" else f"C of link {k + 1} ({link})"
        was = inertia[k] if kind == "I" else C[k]
        if value is None:
            fit_rows.append([what, f"{was:.4e}", "none (no positive value)", "—"])
            continue
        i2, c2 = inertia.copy(), C.copy()
        (i2 if kind == "I" else c2)[k] = value
        fit_devs.append(dev(spectrum(i2, c2)))
        fit_rows.append([what, f"{was:.4e}", f"{value:.4e}", f"{fit_devs[-1]:.1%}"])
    fit_header = ["value changed", "0° table", "value giving the printed product", "max deviation"]
    return markdown_table(fit_header, fit_rows), min(fit_devs)


def _proof_text(n: dict, rows: list[list[str]], fit_table: str, best: float) -> str:
    """The sub-section's text from :func:`_invariant_numbers` and the single-value table."""
    bound, e_ratio, e_bound = n["rounding_bound"], n["elevation_ratio"], n["elevation_bound"]
    ratio0, ratio90 = n["ratio_0"], n["ratio_90"]
    shortfall = f"{ratio0 - 1:.1%}".replace("-", "−")
    eig_check = n["eig_check"]
    eig_agrees = "to within 1e-12" if eig_check <= 1e-12 else f"only to {eig_check:.1e}"
    n_trees = 7 ** (7 - 2)  # Cayley: labelled trees on 7 bodies
    n_models = n_trees * math.factorial(6)  # a tree and an order of the six stiffnesses
    return f"""### A proof instead of a search: the product of the ω²

**Theorem** ([`docs/tree-invariant.md`](../../docs/tree-invariant.md),
`rt70.linear.tree_invariant`, tested against `eigh` on random trees). For n bodies of
inertias I_k on one axis joined by n − 1 torsion springs C_s that form a tree with no
link to the ground (K = Γᵀ diag(C) Γ, Γ one −1 and one +1 per row), the spectrum of
K v = ω² M v has one zero and

    Π ω² (over the n − 1 non-zero modes) = ΠC · ΣI / ΠI,

whatever the wiring: by Cauchy–Binet the product is ΠC · Σ_k det(Γ_(k))² I_k / ΠI, and
every Γ_(k) (Γ without column k) of a tree has determinant ±1 — the weighted
matrix-tree theorem (Kirchhoff). The book's azimuth model is such a tree (Γα has one −1
and one +1 per row, six links joining all seven bodies, none to the ground; checked by
`free_tree_check`), so the theorem applies as printed; were a row scaled by a ratio r_s
(a gear or lever), C_s would become r_s² C_s. The unit cancels (I and C scale alike).

| | Π ω², s⁻¹² | printed / this |
|---|---|---|
{chr(10).join("| " + " | ".join(r) + " |" for r in rows)}

(`eigh` of the 0° model gives the same product {eig_agrees}.) Printing each
frequency to four decimals moves the printed product by at most ±{bound:.1e} (relative,
first order). As a control, the elevation model, whose spectrum *is* reproduced, gives
printed / tables = 1 {"+" if e_ratio >= 1 else "−"} {abs(e_ratio - 1):.1e}, inside its
rounding bound ±{e_bound:.1e}.

**What it proves.** With the 0° tables the printed spectrum's product is
{ratio0:.4f} of the tables' ({shortfall}, {abs(ratio0 - 1) / bound:.0f} times the
rounding). Every model made of the same six stiffnesses and seven inertias has the
tables' product, so none of them has the printed spectrum: no re-wiring of the springs
into any tree of the seven bodies ({n_trees} trees, Cayley), no permutation of the
stiffnesses among the springs (720) or of the inertias among the bodies (5040), and no
combination of them — {n_models:,} distinct models (a permutation of the inertias is
itself a re-wiring), ruled out by one number instead of sampled. Six springs among the
seven bodies that do not form a tree leave them in two parts or more: a second zero
frequency, which the printed spectrum does not have. So no wiring of the six springs
between the seven bodies, with any order of the values, gives the printed spectrum; the
swaps and re-wirings of the search above could never have matched.
With the 90° tables the printed product is {ratio90:.2e} of the tables' — the printed
spectrum is not the 90° model under any wiring or permutation either — and mixing the
columns (inertias of one, stiffnesses of the other) does not give it.

**What it does not rule out**: anything that changes the values or the kind of graph —
a changed value (a misprinted digit of an inertia or a stiffness), an inertia swapped
with a stiffness, a missing or an extra body or spring (another n; a loop replaces ΠC by
the sum over spanning trees), a gear or lever ratio on a link (r_s² C_s), or a
misprinted frequency (then the printed product itself is off), or a spring to the ground
(its printed zero would then come from a part left free). And the invariant is only
necessary: an equal product would not make a model right.

It does settle one changed value of any size: the product fixes the only value each
inertia or stiffness could take, and with Γα that value still misses the spectrum:

{fit_table}

No single changed value, whatever its size, reproduces the printed spectrum with Γα
(best {best:.1%}).
"""


def azimuth_section() -> tuple[str, dict]:
    """The azimuth model (§2.3): what is reproduced and what is not, with the search."""
    printed = np.array(rt70_data.AZIMUTH_SPECTRUM_EL0_HZ)
    m0, m90 = rt70_chapter2.azimuth_model("0"), rt70_chapter2.azimuth_model("90")
    f0, f90 = frequencies(m0.m, m0.C), frequencies(m90.m, m90.C)
    inertia = np.diag(m0.m).copy()
    C = np.asarray(m0.c_links, dtype=float)
    G = np.asarray(m0.gamma, dtype=float)

    def dev(freqs):
        return float(np.max(np.abs(freqs[1:] - printed[1:]) / printed[1:]))

    def spectrum(inertia, C, G):
        return np.sqrt(
            np.clip(
                scipy.linalg.eigh(G.T @ np.diag(C) @ G, np.diag(inertia), eigvals_only=True),
                0,
                None,
            )
        ) / (2 * np.pi)

    edits = _azimuth_edits()
    singles = sorted((dev(spectrum(*e.apply(inertia, C, G))), e.label) for e in edits)
    doubles = sorted(
        (dev(spectrum(*e2.apply(*e1.apply(inertia, C, G)))), f"{e1.label}; {e2.label}")
        for e1, e2 in itertools.combinations(edits, 2)
    )
    best_rows = [[f"{d:.1%}", label] for d, label in singles[:5]]
    best_rows += [[f"{d:.1%}", label] for d, label in doubles[:3]]
    proof, invariant = _invariant_text(printed, lambda i, c: spectrum(i, c, G), dev)
    text = f"""## Azimuth model, 7 masses (§2.3, Tables 2.1–2.2, Γα (2.14)) — not reproduced

The printed spectrum (elevation 0°) against `eig(ΓᵀCΓ, I)` of Tables 2.1–2.2 (0° columns)
with Γα as read from the OCR:

{spectrum_table(list(printed), f0)}

The zero frequency (free azimuth bearing, no link to the ground) is reproduced; **none of
the six elastic frequencies is** — deviations up to {dev(f0):.1%}. With the 90° columns
the model gives {", ".join(f"{f:.4f}" for f in f90)} Hz. The unit (kgf or N) cannot
matter: it scales I and C alike.

What was tried, as a diagnosis only (the data are kept as printed): every single change
among {len(edits)} candidates — re-wiring one link of Γα to any other pair of nodes,
swapping two inertias, swapping two stiffnesses, taking one inertia or stiffness from
the 90° column — and every pair of them ({len(doubles)} combinations). None reproduces
the printed spectrum: the best single change still deviates by {singles[0][0]:.1%}, the
best pair by {doubles[0][0]:.1%} (largest relative deviation over the six elastic
frequencies). Best candidates:

{markdown_table(["max deviation", "change"], best_rows)}

{proof}
So the printed spectrum cannot come from the printed tables by any re-wiring or swap of
values (proved), nor by one or two slips of the other kinds tried (searched); the model
behind it is not recoverable from the book. This stays an open
finding (rt70-data.md §A).
"""
    return text, {
        "max_deviation": dev(f0),
        "best_single": singles[0],
        "best_pair": doubles[0],
        "invariant": invariant,
    }
