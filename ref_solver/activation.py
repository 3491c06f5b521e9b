"""The contacts a step starts with: the first activation round's index set.

Three rules, shared by the Python stepper (:mod:`.stepper`) and the compiled step
(:mod:`.compiled.step`); a contact is a slot (pair i, candidate k) of the candidates at q_k.

- ``gap`` (the study's combined projection, the default): the contacts closed at q_k,
  g <= margin. Contacts that close within the step are found at its end and the step is redone
  with them (the activation loop, eq. 22 of the study).
- ``held``: those, and the contacts that carried a normal impulse in the previous step and
  are open by at most the hold margin (hysteresis, as the study's own code: Siconos's mechanics
  toolbox, ``MBTB_MoreauJeanOSI``, keeps a contact in its index set until it is open by more
  than a deactivation threshold). A held contact that the step leaves open carries no impulse
  (its velocity-level law holds with r_N = 0), or, if it approaches, is stopped while still open
  by at most its gap: at most the hold margin. On the C-60 these are the contacts of the
  clearance joints that reopen by round-off and close again within the next step, which the
  ``gap`` rule finds only at the step's end and solves the step again for.
- ``predicted``: those of ``held``, and the contacts that the free motion would close within
  the step, g + h (theta u_free + (1 - theta) u_k) <= margin, with u_k the normal velocity at
  the step's start and u_free at the free velocity (no contact impulse). Contacts that approach
  faster than the restitution threshold with e > 0 are not added: they are the impacts that
  impact localisation (``localise_impacts``) splits the step at, which it finds in the first
  round's closing contacts. A predicted contact's velocity-level law forbids any approach while
  it is still open, also an approach the step's true motion would not complete: on
  hoop-off-edge (a hoop tipping over a table's edge) its path leaves the exact pivot by 20 % of
  the hoop's radius (0.7 % with ``gap``). Kept as a measured variant, not a recommended rule.
- ``moreau`` (plain Moreau–Jean, without the projection): Moreau's prediction
  g + (h / 2) u_k <= margin.
"""

from __future__ import annotations

import numpy as np
from numba import njit

#: Rule codes of :func:`first_round`.
RULE_GAP, RULE_PREDICTED, RULE_MOREAU, RULE_HELD = 0, 1, 2, 3
#: The rules a user names (``moreau`` is the rule of the scheme without projection).
RULES = {"gap": RULE_GAP, "held": RULE_HELD, "predicted": RULE_PREDICTED}


@njit(cache=True)
def first_round(rule, gap, u_start, u_free, previous, h, theta, margin, hold, restitution,
                threshold):
    """(npair, K) bool: the contacts active from the step's start under ``rule``.

    ``gap`` (npair, K) [L] at q_k (+inf or NaN in empty slots: never active); ``u_start``,
    ``u_free`` (npair, K) [L/T] normal velocities at the start of the step and at the free
    velocity (read only by the rules that predict); ``previous`` (npair, K, 3) [F T] the
    impulses of the previous step in the contact frames (normal first); ``h`` [T]; ``margin``
    [L] the activation margin; ``hold`` [L] the hold margin (``held``, ``predicted``);
    ``restitution`` (npair,) the pairs' e; ``threshold`` [L/T] the restitution threshold
    (approaches slower than it are plastic).
    """
    active = gap <= margin
    if rule == RULE_MOREAU:
        return gap + 0.5 * h * u_start <= margin
    if rule == RULE_GAP:
        return active
    for i in range(gap.shape[0]):
        elastic = restitution[i] > 0.0
        for k in range(gap.shape[1]):
            if active[i, k] or not np.isfinite(gap[i, k]):
                continue
            if previous[i, k, 0] > 0.0 and gap[i, k] <= hold:
                active[i, k] = True
                continue
            if rule == RULE_HELD:
                continue
            if elastic and u_start[i, k] < -threshold:
                continue
            predicted = gap[i, k] + h * (theta * u_free[i, k] + (1.0 - theta) * u_start[i, k])
            active[i, k] = predicted <= margin
    return active


def activation_rule(settings) -> int:
    """The rule code of a :class:`~clearbench.ref_solver.stepper.StepperSettings`: Moreau's
    prediction without the projection, ``settings.activation`` with it."""
    return RULES[settings.activation] if settings.projection else RULE_MOREAU
