"""Closed chains (issue 12 part 2): <rt70:loop>, Φ/B_c/C and the constrained dynamics (14).

Both sides against each other and against their own definitions (B_c q̇ = Φ̇ and
C = Ḃ_c q̇ by central differences of the exact functions), the KKT solution's
equations, the Baumgarte law (2.2) of source 002, consistent assembly, simulation of
the crank–slider with and without stabilisation, and the indefiniteness of the KKT
matrix (erratum X.3.11: plain CG breaks down where the range-space method does not).
"""

from __future__ import annotations

import json
import subprocess
import sys

import numpy as np
import pytest
import scipy.sparse.linalg

import rt70.cli.main
from rt70.errors import ExtensionError, Rt70Error, SimulationError
from rt70.model.scene import load_scene, scene_from_text
from rt70.physics.baumgarte import Baumgarte
from rt70.physics.kkt import solve_kkt
from rt70.reference import loops as rl
from rt70.reference import points as ref_points
from rt70.simulation.closed_chains import assemble
from rt70.simulation.loop_constraints import CLOSURE_TOL
from rt70.simulation.simulate import simulate
from rt70.testing import MIN_REL, assert_close
from rt70.textbook import dynamics, forces
from rt70.textbook import loops as tl

LOOP_SCENES = ("four_bar", "crank_slider")
TOL = 1e-10

# --- a frame loop: two rods on the same pivot, welded (6 rows, rank 1) -------------
ROD = (
    '<inertial><origin xyz="0.25 0 0"/><mass value="{m}"/>'
    '<inertia ixx="1e-4" ixy="0" ixz="0" iyy="{i}" iyz="0" izz="{i}"/></inertial>'
)


def welded(loop_type: str = "frame", frame2: str = 'link="b" xyz="0.3 0 0" rpy="0 0 0.4"') -> str:
    """Two rods pivoted about z at the ground origin, welded by a loop at an offset."""
    joints = "".join(
        f'<joint name="j{k}" type="revolute"><parent link="world"/><child link="{k}"/>'
        f'<origin xyz="0 0 0" rpy="0 0 0"/><axis xyz="0 0 1"/>'
        '<limit lower="-100" upper="100" effort="1" velocity="1"/></joint>'
        for k in "ab"
    )
    return (
        '<?xml version="1.0"?><robot name="welded" xmlns:rt70="urn:rt70:urdf-extensions:1">'
        '<link name="world"/>'
        f'<link name="a">{ROD.format(m=1.0, i=0.02)}</link>'
        f'<link name="b">{ROD.format(m=2.0, i=0.05)}</link>{joints}'
        '<rt70:gravity xyz="0 -9.81 0"/>'
        f'<rt70:loop name="weld" type="{loop_type}">'
        '<rt70:frame1 link="a" xyz="0.3 0 0" rpy="0 0 0.4"/>'
        f"<rt70:frame2 {frame2}/></rt70:loop></robot>"
    )


@pytest.fixture(scope="module", params=[*LOOP_SCENES, "welded"])
def scene(request):
    if request.param == "welded":
        return scene_from_text(welded(), "welded")
    return load_scene(request.param)


def reach(scene, q) -> float:
    """The largest distance of a loop's frame from the ground origin (m), the scale of Φ.

    Φ is a difference of such positions, each a sum of the links' offsets; the same scale
    as :func:`rt70.crosscheck.loop_check.loop_scales` gives the loop rows of ``rt70 validate``.
    """
    located = [
        (f.link, f.xyz) for loop in scene.description.loops for f in (loop.frame1, loop.frame2)
    ]
    positions = ref_points.point_positions(scene.reference, scene.reference_data, q, located)
    return float(np.max(np.linalg.norm(positions, axis=1)))


def _state(scene, seed=3):
    rng = np.random.default_rng(seed)
    n = scene.textbook.nv
    return rng.uniform(-0.5, 0.5, n), rng.uniform(-2.0, 2.0, n)


# --- the element ----------------------------------------------------------------


def test_loop_element_is_read():
    desc = load_scene("crank_slider").description
    (loop,) = desc.loops
    assert (loop.name, loop.type, loop.rows) == ("rod_slider", "point", 3)
    assert (loop.frame1.link, loop.frame2.link) == ("rod", "slider")
    np.testing.assert_array_equal(loop.frame1.xyz, [0.4, 0.0, 0.0])


def test_world_means_the_ground_even_when_the_root_has_another_name():
    text = welded("point", 'link="world" xyz="0.3 0 0"').replace('"world"', '"ground"')
    text = text.replace('link="ground" xyz="0.3', 'link="world" xyz="0.3')
    scene = scene_from_text(text, "grounded")
    (loop,) = scene.description.loops
    assert loop.frame2.link == "ground"
    q = np.array([0.0, 0.0])
    assert_close(
        tl.loop_residual(scene.textbook, scene.textbook_data, q),
        rl.loop_residual(scene.reference, scene.reference_data, q),
        rel=1e-14,
        scale=reach(scene, q),
    )


BAD_LOOPS = {
    "unknown-type": (
        welded("slot"),
        ("<rt70:loop name='weld'>", "type 'slot'", "point, frame"),
    ),
    "missing-frame2": (
        welded().replace('<rt70:frame2 link="b" xyz="0.3 0 0" rpy="0 0 0.4"/>', ""),
        ("<rt70:loop name='weld'>", "lacks <rt70:frame2>"),
    ),
    "unknown-link": (
        welded("frame", 'link="ghost"'),
        ("<rt70:loop name='weld'> <rt70:frame2>", "link 'ghost' does not exist"),
    ),
    "same-link": (
        welded("frame", 'link="a"'),
        ("<rt70:loop name='weld'>", "both on link 'a'"),
    ),
    "bad-number": (
        welded("frame", 'link="b" xyz="0.3 0"'),
        ("<rt70:frame2", "expected 3 numbers"),
    ),
    "two-with-one-name": (
        welded().replace(
            "</robot>",
            '<rt70:loop name="weld"><rt70:frame1 link="a"/>'
            '<rt70:frame2 link="b"/></rt70:loop></robot>',
        ),
        ("two loops named 'weld'",),
    ),
}


@pytest.mark.parametrize("case", list(BAD_LOOPS))
def test_bad_loop_element(case, tmp_path, capsys):
    text, needles = BAD_LOOPS[case]
    path = tmp_path / f"{case}.urdf"
    path.write_text(text, encoding="utf-8")
    with pytest.raises(ExtensionError) as excinfo:
        load_scene(str(path))
    message = str(excinfo.value)
    assert message.startswith(f"{path}: ") and "\n" not in message
    for needle in needles:
        assert needle in message, message
    capsys.readouterr()
    assert rt70.cli.main.main(["validate", str(path)]) == 2
    out, err = capsys.readouterr()
    assert out == "" and err.splitlines() == [f"rt70: error: {message}"]


# --- each side against its own definitions, and the two sides ---------------------


def test_jacobian_and_bias_are_the_derivatives_of_the_residual(scene):
    """``B_c q̇ = Φ̇`` (position rows exactly; rotation rows on Φ = 0) and ``C = Ḃ_c q̇``."""
    tm, td = scene.textbook, scene.textbook_data
    q, qd = _state(scene)
    if scene.name == "welded":
        q, qd = assemble(scene, q, qd)  # the rotation rows are exact on the manifold
    h = 1e-6
    B = tl.loop_jacobian(tm, td, q)
    dphi = (tl.loop_residual(tm, td, q + h * qd) - tl.loop_residual(tm, td, q - h * qd)) / (2 * h)
    # central differences, O(h²) and O(ε |Φ| / h): on the loop's velocity scale |q̇| · reach
    length, speed = reach(scene, q), np.abs(qd).max()
    assert_close(B @ qd, dphi, rel=1e-8, scale=max(length, np.abs(B).max()) * speed)
    dB = (tl.loop_jacobian(tm, td, q + h * qd) - tl.loop_jacobian(tm, td, q - h * qd)) / (2 * h)
    C = tl.loop_bias(tm, td, q, qd)
    # on the scale of the bias: the centripetal terms |q̇|² · reach
    assert_close(C, dB @ qd, rel=1e-7, scale=length * speed**2 + np.abs(C).max())


@pytest.mark.parametrize("stabilization", [None, Baumgarte(), Baumgarte(50.0, 0.7)])
def test_both_sides_agree(scene, stabilization):
    tm, td = scene.textbook, scene.textbook_data
    ref, rd = scene.reference, scene.reference_data
    q, qd = _state(scene, seed=11)
    if scene.name == "welded":  # Pinocchio's 6-D error is log₆, ours (p₁−p₂, log₃): on Φ = 0
        q, qd = assemble(scene, q, qd)

    # the scales of rt70.crosscheck.loop_check.loop_scales: Φ is welded shut (0) on the manifold
    length, speed = reach(scene, q), np.abs(qd).max()
    B_ref, C_ref = rl.loop_jacobian(ref, rd, q), rl.loop_bias(ref, rd, q, qd)
    assert_close(tl.loop_residual(tm, td, q), rl.loop_residual(ref, rd, q), rel=TOL, scale=length)
    jacobian_scale = max(length, np.abs(B_ref).max())
    assert_close(tl.loop_jacobian(tm, td, q), B_ref, rel=TOL, scale=jacobian_scale)
    bias_scale = length * speed**2 + np.abs(C_ref).max()
    assert_close(tl.loop_bias(tm, td, q, qd), C_ref, rel=TOL, scale=bias_scale)
    Q = np.linspace(-1.0, 1.0, tm.nv)
    qdd_t, lam_t = tl.constrained_forward_dynamics(tm, td, q, qd, Q, stabilization)
    qdd_r, lam_r = rl.constrained_forward_dynamics(ref, rd, q, qd, Q, stabilization)
    assert_close(qdd_t, qdd_r, rel=TOL)
    B = tl.loop_jacobian(tm, td, q)
    assert_close(B.T @ lam_t, B.T @ lam_r, rel=TOL)  # the generalised reactions: unique
    if scene.name != "welded":  # λ itself where the rows are independent (z row: zero)
        assert_close(lam_t, lam_r, rel=TOL)


def test_constrained_equations_and_the_perturbation_law(scene):
    """``A q̈ = f + B_cᵀλ`` and ``Φ̈ = B_c q̈ + C = −2ζω Φ̇ − ω²Φ`` (2.2); λ least-norm."""
    tm, td = scene.textbook, scene.textbook_data
    q, qd = _state(scene, seed=5)
    gains = Baumgarte(30.0, 0.5)
    qdd, lam = tl.constrained_forward_dynamics(tm, td, q, qd, stabilization=gains)
    A = dynamics.mass_matrix(tm, td, q)
    Qc, Qd = forces.spring_damper_force(tm, td, q, qd)
    f = dynamics.gravity_force(tm, td, q) + Qc + Qd - dynamics.bias_force(tm, td, q, qd)
    B = tl.loop_jacobian(tm, td, q)
    phi, C = tl.loop_residual(tm, td, q), tl.loop_bias(tm, td, q, qd)
    scale = np.abs(A @ qdd).max() + np.abs(f).max()
    assert_close(A @ qdd, f + B.T @ lam, rel=1e-12, scale=scale)
    target = -2 * 0.5 * 30.0 * (B @ qd) - 900.0 * phi - C
    # Φ̈ on the scale of its terms: B q̈, C and the law's 2ζω B q̇ and ω² Φ
    terms = (
        np.abs(B) @ np.abs(qdd) + np.abs(C) + 30.0 * np.abs(B) @ np.abs(qd) + 900.0 * np.abs(phi)
    )
    target = B @ np.linalg.lstsq(B, target, rcond=1e-10)[0] + C  # dependent rows: least squares
    assert_close(B @ qdd + C, target, rel=1e-10, scale=terms.max())
    _, s, Vt = np.linalg.svd(B.T)
    null = Vt[int((s > 1e-10 * s[0]).sum()) :].T  # the null space of B_cᵀ
    assert null.shape[1] > 0  # every loop scene here has a dependent row
    # least norm: no component of λ in the null space of B_cᵀ, on λ's scale
    assert_close(null.T @ lam, np.zeros(null.shape[1]), rel=1e-12, scale=np.abs(lam).max())


def test_planar_loops_have_a_dependent_row():
    for name in LOOP_SCENES:
        scene = load_scene(name)
        B = tl.loop_jacobian(scene.textbook, scene.textbook_data, np.array([0.3, 0.2, 0.1]))
        assert B.shape == (3, 3) and np.linalg.matrix_rank(B) == 2
        # z: the mechanisms are planar
        assert_close(B[2], np.zeros(3), rel=MIN_REL, scale=np.abs(B).max())


def test_welded_rods_move_as_one_body():
    """A frame loop welding two rods on one pivot: q̈₁ = q̈₂ = −(Σ gravity torque)/(Σ I)."""
    scene = scene_from_text(welded(), "welded")
    tm, td = scene.textbook, scene.textbook_data
    q, qd = assemble(scene, np.array([0.3, 0.2]), np.array([1.0, 0.0]), keep=["ja"])
    assert_close(q, [0.3, 0.3], rel=1e-12)
    assert_close(qd, [1.0, 1.0], rel=1e-12)
    qdd, _ = tl.constrained_forward_dynamics(tm, td, q, qd)
    A = dynamics.mass_matrix(tm, td, q)
    torque = dynamics.gravity_force(tm, td, q).sum()
    assert_close(qdd, torque / A.sum() * np.ones(2), rel=1e-12)


def test_bad_gains_are_refused():
    for omega, zeta in ((0.0, 1.0), (10.0, -1.0), (np.nan, 1.0)):
        with pytest.raises(Rt70Error, match="Baumgarte"):
            Baumgarte(omega, zeta)
    assert_close(Baumgarte(20.0, 1.0).gains(), (400.0, 40.0), rel=MIN_REL)


# --- assembly --------------------------------------------------------------------


def test_assemble_keeps_the_crank():
    scene = load_scene("crank_slider")
    q, qd = assemble(
        scene, np.array([0.7, 0.0, 0.0]), np.array([10.0, 0.0, 0.0]), keep=["crank_joint"]
    )
    tm, td = scene.textbook, scene.textbook_data
    assert q[0] == 0.7 and qd[0] == 10.0  # kept: not touched
    phi, B = tl.loop_residual(tm, td, q), tl.loop_jacobian(tm, td, q)
    assert_close(phi, np.zeros_like(phi), rel=1e-13, scale=reach(scene, q))
    assert_close(B @ qd, np.zeros(len(B)), rel=1e-13, scale=np.abs(B) @ np.abs(qd))
    x = 0.1 * np.cos(0.7) + np.sqrt(0.4**2 - (0.1 * np.sin(0.7)) ** 2)  # the slider's position
    assert_close(q[2], x, rel=1e-13)


def test_assemble_refuses_what_cannot_close():
    scene = load_scene("four_bar")
    with pytest.raises(Rt70Error, match="Newton's method did not close"):
        assemble(scene, np.array([0.0, 0.0, 2.5]), keep=["crank_joint", "rocker_joint"])
    with pytest.raises(Rt70Error, match="unknown coordinate 'crank'"):
        assemble(scene, np.zeros(3), keep=["crank"])


# --- simulation --------------------------------------------------------------------


@pytest.fixture(scope="module")
def crank_slider_start():
    scene = load_scene("crank_slider")
    x0 = assemble(scene, np.zeros(3), np.array([10.0, 0.0, 0.0]), keep=["crank_joint"])
    return scene, x0


@pytest.mark.slow
def test_crank_slider_ten_seconds_stays_closed(crank_slider_start):
    """Target of issue 12: |Φ| ≤ 1e-10 over 10 s with stabilisation; the drift without."""
    scene, x0 = crank_slider_start
    kw = dict(side="reference", method="DOP853", rtol=1e-10, atol=1e-12)
    held = simulate(scene, (0.0, 10.0), x0, **kw)
    drifting = simulate(scene, (0.0, 10.0), x0, stabilization=None, **kw)
    assert held.success and drifting.success
    length = reach(scene, x0[0])
    residual = held.constraint_residual
    assert_close(residual, np.zeros_like(residual), rel=1e-10, scale=length)
    assert drifting.constraint_residual.max() > 10 * held.constraint_residual.max()
    # reactions do no work: a relative drift, whose own scale is 1
    assert_close(held.relative_drift, 0.0, rel=1e-8, scale=1.0)
    assert not held.drift_flagged
    speed = held.qd[:, 0]
    assert speed[0] == 10.0 and speed.min() > 5.0  # gravity normal to the plane: it runs on
    turns = (held.q[-1, 0] - held.q[0, 0]) / (2 * np.pi)
    assert 10.0 < turns < 20.0


def test_textbook_backend_follows_pinocchio(crank_slider_start):
    scene, x0 = crank_slider_start
    kw = dict(method="DOP853", rtol=1e-10, atol=1e-12, t_eval=np.linspace(0.0, 0.2, 5))
    tb = simulate(scene, (0.0, 0.2), x0, side="textbook", **kw)
    pin_ = simulate(scene, (0.0, 0.2), x0, side="reference", **kw)
    assert_close(tb.q, pin_.q, rel=1e-8)
    residual = tb.constraint_residual
    assert_close(residual, np.zeros_like(residual), rel=1e-10, scale=reach(scene, x0[0]))


def test_open_start_is_refused_and_rest_is_assembled():
    scene = load_scene("four_bar")
    with pytest.raises(SimulationError, match="violates loop 'coupler_rocker'.*assemble"):
        simulate(scene, (0.0, 0.1), (np.zeros(3), np.zeros(3)))
    with pytest.raises(Rt70Error, match="did not close.*close elsewhere"):  # q = 0: on one line
        assemble(scene, np.zeros(3))
    rest = simulate(scene, (0.0, 0.1))  # from rest where the closure search closed the loop
    assert rest.constraint_residual[0] <= CLOSURE_TOL * (1.0 + reach(scene, rest.q[0]))
    np.testing.assert_array_equal(rest.qd[0], 0.0)
    crank_slider = load_scene("crank_slider")
    result = simulate(crank_slider, (0.0, 0.1), method="DOP853", rtol=1e-8)
    assert_close(result.q[0], [0.0, 0.0, 0.5], rel=MIN_REL)  # slider moved
    residual = result.constraint_residual
    assert_close(
        residual, np.zeros_like(residual), rel=1e-8, scale=reach(crank_slider, result.q[0])
    )


def test_scenes_without_loops_report_no_residual():
    result = simulate(load_scene("double_pendulum"), (0.0, 0.01))
    assert result.constraint_residual.size == 0


# --- erratum X.3.11: the KKT matrix is indefinite -----------------------------------


def test_kkt_matrix_is_indefinite_and_plain_cg_breaks_down(crank_slider_start):
    scene, _ = crank_slider_start
    tm, td = scene.textbook, scene.textbook_data
    q, qd = assemble(scene, np.array([0.7, 0.0, 0.4]), np.array([10.0, 0.0, 0.0]), keep=[0])
    A = dynamics.mass_matrix(tm, td, q)
    B = tl.loop_jacobian(tm, td, q)[:2]  # the independent rows
    g = -tl.loop_bias(tm, td, q, qd)[:2]
    K = np.block([[A, B.T], [B, np.zeros((2, 2))]])
    eig = np.linalg.eigvalsh(K)
    assert (eig < 0).sum() == 2 and (eig > 0).sum() == 3  # m negative, n positive
    # a crank torque for which the first CG step has zero curvature rᵀKr = 0
    u = np.array([1.0, 0.0, 0.0])
    f = -2.0 * (g @ B @ u) / (u @ A @ u) * u
    rhs = np.concatenate([f, g])
    x, info = scipy.sparse.linalg.cg(K, rhs, maxiter=50, rtol=1e-12)
    assert info != 0 and np.linalg.norm(K @ x - rhs) > 1e6 * np.linalg.norm(rhs)
    sol = solve_kkt(A, B, f, g)  # the range-space method
    # the equations on the scale of their terms
    terms = np.abs(A) @ np.abs(sol.x) + np.abs(B.T) @ np.abs(sol.lam)
    assert_close(A @ sol.x - B.T @ sol.lam, f, rel=1e-12, scale=terms)
    assert_close(B @ sol.x, g, rel=1e-12, scale=np.abs(B) @ np.abs(sol.x))


def test_modes_of_the_crank_slider_on_its_table_is_one_rigid_mode(capsys):
    """Gravity normal to its plane: one motion the loops leave, held by nothing — a rigid
    mode on the manifold (not the tree's three, not a refusal)."""
    assert rt70.cli.main.main(["modes", "crank_slider", "--json"]) == 0
    out = json.loads(capsys.readouterr().out)
    assert out["constraints"]["loop_rows"] == 3 and out["constraints"]["rank"] == 2
    assert [m["kind"] for m in out["modes"]] == ["rigid"]


def test_rt70_modes_of_the_four_bar_match_its_simulated_small_oscillation():
    """``rt70 modes four_bar`` (textbook side, on the manifold, with the multipliers'
    geometric stiffness) against the period of a small oscillation integrated with
    Pinocchio's ``constraintDynamics``: an independent check of the constrained modes."""
    from rt70.linear.constrained_scene import constrained_linearize, constrained_modes
    from rt70.scenes.loop_scenes import start_state

    out = subprocess.run(
        [sys.executable, "-m", "rt70", "modes", "four_bar", "--json"],
        capture_output=True,
        text=True,
        check=True,
    )
    f_cli = json.loads(out.stdout)["modes"][0]["freq_hz"]
    scene = load_scene("four_bar")
    model = constrained_linearize(
        scene,
        tl.loop_residual,
        tl.loop_jacobian,
        q_start=start_state(scene)[0],
        descend=True,
    )
    # the command runs this very computation: bit for bit
    assert constrained_modes(model)["modes"][0]["freq_hz"] == f_cli
    qe = model.equilibrium.q
    assert np.linalg.eigvalsh(model.reduced.K_r).min() > 0  # the stable equilibrium
    q0, qd0 = assemble(scene, qe + np.array([1e-4, 0.0, 0.0]), keep=["crank_joint"])
    t = np.linspace(0.0, 3.0 / f_cli, 3001)
    run = simulate(scene, (0.0, t[-1]), (q0, qd0), method="DOP853", rtol=1e-11, t_eval=t)
    x = run.q[:, 0] - qe[0]
    up = np.where((x[:-1] < 0) & (x[1:] >= 0))[0]
    crossings = t[up] - x[up] * (t[up + 1] - t[up]) / (x[up + 1] - x[up])
    assert len(crossings) >= 2
    f_sim = (len(crossings) - 1) / (crossings[-1] - crossings[0])
    assert_close(f_sim, f_cli, rel=1e-7)
