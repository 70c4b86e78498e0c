"""State equations of a causal linear bond graph: ``ẋ = A x + B u``, ``y = C x + D u``.

The states are the energy variables of the storage elements, in the order they were
added: the momentum ``p`` of every ``I`` (2.3) and the displacement ``q`` of every ``C``
(2.4) — the generalised momenta and coordinates of the companion source 003, §2.1
step 6. The inputs are the sources' inputs.

How the equations are formed (003.4, steps 4–6, done in causal order): every bond's
effort and flow is computed by exactly one of its two ends (:mod:`causality`), as a
linear form in ``[x; u]``. The forms are evaluated recursively from the storages'
states and the sources' inputs through the junction laws (2.1)/(2.2), the transformer
(2.6) and gyrator (2.7) laws and the resistors (2.5); then ``ṗ = e`` on each ``I``
bond and ``q̇ = f`` on each ``C`` bond. Each coefficient is a short product/sum of the
parameters, so it carries a few rounding errors only (no linear solve). A cycle in
this evaluation is an algebraic loop (resistors fixing each other's variables); then
all bond variables are solved at once from their causal laws, ``(1 − N) v = S [x; u]``
(a singular loop is refused).

Sign convention: a bond carries ``e`` and ``f`` with ``e·f`` the power in its
direction. A one-port whose bond points *into* it sees ``(e, f)``; one whose bond
points *away* sees ``(e, −f)`` (power into the element is always ``e·f_in``).
"""

from __future__ import annotations

from dataclasses import dataclass, field

import numpy as np
from scipy.linalg import matrix_balance

from rt70.bondgraph.causality import Causality, assign_causality
from rt70.bondgraph.graph import Bond, BondGraph, BondGraphError, CausalityError

Key = tuple[str, str]  # (bond name, "e" or "f")


@dataclass(frozen=True)
class PowerBalance:
    """The power budget at one state: ``stored == supplied − dissipated`` (exactly).

    Attributes
    ----------
    stored : float
        ``dH/dt = ∇H(x) · (A x + B u)``.
    supplied : float
        Power the sources deliver into the graph, ``Σ e·f`` on their bonds.
    dissipated : float
        Power the ``R`` elements take, ``Σ R f²`` (≥ 0).
    """

    stored: float
    supplied: float
    dissipated: float


@dataclass
class StateEquations:
    """The linear state equations of a bond graph, with names and its energy.

    Attributes
    ----------
    A, B, C, D : numpy.ndarray
        ``ẋ = A x + B u``, ``y = C x + D u``.
    states, inputs, outputs : list[str]
        ``p_<I name>`` / ``q_<C name>``; the sources' inputs; the requested outputs.
    """

    A: np.ndarray
    B: np.ndarray
    C: np.ndarray
    D: np.ndarray
    states: list[str]
    inputs: list[str]
    outputs: list[str]
    causality: Causality
    forms: dict[Key, np.ndarray] = field(repr=False)

    def energy(self, x: np.ndarray) -> float:
        """Stored energy ``H(x) = Σ p²/2I + Σ k q²/2`` (k = 1/C)."""
        return float(0.5 * x @ (self._hessian() @ x))

    def _hessian(self) -> np.ndarray:
        els = self.causality.graph.elements
        gains = []
        for s in self.states:
            el = els[s[2:]]
            gains.append(1.0 / el.value if el.kind == "I" else el.value)
        return np.diag(gains)

    def bond_values(self, x: np.ndarray, u: np.ndarray) -> dict[Key, float]:
        """Every bond's effort and flow at ``(x, u)``: ``{(bond, "e"|"f"): value}``."""
        z = np.concatenate([np.asarray(x, float), np.asarray(u, float)])
        return {k: float(v @ z) for k, v in self.forms.items()}

    def power(self, x: np.ndarray, u: np.ndarray) -> PowerBalance:
        """The power budget at ``(x, u)`` from the bond variables (see :class:`PowerBalance`)."""
        x, u = np.asarray(x, float), np.asarray(u, float)
        values = self.bond_values(x, u)
        stored = float((self._hessian() @ x) @ (self.A @ x + self.B @ u))
        supplied = dissipated = 0.0
        for b in self.causality.graph.bonds:
            ef = values[(b.name, "e")] * values[(b.name, "f")]
            for end, sign in ((b.tail, 1.0), (b.head, -1.0)):
                kind = self.causality.graph.elements[end].kind
                if kind in ("Se", "Sf"):
                    supplied += sign * ef
                elif kind == "R":
                    dissipated -= sign * ef
        return PowerBalance(stored, supplied, dissipated)

    def transfer(self, s: complex) -> np.ndarray:
        """The transfer matrix ``C (sI − A)⁻¹ B + D`` at the complex frequency ``s``.

        Solved in balanced coordinates (``scipy.linalg.matrix_balance``, a diagonal
        similarity): a drive's entries span twenty orders of magnitude (``C_r`` against
        ``1/J_l``), and the unbalanced solve loses up to 1e-10 relative there.
        """
        n = self.A.shape[0]
        Ab, (scale, _) = matrix_balance(self.A, permute=False, separate=True)
        Bb = self.B / scale[:, None]
        Cb = self.C * scale[None, :]
        return Cb @ np.linalg.solve(s * np.eye(n) - Ab, Bb.astype(complex)) + self.D


class _AlgebraicLoop(Exception):
    """Internal: the causal evaluation met a cycle (the keys on it)."""

    def __init__(self, keys: list[Key]) -> None:
        super().__init__(keys)
        self.keys = list(keys)


class _Former:
    """Evaluates each bond variable as a linear form in ``z = [x; u]``, in causal order."""

    def __init__(self, causality: Causality, states: list[str], inputs: list[str]) -> None:
        self.c = causality
        self.g = causality.graph
        self.n = len(states) + len(inputs)
        self.index = {name: i for i, name in enumerate(states)}
        self.index.update({f"u:{name}": len(states) + i for i, name in enumerate(inputs)})
        self.width = self.n  # length of a form; longer while solving a loop
        self.symbolic: dict[Key, int] | None = None
        self.forms: dict[Key, np.ndarray] = {}
        self.busy: list[Key] = []

    def unit(self, key: str) -> np.ndarray:
        v = np.zeros(self.width)
        v[self.index[key]] = 1.0
        return v

    def get(self, key: Key) -> np.ndarray:
        if key in self.forms:
            return self.forms[key]
        if self.symbolic is not None:  # a bond variable stands for itself
            v = np.zeros(self.width)
            v[self.n + self.symbolic[key]] = 1.0
            return v
        if key in self.busy:
            raise _AlgebraicLoop(self.busy[self.busy.index(key) :])
        self.busy.append(key)
        form = self._law_of(key)
        self.busy.pop()
        self.forms[key] = form
        return form

    def _law_of(self, key: Key) -> np.ndarray:
        bond = self.g.bond_named(key[0])
        receiver = self.c.effort_to[bond.name]
        sender = bond.head if bond.tail == receiver else bond.tail
        return self._law(bond, key[1], sender if key[1] == "e" else receiver)

    def solve_all(self, loop: list[Key]) -> None:
        """Every bond variable at once: ``v = N v + S z`` solved as ``(1 − N) v = S z``.

        Used only when the causal evaluation meets an algebraic loop (resistors that
        fix each other's variables); the loop-free evaluation needs no solve.
        """
        keys = [(b.name, var) for b in self.g.bonds for var in ("e", "f")]
        self.symbolic = {k: i for i, k in enumerate(keys)}
        self.width = self.n + len(keys)
        self.forms, self.busy = {}, []
        rows = np.array([self._law_of(k) for k in keys])
        self.symbolic, self.width = None, self.n
        matrix = np.eye(len(keys)) - rows[:, self.n :]
        if np.linalg.matrix_rank(matrix) < len(keys):
            names = ", ".join(f"{b}.{v}" for b, v in loop)
            raise CausalityError(
                f"bond graph '{self.g.name}': the algebraic loop through {names} has no "
                "unique solution (singular junction structure)"
            )
        solved = np.linalg.solve(matrix, rows[:, : self.n])
        self.forms = {k: solved[i] for i, k in enumerate(keys)}

    def _law(self, bond: Bond, var: str, name: str) -> np.ndarray:
        el = self.g.elements[name]
        s = 1.0 if bond.head == name else -1.0  # +1 when the bond points into `name`
        if el.kind in ("Se", "Sf"):
            return self.unit(f"u:{el.input}")
        if el.kind == "I":  # receives e, gives f = p/I (seen by the element as s·f)
            return s * self.unit(f"p_{name}") / el.value
        if el.kind == "C":  # gives e = k q
            return el.value * self.unit(f"q_{name}")
        if el.kind == "R":
            if var == "e":  # e = R f_in = R s f
                return el.value * s * self.get((bond.name, "f"))
            return s * self.get((bond.name, "e")) / el.value
        if el.kind in ("TF", "GY"):
            return self._two_port(bond, var, name, el.kind, el.value)
        return self._junction(bond, var, name, el.kind)

    def _two_port(self, bond: Bond, var: str, name: str, kind: str, m: float) -> np.ndarray:
        b1, b2 = self.g.ports(name)
        first = bond.name == b1.name
        other = b2 if first else b1
        if kind == "TF":  # (2.6): e1 = m e2, f2 = m f1
            if var == "e":
                e = self.get((other.name, "e"))
                return m * e if first else e / m
            f = self.get((other.name, "f"))
            return f / m if first else m * f
        # GY (2.7): e1 = r f2, e2 = r f1 (and f1 = e2/r, f2 = e1/r)
        if var == "e":
            return m * self.get((other.name, "f"))
        return self.get((other.name, "e")) / m

    def _junction(self, bond: Bond, var: str, name: str, kind: str) -> np.ndarray:
        common = "e" if kind == "0" else "f"
        bonds = self.g.bonds_of(name)
        strong = next(b for b in bonds if self._is_strong(b, name, kind))
        if var == common:  # the common variable, brought in by the strong bond
            return self.get((strong.name, common))
        # the summed variable on the strong bond: Σ σ_b v_b = 0, σ = +1 into the junction
        total = np.zeros(self.width)
        for b in bonds:
            if b.name != bond.name:
                total = total + (1.0 if b.head == name else -1.0) * self.get((b.name, var))
        return -(1.0 if bond.head == name else -1.0) * total

    def _is_strong(self, b: Bond, name: str, kind: str) -> bool:
        to_junction = self.c.effort_to[b.name] == name
        return to_junction if kind == "0" else not to_junction


def state_equations(
    graph: BondGraph | Causality, outputs: list[tuple[str, str, str]] | None = None
) -> StateEquations:
    """Form ``ẋ = A x + B u`` and the named outputs ``y = C x + D u`` of a bond graph.

    Parameters
    ----------
    graph : BondGraph or Causality
        A graph (causality is assigned by :func:`assign_causality`) or a causal graph.
    outputs : list of (name, bond, "e" | "f"), optional
        Named outputs: the effort or flow of a bond.

    Returns
    -------
    StateEquations

    Raises
    ------
    CausalityError
        Derivative causality, a causal conflict, or a singular algebraic loop.
    BondGraphError
        An output names an unknown bond or variable.
    """
    causal = graph if isinstance(graph, Causality) else assign_causality(graph)
    g = causal.graph
    states = [
        f"{'p' if el.kind == 'I' else 'q'}_{el.name}"
        for el in g.elements.values()
        if el.kind in ("I", "C")
    ]
    inputs = g.inputs()
    former = _Former(causal, states, inputs)
    try:
        for b in g.bonds:  # every bond variable, in causal order
            former.get((b.name, "e"))
            former.get((b.name, "f"))
    except _AlgebraicLoop as loop:
        former.solve_all(loop.keys)
    rows = []
    for state in states:
        el = g.elements[state[2:]]
        (b,) = g.bonds_of(el.name)
        if el.kind == "I":  # ṗ = e
            rows.append(former.get((b.name, "e")))
        else:  # q̇ = f_in = s f
            rows.append((1.0 if b.head == el.name else -1.0) * former.get((b.name, "f")))
    out_rows, out_names = [], []
    for name, bond, var in outputs or []:
        if var not in ("e", "f"):
            raise BondGraphError(f"bond graph '{g.name}': output '{name}': variable must be e or f")
        g.bond_named(bond)
        out_rows.append(former.get((bond, var)))
        out_names.append(name)
    n = len(states)
    M = np.array(rows).reshape(n, former.n)
    Y = np.array(out_rows).reshape(len(out_names), former.n)
    return StateEquations(
        A=M[:, :n],
        B=M[:, n:],
        C=Y[:, :n],
        D=Y[:, n:],
        states=states,
        inputs=inputs,
        outputs=out_names,
        causality=causal,
        forms=dict(former.forms),
    )
