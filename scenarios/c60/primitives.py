"""The C-60 contact surfaces as exact primitives, read from ``data/c60/primitives.json``.

The JSON document is written offline by :mod:`.c60_cad` (``clearbench c60-extract``) from the
STEP files of ``data/c60/cad``; this module reads it with the standard library only, so the
project needs no CAD library at run time.

Every length is in mm, every angle in rad. Coordinates are those of the STEP file: the body
frame of a part file (``CadFile.frame`` = body name of ``model.toml``) or world for the frame
("batie") surfaces (``CadFile.frame == "world"``). The document's ``conventions`` section is the
full contract; in short:

* angles (circle, arc, ring, cylinder): the point at angle t is
  ``centre + radius * (cos t * x_axis + sin t * (normal x x_axis))``, covering
  ``start_angle <= t <= end_angle`` with ``0 <= start_angle < 2 pi`` and
  ``start_angle < end_angle <= start_angle + 2 pi`` (the convention of :class:`.shapes.Arc` in
  the frame whose x, y, z axes are ``x_axis``, ``normal x x_axis``, ``normal``);
* a cylinder (or ring) spans ``axis_point + s * axis`` for ``0 <= s <= length``;
* a plane keeps its face normal; ``outward`` tells whether it points out of the body's
  material (+1), into it (-1), or is unknown (None).
"""

from __future__ import annotations

import json
import math
from collections.abc import Iterator
from dataclasses import dataclass
from pathlib import Path
from typing import Any, ClassVar

PRIMITIVES_PATH = Path(__file__).resolve().parent / "data" / "primitives.json"
FORMAT_NAME = "clearbench.c60.primitives"
FORMAT_VERSION = 1

#: Default tolerance of :func:`compare_documents` (mm, rad, or unit-vector components): far
#: above the round-off of mm-sized numbers (1e-15) and of the 12 digits the document keeps,
#: far below the tightest clearance of the data sheet (S3, 0.006 mm).
CHECK_TOLERANCE = 1.0e-7
#: Fields that may differ between two extractions without the geometry differing.
IGNORED_FIELDS = frozenset({"ocp_version"})

Vector = tuple[float, float, float]


class PrimitivesFormatError(ValueError):
    """The primitives document is not the format this module reads."""


def _vector(values: Any) -> Vector:
    x, y, z = (float(value) for value in values)
    return (x, y, z)


def _cross(a: Vector, b: Vector) -> Vector:
    return (a[1] * b[2] - a[2] * b[1], a[2] * b[0] - a[0] * b[2], a[0] * b[1] - a[1] * b[0])


@dataclass(frozen=True)
class Source:
    """Where a primitive comes from in its STEP file (1-based indices, see ``conventions``)."""

    faces: tuple[int, ...] = ()
    edge: int | None = None
    vertex: int | None = None
    occ_type: str | None = None
    defined_by: str | None = None

    @classmethod
    def from_dict(cls, data: dict[str, Any]) -> Source:
        occ_type = data.get("occ_type")
        if isinstance(occ_type, list):
            occ_type = ",".join(occ_type)
        return cls(faces=tuple(data.get("faces", ())), edge=data.get("edge"),
                   vertex=data.get("vertex"), occ_type=occ_type,
                   defined_by=data.get("defined_by"))


@dataclass(frozen=True)
class Primitive:
    """Base of every primitive: its origin in the file and the fit residual (mm)."""

    kind: ClassVar[str] = ""
    source: Source
    residual_mm: float


@dataclass(frozen=True)
class Point(Primitive):
    kind: ClassVar[str] = "point"
    position: Vector


@dataclass(frozen=True)
class Segment(Primitive):
    kind: ClassVar[str] = "segment"
    start: Vector
    end: Vector

    @property
    def length(self) -> float:
        """Length of the segment (mm)."""
        return math.dist(self.start, self.end)


@dataclass(frozen=True)
class Arc(Primitive):
    """A circular arc (a full circle when the range is [0, 2 pi]: :class:`Circle`)."""

    kind: ClassVar[str] = "arc"
    centre: Vector
    normal: Vector
    radius: float
    x_axis: Vector
    start_angle: float
    end_angle: float

    @property
    def y_axis(self) -> Vector:
        """``normal x x_axis``: the direction of angle pi/2."""
        return _cross(self.normal, self.x_axis)

    @property
    def is_full(self) -> bool:
        return self.end_angle - self.start_angle >= 2.0 * math.pi - 1e-9

    def point_at(self, angle: float) -> Vector:
        """Point of the circle at ``angle`` (rad), in the file's frame (mm)."""
        c, s = math.cos(angle), math.sin(angle)
        y_axis = self.y_axis
        return tuple(  # type: ignore[return-value]
            self.centre[i] + self.radius * (c * self.x_axis[i] + s * y_axis[i]) for i in range(3)
        )


@dataclass(frozen=True)
class Circle(Arc):
    kind: ClassVar[str] = "circle"


@dataclass(frozen=True)
class LeastSquaresFit:
    """Best cylinder through the sampled B-spline surface, for comparison with the exact one."""

    radius: float
    axis_offset_mm: float
    axis_angle_rad: float
    residual_mm: float


@dataclass(frozen=True)
class Cylinder(Primitive):
    """A cylinder or a patch of one (the angular range says which)."""

    kind: ClassVar[str] = "cylinder"
    axis_point: Vector
    axis: Vector
    radius: float
    length: float
    x_axis: Vector
    start_angle: float
    end_angle: float
    angular_range_from: str
    face_normal: str
    material: str | None
    least_squares: LeastSquaresFit

    @property
    def is_full(self) -> bool:
        return self.end_angle - self.start_angle >= 2.0 * math.pi - 1e-9

    def circle_at(self, s: float) -> Arc:
        """The section of the surface at height ``s`` (mm) along the axis from ``axis_point``."""
        centre = tuple(self.axis_point[i] + s * self.axis[i] for i in range(3))
        cls = Circle if self.is_full else Arc
        return cls(source=self.source, residual_mm=self.residual_mm, centre=centre,
                   normal=self.axis, radius=self.radius, x_axis=self.x_axis,
                   start_angle=self.start_angle, end_angle=self.end_angle)


@dataclass(frozen=True)
class Ring(Cylinder):
    """A bearing ring drawn as a band shorter than ``ring_max_length_mm`` (0.005-0.02 mm)."""

    kind: ClassVar[str] = "ring"

    @property
    def mid_circle(self) -> Arc:
        """The circle at the middle of the band."""
        return self.circle_at(0.5 * self.length)


@dataclass(frozen=True)
class Plane(Primitive):
    """A planar face: its plane, bounding rectangle and exact boundary edges."""

    kind: ClassVar[str] = "plane"
    point: Vector
    normal: Vector
    u_axis: Vector
    v_axis: Vector
    u_range: tuple[float, float]
    v_range: tuple[float, float]
    outward: int | None
    boundary: tuple[Primitive, ...]


@dataclass(frozen=True)
class Unreduced:
    """A face or edge that is none of the primitives above (never guessed)."""

    source: Source
    reason: str
    details: tuple[tuple[str, Any], ...] = ()


@dataclass(frozen=True)
class CadFile:
    """The primitives of one STEP file."""

    path: str
    sha256: str
    frame: str
    used_by: tuple[str, ...]
    primitives: tuple[Primitive, ...]
    unreduced: tuple[Unreduced, ...]

    def of_kind(self, kind: str) -> tuple[Primitive, ...]:
        """The primitives of one ``kind`` ("plane", "ring", ...)."""
        return tuple(primitive for primitive in self.primitives if primitive.kind == kind)


@dataclass(frozen=True)
class PairDistance:
    """Distance between the two surfaces of a pair in the ON pose, by OpenCASCADE (mm)."""

    name: str
    group: str
    on_pose_distance_mm: float
    on_pose_gap_mm: float | None


@dataclass(frozen=True)
class PrimitiveSet:
    """The whole document: files by path (relative to ``data/c60/cad``) and pair distances."""

    files: dict[str, CadFile]
    pairs: tuple[PairDistance, ...]
    extraction: dict[str, Any]

    def __getitem__(self, path: str) -> CadFile:
        return self.files[path]

    def __iter__(self) -> Iterator[CadFile]:
        return iter(self.files.values())

    def pair(self, name: str, group: str = "contact") -> PairDistance:
        """The pair distance record of a contact (or measurement) by name."""
        for record in self.pairs:
            if record.name == name and record.group == group:
                return record
        raise KeyError(f"no {group} pair named {name!r}")


def _primitive(data: dict[str, Any]) -> Primitive:
    kind = data["kind"]
    source = Source.from_dict(data["source"])
    residual = float(data.get("residual_mm", 0.0))
    if kind == "point":
        return Point(source, residual, _vector(data["position"]))
    if kind == "segment":
        return Segment(source, residual, _vector(data["start"]), _vector(data["end"]))
    if kind in ("arc", "circle"):
        cls = Circle if kind == "circle" else Arc
        return cls(source, residual, _vector(data["centre"]), _vector(data["normal"]),
                   float(data["radius"]), _vector(data["x_axis"]), float(data["start_angle"]),
                   float(data["end_angle"]))
    if kind in ("cylinder", "ring"):
        cls = Ring if kind == "ring" else Cylinder
        return cls(source, residual, _vector(data["axis_point"]), _vector(data["axis"]),
                   float(data["radius"]), float(data["length"]), _vector(data["x_axis"]),
                   float(data["start_angle"]), float(data["end_angle"]),
                   data["angular_range_from"], data["face_normal"], data["material"],
                   LeastSquaresFit(**data["least_squares"]))
    if kind == "plane":
        return Plane(source, residual, _vector(data["point"]), _vector(data["normal"]),
                     _vector(data["u_axis"]), _vector(data["v_axis"]),
                     tuple(data["u_range"]), tuple(data["v_range"]), data["outward"],
                     tuple(_primitive(edge) for edge in data["boundary"]))
    raise PrimitivesFormatError(f"unknown primitive kind {kind!r}")


def _unreduced(data: dict[str, Any]) -> Unreduced:
    details = tuple(sorted((key, value) for key, value in data.items()
                           if key not in ("kind", "source", "reason")))
    return Unreduced(Source.from_dict(data["source"]), data["reason"], details)


def parse_document(document: dict[str, Any]) -> PrimitiveSet:
    """Build a :class:`PrimitiveSet` from the decoded JSON document."""
    if document.get("format") != FORMAT_NAME or document.get("version") != FORMAT_VERSION:
        raise PrimitivesFormatError(
            f"expected format {FORMAT_NAME} version {FORMAT_VERSION}, got "
            f"{document.get('format')!r} version {document.get('version')!r}"
        )
    files = {}
    for entry in document["files"]:
        files[entry["path"]] = CadFile(
            path=entry["path"],
            sha256=entry["sha256"],
            frame=entry["frame"],
            used_by=tuple(entry["used_by"]),
            primitives=tuple(_primitive(item) for item in entry["primitives"]),
            unreduced=tuple(_unreduced(item) for item in entry["unreduced"]),
        )
    pairs = tuple(PairDistance(item["name"], item["group"], float(item["on_pose_distance_mm"]),
                               item.get("on_pose_gap_mm"))
                  for item in document["pairs"])
    return PrimitiveSet(files=files, pairs=pairs, extraction=dict(document["extraction"]))


def load_primitives(path: Path = PRIMITIVES_PATH) -> PrimitiveSet:
    """Read the primitives document (default: the one shipped with the package)."""
    with Path(path).open(encoding="utf-8") as stream:
        return parse_document(json.load(stream))


def dump_document(document: dict[str, Any]) -> str:
    """The JSON text of a document, as committed (stable key order, one trailing newline)."""
    return json.dumps(document, indent=1, ensure_ascii=False) + "\n"


def compare_documents(expected: Any, actual: Any, tolerance: float = CHECK_TOLERANCE,
                      where: str = "$") -> list[str]:
    """Differences between two decoded documents, one line each (empty when they agree).

    Numbers agree when they differ by at most ``tolerance`` (absolute: mm, rad or unit-vector
    components); everything else must be equal. Fields in :data:`IGNORED_FIELDS` are skipped.
    """
    if isinstance(expected, dict) and isinstance(actual, dict):
        differences = []
        for key in sorted(set(expected) | set(actual)):
            if key in IGNORED_FIELDS:
                continue
            if key not in actual:
                differences.append(f"{where}.{key}: missing")
            elif key not in expected:
                differences.append(f"{where}.{key}: unexpected")
            else:
                differences += compare_documents(expected[key], actual[key], tolerance,
                                                 f"{where}.{key}")
        return differences
    if isinstance(expected, list) and isinstance(actual, list):
        if len(expected) != len(actual):
            return [f"{where}: {len(expected)} items expected, {len(actual)} found"]
        differences = []
        for index, (left, right) in enumerate(zip(expected, actual, strict=True)):
            differences += compare_documents(left, right, tolerance, f"{where}[{index}]")
        return differences
    numbers = (int, float)
    if (isinstance(expected, numbers) and isinstance(actual, numbers)
            and not isinstance(expected, bool) and not isinstance(actual, bool)):
        if abs(float(expected) - float(actual)) <= tolerance:
            return []
        return [f"{where}: {expected!r} expected, {actual!r} found"]
    return [] if expected == actual else [f"{where}: {expected!r} expected, {actual!r} found"]
