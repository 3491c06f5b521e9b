"""The C-60 model's documented alternatives as named, validated parameters.

The source (``plugins/plugin1.cpp`` of the Siconos example, see ``data/README.md``) carries,
in comments beside the values it uses, the values of other versions of its laws:

* contact-pressure law ``M = 244.46 (D + preload)``, ``D = theta_mc - theta_plate - offset``:
  ``preload`` 0.49 rad (used), 0.6547 and 0.9599 rad (comment after it), 0.5236 rad (a
  commented-out block); ``offset`` -(54.54 + 22.0) deg (used), "(-69+2)" = -67 deg and
  "FvsD -78.5+2" = -76.5 deg (comment on the line; FvsD reads as the force-displacement test);
* the force of that law on the moving contact, ``M / lever``: 6.06 mm (used), "4.84(old plugin
  value validated)", "7.99 new value";
* its force on the plate, ``M / lever``: 5.48 mm (used, "updated 26 May 2015"), "5(old plugin
  value validated)".

The handle spring's point of application (``handle_spring_arm``, ``source`` or ``design``) and
the latch's edge (``latch_edge``, :data:`LATCH_EDGES`) are described in :mod:`.model`. Friction
is given per contact class (:data:`CONTACT_CLASSES`): the source's values (0.2 on the
hook/tripping-bar latch C4 and the needle bearing S3, 0.1 elsewhere), or ``paper-table-4``:
each pair at the paper's Table 4 value for its two materials (plastic/plastic 0.3,
metal/plastic 0.1), the materials established in :data:`PART_MATERIALS`. Table 4 gives no
metal/metal value: the one metal/metal pair (C7, the two electrical contacts)
keeps the source's 0.1.

:func:`model_parameters` resolves a named variant (:data:`VARIANTS`) plus explicit overrides
into a :class:`ModelParameters`, and refuses a bad value naming the field before any scene is
built. The defaults are the source's model, with the latch corner's fillet from the CAD where
the source's two files of it differ (``latch_edge``).
"""

from __future__ import annotations

import math
from collections.abc import Mapping
from dataclasses import dataclass, fields, replace

from clearbench.scenarios.validation import SceneError

#: Friction sets: the source's per-pair values, or the paper's Table 4 by materials.
FRICTION_SETS = ("source", "paper-table-4")
HANDLE_SPRING_ARMS = ("source", "design")
#: How the hook's latch face meets the tripping bar's latch corner past the face's free edge
#: (the C4_3 and C4_4 pairs, :mod:`.model`): ``fillet`` (default), the bar's corner rounded by
#: the r 0.05 mm fillet of the source's wedge file against the face's sharp edge, the edge of the
#: face's solid; ``face-normal``, the source's bare arcs against the face continued past its
#: free edge (its normal and plane gap there, as the source's CAD distance takes them).
LATCH_EDGES = ("fillet", "face-normal")
#: Contact classes (the prefix every sheet contact of the class carries in its name).
CONTACT_CLASSES = ("J1", "J2", "J3", "J4", "J5", "J6", "J7", "S3", "C1", "C3", "C4", "C5",
                   "C6", "C7", "TRIP", "FC_X", "plunger_bearing")

PLASTIC, METAL = "plastic", "metal"
#: Material of each part and where it comes from. Densities are the part's mass (the source's
#: data sheet, equal to the paper's Table 3; the needle's from Table 3) over the volume of its
#: CAD solid (the STEP file the sheet names, computed with OpenCASCADE); moulded plastics are
#: 1.0-2.0 g/cm3, steel 7.8, copper alloys 8.4-8.9.
PART_MATERIALS = {
    "frame": (PLASTIC, "paper, Section 3: 'plastic molded case and cover'"),
    "handle": (PLASTIC, "1.36 g/cm3 (1.3 g / 957.4 mm3)"),
    "rod": (METAL, "7.34 g/cm3 (0.5 g / 68.13 mm3): steel"),
    "hook": (PLASTIC, "1.45 g/cm3 (0.09 g / 62.19 mm3)"),
    "plate": (PLASTIC, "1.93 g/cm3 (1.35 g / 698.4 mm3): a filled plastic"),
    "moving_contact": (PLASTIC, "two solids: a carrier of 848.3 mm3 and a blade of 123.7 mm3; "
                       "the sheet's mass (2.5 g) and centre of mass (7.791, -1.781, 4.034) "
                       "mm are reproduced to 3 digits with 1.68 g/cm3 for the carrier and "
                       "8.73 g/cm3 (a copper alloy) for the blade; every contact surface but "
                       "C7's lies on the carrier"),
    "tripping_bar": (PLASTIC, "1.44 g/cm3 (0.77 g / 534.0 mm3; the sheet's centre of mass is "
                     "the uniform solid's in x and y)"),
    "plunger": (METAL, "the trip coil's magnetic plunger (paper, footnotes 5-6)"),
    "needle": (METAL, "7.78 g/cm3 (paper's 0.39 g / 50.16 mm3): steel"),
}
#: Contact surfaces (CAD file stems) whose material is not their part's, and why.
SURFACE_MATERIALS = {
    "porte_contact_asm_contact_surface": (
        METAL, "on the moving contact's blade (8.73 g/cm3, see the moving contact)"),
    "Case_as_fixedcontact_movingcontact_stopper_C7": (
        METAL, "the fixed electrical contact, mounted on the frame (paper, Section 3, item 3)"),
}
#: The paper's Table 4: friction coefficient by the pair's materials (no metal/metal value).
TABLE_4_FRICTION = {frozenset({PLASTIC}): 0.3, frozenset({METAL, PLASTIC}): 0.1}

#: The source's contact-pressure law offset [deg]: D = theta_mc - theta_plate - offset.
SOURCE_ANGLE_OFFSET = -54.54 - 22.0


@dataclass(frozen=True)
class ModelParameters:
    """The C-60 parameters the source documents alternatives for (defaults: the source's).

    contact_spring_preload : rad, in [0, pi/2]
    contact_spring_angle_offset : deg, in [-90, -60]
    moving_contact_force_lever, plate_force_lever : mm, in [1, 20]
    handle_spring_arm : ``source`` or ``design``
    latch_edge : ``fillet`` or ``face-normal`` (:data:`LATCH_EDGES`; ``fillet`` is the CAD's)
    friction_set : ``source`` or ``paper-table-4`` (the base value of every pair)
    friction : sorted (contact class, coefficient) pairs overriding the base, each in [0, 1]
    """

    contact_spring_preload: float = 0.49
    contact_spring_angle_offset: float = SOURCE_ANGLE_OFFSET
    moving_contact_force_lever: float = 6.06
    plate_force_lever: float = 5.48
    handle_spring_arm: str = "source"
    latch_edge: str = "fillet"
    friction_set: str = "source"
    friction: tuple[tuple[str, float], ...] = ()

    def changes(self) -> dict:
        """The parameters that differ from the source's model (field -> value)."""
        default = ModelParameters()
        return {f.name: getattr(self, f.name) for f in fields(self)
                if getattr(self, f.name) != getattr(default, f.name)}

    def label(self) -> str:
        """The changes as text ("the source's model" when there are none)."""
        changes = self.changes()
        if not changes:
            return "the source's model"
        parts = []
        for name, value in changes.items():
            if name == "friction":
                value = ", ".join(f"{c} {mu:g}" for c, mu in value)
            parts.append(f"{name} {value}")
        return "; ".join(parts)


#: Named variants: the source's documented alternatives, the paper's friction, and the
#: combinations the identification study (``clearbench c60 identify``) runs.
VARIANTS: dict[str, dict] = {
    "source": {},
    "preload-0.5236": {"contact_spring_preload": 0.5236},
    "preload-0.6547": {"contact_spring_preload": 0.6547},
    "preload-0.9599": {"contact_spring_preload": 0.9599},
    "offset-67": {"contact_spring_angle_offset": -67.0},
    "offset-76.5": {"contact_spring_angle_offset": -76.5},
    "lever-4.84": {"moving_contact_force_lever": 4.84},
    "lever-7.99": {"moving_contact_force_lever": 7.99},
    "old-validated-levers": {"moving_contact_force_lever": 4.84, "plate_force_lever": 5.0},
    "design-arm": {"handle_spring_arm": "design"},
    "latch-face-normal": {"latch_edge": "face-normal"},
    "paper-table-4": {"friction_set": "paper-table-4"},
    "latch-0.1": {"friction": {"C4": 0.1}},
    "preload-0.9599-lever-4.84": {"contact_spring_preload": 0.9599,
                                  "moving_contact_force_lever": 4.84},
    "preload-0.9599-latch-0.1": {"contact_spring_preload": 0.9599, "friction": {"C4": 0.1}},
    "paper-table-4-preload-0.9599": {"friction_set": "paper-table-4",
                                     "contact_spring_preload": 0.9599},
}

_RANGES = {
    "contact_spring_preload": (0.0, 0.5 * math.pi, "rad"),
    "contact_spring_angle_offset": (-90.0, -60.0, "deg"),
    "moving_contact_force_lever": (1.0, 20.0, "mm"),
    "plate_force_lever": (1.0, 20.0, "mm"),
}


def _number(field: str, value: object) -> float:
    low, high, unit = _RANGES[field]
    if isinstance(value, bool) or not isinstance(value, int | float) or not math.isfinite(
            value) or not low <= value <= high:
        raise SceneError(field, value, f"must be a number in [{low:g}, {high:g}] {unit}")
    return float(value)


def _friction(value: object) -> tuple[tuple[str, float], ...]:
    if not isinstance(value, Mapping):
        raise SceneError("friction", value, "must map contact classes to coefficients")
    checked = {}
    for name, mu in value.items():
        if name not in CONTACT_CLASSES:
            raise SceneError(f"friction.{name}", mu, f"unknown contact class; classes: "
                             f"{', '.join(CONTACT_CLASSES)}")
        if isinstance(mu, bool) or not isinstance(mu, int | float) or not 0.0 <= mu <= 1.0:
            raise SceneError(f"friction.{name}", mu, "must be a coefficient in [0, 1]")
        checked[name] = float(mu)
    return tuple(sorted(checked.items()))


def _choice(field: str, value: object, choices: tuple[str, ...]) -> str:
    if value not in choices:
        raise SceneError(field, value, f"must be one of {', '.join(choices)}")
    return str(value)


def model_parameters(variant: str = "source", **overrides) -> ModelParameters:
    """The named ``variant`` with ``overrides`` (ModelParameters fields; ``friction`` a mapping
    class -> coefficient, merged over the variant's), validated. None leaves a field to the
    variant. Raises SceneError naming the field and value."""
    if variant not in VARIANTS:
        raise SceneError("variant", variant, f"unknown variant; variants: {', '.join(VARIANTS)}")
    known = {f.name for f in fields(ModelParameters)}
    unknown = sorted(set(overrides) - known)
    if unknown:
        raise SceneError(unknown[0], overrides[unknown[0]], "not a C-60 model parameter")
    values = dict(VARIANTS[variant])
    for name, value in overrides.items():
        if value is None:
            continue
        if name == "friction" and isinstance(value, Mapping):
            value = {**values.get("friction", {}), **value}
        values[name] = value
    checked = {}
    for name, value in values.items():
        if name in _RANGES:
            checked[name] = _number(name, value)
        elif name == "handle_spring_arm":
            checked[name] = _choice(name, value, HANDLE_SPRING_ARMS)
        elif name == "latch_edge":
            checked[name] = _choice(name, value, LATCH_EDGES)
        elif name == "friction_set":
            checked[name] = _choice(name, value, FRICTION_SETS)
        else:
            checked[name] = _friction(value)
    return replace(ModelParameters(), **checked)


def contact_class(sheet_name: str) -> str:
    """Class of a data-sheet contact (``Hook_Tbar_C4_1`` -> ``C4``)."""
    if sheet_name == "plunger_bearing":
        return sheet_name
    if sheet_name.startswith("TRIP_"):
        return "TRIP"
    for name in CONTACT_CLASSES:
        if f"_{name}_" in f"_{sheet_name}_":
            return name
    raise KeyError(f"{sheet_name!r} is in no contact class")


def surface_material(body: str, cad_stem: str) -> str:
    """Material of a contact surface: its own (SURFACE_MATERIALS) or its part's."""
    if cad_stem in SURFACE_MATERIALS:
        return SURFACE_MATERIALS[cad_stem][0]
    return PART_MATERIALS[body][0]


def table_4_friction(materials: frozenset) -> float | None:
    """The paper's Table 4 coefficient for a pair of materials (None: not in the table)."""
    return TABLE_4_FRICTION.get(materials)


def contact_friction(contact: Mapping, parameters: ModelParameters, stem) -> float:
    """Friction coefficient of one data-sheet contact under ``parameters``; ``stem`` maps a CAD
    path to its file stem."""
    overrides = dict(parameters.friction)
    kind = contact_class(contact["name"])
    if kind in overrides:
        return overrides[kind]
    if parameters.friction_set == "paper-table-4":
        materials = frozenset(surface_material(contact[f"body{side}"],
                                               stem(contact[f"cad{side}"])) for side in "12")
        value = table_4_friction(materials)
        if value is not None:
            return value
    return float(contact["friction"])
