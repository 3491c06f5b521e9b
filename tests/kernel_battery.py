"""The battery of kernel calls of tests/test_kernels_without_numba.py: numpy only, so that the
Siconos worker's interpreter (Debian's Python, no pytest, no clearbench installed) runs it too,
imported by path."""

import numpy as np


def compute(cases, frames, gaps, quaternion, time_profiles):
    """Every kernel result of the battery (plain Python or compiled, by the modules given)."""
    m = cases["kinds"].shape[0]
    rows = gaps.MAX_CONTACTS_PER_PAIR
    out = {name: np.zeros(shape) for name, shape in (
        ("count", m), ("gap", (m, rows)), ("point_a", (m, rows, 3)), ("point_b", (m, rows, 3)),
        ("frame", (m, rows, 3, 3)), ("slots", m), ("slot_gap", (m, rows)),
        ("slot_frame", (m, rows, 3, 3)), ("kept", (m, rows)))}
    for i in range(m):
        shapes = [(int(cases["kinds"][i, s]), cases["params"][i, s], cases["positions"][i, s],
                   cases["rotations"][i, s]) for s in (0, 1)]
        arrays = [np.zeros(rows), np.zeros((rows, 3)), np.zeros((rows, 3)),
                  np.zeros((rows, 3, 3))]
        out["count"][i] = gaps.pair_contacts(*shapes[0], *shapes[1], *arrays)
        for name, array in zip(("gap", "point_a", "point_b", "frame"), arrays, strict=True):
            out[name][i] = array
        kept = np.zeros(rows, dtype=np.bool_)
        slot_arrays = [np.zeros(rows), np.zeros((rows, 3)), np.zeros((rows, 3)),
                       np.zeros((rows, 3, 3))]
        out["slots"][i] = gaps.pair_contact_slots(*shapes[0], *shapes[1], *slot_arrays, kept)
        out["slot_gap"][i], out["slot_frame"][i], out["kept"][i] = \
            slot_arrays[0], slot_arrays[3], kept
    out["frames"] = np.array([frames.contact_frame(n) for n in cases["normals"]])
    q, p = cases["quaternions"], cases["quaternions"][::-1].copy()
    out["normalized"] = np.array([quaternion.quat_normalize(x) for x in q])
    unit = out["normalized"]
    out["matrices"] = np.array([quaternion.quat_to_matrix(x) for x in unit])
    out["products"] = np.array([quaternion.quat_multiply(a, b) for a, b in zip(q, p,
                                                                                 strict=True)])
    out["logs"] = np.array([quaternion.quat_log(x) for x in unit])
    out["from_matrices"] = np.array([quaternion.quat_from_matrix(r) for r in out["matrices"]])
    times, values, t = cases["profile_times"], cases["profile_values"], cases["profile_t"]
    out["profiles"] = np.array([[time_profiles.profile_value(times, values, x),
                                 time_profiles.profile_slope(times, values, x),
                                 time_profiles.profile_integral(times, values, x)] for x in t])
    return out
