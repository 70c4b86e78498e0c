"""Causality of a bond graph by the sequential causality assignment procedure (SCAP).

Every bond carries one effort and one flow; causality says which end computes which.
We record, per bond, the element that *receives the effort* (the end with the causal
stroke); the other end receives the flow. The constraints (Karnopp, Margolis &
Rosenberg, *System Dynamics*, ch. 5; the companion source 003 only lists the elements):

- ``Se`` imposes the effort; ``Sf`` imposes the flow (receives the effort);
- ``I`` in integral causality receives the effort (``ṗ = e``, ``f = p/I``); ``C`` in
  integral causality imposes the effort (``q̇ = f``, ``e = k q``); ``R`` either way;
- a 0-junction has exactly one bond that imposes the effort on it (the others receive
  it); a 1-junction has exactly one bond that imposes the flow on it;
- a ``TF`` passes the effort through (one port receives it, the other imposes it); a
  ``GY`` receives the effort on both ports or on neither.

The procedure: (1) each source in turn, with its causality propagated through the
junctions and two-ports; (2) each storage in integral causality, propagated; (3) each
remaining ``R``, arbitrarily (it receives the flow), propagated; (4) any junction bond
still free, arbitrarily. A storage forced into derivative causality, or any
constraint broken by propagation (a causal conflict), raises :class:`CausalityError`
naming the element — the state equations need every storage independent.
"""

from __future__ import annotations

from dataclasses import dataclass

from rt70.bondgraph.graph import Bond, BondGraph, CausalityError


@dataclass(frozen=True)
class Causality:
    """A causal bond graph: for each bond, the element that receives its effort.

    Attributes
    ----------
    graph : BondGraph
        The graph (checked).
    effort_to : dict[str, str]
        Bond name → name of the element at the bond's end that receives the effort.
    reason : dict[str, str]
        Bond name → the assignment step that fixed it (for explanations).
    """

    graph: BondGraph
    effort_to: dict[str, str]
    reason: dict[str, str]

    def receives_effort(self, bond: Bond, element: str) -> bool:
        """True when ``element`` (an end of ``bond``) receives the bond's effort."""
        return self.effort_to[bond.name] == element


def _other(bond: Bond, element: str) -> str:
    return bond.head if bond.tail == element else bond.tail


class _Assigner:
    """The state of one SCAP run: assignments so far and the propagation worklist."""

    def __init__(self, graph: BondGraph) -> None:
        self.g = graph
        self.effort_to: dict[str, str] = {}
        self.reason: dict[str, str] = {}

    def set(self, bond: Bond, receiver: str, why: str) -> None:
        current = self.effort_to.get(bond.name)
        if current == receiver:
            return
        if current is not None:
            raise CausalityError(
                f"bond graph '{self.g.name}': causal conflict on bond '{bond.name}': "
                f"{why} needs its effort into '{receiver}', but {self.reason[bond.name]} "
                f"already sends it into '{current}'"
            )
        self.effort_to[bond.name] = receiver
        self.reason[bond.name] = why
        self._propagate(bond, why)

    def _propagate(self, bond: Bond, why: str) -> None:
        for element in (bond.tail, bond.head):
            kind = self.g.elements[element].kind
            if kind in ("0", "1"):
                self._junction(element, why)
            elif kind in ("TF", "GY"):
                self._two_port(element, why)

    def _two_port(self, name: str, why: str) -> None:
        b1, b2 = self.g.ports(name)
        kind = self.g.elements[name].kind
        for known, free in ((b1, b2), (b2, b1)):
            if known.name in self.effort_to:
                into = self.effort_to[known.name] == name
                # TF: effort in on one port, out on the other; GY: same on both ports
                into_free = (not into) if kind == "TF" else into
                self.set(free, name if into_free else _other(free, name), why)

    def _junction(self, name: str, why: str) -> None:
        kind = self.g.elements[name].kind
        bonds = self.g.bonds_of(name)

        # "strong" bond: on a 0-junction the one that brings the effort in; on a
        # 1-junction the one that brings the flow in (the junction sends its effort out)
        def strong(b: Bond) -> bool:
            to_junction = self.effort_to[b.name] == name
            return to_junction if kind == "0" else not to_junction

        assigned = [b for b in bonds if b.name in self.effort_to]
        free = [b for b in bonds if b.name not in self.effort_to]
        strongs = [b for b in assigned if strong(b)]
        what = "effort" if kind == "0" else "flow"
        if len(strongs) > 1:
            names = ", ".join(f"'{b.name}'" for b in strongs)
            raise CausalityError(
                f"bond graph '{self.g.name}': causal conflict at {kind}-junction '{name}': "
                f"bonds {names} all impose its {what} (last step: {why})"
            )
        if len(strongs) == 1:
            for b in free:  # every other bond receives the common variable
                weak_to = _other(b, name) if kind == "0" else name
                self.set(b, weak_to, why)
        elif not free:
            raise CausalityError(
                f"bond graph '{self.g.name}': causal conflict at {kind}-junction '{name}': "
                f"no bond imposes its {what} (last step: {why})"
            )
        elif len(free) == 1:
            b = free[0]
            self.set(b, name if kind == "0" else _other(b, name), why)


def assign_causality(graph: BondGraph) -> Causality:
    """Assign causality by SCAP; refuse derivative causality and causal conflicts.

    Parameters
    ----------
    graph : BondGraph
        A complete graph (every element bonded; checked with :meth:`BondGraph.check`).

    Returns
    -------
    Causality
        Every bond's effort receiver; every ``I`` and ``C`` in integral causality.

    Raises
    ------
    CausalityError
        A storage element in derivative causality (e.g. an inductance in series with a
        current source, two inertias on one 1-junction), or a causal conflict (two
        sources imposing one junction's variable), naming the graph and the element.
    """
    graph.check()
    a = _Assigner(graph)
    elements = list(graph.elements.values())
    for el in elements:  # (1) sources
        if el.kind in ("Se", "Sf"):
            (b,) = graph.bonds_of(el.name)
            receiver = _other(b, el.name) if el.kind == "Se" else el.name
            a.set(b, receiver, f"source {el.kind} '{el.name}'")
    for el in elements:  # (2) storage in integral causality
        if el.kind in ("I", "C"):
            (b,) = graph.bonds_of(el.name)
            integral = el.name if el.kind == "I" else _other(b, el.name)
            if b.name in a.effort_to and a.effort_to[b.name] != integral:
                raise CausalityError(
                    f"bond graph '{graph.name}': {el.kind} element '{el.name}' is in "
                    f"derivative causality (forced by {a.reason[b.name]}): its state "
                    "depends on the others; merge it with the storage it is rigidly "
                    "tied to, or add the compliance/inertia that separates them"
                )
            a.set(b, integral, f"integral causality of {el.kind} '{el.name}'")
    for el in elements:  # (3) remaining resistors: receive the flow
        if el.kind == "R":
            (b,) = graph.bonds_of(el.name)
            if b.name not in a.effort_to:
                a.set(b, _other(b, el.name), f"R '{el.name}' (arbitrary)")
    for b in graph.bonds:  # (4) junction structure still free
        if b.name not in a.effort_to:
            a.set(b, b.head, f"bond '{b.name}' (arbitrary)")
    for el in elements:  # every junction's constraint holds once all bonds are set
        if el.kind in ("0", "1"):
            a._junction(el.name, "final check")
    return Causality(graph, dict(a.effort_to), dict(a.reason))
