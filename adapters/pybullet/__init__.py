"""Prototype of the PyBullet engine adapter (issue 14): ``create(preset)`` and
``availability()`` as every adapter module exposes them."""

from clearbench.adapters.pybullet.engine import PRESETS, PybulletEngine, availability, create

__all__ = ["PRESETS", "PybulletEngine", "availability", "create"]
