"""Analytic references the scene library is judged by.

One import point for the closed-form solutions; each family lives in its own module:

* :mod:`.analytic_impacts` -- bouncing ball (Newton restitution, Zeno accumulation) and
  Housner's rocking block;
* :mod:`.analytic_friction` -- box on an incline, box sliding to rest, sphere going from
  sliding to rolling;
* :mod:`.analytic_rigid` -- pendulum on a revolute joint (Jacobi elliptic functions),
  torque-free rigid body (Euler's equations, Dzhanibekov flip), rigid-body energy;
* :mod:`.analytic_linkages` -- slider–crank at constant crank speed;
* :mod:`.edges` -- a hoop sliding without friction off a plate's sharp edge (pivot about the
  edge, leave angle, free flight).

All functions are pure and unit-agnostic (any consistent unit system; angles in radians), and
vectorised over time: a time argument of any shape gives results of that shape (with a
trailing axis of 3 for vectors). Misuse raises ValueError naming the argument.
"""

from clearbench.scenarios.analytic.edges import (
    HoopOverEdge,
    hoop_over_edge_leave_angle,
    hoop_over_edge_path,
    hoop_over_edge_pivot_time,
)
from clearbench.scenarios.analytic.friction import (
    SOLID_SPHERE_INERTIA_RATIO,
    incline_block_acceleration,
    incline_block_displacement,
    incline_block_sticks,
    incline_block_velocity,
    rolling_incline_acceleration,
    rolling_sphere_angular_velocity,
    rolling_sphere_final_speed,
    rolling_sphere_onset_time,
    rolling_sphere_position,
    rolling_sphere_velocity,
    sliding_box_position,
    sliding_box_stop_distance,
    sliding_box_stop_time,
    sliding_box_velocity,
)
from clearbench.scenarios.analytic.impacts import (
    bouncing_ball_apex_heights,
    bouncing_ball_apex_times,
    bouncing_ball_height,
    bouncing_ball_impact_speed,
    bouncing_ball_impact_times,
    bouncing_ball_rest_time,
    bouncing_ball_velocity,
    rocking_block_amplitudes,
    rocking_block_angle,
    rocking_block_angular_velocity,
    rocking_block_fall_time,
    rocking_block_frequency,
    rocking_block_impact_speed,
    rocking_block_impact_times,
    rocking_block_slenderness,
    rocking_block_velocity_ratio,
)
from clearbench.scenarios.analytic.linkages import (
    SliderCrankMotion,
    slider_crank_dead_centres,
    slider_crank_motion,
)
from clearbench.scenarios.analytic.rigid import (
    PolhodeAxis,
    RigidBodyEnergy,
    TorqueFreePolhode,
    pendulum_angle,
    pendulum_angular_velocity,
    pendulum_energy,
    pendulum_period,
    physical_pendulum_frequency,
    rigid_body_energy,
    simple_pendulum_frequency,
    torque_free_angular_velocity,
    torque_free_invariants,
    torque_free_period,
    torque_free_polhode,
)

__all__ = [
    "SOLID_SPHERE_INERTIA_RATIO",
    "HoopOverEdge",
    "PolhodeAxis",
    "RigidBodyEnergy",
    "SliderCrankMotion",
    "TorqueFreePolhode",
    "bouncing_ball_apex_heights",
    "hoop_over_edge_leave_angle",
    "hoop_over_edge_path",
    "hoop_over_edge_pivot_time",
    "bouncing_ball_apex_times",
    "bouncing_ball_height",
    "bouncing_ball_impact_speed",
    "bouncing_ball_impact_times",
    "bouncing_ball_rest_time",
    "bouncing_ball_velocity",
    "incline_block_acceleration",
    "incline_block_displacement",
    "incline_block_sticks",
    "incline_block_velocity",
    "pendulum_angle",
    "pendulum_angular_velocity",
    "pendulum_energy",
    "pendulum_period",
    "physical_pendulum_frequency",
    "rigid_body_energy",
    "rocking_block_amplitudes",
    "rocking_block_angle",
    "rocking_block_angular_velocity",
    "rocking_block_fall_time",
    "rocking_block_frequency",
    "rocking_block_impact_speed",
    "rocking_block_impact_times",
    "rocking_block_slenderness",
    "rocking_block_velocity_ratio",
    "rolling_sphere_angular_velocity",
    "rolling_incline_acceleration",
    "rolling_sphere_final_speed",
    "rolling_sphere_onset_time",
    "rolling_sphere_position",
    "rolling_sphere_velocity",
    "simple_pendulum_frequency",
    "slider_crank_dead_centres",
    "slider_crank_motion",
    "sliding_box_position",
    "sliding_box_stop_distance",
    "sliding_box_stop_time",
    "sliding_box_velocity",
    "torque_free_angular_velocity",
    "torque_free_invariants",
    "torque_free_period",
    "torque_free_polhode",
]
