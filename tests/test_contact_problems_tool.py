"""``tools.contact_problems``: a run's one-step problems kept and solved again.

The replay is the instrument docs/reference-solver-speed.md measures the hybrid chain's changes
with, so it must give back, on the checkout that recorded them, exactly what the run's own
(Python) chain returned: the compiled chain is the same sequence of attempts on the same
kernels, its "Newton first" memory carried from problem to problem as in the run.
"""

from __future__ import annotations

import numpy as np

from tools.contact_problems import problems, record, replay


def test_a_recording_replays_to_the_bit_on_its_own_checkout(tmp_path):
    data = record("clearance-pendulum", None, 0, 60)
    np.savez_compressed(tmp_path / "p.npz", **data)
    with np.load(tmp_path / "p.npz") as handle:
        loaded = {name: handle[name] for name in handle.files}
    cases = problems(loaded)
    assert len(cases) == loaded["rows"].size > 0
    for (_, W, q, mu, nb, r0, r), m in zip(cases, loaded["rows"], strict=True):
        assert W.shape == (m, m) and q.shape == r0.shape == r.shape == (m,)
        assert mu.size == (m - nb) // 3
    replayed = replay(loaded)
    assert replayed["equal"] == len(cases)
    assert replayed["largest_velocity_difference"] == 0.0
    np.testing.assert_array_equal(replayed["iterations"], loaded["iterations"])
    np.testing.assert_array_equal(replayed["converged"], loaded["converged"])
