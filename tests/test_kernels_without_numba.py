"""The kernels import and give the compiled numbers without numba (``kernels/jit.py``).

The Siconos worker runs the gap, frame, quaternion and time-profile kernels as plain Python
under Debian's ``/usr/bin/python3`` (no numba). Here a subprocess computes a fixed battery of
cases without numba, once in this environment with numba made unimportable and once in the
worker's own interpreter (through ``adapters/siconos/worker/project_kernels.py``, skipped where
that interpreter has no numpy), and the results are compared with the compiled kernels'.
"""

from __future__ import annotations

import math
import os
import subprocess
import sys
from pathlib import Path

import numba
import numpy as np
import pytest

from clearbench.adapters.siconos import run as siconos_run
from clearbench.adapters.siconos.worker import project_kernels
from clearbench.kernels import frames, gaps, jit, quaternion, time_profiles

from .kernel_battery import compute

WORKER_FOLDER = Path(project_kernels.__file__).parent

# Plain-Python side of the comparison: reads the cases, writes the kernels' results. ``mode``
# "blocked": this environment with numba made unimportable; "worker": the Siconos worker's
# interpreter, the kernels imported by path as the worker does.
_BATTERY = """
import sys
mode, worker_folder, tests_folder, cases_path, out_path = sys.argv[1:6]
if mode == "blocked":
    sys.modules["numba"] = None
else:
    sys.path.insert(0, worker_folder)
    import project_kernels  # registers clearbench.kernels by path
sys.path.insert(0, tests_folder)
import numpy as np
from clearbench.kernels import frames, gaps, jit, quaternion, time_profiles
from kernel_battery import compute

assert not jit.NUMBA_AVAILABLE
out = {"modules": np.array(sorted(m for m in sys.modules if m.startswith("clearbench")))}
out.update(compute(dict(np.load(cases_path)), frames, gaps, quaternion, time_profiles))
np.savez(out_path, **out)
"""


def _parameters(kind: int, rng) -> np.ndarray:
    packed = np.zeros(gaps.PARAMETER_COUNT)
    if kind in (gaps.SPHERE, gaps.CIRCLE):
        packed[0] = rng.uniform(0.05, 0.3)
    elif kind == gaps.BOX:
        packed[:3] = rng.uniform(0.05, 0.4, size=3)
    elif kind in (gaps.CAPSULE, gaps.CYLINDER):
        packed[:2] = rng.uniform(0.02, 0.2), rng.uniform(0.05, 0.5)
    elif kind == gaps.ARC:
        start = rng.uniform(-math.pi, math.pi)
        packed[:3] = rng.uniform(0.05, 0.3), start, start + rng.uniform(0.2, 2 * math.pi)
    elif kind == gaps.RECTANGLE:
        packed[:3] = *rng.uniform(0.1, 0.5, size=2), rng.choice([0.0, 0.1])
    elif kind == gaps.DISC:
        packed[:2] = rng.uniform(0.1, 0.5), rng.choice([0.0, 0.1])
    elif kind == gaps.BORE:
        start = rng.uniform(-math.pi, math.pi)
        span = 2 * math.pi if rng.uniform() < 0.5 else rng.uniform(0.5, 2 * math.pi)
        packed[:4] = rng.uniform(0.2, 0.4), rng.uniform(0.05, 0.5), start, start + span
    return packed


def _rotation(rng, scale=None) -> np.ndarray:
    q = rng.normal(size=4) if scale is None else np.r_[1.0, rng.normal(scale=scale, size=3)]
    return quaternion.quat_to_matrix(quaternion.quat_normalize(q))


def _cases() -> dict[str, np.ndarray]:
    """Every supported pair of kinds in both orders, 12 random configurations each (a third of
    them nearly coaxial, small offsets: the journal-in-ring and ring-in-bore cases), unit
    normals (the frame's pole and singular direction among them), quaternions and three
    piecewise-linear profiles with a jump."""
    rng = np.random.default_rng(27)
    kinds, params, positions, rotations = [], [], [], []
    for kind_a, kind_b in gaps.CANONICAL_PAIRS:
        for order in ((kind_a, kind_b), (kind_b, kind_a)):
            for trial in range(12):
                coaxial = trial % 3 == 0
                rotation = _rotation(rng)
                kinds.append(order)
                params.append([_parameters(kind, rng) for kind in order])
                scale = 2e-3 if coaxial else 0.3
                positions.append(rng.normal(scale=scale, size=(2, 3)))
                rotations.append([rotation @ _rotation(rng, 0.05), rotation] if coaxial
                                 else [_rotation(rng), _rotation(rng)])
    normals = rng.normal(size=(300, 3))
    normals = np.vstack([normals / np.linalg.norm(normals, axis=1)[:, None],
                         frames.FRAME_POLE, frames.FRAME_SINGULAR_DIRECTION, np.eye(3)])
    times = np.array([0.1, 0.5, 0.9, 0.9, 1.5])
    return {"kinds": np.array(kinds), "params": np.array(params),
            "positions": np.array(positions), "rotations": np.array(rotations),
            "normals": normals, "quaternions": rng.normal(size=(200, 4)),
            "profile_times": times, "profile_values": np.array([1.0, -2.0, 3.0, 0.5, 0.0]),
            "profile_t": np.concatenate([np.linspace(-0.5, 2.5, 61), times])}


def _run_battery(tmp_path, interpreter: str, mode: str, env=None) -> dict[str, np.ndarray]:
    cases = _cases()
    np.savez(tmp_path / "cases.npz", **cases)
    script = tmp_path / "battery.py"
    script.write_text(_BATTERY)
    completed = subprocess.run(
        [interpreter, str(script), mode, str(WORKER_FOLDER), str(Path(__file__).parent),
         str(tmp_path / "cases.npz"), str(tmp_path / "out.npz")],
        capture_output=True, text=True, timeout=600, env=env)
    assert completed.returncode == 0, completed.stderr
    with np.load(tmp_path / "out.npz") as data:
        return {key: data[key] for key in data.files}


def _compare_with_compiled(plain: dict[str, np.ndarray]) -> None:
    cases = _cases()
    compiled = compute(cases, frames, gaps, quaternion, time_profiles)
    # Discrete outcomes (how many contacts, which slots are kept) are the same: no random case
    # sits within round-off of a decision threshold.
    for key in ("count", "slots", "kept"):
        np.testing.assert_array_equal(plain[key], compiled[key], err_msg=key)
    # Lengths [m] on configurations of size ~1 m and dimensionless frames: 1e-12 is a few
    # thousand ulp. Plain Python runs the same operations in the same order; they differ only
    # where libm and LLVM's intrinsics, or numpy's and numba's LAPACK (the roots of the
    # ring-angle quartic, polished by Newton steps afterwards), round differently.
    # One exception, the witness points of a ring or arc against a face's solid or a bore's:
    # their slots 6..7 (a bore's one slot, where its closed form does not apply) are minima over
    # the ring's angle found by Brent's search (kernels/gaps/ring_faces.py) or golden-section
    # search (kernels/gaps/round_solids.py), where the gap is quadratic in the angle, so the
    # minimum's position is fixed by the gap's round-off only to sqrt(eps) ~ 1.5e-8 of the
    # radius (<= 0.3 m here): 1e-8 m for those points. The same holds for a journal in a bore
    # (kernels/gaps/bores.py), whose candidates past a bore's edge or across a partial bore's
    # cut are minima over a ring's angle and a golden-section search over height or along an
    # edge. Their gaps keep 1e-12 (the gap is flat
    # there to second order); their frames, past a face's edge the direction from the edge to
    # the point, turn by at most the point's difference over the gap: 1e-8 m / |gap| (|gap|
    # taken no smaller than 1e-4 m).
    count = compiled["count"].astype(int)
    slots = compiled["slots"].astype(int)
    kinds = cases["kinds"]
    ring_face = {gaps.CIRCLE, gaps.ARC}, {gaps.RECTANGLE, gaps.DISC, gaps.BORE}
    for i in range(count.size):
        pair = set(int(k) for k in kinds[i])
        minima = (bool(pair & ring_face[0]) and bool(pair & ring_face[1])
                  or pair == {gaps.CYLINDER, gaps.BORE})
        smallest_gap = max(float(np.min(np.abs(compiled["gap"][i, :count[i]]), initial=1.0)),
                           1e-4)
        frame_bound = 1e-12 + 1e-8 / smallest_gap if minima else 1e-12
        for key in ("gap", "point_a", "point_b", "frame"):
            bound = {"gap": 1e-12, "frame": frame_bound}.get(key, 1e-8 if minima else 1e-12)
            np.testing.assert_allclose(plain[key][i, :count[i]], compiled[key][i, :count[i]],
                                       rtol=0, atol=bound, err_msg=f"{key}, case {i}")
        for key in ("slot_gap", "slot_frame"):
            bound = frame_bound if key == "slot_frame" else 1e-12
            np.testing.assert_allclose(plain[key][i, :slots[i]], compiled[key][i, :slots[i]],
                                       rtol=0, atol=bound, err_msg=f"{key}, case {i}")
    # Frames, quaternions, rotation matrices and profiles of O(1) inputs: closed forms of a
    # few dozen operations (quat_log: one atan2), 1e-14 is ~50 ulp.
    for key in ("frames", "normalized", "matrices", "products", "logs", "from_matrices",
                "profiles"):
        np.testing.assert_allclose(plain[key], compiled[key], rtol=0, atol=1e-14,
                                   err_msg=key)


def test_the_kernels_give_the_compiled_numbers_with_numba_unimportable(tmp_path):
    plain = _run_battery(tmp_path, sys.executable, "blocked")
    _compare_with_compiled(plain)


def test_the_siconos_worker_interpreter_runs_the_kernels(tmp_path):
    interpreter = siconos_run.SICONOS_PYTHON
    if not Path(interpreter).exists():
        pytest.skip(f"{interpreter} not found")
    probe = subprocess.run([interpreter, "-c", "import numpy"], capture_output=True,
                           env=siconos_run.clean_environment())
    if probe.returncode != 0:
        pytest.skip(f"{interpreter} has no numpy")
    plain = _run_battery(tmp_path, interpreter, "worker", env=siconos_run.clean_environment())
    # The worker imports the kernels and nothing else of the project.
    gap_modules = {f"clearbench.kernels.gaps.{path.stem}"
                   for path in Path(gaps.__file__).parent.glob("*.py") if path.stem != "__init__"}
    assert set(plain["modules"]) == {
        "clearbench", "clearbench.kernels", "clearbench.kernels.frames",
        "clearbench.kernels.gaps", "clearbench.kernels.jit", "clearbench.kernels.quaternion",
        "clearbench.kernels.time_profiles"} | gap_modules
    _compare_with_compiled(plain)


def test_the_worker_finds_the_projects_kernels_folder():
    assert Path(project_kernels.KERNELS_FOLDER) == Path(jit.__file__).parent
    assert os.path.isfile(os.path.join(project_kernels.KERNELS_FOLDER, "gaps", "__init__.py"))


def test_njit_is_numbas_own_when_numba_imports():
    assert jit.NUMBA_AVAILABLE
    assert jit.njit is numba.njit


def test_the_stand_in_njit_returns_the_function_in_every_call_form(tmp_path):
    script = tmp_path / "forms.py"
    script.write_text(
        "import sys\n"
        "sys.modules['numba'] = None\n"
        "from clearbench.kernels.jit import NUMBA_AVAILABLE, njit\n"
        "def f(x):\n"
        "    return x + 1\n"
        "assert not NUMBA_AVAILABLE\n"
        "assert njit(f) is f\n"
        "assert njit(cache=True)(f) is f\n"
        "assert njit(cache=True, inline='always', error_model='numpy')(f) is f\n"
        "assert njit('float64(float64)', cache=True)(f) is f\n"
        "assert njit()(f) is f\n")
    completed = subprocess.run([sys.executable, str(script)], capture_output=True, text=True,
                               timeout=120)
    assert completed.returncode == 0, completed.stderr
