# ruff: noqa: D102
"""TEMPORARY (issue 9 migration): the old method-style calls, delegating to the algorithms.

Removed once every caller uses ``algorithm(model, data, q, …)``.
"""

from __future__ import annotations

from functools import cached_property


class LegacyMethods:
    """``model.mass_matrix(q)`` etc. with a private Data; for the migration only."""

    @cached_property
    def _legacy_data(self):
        from rt70.reference.model import ReferenceData

        return ReferenceData(self)

    @property
    def model(self):
        return self.pin_model

    @property
    def data(self):
        return self._legacy_data.pin_data

    def _call(self, name, *args):
        import rt70.reference as r

        return getattr(r, name)(self, self._legacy_data, *args)

    def mass_matrix(self, q):
        return self._call("mass_matrix", q)

    def bias_force(self, q, qd):
        return self._call("bias_force", q, qd)

    def gravity_force(self, q):
        return self._call("gravity_force", q)

    def forward_dynamics(self, q, qd):
        return self._call("forward_dynamics", q, qd)

    def kinetic_energy(self, q, qd):
        return self._call("kinetic_energy", q, qd)

    def gravity_potential(self, q):
        return self._call("gravity_potential", q)

    def weight_moment(self, q):
        return self._call("weight_moment", q)

    def spring_damper_force(self, q, qd):
        return self._call("spring_damper_force", q, qd)

    def spring_potential(self, q):
        return self._call("spring_potential", q)

    def spring_damper_magnitudes(self, q, qd):
        return self._call("spring_damper_magnitudes", q, qd)

    def element_torques(self, qp, vp):
        return self._call("element_torques", qp, vp)

    def element_gains(self, qp):
        return self._call("element_gains", qp)

    def deformations(self, qp, jacobian=True):
        return self._call("deformations", qp, jacobian)

    def to_pinocchio(self, q, qd=None):
        import rt70.reference as r

        return r.to_pinocchio(self, q, qd)
