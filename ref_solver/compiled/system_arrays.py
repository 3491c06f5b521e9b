"""The system and the settings of a stepper compiled once into flat arrays and scalars.

:func:`compile_system` turns a :class:`~clearbench.ref_solver.stepper.MoreauJeanStepper` (its
:class:`~clearbench.ref_solver.system.MultibodySystem`, its mass and projection metrics, its
spring clusters and its settings) into the typed containers the compiled loop takes: numba
reads the fields of a ``NamedTuple`` by name, so the kernels stay readable.
"""

from __future__ import annotations

from typing import NamedTuple

import numpy as np

from clearbench.ref_solver.activation import activation_rule
from clearbench.ref_solver.compiled.contact_solve import METHOD_CODES
from clearbench.ref_solver.fc3d_local import LOCAL_KIND
from clearbench.ref_solver.projection_kernel import closed_gap_slack


class CompiledSystem(NamedTuple):
    """Arrays of one system (``nb`` bodies, ``npair`` pairs, ``nf`` force elements).

    ``geometry`` is :func:`projection_kernel.geometry_arrays` (shapes, pairs, joints, drivers);
    the metrics are (6 nb, 6 nb); the clusters are those of ``MoreauJeanStepper._clusters``
    and ``single_*`` the clusters of one body each (the projection's).
    """

    geometry: tuple
    mass: np.ndarray                # (nb,) [M]
    inertia: np.ndarray             # (nb, 3, 3) [M L^2]
    inverse_inertia: np.ndarray     # (nb, 3, 3)
    gravity: np.ndarray             # (3,) [L/T^2]
    fixed: np.ndarray               # (nb,) bool
    force_kind: np.ndarray          # (nf,) int64
    force_body_a: np.ndarray        # (nf,) int64
    force_body_b: np.ndarray        # (nf,) int64
    force_parameters: np.ndarray    # (nf, 24)
    pair_friction: np.ndarray       # (npair,)
    pair_restitution: np.ndarray    # (npair,)
    mass_matrix: np.ndarray         # (6 nb, 6 nb)
    inverse_mass: np.ndarray        # (6 nb, 6 nb)
    projection_inverse: np.ndarray  # (6 nb, 6 nb)
    cluster: np.ndarray             # (nb,) int64
    cluster_dofs: np.ndarray        # (6 nb,) int64
    cluster_start: np.ndarray       # (clusters + 1,) int64
    single_cluster: np.ndarray      # (nb,) int64
    single_dofs: np.ndarray         # (6 nb,) int64
    single_start: np.ndarray        # (nb + 1,) int64
    n_bilateral: int                # joint and driver rows
    n_joint_rows: int               # joint rows (the first of the bilateral rows)
    has_springs: bool


class LoopSettings(NamedTuple):
    """The scalars of :class:`~clearbench.ref_solver.stepper.StepperSettings` and of its
    contact solver options, as the compiled loop reads them (lengths [L], times [T])."""

    time_step: float
    theta: float
    projection: bool
    position_tolerance: float
    max_projection_iterations: int
    max_activation_rounds: int
    activation_margin: float
    activation_rule: int            # activation.RULE_*
    activation_hold: float          # StepperSettings.activation_hold [L]
    length_step: float              # finite-difference step of the spring stiffness [L]
    method: int                     # contact_solve.METHOD_*
    hybrid_sweeps: int
    hybrid_last_sweeps: int         # StepperSettings.hybrid_last_sweeps
    restitution_threshold: float    # [L/T]
    midpoint_joints: bool
    tolerance: float
    use_max: bool
    max_iterations: int
    local_kind: int
    local_tolerance: float
    local_max_iterations: int
    check_interval: int
    roundoff_floor: bool
    proximal_rescue: float          # StepperSettings.proximal_rescue (0: off)
    closed_gap_slack: float         # projection_kernel.closed_gap_slack [L]
    length_scale: float             # StepperSettings.length_scale [L]
    impact_splits: int              # impacts localised per step (0: no impact localisation)


def compile_system(stepper) -> tuple[CompiledSystem, LoopSettings]:
    """The arrays and settings of ``stepper`` (a ``MoreauJeanStepper``), for :mod:`.loop`."""
    s = stepper.system
    cfg = stepper.settings
    solver = cfg.solver
    n_drivers = int(s.driver_body.shape[0])
    system = CompiledSystem(
        geometry=stepper.geometry, mass=s.mass, inertia=s.inertia,
        inverse_inertia=s.inverse_inertia, gravity=s.gravity, fixed=s.body_fixed,
        force_kind=s.force_kind, force_body_a=s.force_body_a, force_body_b=s.force_body_b,
        force_parameters=s.force_parameters, pair_friction=s.pair_friction,
        pair_restitution=s.pair_restitution, mass_matrix=stepper.mass_matrix,
        inverse_mass=stepper.inverse_mass, projection_inverse=stepper.projection_inverse,
        cluster=stepper.cluster, cluster_dofs=stepper.cluster_dofs,
        cluster_start=stepper.cluster_start, single_cluster=stepper.single_clusters[0],
        single_dofs=stepper.single_clusters[1], single_start=stepper.single_clusters[2],
        n_bilateral=int(stepper.n_bilateral), n_joint_rows=int(stepper.n_bilateral) - n_drivers,
        has_springs=bool(stepper.has_springs))
    settings = LoopSettings(
        time_step=float(cfg.time_step), theta=float(cfg.theta),
        projection=bool(cfg.projection), position_tolerance=float(cfg.position_tolerance),
        max_projection_iterations=int(cfg.max_projection_iterations),
        max_activation_rounds=int(cfg.max_activation_rounds),
        activation_margin=float(cfg.activation_margin),
        activation_rule=activation_rule(cfg), activation_hold=float(cfg.activation_hold),
        length_step=1e-6 * float(cfg.length_scale), method=METHOD_CODES[cfg.method],
        hybrid_sweeps=int(cfg.hybrid_sweeps), hybrid_last_sweeps=int(cfg.hybrid_last_sweeps),
        restitution_threshold=float(cfg.restitution_threshold),
        midpoint_joints=cfg.joint_law == "midpoint", tolerance=float(solver.tolerance),
        use_max=bool(solver.use_max_normalisation), max_iterations=int(solver.max_iterations),
        local_kind=int(LOCAL_KIND[solver.local_solver]),
        local_tolerance=float(solver.local_tolerance),
        local_max_iterations=int(solver.local_max_iterations),
        check_interval=int(solver.residual_check_interval),
        roundoff_floor=bool(solver.roundoff_floor),
        proximal_rescue=float(cfg.proximal_rescue),
        closed_gap_slack=float(closed_gap_slack(cfg.position_tolerance, cfg.length_scale)),
        length_scale=float(cfg.length_scale),
        impact_splits=int(cfg.max_impact_splits) if cfg.localise_impacts else 0)
    return system, settings


def history_length(settings: LoopSettings) -> int:
    """Length of the solvers' residual-history scratch: at least every iteration cap."""
    return max(settings.max_iterations, settings.hybrid_sweeps, settings.hybrid_last_sweeps, 200)
