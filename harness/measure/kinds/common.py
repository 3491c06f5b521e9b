"""Helpers the figure handlers of several kinds share: centre-of-mass paths, heights, the
slope of an incline, and the rest-speed threshold."""

from __future__ import annotations

import numpy as np

from clearbench.harness.measure import series as metrics
from clearbench.kernels.quaternion import quat_rotate_batch

#: A body counts as stopped (``sliding_stop``) or rolling (``rolling_transition``) once its
#: speed, or its contact point's slip speed, is at most this fraction of the expectation's
#: initial speed v0. The deceleration is constant (mu g; 7/2 mu g for the slip), so the
#: threshold is met a fraction 1e-3 of the event time early: 0.1 %, 20 times below the 2 %
#: criteria. A compliant engine's residual speed at rest (soft or regularised friction) is
#: of order 1 mm/s or less, below the library's 2 mm/s (v0 = 2 m/s), where a threshold of
#: 1e-9 v0 was never met by such an engine, or only long after the stop.
REST_SPEED_FRACTION = 1e-3


def centre_of_mass(scene, trajectory, body: str) -> np.ndarray:
    """Centre-of-mass positions of ``body`` over the samples, (n, 3) [L]."""
    return metrics.centre_of_mass_positions(scene, trajectory)[:, scene.body_index(body)]


def height(scene, trajectory, body: str) -> np.ndarray:
    """Height of the centre of mass along -gravity, (n,) [L]."""
    g = np.asarray(scene.gravity, dtype=float)
    up = -g / np.linalg.norm(g)
    return centre_of_mass(scene, trajectory, body) @ up


def slope_direction(scene, body: str) -> np.ndarray:
    """Down-slope unit vector (3,): gravity's component along the plane that ``body`` touches
    (the normal of the last contact partner's frame z axis)."""
    g = np.asarray(scene.gravity, dtype=float)
    normal = None
    for contact in scene.contacts:
        if body in (contact.body_a, contact.body_b):
            ground = contact.body_a if contact.body_b == body else contact.body_b
            q = np.asarray(scene.body(ground).orientation, dtype=float)
            normal = quat_rotate_batch(q / np.linalg.norm(q), np.array([0.0, 0.0, 1.0]))
    tangential = g - (g @ normal) * normal
    return tangential / np.linalg.norm(tangential)
