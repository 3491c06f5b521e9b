"""What the toy does with each scene feature, one feature kind at a time (the hooks
:class:`~clearbench.adapters.base.ModuleEngine` calls with the context first)."""

from __future__ import annotations

from clearbench.adapters.base import Capability, Support

#: The plain features the toy represents, and how.
PLAIN = {
    "gravity": Capability(Support.NATIVE),
    "fixed_bodies": Capability(Support.NATIVE),
    "contacts": Capability(Support.APPROXIMATED, "penalty spring-damper: an impact lasts about "
                           "contact_steps steps; a resting body sinks g (contact_steps h / pi)^2"),
    "restitution": Capability(Support.APPROXIMATED, "linear damper matched to e for a two-sided "
                              "oscillator; the force clamped at 0 bounces a little higher"),
    "friction": Capability(Support.APPROXIMATED, "regularised Coulomb: viscous below mu N, so a "
                           "body that must stick creeps"),
}


def plain_capability(context, name: str) -> Capability:
    return PLAIN.get(name) or Capability(
        Support.UNSUPPORTED, f"the toy engine has free bodies, gravity and sphere-plane "
        f"contacts only (no {name})")


def shape_capability(context, kind: str) -> Capability:
    if kind in ("sphere", "plane"):
        return Capability(Support.NATIVE)
    return Capability(Support.UNSUPPORTED, f"no {kind} shape (spheres and planes only)")


def joint_capability(context, kind: str) -> Capability:
    return Capability(Support.UNSUPPORTED, "no ideal joints")


def pair_capability(context, kind_a: str, kind_b: str) -> Capability:
    if (kind_a, kind_b) == ("plane", "sphere"):
        return PLAIN["contacts"]
    return Capability(Support.UNSUPPORTED, f"no {kind_a}-{kind_b} contact (sphere-plane only)")
