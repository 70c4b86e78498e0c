"""Bond graph vs Lagrange: the drive's equations formed two independent ways (issue 10).

The bond graph (rt70/bondgraph/drive.py, after the companion source 003) and the
Lagrange form written from formalism §4.5 (rt70/bondgraph/lagrange.py) must give the
same equations: the state matrices related by the map from ``[q; q̇]`` to the bond
graph's energy variables, the same transfer functions and eigenvalues (issue 10
target ≤ 1e-12 relative); the locked-rotor frequency of the two-mass drive equals
``ω² = C_r (1/J_m' + 1/J_l)`` with ``J_m' = J_m i_r²`` (rotor inertia reflected to the
load side); the power budget closes; SCAP refuses bad graphs with a clear message.

Parameters. Book magnitudes (formalism §4.5): reducer ratio 1e5 and 1e6; nominal axis
torque 5e6 kgf·m. The load inertia is the sum of the book's azimuth inertias at
elevation 0° (rt70-data.md §A, 7.3672e7 kgf·s²·m). Everything else is a TEST VALUE,
chosen only to give a drive of plausible shape (not the project's drive table,
docs/drives.md): L_a 1 mH, R_a 0.05 Ω, nominal current 100 A (so c_m = c_e = nominal
motor torque / 100 A), J_m 2 kg·m², D_m 0.1 N·m·s/rad, reducer stiffness 0.5350e10
kgf·m/rad (the magnitude of the book's platform–base link), D_r 1e8 N·m·s/rad,
D_l 1e6 N·m·s/rad.
"""

from __future__ import annotations

import ast
from pathlib import Path

import numpy as np
import pytest
from scipy.linalg import matrix_balance

from rt70.bondgraph import (
    DRIVE_OUTPUTS,
    BondGraph,
    BondGraphError,
    CausalityError,
    DriveParameters,
    GearReducerParameters,
    ParameterError,
    assign_causality,
    dc_motor_reducer_load,
    drive_lagrange,
    gear_reducer,
    reducer_lagrange,
    reducer_outputs,
    state_equations,
)
from rt70.bondgraph.equations import _AlgebraicLoop, _Former
from rt70.bondgraph.lagrange import book_motor_matrices, reducer_deformations
from rt70.errors import Rt70Error
from rt70.scenes import mechanisms
from rt70.testing import EPS, assert_close

KGF = 9.80665  # N per kgf
AZIMUTH_INERTIA_KGF = 0.2100e8 + 0.4000e7 + 0.9472e7 + 0.1600e8 + 0.3200e7 + 0.1060e5 + 0.4700e7
TOL = 1e-12


def drive_params(i_r: float = 1e5, damped: bool = True) -> DriveParameters:
    c = 5e6 * KGF / i_r / 100.0  # nominal axis torque / ratio / nominal current (test)
    return DriveParameters(
        L_a=1e-3,
        R_a=0.05,
        c_m=c,
        c_e=c,
        J_m=2.0,
        D_m=0.1 if damped else 0.0,
        i_r=i_r,
        C_r=0.5350e10 * KGF,
        D_r=1e8 if damped else 0.0,
        J_l=AZIMUTH_INERTIA_KGF * KGF,
        D_l=1e6 if damped else 0.0,
    )


def to_bond_states(p: DriveParameters) -> np.ndarray:
    """x_bg = T [ρ, α_m, α_l, ρ̇, α̇_m, α̇_l]: [p_L_a, p_J_m, q_C_r, p_J_l]."""
    T = np.zeros((4, 6))
    T[0, 3], T[1, 4], T[3, 5] = p.L_a, p.J_m, p.J_l
    T[2, 1], T[2, 2] = 1.0 / p.i_r, -1.0  # q_C_r = α_m/i_r − α_l = −Δα (4.139)
    return T


def parts(z: np.ndarray) -> np.ndarray:
    """Real and imaginary parts of ``z`` stacked on a new first axis, for assert_close."""
    z = np.asarray(z)
    return np.stack([z.real, z.imag])


def power_scale(b) -> float:
    """Natural scale of a power budget: the sizes of the powers that must balance."""
    return abs(b.stored) + abs(b.supplied) + abs(b.dissipated)


RATIOS = pytest.mark.parametrize("i_r", [1e5, 1e6])


# --- the drive: bond graph = Lagrange ------------------------------------------------


@RATIOS
def test_drive_graph_is_causal_with_integral_storage(i_r):
    ss = state_equations(dc_motor_reducer_load(drive_params(i_r)), DRIVE_OUTPUTS)
    assert ss.states == ["p_L_a", "p_J_m", "q_C_r", "p_J_l"]
    assert ss.inputs == ["U", "tau_l"]
    causal = ss.causality
    for name in ("L_a", "J_m", "J_l"):  # I elements receive the effort
        assert causal.effort_to[name] == name
    assert causal.effort_to["C_r"] == "1_twist"  # C imposes its effort


@RATIOS
def test_state_matrices_equal_lagrange(i_r):
    """T A_L = A_bg T, T B_L = B_bg, C_bg T = C_L, entry by entry to 1e-12."""
    p = drive_params(i_r)
    ss = state_equations(dc_motor_reducer_load(p), DRIVE_OUTPUTS)
    AL, BL = drive_lagrange(p).first_order()
    T = to_bond_states(p)
    # entry by entry on the magnitudes that were summed into each entry
    scale_a = np.abs(T) @ np.abs(AL) + np.abs(ss.A) @ np.abs(T)
    assert_close(T @ AL, ss.A @ T, rel=TOL, scale=scale_a, what="T A_L vs A_bg T")
    assert_close(T @ BL, ss.B, rel=TOL, scale=np.abs(T) @ np.abs(BL), what="T B_L vs B_bg")
    # outputs from the Lagrange coordinates: I_a = ρ̇, ω_m, ω_l, motor torque c_m ρ̇,
    # axis torque K = −C_r Δα − D_r Δα̇ (4.143)
    CL = np.zeros((5, 6))
    CL[0, 3], CL[1, 4], CL[2, 5], CL[3, 3] = 1.0, 1.0, 1.0, p.c_m
    CL[4, 1], CL[4, 2] = p.C_r / p.i_r, -p.C_r
    CL[4, 4], CL[4, 5] = p.D_r / p.i_r, -p.D_r
    assert_close(ss.C @ T, CL, rel=TOL, scale=np.abs(ss.C) @ np.abs(T), what="C_bg T vs C_L")
    assert not np.any(ss.D)
    assert ss.outputs == [name for name, _, _ in DRIVE_OUTPUTS]


@RATIOS
def test_frequency_responses_equal_lagrange(i_r):
    """The state responses to U and τ_l at seven frequencies agree to 1e-12.

    Compared as the bond graph's states ``X(s) = (sI − A)⁻¹ B`` against the Lagrange
    ``T [Q; sQ]``, ``Q = (s²M + sD + K)⁻¹ B``, normwise per input in the balanced
    coordinates of ``A`` (scipy.linalg.matrix_balance): entry by entry, outputs that
    are small differences of large terms (the current at low frequency, where the
    back-EMF balances the voltage) carry the conditioning of the solve, not of the
    formulation (the formulations are compared entry by entry above). Near the
    locked-rotor resonance the balanced ``sI − A`` has condition number κ ≈ 1.3e3, and
    the solve's rounding κ·ε (3e-13) is not far below 1e-12: the bound is then
    ``16 κ ε``. The load speed, the output a servo engineer reads, is also compared
    entry by entry.
    """
    p = drive_params(i_r)
    ss = state_equations(dc_motor_reducer_load(p), DRIVE_OUTPUTS)
    lag = drive_lagrange(p)
    T = to_bond_states(p)
    _, (scale, _) = matrix_balance(ss.A, permute=False, separate=True)
    balanced = ss.A * scale[None, :] / scale[:, None]
    w_lock = np.sqrt(p.C_r * (1 / (p.J_m * p.i_r**2) + 1 / p.J_l))
    for w in (1e-2, 0.1, 1.0, w_lock, 10.0, 100.0, 1e4):
        s = 1j * w
        Q = lag.transfer(s)
        XL = T @ np.vstack([Q, s * Q]) / scale[:, None]
        XB = np.linalg.solve(s * np.eye(4) - ss.A, ss.B.astype(complex)) / scale[:, None]
        # each input's column on its norm, to the solve's conditioning where that is larger
        kappa = np.linalg.cond(s * np.eye(4) - balanced)
        rel = max(TOL, 16 * EPS * kappa)
        column = np.linalg.norm(XB, axis=0)
        assert_close(parts(XL), parts(XB), rel=rel, scale=column, what=f"X at ω={w:g}")
        G = ss.transfer(s)[ss.outputs.index("omega_l")]
        assert_close(parts(s * Q[2]), parts(G), rel=TOL, scale=np.abs(G), what=f"ω_l at ω={w:g}")


@RATIOS
def test_eigenvalues_equal_lagrange(i_r):
    """The Lagrange form has the bond graph's eigenvalues and two zeros (ρ and the
    absolute angle are cyclic)."""
    p = drive_params(i_r)
    lam_bg = np.linalg.eigvals(state_equations(dc_motor_reducer_load(p)).A)
    lam_l = np.linalg.eigvals(drive_lagrange(p).first_order()[0])
    scale = np.max(np.abs(lam_bg))
    order = np.argsort(np.abs(lam_l))
    assert_close(lam_l[order[:2]].real, np.zeros(2), rel=TOL, scale=scale, what="zeros")
    assert_close(lam_l[order[:2]].imag, np.zeros(2), rel=TOL, scale=scale, what="zeros")
    rest = lam_l[order[2:]]
    for lam in lam_bg:
        nearest = rest[np.argmin(np.abs(rest - lam))]
        assert_close(parts(nearest), parts(lam), rel=TOL, scale=abs(lam), what=f"λ = {lam}")


@RATIOS
def test_two_mass_locked_rotor_frequency(i_r):
    """Current-fed drive, no damping: eigenvalues 0, ±jω, ω² = C_r (1/(J_m i_r²) + 1/J_l)."""
    p = drive_params(i_r, damped=False)
    ss = state_equations(dc_motor_reducer_load(p, source="current"))
    assert ss.states == ["p_J_m", "q_C_r", "p_J_l"] and ss.inputs == ["I_a", "tau_l"]
    w2 = p.C_r * (1.0 / (p.J_m * p.i_r**2) + 1.0 / p.J_l)
    lam = np.linalg.eigvals(ss.A)
    w = np.sqrt(w2)
    assert_close(lam.real, np.zeros(lam.size), rel=TOL, scale=w)
    assert_close(np.max(lam.imag) ** 2, w2, rel=TOL)
    # the Lagrange form of the same (M, K): generalised eigenvalues 0 and ω²
    lag = drive_lagrange(p, source="current")
    mu = np.sort(np.linalg.eigvals(np.linalg.solve(lag.M, lag.K)).real)
    assert_close(mu, [0.0, w2], rel=TOL)


def test_lagrange_form_is_the_books_4_142():
    """drive_lagrange reproduces H, Z, B, F of (4.141)/(4.142) for q = [ρ, α_m]."""
    p = drive_params()
    lag = drive_lagrange(p)
    Minv = np.linalg.inv(lag.M)
    acc_v = -Minv @ lag.D  # q̈ per q̇ = [ρ̇, α̇_m, α̇_l]
    acc_q = -Minv @ lag.K
    acc_u = Minv @ lag.B
    # each entry on the magnitudes that were summed into it
    size_v = np.abs(Minv) @ np.abs(lag.D)
    size_q = np.abs(Minv) @ np.abs(lag.K)
    size_u = np.abs(Minv) @ np.abs(lag.B)
    book = book_motor_matrices(p)
    pairs = [
        ("H", acc_v[:2, :2], size_v[:2, :2]),
        ("Z", acc_q[:2, :2], size_q[:2, :2]),
        ("B", acc_u[:2, 0], size_u[:2, 0]),
        (
            "F",
            np.column_stack([acc_v[:2, 2], acc_q[:2, 2]]),
            np.column_stack([size_v[:2, 2], size_q[:2, 2]]),
        ),
    ]
    for name, mine, size in pairs:
        assert_close(mine, book[name], rel=TOL, scale=size, what=name)


@pytest.mark.parametrize("seed", [0, 1, 2])
def test_drive_energy_balance(seed):
    """dH/dt = P_in − P_R at a random state and input; H equals the Lagrange T + U."""
    p = drive_params()
    ss = state_equations(dc_motor_reducer_load(p), DRIVE_OUTPUTS)
    rng = np.random.default_rng(seed)
    xl = rng.standard_normal(6) * np.array([1, 1e3, 1e-2, 1e2, 1e2, 1e-3])
    x = to_bond_states(p) @ xl
    u = rng.standard_normal(2) * np.array([400.0, 1e6])
    b = ss.power(x, u)
    assert_close(b.stored, b.supplied - b.dissipated, rel=TOL, scale=power_scale(b), what=str(b))
    assert b.dissipated > 0.0
    lag = drive_lagrange(p)
    q, v = xl[:3], xl[3:]
    energy = 0.5 * v @ lag.M @ v + 0.5 * q @ lag.K @ q
    assert_close(ss.energy(x), energy, rel=TOL)


# --- causality: the procedure refuses what it cannot handle ----------------------------


def test_current_source_with_inductance_is_derivative_causality():
    g = BondGraph("fed inductor")
    g.source_flow("I_src", input="I")
    g.one("1")
    g.inertia("L_a", 1e-3)
    g.resistor("R_a", 0.1)
    g.bond("I_src", "1")
    g.bond("1", "L_a")
    g.bond("1", "R_a")
    with pytest.raises(CausalityError, match=r"'fed inductor'.*I element 'L_a'.*derivative"):
        assign_causality(g)


def test_two_inertias_on_one_junction_are_refused():
    g = BondGraph("rigid pair")
    g.source_effort("tau", input="tau")
    g.one("1")
    g.inertia("J1", 1.0)
    g.inertia("J2", 2.0)
    for end in ("1", "J1", "J2"):
        if end != "1":
            g.bond("1", end)
    g.bond("tau", "1")
    with pytest.raises(CausalityError, match="I element 'J2' is in derivative causality"):
        state_equations(g)


def test_two_flow_sources_on_a_1_junction_conflict():
    g = BondGraph("two sources")
    g.source_flow("v1", input="v1")
    g.source_flow("v2", input="v2")
    g.one("1")
    g.resistor("R", 1.0)
    g.bond("v1", "1")
    g.bond("v2", "1")
    g.bond("1", "R")
    with pytest.raises(CausalityError, match="causal conflict on bond 'v2->1'.*source Sf 'v1'"):
        assign_causality(g)
    assert issubclass(CausalityError, Rt70Error)


def test_algebraic_loop_is_solved():
    """A resistor divider: R1 and R2 fix each other's variables (an algebraic loop).

    Hand solution: node voltage V = (U − i) R1R2/(R1 + R2) with R1 = 1, R2 = 2; then
    L di/dt = V − R3 i, so with p = L i: ṗ = −(2/3 + 3) p / L + (2/3) U.
    """
    g = BondGraph("divider")
    g.source_effort("U", input="U")
    g.one("1_a")
    g.resistor("R1", 1.0)
    g.zero("0_b")
    g.resistor("R2", 2.0)
    g.one("1_c")
    g.resistor("R3", 3.0)
    g.inertia("L", 1e-3)
    for tail, head in [
        ("U", "1_a"),
        ("1_a", "R1"),
        ("1_a", "0_b"),
        ("0_b", "R2"),
        ("0_b", "1_c"),
        ("1_c", "R3"),
        ("1_c", "L"),
    ]:
        g.bond(tail, head)
    former = _Former(assign_causality(g), ["p_L"], ["U"])
    with pytest.raises(_AlgebraicLoop):  # the causal evaluation does meet the loop
        former.get(("1_c->L", "e"))
    ss = state_equations(g, [("V", "0_b->R2", "e")])
    assert_close(ss.A[0, 0], -(2 / 3 + 3) / 1e-3, rel=TOL)
    assert_close(ss.B[0, 0], 2 / 3, rel=TOL)
    assert_close(ss.C[0, 0], -(2 / 3) / 1e-3, rel=TOL)  # V per p (i = p/L)
    assert_close(ss.D[0, 0], 2 / 3, rel=TOL)
    b = ss.power(np.array([0.3]), np.array([2.0]))
    assert_close(b.stored, b.supplied - b.dissipated, rel=TOL, scale=power_scale(b), what=str(b))


def test_bond_graph_doctest_and_unknown_output():
    import doctest

    import rt70.bondgraph.graph as graph_module

    result = doctest.testmod(graph_module)
    assert result.attempted >= 5 and result.failed == 0
    g = dc_motor_reducer_load(drive_params())
    with pytest.raises(BondGraphError, match="no bond named 'nope'"):
        state_equations(g, [("y", "nope", "f")])
    with pytest.raises(BondGraphError, match="output 'y': variable must be e or f"):
        state_equations(g, [("y", "J_l", "v")])


def test_malformed_graphs_and_parameters_are_refused():
    g = BondGraph("loose")
    g.one("1")
    g.inertia("J", 1.0)
    g.bond("1", "J")
    with pytest.raises(BondGraphError, match="1 element '1' has 1 bond"):
        assign_causality(g)
    with pytest.raises(BondGraphError, match="C element 'k' needs a finite positive"):
        g.compliance("k", stiffness=-1.0)
    with pytest.raises(BondGraphError, match="no element named 'X'"):
        g.bond("1", "X")
    with pytest.raises(ParameterError, match=r"DriveParameters\.J_m"):
        DriveParameters(1e-3, 0.05, 5.0, 5.0, float("nan"), 0.1, 1e5, 1e10, 1e8, 1e9, 0.0)
    p = drive_params()
    bad = DriveParameters(**{**p.__dict__, "c_e": 2 * p.c_m})
    with pytest.raises(BondGraphError, match="c_m .* and c_e .* differ"):
        dc_motor_reducer_load(bad)


# --- Example 1a: the non-rigid gear reducer (book §1.4) --------------------------------

#: The book gives no numbers for Example 1a: the project's values of the gear_reducer
#: scene (gears 1..4, shafts/meshes C1..C5, D1..D5, radii R1..R4; overall ratio 15),
#: with the output angle prescribed (no load inertia) unless a test adds one.
REDUCER = {k: mechanisms.GEAR_REDUCER[k] for k in ("inertia", "stiffness", "damping", "radii")}


def test_reducer_transfer_functions_equal_lagrange():
    """β_motor, β_out → β1..β4 and the two shaft torques, each entry to 1e-12."""
    p = GearReducerParameters(**REDUCER)
    ss = state_equations(gear_reducer(p), reducer_outputs(p))
    assert len(ss.states) == 9 and ss.inputs == ["omega_motor", "omega_out"]
    lag = reducer_lagrange(p)
    G, Gb = reducer_deformations(p)
    C, D = np.array(p.stiffness), np.array(p.damping)
    for w in (0.3, 3.0, 30.0, 300.0, 3000.0):
        s = 1j * w
        Q = lag.transfer(s)  # β per β_b; the bond graph's ω per ω_b is the same ratio
        delta = G @ Q + Gb  # deformations per input
        tau1 = (C[0] + s * D[0]) * delta[0]  # torque in shaft 1 on gear 1 (= −K_out)
        tau3 = -(C[2] + s * D[2]) * delta[2]  # torque of shaft 3 on gear 4 (= −K_motor)
        GL = np.vstack([Q, tau1 / s, tau3 / s])  # torques per flow input: divide by s
        GB = ss.transfer(s)
        assert_close(parts(GL), parts(GB), rel=TOL, scale=np.abs(GB), what=f"ω={w:g}")


def test_reducer_rigid_limit_gives_the_ideal_ratio():
    """With a free load, the steady speed ratio is the ideal R2 R4 / (R1 R3) (to 1e-12),
    and as the internal stiffnesses grow the lowest frequency tends to that of a rigid
    train on the motor shaft, ω² = C3 / J_red, at first order in 1/λ."""
    R1, R2, R3, R4 = REDUCER["radii"]
    ratio = R2 * R4 / (R1 * R3)
    p = GearReducerParameters(**{**REDUCER, "damping": (0.0,) * 5}, load_inertia=50.0)
    ss = state_equations(gear_reducer(p), reducer_outputs(p))
    dc = -ss.C @ np.linalg.solve(ss.A, ss.B)
    out = dict(zip(ss.outputs, dc[:, 0], strict=True))
    assert_close(out["omega_out"], ratio, rel=TOL)
    assert_close(out["omega_1"], ratio, rel=TOL)
    assert_close(out["omega_4"], 1.0, rel=TOL)
    I1, I2, I3, I4 = REDUCER["inertia"]
    g34 = R4 / R3  # |ω3/ω4|
    J_red = I4 + (I3 + I2) * g34**2 + (I1 + 50.0) * ratio**2
    w2 = REDUCER["stiffness"][2] / J_red
    lowest = []
    for lam in (1e5, 1e6):
        k = [c * lam for c in REDUCER["stiffness"]]
        k[2] = REDUCER["stiffness"][2]  # the motor shaft stays compliant
        stiff = GearReducerParameters(
            **{**REDUCER, "damping": (0.0,) * 5, "stiffness": tuple(k)}, load_inertia=50.0
        )
        eig = np.linalg.eigvals(state_equations(gear_reducer(stiff)).A)
        lowest.append(np.min(np.abs(eig.imag[eig.imag > 0])) ** 2)
    assert_close(lowest[1], w2, rel=2e-5)  # the rigid train's, at first order in 1/λ
    errors = np.abs(np.array(lowest) / w2 - 1.0)
    assert 8.0 < errors[0] / errors[1] < 12.0, errors  # the error falls as 1/λ


@pytest.mark.parametrize("seed", [0, 1])
def test_reducer_energy_balance(seed):
    p = GearReducerParameters(**REDUCER)
    ss = state_equations(gear_reducer(p))
    rng = np.random.default_rng(seed)
    b = ss.power(rng.standard_normal(9), rng.standard_normal(2))
    assert_close(b.stored, b.supplied - b.dissipated, rel=TOL, scale=power_scale(b), what=str(b))


# --- independence ----------------------------------------------------------------------

PACKAGE = Path(__file__).resolve().parents[1] / "rt70" / "bondgraph"


def _rt70_imports(path: Path) -> set[str]:
    found = set()
    for node in ast.walk(ast.parse(path.read_text(encoding="utf-8"))):
        if isinstance(node, ast.ImportFrom) and node.module:
            found.add(node.module)
        elif isinstance(node, ast.Import):
            found |= {a.name for a in node.names}
    return {m for m in found if m.startswith("rt70")}


def test_bondgraph_imports_neither_side():
    """The package uses numpy/scipy and rt70.errors only; its Lagrange form uses no
    bond-graph code (only the parameter dataclasses)."""
    modules = sorted(PACKAGE.glob("*.py"))
    assert len(modules) >= 7
    for path in modules:
        for m in _rt70_imports(path):
            assert m == "rt70.errors" or m.startswith("rt70.bondgraph"), (path.name, m)
    assert _rt70_imports(PACKAGE / "lagrange.py") == {"rt70.bondgraph.parameters"}
