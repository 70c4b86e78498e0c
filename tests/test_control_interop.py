"""rt70's plants are python-control systems, and rt70.linear takes any python-control one.

The plant of the RT-70 with its axes free, as rt70 builds it (a python-control
``StateSpace`` that keeps its second-order model) and as a plain python-control system
with the same matrices (``control.ss``): balanced truncation, its H∞ error and the
frequency response give the same numbers from either; modal truncation, which needs the
second-order model, says so.
"""

from __future__ import annotations

import control
import numpy as np
import pytest

from rt70.errors import Rt70Error
from rt70.linear import linearize as lin
from rt70.linear import plant as pl
from rt70.linear import reduce as rd
from rt70.linear import responses as rs
from rt70.linear.state_space import as_state_space
from rt70.model.scene import load_scene
from rt70.testing import assert_close


@pytest.fixture(scope="module")
def plants():
    scene = load_scene("rt70_servo")
    held = {"platform_rz": 0.0, "base_rx": np.pi / 4}
    q0 = lin.equilibrium(scene, held)
    ins = [pl.CoordinateInput(f"torque:{a}", a) for a in held]
    outs = [pl.CoordinateOutput(f"angle:{a}", a) for a in held]
    ss = pl.plant(scene, q0, ins, outs)
    return ss, control.ss(ss)


def test_balanced_truncation_and_its_error_take_either_type(plants):
    ss, sys = plants
    ours, theirs = rd.balanced_truncation(ss, 12), rd.balanced_truncation(sys, 12)
    assert ours.order == theirs.order == 12
    e_ours, e_theirs = rd.hinf_error(ss, ours.ss), rd.hinf_error(sys, theirs.ss)
    # without the second-order model the split into rigid and stable parts works on the
    # physical A, which places the lightly damped poles less well: measured 3.3e-8 of
    # ‖G‖∞ against 6.2e-9 with it; both far below the plant's own scale
    assert 0.0 < e_ours.relative < 1e-7 and 0.0 < e_theirs.relative < 1e-6
    f = np.array([0.05, 0.5, 2.0])
    a, b = (rs.frequency_response(r.ss, f).H for r in (ours, theirs))
    full = rs.frequency_response(ss, f).H
    scale = float(np.abs(full).max())
    # at the frequencies of the servo loops, each within 1e-3 of the plant's response
    # (measured: 6.4e-5 and 7.3e-5 of its largest entry there)
    assert_close(a, full, rel=1e-3, scale=scale)
    assert_close(b, full, rel=1e-3, scale=scale)


def test_the_frequency_response_takes_either_type(plants):
    ss, sys = plants
    f = np.array([0.05, 0.5, 2.0])
    ours = rs.frequency_response(ss, f, method="state_space").H
    theirs = rs.frequency_response(sys, f).H
    assert_close(theirs, ours, rel=1e-8, scale=float(np.abs(ours).max()))


def test_what_needs_the_second_order_model_says_so(plants):
    _, sys = plants
    with pytest.raises(Rt70Error, match="needs a plant built from M, K, D"):
        rd.modal_truncation(sys, 5)
    with pytest.raises(Rt70Error, match="expected a python-control StateSpace"):
        as_state_space(np.eye(2))
