"""Mass properties of homogeneous solids, about their centre of mass in their own axes."""

from __future__ import annotations


def diagonal(ixx: float, iyy: float, izz: float) -> tuple:
    """Diagonal inertia tensor as nested tuples [M L^2]."""
    return ((ixx, 0.0, 0.0), (0.0, iyy, 0.0), (0.0, 0.0, izz))


def solid_sphere(mass: float, radius: float) -> tuple:
    """Uniform ball: (2/5) m R^2 about every axis."""
    value = 0.4 * mass * radius**2
    return diagonal(value, value, value)


def solid_box(mass: float, half_extents: tuple[float, float, float]) -> tuple:
    """Uniform box of half extents (a, b, c): m (b^2 + c^2) / 3 about x, etc."""
    a, b, c = half_extents
    return diagonal(mass * (b * b + c * c) / 3.0, mass * (a * a + c * c) / 3.0,
                    mass * (a * a + b * b) / 3.0)

