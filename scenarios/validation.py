"""Input checks shared by the scene description, and the physical dimension of every field.

Every check raises :class:`SceneError`, whose message names the field (a dotted path such as
``bodies[2].mass``) and the offending value, so a user sees what to fix before any engine runs.

Dimensions are exponents of (length, mass, time) stored in the ``metadata`` of dataclass fields;
:mod:`clearbench.scenarios.units` uses them to rescale a scene between unit systems.
"""

from __future__ import annotations

import math
from collections.abc import Iterable

import numpy as np

#: Exponents (length, mass, time) of the physical quantities the scene description uses.
DIMENSIONLESS = (0, 0, 0)
LENGTH = (1, 0, 0)
MASS = (0, 1, 0)
TIME = (0, 0, 1)
VELOCITY = (1, 0, -1)
ACCELERATION = (1, 0, -2)
ANGULAR_VELOCITY = (0, 0, -1)
ANGULAR_ACCELERATION = (0, 0, -2)
FORCE = (1, 1, -2)
MOMENT = (2, 1, -2)
INERTIA = (2, 1, 0)
LINEAR_STIFFNESS = (0, 1, -2)
LINEAR_DAMPING = (0, 1, -1)
TORSIONAL_STIFFNESS = (2, 1, -2)
TORSIONAL_DAMPING = (2, 1, -1)


class SceneError(ValueError):
    """A scene field holds a bad value.

    Attributes
    ----------
    field : str
        Dotted path of the field, e.g. ``bodies[1].inertia``.
    value : object
        The offending value as given.
    reason : str
        What is wrong with it.
    """

    def __init__(self, field: str, value: object, reason: str):
        self.field = field
        self.value = value
        self.reason = reason
        super().__init__(f"{field} = {value!r}: {reason}")

    def within(self, prefix: str) -> SceneError:
        """Return the same error with ``prefix`` prepended to the field path."""
        path = f"{prefix}.{self.field}" if self.field else prefix
        return SceneError(path, self.value, self.reason)


def dim(dimension: tuple[int, int, int]) -> dict:
    """Field metadata declaring the physical dimension of a numeric field."""
    return {"dimension": dimension}


def dimensionless() -> dict:
    """Field metadata of a numeric field with no unit (ratios, angles, quaternions)."""
    return {"dimension": DIMENSIONLESS}


def check_name(field: str, value: object) -> str:
    """A non-empty string without surrounding white space."""
    if not isinstance(value, str) or not value or value != value.strip():
        raise SceneError(field, value, "must be a non-empty name without surrounding spaces")
    return value


#: Largest magnitude of any number of a scene, in the scene's units. The engines multiply the
#: inputs together (inertia m r^2, kinetic energy m v^2 / 2, contact stiffness times depth, the
#: products of a Delassus matrix, units rescaled by powers of 1000): a product of ten numbers of
#: at most 1e30 stays below 1e300, inside double precision (1.8e308), where a single 1e308 radius
#: overflows to inf at its first square. Mechanisms in any unit system this project offers (m to
#: um, kg to mg, s to us) sit many decades inside the bound.
MAX_MAGNITUDE = 1e30


def check_finite(field: str, value: object) -> float:
    """A finite real number of magnitude at most :data:`MAX_MAGNITUDE` (bool is refused)."""
    if isinstance(value, bool) or not isinstance(value, int | float):
        raise SceneError(field, value, "must be a real number")
    try:
        number = float(value)
    except OverflowError:  # an integer beyond double precision
        raise SceneError(field, value, f"magnitude exceeds {MAX_MAGNITUDE:g}, the largest the "
                         "engines can multiply without overflow") from None
    if not math.isfinite(number):
        raise SceneError(field, value, "must be finite (NaN and inf are refused)")
    if abs(number) > MAX_MAGNITUDE:
        raise SceneError(field, value, f"magnitude exceeds {MAX_MAGNITUDE:g}, the largest the "
                         "engines can multiply without overflow")
    return number


def check_positive(field: str, value: object) -> float:
    """A finite number > 0."""
    number = check_finite(field, value)
    if number <= 0.0:
        raise SceneError(field, value, "must be > 0")
    return number


def check_non_negative(field: str, value: object) -> float:
    """A finite number >= 0."""
    number = check_finite(field, value)
    if number < 0.0:
        raise SceneError(field, value, "must be >= 0")
    return number


def check_in_range(field: str, value: object, low: float, high: float) -> float:
    """A finite number in the closed interval [low, high]."""
    number = check_finite(field, value)
    if not low <= number <= high:
        raise SceneError(field, value, f"must lie in [{low}, {high}]")
    return number


def check_finite_vector(field: str, value: object, length: int) -> tuple[float, ...]:
    """A sequence of ``length`` finite numbers, returned as a tuple of floats."""
    if isinstance(value, str) or not isinstance(value, Iterable):
        raise SceneError(field, value, f"must be a list of {length} numbers")
    items = list(value)
    if len(items) != length:
        raise SceneError(field, value, f"must have {length} components, has {len(items)}")
    return tuple(check_finite(f"{field}[{i}]", item) for i, item in enumerate(items))


def check_unit_quaternion(field: str, value: object, tolerance: float = 1e-6) -> tuple:
    """A quaternion (w, x, y, z) of norm 1 within ``tolerance``, returned normalised to round-off.

    A zero or non-finite quaternion, or one whose norm is off by more than ``tolerance``, is
    refused rather than silently normalised: a wrong orientation is a modelling error.
    """
    quaternion = check_finite_vector(field, value, 4)
    norm = math.sqrt(sum(c * c for c in quaternion))
    if norm == 0.0:
        raise SceneError(field, value, "zero quaternion: a unit quaternion (w, x, y, z) is needed")
    if abs(norm - 1.0) > tolerance:
        raise SceneError(
            field, value, f"quaternion norm {norm:.9g} differs from 1 by more than {tolerance}"
        )
    return tuple(c / norm for c in quaternion)


def check_matrix3(field: str, value: object) -> tuple[tuple[float, ...], ...]:
    """A 3x3 matrix of finite numbers as nested tuples."""
    if isinstance(value, str) or not isinstance(value, Iterable):
        raise SceneError(field, value, "must be a 3x3 matrix (list of 3 rows)")
    rows = list(value)
    if len(rows) != 3:
        raise SceneError(field, value, f"must have 3 rows, has {len(rows)}")
    return tuple(check_finite_vector(f"{field}[{i}]", row, 3) for i, row in enumerate(rows))


def check_inertia(field: str, value: object) -> tuple[tuple[float, ...], ...]:
    """A rigid-body inertia tensor: symmetric, positive definite, principal moments satisfying
    the triangle inequality (each <= the sum of the other two).

    Symmetry and the triangle inequality are checked relative to the largest moment, with a
    round-off allowance of 1e-9 of it.
    """
    matrix = np.array(check_matrix3(field, value), dtype=float)
    scale = float(np.max(np.abs(matrix)))
    if scale == 0.0:
        raise SceneError(field, value, "inertia tensor is zero: must be positive definite")
    asymmetry = float(np.max(np.abs(matrix - matrix.T)))
    if asymmetry > 1e-9 * scale:
        raise SceneError(
            field, value, f"inertia tensor is not symmetric (|I - I^T| = {asymmetry:.3g})"
        )
    symmetric = 0.5 * (matrix + matrix.T)
    moments = np.linalg.eigvalsh(symmetric)
    if moments[0] <= 0.0:
        raise SceneError(
            field, value, f"inertia tensor is not positive definite (principal moments {moments})"
        )
    a, b, c = moments
    if c > a + b + 1e-9 * c:
        raise SceneError(
            field,
            value,
            f"principal moments {moments} violate the triangle inequality I3 <= I1 + I2",
        )
    return tuple(tuple(float(x) for x in row) for row in symmetric)
