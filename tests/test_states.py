"""Extra states of the simulation: components integrated with the mechanics.

The module: rt70/simulation/states.py.
"""

import numpy as np
import pytest
from scipy.integrate import solve_ivp

import rt70.reference as reference
from rt70.errors import Rt70Error, ShapeError
from rt70.model.scene import load_scene
from rt70.simulation.backends import BACKENDS
from rt70.simulation.simulate import IMPLICIT, simulate
from rt70.simulation.states import EnergyAudit, StateComponent
from rt70.testing import assert_close


class Filter(StateComponent):
    """First-order filter of the first coordinate: ṡ = (q_0 − s)/τ."""

    names = ("filtered_q0",)

    def __init__(self, tau: float, s0: float = 0.0) -> None:
        self.tau = tau
        self.initial = np.array([s0])
        self.atol = np.array([1e-12])

    def derivative(self, t, q, qd, s, forces):
        return np.array([(q[0] - s[0]) / self.tau])


class Travel(StateComponent):
    """∫ q̇ dt of every coordinate (closed form: q(t) − q(0)) and ∫ q̇ᵀq̇ dt."""

    def __init__(self, n: int) -> None:
        self.names = tuple(f"travel{i}" for i in range(n)) + ("qd_squared",)
        self.initial = np.zeros(n + 1)
        self.atol = np.full(n + 1, 1e-12)

    def derivative(self, t, q, qd, s, forces):
        return np.r_[qd, qd @ qd]


class Anchor(StateComponent):
    """A spring of stiffness k from the first coordinate to a state that stays put."""

    names = ("anchor",)

    def __init__(self, k: float, at: float, n: int) -> None:
        self.k, self.n = k, n
        self.initial = np.array([at])
        self.atol = np.array([1e-9])

    def derivative(self, t, q, qd, s, forces):
        return np.zeros(1)

    def force(self, t, q, qd, s):
        Q = np.zeros(self.n)
        Q[0] = -self.k * (q[0] - s[0])
        return Q


def test_a_filter_integrates_with_the_mechanics_as_an_independent_solve():
    """The filter's state against one solve_ivp of [q, q̇, s] written here by hand."""
    scene = load_scene("double_pendulum")
    model, data = scene.reference, reference.ReferenceData(scene.reference)
    q0, qd0, tau = np.array([0.8, -0.3]), np.array([0.0, 0.5]), 0.2
    t = np.linspace(0.0, 2.0, 41)
    r = simulate(
        scene,
        (0.0, 2.0),
        (q0, qd0),
        method="DOP853",
        rtol=1e-11,
        t_eval=t,
        components=[Filter(tau, s0=0.1)],
    )

    def rhs(_t, x):
        q, qd, s = x[:2], x[2:4], x[4]
        return np.r_[qd, reference.forward_dynamics(model, data, q, qd), (q[0] - s) / tau]

    ref = solve_ivp(rhs, (0.0, 2.0), np.r_[q0, qd0, 0.1], "DOP853", t, rtol=1e-12, atol=1e-13)
    assert r.success and ref.success
    assert list(r.states) == ["dissipated", "input_work", "filtered_q0"]
    assert_close(r.q, ref.y[:2].T, rel=1e-8, what="q")
    s = r.states["filtered_q0"]
    assert_close(s, ref.y[4], rel=1e-8, what="filter state")
    assert np.ptp(s) > 0.1  # it moved: the comparison is not of two constants


@pytest.mark.parametrize("side", ["reference", "textbook"])
def test_integrals_of_the_velocities_are_the_displacements(side):
    """∫ q̇ dt = q(t) − q(0) (closed form) and ∫ q̇ᵀq̇ dt ≥ 0, increasing, on a damped model."""
    scene = load_scene("two_body_gravity")
    n = scene.textbook.nv
    x0 = (np.full(n, 0.02), np.linspace(-0.1, 0.1, n))
    r = simulate(
        scene, (0.0, 0.2), x0, side=side, method="DOP853", rtol=1e-10, components=[Travel(n)]
    )
    assert r.success
    travel = np.column_stack([r.states[f"travel{i}"] for i in range(n)])
    assert_close(travel, r.q - r.q[0], rel=1e-8)
    assert np.abs(r.q - r.q[0]).max() > 1e-3
    assert np.all(np.diff(r.states["qd_squared"]) >= 0.0) and r.states["qd_squared"][-1] > 0.0


def test_a_component_force_acts_like_the_same_input():
    """force() from a state is the generalised force an ``inputs`` callable would give."""
    scene = load_scene("double_pendulum")
    x0 = (np.array([0.4, 0.2]), np.zeros(2))

    def spring(t, q, qd):
        return np.array([-30.0 * (q[0] - 0.25), 0.0])

    class Watcher(Anchor):  # the same state, pushing nothing
        def force(self, t, q, qd, s):
            return None

    kw = dict(method="DOP853", rtol=1e-10)
    a = simulate(scene, (0.0, 1.0), x0, components=[Anchor(30.0, 0.25, 2)], **kw)
    b = simulate(scene, (0.0, 1.0), x0, inputs=spring, components=[Watcher(30.0, 0.25, 2)], **kw)
    free = simulate(scene, (0.0, 1.0), x0, **kw)
    # the same arithmetic by construction (one force, added where an input is): bit for bit
    assert np.array_equal(a.t, b.t) and np.array_equal(a.q, b.q)
    assert np.array_equal(a.input_work, b.input_work) and np.abs(a.input_work).max() > 0.1
    # the component's work enters the balance: a relative drift, scale 1
    assert_close(a.relative_drift, 0.0, rel=1e-8, scale=1.0)
    assert np.abs(a.q[-1] - free.q[-1]).max() > 0.1  # the force did act


def _before(scene, side, method, rtol, x0, t_span, inputs=None):
    """The simulation as written before the seam: x = [q, q̇, E_ψ, W_u] by hand."""
    backend = BACKENDS[side](scene)
    n = scene.textbook.nv
    q0, qd0 = x0
    T0, Ug0, Uc0 = backend.energies(q0, qd0)
    energy_scale = max(T0 + Uc0, 1e-12 * max(abs(Ug0), 1.0), 1e-300)
    atol = np.r_[np.full(2 * n, 1e-3 * rtol), np.full(2, rtol * energy_scale)]

    def Q_u(t, q, qd):
        return None if inputs is None else np.asarray(inputs(t, q, qd), dtype=float)

    def rhs(t, x):
        q, qd = x[:n], x[n : 2 * n]
        Qu = Q_u(t, q, qd)
        qdd, Qd = backend.accelerations(q, qd, Qu)
        power_u = 0.0 if Qu is None else float(qd @ Qu)
        return np.concatenate([qd, qdd, [-float(qd @ Qd), power_u]])

    kw = {}
    if method in IMPLICIT and backend.jacobian(q0, qd0, None) is not None:

        def jac(t, x):
            q, qd = x[:n], x[n : 2 * n]
            J = np.zeros((2 * n + 2, 2 * n + 2))
            J[: 2 * n, : 2 * n] = backend.jacobian(q, qd, Q_u(t, q, qd))
            return J

        kw["jac"] = jac
    return solve_ivp(
        rhs, t_span, np.r_[q0, qd0, 0.0, 0.0], method=method, rtol=rtol, atol=atol, **kw
    )


@pytest.mark.slow
@pytest.mark.parametrize("side", ["reference", "textbook"])
@pytest.mark.parametrize(
    "name, method, inputs",
    [
        ("two_body_gravity", "BDF", None),
        ("double_pendulum", "DOP853", lambda t, q, qd: np.array([np.sin(3.0 * t), 0.1 * qd[0]])),
    ],
)
def test_the_energy_audit_as_a_component_is_bit_identical_to_the_hand_written_state(
    name, method, inputs, side
):
    scene = load_scene(name)
    n = scene.textbook.nv
    x0 = (np.linspace(0.02, 0.05, n), np.linspace(-0.1, 0.1, n))
    old = _before(scene, side, method, 1e-7, x0, (0.0, 0.2), inputs)
    new = simulate(scene, (0.0, 0.2), x0, side=side, method=method, rtol=1e-7, inputs=inputs)
    # the seam performs the hand-written state's operations on the same arrays: bit for bit
    assert np.array_equal(new.t, old.t)
    assert np.array_equal(new.q, old.y[:n].T) and np.array_equal(new.qd, old.y[n : 2 * n].T)
    assert np.array_equal(new.dissipated, old.y[2 * n]) and new.states["dissipated"] is not None
    assert np.array_equal(new.input_work, old.y[2 * n + 1])
    assert (new.nfev, new.njev, new.nlu) == (old.nfev, old.njev, old.nlu)
    assert new.dissipated[-1] > 0.0 or new.input_work[-1] != 0.0


def test_component_states_are_saved_by_name(tmp_path):
    scene = load_scene("double_pendulum")
    r = simulate(
        scene,
        (0.0, 0.2),
        (np.array([0.3, 0.0]), np.zeros(2)),
        method="DOP853",
        components=[Filter(0.1)],
    )
    csv = r.save(tmp_path / "run.csv")
    header = csv.read_text().splitlines()[0].split(",")
    assert header[-1] == "state:filtered_q0" and header.count("dissipated") == 1
    table = np.loadtxt(csv, delimiter=",", skiprows=1)
    assert np.array_equal(table[:, -1], r.states["filtered_q0"])
    npz = np.load(r.save(tmp_path / "run.npz"))
    assert np.array_equal(npz["state:filtered_q0"], r.states["filtered_q0"])


def test_bad_components_are_refused_with_their_name():
    scene = load_scene("double_pendulum")
    span, x0 = (0.0, 0.1), (np.array([0.3, 0.0]), np.zeros(2))
    with pytest.raises(Rt70Error, match="named twice: filtered_q0"):
        simulate(scene, span, x0, components=[Filter(0.1), Filter(0.2)])
    with pytest.raises(Rt70Error, match="named twice: dissipated"):
        clash = Filter(0.1)
        clash.names = ("dissipated",)
        simulate(scene, span, x0, components=[clash])
    wrong = Filter(0.1)
    wrong.atol = np.ones(2)
    with pytest.raises(ShapeError, match=r"Filter: atol must have shape \(1,\)"):
        simulate(scene, span, x0, components=[wrong])

    class Broken(Filter):
        def derivative(self, t, q, qd, s, forces):
            return np.zeros(3)

    with pytest.raises(ShapeError, match=r"Broken: derivative must have shape \(1,\)"):
        simulate(scene, span, x0, components=[Broken(0.1)])


def test_energy_audit_names_and_tolerance():
    audit = EnergyAudit(1e-5)
    assert audit.names == ("dissipated", "input_work")
    assert np.array_equal(audit.atol, [1e-5, 1e-5]) and not audit.initial.any()


def test_progress_bar_only_when_asked(capsys):
    scene = load_scene("double_pendulum")
    x0 = (np.array([0.3, 0.0]), np.zeros(2))
    simulate(scene, (0.0, 0.2), x0, method="DOP853")
    assert capsys.readouterr().err == ""
    simulate(scene, (0.0, 0.2), x0, method="DOP853", progress=True)
    err = capsys.readouterr().err
    assert "100%" in err and "0.200/0.200 s" in err
