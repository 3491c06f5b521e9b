"""Array description of a multibody system, as the reference solver consumes it.

The reference solver knows nothing of scenes: the reference adapter converts a Scene into a
:class:`MultibodySystem`. Conventions (consistent units, whatever they are):

- Body ``b`` is described at its centre of mass: position ``x`` (3,) world, orientation ``p``
  (4,) unit quaternion (w, x, y, z) rotating body axes to world axes, velocity ``v`` (3,) world
  axes, angular velocity ``omega`` (3,) BODY axes. The mass matrix diag(m I3, J) is therefore
  constant (J is the inertia about the centre of mass in body axes).
- Fixed bodies carry no degrees of freedom; a body-index of -1 never occurs in arrays, fixed
  bodies are flagged by ``body_fixed``.
- Points and frames attached to a body are given relative to its centre of mass in body axes.
"""

from __future__ import annotations

from dataclasses import dataclass, field

import numpy as np

# Joint kinds (integer codes used inside compiled loops).
JOINT_SPHERICAL = 0
JOINT_REVOLUTE = 1
JOINT_PRISMATIC = 2
JOINT_FIXED = 3
JOINT_CODES = {
    "spherical": JOINT_SPHERICAL,
    "revolute": JOINT_REVOLUTE,
    "prismatic": JOINT_PRISMATIC,
    "fixed": JOINT_FIXED,
}
#: Number of bilateral rows of each joint kind.
JOINT_ROWS = np.array([3, 5, 5, 6], dtype=np.int64)

# Force-element kinds.
FORCE_LINEAR_SPRING = 0
FORCE_TORSIONAL_SPRING = 1
FORCE_POINT_FORCE = 2
FORCE_MOMENT = 3
FORCE_LEVER_SPRING = 4
FORCE_ANGLE_LAW = 5
FORCE_DISTANCE_LAW = 6
#: Force elements that depend on the configuration (linearised implicitly by the stepper).
CONFIGURATION_FORCES = (FORCE_LINEAR_SPRING, FORCE_TORSIONAL_SPRING, FORCE_LEVER_SPRING,
                        FORCE_ANGLE_LAW, FORCE_DISTANCE_LAW)


@dataclass(frozen=True)
class MultibodySystem:
    """Everything the stepper needs, as contiguous float64 / int64 arrays.

    Shapes: ``nb`` bodies, ``ns`` shapes, ``npair`` contact pairs, ``nj`` joints, ``nd``
    drivers, ``nf`` force elements; ``P`` shape parameters (see scenarios.geometry).
    """

    # bodies
    mass: np.ndarray                 # (nb,)            [M]
    inertia: np.ndarray              # (nb, 3, 3)       [M L^2] about the COM, body axes
    inverse_inertia: np.ndarray      # (nb, 3, 3)
    body_fixed: np.ndarray           # (nb,) bool
    gravity: np.ndarray              # (3,)             [L/T^2]
    # shapes (placement relative to the body's centre of mass, body axes)
    shape_kind: np.ndarray           # (ns,) int
    shape_parameters: np.ndarray     # (ns, P)
    shape_body: np.ndarray           # (ns,) int
    shape_position: np.ndarray       # (ns, 3)          [L]
    shape_rotation: np.ndarray       # (ns, 3, 3)       shape axes -> body axes
    # contact pairs
    pair_shape_a: np.ndarray         # (npair,) int
    pair_shape_b: np.ndarray         # (npair,) int
    pair_friction: np.ndarray        # (npair,)
    pair_restitution: np.ndarray     # (npair,)
    pair_offset: np.ndarray          # (npair,)         [L]
    # ideal joints
    joint_kind: np.ndarray           # (nj,) int
    joint_body_a: np.ndarray         # (nj,) int
    joint_body_b: np.ndarray         # (nj,) int
    joint_anchor_a: np.ndarray       # (nj, 3)          [L] anchor in A (COM-relative, body axes)
    joint_anchor_b: np.ndarray       # (nj, 3)          [L] anchor in B
    joint_frame_a: np.ndarray        # (nj, 3, 3)       columns (axis, t1, t2) in A's body axes
    joint_axis_b: np.ndarray         # (nj, 3)          axis in B's body axes
    joint_relative_rotation: np.ndarray  # (nj, 4)      p_A^-1 p_B at t = 0
    # drivers: component 0..2 translation of the COM along world x, y, z; 3..5 rotation about
    # world x, y, z; quantity 0 velocity, 1 position. Profile i is
    # times[driver_start[i]:driver_start[i+1]] (piecewise linear, constant outside).
    driver_body: np.ndarray          # (nd,) int
    driver_component: np.ndarray     # (nd,) int
    driver_quantity: np.ndarray      # (nd,) int
    driver_start: np.ndarray         # (nd + 1,) int
    driver_times: np.ndarray         # (sum,)           [T]
    driver_values: np.ndarray        # (sum,)           [L, L/T, rad or rad/T]
    driver_initial: np.ndarray       # (nd,)            initial value of the component
    driver_reference: np.ndarray     # (nd, 4)          body orientation at t = 0
    # force elements: kind, two bodies (-1 = none), real parameters (see forces.py)
    force_kind: np.ndarray           # (nf,) int
    force_body_a: np.ndarray         # (nf,) int
    force_body_b: np.ndarray         # (nf,) int
    force_parameters: np.ndarray     # (nf, 24)
    # names, for statistics and read-out
    body_names: tuple = field(default=())
    pair_names: tuple = field(default=())
    joint_names: tuple = field(default=())

    @property
    def body_count(self) -> int:
        return int(self.mass.shape[0])

    @property
    def pair_count(self) -> int:
        return int(self.pair_shape_a.shape[0])

    @property
    def bilateral_row_count(self) -> int:
        """Rows of ideal joints plus driver rows."""
        return int(JOINT_ROWS[self.joint_kind].sum()) + int(self.driver_body.shape[0])

    @property
    def has_springs(self) -> bool:
        """True when some force element depends on the configuration or velocity."""
        return bool(np.isin(self.force_kind, CONFIGURATION_FORCES).any())


@dataclass
class State:
    """Configuration and velocity of every body at one time (arrays are updated in place).

    x (nb, 3) [L], p (nb, 4), v (nb, 3) [L/T] world, omega (nb, 3) [1/T] body axes, t [T].
    """

    t: float
    x: np.ndarray
    p: np.ndarray
    v: np.ndarray
    omega: np.ndarray

    def copy(self) -> State:
        return State(self.t, self.x.copy(), self.p.copy(), self.v.copy(), self.omega.copy())
