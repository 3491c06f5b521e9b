"""Data types of the one-step frictional contact problem: problem, options, result, status.

The problem (one time step of the Moreau–Jean scheme, at impulse level) is the discrete 3D
Coulomb frictional contact problem of FCLIB/Siconos, extended with bilateral (equality) rows:

    u = W r + q,
    u_b = 0                                  for the n_bilateral first rows (r_b free),
    K_i* ∋ u_i + [mu_i |u_Ti|, 0, 0]  ⊥  r_i ∈ K_i = {|r_T| <= mu_i r_N}   for each contact i,

with each contact a block of 3 rows ordered (N, T1, T2). The unknown r is an impulse and u a
relative velocity, in whatever consistent units the caller uses: W is in (velocity / impulse),
q in velocity units. Every tolerance here is relative, so the problem may be given in any units.

The solvers live in :mod:`fc3d_nsgs` and :mod:`fc3d_newton`; the dispatcher
:func:`clearbench.ref_solver.fc3d_solve.solve_contact_problem` picks one from
:class:`SolverOptions`.
"""

from __future__ import annotations

import enum
import functools
from collections.abc import Callable
from dataclasses import dataclass, field
from typing import TypeVar

import numpy as np
import scipy.sparse as sp
from numba import njit


class SolverStatus(enum.Enum):
    """How a solve ended. Only ``CONVERGED`` means the tolerance was met."""

    CONVERGED = "converged"
    MAX_ITERATIONS = "max_iterations"  # iteration cap reached before the tolerance
    STALLED = "stalled"  # Newton: no descent step could be found (line search failed)
    NUMERICAL_FAILURE = "numerical_failure"  # NaN/inf appeared, or a singular system


class Normalisation(enum.Enum):
    """Normalisation of the natural-map residual |F(r)| (2-norm over all rows).

    ``Q``: |F| / |q| (Acary, Brémond & Huber 2018 comparison paper).
    ``MAX``: |F| / max(|q|, |r|, |u|) (Siconos's ``fc3d_compute_error`` since 4.x).
    If the denominator is zero (q = 0 and r = u = 0, or q = 0 for ``Q``), |F| is returned as is:
    with q = 0 the solution is r = 0, F = 0, so this only matters for a non-solution.
    """

    Q = "q"
    MAX = "max"


METHODS = ("nsgs", "newton")
NEWTON_DIRECTIONS = ("regularised", "least_norm")


@njit(cache=True)
def _dense_to_csr(W):
    """CSR arrays (data, indices, indptr) of the non-zeros of a dense matrix."""
    m, n = W.shape
    count = 0
    for i in range(m):
        for j in range(n):
            if W[i, j] != 0.0:
                count += 1
    data = np.empty(count)
    indices = np.empty(count, dtype=np.int32)
    indptr = np.zeros(m + 1, dtype=np.int32)
    k = 0
    for i in range(m):
        for j in range(n):
            if W[i, j] != 0.0:
                data[k] = W[i, j]
                indices[k] = j
                k += 1
        indptr[i + 1] = k
    return data, indices, indptr
LOCAL_SOLVERS = ("ac", "fb", "projection")

_Derived = TypeVar("_Derived")


def _as_matrix(W) -> np.ndarray | sp.csr_matrix:
    """Return W as a float64 C-contiguous ndarray or a float64 CSR matrix."""
    if sp.issparse(W):
        return sp.csr_matrix(W, dtype=np.float64)
    return np.ascontiguousarray(W, dtype=np.float64)


@dataclass(frozen=True, eq=False)
class ContactProblem:
    """One-step frictional contact problem with optional bilateral rows.

    Parameters
    ----------
    W : ndarray or scipy.sparse matrix, shape (m, m)
        Delassus operator (velocity per impulse). Need not be symmetric.
    q : ndarray, shape (m,)
        Free relative velocity (velocity units).
    mu : ndarray, shape (nc,)
        Friction coefficients (>= 0), one per contact.
    n_bilateral : int
        Number of leading equality rows (r free, u = 0).

    ``m == n_bilateral + 3 * nc`` is checked. Arrays are converted to float64 copies.
    """

    W: np.ndarray | sp.csr_matrix
    q: np.ndarray
    mu: np.ndarray
    n_bilateral: int = 0

    def __post_init__(self) -> None:
        W = _as_matrix(self.W)
        q = np.array(self.q, dtype=np.float64).ravel()
        mu = np.array(self.mu, dtype=np.float64).ravel()
        n_bilateral = int(self.n_bilateral)
        if W.ndim != 2 or W.shape[0] != W.shape[1]:
            raise ValueError(f"W must be square, got shape {W.shape}")
        m = W.shape[0]
        if q.shape != (m,):
            raise ValueError(f"q must have shape ({m},), got {q.shape}")
        if n_bilateral < 0 or n_bilateral > m:
            raise ValueError(f"n_bilateral must be in [0, {m}], got {n_bilateral}")
        if 3 * mu.size + n_bilateral != m:
            raise ValueError(
                f"size mismatch: m = {m} but n_bilateral + 3 * len(mu) = "
                f"{n_bilateral} + 3 * {mu.size}"
            )
        if np.any(~np.isfinite(mu)) or np.any(mu < 0.0):
            raise ValueError("mu must be finite and >= 0")
        if not np.all(np.isfinite(q)):
            raise ValueError("q contains NaN or inf")
        values = W.data if sp.issparse(W) else W
        if not np.all(np.isfinite(values)):
            raise ValueError("W contains NaN or inf")
        object.__setattr__(self, "W", W)
        object.__setattr__(self, "q", q)
        object.__setattr__(self, "mu", mu)
        object.__setattr__(self, "n_bilateral", n_bilateral)

    @property
    def size(self) -> int:
        """Number of rows m."""
        return self.q.size

    @property
    def n_contacts(self) -> int:
        """Number of frictional contacts nc."""
        return self.mu.size

    @functools.cached_property
    def _csr(self) -> sp.csr_matrix:
        if sp.issparse(self.W):
            return self.W
        return sp.csr_matrix(self._csr_arrays, shape=self.W.shape)

    @functools.cached_property
    def _csr_arrays(self) -> tuple[np.ndarray, np.ndarray, np.ndarray]:
        if sp.issparse(self.W):
            return self.W.data, self.W.indices, self.W.indptr
        # Compiled conversion: scipy's csr_matrix(dense) costs ~100 us for small matrices,
        # more than a whole NSGS solve of a few contacts (and even wrapping the arrays in a
        # csr_matrix costs tens of us: the compiled solvers take the arrays).
        return _dense_to_csr(self.W)

    def W_csr_arrays(self) -> tuple[np.ndarray, np.ndarray, np.ndarray]:
        """(data, indices, indptr) of W in CSR form; computed once. Do not modify."""
        return self._csr_arrays

    @functools.cached_property
    def _dense(self) -> np.ndarray:
        return self.W.toarray() if sp.issparse(self.W) else self.W

    def W_csr(self) -> sp.csr_matrix:
        """W as CSR (explicit zeros of a dense W dropped); computed once. Do not modify."""
        return self._csr

    def W_dense(self) -> np.ndarray:
        """W as a dense ndarray; computed once. Do not modify."""
        return self._dense

    def velocity(self, r: np.ndarray) -> np.ndarray:
        """u = W r + q, shape (m,)."""
        return self.W @ r + self.q

    @functools.cached_property
    def _derived(self) -> dict:
        return {}

    def derived(self, key: str, compute: Callable[[ContactProblem], _Derived]) -> _Derived:
        """``compute(self)``, evaluated once per problem and ``key`` (a solver's per-problem data).

        For data that depends only on the problem (e.g. the inverse of the bilateral block of
        W), so that several solves of one problem (the stepper's hybrid strategy tries NSGS,
        then Newton from several starts) share it. The problem's arrays must not be modified.
        """
        cache = self._derived
        if key not in cache:
            cache[key] = compute(self)
        return cache[key]

    def forget_derived(self) -> None:
        """Drop everything :meth:`derived` cached (benchmarks time a solve from scratch)."""
        self.__dict__.pop("_derived", None)


@dataclass(frozen=True)
class SolverOptions:
    """Options of :func:`solve_contact_problem`.

    Parameters
    ----------
    method : {"nsgs", "newton"}
        Nonsmooth Gauss–Seidel over contacts, or semismooth Newton (Alart–Curnier) on all rows.
    tolerance : float
        Stop when the natural-map residual, normalised by ``normalisation``, is <= tolerance.
    normalisation : {"max", "q"}
        ``"max"`` (default): |F| / max(|q|, |r|, |u|), Siconos's measure; it stays meaningful
        when |q| is tiny against |r| (resting contacts whose impulses only balance gravity) and
        is what Siconos's own stopping test uses, so timings compare like with like.
        ``"q"``: |F| / |q|, the measure of the 2018 FCLIB comparison paper (stricter when
        |r| or |u| >> |q|).
    max_iterations : int
        Cap on sweeps (NSGS) or Newton iterations. Reaching it returns converged=False.
    local_solver : {"ac", "fb", "projection"}
        NSGS only. "ac": exact local solve by a damped Newton on the Alart–Curnier function,
        with a projection fixed-point fall-back; "fb": the same with the Fischer–Burmeister
        function; "projection": a single projection step per contact (no local iteration).
    local_tolerance : float
        Relative tolerance of the local solves (on |F_local| / max(|q_loc|, |r_i|, |u_i|)).
    local_max_iterations : int
        Cap on local Newton iterations per contact and sweep.
    residual_check_interval : int
        NSGS: the full residual (one product W r) is evaluated every this many sweeps and on
        the last one.
    roundoff_floor : bool
        Also accept a residual above ``tolerance`` when it is below the bound on its own
        rounding error (:func:`fc3d_residual.roundoff_floor`): at such an r the computed
        residual cannot be told from that of the exact solution. The result says so in its
        ``message``. Off by default (the FCLIB comparisons use Siconos's plain test); the
        reference stepper turns it on, since its tolerance (1e-12) sits near that bound on
        ill-conditioned problems (redundant bearing rings: cond(W) ~ 1e19).
    stall_window : int
        0 (default): iterate up to ``max_iterations``. n > 0: stop early, as ``STALLED``, when
        the residual's mean rate of decrease over the last n checks (NSGS) or iterations
        (Newton), if kept up, would not reach the tolerance within the iterations left
        (:func:`fc3d_residual.hopeless`). A solve stopped so could at best have converged by a
        late acceleration. Off by default, and not used by the reference stepper: its hybrid
        chain runs every attempt to its cap (cutting NSGS short was measured on c60-trip and
        dropped; see :meth:`MoreauJeanStepper._solve`).
    newton_direction : {"regularised", "least_norm"}
        Newton only. "regularised": (J + delta I) d = -Phi, delta from the residual;
        "least_norm": the minimum-norm least-squares solution of J d = -Phi (dense, compiled),
        which converges where redundant contacts make J singular and the regularised direction
        crawls (:func:`fc3d_newton_dense.least_norm_direction`).
    stall_after : int
        No early stop before this many checks (NSGS) or iterations (Newton): NSGS may sit on a
        plateau for hundreds of sweeps until the contact statuses settle, then converge at
        once (the clearance pendulum: flat at 7e-4 for 200 sweeps, converged after 430-658).
    """

    method: str = "nsgs"
    tolerance: float = 1e-10
    normalisation: str = "max"
    max_iterations: int = 10_000
    local_solver: str = "ac"
    local_tolerance: float = 1e-14
    local_max_iterations: int = 30
    residual_check_interval: int = 1
    roundoff_floor: bool = False
    stall_window: int = 0
    stall_after: int = 0
    newton_direction: str = "regularised"

    def __post_init__(self) -> None:
        if self.method not in METHODS:
            raise ValueError(f"method must be one of {METHODS}, got {self.method!r}")
        if self.newton_direction not in NEWTON_DIRECTIONS:
            raise ValueError(f"newton_direction must be one of {NEWTON_DIRECTIONS}, got "
                             f"{self.newton_direction!r}")
        if self.local_solver not in LOCAL_SOLVERS:
            raise ValueError(
                f"local_solver must be one of {LOCAL_SOLVERS}, got {self.local_solver!r}"
            )
        Normalisation(self.normalisation)
        if not self.tolerance > 0.0:
            raise ValueError(f"tolerance must be > 0, got {self.tolerance}")
        if self.max_iterations < 1:
            raise ValueError(f"max_iterations must be >= 1, got {self.max_iterations}")
        if self.stall_window < 0 or self.stall_after < 0:
            raise ValueError(f"stall_window and stall_after must be >= 0, got "
                             f"{self.stall_window} and {self.stall_after}")
        if self.local_max_iterations < 1 or self.residual_check_interval < 1:
            raise ValueError("local_max_iterations and residual_check_interval must be >= 1")

    @functools.cached_property
    def use_max_normalisation(self) -> bool:
        """True for the "max" normalisation, False for "q" (computed once per options)."""
        return Normalisation(self.normalisation) is Normalisation.MAX


@dataclass(frozen=True, eq=False, init=False)
class SolverResult:
    """Outcome of a contact solve.

    Attributes
    ----------
    r : ndarray, shape (m,)
        Impulses (bilateral rows first, then (N, T1, T2) per contact).
    u : ndarray, shape (m,)
        Relative velocities u = W r + q.
    iterations : int
        Sweeps (NSGS) or Newton iterations done.
    residual : float
        Natural-map residual in the normalisation of the options (the one tested).
    residual_q, residual_max : float
        The same residual in both normalisations (|F|/|q| and |F|/max(|q|,|r|,|u|)).
    converged : bool
        residual <= tolerance.
    status : SolverStatus
    method : str
        Solver used, e.g. "nsgs-ac", "newton-ac".
    message : str
        Human-readable detail on a failure.
    local_failures : int
        NSGS: local solves that ended above the local tolerance (last sweep).
    history : ndarray
        Normalised residual at each check (NSGS) or Newton iteration.
    """

    r: np.ndarray
    u: np.ndarray
    iterations: int
    residual: float
    residual_q: float
    residual_max: float
    converged: bool
    status: SolverStatus
    method: str
    message: str = ""
    local_failures: int = 0
    history: np.ndarray = field(default_factory=lambda: np.zeros(0))

    def __init__(
        self, r: np.ndarray, u: np.ndarray, iterations: int, residual: float, residual_q: float,
        residual_max: float, converged: bool, status: SolverStatus, method: str,
        message: str = "", local_failures: int = 0, history: np.ndarray | None = None,
    ) -> None:
        # Hand-written: the generated frozen __init__ sets each of the 12 fields through
        # object.__setattr__ (about 2 us), more than a whole NSGS solve of one contact. The
        # instance stays frozen (assignment raises FrozenInstanceError).
        fields = self.__dict__
        fields["r"] = r
        fields["u"] = u
        fields["iterations"] = iterations
        fields["residual"] = residual
        fields["residual_q"] = residual_q
        fields["residual_max"] = residual_max
        fields["converged"] = converged
        fields["status"] = status
        fields["method"] = method
        fields["message"] = message
        fields["local_failures"] = local_failures
        fields["history"] = np.zeros(0) if history is None else history
