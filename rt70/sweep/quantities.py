"""What a sweep computes at one point, and which scene parameters it can scale.

Two small registries, each cheap to extend (docs/sweeps.md):

- :data:`QUANTITIES`: ``name → Quantity``. A quantity is a function
  ``compute(scene, point) -> {field: float or array}`` with the fields it returns
  declared up front (name, shape, unit) so a failed point can be stored as NaN of the
  right shape. ``point`` is a :class:`SweepPoint`: the values of the grid's axes and the
  static equilibrium at that pointing, solved once and shared by every quantity of the
  point. Register a new one with :func:`register_quantity`.
- :data:`PARAMETERS`: ``name → SceneParameter``. A parameter scales numbers of the
  scene's description (:class:`rt70.urdf.RobotDescription`); both sides of the
  cross-check are built from the description, so both see the scaled values
  (:func:`scaled_scene`).
"""

from __future__ import annotations

import dataclasses
from collections.abc import Callable, Mapping, Sequence
from dataclasses import dataclass, field
from typing import Any

import numpy as np

from rt70.errors import Rt70Error
from rt70.model.scene import Scene
from rt70.urdf import RobotDescription

# --- points --------------------------------------------------------------------------


@dataclass
class SweepPoint:
    """One point of a sweep grid and what its quantities share.

    Attributes
    ----------
    elevation, azimuth : float
        The pointing, degrees, of the scene's ``<rt70:mount>``
        (:func:`rt70.model.antenna.pointing`).
    wind, direction : float
        Wind speed (m/s) and the direction it blows from (degrees); carried for the
        quantities that use them (none of the built-in ones does).
    scales : dict of str to float
        Scene parameters' factors (:data:`PARAMETERS`); the scene a quantity receives
        is already scaled.
    """

    elevation: float
    azimuth: float = 0.0
    wind: float = 0.0
    direction: float = 0.0
    scales: dict[str, float] = field(default_factory=dict)
    _equilibrium: np.ndarray | Exception | None = field(default=None, repr=False)

    def held(self, scene: Scene) -> dict[str, float]:
        """The mount's axes held at this pointing (coordinate name → angle, rad)."""
        from rt70.model.antenna import pointing

        return pointing(scene, self.elevation, self.azimuth)

    def equilibrium(self, scene: Scene) -> np.ndarray:
        """Static equilibrium under gravity with the axes held (solved once per point).

        :func:`rt70.linear.linearize.equilibrium` from the construction q = 0 (a cold
        start: warm starts from the previous elevation do not pay, docs/sweeps.md). A
        failure is kept too, so every quantity of the point reports the same error.
        """
        from rt70.linear.linearize import equilibrium

        if self._equilibrium is None:
            try:
                with np.errstate(over="ignore", invalid="ignore"):  # overflow is reported
                    self._equilibrium = equilibrium(scene, self.held(scene))
            except Rt70Error as exc:
                self._equilibrium = exc
        if isinstance(self._equilibrium, Exception):
            raise self._equilibrium
        return self._equilibrium

    def as_dict(self) -> dict[str, float]:
        """The point's values by axis name (scales as ``scale:NAME``)."""
        values = {
            "elevation": self.elevation,
            "azimuth": self.azimuth,
            "wind": self.wind,
            "direction": self.direction,
        }
        values.update({f"scale:{k}": v for k, v in self.scales.items()})
        return values


# --- quantities ----------------------------------------------------------------------


@dataclass(frozen=True)
class Field:
    """One array a quantity fills: its name (a key of the NPZ file), shape per point, unit.

    Attributes
    ----------
    nan : str
        What a NaN in this field means where it is not a failure (``frequencies``: a
        spectrum shorter than the field). Empty: every NaN is a failed point, with an
        error record (:func:`rt70.sweep.run.compute_chunk` makes it one).
    """

    name: str
    shape: tuple[int, ...]
    unit: str
    description: str
    nan: str = ""


@dataclass(frozen=True)
class Quantity:
    """A registered sweep quantity.

    Attributes
    ----------
    name : str
        What ``--quantity`` names.
    fields : tuple of Field
        What ``compute`` returns, by field name.
    compute : callable (Scene, SweepPoint) -> mapping of field name to value
        Raises :class:`~rt70.errors.Rt70Error` when the point has no answer (stored as
        NaN with the message).
    check : callable (Scene) -> None, optional
        Raises :class:`~rt70.errors.Rt70Error` when the scene cannot give the quantity
        at all (checked before any work starts).
    description : str
        One line for ``--help`` and the JSON metadata.
    """

    name: str
    fields: tuple[Field, ...]
    compute: Callable[[Scene, SweepPoint], Mapping[str, Any]]
    check: Callable[[Scene], None] | None = None
    description: str = ""


#: The registered quantities by name (:func:`register_quantity`).
QUANTITIES: dict[str, Quantity] = {}


def register_quantity(quantity: Quantity) -> Quantity:
    """Add ``quantity`` to :data:`QUANTITIES` (a field name may belong to one quantity only).

    A quantity of a name already registered replaces it (``surface`` made again with
    the frequencies of ``rt70 sweep --frequency``).
    """
    taken = {
        f.name: q.name for q in QUANTITIES.values() for f in q.fields if q.name != quantity.name
    }
    clash = [f.name for f in quantity.fields if f.name in taken]
    if clash:
        raise Rt70Error(f"sweep quantity {quantity.name}: field(s) {', '.join(clash)} taken")
    QUANTITIES[quantity.name] = quantity
    return quantity


def quantity_names(text: str) -> tuple[str, ...]:
    """Parse ``first_frequency,sag`` into registered names (clear error for an unknown one)."""
    names = tuple(dict.fromkeys(n.strip() for n in text.split(",") if n.strip()))
    if not names:
        raise Rt70Error("no quantity named")
    unknown = [n for n in names if n not in QUANTITIES]
    if unknown:
        raise Rt70Error(
            f"unknown quantity {', '.join(unknown)} (known: {', '.join(sorted(QUANTITIES))})"
        )
    return names


#: Frequencies kept per point by ``first_frequency``.
N_FREQUENCIES = 6


def _first_frequency(scene: Scene, point: SweepPoint) -> dict[str, Any]:
    """The locked-rotor spectrum at the point (as ``rt70 modes``): its lowest six, Hz.

    A scene with drives: the motors held, their reducers holding the axes
    (:func:`rt70.linear.linearize.locked_rotor`); without drives the held axes are
    locked (drives infinitely stiff). ``K v = ω² M v`` (:func:`rt70.linear.modal.modes`);
    damping does not enter the undamped frequencies.
    """
    from rt70.linear import linearize as lin
    from rt70.linear import modal

    q = point.equilibrium(scene)
    drives = bool(scene.description.drives)
    model = lin.linearize(scene, q, locked=() if drives else tuple(point.held(scene)))
    if drives:
        model = lin.locked_rotor(scene, model)
    result = modal.modes(model.M, model.K)
    if result.freq_hz.size == 0:
        raise Rt70Error("no mode: every coordinate is held")
    for mask, what in ((result.negative, "unstable"), (result.rigid, "rigid")):
        if mask.any():
            raise Rt70Error(f"{int(mask.sum())} {what} mode(s): no first frequency")
    freqs = np.full(N_FREQUENCIES, np.nan)
    n = min(N_FREQUENCIES, result.freq_hz.size)
    freqs[:n] = result.freq_hz[:n]
    return {"first_frequency": float(result.freq_hz[0]), "frequencies": freqs}


def _sag(scene: Scene, point: SweepPoint) -> dict[str, Any]:
    """Gravity sag of the main mirror's axis against the source of the pointing, arcsec.

    At the static equilibrium with the axes held (:meth:`SweepPoint.equilibrium`):
    ``main_mirror_misalignment`` (4.157), the angle between the main mirror's focal
    axis n5 (4.155) and the source direction s (4.153) the undeformed antenna looks at,
    and ``main_mirror_error`` (4.156), s − n5 in the reference-ring axes
    (:mod:`rt70.model.optics`), both from the reference side's kinematics (as
    ``rt70 simulate``'s static misalignment, :mod:`rt70.telescope.scenarios`).
    """
    from rt70.model.antenna import pointing_outputs
    from rt70.model.outputs import evaluate

    wanted = ("main_mirror_misalignment", "main_mirror_error")
    outs = [o for o in pointing_outputs(scene, point.elevation, point.azimuth)]
    chosen = [o for o in outs if o.name in wanted]
    values = evaluate(scene, point.equilibrium(scene), chosen, "reference")
    return {"sag": float(values[wanted[0]][0]), "sag_error": values[wanted[1]]}


def _check_mirror(scene: Scene) -> None:
    """Refuse a mirror system whose sag is undefined, before any work.

    A missing or repeated optical point, or a focus on its mirror's vertex (no focal
    axis n5 or n7, (4.155)).
    """
    from rt70.model.antenna import mirror_system

    system = mirror_system(scene)  # raises naming a missing <rt70:mount> or <rt70:optics>
    optics = scene.description.optics
    used = {optics.primary.focus, optics.primary.vertex}
    if optics.secondary is not None:
        used |= {optics.secondary.focus, optics.secondary.vertex}
    names = [p.name for p in scene.description.optical_points]
    repeated = sorted({n for n in names if n in used and names.count(n) > 1})
    if repeated:
        raise Rt70Error(
            f"{scene.name}: <rt70:optical_point name='{repeated[0]}'> is given "
            f"{names.count(repeated[0])} times: which one is meant?"
        )
    pairs = [(system.main_focus, system.main_vertex, "main mirror")]
    if system.has_counterreflector:
        pairs.append((system.cr_focus, system.cr_vertex, "secondary reflector"))
    for focus, vertex, what in pairs:
        if focus[0] == vertex[0] and np.array_equal(focus[1], vertex[1]):
            raise Rt70Error(
                f"{scene.name}: the {what}'s focus and vertex are the same point "
                f"({focus[0]} {' '.join(f'{x:g}' for x in focus[1])}): its axis is undefined"
            )


register_quantity(
    Quantity(
        "first_frequency",
        (
            Field("first_frequency", (), "Hz", "lowest locked-rotor eigenfrequency"),
            Field(
                "frequencies",
                (N_FREQUENCIES,),
                "Hz",
                "lowest six, ascending",
                nan="the spectrum has fewer modes than six: the missing ones",
            ),
        ),
        _first_frequency,
        description="the locked-rotor spectrum's first frequency and its lowest six (Hz)",
    )
)
register_quantity(
    Quantity(
        "sag",
        (
            Field("sag", (), "arcsec", "main mirror axis vs source, (4.157)"),
            Field("sag_error", (3,), "arcsec", "s − n5 in the OK frame, (4.156)"),
        ),
        _sag,
        check=_check_mirror,
        description="gravity sag of the main mirror's axis against the source (arcsec)",
    )
)


def _pointing(scene: Scene, point: SweepPoint) -> dict[str, Any]:
    """The wind pointing budget at the point (:func:`rt70.telescope.pointing.pointing_budget`).

    The point's wind speed (> 0) and direction; its pointing. The budget solves its own
    drive-held equilibria (with and without the wind), not the point's coordinate-held
    one.
    """
    from rt70.telescope.pointing import PointingCase, pointing_budget

    if not point.wind > 0.0:
        raise Rt70Error("the pointing budget needs a wind speed above 0 (--wind)")
    case = PointingCase(point.elevation, point.azimuth, point.wind, point.direction)
    b = pointing_budget(scene, case)
    out: dict[str, Any] = {}
    for name, (steady, gust) in POINTING_FIELDS.items():
        out[steady], out[gust] = b.steady[name], b.gust_rms[name]
    out["quasi_static_share"] = b.extra["quasi_static_share"]
    out["first_frequency_wind"] = b.extra["first_frequency_hz"]
    return out


def _check_pointing(scene: Scene) -> None:
    from rt70.telescope.pointing import check_scene

    check_scene(scene)


#: The budget's outputs (:data:`rt70.telescope.pointing.BUDGET_OUTPUTS`) and their two fields.
POINTING_FIELDS = {
    "main_mirror_error": ("pointing_steady", "pointing_gust"),
    "counterreflector_error": ("counterreflector_steady", "counterreflector_gust"),
    "focal_offset": ("focus_steady", "focus_gust"),
}
register_quantity(
    Quantity(
        "pointing",
        (
            Field("pointing_steady", (), "arcsec", "steady main-mirror axis error vs source"),
            Field("pointing_gust", (), "arcsec", "gust rms of the main-mirror axis error"),
            Field("counterreflector_steady", (), "arcsec", "steady CR vs main-mirror axis"),
            Field("counterreflector_gust", (), "arcsec", "gust rms of CR vs main-mirror axis"),
            Field("focus_steady", (), "mm", "steady CR focus vs main focus"),
            Field("focus_gust", (), "mm", "gust rms of the focus offset"),
            Field("quasi_static_share", (), "1", "share of the gust variance that is quasi-static"),
            Field("first_frequency_wind", (), "Hz", "first locked-rotor frequency with K + K_wind"),
        ),
        _pointing,
        check=_check_pointing,
        description="the wind pointing budget with the servos closed (docs/pointing.md)",
    )
)


# --- scene parameters ----------------------------------------------------------------


@dataclass(frozen=True)
class SceneParameter:
    """Numbers of the scene scaled by a factor: ``apply(description, factor)``.

    ``values(description)`` lists the numbers ``apply`` scales (so that a factor which
    would take one beyond what rt70 reads in a model is refused up front).
    """

    name: str
    apply: Callable[[RobotDescription, float], RobotDescription]
    description: str
    values: Callable[[RobotDescription], list[float]]


def _scale_stiffness(desc: RobotDescription, f: float) -> RobotDescription:
    return dataclasses.replace(
        desc,
        bushings=[dataclasses.replace(b, stiffness=b.stiffness * f) for b in desc.bushings],
        joint_springs=[
            dataclasses.replace(s, stiffness=s.stiffness * f) for s in desc.joint_springs
        ],
        modal_bodies=tuple(
            dataclasses.replace(b, stiffness=b.stiffness * f) for b in desc.modal_bodies
        ),
    )


def _scale_damping(desc: RobotDescription, f: float) -> RobotDescription:
    return dataclasses.replace(
        desc,
        bushings=[dataclasses.replace(b, damping=b.damping * f) for b in desc.bushings],
        joint_springs=[dataclasses.replace(s, damping=s.damping * f) for s in desc.joint_springs],
        modal_bodies=tuple(
            dataclasses.replace(b, damping=b.damping * f) for b in desc.modal_bodies
        ),
    )


def _structural(desc: RobotDescription, attribute: str) -> list[float]:
    """The ``stiffness`` or ``damping`` numbers of every bushing, joint spring and modal body."""
    numbers = [float(x) for b in desc.bushings for x in np.ravel(getattr(b, attribute))]
    numbers += [float(x) for b in desc.modal_bodies for x in np.ravel(getattr(b, attribute))]
    return numbers + [float(getattr(s, attribute)) for s in desc.joint_springs]


def _scale_reducers(desc: RobotDescription, f: float) -> RobotDescription:
    return dataclasses.replace(
        desc, drives=[dataclasses.replace(d, C_r=d.C_r * f) for d in desc.drives]
    )


#: The scene parameters ``--scale NAME=…`` knows.
PARAMETERS: dict[str, SceneParameter] = {
    p.name: p
    for p in (
        SceneParameter(
            "stiffness",
            _scale_stiffness,
            "the stiffness of every structural elastic element (bushings, strut-package "
            "struts, joint springs, modal bodies' K_η); their damping unchanged; drives' "
            "reducers unchanged",
            lambda desc: _structural(desc, "stiffness"),
        ),
        SceneParameter(
            "damping",
            _scale_damping,
            "the damping of every structural elastic element (bushings, struts, joint springs, "
            "modal bodies' D_η)",
            lambda desc: _structural(desc, "damping"),
        ),
        SceneParameter(
            "reducer_stiffness",
            _scale_reducers,
            "the reducer stiffness C_r of every drive",
            lambda desc: [float(d.C_r) for d in desc.drives],
        ),
    )
}


def check_factors(scene: Scene, name: str, factors: Sequence[float]) -> None:
    """Refuse factors that take a number of the scene beyond what rt70 reads in a model.

    Parameters
    ----------
    scene : Scene
        The unscaled scene.
    name : str
        A scene parameter of :data:`PARAMETERS` (``--scale NAME``).
    factors : sequence of float
        The factors the sweep applies to it (dimensionless).

    Raises
    ------
    Rt70Error
        ``--scale NAME``: the largest factor times the largest number it scales exceeds
        :data:`rt70.urdf.elements.MAX_MAGNITUDE`.
    """
    from rt70.urdf.elements import MAX_MAGNITUDE

    numbers = [abs(v) for v in PARAMETERS[name].values(scene.description)]
    if not numbers or not factors:
        return
    with np.errstate(over="ignore"):
        largest = np.float64(max(numbers)) * max(factors)
    if not largest <= MAX_MAGNITUDE:
        raise Rt70Error(
            f"--scale {name}: factor {max(factors):g} times the largest "
            f"{name.replace('_', ' ')} {max(numbers):g} of {scene.name} is {largest:.3g}, beyond "
            f"{MAX_MAGNITUDE:g} (the largest number rt70 reads in a model)"
        )


def scaled_scene(scene: Scene, scales: Mapping[str, float]) -> Scene:
    """``scene`` with its description scaled by each parameter's factor (both sides see it).

    Returns the scene itself when every factor is 1 (nothing rebuilt).
    """
    desc = scene.description
    for name, factor in scales.items():
        if name not in PARAMETERS:
            raise Rt70Error(f"unknown scene parameter {name} (known: {', '.join(PARAMETERS)})")
        if factor != 1.0:
            desc = PARAMETERS[name].apply(desc, factor)
    if desc is scene.description:
        return scene
    return Scene(scene.name, scene.path, scene.text, desc)
