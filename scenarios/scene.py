"""The engine-neutral scene: bodies, joints, contacts, loads, drivers, outputs, expectations.

A :class:`Scene` is immutable and validated when built: every cross reference (body, shape and
contact names) is checked, and every error names the field and value at fault. Its
:attr:`Scene.features` are derived from its content, so an engine that lacks a feature can
refuse the scene cell by cell with a reason. :meth:`Scene.rescaled` gives the same physics in
another consistent unit system.
"""

from __future__ import annotations

import dataclasses
import hashlib
import json
from dataclasses import dataclass, field
from functools import cached_property

from clearbench.scenarios.bodies import Body, Motion
from clearbench.scenarios.contacts import ContactPair
from clearbench.scenarios.dict_form import scene_to_dict
from clearbench.scenarios.drivers import Driver
from clearbench.scenarios.expectations import (
    EXPECTATION_KINDS,
    OUTPUT_DIMENSION,
    Expectation,
)
from clearbench.scenarios.features import (
    LOAD_FEATURES,
    joint_feature,
    pair_feature,
    shape_feature,
)
from clearbench.scenarios.joints import ClearanceRevoluteJoint, Joint
from clearbench.scenarios.loads import Load, Moment, PointForce
from clearbench.scenarios.outputs import ContactForce, Output
from clearbench.scenarios.rescaling import rescale_element
from clearbench.scenarios.tags import check_tags
from clearbench.scenarios.units import UnitSystem
from clearbench.scenarios.validation import (
    ACCELERATION,
    TIME,
    SceneError,
    check_finite_vector,
    check_name,
    check_positive,
    dim,
)

#: The name of a scene built without one (a library factory's, before the registry names it).
UNNAMED = "unnamed"


@dataclass(frozen=True)
class Scene:
    """A complete, validated scene.

    Parameters
    ----------
    name : str
        The scene's name; a library scene is named by the registry
        (:func:`~clearbench.scenarios.registry.register`), so its factory leaves it out.
    description : str
        One or two sentences for listings and reports.
    units : UnitSystem
        Consistent units of every dimensioned value in the scene.
    gravity : (3,) tuple
        Gravitational acceleration, world axes [L/T^2].
    horizon : float
        Simulated duration [T].
    time_step : float
        Suggested (comfortable) time step [T], used where a run gives none.
    bodies, joints, clearance_joints, contacts, loads, drivers, outputs, expectations : tuples
        The elements; names unique within each collection.
    tags : tuple of str
        Tags of :data:`clearbench.scenarios.tags.TAGS` (``smoke``, ``analytic``, ``c60``, ...);
        a library scene's are its registry entry's.
    """

    name: str = UNNAMED
    description: str = ""
    units: UnitSystem = UnitSystem()
    gravity: tuple = field(default=(0.0, 0.0, -9.81), metadata=dim(ACCELERATION))
    horizon: float = field(default=1.0, metadata=dim(TIME))
    time_step: float = field(default=1e-3, metadata=dim(TIME))
    bodies: tuple[Body, ...] = ()
    joints: tuple[Joint, ...] = ()
    clearance_joints: tuple[ClearanceRevoluteJoint, ...] = ()
    contacts: tuple[ContactPair, ...] = ()
    loads: tuple[Load, ...] = ()
    drivers: tuple[Driver, ...] = ()
    outputs: tuple[Output, ...] = ()
    expectations: tuple[Expectation, ...] = ()
    tags: tuple[str, ...] = ()

    def __post_init__(self) -> None:
        check_name("name", self.name)
        if not isinstance(self.units, UnitSystem):
            raise SceneError("units", self.units, "must be a UnitSystem")
        object.__setattr__(self, "gravity", check_finite_vector("gravity", self.gravity, 3))
        check_positive("horizon", self.horizon)
        check_positive("time_step", self.time_step)
        if self.time_step > self.horizon:
            raise SceneError("time_step", self.time_step, f"exceeds the horizon {self.horizon}")
        for collection in (
            "bodies", "joints", "clearance_joints", "contacts", "loads", "drivers", "outputs",
            "expectations", "tags",
        ):
            object.__setattr__(self, collection, tuple(getattr(self, collection)))
        check_tags("tags", self.tags)
        self._check_unique_names()
        self._check_references()

    # ------------------------------------------------------------------ validation
    def _check_unique_names(self) -> None:
        for collection in (
            "bodies", "joints", "clearance_joints", "contacts", "loads", "drivers", "outputs",
            "expectations",
        ):
            seen: set[str] = set()
            for index, element in enumerate(getattr(self, collection)):
                if element.name in seen:
                    raise SceneError(f"{collection}[{index}].name", element.name, "duplicate name")
                seen.add(element.name)
        joint_names = {j.name for j in self.clearance_joints}
        for index, contact in enumerate(self.contacts):
            if contact.name.split(".")[0] in joint_names:
                raise SceneError(
                    f"contacts[{index}].name", contact.name,
                    "clashes with the contacts generated by a clearance joint of that name",
                )

    def _body_or_error(self, path: str, name: str | None) -> Body:
        for body in self.bodies:
            if body.name == name:
                return body
        known = ", ".join(b.name for b in self.bodies) or "none"
        raise SceneError(path, name, f"unknown body (bodies: {known})")

    def _check_references(self) -> None:
        for joint in self.joints:
            self._body_or_error(f"joints[{joint.name!r}].body_a", joint.body_a)
            self._body_or_error(f"joints[{joint.name!r}].body_b", joint.body_b)
        for joint in self.clearance_joints:
            self._body_or_error(f"clearance_joints[{joint.name!r}].journal_body",
                                joint.journal_body)
            self._body_or_error(f"clearance_joints[{joint.name!r}].bearing_body",
                                joint.bearing_body)
        for contact in self.contacts:
            path = f"contacts[{contact.name!r}]"
            for side in ("a", "b"):
                body = self._body_or_error(f"{path}.body_{side}", getattr(contact, f"body_{side}"))
                shape = getattr(contact, f"shape_{side}")
                if shape not in {s.name for s in body.shapes}:
                    known = ", ".join(s.name for s in body.shapes) or "none"
                    raise SceneError(f"{path}.shape_{side}", shape,
                                     f"body {body.name!r} has no such shape (shapes: {known})")
            a = self._body_or_error(path, contact.body_a)
            b = self._body_or_error(path, contact.body_b)
            if a.motion is Motion.FIXED and b.motion is Motion.FIXED:
                raise SceneError(f"{path}.body_b", contact.body_b, "both bodies are fixed")
        for load in self.loads:
            for attribute in ("body", "body_a", "body_b"):
                if hasattr(load, attribute):
                    self._body_or_error(f"loads[{load.name!r}].{attribute}",
                                        getattr(load, attribute))
            for index, name in enumerate(getattr(load, "angle_bodies", ())):
                self._body_or_error(f"loads[{load.name!r}].angle_bodies[{index}]", name)
            for index, application in enumerate(getattr(load, "applications", ())):
                self._body_or_error(f"loads[{load.name!r}].applications[{index}].body",
                                    application.body)
        driven = set()
        for driver in self.drivers:
            body = self._body_or_error(f"drivers[{driver.name!r}].body", driver.body)
            if body.motion is not Motion.DRIVEN:
                raise SceneError(f"drivers[{driver.name!r}].body", driver.body,
                                 f"body motion is {body.motion.value!r}, must be 'driven'")
            key = (driver.body, driver.component)
            if key in driven:
                raise SceneError(f"drivers[{driver.name!r}].component", driver.component,
                                 "component already driven by another driver")
            driven.add(key)
        for body in self.bodies:
            if body.motion is Motion.DRIVEN and not any(d.body == body.name for d in self.drivers):
                raise SceneError(f"bodies[{body.name!r}].motion", "driven", "no driver for it")
        contact_names = {c.name for c in self.all_contacts}
        for output in self.outputs:
            path = f"outputs[{output.name!r}]"
            if isinstance(output, ContactForce):
                if output.contact not in contact_names:
                    raise SceneError(f"{path}.contact", output.contact, "unknown contact pair")
                continue
            for attribute in ("body", "body_a", "body_b"):
                if hasattr(output, attribute):
                    self._body_or_error(f"{path}.{attribute}", getattr(output, attribute))
        output_names = {output.name for output in self.outputs}
        for expectation in self.expectations:
            if expectation.body is not None:
                self._body_or_error(f"expectations[{expectation.name!r}].body", expectation.body)
            if expectation.output is not None and expectation.output not in output_names:
                raise SceneError(f"expectations[{expectation.name!r}].output", expectation.output,
                                 f"unknown output; outputs: {sorted(output_names)}")
            EXPECTATION_KINDS[expectation.kind].check_in_scene(self, expectation)

    # ------------------------------------------------------------------ access
    def body(self, name: str) -> Body:
        """The body called ``name`` (KeyError otherwise)."""
        for body in self.bodies:
            if body.name == name:
                return body
        raise KeyError(f"scene {self.name!r} has no body {name!r}")

    def body_index(self, name: str) -> int:
        """Index of ``name`` in :attr:`bodies`."""
        for index, body in enumerate(self.bodies):
            if body.name == name:
                return index
        raise KeyError(f"scene {self.name!r} has no body {name!r}")

    @cached_property
    def expanded(self) -> Scene:
        """The same scene with every clearance joint rebuilt as shapes and contact pairs.

        Engines that treat clearance joints as contacts (the reference solver, Siconos) and the
        metrics use this form; it has no clearance joints left.
        """
        if not self.clearance_joints:
            return self
        extra_shapes: dict[str, list] = {b.name: [] for b in self.bodies}
        extra_contacts: list[ContactPair] = []
        for joint in self.clearance_joints:
            journal = self.body(joint.journal_body)
            bearing = self.body(joint.bearing_body)
            journal_shapes, bearing_shapes, contacts = joint.expand(
                (journal.position, journal.orientation), (bearing.position, bearing.orientation)
            )
            extra_shapes[journal.name].extend(journal_shapes)
            extra_shapes[bearing.name].extend(bearing_shapes)
            extra_contacts.extend(contacts)
        bodies = tuple(
            dataclasses.replace(b, shapes=b.shapes + tuple(extra_shapes[b.name]))
            for b in self.bodies
        )
        return dataclasses.replace(
            self, bodies=bodies, clearance_joints=(), contacts=self.contacts + tuple(extra_contacts)
        )

    @property
    def all_contacts(self) -> tuple[ContactPair, ...]:
        """Explicit contact pairs followed by those generated by clearance joints."""
        return self.expanded.contacts if self.clearance_joints else self.contacts

    # ------------------------------------------------------------------ derived
    @cached_property
    def features(self) -> frozenset[str]:
        """Features the scene uses, derived from its content (written and read with
        :mod:`clearbench.scenarios.features`).

        Vocabulary: ``gravity``, ``contacts``, ``friction``, ``restitution``, ``shape:<kind>``,
        ``pair:<kind>-<kind>`` (sorted), ``ideal_joints``, ``joint:<kind>``, ``closed_loop``,
        ``clearance_joints``, ``rings``, ``arcs``, ``springs``, ``torsional_springs``,
        ``point_forces``, ``moments``, ``angle_law_loads``, ``distance_law_loads``,
        ``time_switched_loads``, ``drivers``, ``fixed_bodies``.
        """
        features: set[str] = set()
        if any(self.gravity):
            features.add("gravity")
        expanded = self.expanded
        shapes = {
            (body.name, shape.name): shape for body in expanded.bodies for shape in body.shapes
        }
        for contact in expanded.contacts:
            features.add("contacts")
            if contact.friction > 0:
                features.add("friction")
            if contact.restitution > 0:
                features.add("restitution")
            kinds = (shapes[(contact.body_a, contact.shape_a)].kind,
                     shapes[(contact.body_b, contact.shape_b)].kind)
            features.add(pair_feature(*kinds))
            for kind in kinds:
                features.add(shape_feature(kind))
                if kind == "circle":
                    features.add("rings")
                if kind == "arc":
                    features.add("arcs")
        if self.joints:
            features.add("ideal_joints")
            features.update(joint_feature(joint.kind) for joint in self.joints)
            if self._joint_graph_has_cycle():
                features.add("closed_loop")
        if self.clearance_joints:
            features.add("clearance_joints")
        for load in self.loads:
            features.add(LOAD_FEATURES[load.kind])
            if isinstance(load, PointForce | Moment) and (
                load.start_time > 0 or load.end_time is not None
            ):
                features.add("time_switched_loads")
        if self.drivers:
            features.add("drivers")
        if any(b.motion is Motion.FIXED for b in self.bodies):
            features.add("fixed_bodies")
        return frozenset(features)

    def _joint_graph_has_cycle(self) -> bool:
        """True when the ideal joints close a loop (fixed bodies count as one node)."""
        fixed = {b.name for b in self.bodies if b.motion is Motion.FIXED}
        parent: dict[str, str] = {}

        def root(node: str) -> str:
            node = "<fixed>" if node in fixed else node
            while parent.get(node, node) != node:
                node = parent[node]
            return node

        for joint in self.joints:
            a, b = root(joint.body_a), root(joint.body_b)
            if a == b:
                return True
            parent[a] = b
        return False

    def rescaled(self, units: UnitSystem) -> Scene:
        """The same physics expressed in ``units`` (every dimensioned value converted)."""
        scene = rescale_element(self, self.units, units)
        dimensions = {output.name: output.dimension for output in self.outputs}
        converted = []
        for expectation in scene.expectations:
            spec = EXPECTATION_KINDS[expectation.kind]
            in_output_unit = [k for k in expectation.parameters
                              if spec.parameters[k].dimension == OUTPUT_DIMENSION]
            if in_output_unit:
                factor = self.units.factor_to(units, dimensions[expectation.output])
                parameters = dict(expectation.parameters)
                for key in in_output_unit:
                    parameters[key] *= factor
                expectation = dataclasses.replace(expectation, parameters=parameters)
            converted.append(expectation)
        return dataclasses.replace(scene, expectations=tuple(converted))

    @cached_property
    def content_hash(self) -> str:
        """sha256 of the canonical JSON form: identifies the physics a run was given."""
        text = json.dumps(scene_to_dict(self), sort_keys=True, separators=(",", ":"))
        return hashlib.sha256(text.encode()).hexdigest()
