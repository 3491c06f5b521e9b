"""Reduce the C-60 STEP contact surfaces to exact primitives (offline tool, needs OpenCASCADE).

The C-60 data sheet (``data/c60/model.toml``) names, for each of its 39 contacts and 7
measurement pairs, one STEP file per side. This module reads those files with OpenCASCADE (the
optional ``cadquery-ocp`` package, extra ``cad``; imported only when an extraction runs) and
writes what each file *is* as plain primitives to one JSON document, ``data/c60/primitives.json``,
that the project reads at run time without any CAD library (see :mod:`.c60_primitives`).

Method, per file (units mm and rad throughout)
----------------------------------------------
* Faces (every one is a B-spline surface in these files) are sampled on a regular grid of
  ``SAMPLES_PER_DIRECTION**2`` points of their (u, v) bounds, with the face normal (face
  orientation applied). A plane is fitted to the points (SVD); if its residual (max distance of
  the samples from the plane) is at most ``ACCEPT_RESIDUAL_MM`` the face is a plane. Otherwise a
  cylinder is fitted: axis = the direction orthogonal to all sampled normals (smallest singular
  vector), circle = algebraic least-squares fit of the points projected on the plane normal to
  that axis; residual = max | distance to axis - radius |. Faces that fit the same cylinder
  (two half faces, as the CAD stores a full journal) are merged and fitted again together.
  A face that fits neither is reported as unreduced with its OCC type and both residuals.
* A cylinder shorter than ``RING_MAX_LENGTH_MM`` is a *ring*: the thin band (0.005 to 0.02 mm
  wide) by which the CAD draws a bearing ring; it keeps the cylinder's fields.
* Edges that bound no face and vertices that bound no edge are primitives of their own: exact
  circles and arcs (OCC ``gp_Circ``), segments (OCC lines), points.
* For a part (body) file, the side of a plane where the material is, and whether a cylinder or
  ring has its material inside (journal) or outside (bore), are found by classifying probe
  points against that body's solid (``bodies.cad`` of the data sheet). The frame ("batie") has
  no solid in the data set: these fields are then null.
* Pairs: the two surfaces of each contact and measurement pair are placed in the ON pose of the
  data sheet and their minimum distance is computed by OpenCASCADE (``BRepExtrema``), as the
  study's contact detection does at t = 0; the gap is that distance minus the offset.

Conventions written into the document (``conventions``) are the contract of
:mod:`.c60_primitives`.
"""

from __future__ import annotations

import hashlib
import logging
import math
import time
import tomllib
from collections.abc import Iterable
from pathlib import Path
from typing import Any

import numpy as np

from clearbench.scenarios.c60.primitives import FORMAT_NAME, FORMAT_VERSION, PRIMITIVES_PATH

logger = logging.getLogger(__name__)

DATA_DIR = PRIMITIVES_PATH.parent
#: The STEP files (kept with this tool: a user running scenes never needs them).
CAD_DIR = Path(__file__).resolve().parent / "cad"
MODEL_PATH = DATA_DIR / "model.toml"

#: Grid samples per parametric direction of a face (65: the residuals agree with 129 to 4 digits).
SAMPLES_PER_DIRECTION = 65
#: Samples along each boundary edge (end points included).
EDGE_SAMPLES = 33
#: A face is reduced to a plane / cylinder when its residual is at most this (mm): 1/20 of the
#: tightest clearance of the data sheet (S3, 0.3 - 0.294 = 0.006 mm). The B-spline journals and
#: rings deviate from their exact boundary circles by up to about 1.2e-4 mm.
ACCEPT_RESIDUAL_MM = 3.0e-4
#: Tolerance for two fitted cylinders to be the same one (axis distance, radius; mm).
MERGE_TOLERANCE_MM = 1.0e-6
#: A cylinder shorter than this (mm) is a bearing ring band; the shortest journal is 3.2 mm.
RING_MAX_LENGTH_MM = 0.05
#: Angular tolerance when joining arcs (rad).
ANGLE_TOLERANCE = 1.0e-9
#: Probe distances (mm) for the material-side classification against a body's solid.
PROBE_DISTANCES_MM = (1.0e-3, 1.0e-2)

TWO_PI = 2.0 * math.pi

CONVENTIONS = {
    "frame": (
        "Coordinates of a file are in the frame it is drawn in: the body frame for a part file "
        "(frame = body name of the data sheet), world for the frame/'batie' surfaces (frame = "
        "'world'). A world point of a body is origin + R(rotation_axis, rotation_angle) @ p."
    ),
    "indices": (
        "face, edge and vertex indices are 1-based, in the order of OpenCASCADE's "
        "TopExp_Explorer over the file's shape, each sub-shape counted once."
    ),
    "angles": (
        "A circle, arc, ring or cylinder has a unit normal/axis n and a reference unit vector "
        "x_axis orthogonal to n; the point at angle t is centre + radius * (cos t x_axis + "
        "sin t (n cross x_axis)) (plus s n along a cylinder). The covered range is start_angle "
        "<= t <= end_angle with 0 <= start_angle < 2 pi and start_angle < end_angle <= "
        "start_angle + 2 pi; a full circle is [0, 2 pi]. x_axis is the projection on the plane "
        "normal to n of the first of world x, y, z that is not within acos(0.9) of n."
    ),
    "direction_sign": (
        "The axis of a cylinder or ring, and the normal of a circle or arc, points so that its "
        "first component of absolute value above 1e-9 is positive. A plane keeps the normal of "
        "its face (face orientation applied)."
    ),
    "cylinder": (
        "axis_point is on the axis at the lower end of the surface: the surface spans "
        "axis_point + s axis for 0 <= s <= length. material: 'inside' (a journal, convex), "
        "'outside' (a bore) or null (not determined). face_normal: 'away_from_axis' or "
        "'toward_axis' as the file's face normals point."
    ),
    "ring": (
        "A cylinder of length below ring_max_length_mm: the band by which the CAD draws a "
        "bearing ring (a circle for contact purposes). Same fields as a cylinder."
    ),
    "plane": (
        "point = centre of the bounding rectangle of the face boundary; normal = face normal; "
        "u_axis, v_axis: in-plane unit vectors (v_axis = projection of world z, or of world y "
        "when the normal is within acos(0.9) of z; u_axis = v_axis cross normal); u_range and "
        "v_range bound the face boundary in those coordinates about point. outward: +1 when "
        "normal points out of the body's material, -1 when into it, null if not determined. "
        "boundary: the face's edges as segments and arcs."
    ),
    "residual": (
        "residual_mm = max distance of the sampled surface points (grid of the face's (u, v) "
        "bounds) from the fitted primitive, in mm; 0 for primitives read exactly from OCC "
        "curves (circles, arcs, segments, points)."
    ),
    "pairs": (
        "on_pose_distance_mm: minimum distance between the two surfaces placed in the ON pose "
        "of the data sheet (OpenCASCADE BRepExtrema_DistShapeShape); on_pose_gap_mm = distance "
        "- offset (contacts only)."
    ),
}


class CadLibraryMissing(RuntimeError):
    """Raised when OpenCASCADE (the ``cadquery-ocp`` package) cannot be imported."""


class ExtractionError(RuntimeError):
    """A STEP file could not be read, or the data sheet names a file inconsistently."""


# ---------------------------------------------------------------------------------------------
# OpenCASCADE access (lazy)
# ---------------------------------------------------------------------------------------------


def _occ():
    """Import the OpenCASCADE modules used here; return them as a namespace-like dict."""
    try:
        from OCP.BRep import BRep_Tool
        from OCP.BRepAdaptor import BRepAdaptor_Curve, BRepAdaptor_Surface
        from OCP.BRepBuilderAPI import BRepBuilderAPI_Transform
        from OCP.BRepClass3d import BRepClass3d_SolidClassifier
        from OCP.BRepExtrema import BRepExtrema_DistShapeShape
        from OCP.GeomAbs import GeomAbs_CurveType
        from OCP.gp import gp_Ax1, gp_Dir, gp_Pnt, gp_Pnt2d, gp_Trsf, gp_Vec
        from OCP.IFSelect import IFSelect_ReturnStatus
        from OCP.IntTools import IntTools_FClass2d
        from OCP.STEPControl import STEPControl_Reader
        from OCP.TopAbs import TopAbs_Orientation, TopAbs_ShapeEnum, TopAbs_State
        from OCP.TopExp import TopExp_Explorer
        from OCP.TopoDS import TopoDS
    except ImportError as error:
        raise CadLibraryMissing(
            "OpenCASCADE is not installed: the C-60 extraction needs the optional extra 'cad' "
            "(pip install -e '.[cad]', which installs cadquery-ocp)"
        ) from error

    def cast(name):
        # OCP 7.7 exposes TopoDS.Face_s(...), OCP 8 TopoDS.Face(...).
        return getattr(TopoDS, f"{name}_s", None) or getattr(TopoDS, name)

    return {
        "BRep_Tool": BRep_Tool,
        "Curve": BRepAdaptor_Curve,
        "Surface": BRepAdaptor_Surface,
        "Transform": BRepBuilderAPI_Transform,
        "Classifier": BRepClass3d_SolidClassifier,
        "FaceClassifier": IntTools_FClass2d,
        "Pnt2d": gp_Pnt2d,
        "Distance": BRepExtrema_DistShapeShape,
        "CurveType": GeomAbs_CurveType,
        "Ax1": gp_Ax1,
        "Dir": gp_Dir,
        "Pnt": gp_Pnt,
        "Trsf": gp_Trsf,
        "Vec": gp_Vec,
        "RetDone": IFSelect_ReturnStatus.IFSelect_RetDone,
        "Reader": STEPControl_Reader,
        "Orientation": TopAbs_Orientation,
        "ShapeEnum": TopAbs_ShapeEnum,
        "State": TopAbs_State,
        "Explorer": TopExp_Explorer,
        "face": cast("Face"),
        "edge": cast("Edge"),
        "vertex": cast("Vertex"),
    }


def ocp_version() -> str:
    """Return the installed cadquery-ocp version, or raise :class:`CadLibraryMissing`."""
    _occ()
    from importlib.metadata import PackageNotFoundError, version

    for name in ("cadquery-ocp", "cadquery-ocp-novtk"):
        try:
            return version(name)
        except PackageNotFoundError:
            continue
    return "unknown"


def read_step(occ, path: Path):
    """Read one STEP file and return its shape (a TopoDS_Shape)."""
    reader = occ["Reader"]()
    status = reader.ReadFile(str(path))
    if status != occ["RetDone"]:
        raise ExtractionError(f"{path}: STEP reader status {status}")
    reader.TransferRoots()
    return reader.OneShape()


def _unique(occ, shape, kind: str, avoid: str | None = None) -> list:
    """Sub-shapes of ``shape`` of type ``kind`` (not inside an ``avoid``), each once, in order."""
    shape_enum = occ["ShapeEnum"]
    to_find = getattr(shape_enum, f"TopAbs_{kind}")
    if avoid is None:
        explorer = occ["Explorer"](shape, to_find)
    else:
        explorer = occ["Explorer"](shape, to_find, getattr(shape_enum, f"TopAbs_{avoid}"))
    found: list = []
    while explorer.More():
        current = explorer.Current()
        if not any(current.IsSame(seen) for seen in found):
            found.append(current)
        explorer.Next()
    return found


# ---------------------------------------------------------------------------------------------
# Pure geometry helpers (numpy)
# ---------------------------------------------------------------------------------------------


def canonical_direction(direction: np.ndarray) -> np.ndarray:
    """Unit vector parallel to ``direction`` whose first component above 1e-9 in size is > 0.

    Parameters
    ----------
    direction : (3,) array
        Any non-zero vector.
    """
    unit = np.asarray(direction, dtype=float) / np.linalg.norm(direction)
    for component in unit:
        if abs(component) > 1e-9:
            return unit if component > 0 else -unit
    raise ValueError("zero direction")


def reference_x_axis(normal: np.ndarray) -> np.ndarray:
    """In-plane reference axis of the ``angles`` convention for the unit ``normal`` (3,)."""
    for candidate in np.eye(3):
        if abs(float(candidate @ normal)) < 0.9:
            projected = candidate - (candidate @ normal) * normal
            return projected / np.linalg.norm(projected)
    raise AssertionError("unreachable: one of x, y, z is always within 0.9")


def plane_in_plane_axes(normal: np.ndarray) -> tuple[np.ndarray, np.ndarray]:
    """The (u_axis, v_axis) of the ``plane`` convention for the unit ``normal`` (3,)."""
    up = np.array([0.0, 0.0, 1.0]) if abs(normal[2]) < 0.9 else np.array([0.0, 1.0, 0.0])
    v_axis = up - (up @ normal) * normal
    v_axis /= np.linalg.norm(v_axis)
    u_axis = np.cross(v_axis, normal)
    return u_axis, v_axis


def angles_about(
    points: np.ndarray, centre: np.ndarray, normal: np.ndarray, x_axis: np.ndarray
) -> np.ndarray:
    """Angles (rad, in [0, 2 pi)) of ``points`` (N, 3) about the axis (centre, normal)."""
    y_axis = np.cross(normal, x_axis)
    relative = points - centre
    return np.mod(np.arctan2(relative @ y_axis, relative @ x_axis), TWO_PI)


def fit_plane(points: np.ndarray) -> tuple[np.ndarray, np.ndarray, float]:
    """Least-squares plane through ``points`` (N, 3).

    Returns
    -------
    centroid : (3,) point on the plane, mm.
    normal : (3,) unit normal (sign arbitrary).
    residual : max distance of the points from the plane, mm.
    """
    centroid = points.mean(axis=0)
    _, _, vt = np.linalg.svd(points - centroid, full_matrices=False)
    normal = vt[-1]
    residual = float(np.max(np.abs((points - centroid) @ normal)))
    return centroid, normal, residual


def fit_cylinder(points: np.ndarray, normals: np.ndarray) -> tuple[np.ndarray, np.ndarray, float,
                                                                    float]:
    """Cylinder through ``points`` (N, 3) whose surface normals are ``normals`` (N, 3).

    The axis is the direction orthogonal to all normals (smallest right singular vector of the
    normal matrix); the circle is the algebraic least-squares fit (Kasa) of the points projected
    on the plane normal to the axis.

    Returns
    -------
    centre : (3,) a point of the axis, mm.
    axis : (3,) unit axis direction (canonical sign).
    radius : mm.
    residual : max | distance to the axis - radius | over the points, mm.
    """
    _, _, vt = np.linalg.svd(normals, full_matrices=False)
    axis = canonical_direction(vt[-1])
    x_axis = reference_x_axis(axis)
    y_axis = np.cross(axis, x_axis)
    origin = points.mean(axis=0)
    relative = points - origin
    planar = np.column_stack([relative @ x_axis, relative @ y_axis])
    design = np.column_stack([planar, np.ones(len(planar))])
    target = np.sum(planar**2, axis=1)
    (a, b, c), *_ = np.linalg.lstsq(design, target, rcond=None)
    centre_2d = np.array([a / 2.0, b / 2.0])
    radius = math.sqrt(c + centre_2d @ centre_2d)
    centre = origin + centre_2d[0] * x_axis + centre_2d[1] * y_axis
    residual = float(np.max(np.abs(_distance_to_axis(points, centre, axis) - radius)))
    return centre, axis, radius, residual


def _distance_to_axis(points: np.ndarray, centre: np.ndarray, axis: np.ndarray) -> np.ndarray:
    relative = points - centre
    radial = relative - np.outer(relative @ axis, axis)
    return np.linalg.norm(radial, axis=1)


def union_of_arcs(intervals: Iterable[tuple[float, float]]) -> list[tuple[float, float]]:
    """Union of angular intervals (start, end) on the circle, as disjoint intervals.

    Each interval has ``0 <= start < 2 pi`` and ``start < end <= start + 2 pi`` (rad). A union
    that covers the whole circle is returned as ``[(0, 2 pi)]``.
    """
    ordered = sorted(intervals)
    if not ordered:
        return []
    merged: list[list[float]] = [list(ordered[0])]
    for start, end in ordered[1:]:
        if start <= merged[-1][1] + ANGLE_TOLERANCE:
            merged[-1][1] = max(merged[-1][1], end)
        else:
            merged.append([start, end])
    # The last interval may wrap past 2 pi onto the first ones.
    while len(merged) > 1 and merged[-1][1] - TWO_PI >= merged[0][0] - ANGLE_TOLERANCE:
        first = merged.pop(0)
        merged[-1][1] = max(merged[-1][1], first[1] + TWO_PI)
    if any(end - start >= TWO_PI - ANGLE_TOLERANCE for start, end in merged):
        return [(0.0, TWO_PI)]
    return [(start, end) for start, end in merged]


def _within_arc(angles: np.ndarray, start: float, end: float, slack: float) -> np.ndarray:
    """Whether each angle (rad) lies in [start - slack, end + slack] on the circle."""
    return np.mod(angles - start + slack, TWO_PI) <= (end - start) + 2.0 * slack


# ---------------------------------------------------------------------------------------------
# Sampling OCC shapes
# ---------------------------------------------------------------------------------------------


def _xyz(point) -> np.ndarray:
    return np.array([point.X(), point.Y(), point.Z()])


def _sample_face(occ, face) -> tuple[np.ndarray, np.ndarray]:
    """Grid points (N, 3) and unit normals (N, 3) of a face, orientation applied.

    The grid spans the face's (u, v) bounds; points outside a trimmed face are dropped.
    """
    adaptor = occ["Surface"](face)
    u_values = np.linspace(adaptor.FirstUParameter(), adaptor.LastUParameter(),
                           SAMPLES_PER_DIRECTION)
    v_values = np.linspace(adaptor.FirstVParameter(), adaptor.LastVParameter(),
                           SAMPLES_PER_DIRECTION)
    reversed_face = face.Orientation() == occ["Orientation"].TopAbs_REVERSED
    point, d1u, d1v = occ["Pnt"](), occ["Vec"](), occ["Vec"]()
    outside = occ["State"].TopAbs_OUT
    classifier = occ["FaceClassifier"](face, 1e-9)
    rows = []  # x, y, z, dPdu (3), dPdv (3) per kept grid point
    for u in u_values:
        for v in v_values:
            if classifier.Perform(occ["Pnt2d"](float(u), float(v))) == outside:
                continue
            adaptor.D1(float(u), float(v), point, d1u, d1v)
            rows.append((point.X(), point.Y(), point.Z(), d1u.X(), d1u.Y(), d1u.Z(),
                         d1v.X(), d1v.Y(), d1v.Z()))
    samples = np.array(rows)
    normals = np.cross(samples[:, 3:6], samples[:, 6:9])
    lengths = np.linalg.norm(normals, axis=1)
    regular = lengths > 0.0  # a degenerate point of the parametrisation has no normal
    normals = normals[regular] / lengths[regular, None]
    return samples[regular, :3], (-normals if reversed_face else normals)


def _sample_edge(occ, edge) -> np.ndarray:
    """``EDGE_SAMPLES`` points (N, 3) along an edge, end points included."""
    adaptor = occ["Curve"](edge)
    parameters = np.linspace(adaptor.FirstParameter(), adaptor.LastParameter(), EDGE_SAMPLES)
    return np.array([_xyz(adaptor.Value(float(t))) for t in parameters])


def _round(values, digits: int = 12):
    """Round floats (scalars or nested sequences) for a stable, readable JSON document."""
    if isinstance(values, np.ndarray):
        values = values.tolist()
    if isinstance(values, list | tuple):
        return [_round(value, digits) for value in values]
    rounded = round(float(values), digits)
    return 0.0 if rounded == 0.0 else rounded  # no "-0.0" in the document


def edge_primitive(occ, edge, index: int) -> dict[str, Any]:
    """Exact primitive of one edge: circle, arc, segment, or an unreduced record."""
    adaptor = occ["Curve"](edge)
    curve_type = adaptor.GetType()
    first, last = adaptor.FirstParameter(), adaptor.LastParameter()
    if curve_type == occ["CurveType"].GeomAbs_Line:
        return {
            "kind": "segment",
            "source": {"edge": index},
            "start": _round(_xyz(adaptor.Value(first))),
            "end": _round(_xyz(adaptor.Value(last))),
            "residual_mm": 0.0,
        }
    if curve_type == occ["CurveType"].GeomAbs_Circle:
        circle = adaptor.Circle()
        occ_normal = _xyz(circle.Axis().Direction())
        occ_x = _xyz(circle.XAxis().Direction())
        normal = canonical_direction(occ_normal)
        x_axis = reference_x_axis(normal)
        y_axis = np.cross(normal, x_axis)
        # Angle t of OCC's parametrisation maps to phase + sense * t in the canonical frame.
        sense = 1.0 if occ_normal @ normal > 0 else -1.0
        phase = math.atan2(occ_x @ y_axis, occ_x @ x_axis)
        if last - first >= TWO_PI - ANGLE_TOLERANCE:
            start, end = 0.0, TWO_PI
        else:
            ends = sorted((phase + sense * first, phase + sense * last))
            start = math.fmod(ends[0], TWO_PI) % TWO_PI
            end = start + (ends[1] - ends[0])
        full = end - start >= TWO_PI - ANGLE_TOLERANCE
        return {
            "kind": "circle" if full else "arc",
            "source": {"edge": index},
            "centre": _round(_xyz(circle.Location())),
            "normal": _round(normal),
            "radius": _round(circle.Radius()),
            "x_axis": _round(x_axis),
            "start_angle": _round(start),
            "end_angle": _round(end),
            "residual_mm": 0.0,
        }
    return {
        "kind": "unreduced",
        "source": {"edge": index},
        "occ_type": str(curve_type).split(".")[-1],
        "reason": "edge curve is neither a line nor a circle",
    }


# ---------------------------------------------------------------------------------------------
# Faces -> planes and cylinders
# ---------------------------------------------------------------------------------------------


class _FaceFit:
    """Samples and fits of one face (internal)."""

    def __init__(self, occ, face, index: int, edge_indices: list[int], edges: list):
        self.index = index
        self.face = face
        self.occ_type = str(occ["Surface"](face).GetType()).split(".")[-1]
        self.points, self.normals = _sample_face(occ, face)
        self.edge_indices = edge_indices
        self.edges = edges
        self.edge_records = [edge_primitive(occ, edge, i)
                             for edge, i in zip(edges, edge_indices, strict=True)]
        self.edge_points = [_sample_edge(occ, edge) for edge in edges]
        self.boundary_points = np.vstack(self.edge_points)
        all_points = np.vstack([self.points, self.boundary_points])
        self.plane = fit_plane(all_points)
        self.cylinder = None
        self.least_squares = None
        if self.plane[2] > ACCEPT_RESIDUAL_MM:
            self.least_squares = fit_cylinder(self.points, self.normals)
            self.cylinder = self._cylinder_of_circles() or self.least_squares

    def _cylinder_of_circles(self):
        """(centre, axis, radius, residual) of the exact boundary circles, if they agree."""
        circles = [record for record in self.edge_records if record["kind"] in ("circle", "arc")]
        if not circles:
            return None
        centre = np.array(circles[0]["centre"])
        axis = np.array(circles[0]["normal"])
        radius = circles[0]["radius"]
        for record in circles[1:]:
            other = np.array(record["centre"])
            if (abs(abs(np.array(record["normal"]) @ axis) - 1.0) > 1e-9
                    or _distance_to_axis(other[None, :], centre, axis)[0] > MERGE_TOLERANCE_MM
                    or abs(record["radius"] - radius) > MERGE_TOLERANCE_MM):
                return None
        residual = float(np.max(np.abs(_distance_to_axis(self.points, centre, axis) - radius)))
        return centre, axis, radius, residual

    @property
    def cylinder_source(self) -> str:
        return "least squares" if self.cylinder is self.least_squares else "boundary circles"


def _plane_record(occ, fit: _FaceFit, edge_records: list[dict]) -> dict[str, Any]:
    _, normal, residual = fit.plane
    mean_face_normal = fit.normals.mean(axis=0)
    if normal @ mean_face_normal < 0:
        normal = -normal
    u_axis, v_axis = plane_in_plane_axes(normal)
    centroid = fit.boundary_points.mean(axis=0)
    u_coords = (fit.boundary_points - centroid) @ u_axis
    v_coords = (fit.boundary_points - centroid) @ v_axis
    u_mid = 0.5 * (u_coords.min() + u_coords.max())
    v_mid = 0.5 * (v_coords.min() + v_coords.max())
    point = centroid + u_mid * u_axis + v_mid * v_axis
    # Express the point on the plane exactly (remove the sub-residual normal component).
    point = point - ((point - fit.plane[0]) @ normal) * normal
    half_u = 0.5 * (u_coords.max() - u_coords.min())
    half_v = 0.5 * (v_coords.max() - v_coords.min())
    return {
        "kind": "plane",
        "source": {"faces": [fit.index], "occ_type": fit.occ_type},
        "point": _round(point),
        "normal": _round(normal),
        "u_axis": _round(u_axis),
        "v_axis": _round(v_axis),
        "u_range": _round([-half_u, half_u]),
        "v_range": _round([-half_v, half_v]),
        "outward": None,
        "boundary": edge_records,
        "residual_mm": _round(residual, 15),
    }


def _cylinder_record(occ, fits: list[_FaceFit]) -> dict[str, Any]:
    """One cylinder (or ring) from the faces that share it.

    The cylinder is the one of the faces' exact boundary circles when they have some (the
    design intent), else the least-squares fit; ``residual_mm`` is the largest distance of the
    sampled surface points from it, ``least_squares`` the best fit to the samples for comparison.
    """
    points = np.vstack([fit.points for fit in fits])
    normals = np.vstack([fit.normals for fit in fits])
    centre, axis, radius, _ = fits[0].cylinder
    axis = canonical_direction(axis)
    residual = float(np.max(np.abs(_distance_to_axis(points, centre, axis) - radius)))
    lsq_centre, lsq_axis, lsq_radius, lsq_residual = fit_cylinder(points, normals)
    x_axis = reference_x_axis(axis)
    boundary = np.vstack([fit.boundary_points for fit in fits])
    heights = (boundary - centre) @ axis
    low, high = float(heights.min()), float(heights.max())
    axis_point = centre + low * axis
    length = high - low
    # Angular coverage: exact, from the boundary circles that lie on this cylinder.
    intervals = []
    for fit in fits:
        for record, arc_points in zip(fit.edge_records, fit.edge_points, strict=True):
            if record["kind"] not in ("circle", "arc"):
                continue
            edge_centre = np.array(record["centre"])
            on_axis = _distance_to_axis(edge_centre[None, :], centre, axis)[0]
            if (abs(abs(np.array(record["normal"]) @ axis) - 1.0) > 1e-9
                    or on_axis > MERGE_TOLERANCE_MM
                    or abs(record["radius"] - radius) > MERGE_TOLERANCE_MM):
                continue
            sweep = record["end_angle"] - record["start_angle"]
            if sweep >= TWO_PI - ANGLE_TOLERANCE:
                intervals.append((0.0, TWO_PI))
                continue
            # Re-express the arc about the cylinder's (axis, x_axis): the sampled arc runs from
            # its first to its last point one way round.
            arc_angles = angles_about(arc_points, centre, axis, x_axis)
            forward = np.mod(arc_angles[len(arc_angles) // 2] - arc_angles[0], TWO_PI) < sweep
            begin = float(arc_angles[0] if forward else arc_angles[-1])
            intervals.append((begin, begin + sweep))
    method = "boundary circles"
    arcs = union_of_arcs(intervals)
    boundary_angles = angles_about(boundary, centre, axis, x_axis)
    slack = ACCEPT_RESIDUAL_MM / radius  # an edge of the B-spline face may stray by the residual
    if len(arcs) != 1 or not np.all(_within_arc(boundary_angles, *arcs[0], slack)):
        # The boundary circles do not bound the face: the largest gap between the angles of
        # the sampled boundary bounds it.
        method = "sampled boundary"
        all_angles = np.sort(boundary_angles)
        gaps = np.diff(np.concatenate([all_angles, [all_angles[0] + TWO_PI]]))
        widest = int(np.argmax(gaps))
        if gaps[widest] < 4.0 * TWO_PI / EDGE_SAMPLES:
            arcs = [(0.0, TWO_PI)]
        else:
            start = float(all_angles[(widest + 1) % len(all_angles)])
            arcs = [(start, start + TWO_PI - float(gaps[widest]))]
    start, end = arcs[0]
    radial = points - centre - np.outer((points - centre) @ axis, axis)
    outward_share = float(np.mean(np.sum(radial * normals, axis=1) > 0))
    face_normal = ("away_from_axis" if outward_share == 1.0
                   else "toward_axis" if outward_share == 0.0 else "mixed")
    return {
        "kind": "ring" if length < RING_MAX_LENGTH_MM else "cylinder",
        "source": {"faces": [fit.index for fit in fits],
                   "occ_type": sorted({fit.occ_type for fit in fits}),
                   "defined_by": fits[0].cylinder_source},
        "axis_point": _round(axis_point),
        "axis": _round(axis),
        "radius": _round(radius),
        "length": _round(length),
        "x_axis": _round(x_axis),
        "start_angle": _round(start),
        "end_angle": _round(end),
        "angular_range_from": method,
        "face_normal": face_normal,
        "material": None,
        "residual_mm": _round(residual, 15),
        "least_squares": {
            "radius": _round(lsq_radius),
            "axis_offset_mm": _round(
                _distance_to_axis(centre[None, :], lsq_centre, canonical_direction(lsq_axis))[0]),
            "axis_angle_rad": _round(math.acos(min(1.0, abs(float(lsq_axis @ axis))))),
            "residual_mm": _round(lsq_residual, 15),
        },
    }


def _same_cylinder(first, second) -> bool:
    centre_a, axis_a, radius_a, _ = first
    centre_b, axis_b, radius_b, _ = second
    return (abs(abs(axis_a @ axis_b) - 1.0) < 1e-9
            and _distance_to_axis(centre_b[None, :], centre_a, axis_a)[0] < MERGE_TOLERANCE_MM
            and abs(radius_a - radius_b) < MERGE_TOLERANCE_MM)


# ---------------------------------------------------------------------------------------------
# Material side against a body's solid
# ---------------------------------------------------------------------------------------------


class _SolidProbe:
    """Classify points against the solids of one body's part file."""

    def __init__(self, occ, shape):
        self._occ = occ
        self._solids = _unique(occ, shape, "SOLID")

    def inside(self, point: np.ndarray) -> bool:
        occ = self._occ
        probe = occ["Pnt"](*map(float, point))
        for solid in self._solids:
            classifier = occ["Classifier"](solid, probe, 1e-7)
            if classifier.State() == occ["State"].TopAbs_IN:
                return True
        return False

    def plane_outward(self, point: np.ndarray, normal: np.ndarray) -> int | None:
        """+1 when ``normal`` leaves the material at ``point``, -1 when it enters it, else None."""
        for distance in PROBE_DISTANCES_MM:
            ahead = self.inside(point + distance * normal)
            behind = self.inside(point - distance * normal)
            if ahead != behind:
                return -1 if ahead else 1
        return None

    def cylinder_material(self, record: dict) -> str | None:
        """'inside' (journal), 'outside' (bore) or None.

        A full cylinder or ring is a journal when its axis point at mid-length is in the
        material, a bore otherwise (the CAD draws bearing rings inside the material, 0.5 mm off
        the journal, so probing beside the surface would say nothing). A partial cylinder is
        probed on both sides of its surface at mid-angle.
        """
        axis_point = np.array(record["axis_point"])
        axis = np.array(record["axis"])
        middle = axis_point + 0.5 * record["length"] * axis
        if record["end_angle"] - record["start_angle"] >= TWO_PI - ANGLE_TOLERANCE:
            return "inside" if self.inside(middle) else "outside"
        x_axis = np.array(record["x_axis"])
        mid_angle = 0.5 * (record["start_angle"] + record["end_angle"])
        y_axis = np.cross(axis, x_axis)
        radial = math.cos(mid_angle) * x_axis + math.sin(mid_angle) * y_axis
        surface = middle + record["radius"] * radial
        for distance in PROBE_DISTANCES_MM:
            towards_axis = self.inside(surface - distance * radial)
            away = self.inside(surface + distance * radial)
            if towards_axis != away:
                return "inside" if towards_axis else "outside"
        return None


# ---------------------------------------------------------------------------------------------
# Files and the whole document
# ---------------------------------------------------------------------------------------------


def sha256_of(path: Path) -> str:
    """Hex sha256 of a file's bytes."""
    return hashlib.sha256(path.read_bytes()).hexdigest()


def extract_file(occ, path: Path, probe: _SolidProbe | None = None) -> dict[str, Any]:
    """Primitives of one STEP file (coordinates as in the file).

    Parameters
    ----------
    occ : the OpenCASCADE namespace of :func:`_occ`.
    path : the STEP file.
    probe : classifier of the body's solid, for the material side; None for frame files.
    """
    shape = read_step(occ, path)
    all_edges = _unique(occ, shape, "EDGE")
    all_vertices = _unique(occ, shape, "VERTEX")

    def edge_index(edge) -> int:
        return next(i for i, seen in enumerate(all_edges, 1) if seen.IsSame(edge))

    primitives: list[dict[str, Any]] = []
    unreduced: list[dict[str, Any]] = []
    fits: list[_FaceFit] = []
    for index, face_shape in enumerate(_unique(occ, shape, "FACE"), 1):
        face = occ["face"](face_shape)
        edges = [occ["edge"](edge) for edge in _unique(occ, face, "EDGE")]
        fits.append(_FaceFit(occ, face, index, [edge_index(edge) for edge in edges], edges))

    cylinder_groups: list[list[_FaceFit]] = []
    for fit in fits:
        if fit.cylinder is None:
            edge_records = [{key: value for key, value in record.items() if key != "residual_mm"}
                            for record in fit.edge_records]
            primitives.append(_plane_record(occ, fit, edge_records))
        elif fit.cylinder[3] <= ACCEPT_RESIDUAL_MM:
            for group in cylinder_groups:
                if _same_cylinder(group[0].cylinder, fit.cylinder):
                    group.append(fit)
                    break
            else:
                cylinder_groups.append([fit])
        else:
            unreduced.append({
                "kind": "unreduced",
                "source": {"faces": [fit.index], "occ_type": fit.occ_type},
                "reason": "neither a plane nor a cylinder within accept_residual_mm",
                "plane_residual_mm": _round(fit.plane[2], 15),
                "cylinder_residual_mm": _round(fit.cylinder[3], 15),
            })
    for group in cylinder_groups:
        primitives.append(_cylinder_record(occ, group))

    for edge in _unique(occ, shape, "EDGE", avoid="FACE"):
        record = edge_primitive(occ, occ["edge"](edge), edge_index(edge))
        (unreduced if record["kind"] == "unreduced" else primitives).append(record)
    for vertex in _unique(occ, shape, "VERTEX", avoid="EDGE"):
        index = next(i for i, seen in enumerate(all_vertices, 1) if seen.IsSame(vertex))
        point = occ["BRep_Tool"].Pnt_s(occ["vertex"](vertex))
        primitives.append({"kind": "point", "source": {"vertex": index},
                           "position": _round(_xyz(point)), "residual_mm": 0.0})

    if probe is not None:
        for record in primitives:
            if record["kind"] == "plane":
                record["outward"] = probe.plane_outward(np.array(record["point"]),
                                                        np.array(record["normal"]))
            elif record["kind"] in ("cylinder", "ring"):
                record["material"] = probe.cylinder_material(record)
    return {"primitives": primitives, "unreduced": unreduced,
            "counts": {"faces": len(fits), "edges": len(all_edges),
                       "vertices": len(all_vertices)}}


def load_model(model_path: Path = MODEL_PATH) -> dict[str, Any]:
    """The C-60 data sheet as a dict (``tomllib``)."""
    with model_path.open("rb") as stream:
        return tomllib.load(stream)


def named_files(model: dict[str, Any]) -> dict[str, dict[str, Any]]:
    """Every STEP file named by a contact or measurement pair: path -> frame and users.

    Raises
    ------
    ExtractionError
        If one file is used on two different bodies (its frame would be ambiguous).
    """
    files: dict[str, dict[str, Any]] = {}
    for group in ("contacts", "measurements"):
        for pair in model[group]:
            for side in ("1", "2"):
                body = pair[f"body{side}"]
                frame = "world" if body == model["frame"]["name"] else body
                entry = files.setdefault(pair[f"cad{side}"], {"frame": frame, "used_by": []})
                if entry["frame"] != frame:
                    raise ExtractionError(
                        f"{pair[f'cad{side}']} is used in frame {entry['frame']} and {frame}"
                    )
                entry["used_by"].append(f"{group[:-1]}:{pair['name']}:{side}")
    return files


def _body_transform(occ, body: dict[str, Any]):
    """gp_Trsf of the body's ON pose: x_world = origin + R(axis, angle) x_body."""
    rotation = occ["Trsf"]()
    rotation.SetRotation(
        occ["Ax1"](occ["Pnt"](0.0, 0.0, 0.0), occ["Dir"](*map(float, body["rotation_axis"]))),
        float(body["rotation_angle"]),
    )
    translation = occ["Trsf"]()
    translation.SetTranslation(occ["Vec"](*map(float, body["origin"])))
    return translation.Multiplied(rotation)


def _pairs(occ, model: dict[str, Any], cad_dir: Path) -> list[dict[str, Any]]:
    bodies = {body["name"]: body for body in model["bodies"]}
    placed: dict[tuple[str, str], Any] = {}

    def world_shape(path: str, body_name: str):
        key = (path, body_name)
        if key not in placed:
            shape = read_step(occ, cad_dir / path)
            if body_name in bodies:
                shape = occ["Transform"](shape, _body_transform(occ, bodies[body_name]),
                                         True).Shape()
            placed[key] = shape
        return placed[key]

    records = []
    for group in ("contacts", "measurements"):
        for pair in model[group]:
            first = world_shape(pair["cad1"], pair["body1"])
            second = world_shape(pair["cad2"], pair["body2"])
            distance = occ["Distance"](first, second)
            if not distance.IsDone():
                raise ExtractionError(f"{pair['name']}: BRepExtrema failed")
            record = {
                "name": pair["name"],
                "group": group[:-1],
                "on_pose_distance_mm": _round(distance.Value(), 9),
            }
            if "offset" in pair:
                record["on_pose_gap_mm"] = _round(distance.Value() - pair["offset"], 9)
            records.append(record)
    return records


def extract(data_dir: Path = DATA_DIR, cad_dir: Path = CAD_DIR) -> dict[str, Any]:
    """Extract the primitives of every STEP file the data sheet names (the whole document).

    Parameters
    ----------
    data_dir : folder holding ``model.toml``.
    cad_dir : folder holding the STEP files the data sheet names.

    Returns
    -------
    dict
        The JSON-ready document described in the module docstring.
    """
    occ = _occ()
    started = time.perf_counter()
    model = load_model(data_dir / "model.toml")
    body_files = {body["name"]: body["cad"] for body in model["bodies"]}
    probes: dict[str, _SolidProbe] = {}
    documents = []
    for path, usage in sorted(named_files(model).items()):
        frame = usage["frame"]
        probe = None
        if frame in body_files:
            if frame not in probes:
                probes[frame] = _SolidProbe(occ, read_step(occ, cad_dir / body_files[frame]))
            probe = probes[frame]
        result = extract_file(occ, cad_dir / path, probe)
        documents.append({
            "path": path,
            "sha256": sha256_of(cad_dir / path),
            "frame": frame,
            "used_by": usage["used_by"],
            "occ_counts": result["counts"],
            "primitives": result["primitives"],
            "unreduced": result["unreduced"],
        })
        logger.info("%s: %d primitives, %d unreduced", path, len(result["primitives"]),
                    len(result["unreduced"]))
    pairs = _pairs(occ, model, cad_dir)
    logger.info("extraction took %.2f s", time.perf_counter() - started)
    return {
        "format": FORMAT_NAME,
        "version": FORMAT_VERSION,
        "units": {"length": "mm", "angle": "rad"},
        "source": ("tools/c60_cad/cad/ and scenarios/c60/data/model.toml (Schneider Electric C-60, "
                   "Apache-2.0)"),
        "conventions": CONVENTIONS,
        "extraction": {
            "tool": "python -m tools.c60_cad (tools.c60_cad.extract)",
            "ocp_version": ocp_version(),
            "samples_per_direction": SAMPLES_PER_DIRECTION,
            "edge_samples": EDGE_SAMPLES,
            "accept_residual_mm": ACCEPT_RESIDUAL_MM,
            "ring_max_length_mm": RING_MAX_LENGTH_MM,
            "body_solids": body_files,
        },
        "files": documents,
        "pairs": pairs,
    }
