"""The closed-chain wiring (rt70.linear.constrained_scene) on scenes closed by hand.

The loop functions of ``<rt70:loop>`` are not needed to test the wiring: any
``(model, data, q) → Φ`` / ``→ B_c`` pair of a side serves. Here:

- no closure at all: the RT-70 servo scene must give exactly what ``rt70 modes`` gives;
- a linear closure (a coordinate fixed) must give ``linearize``'s locked model;
- a nonlinear closure of the double pendulum (its tip on a vertical line, a one-DOF
  closed chain) written with each side's own point kinematics: the two sides and the
  two reductions (null space, coordinate partition) must agree.
"""

from __future__ import annotations

import json

import numpy as np
import pytest

from rt70.cli.main import main
from rt70.errors import Rt70Error
from rt70.linear import constrained_scene as cs
from rt70.linear import linearize as lin
from rt70.linear import modal
from rt70.model.scene import load_scene
from rt70.reference import points as ref_points
from rt70.testing import MIN_REL, assert_close
from rt70.textbook import points as tb_points

TIP = ("link2", np.array([1.0, 0.0, 0.0]))
LINE_X = 1.2  # the vertical line x = 1.2 m the tip slides on


def _tip_on_line(points):
    def residual(model, data, q):
        return np.array([points.point_position(model, data, q, *TIP)[0] - LINE_X])

    def jacobian(model, data, q):
        return points.point_jacobian(model, data, q, *TIP)[0][:1]

    return residual, jacobian


def _no_loop(model, data, q):
    return np.zeros(0)


def _no_loop_jacobian(model, data, q):
    return np.zeros((0, q.size))


@pytest.mark.slow
@pytest.mark.parametrize(
    "argv",
    [["rt70_servo"], ["rt70", "--elevation", "30", "--lock-axes"]],
    ids=["servo-locked-rotor", "rt70-axes-locked"],
)
@pytest.mark.parametrize("method", cs.METHODS)
def test_without_loops_it_is_rt70_modes(capsys, argv, method):
    """An empty closure: the equilibrium with the axes held, and the spectrum with the
    drives' locked rotors (rt70_servo) or with the axes locked (rt70 --lock-axes)."""
    assert main(["modes", *argv, "--json"]) == 0
    want = json.loads(capsys.readouterr().out)
    scene = load_scene(argv[0])
    lock = "--lock-axes" in argv
    model = cs.constrained_linearize(
        scene, _no_loop, _no_loop_jacobian, held=want["held"], lock_held=lock, method=method
    )
    got = cs.constrained_modes(model)
    assert got["locked_rotor"] == want["locked_rotor"] == (not lock)
    assert got["constraints"]["loop_rows"] == 0
    assert got["constraints"]["rank"] == (2 if lock else 0)
    f_want = np.array([r["freq_hz"] for r in want["modes"]])
    f_got = np.array([r["freq_hz"] for r in got["modes"]])
    assert_close(f_got, f_want, rel=1e-8)
    assert [r["dominant"] for r in got["modes"]] == [r["dominant"] for r in want["modes"]]
    z_want = np.array([r["zeta"] for r in want["modes"]])
    assert_close([r["zeta"] for r in got["modes"]], z_want, rel=1e-7)
    if lock:  # the locked axes do not move in the full-coordinate shapes
        for r in got["modes"]:
            held = [r["shape"][name] for name in want["held"]]
            size = max(abs(v) for v in r["shape"].values())  # the shape's own scale
            assert_close(held, np.zeros(len(held)), rel=MIN_REL, scale=size, what=r["dominant"])


def test_a_fixed_coordinate_is_the_locked_model():
    scene = load_scene("double_pendulum")
    model, data = scene.textbook, scene.textbook_data

    def residual(model_, data_, q):
        return np.array([q[0] - 0.3])

    def jacobian(model_, data_, q):
        return np.array([[1.0, 0.0]])

    start = np.array([0.2, -1.5])
    got = cs.constrained_linearize(scene, residual, jacobian, q_start=start)
    q0 = lin.equilibrium(scene, held={"joint1": 0.3}, q_start=start, tol=1e-13)
    assert_close(q0[1], -np.pi / 2 - 0.3, rel=1e-10)  # link 2 hangs
    assert_close(got.equilibrium.q, q0, rel=1e-10)
    locked = lin.linearize(scene, q0, locked=("joint1",))
    want = modal.modes(locked.M, locked.K)
    res = cs.constrained_modes(got)
    assert_close([r["freq_hz"] for r in res["modes"]], want.freq_hz, rel=1e-8)
    shape = res["modes"][0]["shape"]
    assert_close(shape["joint1"], 0.0, rel=MIN_REL, scale=abs(shape["joint2"]))
    assert_close(res["modes"][0]["shape"]["joint2"], want.shapes[0, 0], rel=1e-8)
    # its multiplier is the torque that holds joint1: minus gravity's moment about it
    Qg = lin.static_force(scene, q0)
    assert_close(got.equilibrium.lam, [-Qg[0]], rel=1e-8)
    assert model.nv == 2 and data is scene.textbook_data


@pytest.fixture(scope="module")
def tip_models():
    scene = load_scene("double_pendulum")
    start = np.array([-0.3, -0.6])
    out = {}
    for side, points in (("textbook", tb_points), ("reference", ref_points)):
        for method in cs.METHODS:
            out[side, method] = cs.constrained_linearize(
                scene, *_tip_on_line(points), side=side, method=method, q_start=start, tol=1e-12
            )
    return out


def test_tip_on_a_line_both_sides_both_reductions(tip_models):
    base = tip_models["textbook", "null-space"]
    q = base.equilibrium.q
    # on the line, and the gravity not balanced by the line is zero along the manifold
    assert_close(np.cos(q[0]) + np.cos(q[0] + q[1]), LINE_X, rel=1e-12)
    w = cs.constrained_modes(base)["modes"][0]
    assert w["kind"] == "elastic"
    for key, other in tip_models.items():
        assert_close(other.equilibrium.q, q, rel=1e-10, what=str(key))
        row = cs.constrained_modes(other)["modes"][0]
        assert_close(row["freq_hz"], w["freq_hz"], rel=1e-8, what=str(key))
        shape = list(row["shape"].values())
        assert_close(shape, list(w["shape"].values()), rel=1e-8, what=str(key))


def _minimal_tip_on_line(psi1):
    """Closed form of the scene's closed chain in its link-1 angle ψ1 (unit rods, 1 kg).

    The tip on x = LINE_X: ``cos ψ1 + cos ψ2 = LINE_X``, link 2 pointing down (ψ2 < 0).
    Returns (V, the centres of mass and angles (p1, p2, ψ1, ψ2) as one vector).
    """
    psi2 = -np.arccos(LINE_X - np.cos(psi1))
    p1 = 0.5 * np.array([np.cos(psi1), np.sin(psi1)])
    p2 = 2 * p1 + 0.5 * np.array([np.cos(psi2), np.sin(psi2)])
    return 9.81 * (p1[1] + p2[1]), np.array([*p1, *p2, psi1, psi2])


def _closed_form_frequency(psi1: float) -> tuple[float, float]:
    """(V'(ψ1), f = √(V''/m_r)/2π) by five-point differences of the closed form.

    The stencils' error is O(h⁴ V⁽⁵⁾): the closed form's arccos is singular 0.21 rad from
    the equilibrium, so V' takes h = 2.5e-4 (truncation ≈ 3e-12, rounding ≈ 1e-11);
    V'' takes h = 1e-3 (its rounding grows as ε V/h²).
    """

    def d(f, x, k, h=1e-3):  # five-point first (k=1) and second (k=2) derivatives
        v = [f(x + j * h) for j in (-2, -1, 0, 1, 2)]
        if k == 1:
            return (v[0] - 8 * v[1] + 8 * v[3] - v[4]) / (12 * h)
        return (-v[0] + 16 * v[1] - 30 * v[2] + 16 * v[3] - v[4]) / (12 * h * h)

    V = lambda x: _minimal_tip_on_line(x)[0]  # noqa: E731
    rate = d(lambda x: _minimal_tip_on_line(x)[1], psi1, 1)
    m_r = rate[:2] @ rate[:2] + rate[2:4] @ rate[2:4] + (rate[4] ** 2 + rate[5] ** 2) / 12
    return d(V, psi1, 1, 2.5e-4), np.sqrt(d(V, psi1, 2) / m_r) / (2 * np.pi)


def test_tip_on_a_line_against_its_closed_form(tip_models):
    """ω² = V''/m_r at the scene's equilibrium, from the closed form (no rt70 code): V' = 0
    there and the frequency agrees to the differences' error."""
    q = tip_models["textbook", "null-space"].equilibrium.q
    slope, f = _closed_form_frequency(q[0])
    # the scene's equilibrium is V's stationary point: V' zero on the scale of the
    # gravity moments, the rods' weight (2 × 1 kg) times a rod's length (1 m)
    assert_close(slope, 0.0, rel=5e-12, scale=9.81 * 2.0)
    for key, model in tip_models.items():
        f_model = cs.constrained_modes(model)["modes"][0]["freq_hz"]
        assert_close(f_model, f, rel=1e-8, what=str(key))


def test_tip_on_a_line_needs_its_geometric_stiffness(tip_models):
    """The line's reaction (horizontal) times the tip path's curvature is part of K_r."""
    base = tip_models["textbook", "null-space"]
    red = base.reduced
    assert abs(red.K_geometric[0, 0]) > 0.05 * abs(red.K_r[0, 0])


def test_tip_on_a_line_with_its_bias_is_exact(tip_models):
    """C = Ḃ_c q̇ of the line, written by hand: ẍ_tip at q̈ = 0 is −Σ cos ψ_i ψ̇_i²."""

    def bias(model, data, q, qd):
        psi, w = np.cumsum(q), np.cumsum(qd)
        return np.array([-(np.cos(psi) @ w**2)])

    scene = load_scene("double_pendulum")
    exact = cs.constrained_linearize(
        scene, *_tip_on_line(tb_points), q_start=np.array([-0.3, -0.6]), tol=1e-12, loop_bias=bias
    )
    base = tip_models["textbook", "null-space"]
    G, G_diff = exact.reduced.K_geometric, base.reduced.K_geometric
    assert_close(G, G_diff, rel=1e-8)
    f = cs.constrained_modes(exact)["modes"][0]["freq_hz"]
    assert_close(f, cs.constrained_modes(base)["modes"][0]["freq_hz"], rel=1e-9)


def test_bad_side_and_method_are_refused():
    scene = load_scene("double_pendulum")
    with pytest.raises(Rt70Error, match="'pinocchio' is now 'reference'"):
        cs.constrained_linearize(scene, _no_loop, _no_loop_jacobian, side="pinocchio")
    with pytest.raises(Rt70Error, match="unknown side"):
        cs.constrained_linearize(scene, _no_loop, _no_loop_jacobian, side="ref")
    with pytest.raises(Rt70Error, match="unknown method"):
        cs.constrained_linearize(scene, _no_loop, _no_loop_jacobian, method="qr")
    with pytest.raises(Rt70Error, match="q_start has shape"):
        cs.constrained_linearize(scene, _no_loop, _no_loop_jacobian, q_start=np.zeros(3))
    with pytest.raises(Rt70Error, match="double_pendulum: no coordinate"):
        cs.constrained_linearize(scene, _no_loop, _no_loop_jacobian, held={"elevation": 1.0})


if __name__ == "__main__":  # python tests/test_constrained_scene.py: the numbers in the docs
    scene = load_scene("double_pendulum")
    start = np.array([-0.3, -0.6])
    base = None
    for side, points in (("textbook", tb_points), ("reference", ref_points)):
        for method in cs.METHODS:
            m = cs.constrained_linearize(
                scene, *_tip_on_line(points), side=side, method=method, q_start=start, tol=1e-12
            )
            row = cs.constrained_modes(m)["modes"][0]
            if base is None:
                slope, f_closed = _closed_form_frequency(m.equilibrium.q[0])
                print(f"closed form at q*: V' = {slope:.1e} N·m, f = {f_closed:.12g} Hz")
                base = (m.equilibrium.q, f_closed)
            print(
                f"tip on x = {LINE_X}: {side:<9} {method:<10} q* = {m.equilibrium.q}, "
                f"λ = {m.equilibrium.lam[0]:.10g} N, f = {row['freq_hz']:.12g} Hz "
                f"(Δq* {np.abs(m.equilibrium.q - base[0]).max():.1e}, "
                f"f/f_closed − 1 = {row['freq_hz'] / base[1] - 1:.1e})"
            )
            if method == "null-space":
                red = m.reduced
                naive = np.sqrt((red.K_r - red.K_geometric)[0, 0] / red.M_r[0, 0]) / (2 * np.pi)
                print(
                    f"  K_r = {red.K_r[0, 0]:.6g}, of it G: {red.K_geometric[0, 0]:.6g}; "
                    f"without G f = {naive:.6g} Hz"
                )
    import contextlib
    import io

    for argv in (["rt70_servo"], ["rt70", "--elevation", "30", "--lock-axes"]):
        text = io.StringIO()
        with contextlib.redirect_stdout(text):
            main(["modes", *argv, "--json"])
        want = json.loads(text.getvalue())
        lock = "--lock-axes" in argv
        for method in cs.METHODS:
            m = cs.constrained_linearize(
                load_scene(argv[0]),
                _no_loop,
                _no_loop_jacobian,
                held=want["held"],
                lock_held=lock,
                method=method,
            )
            got = cs.constrained_modes(m)["modes"]
            f = np.array(
                [[r["freq_hz"], w["freq_hz"]] for r, w in zip(got, want["modes"], strict=True)]
            )
            z = np.array(
                [[r["zeta"], w["zeta"]] for r, w in zip(got, want["modes"], strict=True)], float
            )
            print(
                f"rt70 modes {' '.join(argv)}, no loop, {method}: {len(got)} modes, "
                f"max|f/f_cli − 1| = {np.max(np.abs(f[:, 0] / f[:, 1] - 1)):.1e}, "
                f"max|ξ/ξ_cli − 1| = {np.nanmax(np.abs(z[:, 0] / z[:, 1] - 1)):.1e}"
            )
