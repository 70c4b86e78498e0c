"""What a simulation returns: the trajectory, its energy audit, and how it is written.

:class:`SimulationResult` holds one run of :func:`rt70.simulation.simulate.simulate`
(the samples, the energies of the audit and their balance, the extra states, the
outputs, the measured series of an analysis, the solver's statistics and timing) and
writes itself atomically as ``.npz`` or ``.csv`` (:data:`OUTPUT_SUFFIXES`), with the
unit of every column or array in a sidecar ``<name>.units.json`` (:meth:`units`).
"""

from __future__ import annotations

import json
from collections.abc import Callable
from dataclasses import dataclass, field
from pathlib import Path

import numpy as np

from rt70.errors import OutputError
from rt70.model.outputs import column_labels
from rt70.simulation.states import EnergyAudit

#: A drift of the energy balance larger than this many times rtol (relative to the energy
#: exchanged during the run) is flagged: more than the tolerance explains.
DRIFT_FACTOR = 100.0
#: Output formats of :meth:`SimulationResult.save`, by suffix.
OUTPUT_SUFFIXES = (".csv", ".npz")


@dataclass
class SimulationResult:
    """Trajectory, energies and solver statistics of one run.

    ``side`` is the side that ran (``"reference"``, Pinocchio's, or ``"textbook"``).
    Energies in J: ``kinetic`` T, ``gravity`` U_g, ``elastic`` U_c, ``dissipated`` E_ψ,
    ``input_work`` W_u; ``balance = T + U_g + U_c + E_ψ − W_u − (its value at t0)`` and
    ``balance_scale`` the energy exchanged in the run (what ``relative_drift`` is
    relative to). ``drift_flagged`` is set when a passive run drifts by more than
    ``DRIFT_FACTOR · rtol`` of it (:data:`DRIFT_FACTOR`).
    ``states`` holds the trajectory of every extra state by name
    (:mod:`rt70.simulation.states`; the energy audit's ``dissipated`` and ``input_work``
    first). ``constraint_residual`` is ``max |Φ|`` per sample for a scene with closed
    chains (:mod:`rt70.simulation.closed_chains`), empty otherwise. ``t_events`` holds
    the times at which each of the ``events`` of :func:`rt70.simulation.simulate.simulate`
    crossed zero. ``timing`` splits
    ``wall_time_s``: "rhs" (s inside the right-hand side, including the calls of a
    difference-quotient Jacobian), "jacobian" (s inside the analytic Jacobian) and
    "integrator" (the rest: the solver's own work, its linear algebra included).
    ``nlu`` is −1 where the solver does not report it (CVODE) or factors without LU
    (generalized-alpha, whose ``njev`` counts its iteration matrices), ``n_steps`` −1 when
    ``t_eval`` was given. ``coordinate_units`` holds each coordinate's unit ("rad" or
    "m"), ``output_units`` and ``state_units`` the outputs' and the extra states' by name;
    ``series`` holds what an analysis measured on the run (a servo scenario's references,
    errors, torques and currents, :mod:`rt70.telescope.scenarios`), each an (n_t,) array,
    with its unit in ``series_units``.
    """

    scene: str
    side: str
    method: str
    rtol: float
    atol: float
    t: np.ndarray
    q: np.ndarray
    qd: np.ndarray
    kinetic: np.ndarray
    gravity: np.ndarray
    elastic: np.ndarray
    dissipated: np.ndarray
    input_work: np.ndarray
    balance: np.ndarray
    balance_scale: float
    nfev: int
    njev: int
    nlu: int
    n_steps: int
    wall_time_s: float
    success: bool
    message: str
    coordinates: list[str] = field(default_factory=list)
    drift_flagged: bool = False
    outputs: dict[str, np.ndarray] = field(default_factory=dict)
    states: dict[str, np.ndarray] = field(default_factory=dict)
    constraint_residual: np.ndarray = field(default_factory=lambda: np.zeros(0))
    t_events: list[np.ndarray] = field(default_factory=list)
    timing: dict[str, float] = field(default_factory=dict)
    coordinate_units: list[str] = field(default_factory=list)
    output_units: dict[str, str] = field(default_factory=dict)
    state_units: dict[str, str] = field(default_factory=dict)
    series: dict[str, np.ndarray] = field(default_factory=dict)
    series_units: dict[str, str] = field(default_factory=dict)

    @property
    def relative_drift(self) -> float:
        """Largest ``|balance|`` over the run, relative to ``balance_scale``."""
        return float(np.max(np.abs(self.balance)) / self.balance_scale)

    @property
    def real_time_factor(self) -> float:
        """Simulated time per wall-clock second."""
        return float((self.t[-1] - self.t[0]) / self.wall_time_s)

    def save(self, path: str | Path) -> Path:
        """Write the result atomically: ``.npz`` (all arrays) or ``.csv`` (a table)."""
        from rt70.guards.atomic import atomic_write

        return atomic_write(path, self.writer(path))

    def writer(self, path: str | Path) -> Callable[[Path], None]:
        """The function that writes the result to a (temporary) file, in ``path``'s format.

        For :func:`rt70.guards.atomic.atomic_write_all`, to write it together with other files.

        Raises
        ------
        OutputError
            If ``path`` does not end in one of :data:`OUTPUT_SUFFIXES`.
        """
        suffix = check_output_suffix(path)
        if suffix == ".npz":
            arrays = {
                k: getattr(self, k)
                for k in ("t", "q", "qd", "kinetic", "gravity", "elastic", "dissipated")
            }
            arrays.update(input_work=self.input_work, balance=self.balance)
            arrays.update({f"state:{k}": v for k, v in self._component_states().items()})
            arrays["coordinates"] = np.array(self.coordinates)
            if self.constraint_residual.size:  # closed chains: max |Φ| per sample
                arrays["constraint_residual"] = self.constraint_residual
            arrays.update({f"output:{k}": v for k, v in self.outputs.items()})
            arrays.update({f"series:{k}": v for k, v in self.series.items()})
            return lambda tmp: np.savez_compressed(tmp, **arrays)
        extra = self._component_states()
        names = ["t"] + [f"q:{c}" for c in self.coordinates] + [f"qd:{c}" for c in self.coordinates]
        names += ["kinetic", "gravity", "elastic", "dissipated", "input_work", "balance"]
        names += [f"state:{k}" for k in extra]
        table = np.column_stack(
            [self.t, self.q, self.qd, self.kinetic, self.gravity, self.elastic]
            + [self.dissipated, self.input_work, self.balance, *extra.values()]
        )
        if self.constraint_residual.size:  # closed chains: max |Φ| per sample
            names.append("constraint_residual")
            table = np.column_stack([table, self.constraint_residual])
        for name, values in self.outputs.items():  # rt70.model.outputs, one column per component
            names += column_labels(name, values.shape[1])
            table = np.column_stack([table, values])
        for name, values in self.series.items():
            names.append(f"series:{name}")
            table = np.column_stack([table, values])
        lines = [",".join(names)] + [",".join(f"{x:.17g}" for x in row) for row in table]
        text = "\n".join(lines) + "\n"
        return lambda tmp: tmp.write_text(text, encoding="utf-8", newline="\n")

    def units(self, path: str | Path) -> dict[str, str]:
        """The unit of every column (``.csv``) or array (``.npz``) of the file ``path``.

        Coordinates in rad or m (their joints' kind), velocities per second, energies in
        J, each state, output and series in its own unit; "unknown" only for a state
        whose component declares none (:attr:`rt70.simulation.states.StateComponent.STATE_UNITS`).
        """
        csv = check_output_suffix(path) == ".csv"
        units = {"t": "s"}
        for c, u in zip(self.coordinates, self.coordinate_units, strict=True):
            units[f"q:{c}" if csv else "q"] = u if csv else "rad or m (coordinate_units)"
            units[f"qd:{c}" if csv else "qd"] = f"{u}/s" if csv else "rad/s or m/s"
        for name in ("kinetic", "gravity", "elastic", "dissipated", "input_work", "balance"):
            units[name] = "J"
        units.update({f"state:{k}": self.state_units[k] for k in self._component_states()})
        if self.constraint_residual.size:
            units["constraint_residual"] = "m or rad"
        for name, values in self.outputs.items():
            unit = self.output_units[name]
            if csv:
                units.update({label: unit for label in column_labels(name, values.shape[1])})
            else:
                units[f"output:{name}"] = unit
        units.update({f"series:{k}": self.series_units[k] for k in self.series})
        if not csv:
            units["coordinates"] = "names"
        return units

    def units_writer(self, path: str | Path) -> Callable[[Path], None]:
        """The function that writes :meth:`units` as JSON, for ``<name>.units.json``."""
        header = {
            "scene": self.scene,
            "side": self.side,
            "file": Path(path).name,
            "coordinate_units": dict(zip(self.coordinates, self.coordinate_units, strict=True)),
            "units": self.units(path),
        }
        text = json.dumps(header, indent=1, ensure_ascii=False) + "\n"
        return lambda tmp: tmp.write_text(text, encoding="utf-8")

    def _component_states(self) -> dict[str, np.ndarray]:
        """The extra states other than the energy audit's (written as ``state:<name>``)."""
        return {k: v for k, v in self.states.items() if k not in EnergyAudit.names}


def units_path(path: str | Path) -> Path:
    """Where the units of a result file go: ``run.csv`` → ``run.units.json``."""
    return Path(path).with_suffix(".units.json")


def check_output_suffix(path: str | Path) -> str:
    """The suffix of an output path, one of :data:`OUTPUT_SUFFIXES`, or an OutputError."""
    suffix = Path(path).suffix
    if suffix not in OUTPUT_SUFFIXES:
        raise OutputError(f"{path}: output must end in {' or '.join(OUTPUT_SUFFIXES)}")
    return suffix


def coordinate_units(scene) -> list[str]:
    """Each coordinate's unit: "m" for a prismatic joint's, "rad" for any other's.

    Parameters
    ----------
    scene : rt70.model.scene.Scene
        The scene simulated.
    """
    kinds = {j.name: j.type for j in scene.description.joints}
    return ["m" if kinds.get(c) == "prismatic" else "rad" for c in scene.textbook.coordinate_names]


def initial_energy_scale(T0: float, U_g0: float, U_c0: float) -> float:
    """``max(T + U_c, 10⁻¹² max(|U_g|, 1), 10⁻³⁰⁰)`` at the start, J: the audit's floor.

    Parameters
    ----------
    T0, U_g0, U_c0 : float
        Kinetic, gravity and elastic energy at the initial state, J.
    """
    return max(T0 + U_c0, 1e-12 * max(abs(U_g0), 1.0), 1e-300)


def energy_balance(
    T: np.ndarray, U_g: np.ndarray, U_c: np.ndarray, E_psi: np.ndarray, W_u: np.ndarray
) -> tuple[np.ndarray, float]:
    """``T + U_g + U_c + E_ψ − W_u`` less its initial value, and the energy exchanged.

    The exchanged energy is the largest of the mechanical energy ``T + U_c``, the energy
    dissipated and the inputs' work over the run (:attr:`SimulationResult.balance_scale`
    is at least the initial energy scale besides, :func:`initial_energy_scale`).

    Parameters
    ----------
    T, U_g, U_c, E_psi, W_u : numpy.ndarray, shape (n_t,)
        Kinetic, gravity, elastic and dissipated energy and the inputs' work, J.
    """
    total = T + U_g + U_c + E_psi - W_u
    exchanged = max(float(np.max(T + U_c)), float(E_psi[-1]), float(np.max(np.abs(W_u))))
    return total - total[0], exchanged
