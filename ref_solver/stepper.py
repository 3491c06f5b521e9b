"""The Moreau–Jean time-stepper with the combined projection of the C-60 study.

One step of length h from state k (Section 2.4 of Akhadkar, Acary, Brogliato 2018):

1. Free velocity (theta-method). Forces F_k at t_k + theta h; springs linearised implicitly,
   W = M - h theta C - h^2 theta^2 K, so stiff springs do not limit h; gyroscopic terms by the
   momentum-conserving update of :mod:`.gyroscopic`.
2. Velocity stage on the index set I: bilateral rows (joints, drivers) and the contacts of I
   with Newton's impact law (u_N,k+1 + e u_N,k) and Coulomb friction as a second-order cone
   complementarity problem (De Saxcé), solved by :func:`solve_contact_problem`.
3. Position update x_{k+1} = x_k + h v_theta, p_{k+1} = p_k exp(h Omega_theta).
4. Projection stage (``projection=True``): Newton iterations on the position constraints of
   joints, drivers and the contacts of I (as equalities g = 0 for the contacts that carry an
   impulse, as g >= 0 for the others, eq. 21): a mixed LCP in the multipliers delta
   with the correction dq = Mp^-1 H^T delta (Mp: mass for translations, inertia about the
   body's constraint points for rotations, see ``_projection_metric_inverse``), until every
   violation is below ``position_tolerance``.
5. Activation stage: I <- I U {alpha : g_alpha(q_{k+1}) <= 0}; when I grew, the step is redone
   from state k (eq. 22). I starts as the contacts already closed at q_k (gap <= the activation
   margin), or with ``activation="held"`` also those held from the previous step
   (:mod:`.activation`); without projection it starts as Moreau's prediction
   g + (h/2) u_N <= 0.
6. Impact localisation (``localise_impacts=True``, with the projection): the steps above apply
   an impact over the whole step. A ball approaching at speed v that crosses the ground at the
   fraction tau of the step ends it (position update with the mean of the pre- and post-impact
   velocities) |v| h (1 + e) (tau - 1/2) above its physical height when tau > (1 - e) / 2, or
   projected onto the ground, e |v| h (1 - tau) below it, otherwise; and Newton's law acts on
   the normal velocity at the start of the step instead of at the crossing, off by
   g h (1 - (1 + e) tau). Both are O(h) (the position error is largest for tau near 0 or 1): a
   relative apex error of order |v| h / apex. When the first activation round finds contacts
   that were open at q_k and are closed at its end, approaching faster than the restitution
   threshold with e > 0, the step is redone as (a) a substep of tau' h (tau: the crossing
   fraction of the earliest of them, from :func:`crossing_fraction`; tau' = tau enlarged by a
   relative 1e-9 and 4 ulps, at most 1) in which these contacts are not activated, so that the
   motion is the free motion up to the crossing, (b) the impact at the crossing configuration as
   a step of zero length (Moreau's scheme with h = 0: Newton's law and Coulomb friction on the
   impulses, no position change, then the projection, which removes the penetration of order
   1e-9 |v| h left by the enlargement when it exceeds the position tolerance), and (c) the rest
   of the step, (1 - tau') h, from there (which may localise a later impact, up to
   ``max_impact_splits`` per step). There is no cut-off near tau = 0 or 1: the classic position
   error is largest there, and a substep of any length > 0 is a valid step.

Every step returns :class:`StepStatistics`; a one-step problem that does not converge is
flagged there, never hidden.
"""

from __future__ import annotations

import time
from dataclasses import dataclass, field, replace

import numpy as np

from clearbench.ref_solver.activation import (
    RULE_MOREAU,
    RULE_PREDICTED,
    RULES,
    activation_rule,
    first_round,
)
from clearbench.ref_solver.constraints import (
    bilateral_rows,
    contact_rows,
    delassus,
    row_values,
)
from clearbench.ref_solver.contact_problem import (
    ContactProblem,
    SolverOptions,
    SolverResult,
    SolverStatus,
)
from clearbench.ref_solver.fc3d_proximal import (
    DEFAULT_RELATIVE_WEIGHT,
    PROXIMAL_OUTER_ITERATIONS,
    proximal_newton_dense,
)
from clearbench.ref_solver.fc3d_solve import solve_contact_problem
from clearbench.ref_solver.forces import (
    no_angle_memory,
    remember_angles,
    rotation_matrices,
)
from clearbench.ref_solver.gyroscopic import integrate_orientations
from clearbench.ref_solver.projection import solve_projection
from clearbench.ref_solver.projection_kernel import (
    MAX_PROJECTION_HALVINGS,
    candidates,
    closed_gap_limit,
    closed_gap_slack,
    correction_budget,
    correction_size,
    geometry_arrays,
    project,
)
from clearbench.ref_solver.step_kernels import crossing_fraction as crossing_fraction_kernel
from clearbench.ref_solver.step_kernels import free_velocity, velocity_problem
from clearbench.ref_solver.system import MultibodySystem, State
from clearbench.scenarios.geometry import MAX_CONTACTS_PER_PAIR

#: The hybrid chain's proximal-point attempt among its (options, start) attempts
#: (``MoreauJeanStepper._solve``).
_PROXIMAL = object()


@dataclass(frozen=True)
class StepperSettings:
    """Settings of :class:`MoreauJeanStepper` (lengths in the system's length unit).

    Parameters
    ----------
    time_step : float
        h [T], > 0.
    theta : float
        theta of the theta-method, in [1/2, 1].
    projection : bool
        Combined projection on (the study's scheme) or plain Moreau–Jean.
    solver : SolverOptions
        One-step contact solver (method, tolerance, iteration cap).
    position_tolerance : float
        Largest joint violation / contact penetration left by the projection [L].
    max_projection_iterations : int
        Cap of the projection's Gauss–Newton loop (>= 1). Default 100: at 30 the C-60's
        ``c60-trip`` of ``lever-7.99`` at 16 us stopped one projection at 3.3e-4 mm while its
        convergence turned quadratic (docs/reference-solver.md, "The projection's bound").
    max_activation_rounds : int
        Cap of the activation loop per step.
    activation_margin : float
        Contacts whose gap at the start of the step is below this are active from the start
        of the step [L].
    activation : str
        With the projection, the first activation round's rule (:mod:`.activation`): ``gap``
        (the contacts closed at the step's start, the study's scheme), ``held`` (also those
        that carried an impulse in the previous step while open by at most
        ``activation_hold``) or ``predicted`` (also those that the free motion closes within
        the step).
    activation_hold : float
        The hold margin of the ``held`` and ``predicted`` rules [L] (>= 0).
    length_scale : float
        Characteristic length [L] (the scene's largest): finite-difference steps of the
        spring stiffness, the round-off of gaps (``projection_kernel.closed_gap_slack``) and
        the bound of the projection's corrections (``projection_kernel.correction_budget``).
    method : str
        ``nsgs``, ``newton`` or ``hybrid`` (NSGS for at most ``hybrid_sweeps`` sweeps, then
        Newton from where it stopped).
    restitution_threshold : float
        Impacts with a normal approach speed below this [L/T] are plastic (e = 0). A bounce of
        speed v under gravity g lasts 2 v / g; below about g h it fits within one step and a
        fixed-step scheme cannot resolve it: with e > 0 a resting body would chatter at an
        amplitude of order e^2 g h^2 instead of coming to rest. 0 disables the threshold. It is
        a speed tied to the nominal step: the substeps of a localised impact keep it.
    joint_law : str
        ``midpoint``: ideal joints constrain the mid-step velocity (energy error O(h^2));
        ``end``: they constrain v_{k+1} as contacts do in Moreau–Jean (O(h) energy loss, the
        classic scheme; the limit of a clearance joint whose clearance goes to zero).
    localise_impacts : bool
        Split a step at the crossing time of a contact that closes within it with an elastic
        impact (module docstring, item 6). Requires ``projection``. Off: the classic scheme,
        whose apex error of a bouncing ball is first order in h.
    max_impact_splits : int
        Most impacts localised within one step (>= 1); later ones in the step are taken by the
        classic scheme.
    hybrid_last_sweeps : int
        The sweeps of each of the ``hybrid`` chain's two last attempts, NSGS from zero and
        from where its first NSGS stopped, after everything else failed (>= 1). Default 100:
        at their former cap (``solver.max_iterations``, 10,000) they converged none of the
        C-60's problems they ran on and took most of a coarse step's solve
        (docs/reference-solver-speed.md, "Choosing the contact solve").
    proximal_rescue : float
        > 0: an attempt of the ``hybrid`` chain by proximal-point Newton from the warm start,
        after its Newton attempts (from NSGS's end, the warm start and zero) failed
        (:meth:`MoreauJeanStepper._solve`), with the weight rho = ``proximal_rescue`` x the
        largest diagonal entry of W (:mod:`.fc3d_proximal`); default
        :data:`.fc3d_proximal.DEFAULT_RELATIVE_WEIGHT` (1e-8). 0: no such attempt.
    """

    time_step: float
    theta: float = 0.5
    projection: bool = True
    solver: SolverOptions = field(
        default_factory=lambda: SolverOptions(tolerance=1e-12, roundoff_floor=True))
    position_tolerance: float = 1e-12
    max_projection_iterations: int = 100
    max_activation_rounds: int = 20
    activation_margin: float = 1e-12
    activation: str = "gap"
    activation_hold: float = 0.0
    length_scale: float = 1.0
    method: str = "hybrid"
    hybrid_sweeps: int = 100
    hybrid_last_sweeps: int = 100
    restitution_threshold: float = 0.0
    joint_law: str = "midpoint"
    localise_impacts: bool = False
    max_impact_splits: int = 1
    proximal_rescue: float = DEFAULT_RELATIVE_WEIGHT

    def __post_init__(self) -> None:
        if not self.time_step > 0.0:
            raise ValueError(f"time_step must be > 0, got {self.time_step!r}")
        for name in ("hybrid_last_sweeps", "max_projection_iterations"):
            value = getattr(self, name)
            if not (isinstance(value, int) and value >= 1):
                raise ValueError(f"{name} must be an integer >= 1, got {value!r}")
        if not 0.5 <= self.theta <= 1.0:
            raise ValueError(f"theta must be in [0.5, 1], got {self.theta!r}")
        if self.activation not in RULES:
            raise ValueError(f"activation must be one of {sorted(RULES)}, got "
                             f"{self.activation!r}")
        if not self.activation_hold >= 0.0:
            raise ValueError(f"activation_hold must be >= 0, got {self.activation_hold!r}")
        if self.joint_law not in ("midpoint", "end"):
            raise ValueError(f"joint_law must be 'midpoint' or 'end', got {self.joint_law!r}")
        if not self.position_tolerance > 0.0:
            raise ValueError(f"position_tolerance must be > 0, got {self.position_tolerance!r}")
        if not isinstance(self.localise_impacts, bool):
            raise ValueError(f"localise_impacts must be a bool, got {self.localise_impacts!r}")
        if self.localise_impacts and not self.projection:
            raise ValueError("localise_impacts needs projection=True (it relies on the "
                             "activation loop of the combined projection)")
        if not self.max_impact_splits >= 1:
            raise ValueError(f"max_impact_splits must be >= 1, got {self.max_impact_splits!r}")
        if not self.proximal_rescue >= 0.0:
            raise ValueError(f"proximal_rescue must be >= 0, got {self.proximal_rescue!r}")


@dataclass(frozen=True)
class StepStatistics:
    """What one step did (iterations summed over activation rounds).

    ``solver_seconds`` is the wall time spent in the one-step contact solver and
    ``contact_sweeps`` the sum over its solves of (iterations x contacts), so that their ratio
    is the cost per contact per iteration.

    A step with localised impacts (``StepperSettings.localise_impacts``) is computed in
    ``substeps`` pieces (1 when it was not split; each localised impact adds the zero-length
    impact and the rest of the step: 3 for one): the counts, seconds and sweeps are summed over
    every piece, including the first activation round that found the crossing and was
    abandoned (its work counts, its result is discarded, so its convergence does not);
    ``solver_residual`` and ``projection_violation`` are the largest of the pieces, the
    converged flags hold when every piece converged, ``active_contacts`` counts the contacts
    active in any piece.
    """

    solver_iterations: int
    solver_residual: float
    solver_converged: bool
    active_contacts: int
    activation_rounds: int
    projection_iterations: int
    projection_violation: float
    projection_converged: bool
    gyroscopic_iterations: int
    solver_seconds: float = 0.0
    contact_sweeps: int = 0
    substeps: int = 1


@dataclass
class StepResult:
    """State at the end of the step, statistics and the impulses over the step.

    ``contact_impulse`` (npair, K, 3) in each contact's frame (N, T1, T2) [F T];
    ``contact_frame`` (npair, K, 3, 3) rows n, t1, t2; ``contact_point`` (npair, K, 3) world
    point on shape B; ``contact_active`` (npair, K) bool.

    Of a step computed in substeps (localised impacts): the impulses of the substeps summed in
    world coordinates and expressed in the frame of the last substep in which the contact was
    active (frames and points of that substep), ``contact_active`` true when the contact was
    active in any substep.
    """

    state: State
    statistics: StepStatistics
    contact_impulse: np.ndarray
    contact_frame: np.ndarray
    contact_point: np.ndarray
    contact_active: np.ndarray


class MoreauJeanStepper:
    """Advance a :class:`MultibodySystem` one step at a time (see module docstring)."""

    def __init__(self, system: MultibodySystem, settings: StepperSettings):
        self.system = system
        self.settings = settings
        nb = system.body_count
        self.dof = 6 * nb
        mass_matrix = np.zeros((self.dof, self.dof))
        inverse = np.zeros((self.dof, self.dof))
        for b in range(nb):
            if system.body_fixed[b]:
                continue
            s = slice(6 * b, 6 * b + 3)
            mass_matrix[s, s] = system.mass[b] * np.eye(3)
            inverse[s, s] = np.eye(3) / system.mass[b]
            r = slice(6 * b + 3, 6 * b + 6)
            mass_matrix[r, r] = system.inertia[b]
            inverse[r, r] = system.inverse_inertia[b]
        self.mass_matrix = mass_matrix
        self.inverse_mass = inverse
        self.projection_inverse = self._projection_metric_inverse(system)
        self.geometry = geometry_arrays(system)
        self.n_bilateral = system.bilateral_row_count
        self.compiled_projection = True
        self.has_springs = system.has_springs
        # (the method's own options, hybrid's Newton, its first NSGS, its full NSGS, its
        # least-norm Newton)
        solver = settings.solver
        self._solver_options = (
            replace(solver, method=settings.method) if settings.method != "hybrid" else None,
            replace(solver, method="newton", max_iterations=200),
            replace(solver, method="nsgs", max_iterations=settings.hybrid_sweeps),
            replace(solver, method="nsgs", max_iterations=settings.hybrid_last_sweeps),
            replace(solver, method="newton", max_iterations=200, newton_direction="least_norm"))
        self._clusters(system)
        npair = system.pair_count
        k = MAX_CONTACTS_PER_PAIR
        self.previous_impulse = np.zeros((npair, k, 3))
        self.previous_bilateral = np.zeros(system.bilateral_row_count)
        self._newton_first = None  # hybrid: the Newton options that solved the last problem
        # the angle laws' continuous angles at the last step (forces.remember_angles)
        self.angle_memory = no_angle_memory(system.force_kind.shape[0])
        self.single_clusters = (np.arange(nb, dtype=np.int64),
                                np.arange(6 * nb, dtype=np.int64),
                                np.arange(0, 6 * nb + 1, 6, dtype=np.int64))

    # ------------------------------------------------------------------ set-up
    @staticmethod
    def _projection_metric_inverse(system: MultibodySystem) -> np.ndarray:
        """Inverse of the metric of the position projection, (6 nb, 6 nb) block diagonal.

        Translations weigh the mass m; rotations weigh J + m rho^2 I, the inertia about the
        body's farthest constraint point (shape origins and joint anchors, at distance rho
        from the centre of mass). With the plain mass matrix, a light body whose centre of
        mass is far from its joints (a pendulum bob) is corrected by rotating it about its
        centre of mass, which swings the joint tangentially by more than a tight clearance and
        the Newton projection does not converge. Any symmetric positive definite metric
        projects onto the same constraint manifold; this one is scale invariant.
        """
        nb = system.body_count
        rho = np.zeros(nb)
        for shape, body in enumerate(system.shape_body):
            rho[body] = max(rho[body], float(np.linalg.norm(system.shape_position[shape])))
        for j in range(system.joint_kind.shape[0]):
            for body, anchor in ((system.joint_body_a[j], system.joint_anchor_a[j]),
                                 (system.joint_body_b[j], system.joint_anchor_b[j])):
                rho[body] = max(rho[body], float(np.linalg.norm(anchor)))
        out = np.zeros((6 * nb, 6 * nb))
        for b in range(nb):
            if system.body_fixed[b]:
                continue
            out[6 * b:6 * b + 3, 6 * b:6 * b + 3] = np.eye(3) / system.mass[b]
            angular = system.inertia[b] + system.mass[b] * rho[b] ** 2 * np.eye(3)
            out[6 * b + 3:6 * b + 6, 6 * b + 3:6 * b + 6] = np.linalg.inv(angular)
        return out

    def _clusters(self, system: MultibodySystem) -> None:
        """Bodies coupled by springs form clusters; the iteration matrix is block diagonal
        over clusters (each body alone when there is no spring)."""
        nb = system.body_count
        parent = list(range(nb))

        def root(i):
            while parent[i] != i:
                i = parent[i]
            return i

        if system.has_springs:
            for a, b in zip(system.force_body_a, system.force_body_b, strict=True):
                if a >= 0 and b >= 0 and not system.body_fixed[a] and not system.body_fixed[b]:
                    parent[root(a)] = root(b)
        roots = sorted({root(i) for i in range(nb)})
        index = {r: c for c, r in enumerate(roots)}
        cluster = np.array([index[root(i)] for i in range(nb)], dtype=np.int64)
        dofs, start = [], [0]
        for c in range(len(roots)):
            for b in range(nb):
                if cluster[b] == c:
                    dofs.extend(range(6 * b, 6 * b + 6))
            start.append(len(dofs))
        self.cluster = cluster
        self.cluster_dofs = np.array(dofs, dtype=np.int64)
        self.cluster_start = np.array(start, dtype=np.int64)

    # ------------------------------------------------------------------ one step
    def step(self, state: State, time_step: float | None = None) -> StepResult:
        """Advance ``state`` by ``time_step`` [T] (default ``settings.time_step``); ``state`` is
        not modified. Nothing of the stepper depends on the step size but this argument."""
        h = self.settings.time_step if time_step is None else float(time_step)
        if not h > 0.0:
            raise ValueError(f"time_step must be > 0, got {time_step!r}")
        splits = self.settings.max_impact_splits if self.settings.localise_impacts else 0
        result = self._advance(state, h, splits)
        sys_ = self.system
        remember_angles(rotation_matrices(result.state.p), sys_.force_kind, sys_.force_body_a,
                        sys_.force_body_b, sys_.force_parameters, self.angle_memory)
        return result

    def _advance(self, state: State, h: float, splits: int) -> StepResult:
        """One step of length h, localising at most ``splits`` impacts (module docstring)."""
        attempt = self._single_step(state, h, watch=splits > 0)
        if isinstance(attempt, StepResult):
            return attempt
        crossing: _Crossing = attempt
        fraction = min(crossing.fraction * (1.0 + 1e-9) + 4.0 * np.finfo(float).eps, 1.0)
        h1 = fraction * h
        parts = [crossing.abandoned]
        # (a) Free motion to the crossing: the crossing contacts are not activated.
        flight = self._single_step(state, h1, suppress=crossing.contacts)
        parts.append(flight.statistics)
        pieces = [flight]
        current = flight.state
        # (b) The impact at the crossing configuration, a step of zero length; skipped when the
        # estimate left every crossing contact open (the rest of the step then takes it).
        cand = self._candidates(current.x, rotation_matrices(current.p))
        if (self._slots(cand, cand[0] <= self.settings.activation_margin)
                & crossing.contacts).any():
            impact = self._single_step(current, 0.0)
            parts.append(impact.statistics)
            pieces.append(impact)
            current = impact.state
        # (c) The rest of the step.
        if fraction < 1.0:
            rest = self._advance(current, h - h1, splits - 1)
            parts.append(rest.statistics)
            pieces.append(rest)
            current = rest.state
        current.t = state.t + h  # the time of the unsplit step, to the last bit
        return self._combine(current, parts, pieces)

    @staticmethod
    def _combine(state: State, parts: list[StepStatistics], pieces: list[StepResult]
                 ) -> StepResult:
        """One :class:`StepResult` from the substeps of a split step (see its docstring)."""
        active = np.zeros_like(pieces[0].contact_active)
        world = np.zeros_like(pieces[0].contact_impulse)
        frame = pieces[-1].contact_frame.copy()
        point = pieces[-1].contact_point.copy()
        for piece in pieces:
            on = piece.contact_active
            world[on] += np.einsum("ki,kij->kj", piece.contact_impulse[on],
                                   piece.contact_frame[on])
            frame[on] = piece.contact_frame[on]
            point[on] = piece.contact_point[on]
            active |= on
        impulse = np.einsum("pkij,pkj->pki", frame, world)
        stats = StepStatistics(
            solver_iterations=sum(p.solver_iterations for p in parts),
            solver_residual=max(p.solver_residual for p in parts),
            solver_converged=all(p.solver_converged for p in parts),
            active_contacts=int(active.sum()),
            activation_rounds=sum(p.activation_rounds for p in parts),
            projection_iterations=sum(p.projection_iterations for p in parts),
            projection_violation=max(p.projection_violation for p in parts),
            projection_converged=all(p.projection_converged for p in parts),
            gyroscopic_iterations=sum(p.gyroscopic_iterations for p in parts),
            solver_seconds=sum(p.solver_seconds for p in parts),
            contact_sweeps=sum(p.contact_sweeps for p in parts),
            substeps=sum(p.substeps for p in parts),
        )
        return StepResult(state, stats, impulse, frame, point, active)

    def _single_step(self, state: State, h: float, suppress: np.ndarray | None = None,
                     watch: bool = False) -> StepResult | _Crossing:
        """Steps 1-5 of the module docstring over a step of length h >= 0 [T].

        ``suppress`` (npair, K) bool: contacts the activation loop must not add. ``watch``: when
        the first activation round closes contacts that call for localisation, return a
        :class:`_Crossing` instead of finishing the step.
        """
        sys_ = self.system
        cfg = self.settings
        theta = cfg.theta
        rotation = rotation_matrices(state.p)
        nu = np.concatenate((state.v, state.omega), axis=1)  # (nb, 6)

        # 1. Free velocity.
        free, inverse, gyro_iterations = free_velocity(
            state.t + theta * h, h, theta, state.x, state.p, rotation, state.v, state.omega,
            sys_.mass, sys_.inertia, sys_.inverse_inertia, sys_.gravity, sys_.body_fixed,
            sys_.force_kind, sys_.force_body_a, sys_.force_body_b, sys_.force_parameters,
            self.angle_memory, self.has_springs, 1e-6 * cfg.length_scale, self.mass_matrix,
            self.inverse_mass, self.cluster_dofs, self.cluster_start)

        # Contacts at q_k and their normal velocities.
        cand = self._candidates(state.x, rotation)
        rule = activation_rule(cfg)
        u_start = u_free = np.zeros_like(cand[0])
        if rule in (RULE_MOREAU, RULE_PREDICTED):
            u_start = self._normal_velocity(state, rotation, cand, nu)
        if rule == RULE_PREDICTED:
            u_free = self._normal_velocity(state, rotation, cand, free)
        active = self._slots(cand, first_round(
            rule, cand[0], u_start, u_free, self.previous_impulse, h, theta,
            cfg.activation_margin, cfg.activation_hold, sys_.pair_restitution,
            cfg.restitution_threshold))

        totals = dict(iterations=0, projection_iterations=0)
        self._solver_seconds = 0.0
        self._contact_sweeps = 0
        rounds = 0
        while True:
            rounds += 1
            new_state, impulses, solve, closed = self._velocity_stage(
                state, h, rotation, nu, free, inverse, cand, active)
            projection = (0, 0.0, True)
            if cfg.projection:
                projection = self._projection_stage(new_state, active, impulses, closed)
            totals["iterations"] += solve.iterations
            totals["projection_iterations"] += projection[0]
            if not cfg.projection:
                break
            rotation_new = rotation_matrices(new_state.p)
            cand_new = self._candidates(new_state.x, rotation_new)
            closing = self._slots(cand_new, cand_new[0] <= 0.0) & ~active
            if suppress is not None:
                closing &= ~suppress
            if watch and rounds == 1 and closing.any():
                crossing = self._crossing(state, h, rotation, nu, cand, cand_new, closing)
                if crossing is not None:
                    # Work done and discarded: it counts in the cost, not in the
                    # convergence of the step.
                    abandoned = StepStatistics(
                        solver_iterations=totals["iterations"], solver_residual=0.0,
                        solver_converged=True, active_contacts=0,
                        activation_rounds=rounds,
                        projection_iterations=totals["projection_iterations"],
                        projection_violation=0.0, projection_converged=True,
                        gyroscopic_iterations=int(gyro_iterations),
                        solver_seconds=self._solver_seconds,
                        contact_sweeps=self._contact_sweeps, substeps=0)
                    return _Crossing(crossing[0], crossing[1], abandoned)
            if not closing.any() or rounds >= cfg.max_activation_rounds:
                break
            active = active | closing
        self.previous_impulse[:] = 0.0
        self.previous_impulse[active] = impulses[active]
        stats = StepStatistics(
            solver_iterations=totals["iterations"], solver_residual=float(solve.residual),
            solver_converged=bool(solve.converged), active_contacts=int(active.sum()),
            activation_rounds=rounds, projection_iterations=totals["projection_iterations"],
            projection_violation=float(projection[1]),
            projection_converged=bool(projection[2]), gyroscopic_iterations=int(gyro_iterations),
            solver_seconds=self._solver_seconds, contact_sweeps=self._contact_sweeps,
        )
        return StepResult(new_state, stats, impulses, cand[3], cand[2], active)

    def _crossing(self, state, h, rotation, nu, cand, cand_end, closing):
        """Contacts that call for localisation among ``closing`` (open at q_k, closed at the
        end of the first activation round): approaching faster than the restitution threshold
        with e > 0. Returns (crossing fraction of the earliest, (npair, K) mask of them), or
        None when there is none."""
        sys_ = self.system
        pairs, slots = np.nonzero(closing & (sys_.pair_restitution[:, None] > 0.0))
        if not len(pairs):
            return None
        # The candidate slot must be there and open at q_k (a new candidate has no start gap).
        start = cand[0][pairs, slots]
        known = np.isfinite(start) & (start > 0.0)
        pairs, slots = pairs[known], slots[known]
        if not len(pairs):
            return None
        u_start = self._normal_velocity(state, rotation, cand, nu)[pairs, slots]
        fast = u_start < -self.settings.restitution_threshold
        pairs, slots, u_start = pairs[fast], slots[fast], u_start[fast]
        if not len(pairs):
            return None
        fractions = [crossing_fraction(float(cand[0][p, s]), float(u * h),
                                       float(cand_end[0][p, s]))
                     for p, s, u in zip(pairs, slots, u_start, strict=True)]
        mask = np.zeros_like(closing)
        mask[pairs, slots] = True
        return min(fractions), mask

    # ------------------------------------------------------------------ pieces
    def _solve(self, problem: ContactProblem, r0: np.ndarray):
        """One-step problem: NSGS, Newton (regularised, then least-norm if it did not
        converge), or ``hybrid``.

        ``hybrid``: NSGS for at most ``hybrid_sweeps`` sweeps from the warm start; when it has
        not converged, semismooth Newton from where NSGS stopped, then Newton with the
        least-norm direction from there (redundant bearing rings: it converges where the
        regularised direction crawls, 7 of the 11 failed chains of c60-trip's first 6 ms), then
        Newton from the warm start, then from zero, then proximal-point Newton from the warm
        start (weight ``proximal_rescue``, 0: skipped), then NSGS for ``hybrid_last_sweeps``
        sweeps from zero and from where it stopped, keeping the first that converges (else the
        smallest residual).
        The proximal attempt comes before the two NSGS attempts because on the C-60's
        rank-deficient problems they fail where it converges, after 20,000 sweeps
        (docs/reference-solver-speed.md);
        after a step that needed Newton, the Newton that converged is tried first from the
        warm start. Every attempt runs to its cap: stopping
        the attempts early when their rate of progress could not reach the tolerance
        (``SolverOptions.stall_window``) was measured on c60-trip and dropped: 250 unconverged
        steps instead of 5, since a step whose NSGS is cut short goes through the whole chain.
        Redundant contacts (the two rings of a bearing) make W singular: NSGS crawls there and
        Newton can stall from a poor start, while another start converges in a few iterations.
        """
        cfg = self.settings
        single, newton, nsgs_first_options, nsgs, least_norm = self._solver_options
        if cfg.method != "hybrid":
            result = solve_contact_problem(problem, single, r0=r0)
            if result.converged or cfg.method != "newton":
                return result
            # Newton: the least-norm direction from the same start when the regularised one
            # did not converge (redundant contacts), the better of the two kept.
            again = solve_contact_problem(problem, least_norm, r0=r0)
            best = again if again.converged or again.residual < result.residual else result
            return replace(best, iterations=result.iterations + again.iterations)
        iterations = 0
        first = self._newton_first
        if first is not None:
            # The last problem needed Newton: consecutive steps' problems are alike (the same
            # redundant contacts), so the Newton that converged then, from the warm start,
            # first saves the NSGS sweeps that would stall again. Not converged: the usual
            # chain follows.
            best = solve_contact_problem(problem, first, r0=r0)
            if best.converged:
                return best
            iterations = best.iterations
        nsgs_first = solve_contact_problem(problem, nsgs_first_options, r0=r0)
        iterations += nsgs_first.iterations
        if nsgs_first.converged:
            self._newton_first = None
            return replace(nsgs_first, iterations=iterations)
        if first is None or nsgs_first.residual < best.residual:
            best = nsgs_first
        attempts = ((newton, nsgs_first.r), (least_norm, nsgs_first.r), (newton, r0),
                    (newton, None), (_PROXIMAL, r0), (nsgs, None), (nsgs, nsgs_first.r))
        for options, start in attempts:
            if options is _PROXIMAL:
                if cfg.proximal_rescue <= 0.0:
                    continue
                attempt = self._proximal(problem, start)
            else:
                attempt = solve_contact_problem(problem, options, r0=start)
            iterations += attempt.iterations
            if attempt.converged or attempt.residual < best.residual:
                best = attempt
            if attempt.converged:
                self._newton_first = (options if options is not _PROXIMAL
                                      and options.method == "newton" else None)
                break
        return replace(best, iterations=iterations)

    def _proximal(self, problem: ContactProblem, r0: np.ndarray | None) -> SolverResult:
        """The hybrid chain's proximal-point attempt (:func:`fc3d_proximal.proximal_newton_dense`,
        weight ``proximal_rescue``) from the warm start ``r0`` (zero when None)."""
        solver = self.settings.solver
        cap = self._solver_options[1].max_iterations  # the chain's Newton attempts' cap
        W = problem.W.toarray() if hasattr(problem.W, "toarray") else np.asarray(problem.W)
        start = np.zeros(problem.q.size) if r0 is None else r0
        r, u, iterations, residual_q, residual_max, residual, converged = proximal_newton_dense(
            W, problem.q, problem.mu, np.int64(problem.n_bilateral), start,
            float(self.settings.proximal_rescue), float(solver.tolerance),
            np.bool_(solver.use_max_normalisation), np.int64(cap),
            np.bool_(solver.roundoff_floor), float(solver.local_tolerance),
            np.int64(solver.local_max_iterations), np.empty(cap),
            np.int64(PROXIMAL_OUTER_ITERATIONS))
        return SolverResult(
            r=r, u=u, iterations=int(iterations), residual=float(residual),
            residual_q=float(residual_q), residual_max=float(residual_max),
            converged=bool(converged),
            status=SolverStatus.CONVERGED if converged else SolverStatus.MAX_ITERATIONS,
            method="proximal newton")

    def _candidates(self, x, rotation):
        """(gap, point_a, point_b, frame, count) of every pair at (x, rotation)."""
        return candidates(self.geometry, x, rotation)

    @staticmethod
    def _slots(cand, mask):
        count = cand[4]
        valid = np.arange(mask.shape[1])[None, :] < count[:, None]
        return mask & valid

    def _rows(self, t, x, p, rotation, cand, active, bilateral_at=None):
        """Bilateral rows then 3 rows per active contact (contact rows at (x, rotation), where
        the candidates were computed; bilateral rows at ``bilateral_at`` = (x, p, rotation)
        when given)."""
        sys_ = self.system
        nbil = sys_.bilateral_row_count
        # Only slots that hold a candidate at this configuration: a pair's candidate count can
        # drop between the activation and the projection (a point sliding off a bounded face),
        # and an empty slot has no point, no frame and an infinite gap.
        pairs, slots = np.nonzero(self._slots(cand, active))
        m = nbil + 3 * len(pairs)
        row_body = np.full((m, 2), -1, dtype=np.int64)
        row_coef = np.zeros((m, 2, 6))
        violation = np.zeros(m)
        target = np.zeros(m)
        if nbil:
            bx, bp, brot = bilateral_at if bilateral_at is not None else (x, p, rotation)
            bilateral_rows(t, bx, bp, brot, sys_.body_fixed, sys_.joint_kind,
                           sys_.joint_body_a, sys_.joint_body_b, sys_.joint_anchor_a,
                           sys_.joint_anchor_b, sys_.joint_frame_a, sys_.joint_axis_b,
                           sys_.joint_relative_rotation, sys_.driver_body,
                           sys_.driver_component, sys_.driver_quantity, sys_.driver_start,
                           sys_.driver_times, sys_.driver_values, sys_.driver_initial,
                           sys_.driver_reference, row_body, row_coef, violation, target)
        if len(pairs):
            contact_rows(x, rotation, sys_.body_fixed, sys_.shape_body, sys_.pair_shape_a,
                         sys_.pair_shape_b, pairs.astype(np.int64), slots.astype(np.int64),
                         cand[1], cand[2], cand[3], row_body, row_coef, nbil)
            violation[nbil:][0::3] = cand[0][pairs, slots]
        return row_body, row_coef, violation, target, pairs, slots

    def _normal_velocity(self, state, rotation, cand, nu):
        every = self._slots(cand, np.ones_like(cand[0], dtype=bool))
        out = np.zeros_like(cand[0])
        if not every.any():
            return out
        rows = self._rows(state.t, state.x, state.p, rotation, cand, every)
        nbil = self.system.bilateral_row_count
        values = row_values(rows[0], rows[1], nu, nbil, rows[0].shape[0])
        out[rows[4], rows[5]] = values[0::3]
        return out

    def _velocity_stage(self, state, h, rotation, nu, free, inverse, cand, active):
        sys_ = self.system
        cfg = self.settings
        theta = cfg.theta
        t1 = state.t + h
        pairs, slots = np.nonzero(self._slots(cand, active))
        nbil = self.n_bilateral
        m = nbil + 3 * len(pairs)
        new_nu = free.copy()
        impulses = np.zeros_like(self.previous_impulse)
        closed = np.full(active.shape, -np.inf)
        if m:
            # Joint Jacobians at the predicted configuration q_k + theta h v_k: with theta =
            # 1/2 this makes ideal joints second order in energy (at q_k the energy error is
            # O(h)). Ideal joints constrain the mid-step velocity, H_mid (theta v_{k+1} +
            # (1 - theta) v_k) = 0: with constant forces the step then conserves energy
            # exactly (v_mid . H^T lambda = 0), so the energy error of ideal joints is O(h^2)
            # instead of the O(h) loss of H v_{k+1} = 0 (docs/engines/siconos.md). In a step with
            # an impact the motion is not smooth and the mid-step prediction of the Jacobian is
            # off by O(h dv): there the joints take Moreau's law H v_{k+1} = 0, which cannot
            # create energy (it did, by 1 % on the Flores slider-crank, with the mid-step law
            # at impacts). Newton's law only for impacts faster than the threshold (see
            # settings).
            w, y, q, row_body, row_coef, _, _ = velocity_problem(
                self.geometry, nbil, nbil - sys_.driver_body.shape[0], t1, h, theta, state.x,
                state.p, state.v, state.omega, rotation, cand[1], cand[2], cand[3],
                pairs.astype(np.int64), slots.astype(np.int64), nu, free, inverse,
                self.cluster, self.cluster_dofs, self.cluster_start, sys_.pair_restitution,
                cfg.restitution_threshold, cfg.joint_law == "midpoint")
            r0 = np.concatenate((self.previous_bilateral,
                                 self.previous_impulse[pairs, slots].ravel()))
            problem = ContactProblem(w, q, sys_.pair_friction[pairs], n_bilateral=nbil)
            tick = time.perf_counter()
            solve = self._solve(problem, r0)
            self._solver_seconds += time.perf_counter() - tick
            self._contact_sweeps += solve.iterations * len(pairs)
            new_nu = free + (y @ solve.r).reshape(-1, 6)
            self.previous_bilateral = solve.r[:nbil].copy()
            impulses[pairs, slots] = solve.r[nbil:].reshape(-1, 3)
            if len(pairs):
                # Contacts that stay closed: they carry a normal impulse and their normal
                # velocity at the end of the step is (about) zero, not a rebound; each with the
                # gap up to which its slot still holds it (closed_gap_limit).
                u_new = row_values(row_body, row_coef, new_nu, nbil, m).reshape(-1, 3)
                u_start = row_values(row_body, row_coef, nu, nbil, m).reshape(-1, 3)
                normal_impulse = solve.r[nbil:][0::3]
                floor = 1e-14 * max(float(np.max(np.abs(normal_impulse))), 1e-300)
                slack = closed_gap_slack(cfg.position_tolerance, cfg.length_scale)
                for c in np.nonzero((normal_impulse > floor)
                                    & (u_new[:, 0] <= 0.5 * cfg.restitution_threshold))[0]:
                    closed[pairs[c], slots[c]] = closed_gap_limit(
                        cand[0][pairs[c], slots[c]], u_start[c], u_new[c], h, slack)
        else:
            solve = _NO_SOLVE
        new_nu[sys_.body_fixed] = 0.0
        v_theta = theta * new_nu + (1.0 - theta) * nu
        x_new = state.x + h * v_theta[:, :3]
        p_new = integrate_orientations(state.p, np.ascontiguousarray(h * v_theta[:, 3:]),
                                       sys_.body_fixed)
        new_state = State(t1, x_new, p_new, new_nu[:, :3].copy(), new_nu[:, 3:].copy())
        return new_state, impulses, solve, closed

    def _projection_stage(self, state: State, active, impulses, closed) -> tuple[int, float,
                                                                              bool]:
        """Project positions onto the joint, driver and active-contact constraints in place.

        Gauss–Newton on the constraints with the projection metric, globalised by halving the
        correction until the largest violation decreases. Contacts that carry a normal impulse
        are equalities g = 0 (eq. 21 of the study); when that set of equalities cannot be met
        (redundant contacts closed with impulse whose gaps are not compatible, as two bearing
        rings and a flange of a tilted journal can be) the projection is restarted with those
        contacts unilateral (g >= 0). If it still fails, the least violating configuration
        reached is kept, and the step is reported unconverged.

        Returns (iterations, largest remaining violation [L], converged)."""
        start_x, start_p = state.x.copy(), state.p.copy()
        iterations, worst, converged = self._project(state, active, closed)
        if converged or not np.isfinite(closed).any():
            return iterations, worst, converged
        best = (worst, state.x.copy(), state.p.copy())
        state.x[:], state.p[:] = start_x, start_p
        more, worst, converged = self._project(state, active, np.full_like(closed, -np.inf))
        iterations += more
        if not converged and best[0] < worst:
            worst = best[0]
            state.x[:], state.p[:] = best[1], best[2]
        return iterations, worst, converged

    def _violations(self, state: State, active, closed):
        """Rows of the projection at ``state``: (row_body, row_coef, values, n_equal, worst).

        Equalities first (joints, drivers, contacts that carry impulse), then the unilateral
        contact rows; ``worst`` is the largest violation [L]."""
        nbil = self.system.bilateral_row_count
        rotation = rotation_matrices(state.p)
        cand = self._candidates(state.x, rotation)
        row_body, row_coef, violation, _, pairs, slots = self._rows(
            state.t, state.x, state.p, rotation, cand, active)
        keep = np.ones(row_body.shape[0], dtype=bool)
        # Contacts: only the normal rows take part in the projection.
        if len(pairs):
            contact_part = np.zeros(3 * len(pairs), dtype=bool)
            contact_part[0::3] = True
            keep[nbil:] = contact_part
        # Eq. (21) of the study: a contact that transmits a normal impulse (P_N > 0) is
        # projected to g = 0 (an equality); the others only out of penetration (g >= 0).
        # Without it a body resting on a contact that closed within the step hovers at the
        # gap it had (the velocity stage stops it, nothing brings the gap to zero). A
        # contact whose impulse is a rebound (normal velocity > 0 at the end of the step)
        # is left unilateral: pulling a bouncing body down to g = 0 would take away the
        # potential energy of the gap at which the impact was captured. Nor is a slot whose
        # gap here exceeds its limit (``closed``: closed_gap_limit), which holds another
        # candidate than the contact that carried the impulse.
        equality = np.arange(len(keep)) < nbil
        if len(pairs):
            equality[nbil:][0::3] = cand[0][pairs, slots] <= closed[pairs, slots]
        equal = np.nonzero(keep & equality)[0]
        inequal = np.nonzero(keep & ~equality)[0]
        rows = np.concatenate((equal, inequal))
        n_equal = len(equal)
        values = violation[rows]
        equal_error = np.max(np.abs(values[:n_equal])) if n_equal else 0.0
        unilateral_error = max(0.0, -np.min(values[n_equal:])) if len(values) > n_equal \
            else 0.0
        return (np.ascontiguousarray(row_body[rows]), np.ascontiguousarray(row_coef[rows]),
                values, n_equal, max(equal_error, unilateral_error))

    def _project(self, state: State, active, closed) -> tuple[int, float, bool]:
        """Globalised Gauss–Newton projection (see :meth:`_projection_stage`), compiled
        (:func:`projection_kernel.project`) unless ``compiled_projection`` is False."""
        if not self.compiled_projection:
            return self._project_python(state, active, closed)
        iterations, worst, converged = project(
            self.geometry, self.n_bilateral, state.t, state.x, state.p, active, closed,
            self.projection_inverse, *self.single_clusters, self.settings.position_tolerance,
            self.settings.max_projection_iterations, self.settings.length_scale)
        return int(iterations), float(worst), bool(converged)

    def _project_python(self, state: State, active, closed) -> tuple[int, float, bool]:
        """:meth:`_project` in Python and numpy (the reference of the compiled kernel)."""
        sys_ = self.system
        cfg = self.settings
        row_body, row_coef, values, n_equal, worst = self._violations(state, active, closed)
        budget = correction_budget(worst, cfg.length_scale)
        for iteration in range(cfg.max_projection_iterations + 1):
            if worst <= cfg.position_tolerance or len(values) == 0:
                return iteration, worst, True
            if iteration == cfg.max_projection_iterations:
                break
            w, y = delassus(row_body, row_coef, len(values), self.projection_inverse,
                            *self.single_clusters)
            # Contacts of the active set that are open keep a zero multiplier.
            solve = solve_projection(w, values, n_equal, 0.1 * cfg.position_tolerance)
            delta = (y @ solve.delta).reshape(-1, 6)
            # Over the projection, the corrections move no point by more than the budget.
            size = correction_size(delta, cfg.length_scale)
            if size > budget:
                delta *= budget / size
                size = budget
            x0, p0 = state.x.copy(), state.p.copy()
            for _ in range(MAX_PROJECTION_HALVINGS + 1):
                state.x[:] = x0 + delta[:, :3]
                state.p[:] = integrate_orientations(p0, np.ascontiguousarray(delta[:, 3:]),
                                                    sys_.body_fixed)
                trial = self._violations(state, active, closed)
                if trial[4] < worst:
                    break
                delta *= 0.5
                size *= 0.5
            else:
                state.x[:], state.p[:] = x0, p0
                return iteration + 1, worst, False
            row_body, row_coef, values, n_equal, worst = trial
            budget -= size
            if budget <= 0.0 and worst > cfg.position_tolerance:
                return iteration + 1, worst, False
        return cfg.max_projection_iterations, worst, False


def crossing_fraction(gap_start: float, gap_rate: float, gap_end: float) -> float:
    """Fraction s in (0, 1] of a step at which a contact's gap reaches zero
    (:func:`~clearbench.ref_solver.step_kernels.crossing_fraction`, which both step loops
    call); a ValueError unless gap_start > 0 >= gap_end [L]."""
    if not (gap_start > 0.0 and gap_end <= 0.0):
        raise ValueError(f"need gap_start > 0 >= gap_end, got {gap_start!r}, {gap_end!r}")
    return float(crossing_fraction_kernel(float(gap_start), float(gap_rate), float(gap_end)))


@dataclass(frozen=True)
class _Crossing:
    """First activation round of a step that calls for impact localisation."""

    fraction: float               # crossing fraction of the earliest crossing contact
    contacts: np.ndarray          # (npair, K) bool: the contacts crossing within the step
    abandoned: StepStatistics     # the work done before the step was abandoned


@dataclass(frozen=True)
class _NoSolve:
    iterations: int = 0
    residual: float = 0.0
    converged: bool = True
    r: np.ndarray = field(default_factory=lambda: np.zeros(0))


_NO_SOLVE = _NoSolve()
