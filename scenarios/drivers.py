"""Drivers: prescribed velocity or position of chosen components of a body over time."""

from __future__ import annotations

from dataclasses import dataclass, field

from clearbench.scenarios.element import Element
from clearbench.scenarios.time_profiles import check_profile
from clearbench.scenarios.validation import (
    ANGULAR_VELOCITY,
    DIMENSIONLESS,
    LENGTH,
    TIME,
    VELOCITY,
    SceneError,
    check_name,
    dim,
)


def _profiles():
    """:mod:`clearbench.kernels.time_profiles`, imported at the first evaluation: it imports
    numba (about a second), which building, validating and listing scenes do not need."""
    from clearbench.kernels import time_profiles

    return time_profiles


#: Components a driver can prescribe: translation of the centre of mass along a world axis, or
#: rotation about a world axis through the centre of mass.
COMPONENTS = ("x", "y", "z", "rx", "ry", "rz")
QUANTITIES = ("velocity", "position")


@dataclass(frozen=True)
class Driver(Element):
    """Prescribed motion of one component of ``body``.

    The profile is piecewise linear through (``times[i]``, ``values[i]``), constant outside;
    two equal consecutive times make a jump (e.g. a velocity switched on at 0.7 ms).
    ``quantity = 'position'`` prescribes the displacement of the component from its initial
    value [L or rad]; ``'velocity'`` prescribes its rate [L/T or rad/T].
    """

    collection = "drivers"
    body: str = ""
    component: str = "x"
    quantity: str = "velocity"
    times: tuple = field(default=(0.0,), metadata=dim(TIME))
    values: tuple = (0.0,)

    def _validate(self) -> None:
        check_name("body", self.body)
        if self.component not in COMPONENTS:
            raise SceneError("component", self.component, f"must be one of {COMPONENTS}")
        if self.quantity not in QUANTITIES:
            raise SceneError("quantity", self.quantity, f"must be one of {QUANTITIES}")
        times, values = check_profile("times", self.times, "values", self.values)
        self._set("times", times)
        self._set("values", values)

    def field_dimension(self, name: str) -> tuple[int, int, int] | None:
        """Dimension of ``values`` depends on the component and the quantity."""
        if name != "values":
            return None
        rotational = self.component.startswith("r")
        if self.quantity == "position":
            return DIMENSIONLESS if rotational else LENGTH
        return ANGULAR_VELOCITY if rotational else VELOCITY

    @property
    def is_rotation(self) -> bool:
        return self.component.startswith("r")

    @property
    def axis_index(self) -> int:
        """0, 1 or 2 for the world axis of the component."""
        return "xyz".index(self.component[-1])

    def velocity(self, t):
        """Prescribed rate of the component at time(s) ``t`` [L/T or rad/T]: the profile of a
        velocity driver, the slope of the current segment of a position driver."""
        if self.quantity == "velocity":
            return _profiles().evaluate_profile(self.times, self.values, t)
        return _profiles().evaluate_profile_slope(self.times, self.values, t)

    def displacement(self, t):
        """Prescribed displacement of the component from t = 0 [L or rad]: the profile of a
        position driver, the integral from 0 of a velocity driver's."""
        if self.quantity == "position":
            return _profiles().evaluate_profile(self.times, self.values, t)
        return _profiles().evaluate_profile_integral(self.times, self.values, t)
