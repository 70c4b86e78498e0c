"""The lowest 30 modes of a 10⁵-DOF FE model: time, and the factor's order (issue 24).

Target: a 10⁵-DOF model gives its first 30 modes in ≤ 10 s on this machine. The model is
the free two-layer space frame ``rt70.fe.truss.space_frame(130, 130)`` (101 400 DOF, six
rigid-body modes). In one run, BLAS threads pinned to one (:mod:`rt70.reports.threads`),
interleaved round by round, the solver against the one it replaced (the same shift, ARPACK
shift-invert Lanczos, the same Rayleigh–Ritz polish):

- ``lowest_modes``: :func:`rt70.fe.modes.lowest_modes`, METIS nested dissection
  (:mod:`rt70.fe.ordering`) kept by SuperLU in symmetric mode, ARPACK to
  :data:`rt70.fe.modes.LANCZOS_RTOL`;
- ``colamd``: SuperLU's own column order (COLAMD) with partial pivoting, as scipy's
  ``splu`` does by default, ARPACK to machine precision.

Reported: each one's best and median wall time, its factor's entries, the largest
backward error of its modes and the largest relative difference of the elastic
frequencies between the two.

    python validation/bench_sparse_modes.py [--rounds 3] [--size 130]

writes ``validation/results/bench_sparse_modes.md``.
"""

from __future__ import annotations

import argparse
import sys
import time
from pathlib import Path

import numpy as np
import scipy.linalg
import scipy.sparse as sp
import scipy.sparse.linalg as spla

from rt70.fe.modes import SHIFT_RTOL, START_SEED, backward_errors, lowest_modes
from rt70.fe.ordering import nested_dissection
from rt70.fe.truss import space_frame
from rt70.guards.atomic import atomic_write_text
from rt70.reports.provenance import command_line, headed, run_header
from rt70.reports.threads import single_threaded

RESULTS = Path(__file__).resolve().parent / "results"
MODES = 30
TARGET_S = 10.0


def colamd_modes(M, K, count: int):
    """The solver lowest_modes replaced: ``splu`` in COLAMD order, ARPACK to machine precision."""
    n = M.shape[0]
    m_d, k_d = M.diagonal(), K.diagonal()
    sigma = -SHIFT_RTOL * float(np.max(k_d[m_d > 0] / m_d[m_d > 0]))
    start = time.perf_counter()
    Kc, Mc = sp.csc_array(K), sp.csc_array(M)
    lu = spla.splu(Kc - sigma * Mc)
    op_inv = spla.LinearOperator((n, n), matvec=lu.solve, dtype=float)
    v0 = np.random.default_rng(START_SEED).standard_normal(n)
    w, V = spla.eigsh(Kc, k=count, M=Mc, sigma=sigma, which="LM", OPinv=op_inv, v0=v0)
    w, Y = scipy.linalg.eigh(V.T @ (Kc @ V), V.T @ (Mc @ V))
    V = V @ Y
    seconds = time.perf_counter() - start
    return w, backward_errors(Mc, Kc, w, V), seconds, lu.L.nnz + lu.U.nnz


def nd_fill(M, K) -> int:
    """Entries of the factor lowest_modes makes (its order, its shift)."""
    m_d, k_d = M.diagonal(), K.diagonal()
    sigma = -SHIFT_RTOL * float(np.max(k_d[m_d > 0] / m_d[m_d > 0]))
    A = sp.csc_array(sp.csc_array(K) - sigma * sp.csc_array(M))
    p = nested_dissection(A)
    lu = spla.splu(sp.csc_array(A[p][:, p]), permc_spec="NATURAL", diag_pivot_thresh=0.0,
                   options={"SymmetricMode": True})  # fmt: skip
    return lu.L.nnz + lu.U.nnz


def main(argv: list[str] | None = None) -> int:
    parser = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    parser.add_argument("--rounds", type=int, default=3, help="interleaved rounds (default 3)")
    parser.add_argument(
        "--size", type=int, default=130, help="nodes a layer along x and y (default 130)"
    )
    args = parser.parse_args(argv)
    if args.rounds < 1:
        parser.error("--rounds must be at least 1")
    if not 2 <= args.size <= 400:
        parser.error("--size must be between 2 and 400")
    fe = space_frame(args.size, args.size)
    n = fe.M.shape[0]
    times = {"lowest_modes": [], "colamd": []}
    with single_threaded() as pinning:
        for _ in range(args.rounds):
            new = lowest_modes(fe.M, fe.K, MODES)
            times["lowest_modes"].append(new.seconds)
            w_old, res_old, seconds, fill_old = colamd_modes(fe.M, fe.K, MODES)
            times["colamd"].append(seconds)
        fill_new = nd_fill(fe.M, fe.K)
    elastic = ~new.rigid
    diff = float(np.max(np.abs(new.omega2[elastic] / w_old[elastic] - 1.0)))
    ratio = np.median(times["colamd"]) / np.median(times["lowest_modes"])
    lines = [
        "# The lowest modes of a 10⁵-DOF model",
        "",
        f"`python validation/bench_sparse_modes.py --rounds {args.rounds} --size {args.size}`;"
        f" {pinning.describe()}.",
        f"Free space frame {args.size} × {args.size} × 2 nodes, {n} DOF, {MODES} modes "
        f"({int(new.rigid.sum())} rigid); rounds interleaved.",
        "",
        "| solver | best s | median s | factor entries | largest backward error |",
        "|---|---|---|---|---|",
        f"| lowest_modes (nested dissection) | {min(times['lowest_modes']):.2f} | "
        f"{np.median(times['lowest_modes']):.2f} | {fill_new / 1e6:.1f} M | "
        f"{new.residual.max():.1e} |",
        f"| SuperLU's COLAMD order | {min(times['colamd']):.2f} | "
        f"{np.median(times['colamd']):.2f} | {fill_old / 1e6:.1f} M | {res_old.max():.1e} |",
        "",
        f"Elastic ω² of the two: largest relative difference {diff:.1e}.",
        f"Ratio of the medians: {ratio:.2f}.",
        "",
        f"Target (issue 24): ≤ {TARGET_S:g} s for 30 modes of 10⁵ DOF — "
        + ("met" if np.median(times["lowest_modes"]) <= TARGET_S else "NOT met")
        + " (median).",
    ]
    report = "\n".join(lines) + "\n"
    RESULTS.mkdir(exist_ok=True)
    atomic_write_text(RESULTS / "bench_sparse_modes.md", headed(report, run_header(command_line())))
    sys.stdout.write(report)
    return 0


if __name__ == "__main__":
    sys.exit(main())
