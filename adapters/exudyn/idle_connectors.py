"""Idle contact connectors switched off between steps (option ``cull_idle_connectors``).

Exudyn evaluates every active connector in every Newton residual and differentiates it in every
Jacobian, touching or not (docs/engines/exudyn.md, "Where a step's time goes": the C-60's 1298
connectors are most of a step's cost). A connector whose gap stays positive through a step adds
exactly zero to the residual and to the Jacobian, and Exudyn skips an inactive connector
(``activeConnector = False``) in both. Before every step (a PreStep user function) this module
switches off each connector whose gap at the step's start exceeds a margin larger than what the
pair can close in two steps, and switches it back on as soon as it is within the margin; so a
connector is always active during the step in which it could touch, and during the step before.

Why the results do not change: an idle connector's contribution is zero (+0.0 added to a sum
leaves it as it was), and the connector's stored data (its gap at the last step, read by Exudyn
to decide contact and to time the switch) stays positive while it is off, as it would be fresh:
switched on at least one step before it can touch, it is fresh again when it matters. The
margin is checked after the fact: an inactive connector found, one step later, within half of
the margin it was switched off with (it closed more than twice the motion the margin allows
per step) is counted (``margin_breaches``, with examples), never hidden.

The gap of a connector is bounded from below, cheaply and for every connector at once:

- sphere against sphere: the exact gap ``|c1 - c0| - r0 - r1``; inside a hollow sphere
  ``r1 - |c1 - c0| - r0``;
- sphere against a triangle: the larger of ``|c0 - m| - R - r0`` (``m`` the triangle's
  centroid, ``R`` the distance of its farthest corner from ``m``: the triangle lies inside that
  ball) and ``|n . (c0 - m)| - r0`` (``n`` the triangle's unit normal: the triangle lies in its
  plane).

The margin [L] over one step of length h [T]: ``4 h V + 2 a h^2``, with V the largest point
speed of any moving body at the step's start (the speed of its centre of mass plus its angular
speed times the farthest connector point of that body from it, a bound on any
connector's closing speed within one body pair, taken over all bodies so that a body at rest
about to be struck is covered by the striker's speed), the factor 4 for two steps' motion and
the speed doubling in an impact, and ``a`` the applied-force scale over the lightest moving
body's mass (a body at rest that starts to move).
"""

from __future__ import annotations

from dataclasses import dataclass, field

import numpy as np

from clearbench.adapters.exudyn.geometry import PairPlan
from clearbench.kernels.jit import njit
from clearbench.scenarios.scene import Scene

#: Steps' worth of closing motion covered by the margin (two steps) times the growth of a
#: speed within a step (an impact at most doubles a closing speed, restitution <= 1).
MOTION_STEPS = 4.0

#: Fewest connectors for which option 'auto' switches idle ones off: below it the check
#: (tens of microseconds per step) costs more than Exudyn spends on the idle connectors
#: (stepping time with / without, tools/exudyn_idle_connectors.py: 8 connectors 1.36, 74
#: connectors 0.82, 208 and 288 connectors 0.62-0.70, the C-60's 1298 0.12;
#: docs/engines/exudyn.md).
MIN_CONNECTORS = 64

#: Part of the margin below which an inactive connector counts as a breach (it closed more
#: than half the margin in one step: the bound was not conservative there).
BREACH_FRACTION = 0.5


def culling_wanted(choice: str, connectors: int) -> bool:
    """Whether option ``cull_idle_connectors`` = ``choice`` ('auto', 'on', 'off') switches
    idle connectors off in a system of ``connectors`` connectors."""
    if choice == "auto":
        return connectors >= MIN_CONNECTORS
    return choice == "on" and connectors > 0


@dataclass
class IdleConnectors:
    """The connectors' geometry in their bodies' frames and which are switched off.

    Attributes
    ----------
    objects : (nc,) int
        Exudyn object numbers.
    body_a, body_b : (nc,) int
        Scene body index of the sphere's body and of the partner's.
    point_a, point_b : (nc, 3) float
        Sphere centre in body a's frame; partner sphere centre or triangle centroid in body
        b's frame [L].
    radius_a : (nc,) float
        Sphere radius [L].
    radius_b : (nc,) float
        Partner sphere radius, or the triangle's bounding radius about its centroid [L].
    hollow : (nc,) bool
        The partner is a hollow sphere (the sphere moves inside it).
    normal_b : (nc, 3) float
        Triangle's unit normal in body b's frame; zero for a partner sphere.
    lever : (nb,) float
        Largest distance of any connector point of a body (plus its radius) from the body's
        centre of mass [L]; 0 for bodies without connectors.
    active : (nc,) bool
        Current ``activeConnector`` of each connector.
    switches, checks, active_sum : int, int, float
        Connectors switched on or off, checks made (one per Exudyn step) and the sum of the
        active counts over the checks (the mean active fraction of :meth:`statistics`).
    margin_breaches, breach_examples : int, list of str
        Breaches of the margin (module docstring) and the first five, described.
    last_margin : float
        The margin of the last check [L]; ``margins``: every finite margin so far [L].
    """

    objects: np.ndarray
    body_a: np.ndarray
    body_b: np.ndarray
    point_a: np.ndarray
    point_b: np.ndarray
    radius_a: np.ndarray
    radius_b: np.ndarray
    hollow: np.ndarray
    normal_b: np.ndarray
    lever: np.ndarray
    active: np.ndarray
    switches: int = 0
    margin_breaches: int = 0
    active_sum: float = 0.0
    checks: int = 0
    last_margin: float = 0.0
    margins: list = field(default_factory=list)
    breach_examples: list[str] = field(default_factory=list)

    @classmethod
    def from_plans(cls, scene: Scene, plans: list[PairPlan], objects: list[int],
                   com: np.ndarray) -> IdleConnectors:
        """From the contact plans in build order (one object number per connector) and the
        bodies' centres of mass (nb, 3) in their frames [L]."""
        body_a, body_b, point_a, point_b, radius_a, radius_b = [], [], [], [], [], []
        hollow, normal_b = [], []
        for plan in plans:
            for connector in plan.connectors:
                body_a.append(scene.body_index(connector.sphere_body))
                body_b.append(scene.body_index(connector.other_body))
                point_a.append(connector.sphere_point)
                radius_a.append(connector.sphere_radius)
                hollow.append(bool(connector.hollow))
                if connector.kind == "sphere_sphere":
                    point_b.append(connector.other_point)
                    radius_b.append(connector.other_radius)
                    normal_b.append(np.zeros(3))
                else:
                    corners = np.asarray(connector.triangle, dtype=float)
                    centroid = corners.mean(axis=0)
                    point_b.append(centroid)
                    radius_b.append(float(np.max(np.linalg.norm(corners - centroid, axis=1))))
                    normal = np.cross(corners[1] - corners[0], corners[2] - corners[0])
                    normal_b.append(normal / np.linalg.norm(normal))
        count = len(body_a)
        if count != len(objects):
            raise ValueError(f"{len(objects)} connector objects for {count} planned connectors")
        body_a, body_b = np.asarray(body_a, dtype=int), np.asarray(body_b, dtype=int)
        point_a = np.asarray(point_a, dtype=float).reshape(count, 3)
        point_b = np.asarray(point_b, dtype=float).reshape(count, 3)
        radius_a = np.asarray(radius_a, dtype=float)
        radius_b = np.asarray(radius_b, dtype=float)
        lever = np.zeros(len(scene.bodies))
        for body, point, radius in ((body_a, point_a, radius_a), (body_b, point_b, radius_b)):
            reach = np.linalg.norm(point - com[body], axis=1) + radius
            np.maximum.at(lever, body, reach)
        return cls(np.asarray(objects, dtype=int), body_a, body_b, point_a, point_b, radius_a,
                   radius_b, np.asarray(hollow, dtype=bool),
                   np.asarray(normal_b, dtype=float).reshape(count, 3), lever,
                   np.ones(count, dtype=bool))

    def gap_bounds(self, position: np.ndarray, rotation: np.ndarray) -> np.ndarray:
        """Lower bounds of the connectors' gaps (nc,) [L] at body origins ``position`` (nb, 3)
        and rotations ``rotation`` (nb, 3, 3, body to world)."""
        return gap_bounds(position, rotation, self.body_a, self.point_a, self.radius_a,
                          self.body_b, self.point_b, self.radius_b, self.hollow, self.normal_b)

    def margin(self, velocity: np.ndarray, omega: np.ndarray, acceleration: float,
               step: float) -> float:
        """Margin [L] for a step of ``step`` [T] (module docstring): ``velocity`` (nb, 3)
        centre-of-mass velocities [L/T], ``omega`` (nb, 3) angular velocities [1/T],
        ``acceleration`` the applied-force scale over the lightest moving mass [L/T^2]."""
        speed = np.linalg.norm(velocity, axis=1) + np.linalg.norm(omega, axis=1) * self.lever
        return MOTION_STEPS * step * float(np.max(speed, initial=0.0)) \
            + 2.0 * acceleration * step * step

    def update(self, position: np.ndarray, rotation: np.ndarray, margin: float,
               time: float) -> np.ndarray:
        """Decide which connectors are on for the next step; returns the indices (into the
        connector arrays) whose state changed. Counts inactive connectors found within
        ``BREACH_FRACTION`` of the previous step's margin (the bound failed) as breaches."""
        gap = self.gap_bounds(position, rotation)
        if self.checks == 0:
            # Exudyn's stored gaps start at 0 ("touching"): a connector switched on again
            # with that stored gap would flag a contact switch (a repeated discontinuous
            # iteration, same result). Every connector is evaluated in the first step.
            margin = np.inf
        breached = ~self.active & (gap <= BREACH_FRACTION * self.last_margin)
        if breached.any():
            self.margin_breaches += int(breached.sum())
            if len(self.breach_examples) < 5:
                worst = int(np.argmin(np.where(breached, gap, np.inf)))
                self.breach_examples.append(
                    f"t = {time:.6g}: connector {int(self.objects[worst])} inactive at gap "
                    f"bound {gap[worst]:.3g}, switched off at margin {self.last_margin:.3g}")
        wanted = gap <= margin
        changed = np.flatnonzero(wanted != self.active)
        self.active = wanted
        self.last_margin = margin
        if np.isfinite(margin):
            self.margins.append(margin)
        self.switches += len(changed)
        self.active_sum += float(np.count_nonzero(wanted))
        self.checks += 1
        return changed

    def statistics(self) -> dict:
        """Mean active fraction, switches and margin breaches of the run (metadata)."""
        count = len(self.objects)
        mean = self.active_sum / self.checks / count if self.checks and count else 1.0
        margins = np.asarray(self.margins)
        return {"connectors": count, "mean_active_fraction": mean, "switches": self.switches,
                "checks": self.checks,
                "margin_median": float(np.median(margins)) if margins.size else None,
                "margin_max": float(np.max(margins)) if margins.size else None,
                "margin_breaches": self.margin_breaches,
                "breach_examples": list(self.breach_examples)}


# ---------------------------------------------------------------------------- kernels
# Compiled: it runs before every Exudyn step, whose own cost on the library scenes is tens of
# microseconds.
@njit(cache=True)
def gap_bounds(position, rotation, body_a, point_a, radius_a, body_b, point_b, radius_b,
               hollow, normal_b):
    """Lower bounds of the connectors' gaps (nc,) [L] (:meth:`IdleConnectors.gap_bounds`;
    arrays as its attributes, ``position`` (nb, 3), ``rotation`` (nb, 3, 3))."""
    count = body_a.shape[0]
    out = np.empty(count)
    for c in range(count):
        a, b = body_a[c], body_b[c]
        offset = np.empty(3)
        plane = 0.0
        for i in range(3):
            centre_a = position[a, i]
            centre_b = position[b, i]
            for j in range(3):
                centre_a += rotation[a, i, j] * point_a[c, j]
                centre_b += rotation[b, i, j] * point_b[c, j]
            offset[i] = centre_a - centre_b
        distance = np.sqrt(offset[0] ** 2 + offset[1] ** 2 + offset[2] ** 2)
        if hollow[c]:
            out[c] = radius_b[c] - distance - radius_a[c]
            continue
        for i in range(3):
            normal = 0.0
            for j in range(3):
                normal += rotation[b, i, j] * normal_b[c, j]
            plane += normal * offset[i]
        out[c] = max(distance - radius_b[c], abs(plane)) - radius_a[c]
    return out
