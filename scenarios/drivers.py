"""Drivers: prescribed velocity or position of chosen components of a body over time."""

from __future__ import annotations

from dataclasses import dataclass, field

import numpy as np

from clearbench.scenarios.element import Element
from clearbench.scenarios.time_profiles import check_profile, evaluate_profile, integrate_profile
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
        """Prescribed rate of the component at time(s) ``t`` [L/T or rad/T]."""
        if self.quantity == "velocity":
            return evaluate_profile(self.times, self.values, t)
        # Position profiles are piecewise linear: the rate is the slope of the current segment.
        times = np.asarray(self.times)
        values = np.asarray(self.values)
        t_arr = np.atleast_1d(np.asarray(t, dtype=float))
        rate = np.zeros_like(t_arr)
        for i in range(len(times) - 1):
            if times[i + 1] > times[i]:
                inside = (t_arr >= times[i]) & (t_arr < times[i + 1])
                rate[inside] = (values[i + 1] - values[i]) / (times[i + 1] - times[i])
        return float(rate[0]) if np.ndim(t) == 0 else rate

    def displacement(self, t):
        """Prescribed displacement of the component from t = 0 [L or rad]."""
        if self.quantity == "position":
            return evaluate_profile(self.times, self.values, t)
        if np.ndim(t) == 0:
            return integrate_profile(self.times, self.values, 0.0, float(t))
        return np.array([integrate_profile(self.times, self.values, 0.0, float(x)) for x in t])
