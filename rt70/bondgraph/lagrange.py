"""The same two examples in Lagrange form, written from the book's formulas alone.

Independent of the bond graphs (this module imports no bond-graph code): the drive
from the kinetic energy, potential, Rayleigh function and the motor's
electromechanical coupling of formalism §4.5, (4.137)–(4.143); the gear reducer of
Example 1a (§1.4) from its energies with the deformations listed in
:mod:`rt70.bondgraph.reducer`. Both are second-order systems

    M q̈ + D q̇ + K q = B u + B_v u̇,

which :class:`SecondOrder` turns into a transfer matrix or a first-order ``ẋ = A x +
B u`` (when ``B_v = 0``) with ``x = [q; q̇]``.
"""

from __future__ import annotations

from dataclasses import dataclass

import numpy as np

from rt70.bondgraph.parameters import DriveParameters, GearReducerParameters


@dataclass(frozen=True)
class SecondOrder:
    """``M q̈ + D q̇ + K q = B u + B_v u̇`` with named coordinates and inputs."""

    M: np.ndarray
    D: np.ndarray
    K: np.ndarray
    B: np.ndarray
    coordinates: list[str]
    inputs: list[str]
    B_v: np.ndarray | None = None

    def first_order(self) -> tuple[np.ndarray, np.ndarray]:
        """``(A, B)`` of ``ẋ = A x + B u`` with ``x = [q; q̇]`` (needs ``B_v = 0``)."""
        if self.B_v is not None and np.any(self.B_v):
            raise ValueError("an input enters through its rate: no first-order form in [q; q̇]")
        n = self.M.shape[0]
        Minv = np.linalg.inv(self.M)
        A = np.block([[np.zeros((n, n)), np.eye(n)], [-Minv @ self.K, -Minv @ self.D]])
        B = np.vstack([np.zeros_like(self.B), Minv @ self.B])
        return A, B

    def transfer(self, s: complex) -> np.ndarray:
        """``Q(s)/U(s) = (s² M + s D + K)⁻¹ (B + s B_v)``: coordinates per input.

        The dynamic stiffness ``Z`` is scaled symmetrically by ``|Z_ii|^(-1/2)`` before
        the solve (its diagonal spans many orders of magnitude in a drive).
        """
        rhs = self.B.astype(complex) + (s * self.B_v if self.B_v is not None else 0.0)
        Z = s * s * self.M + s * self.D + self.K
        diag = np.abs(np.diag(Z))
        d = 1.0 / np.sqrt(np.where(diag > 0.0, diag, 1.0))
        return d[:, None] * np.linalg.solve(d[:, None] * Z * d[None, :], d[:, None] * rhs)


def drive_lagrange(p: DriveParameters, source: str = "voltage") -> SecondOrder:
    """The drive of formalism §4.5 as ``M q̈ + D q̇ + K q = B u``.

    Coordinates ``q = [ρ, α_m, α_l]`` (charge (4.138), rotor angle, load angle); with
    ``source="current"`` the charge is no coordinate and the current is an input.

    - kinetic (magnetic) energy ``T = ½ L_a ρ̇² + ½ J_m α̇_m² + ½ J_l α̇_l²``;
    - potential ``U = ½ C_r Δα²`` with ``Δα = α_l − α_m / i_r`` (4.139);
    - Rayleigh ``Ψ = ½ R_a ρ̇² + ½ D_m α̇_m² + ½ D_r Δα̇² + ½ D_l α̇_l²``;
    - motor coupling (4.137): ``+c_e α̇_m`` in the circuit (back-EMF), ``−c_m ρ̇`` on the
      rotor (motor torque) — a gyroscopic, power-conserving term when ``c_m = c_e``;
    - inputs ``u = [U, τ_l]`` (armature voltage; external torque on the load), or
      ``[I_a, τ_l]`` for a current source (rotor torque ``c_m I_a``).
    """
    g = np.array([-1.0 / p.i_r, 1.0])  # ∂Δα/∂[α_m, α_l]
    K2 = p.C_r * np.outer(g, g)
    D2 = p.D_r * np.outer(g, g) + np.diag([p.D_m, p.D_l])
    if source == "current":
        return SecondOrder(
            M=np.diag([p.J_m, p.J_l]),
            D=D2,
            K=K2,
            B=np.array([[p.c_m, 0.0], [0.0, 1.0]]),
            coordinates=["alpha_m", "alpha_l"],
            inputs=["I_a", "tau_l"],
        )
    D = np.zeros((3, 3))
    D[1:, 1:] = D2
    D[0, 0] = p.R_a
    D[0, 1] = p.c_e  # L_a ρ̈ + R_a ρ̇ + c_e α̇_m = U
    D[1, 0] = -p.c_m  # J_m α̈_m − c_m ρ̇ + ... = reducer reaction
    K = np.zeros((3, 3))
    K[1:, 1:] = K2
    return SecondOrder(
        M=np.diag([p.L_a, p.J_m, p.J_l]),
        D=D,
        K=K,
        B=np.array([[1.0, 0.0], [0.0, 0.0], [0.0, 1.0]]),
        coordinates=["rho", "alpha_m", "alpha_l"],
        inputs=["U", "tau_l"],
    )


def book_motor_matrices(p: DriveParameters) -> dict[str, np.ndarray]:
    """The book's matrices of (4.141)/(4.142): ``q̈ = H q̇ + Z q + B U + F f``.

    ``q = [ρ, α_m]`` (4.138), ``f = [α̇_axis, α_axis]`` (the load angle and its rate),
    transcribed from (4.140)–(4.142) with ``T_a = L_a / R_a``.
    """
    Ta = p.L_a / p.R_a
    Jm, ir = p.J_m, p.i_r
    return {
        "H": np.array(
            [[-1.0 / Ta, -p.c_e / p.L_a], [p.c_m / Jm, -(p.D_m / Jm + p.D_r / (Jm * ir**2))]]
        ),
        "Z": np.array([[0.0, 0.0], [0.0, -p.C_r / (Jm * ir**2)]]),
        "B": np.array([1.0 / p.L_a, 0.0]),
        "F": np.array([[0.0, 0.0], [p.D_r / (Jm * ir), p.C_r / (Jm * ir)]]),
    }


def reducer_deformations(p: GearReducerParameters) -> tuple[np.ndarray, np.ndarray]:
    """``(Γ, Γ_b)`` with ``δ = Γ β + Γ_b β_b`` for Example 1a.

    ``β = [β1, β2, β3, β4]`` (and ``β_out`` last when the load is free); ``β_b =
    [β_motor]`` (and ``β_out`` last when the output angle is prescribed).
    """
    R1, R2, R3, R4 = p.radii
    free = p.load_inertia is not None
    n = 5 if free else 4
    G = np.zeros((5, n))
    Gb = np.zeros((5, 1 if free else 2))
    G[0, 0] = -1.0  # δ1 = β_out − β1
    if free:
        G[0, 4] = 1.0
    else:
        Gb[0, 1] = 1.0
    G[1, 1], G[1, 2] = -1.0, 1.0  # δ2 = β3 − β2
    G[2, 3], Gb[2, 0] = 1.0, -1.0  # δ3 = β4 − β_motor
    G[3, 0], G[3, 1] = 1.0, R2 / R1  # δ4 = β1 + (R2/R1) β2
    G[4, 2], G[4, 3] = 1.0, R4 / R3  # δ5 = β3 + (R4/R3) β4
    return G, Gb


def reducer_lagrange(p: GearReducerParameters) -> SecondOrder:
    """Example 1a as ``M β̈ + Γᵀ D Γ β̇ + Γᵀ C Γ β = −Γᵀ C Γ_b β_b − Γᵀ D Γ_b β̇_b``.

    From ``T = ½ Σ I_i β̇_i²``, ``U = ½ Σ C_s δ_s²``, ``Ψ = ½ Σ D_s δ̇_s²`` (book §1.4 with
    the mesh deformations of :func:`reducer_deformations`); inputs are the prescribed
    angles ``β_b`` (motor, and output unless the load is free).
    """
    G, Gb = reducer_deformations(p)
    C, D = np.diag(p.stiffness), np.diag(p.damping)
    inertias = list(p.inertia) + ([p.load_inertia] if p.load_inertia is not None else [])
    names = ["beta_1", "beta_2", "beta_3", "beta_4"]
    names += ["beta_out"] if p.load_inertia is not None else []
    inputs = ["beta_motor"] + ([] if p.load_inertia is not None else ["beta_out"])
    return SecondOrder(
        M=np.diag(inertias),
        D=G.T @ D @ G,
        K=G.T @ C @ G,
        B=-G.T @ C @ Gb,
        B_v=-G.T @ D @ Gb,
        coordinates=names,
        inputs=inputs,
    )
