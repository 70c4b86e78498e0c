"""A bond graph as plain data: its elements, its bonds and their power directions.

The elements are those of the companion source 003 (Kuzmin 2008, §2.1, Table 2.1;
equations (2.1)–(2.7) reconstructed in companion-sources.md): effort and flow sources
``Se``/``Sf``, the inertial storage ``I`` (2.3), the capacitive storage ``C`` (2.4), the
dissipator ``R`` (2.5), the transformer ``TF`` (2.6), the gyrator ``GY`` (2.7), and the
common-effort ``0`` and common-flow ``1`` junctions ((2.1), (2.2)). All of them are linear
here (constant parameters), which is what the state equations ``ẋ = A x + B u`` of
:mod:`rt70.bondgraph.equations` need.

A bond joins two elements and points in the direction of positive power ``e·f`` (the
half-arrow). This module only holds and checks the graph; causality is assigned by
:mod:`rt70.bondgraph.causality` and the equations are formed by
:mod:`rt70.bondgraph.equations`.
"""

from __future__ import annotations

import math
from dataclasses import dataclass, field

from rt70.errors import Rt70Error

#: Element kinds and the number of bonds each must have (None: any number ≥ 2).
PORTS: dict[str, int | None] = {
    "Se": 1,
    "Sf": 1,
    "I": 1,
    "C": 1,
    "R": 1,
    "TF": 2,
    "GY": 2,
    "0": None,
    "1": None,
}


class BondGraphError(Rt70Error):
    """A bond graph is malformed: unknown element, wrong number of bonds, bad parameter."""


class CausalityError(BondGraphError):
    """Causality cannot be assigned: derivative causality, a causal conflict or a loop."""


@dataclass(frozen=True)
class Element:
    """One element of a bond graph.

    Parameters
    ----------
    name : str
        Unique name (used in error messages and state names).
    kind : str
        One of :data:`PORTS`.
    value : float
        ``I``: inertia (mass, moment of inertia, inductance), ``f = p / I``;
        ``C``: stiffness ``k = 1/C`` (the inverse compliance), ``e = k q``;
        ``R``: resistance, ``e = R f``; ``TF``: modulus ``m`` of (2.6), ``e1 = m e2``,
        ``f2 = m f1``; ``GY``: modulus ``r`` of (2.7), ``e1 = r f2``, ``e2 = r f1``;
        sources and junctions: unused (``nan``).
    input : str
        Sources only: the name of the input they impose (an entry of ``u``).
    """

    name: str
    kind: str
    value: float = math.nan
    input: str = ""


@dataclass(frozen=True)
class Bond:
    """A bond from ``tail`` to ``head``: positive power ``e·f`` flows tail → head."""

    name: str
    tail: str
    head: str


@dataclass
class BondGraph:
    """A bond graph under construction: add elements, then bonds between them.

    Examples
    --------
    An RC circuit, ``q̇ = (U − 4 q)/2``:

    >>> from rt70.bondgraph import state_equations
    >>> g = BondGraph("rc")
    >>> g.source_effort("U", input="U")
    >>> g.one("1")
    >>> g.resistor("R", 2.0)
    >>> g.compliance("C", stiffness=4.0)
    >>> for end in ("R", "C"):
    ...     _ = g.bond("1", end)
    >>> g.bond("U", "1")
    'U->1'
    >>> ss = state_equations(g)
    >>> ss.states, ss.A.tolist(), ss.B.tolist()
    (['q_C'], [[-2.0]], [[0.5]])
    """

    name: str
    elements: dict[str, Element] = field(default_factory=dict)
    bonds: list[Bond] = field(default_factory=list)

    # --- elements ---------------------------------------------------------------------
    def _add(self, name: str, kind: str, value: float = math.nan, input: str = "") -> None:
        if not name or name in self.elements:
            raise BondGraphError(
                f"bond graph '{self.name}': element name {name!r} is empty or used"
            )
        if kind in ("I", "C", "R", "TF", "GY"):
            if not (math.isfinite(value) and value > 0.0):
                raise BondGraphError(
                    f"bond graph '{self.name}': {kind} element '{name}' needs a finite "
                    f"positive parameter, got {value!r}"
                )
        self.elements[name] = Element(name, kind, float(value), input)

    def source_effort(self, name: str, *, input: str) -> None:
        """Add an effort source ``Se``: the bond's effort is the input ``input``."""
        self._add(name, "Se", input=input)

    def source_flow(self, name: str, *, input: str) -> None:
        """Add a flow source ``Sf``: the bond's flow is the input ``input``."""
        self._add(name, "Sf", input=input)

    def inertia(self, name: str, value: float) -> None:
        """Add an inertial storage ``I`` (2.3): ``ṗ = e``, ``f = p / value``."""
        self._add(name, "I", value)

    def compliance(
        self, name: str, *, stiffness: float | None = None, compliance: float | None = None
    ) -> None:
        """Add a capacitive storage ``C`` (2.4): ``q̇ = f``, ``e = q / C = k q``.

        Give exactly one of ``stiffness`` (k) or ``compliance`` (C = 1/k); the
        stiffness is stored, so a stiffness given is used without rounding.

        Parameters
        ----------
        name : str
            The element's name, unique in the graph (its state is ``q_<name>``).
        stiffness : float, optional
            k, effort per displacement (N/m, N·m/rad; 1/F for a capacitor): finite and
            positive.
        compliance : float, optional
            C = 1/k, displacement per effort (m/N, rad/(N·m); F for a capacitor).
        """
        if (stiffness is None) == (compliance is None):
            raise BondGraphError(
                f"bond graph '{self.name}': C element '{name}' needs exactly one of "
                "stiffness or compliance"
            )
        k = stiffness if stiffness is not None else 1.0 / compliance  # type: ignore[operator]
        self._add(name, "C", k)

    def resistor(self, name: str, value: float) -> None:
        """Add a dissipator ``R`` (2.5): ``e = value · f``."""
        self._add(name, "R", value)

    def transformer(self, name: str, modulus: float) -> None:
        """Add a transformer ``TF`` (2.6): ``e_in = m e_out``, ``f_out = m f_in``."""
        self._add(name, "TF", modulus)

    def gyrator(self, name: str, modulus: float) -> None:
        """Add a gyrator ``GY`` (2.7): ``e_in = r f_out``, ``e_out = r f_in``."""
        self._add(name, "GY", modulus)

    def zero(self, name: str) -> None:
        """Add a 0-junction (common effort; flows sum to zero, (2.1))."""
        self._add(name, "0")

    def one(self, name: str) -> None:
        """Add a 1-junction (common flow; efforts sum to zero, (2.2))."""
        self._add(name, "1")

    # --- bonds ------------------------------------------------------------------------
    def bond(self, tail: str, head: str, name: str | None = None) -> str:
        """Join ``tail`` to ``head`` (power positive from tail to head); return its name.

        Parameters
        ----------
        tail, head : str
            Names of two different elements of the graph: the bond's half-arrow points
            from ``tail`` to ``head``.
        name : str, optional
            The bond's name, unique in the graph (default ``"tail->head"``).
        """
        for end in (tail, head):
            if end not in self.elements:
                raise BondGraphError(f"bond graph '{self.name}': no element named {end!r}")
        if tail == head:
            raise BondGraphError(f"bond graph '{self.name}': bond from '{tail}' to itself")
        name = name or f"{tail}->{head}"
        if any(b.name == name for b in self.bonds):
            raise BondGraphError(f"bond graph '{self.name}': bond name {name!r} is used")
        self.bonds.append(Bond(name, tail, head))
        return name

    def bonds_of(self, element: str) -> list[Bond]:
        """The bonds at ``element``, in the order they were added."""
        return [b for b in self.bonds if element in (b.tail, b.head)]

    def bond_named(self, name: str) -> Bond:
        """The bond called ``name`` (:class:`BondGraphError` if there is none)."""
        for b in self.bonds:
            if b.name == name:
                return b
        raise BondGraphError(f"bond graph '{self.name}': no bond named {name!r}")

    def check(self) -> None:
        """Check every element has its number of bonds and two-ports pass power through.

        Raises
        ------
        BondGraphError
            Naming the graph and the element.
        """
        for el in self.elements.values():
            n = len(self.bonds_of(el.name))
            want = PORTS[el.kind]
            if (want is None and n < 2) or (want is not None and n != want):
                need = "at least 2" if want is None else str(want)
                raise BondGraphError(
                    f"bond graph '{self.name}': {el.kind} element '{el.name}' has {n} "
                    f"bond(s), needs {need}"
                )
            if el.kind in ("TF", "GY"):
                ins = [b for b in self.bonds_of(el.name) if b.head == el.name]
                if len(ins) != 1:
                    raise BondGraphError(
                        f"bond graph '{self.name}': {el.kind} element '{el.name}' needs one "
                        "bond in and one bond out (power passes through it)"
                    )

    def ports(self, element: str) -> tuple[Bond, Bond]:
        """A two-port's (incoming, outgoing) bonds: port 1 and port 2 of (2.6)/(2.7)."""
        bonds = self.bonds_of(element)
        into = next(b for b in bonds if b.head == element)
        out = next(b for b in bonds if b.tail == element)
        return into, out

    def inputs(self) -> list[str]:
        """The source inputs, in the order the sources were added (the columns of B)."""
        names: list[str] = []
        for el in self.elements.values():
            if el.kind in ("Se", "Sf") and el.input not in names:
                names.append(el.input)
        return names
