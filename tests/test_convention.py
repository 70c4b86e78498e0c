"""One calling convention on both sides (issue 9): a constant model, its data, functions.

The reference side follows Pinocchio (and the textbook side): :class:`ReferenceModel`
is constant once built and has no dynamics methods; the algorithms of
:mod:`rt70.reference` are functions ``algorithm(model, data, q, …)`` that write only
into their :class:`ReferenceData`. Checked here: no algorithm is a method or attribute
of either side's model, every algorithm leaves the model as it found it (its Pinocchio
models, arrays, frames and attributes), and two ``ReferenceData`` of one model give
identical results whatever the other one computed in between.
"""

from __future__ import annotations

from pathlib import Path

import numpy as np
import pytest

from rt70 import reference
from rt70.model.scene import load_scene
from rt70.reference import ReferenceData, ReferenceModel
from rt70.textbook.model import Model

ALL_JOINTS = Path(__file__).parent / "data" / "all_joint_types.urdf"

#: Every algorithm of the reference side (everything it exports but Model and Data).
ALGORITHMS = sorted(set(reference.__all__) - {"ReferenceData", "ReferenceModel"})

#: The method-style names of the old reference side (``ref.model``, ``ref.data`` …).
OLD_ATTRIBUTES = ("model", "data", "model_no_gravity", "data_no_gravity", "_frames1")


def _calls(model: ReferenceModel, data: ReferenceData, q: np.ndarray, qd: np.ndarray):
    """Every algorithm of :mod:`rt70.reference`, called at (q, q̇) with ``data``."""
    qp, vp, _, _ = reference.to_pinocchio(model, q, qd)
    return {
        "to_pinocchio": lambda: reference.to_pinocchio(model, q, qd),
        "mass_matrix": lambda: reference.mass_matrix(model, data, q),
        "bias_force": lambda: reference.bias_force(model, data, q, qd),
        "gravity_force": lambda: reference.gravity_force(model, data, q),
        "forward_dynamics": lambda: reference.forward_dynamics(model, data, q, qd),
        "kinetic_energy": lambda: reference.kinetic_energy(model, data, q, qd),
        "gravity_potential": lambda: reference.gravity_potential(model, data, q),
        "weight_moment": lambda: reference.weight_moment(model, data, q),
        "newton_stiffness": lambda: reference.newton_stiffness(model, data, q),
        "spring_damper_force": lambda: reference.spring_damper_force(model, data, q, qd),
        "spring_potential": lambda: reference.spring_potential(model, data, q),
        "spring_damper_magnitudes": lambda: reference.spring_damper_magnitudes(model, data, q, qd),
        "element_torques": lambda: reference.element_torques(model, data, qp, vp),
        "element_gains": lambda: reference.element_gains(model, data, qp),
        "deformations": lambda: reference.deformations(model, data, qp),
    }


def _arrays(result) -> list[np.ndarray]:
    """A result (array, number, tuple of them, None) as a flat list of arrays."""
    if isinstance(result, tuple):
        return [a for part in result for a in _arrays(part)]
    return [np.asarray(np.nan if result is None else result, dtype=float)]


def _snapshot(model: ReferenceModel) -> dict:
    """Copies of everything a ReferenceModel holds."""
    return {
        "attributes": sorted(vars(model)),
        "pin_model": model.pin_model.copy(),
        "pin_model_no_gravity": model.pin_model_no_gravity.copy(),
        "arrays": {k: np.copy(v) for k, v in vars(model).items() if isinstance(v, np.ndarray)},
        "frames": [
            (joint, placement.homogeneous.copy())
            for joint, placement in model.frames1 + model.frames2
        ],
        "bushings": [
            (b.frame1[1].homogeneous.copy(), b.frame2[1].homogeneous.copy(), b.stiffness.copy())
            for b in model.bushings
        ],
        "coords": list(model.coords),
        "coordinate_names": list(model.coordinate_names),
        "identity_map": model.identity_map,
    }


def _differences(before: dict, model: ReferenceModel) -> list[str]:
    """What differs between a snapshot and the model now (empty: unchanged)."""
    now = _snapshot(model)
    out = [
        k
        for k in ("attributes", "coords", "coordinate_names", "identity_map")
        if before[k] != now[k]
    ]
    out += [k for k in ("pin_model", "pin_model_no_gravity") if not before[k] == now[k]]
    out += [
        f"arrays.{k}"
        for k in before["arrays"]
        if not np.array_equal(before["arrays"][k], now["arrays"].get(k))
    ]
    for key in ("frames", "bushings"):
        flat = [np.asarray(x) for item in before[key] for x in item]
        flat_now = [np.asarray(x) for item in now[key] for x in item]
        if len(flat) != len(flat_now) or not all(map(np.array_equal, flat, flat_now)):
            out.append(key)
    return out


@pytest.fixture(scope="module", params=["all_joint_types", "rt70"])
def scene(request):
    """A scene with every joint kind, mimics, bushings, joint springs (Pinocchio's (q, v)
    differ from the book's), and the RT-70 (bushings; book coordinates are Pinocchio's)."""
    return load_scene(ALL_JOINTS if request.param == "all_joint_types" else "rt70")


def _state(nv: int, seed: int) -> tuple[np.ndarray, np.ndarray]:
    rng = np.random.default_rng(seed)
    return rng.uniform(-0.4, 0.4, nv), rng.uniform(-1.0, 1.0, nv)


def test_every_algorithm_is_called_here():
    """The lists below cover everything rt70.reference exports (a new algorithm joins)."""
    assert ALGORITHMS and all(callable(getattr(reference, n)) for n in ALGORITHMS)
    scene = load_scene("double_pendulum")
    q, qd = _state(scene.reference.nv, 0)
    assert sorted(_calls(scene.reference, scene.reference_data, q, qd)) == ALGORITHMS


@pytest.mark.parametrize("cls", [ReferenceModel, Model], ids=["reference", "textbook"])
def test_models_have_no_dynamics_methods(cls):
    """Algorithms are functions of (model, data, …), never methods of the model."""
    found = [n for n in (*ALGORITHMS, *OLD_ATTRIBUTES) if hasattr(cls, n)]
    assert not found, f"{cls.__name__} has {found}"


def test_reference_model_instance_has_no_old_attributes(scene):
    ref = scene.reference
    assert not [n for n in (*ALGORITHMS, *OLD_ATTRIBUTES) if hasattr(ref, n)]
    assert not [k for k, v in vars(ref).items() if "Data" in type(v).__name__]  # no buffers


def test_reference_algorithms_leave_the_model_unchanged(scene):
    """Model constant, Data the work buffers: no algorithm writes into the ReferenceModel."""
    ref = scene.reference
    before = _snapshot(ref)
    data = ReferenceData(ref)
    for seed in (1, 2):
        q, qd = _state(ref.nv, seed)
        for name, call in _calls(ref, data, q, qd).items():
            call()
            assert not _differences(before, ref), name


def test_the_unchanged_check_sees_changes():
    """The comparison above can fail: it sees a changed gravity, array and attribute."""
    scene = load_scene(ALL_JOINTS)
    ref = ReferenceModel(scene.description, scene.text)
    before = _snapshot(ref)
    assert _differences(before, ref) == []
    ref.pin_model.gravity.linear[2] += 1.0
    ref.spring_k[0] += 1.0
    ref.frames1[0][1].translation[0] += 1.0  # a bushing's own placement
    object.__setattr__(ref, "_cache", ReferenceData(ref))  # past the guard below
    assert _differences(before, ref) == [
        "attributes",
        "pin_model",
        "arrays.spring_k",
        "frames",
        "bushings",
    ]


def test_reference_model_refuses_rebinding():
    """Like the textbook's frozen Model: an attribute cannot be set after building."""
    scene = load_scene(ALL_JOINTS)
    ref = ReferenceModel(scene.description, scene.text)
    with pytest.raises(AttributeError, match="constant once built"):
        ref.spring_k = np.zeros(3)
    with pytest.raises(AttributeError, match="constant once built"):
        ref.new_cache = 1


def test_two_data_of_one_model_give_identical_results(scene):
    """Results depend on (model, state) only, not on what another Data computed."""
    ref = scene.reference
    first, second = ReferenceData(ref), ReferenceData(ref)
    q, qd = _state(ref.nv, 3)
    other_q, other_qd = _state(ref.nv, 4)
    expected = {n: _arrays(c()) for n, c in _calls(ref, first, q, qd).items()}
    for call in _calls(ref, second, other_q, other_qd).values():
        call()  # the second Data now holds another state
    for data in (second, first):
        for name, call in _calls(ref, data, q, qd).items():
            got = _arrays(call())
            assert len(got) == len(expected[name]), name
            for a, b in zip(got, expected[name], strict=True):
                assert np.array_equal(a, b, equal_nan=True), name
